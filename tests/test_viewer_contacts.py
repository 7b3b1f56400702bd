"""Issue 30: contact forces drawn as arrows on request (animate(..., contact_forces=True), mbdsim animate
--contact-forces): the scene carries, per frame, each touching point and its force, equal to the Result's
own contact_points; a box resting on a plane shows four arrows summing to its weight."""
import json
import re

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.viewer import build_scene

G, M, A, K = 9.81, 1.0, 0.1, 1e5


def resting_box():
    m = mb.Model("box", gravity=(0, 0, -G))
    b = m.add_body("box", M, (M * A * A / 6,) * 3, position=(0, 0, A / 2 - M * G / (4 * K)))
    m.add_contact("floor", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), b.add_shape("g", mb.Box((A, A, A))),
                  K, 1.0, 200.0, 1e-4, mu=0.3)
    return m


@pytest.fixture(scope="module")
def res():
    r = mb.simulate(resting_box(), 0.2, 0.01)
    assert r.success
    return r


def test_scene_has_an_arrow_per_touching_point(res):
    plain = build_scene(res)
    assert plain.contact_forces is None and plain.to_json()["contact_forces"] is None
    scene = build_scene(res, contact_forces=True)
    cf = scene.to_json()["contact_forces"]
    assert len(cf["frames"]) == len(scene.time)
    last = np.asarray(cf["frames"][-1]).reshape(-1, 6)
    assert len(last) == 4                                   # the four bottom corners
    assert np.allclose(last[:, 3:].sum(0), (0, 0, M * G), rtol=1e-5, atol=1e-4)   # they carry the weight
    assert np.allclose(np.abs(last[:, :2]), A / 2, rtol=1e-5)                      # at the corners
    ref = res.contact_points("floor")
    ref = ref[ref.time == res.time[-1]]
    assert np.allclose(np.sort(last[:, 2]), np.sort(ref.z), atol=1e-9)
    # a force of the 90th percentile of the run's point forces is drawn 0.1 scene sizes long
    mags = np.concatenate([np.linalg.norm(np.reshape(f, (-1, 6))[:, 3:], axis=1) for f in cf["frames"] if f])
    assert cf["scale"] * np.percentile(mags, 90) == pytest.approx(0.1 * scene.scale, rel=1e-5)


def test_animate_page_carries_the_arrows(res, tmp_path):
    page = mb.animate(res, tmp_path / "a.html", contact_forces=True, signal=None)
    data = json.loads(re.search(r'id="mbdsim-data"[^>]*>(.*?)</script>', page.read_text(), re.S).group(1))
    assert len(np.asarray(data["contact_forces"]["frames"][-1]).reshape(-1, 6)) == 4
    page = mb.animate(res, tmp_path / "b.html", signal=None)
    data = json.loads(re.search(r'id="mbdsim-data"[^>]*>(.*?)</script>', page.read_text(), re.S).group(1))
    assert data["contact_forces"] is None


def test_cli_contact_forces(tmp_path):
    from typer.testing import CliRunner

    from mbdsim.cli.app import app
    model = tmp_path / "box.yaml"
    mb.save_model(resting_box(), model)
    out = tmp_path / "box.html"
    r = CliRunner().invoke(app, ["animate", str(model), "--end", "0.05", "--contact-forces", "-o", str(out)])
    assert r.exit_code == 0, r.output
    assert '"contact_forces":{"scale"' in out.read_text()


def test_sphere_plane_contact_arrow_is_the_contact_force():
    """The exact sphere-plane Contact: one arrow at the touching point, equal to its normal force."""
    m = mb.Model("ball", gravity=(0, 0, -G))
    ball = m.add_particle("ball", 1.0, position=(0, 0, 0.2))
    m.add_contact("floor", mb.Sphere(ball, 0.05), mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), 1e5, 1.5, 50.0, 1e-3)
    res = mb.simulate(m, 0.6, 0.002)
    cf = build_scene(res, contact_forces=True).contact_forces
    Fn = res.spring_force("floor")
    touching = [k for k, f in enumerate(cf["frames"]) if f]
    assert touching == list(np.nonzero(Fn > 0)[0]) and touching
    for k in touching:
        x, y, z, fx, fy, fz = cf["frames"][k]
        assert abs(fz - (-Fn[k])) <= 1e-5 * abs(Fn[k]) + 1e-9    # force on shape_j (the plane): downward
        below = res.position("ball")[k, 2] - 0.05                   # the sphere's lowest point (< 0: overlap)
        assert abs(z - below / 2) <= 1e-5 * abs(below) + 1e-12      # the middle of the overlap
