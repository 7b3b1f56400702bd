"""URDF import (issue 31): against Pinocchio's forward dynamics on the same file, mass, mimic, errors."""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import mbdsim as mb

FILES = Path(__file__).parent / "import_files"
ARM = FILES / "arm.urdf"
MIMIC = '<mimic joint="finger_a_joint" multiplier="0.5" offset="0"/>'
Q0 = {"shoulder": 0.3, "elbow": -0.5, "wrist": 0.8, "finger_a_joint": 0.01, "finger_b_joint": -0.02}
V0 = {"shoulder": 0.5, "elbow": -1.0}


def _quiet(fn, *a, **k):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ImportApproximationWarning)
        return fn(*a, **k)


@pytest.fixture(scope="module")
def arm_free(tmp_path_factory):
    """The arm without its <mimic> (Pinocchio reads mimic joints as independent by default)."""
    path = tmp_path_factory.mktemp("urdf") / "arm.urdf"
    path.write_text(ARM.read_text().replace(MIMIC, ""))
    return path


def _pinocchio_aba(path, q0, v0, times, floating=False):
    """Joint angles of Pinocchio's ABA integrated by scipy (DOP853, rtol 1e-12)."""
    pin = pytest.importorskip("pinocchio")
    from scipy.integrate import solve_ivp
    pm = pin.buildModelFromUrdf(str(path))
    pd = pm.createData()
    names = [pm.names[i] for i in range(1, pm.njoints)]
    th0 = np.array([q0.get(n, 0.0) for n in names])
    w0 = np.array([v0.get(n, 0.0) for n in names])
    n = len(names)

    def f(t, y):
        q = pin.integrate(pm, pin.neutral(pm), y[:n])   # one-DOF joints: q from the angles
        return np.concatenate([y[n:], pin.aba(pm, pd, q, y[n:], np.zeros(n))])

    sol = solve_ivp(f, (times[0], times[-1]), np.concatenate([th0, w0]), method="DOP853", rtol=1e-12,
                    atol=1e-12, t_eval=times)
    return names, sol.y[:n], pin.computeTotalMass(pm)


def test_arm_against_pinocchio_aba(arm_free):
    model = _quiet(mb.from_urdf, arm_free, initial_displacement=Q0, initial_velocity=V0)
    res = mb.simulate(model, 0.5, output_step=0.01, rtol=1e-10)
    assert res.success, res.message
    names, angles, pin_mass = _pinocchio_aba(arm_free, Q0, V0, res.time)
    assert set(names) == {"shoulder", "elbow", "wrist", "finger_a_joint", "finger_b_joint"}
    for k, name in enumerate(names):
        err = np.abs(res.joint_coordinate(name) - angles[k]).max()
        assert err < 1e-7, (name, err)
        assert np.ptp(angles[k]) > 1e-3, name   # every joint moves: the comparison can fail
    moving = sum(b.mass for b in model.bodies.values())
    assert moving == pytest.approx(pin_mass, rel=1e-12)   # the fixed root is ground, as in Pinocchio


def test_merged_fixed_link_conserves_mass_and_names_its_frame():
    model = _quiet(mb.from_urdf, ARM)
    upper = model.bodies["upper"]
    assert upper.mass == pytest.approx(1.7 + 0.4)            # bracket merged into upper
    assert "bracket" in upper.markers and "bracket" not in model.bodies
    assert "bracket_mount" not in model.joints
    floating = _quiet(mb.from_urdf, ARM, floating_base=True)
    total = 4.0 + 1.7 + 0.4 + 1.1 + 0.6 + 0.1 + 0.1
    assert sum(b.mass for b in floating.bodies.values()) == pytest.approx(total)


def test_mimic_pair_moves_in_its_ratio():
    model = _quiet(mb.from_urdf, ARM, initial_displacement={"finger_a_joint": 0.02},
                   initial_velocity={"finger_a_joint": 0.3, "elbow": 1.0})
    res = mb.simulate(model, 0.3, output_step=0.01)
    assert res.success, res.message
    a, b = res.joint_coordinate("finger_a_joint"), res.joint_coordinate("finger_b_joint")
    assert np.ptp(a) > 1e-2
    assert np.abs(b - 0.5 * a).max() < 1e-9
    assert b[0] == pytest.approx(0.01)


def test_mimic_offset_limits_damping_and_friction(tmp_path):
    text = ARM.read_text().replace(MIMIC, '<mimic joint="finger_a_joint" multiplier="-2" offset="0.05"/>')
    text = text.replace('<axis xyz="1 0 -1"/>', '<axis xyz="1 0 -1"/><dynamics damping="0.3" friction="0.01"/>')
    path = tmp_path / "arm2.urdf"
    path.write_text(text)
    model = _quiet(mb.from_urdf, path)
    assert model.forces["wrist_limit"].lower == -3 and model.forces["wrist_limit"].upper == 3
    assert model.forces["wrist_damping"].damping == 0.3
    assert model.forces["wrist_friction"].preload == 0.01
    res = mb.simulate(model, 0.2, output_step=0.01)
    a, b = res.joint_coordinate("finger_a_joint"), res.joint_coordinate("finger_b_joint")
    assert np.abs(b - (-2 * a + 0.05)).max() < 1e-9


def test_missing_mesh_is_a_warning_and_primitives_are_visuals():
    with pytest.warns(mb.ImportApproximationWarning, match="fore.stl"):
        model = mb.from_urdf(ARM)
    kinds = {(v.body, v.kind) for v in model.visuals}
    assert ("upper", "cylinder") in kinds and ("ground", "box") in kinds


def test_visuals_are_placed_on_their_bodies_and_drawn(tmp_path):
    """Issue 31: the file's visual primitives become shapes on their bodies (Body.add_shape, no density:
    the inertials stay the mass properties) that the viewer draws where the body is."""
    import json
    import re
    model = _quiet(mb.from_urdf, ARM)
    upper = model.bodies["upper"]
    placed = [v for v in model.visuals if v.body == "upper" and v.role == "visual"]
    assert placed and len(upper.shapes) == len(placed)
    assert upper.mass == pytest.approx(_quiet(mb.from_urdf, ARM).bodies["upper"].mass)
    html = mb.animate(model, tmp_path / "arm.html", end_time=0.01)
    data = json.loads(re.search(r'id="mbdsim-data">(.*?)</script>', Path(html).read_text(), re.S).group(1))
    moving = sum(len(b.shapes) for b in model.bodies.values() if b is not model.ground)
    assert moving > 0   # every shape is drawn, the base link's on ground too (body -1), each on its body
    assert len(data["shapes"]) == moving + len(model.ground.shapes)
    names = {b: i for i, b in enumerate(n for n in model.bodies if model.bodies[n] is not model.ground)}
    drawn = sorted(s["body"] for s in data["shapes"])
    assert drawn == sorted([-1] * len(model.ground.shapes) + [k for n, k in names.items()
                                                                for _ in model.bodies[n].shapes])


def test_package_mesh_is_resolved(tmp_path):
    (tmp_path / "test_arm" / "meshes").mkdir(parents=True)
    (tmp_path / "test_arm" / "meshes" / "fore.stl").write_text("solid x\nendsolid x\n")
    model = _quiet(mb.from_urdf, ARM, package_dirs=[tmp_path])
    mesh = [v for v in model.visuals if v.kind == "mesh"]
    assert mesh and mesh[0].body == "fore" and mesh[0].file.endswith("fore.stl")


@pytest.mark.parametrize("text, line, what", [
    ('<robot name="r">\n<link name="a"/>\n<joint name="j" type="revolute">\n<parent link="a"/>'
     '<child link="b"/></joint></robot>', 3, "no link named 'b'"),
    ('<robot name="r">\n<link name="a"/>\n<link name="b"/>\n<joint name="j" type="screw">'
     '<parent link="a"/><child link="b"/></joint></robot>', 4, "unsupported joint type"),
    ('<robot name="r">\n<link name="a">\n<inertial><mass value="x"/></inertial></link></robot>', 3, "expected numbers"),
    ('<robot name="r"><link name="a"></robot>', 1, "not well-formed"),
    ('<?xml version="1.0"?>\n<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>\n<robot name="&x;"/>', 2,
     "entity"),
])
def test_bad_files_give_one_clear_error(tmp_path, text, line, what):
    path = tmp_path / "bad.urdf"
    path.write_text(text)
    with pytest.raises(mb.ModelFileError) as err:
        mb.from_urdf(path)
    assert err.value.file == str(path) and err.value.line == line, str(err.value)
    assert what in str(err.value)


def test_initial_values_name_unknown_joints():
    with pytest.raises(mb.ModelFileError, match="'nope' is not a movable joint"):
        _quiet(mb.from_urdf, ARM, initial_displacement={"nope": 1.0})
