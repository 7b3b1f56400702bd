"""Loads written as Python callables (t, state) run inside the compiled step loop (solvers.pyloads).

Each callable is checked against the same load written as an expression (which the compiled core
evaluates by itself): same motion to 1e-8, and the run must report the compiled stepper.
"""
import warnings

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.errors import EvaluationError
from mbdsim.solvers import dynamic

C_DRAG = 0.3


def _pendulum(torque):
    m = mb.Model("p", gravity=(0.0, -9.81, 0.0))
    rod = m.add_body("rod", 2.0, inertia=(0.01, 2 / 12, 2 / 12), position=(0.5, 0, 0))
    m.add_revolute("pin", m.ground, rod, (0, 0, 0), (0, 0, 1))
    m.add_torque("drag", rod, torque(rod))
    return m


def _run(model, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return mb.simulate(model, **{"end_time": 2.0, "output_step": 0.01, **kw})


def test_callable_torque_matches_the_expression_and_runs_compiled():
    expr = _run(_pendulum(lambda rod: (0, 0, f"-{C_DRAG}*WZ(rod)")))
    calls = []

    def drag(rod):
        def f(t, s):
            calls.append(t)
            return (0.0, 0.0, -C_DRAG * s.angular_velocity(rod)[2])
        return f
    call = _run(_pendulum(drag))
    assert call.success and "compiled" in call.stats["method"], call.stats["method"]
    assert len(calls) > 100
    assert np.max(np.abs(call.joint_coordinate("pin") - expr.joint_coordinate("pin"))) < 1e-8
    assert np.max(np.abs(call.reaction_force("pin") - expr.reaction_force("pin"))) < 1e-6


def test_callable_joint_force_and_point_force_in_a_closed_loop():
    """A four-bar (absolute coordinates, redundant revolutes) driven by a callable motor torque reading the
    joint rate, and a callable point force reading a marker's position, against the same loads as
    expressions."""
    def build(callables):
        m = mb.Model("fourbar", gravity=(0.0, -9.81, 0.0))
        A, B, D = np.array([0.2, 0.0, 0.0]), np.array([0.3, 0.4, 0.0]), np.array([0.6, 0.0, 0.0])
        crank = m.add_body("crank", 1.0, inertia=(1e-3, 1e-2, 1e-2), position=A / 2)
        coupler = m.add_body("coupler", 1.0, inertia=(1e-3, 2e-2, 2e-2), position=(A + B) / 2)
        rocker = m.add_body("rocker", 1.0, inertia=(1e-3, 2e-2, 2e-2), position=(B + D) / 2)
        tip = coupler.add_marker("tip", point=B)
        z = (0, 0, 1)
        pin = m.add_revolute("O", m.ground, crank, (0, 0, 0), z)
        m.add_revolute("A", crank, coupler, A, z)
        m.add_revolute("B", coupler, rocker, B, z)
        m.add_revolute("D", rocker, m.ground, D, z)
        if callables:
            m.add_joint_force("motor", pin, lambda t, s: 2.0 * (1.0 - s.joint_velocity(pin) / 5.0))
            m.add_force("push", tip, lambda t, s: (-20.0 * s.position(tip)[0], 0.0, 0.0))
        else:
            m.add_joint_force("motor", pin, "2*(1 - O_dot/5)")
            m.add_force("push", tip, ("-20*DX(coupler.tip)", 0, 0))
        return m
    a, b = _run(build(True), end_time=1.0), _run(build(False), end_time=1.0)
    assert a.success and "compiled" in a.stats["method"], a.stats["method"]
    for j in ("O", "B"):
        assert np.max(np.abs(a.joint_coordinate(j) - b.joint_coordinate(j))) < 1e-8, j


def test_callable_load_that_raises_ends_the_run_naming_it():
    def drag(rod):
        def f(t, s):
            if t > 0.5:
                raise RuntimeError("sensor offline")
            return (0.0, 0.0, -C_DRAG * s.angular_velocity(rod)[2])
        return f
    res = _run(_pendulum(drag))
    assert not res.success
    assert isinstance(res.error, EvaluationError)
    assert "drag" in str(res.error) and "sensor offline" in str(res.error)
    assert 0.4 < res.time[-1] <= 0.5 + 1e-12 and len(res.time) >= 40


@pytest.mark.parametrize("bad", [lambda t, s: (0.0, 0.0, float("nan")), lambda t, s: "three"])
def test_callable_load_with_a_bad_value_fails_cleanly(bad):
    res = _run(_pendulum(lambda rod: bad), end_time=0.2)
    assert not res.success and "drag" in str(res.error)


def test_callable_load_on_a_zero_dof_model_gives_the_reactions_of_the_expression():
    """A fully driven crank with a callable torque on it: the driver's effort must carry the torque."""
    def build(callable_):
        m = mb.Model("crank", gravity=(0.0, -9.81, 0.0))
        crank = m.add_body("crank", 1.0, inertia=(1e-3, 1e-2, 1e-2), position=(0.1, 0, 0))
        pin = m.add_revolute("O", m.ground, crank, (0, 0, 0), (0, 0, 1))
        m.add_motion("drive", pin, displacement="3*t")
        m.add_torque("load", crank, (lambda t, s: (0, 0, -0.5 * np.cos(t))) if callable_ else (0, 0, "-0.5*cos(t)"))
        return m
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a = mb.kinematics(build(True), end_time=1.0, output_step=0.05)
        b = mb.kinematics(build(False), end_time=1.0, output_step=0.05)
    assert a.success and b.success
    assert np.max(np.abs(a.reaction_torque("O") - b.reaction_torque("O"))) < 1e-9


def _crank_rocker(spring_on="O"):
    """Grashof crank-rocker in the x-y plane (crank 0.2 m turning fully, coupler 0.5, rocker 0.4, ground
    0.6), four revolutes (a closed loop in absolute coordinates), a torsion spring on joint `spring_on`
    and a stop on the rocker; the crank starts upright at 12 rad/s, so its angle passes +-pi."""
    O, D = np.zeros(3), np.array([0.6, 0.0, 0.0])
    A = np.array([0.0, 0.2, 0.0])
    d = np.linalg.norm(D - A)                       # B from |AB| = 0.5, |DB| = 0.4 (circle intersection)
    a = (0.5**2 - 0.4**2 + d**2) / (2 * d)
    h = np.sqrt(0.5**2 - a**2)
    u = (D - A) / d
    B = A + a * u + h * np.array([-u[1], u[0], 0.0])
    m = mb.Model("crank-rocker", gravity=(0.0, -9.81, 0.0))
    crank = m.add_body("crank", 1.0, inertia=(1e-4, 4e-3, 4e-3), position=(A + O) / 2)
    coupler = m.add_body("coupler", 1.0, inertia=(1e-4, 2e-2, 2e-2), position=(A + B) / 2)
    rocker = m.add_body("rocker", 1.0, inertia=(1e-4, 1.3e-2, 1.3e-2), position=(B + D) / 2)
    z = (0, 0, 1)
    m.add_revolute("O", m.ground, crank, O, z, initial_velocity=12.0)
    m.add_revolute("A", crank, coupler, A, z)
    m.add_revolute("B", coupler, rocker, B, z)
    m.add_revolute("D", m.ground, rocker, D, z)
    m.add_torsion_spring("spring", spring_on, stiffness=0.2, damping=0.002)
    return m


def test_torsion_spring_in_a_closed_loop_runs_compiled_past_pi():
    """The spring reads the crank angle of a loop (absolute coordinates): called back, its angle continued
    beyond +-pi by the callback; against the reference path (events re-anchor the angle there)."""
    fast = _run(_crank_rocker(), end_time=1.5, rtol=1e-9)
    assert fast.success and "compiled" in fast.stats["method"], fast.stats["method"]
    assert np.ptp(fast.joint_coordinate("O")) > 2 * np.pi     # at least one full turn
    dynamic.USE_COMPILED = False
    try:
        ref = _run(_crank_rocker(), end_time=1.5, method="dop853", rtol=1e-10)
    finally:
        dynamic.USE_COMPILED = True
    assert "compiled" not in ref.stats["method"]
    assert np.max(np.abs(fast.joint_coordinate("O") - ref.joint_coordinate("O"))) < 1e-6
    assert np.max(np.abs(fast.spring_force("spring") - ref.spring_force("spring"))) < 1e-6
