"""MJCF import (issue 31): against MuJoCo's RK4 at a tiny step, exact loop closure, errors."""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import mbdsim as mb

mujoco = pytest.importorskip("mujoco")
FILES = Path(__file__).parent / "import_files"
CHAIN, FOURBAR = FILES / "chain.xml", FILES / "fourbar.xml"


def _quiet(fn, *a, **k):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ImportApproximationWarning)
        return fn(*a, **k)


def _mujoco_rk4(path, end, dt, every):
    """qpos and body (xipos, xmat) of MuJoCo's RK4 from keyframe 0, sampled every `every` steps."""
    mj = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(mj)
    mj.opt.integrator, mj.opt.timestep = mujoco.mjtIntegrator.mjINT_RK4, dt
    mujoco.mj_resetDataKeyframe(mj, d, 0)
    mujoco.mj_kinematics(mj, d)
    qs, pos, rot = [d.qpos.copy()], [d.xipos.copy()], [d.xmat.copy()]
    for k in range(int(round(end / dt))):
        mujoco.mj_step(mj, d)
        if (k + 1) % every == 0:
            mujoco.mj_kinematics(mj, d)
            qs.append(d.qpos.copy()), pos.append(d.xipos.copy()), rot.append(d.xmat.copy())
    return mj, np.array(qs), np.array(pos), np.array(rot)


def test_open_chain_against_mujoco_rk4():
    """Geom-derived masses (densities, default classes, capsule/box/cylinder/ellipsoid/sphere), rotated
    hinge axes, a ball joint, a slide spring with springref, damping, ref, gravity and a keyframe."""
    model = _quiet(mb.from_mjcf, CHAIN)
    res = mb.simulate(model, 0.5, output_step=0.01, rtol=1e-10)
    assert res.success, res.message
    mj, qs, pos, rot = _mujoco_rk4(CHAIN, 0.5, 1e-5, 1000)
    assert np.allclose(model.gravity, [0.3, -0.2, -9.81])
    for b in ("link1", "link2", "link3", "slider"):
        bid = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_BODY, b)
        assert model.bodies[b].mass == pytest.approx(mj.body_mass[bid], rel=1e-12)
        assert np.abs(res.position(b) - pos[:, bid]).max() < 1e-7, b
        assert np.abs(res.orientation(b).reshape(-1, 9) - rot[:, bid]).max() < 1e-7, b
    for name, adr in (("j1", 0), ("j2", 1), ("s1", 6)):
        x = res.joint_coordinate(name) + mj.qpos0[adr]          # mbdsim coordinates are q - ref
        assert np.abs(x - qs[:, adr]).max() < 1e-7, name
        assert np.ptp(qs[:, adr]) > 1e-3, name                    # it moves: the comparison can fail


def test_geom_masses_are_mujocos_closed_forms():
    """Two geoms whose mass MuJoCo derives from the density, checked against the closed forms."""
    model = _quiet(mb.from_mjcf, CHAIN)
    box = 2700 * 0.04 * 0.04 * 0.04                              # slider: a 2 cm half-size cube
    assert model.bodies["slider"].mass == pytest.approx(box, rel=1e-12)
    assert np.allclose(np.diag(model.bodies["slider"].inertia), box * (0.04**2 + 0.04**2) / 12, rtol=1e-9)
    r = 0.04
    sphere = 800 * 4 / 3 * np.pi * r**3
    bar = 800 * 0.1 * 0.02 * 0.02
    assert model.bodies["link3"].mass == pytest.approx(sphere + bar, rel=1e-12)


def test_connect_equality_closes_exactly_where_mujoco_drifts():
    model = _quiet(mb.from_mjcf, FOURBAR)
    assert model.joints["closure"].kind == "spherical"
    res = mb.simulate(model, 1.0, output_step=0.01, rtol=1e-10)
    assert res.success, res.message
    assert np.ptp(res.joint_coordinate("crank_pin")) > 0.5
    rocker, p0 = model.bodies["rocker"], model.joints["closure"].point
    tip_local = rocker.orientation.T @ (p0 - rocker.position)
    tip = res.position("rocker") + np.einsum("nij,j->ni", res.orientation("rocker"), tip_local)
    gap = np.linalg.norm(tip - p0, axis=1).max()
    assert gap < 1e-10
    mj, _, pos, rot = _mujoco_rk4(FOURBAR, 1.0, 1e-4, 100)
    bid = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_BODY, "rocker")
    frame = np.array([p - r.reshape(3, 3) @ mj.body_ipos[bid] for p, r in zip(pos[:, bid], rot[:, bid])])
    tip_mj = frame + np.einsum("nij,j->ni", rot[:, bid].reshape(-1, 3, 3), [0.1, 0, -0.25])
    assert np.linalg.norm(tip_mj - p0, axis=1).max() > 1e3 * gap   # MuJoCo's soft constraint drifts


def test_joint_equality_weld_and_motor(tmp_path):
    text = """<mujoco model="eq">
  <worldbody>
    <body name="a"><joint name="ja" axis="0 0 1"/><geom type="box" size="0.1 0.02 0.02" pos="0.1 0 0"/>
      <body name="a2" pos="0.2 0 0"><geom size="0.02"/></body></body>
    <body name="b" pos="0 0.5 0"><joint name="jb" axis="0 0 1"/><geom type="box" size="0.1 0.02 0.02" pos="0.1 0 0"/></body>
    <body name="c" pos="0 1 0"><joint name="jc" type="slide" axis="1 0 0"/><geom size="0.05"/>
      <body name="d" pos="0 0 -0.2"><joint name="jd" axis="0 1 0"/><geom size="0.03"/></body></body>
  </worldbody>
  <equality><joint joint1="jb" joint2="ja" polycoef="0.1 -2 0 0 0"/><weld body1="c" body2="d"/></equality>
  <actuator><motor name="m" joint="ja" gear="2"/></actuator>
  <keyframe><key ctrl="0.05"/></keyframe>
</mujoco>"""
    path = tmp_path / "eq.xml"
    path.write_text(text)
    model = _quiet(mb.from_mjcf, path)
    assert model.bodies["a"].mass == pytest.approx(mujoco.MjModel.from_xml_path(str(path)).body_mass[1]
                                                   + mujoco.MjModel.from_xml_path(str(path)).body_mass[2])
    res = mb.simulate(model, 0.3, output_step=0.01)
    assert res.success, res.message
    a, b = res.joint_coordinate("ja"), res.joint_coordinate("jb")
    assert np.ptp(a) > 1e-3
    assert np.abs(b - (0.1 - 2 * a)).max() < 1e-9
    assert np.abs(res.joint_coordinate("jd")).max() < 1e-9


@pytest.mark.parametrize("text, line, what", [
    ('<mujoco>\n<worldbody>\n<body><joint type="hinge"/><geom size=".1"/></body></worldbody>\n'
     '<tendon><fixed name="t"/></tendon></mujoco>', 4, "tendons"),
    ('<mujoco>\n<worldbody>\n<body><joint name="j"/><geom size=".1"/></body></worldbody>\n<actuator>\n'
     '<position joint="j"/></actuator></mujoco>', 5, "<position> actuators"),
    ('<?xml version="1.0"?>\n<!DOCTYPE m [<!ENTITY x SYSTEM "file:///etc/passwd">]>\n<mujoco model="&x;"/>', 2,
     "entity"),
    ('<mujoco>\n<worldbody>\n<body>\n<joint type="hing"/><geom size=".1"/></body></worldbody></mujoco>', 4,
     "compiler"),
])
def test_bad_files_give_one_clear_error(tmp_path, text, line, what):
    path = tmp_path / "bad.xml"
    path.write_text(text)
    with pytest.raises(mb.ModelFileError) as err:
        mb.from_mjcf(path)
    assert err.value.file == str(path) and err.value.line == line, str(err.value)
    assert what in str(err.value)
