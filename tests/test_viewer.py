"""Viewer scene and page (no browser): equivalent boxes, quaternions, frames, elements, animate(), CLI,
notebook summaries.  The page is played in a real Chromium in test_viewer_browser.py."""
import json
import re
import subprocess
import sys

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.viewer import build_scene, default_signal
from mbdsim.viewer.scene import equivalent_box, frame_indices, quaternions


def rot(axis, angle):
    from scipy.spatial.transform import Rotation
    return Rotation.from_rotvec(np.asarray(axis, float) / np.linalg.norm(axis) * angle).as_matrix()


def test_equivalent_box_recovers_a_box():
    m, (a, b, c) = 3.0, (0.4, 0.1, 0.25)
    J = m / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    sides, axes = equivalent_box(m, J, 0.0)
    assert sorted(sides) == pytest.approx(sorted([a, b, c]), rel=1e-12)
    R = rot((1, 2, 3), 0.7)              # same box, principal axes turned: the sides follow the axes
    sides, axes = equivalent_box(m, R @ J @ R.T, 0.0)
    for s, ax in zip(sides, axes.T):
        k = int(np.argmax(np.abs(R.T @ ax)))
        assert s == pytest.approx([a, b, c][k], rel=1e-9)
    assert np.linalg.det(axes) == pytest.approx(1.0)
    rod = equivalent_box(2.0, np.diag([0.0, 2 / 12, 2 / 12]), 0.01)[0]   # slender rod: thickness clamped
    assert sorted(rod) == pytest.approx([0.01, 0.01, 1.0])
    assert equivalent_box(0.0, np.eye(3), 0.01) is None


def test_quaternions_three_js_order():
    q = quaternions(np.stack([np.eye(3), rot((0, 0, 1), 0.5)]))
    np.testing.assert_allclose(q[0], [0, 0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(q[1], [0, 0, np.sin(0.25), np.cos(0.25)], atol=1e-15)


def test_frame_indices():
    assert list(frame_indices(5, 10)) == [0, 1, 2, 3, 4]
    idx = frame_indices(10001, 2000)
    assert len(idx) <= 2000 and idx[0] == 0 and idx[-1] == 10000 and np.all(np.diff(idx) > 0)
    with pytest.raises(mb.ModelError, match="max_frames"):
        frame_indices(10, 1)


def rich_model():
    """Pendulum rod with a spring to a particle, a contact ball on the rod and a floor plane."""
    model = mb.Model("rig", gravity=(0.0, 0.0, -9.81))
    rod = model.add_body("rod", mass=2.0, inertia=(1e-3, 2.0 / 12, 2.0 / 12), position=(0.5, 0, 0))
    model.add_revolute("pin", model.ground, rod, point=(0, 0, 0), axis=(0, 1, 0))
    bob = model.add_particle("bob", mass=0.5, position=(1.0, 0, -0.5))
    model.add_spring_damper("spring", (rod, (1.0, 0, 0)), bob, stiffness=200.0, damping=1.0)
    ball = model.add_body("ball", mass=1.0, inertia=(4e-3,) * 3, position=(0, 0.5, 0.3))
    model.add_contact("floor", mb.Plane(model.ground, (0, 0, 0), (0, 0, 1)), mb.Sphere(ball, 0.1),
                      stiffness=1e5, exponent=1.5, damping=10.0, penetration=1e-3)
    return model


@pytest.fixture(scope="module")
def rig():
    return mb.simulate(rich_model(), end_time=0.3, output_step=0.001)


def test_scene_contents(rig):
    sc = build_scene(rig, signal="pin.angle", max_frames=50)
    n = len(sc.time)
    assert n <= 50 and sc.time[0] == 0.0 and sc.time[-1] == pytest.approx(0.3)
    assert sc.up == [0.0, 0.0, 1.0]
    bodies = {b["name"]: b for b in sc.bodies}
    assert bodies["rod"]["shape"]["kind"] == "box"
    assert sorted(bodies["rod"]["shape"]["size"])[-1] == pytest.approx(np.sqrt(6 / 2.0 * (4 / 12 - 1e-3)), rel=1e-6)
    assert bodies["ball"]["shape"] == {"kind": "sphere", "radius": 0.1, "center": [0.0, 0.0, 0.0]}
    assert bodies["bob"]["shape"]["kind"] == "sphere"
    # poses are the Result's at the chosen frames
    idx = frame_indices(len(rig.time), 50)
    pos = np.reshape(bodies["rod"]["pos"], (-1, 3))
    np.testing.assert_allclose(pos, rig.position(rig.system.model.bodies["rod"])[idx], atol=1e-5)
    q = np.reshape(bodies["rod"]["quat"], (-1, 4))
    np.testing.assert_allclose(q, quaternions(rig.orientation(rig.system.model.bodies["rod"])[idx]), atol=1e-5)
    assert [j["name"] for j in sc.joints] == ["pin"] and sc.joints[0]["local"] == [-0.5, 0.0, 0.0]
    (sp,) = sc.springs
    assert sp["kind"] == "coil" and sp["i"]["local"] == [0.5, 0.0, 0.0] and sp["j"]["local"] == [0.0, 0.0, 0.0]
    assert sorted(s["kind"] for s in sc.shapes) == ["plane", "sphere"]
    assert sc.signal["unit"] == "rad" and len(sc.signal["series"][0]["values"]) == n
    json.dumps(sc.to_json(), allow_nan=False)


def test_animate_model_and_result(tmp_path, rig):
    page = mb.animate(rich_model(), tmp_path / "a.html", end_time=0.05)
    html = page.read_text()
    data = json.loads(re.search(r'id="mbdsim-data">(.*?)</script>', html, re.S).group(1).replace("<\\/", "</"))
    assert data["time"][-1] == pytest.approx(0.05) and len(data["time"]) == 1001
    assert data["signal"]["label"] == "pin.angle"                       # default: first joint coordinate
    assert not re.search(r"""(src|href)=["']?(https?:)?//""", html)     # nothing fetched at view time
    assert html.count("data:text/javascript;base64,") == 2 and "</script" not in _scripts_body(html)
    cut = mb.animate(rig, tmp_path / "b.html", end_time=0.1, signal=None, max_frames=20)
    data = json.loads(re.search(r'id="mbdsim-data">(.*?)</script>', cut.read_text(), re.S).group(1))
    assert data["signal"] is None and len(data["time"]) <= 20 and data["time"][-1] == pytest.approx(0.1)


def _scripts_body(html):
    """The text inside the data script element (must not contain a closing tag)."""
    return re.search(r'id="mbdsim-data">(.*?)</script>', html, re.S).group(1)


def test_animate_errors(tmp_path, rig):
    with pytest.raises(mb.ModelError, match="path: must end in .html"):
        mb.animate(rig, tmp_path / "a.png")
    with pytest.raises(mb.ModelError, match="end_time: must be a positive"):
        mb.animate(rig, tmp_path / "a.html", end_time=-1)
    with pytest.raises(mb.ModelError, match="geometry for 'wheel'"):
        mb.animate(rig, tmp_path / "a.html", geometry={"wheel": mb.Sphere("rod", 0.1)})
    with pytest.raises(mb.ModelError, match="expected an mbdsim Result or Model"):
        mb.animate(42, tmp_path / "a.html")


def test_geometry_and_table_scene(tmp_path, rig):
    sc = build_scene(rig, geometry={"rod": mb.Sphere("rod", 0.2)}, max_frames=10)
    assert sc.bodies[0]["shape"]["kind"] == "sphere" and sc.bodies[0]["shape"]["radius"] == 0.2
    df = rig.to_dataframe()
    assert default_signal(df.columns) == "pin.angle [rad]"
    page = mb.animate(df, tmp_path / "t.html", max_frames=30)
    data = json.loads(_scripts_body(page.read_text()))
    assert [b["name"] for b in data["bodies"]] == ["rod", "bob", "ball"] and len(data["time"]) <= 30
    assert data["trails"] is True and sc.trails is False     # table: CM paths drawn; full scene: none
    np.testing.assert_allclose(np.reshape(data["bodies"][0]["pos"], (-1, 3))[-1], df.iloc[-1, 1:4], atol=1e-5)


def test_cli_animate_results_file(tmp_path, rig):
    rig.to_dataframe().to_csv(tmp_path / "r.csv", index=False)
    p = subprocess.run([sys.executable, "-m", "mbdsim", "animate", str(tmp_path / "r.csv"), "-o",
                        str(tmp_path / "r.html"), "--end", "0.1", "--signal", "pin.angle_rate"],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    data = json.loads(_scripts_body((tmp_path / "r.html").read_text()))
    assert data["time"][-1] == pytest.approx(0.1) and data["signal"]["unit"] == "rad/s"
    p = subprocess.run([sys.executable, "-m", "mbdsim", "animate", str(tmp_path / "nope.yaml")],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and "does not exist" in p.stderr


def test_notebook_summaries(rig):
    html = rig.system.model._repr_html_()
    for s in ("rod", "bob", "ball", "pin", "revolute", "spring", "SpringDamper", "floor", "Contact", "-9.81"):
        assert s in html
    r = rig._repr_html_()
    assert "0 .. 0.3 s" in r and f"<td>{len(rig.time)}</td>" in r and "success" in r
    bad = mb.Model("<b>x</b>")
    assert "&lt;b&gt;x&lt;/b&gt;" in bad._repr_html_()


def test_cli_animate_model_file_through_load_model(tmp_path, monkeypatch):
    """`mbdsim animate MODEL` reads the file with mb.load_model (stubbed here with a Python-built model)."""
    from typer.testing import CliRunner

    from mbdsim.cli.app import app
    seen = []

    def load_model(path):
        seen.append(path)
        if path.suffix == ".bad":
            raise mb.ModelError("joint 'pin'", "axis", "must be non-zero")
        return rich_model()

    monkeypatch.setattr(mb, "load_model", load_model, raising=False)
    (tmp_path / "rig.yaml").write_text("model: rig\n")
    (tmp_path / "rig.bad").write_text("model: rig\n")
    r = CliRunner().invoke(app, ["animate", str(tmp_path / "rig.yaml"), "-o", str(tmp_path / "rig.html"),
                                 "--end", "0.02"])
    assert r.exit_code == 0, r.output
    data = json.loads(_scripts_body((tmp_path / "rig.html").read_text()))
    assert seen == [tmp_path / "rig.yaml"] and data["title"] == "rig" and data["time"][-1] == pytest.approx(0.02)
    assert len(data["springs"]) == 1 and len(data["shapes"]) == 2
    r = CliRunner().invoke(app, ["animate", str(tmp_path / "rig.bad"), "-o", str(tmp_path / "bad.html")])
    assert r.exit_code == 2 and "joint 'pin'.axis: must be non-zero" in r.output
