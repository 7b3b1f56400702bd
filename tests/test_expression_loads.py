"""Loads written as expressions of time and state (issue 14): closed forms, equivalence with the built-in
elements, on the compiled joint-coordinate, compiled absolute-coordinate and reference paths."""
from __future__ import annotations

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.system import compiled

I_DISK, T0, W0 = 2.0, 3.0, 10.0


def _disk(how):
    m = mb.Model()
    m.add_body("disk", mass=1.0, inertia=(1.0, 1.0, I_DISK))
    m.add_revolute("pin", "ground", "disk", (0, 0, 0), (0, 0, 1))
    if how == "torque":
        m.add_torque("motor", "disk", [0, 0, f"{T0}*(1 - WZ(disk)/{W0})"])
    else:
        m.add_joint_force("motor", "pin", f"T0_*(1 - pin_dot/{W0})".replace("T0_", str(T0)))
    return m


def _run(m, path, end, step, monkeypatch, rtol=1e-11):
    if path == "absolute":
        monkeypatch.setattr(compiled, "USE_TREE", False)
    method = "rk45" if path == "reference" else None
    res = mb.simulate(m, end, output_step=step, method=method, rtol=rtol)
    if path == "tree":
        assert res.stats["formulation"].startswith("joint coordinates"), res.stats
    elif path == "absolute":
        assert "joint coordinates" not in res.stats.get("formulation", "")
    return res


@pytest.mark.parametrize("how", ["torque", "joint_force"])
@pytest.mark.parametrize("path", ["tree", "absolute", "reference"])
def test_disk_motor_torque_speed_line(how, path, monkeypatch):
    """I dw/dt = T0 (1 - w/w0): w(t) = w0 (1 - exp(-T0 t / (I w0)))."""
    res = _run(_disk(how), path, 1.5, 0.05, monkeypatch)
    w = res.angular_velocity("disk")[:, 2]
    ref = W0 * (1 - np.exp(-T0 * res.time / (I_DISK * W0)))
    assert np.abs(w - ref).max() < 1e-9


def _pendulum(load, c=0.3, k=0.0, w0=0.0):
    m = mb.Model(gravity=(0, -9.81, 0))
    m.add_body("rod", mass=1.2, inertia=(0.01, 0.1, 0.1), position=(0.5, 0, 0), angular_velocity=(0, 0, w0))
    m.add_revolute("pin", "ground", "rod", (0, 0, 0), (0, 0, 1))
    if load == "element":
        m.add_torsion_spring("damper", "pin", k, c)
    elif load == "torque":
        m.add_torque("damper", "rod", [0, 0, f"-{c}*WZ(rod)"])
    else:
        m.add_joint_force("damper", "pin", f"-{k}*pin - {c}*pin_dot")
    return m


def _reference(m, monkeypatch, **kw):
    """The run of the event-driven reference path (the torsion spring element, independent of the
    compiled joint torque it is packed as on the compiled paths)."""
    from mbdsim.solvers import dynamic
    with monkeypatch.context() as mp:
        mp.setattr(dynamic, "USE_COMPILED", False)
        res = mb.simulate(m, 1.0, output_step=0.05, method="dop853", rtol=1e-12, **kw)
    assert "(compiled)" not in res.stats["method"]
    return res


@pytest.mark.parametrize("load,path", [("torque", "tree"), ("torque", "absolute"), ("joint", "tree"),
                                       ("joint", "absolute")])
def test_pendulum_damper_against_torsion_damper(load, path, monkeypatch):
    ref = _reference(_pendulum("element"), monkeypatch)
    res = _run(_pendulum(load), path, 1.0, 0.05, monkeypatch, rtol=1e-12)
    assert np.abs(res.joint_coordinate("pin") - ref.joint_coordinate("pin")).max() < 1e-9
    assert np.abs(res.joint_velocity("pin") - ref.joint_velocity("pin")).max() < 1e-9


@pytest.mark.parametrize("path", ["tree", "absolute"])
def test_joint_angle_expression_through_several_turns(path, monkeypatch):
    if path == "absolute":   # the angle read in absolute coordinates: the event-driven reference DOP853
        monkeypatch.setattr(compiled, "USE_TREE", False)
    """-k*pin - c*pin_dot against the torsion spring, spinning several turns: the angle read by the load is
    continued beyond +-pi (tree: the state itself; absolute: events on the reference path)."""
    ref = _reference(_pendulum("element", c=0.05, k=0.4, w0=25.0), monkeypatch)
    res = mb.simulate(_pendulum("joint", c=0.05, k=0.4, w0=25.0), 1.0, output_step=0.05, method="dop853",
                      rtol=1e-12)
    assert ("joint coordinates" in res.stats.get("formulation", "")) == (path == "tree"), res.stats
    assert abs(ref.joint_coordinate("pin")).max() > 4 * np.pi
    assert np.abs(res.joint_coordinate("pin") - ref.joint_coordinate("pin")).max() < 1e-8


def _spring_model(kind, k=40.0, c=0.7, L0=0.8):
    m = mb.Model(gravity=(0, 0, -9.81))
    m.ground.add_marker("anchor", (0.0, 0.0, 0.0))
    b = m.add_body("ball", mass=1.5, inertia=(0.02, 0.03, 0.04), position=(0.3, 0.1, -1.0),
                   velocity=(0.0, 0.6, 0.2), angular_velocity=(0.5, -0.2, 0.3))
    b.add_marker("hook", (0.32, 0.1, -0.9))
    if kind == "element":
        m.add_spring_damper("s", b.markers["hook"], m.ground.markers["anchor"], k, c, L0)
    else:
        m.add_line_force("s", b.markers["hook"], m.ground.markers["anchor"],
                         f"{k}*(DM(ball.hook, ground.anchor) - {L0}) + {c}*VR(ball.hook, ground.anchor)")
    return m


@pytest.mark.parametrize("method", [None, "rk45"])
def test_line_force_against_spring_damper(method):
    kw = dict(output_step=0.05, rtol=1e-12 if method is None else 1e-10)
    ref = mb.simulate(_spring_model("element"), 1.0, method=method, **kw)
    res = mb.simulate(_spring_model("expr"), 1.0, method=method, **kw)
    assert "auto: DOP853" in res.stats["method"] or method
    assert np.abs(res.position("ball") - ref.position("ball")).max() < 1e-9
    assert np.abs(res.angular_velocity("ball") - ref.angular_velocity("ball")).max() < 1e-9


def _drop(kind, R=0.1, k=1e5, e=1.5, c=40.0, d=1e-3):
    m = mb.Model(gravity=(0, 0, -9.81))
    ball = m.add_body("ball", mass=0.5, inertia=(1e-3, 1e-3, 1e-3), position=(0, 0, 0.3))
    m.add_translational("slide", "ground", "ball", (0, 0, 0.3), (0, 0, 1))
    if kind == "element":
        m.add_contact("c", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), mb.Sphere(ball, R), k, e, c, d)
    else:
        m.add_force("c", ball, [0, 0, f"IMPACT(DZ(ball), VZ(ball), {R}, {k}, {e}, {c}, {d})"])
    return m


def test_impact_load_against_contact_element():
    ref = mb.simulate(_drop("element"), 0.6, output_step=0.01, method="dop853", rtol=1e-11)
    res = mb.simulate(_drop("expr"), 0.6, output_step=0.01, rtol=1e-11)
    z, zr = res.position("ball")[:, 2], ref.position("ball")[:, 2]
    assert zr.min() < 0.1 and np.any(np.diff(np.sign(np.diff(zr))) > 0)    # it bounced
    assert np.abs(z - zr).max() < 1e-7
