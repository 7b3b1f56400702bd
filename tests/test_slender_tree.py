"""Slender bodies (zero inertia about one axis) in joint coordinates: the compiled tree carries them.

The articulated-body pivot of a revolute is at least the child body's moment about the joint axis through
the joint point, so a rod with no axial inertia turning about a perpendicular axis integrates exactly;
closed forms and the absolute-coordinate reference path (dense augmented solve) are the checks.
"""
import warnings

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.solvers import dynamic

M, L, K = 2.0, 1.0, 5.0


def _rod(gravity=(0.0, 0.0, 0.0), w0=0.0):
    model = mb.Model("rod", gravity=gravity)
    rod = model.add_body("rod", M, inertia=(0.0, M * L**2 / 12, M * L**2 / 12), position=(L / 2, 0, 0))
    pin = model.add_revolute("pin", model.ground, rod, (0, 0, 0), (0, 0, 1), initial_velocity=w0)
    model.add_torsion_spring("spring", pin, stiffness=K)
    return model


def _simulate(model, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return mb.simulate(model, **kw)


def test_slender_rod_on_a_torsion_spring_is_harmonic_and_compiled():
    w0 = 0.7
    res = _simulate(_rod(w0=w0), end_time=3.0, output_step=0.01)
    assert res.success and "compiled" in res.stats["method"], res.stats["method"]
    omega = np.sqrt(K / (M * L**2 / 3))          # about the pin: I = m L^2 / 3
    theta = w0 / omega * np.sin(omega * res.time)
    assert np.max(np.abs(res.joint_coordinate("pin") - theta)) < 1e-6 * (w0 / omega)


def test_slender_double_pendulum_matches_the_reference_path():
    def model():
        m = mb.Model("dp", gravity=(0.0, -9.81, 0.0))
        a = m.add_body("a", 1.0, inertia=(0.0, 1 / 12, 1 / 12), position=(0.5, 0, 0))
        b = m.add_body("b", 0.5, inertia=(0.0, 0.5 / 12, 0.5 / 12), position=(1.5, 0, 0))
        m.add_revolute("p1", m.ground, a, (0, 0, 0), (0, 0, 1))
        p2 = m.add_revolute("p2", a, b, (1, 0, 0), (0, 0, 1))
        m.add_torsion_spring("s2", p2, stiffness=3.0, damping=0.05)
        return m
    fast = _simulate(model(), end_time=2.0, output_step=0.02, rtol=1e-10)
    assert "compiled" in fast.stats["method"], fast.stats["method"]
    dynamic.USE_COMPILED = False
    try:
        ref = _simulate(model(), end_time=2.0, output_step=0.02, method="dop853", rtol=1e-10)
    finally:
        dynamic.USE_COMPILED = True
    assert "compiled" not in ref.stats["method"]
    for j in ("p1", "p2"):
        assert np.max(np.abs(fast.joint_coordinate(j) - ref.joint_coordinate(j))) < 1e-7, j
    assert np.max(np.abs(fast.reaction_force("p1") - ref.reaction_force("p1"))) < 1e-5


def test_body_turning_about_its_own_zero_inertia_axis_stays_off_the_tree():
    """A rod spinning about its own axis (zero axial inertia) has a zero pivot: not a joint tree."""
    model = mb.Model("spin", gravity=(0.0, 0.0, 0.0))
    rod = model.add_body("rod", M, inertia=(0.0, 1.0, 1.0), position=(0, 0, 0))
    pin = model.add_revolute("pin", model.ground, rod, (0, 0, 0), (1, 0, 0))
    model.add_torsion_spring("spring", pin, stiffness=K)
    from mbdsim.system import jointtree
    from mbdsim.system.assemble import assemble_system
    sys = assemble_system(model)
    mode, _ = jointtree.tree_arrays(sys, np.arange(sys.nc), sys.q0, sys.v0)
    assert mode == 0


@pytest.mark.parametrize("inertia_x", [0.0, 0.01])
def test_tree_accelerations_and_reactions_see_the_continued_spring_angle(inertia_x):
    """A rod on a torsion spring swinging 5 rad either way (beyond +-pi), no gravity: theta = A sin(w t).
    The accelerations and the pin's reaction after the run (absolute coordinates) must see the spring's
    continuous angle: reaction = m a_cm, a_cm from theta, theta_dot, theta_ddot = -w^2 theta."""
    I_pin = M * L**2 / 3
    omega = np.sqrt(K / I_pin)
    amp = 5.0
    model = mb.Model("rod", gravity=(0.0, 0.0, 0.0))
    rod = model.add_body("rod", M, inertia=(inertia_x, M * L**2 / 12, M * L**2 / 12), position=(L / 2, 0, 0))
    pin = model.add_revolute("pin", model.ground, rod, (0, 0, 0), (0, 0, 1), initial_velocity=amp * omega)
    model.add_torsion_spring("spring", pin, stiffness=K)
    res = _simulate(model, end_time=2.0, output_step=0.01, rtol=1e-10)
    assert res.success and "compiled" in res.stats["method"], res.stats["method"]
    t = res.time
    th, thd, thdd = amp * np.sin(omega * t), amp * omega * np.cos(omega * t), -omega**2 * amp * np.sin(omega * t)
    assert np.max(np.abs(res.joint_coordinate("pin") - th)) < 1e-7 * amp
    c = L / 2
    a_cm = np.stack([c * (-thdd * np.sin(th) - thd**2 * np.cos(th)), c * (thdd * np.cos(th) - thd**2 * np.sin(th)),
                     0 * t], axis=1)
    scale = M * np.max(np.abs(a_cm))
    assert np.max(np.abs(res.acceleration(rod) - a_cm)) < 1e-6 * scale / M
    assert np.max(np.abs(np.asarray(res.reaction_force(pin)) - M * a_cm)) < 1e-6 * scale
    # between outputs (dense output of the run's own steps, or a short re-integration)
    tq = np.array([0.333, 1.777])
    s = res.at(tq)
    thq, thdq = amp * np.sin(omega * tq), amp * omega * np.cos(omega * tq)
    thddq = -omega**2 * thq
    aq = np.stack([c * (-thddq * np.sin(thq) - thdq**2 * np.cos(thq)),
                   c * (thddq * np.cos(thq) - thdq**2 * np.sin(thq)), 0 * tq], axis=1)
    assert np.max(np.abs(s.acceleration(rod) - aq)) < 1e-6 * scale / M
