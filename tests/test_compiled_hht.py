"""The compiled HHT-alpha (method "hht", mbdsim.solvers.fasthht): closed forms, the reference HHT, a loop."""
from __future__ import annotations

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.solvers import hht


def _oscillator(k=400.0, m=2.0, x0=0.05):
    """A block on a translational joint along x with a spring to ground: x(t) = x0 cos(sqrt(k/m) t)."""
    model = mb.Model("oscillator", gravity=(0.0, 0.0, 0.0))
    block = model.add_body("block", m, inertia=(0.1, 0.1, 0.1), position=(x0, 0.0, 0.0))
    model.add_translational("slide", "ground", block, (0, 0, 0), (1, 0, 0))
    model.add_spring_damper("spring", ("ground", (0.0, 0.0, 0.0)), (block, (x0, 0.0, 0.0)), stiffness=k,
                            free_length=0.0)
    return model, block


def _two_mass(k1=100.0, ratio=1e4, m=1.0):
    """Two blocks in series on x, the second spring `ratio` times stiffer: released from the slow mode."""
    k2 = ratio * k1
    model = mb.Model("chain", gravity=(0.0, 0.0, 0.0))
    # slow mode: x2 = x1 (1 + m w^2 / k2)^-1 ..., start with x1 = x2 = 0.01 (the stiff spring unstretched)
    b1 = model.add_body("b1", m, inertia=(0.1, 0.1, 0.1), position=(1.01, 0.0, 0.0))
    b2 = model.add_body("b2", m, inertia=(0.1, 0.1, 0.1), position=(2.01, 0.0, 0.0))
    model.add_translational("s1", "ground", b1, (1.0, 0, 0), (1, 0, 0))
    model.add_translational("s2", "ground", b2, (2.0, 0, 0), (1, 0, 0))
    model.add_spring_damper("k1", ("ground", (0.0, 0.0, 0.0)), (b1, (1.01, 0.0, 0.0)), stiffness=k1, free_length=1.0)
    model.add_spring_damper("k2", (b1, (1.01, 0.0, 0.0)), (b2, (2.01, 0.0, 0.0)), stiffness=k2, free_length=1.0)
    return model, b1, b2, k1, k2, m


def test_oscillator_against_closed_form_and_reference():
    model, block = _oscillator()
    w = np.sqrt(400.0 / 2.0)
    res = mb.simulate(model, 1.0, 0.01, method="hht", rtol=1e-6)
    assert res.success
    assert "compiled" in res.stats["method"] and "HHT" in res.stats["method"]
    x = res.position(block)[:, 0]
    exact = 0.05 * np.cos(w * res.time)
    err = np.max(np.abs(x - exact)) / 0.05
    assert err < 2e-3, err
    tighter = mb.simulate(model, 1.0, 0.01, method="hht", rtol=1e-8)
    err2 = np.max(np.abs(tighter.position(block)[:, 0] - exact)) / 0.05
    assert err2 < err / 5, (err, err2)        # the error falls with the tolerance (second order)
    assert tighter.stats["steps"] > res.stats["steps"]


def test_numerical_damping_of_hht_alpha():
    """HHT-alpha's spectral radius: an undamped oscillator stepped at h w ~ 1 loses amplitude, at rate
    close to the method's (alpha = -0.05), while a resolved one keeps it."""
    model, block = _oscillator(k=2e6, m=2.0, x0=1e-3)
    res = mb.simulate(model, 0.05, 0.001, method="hht", rtol=1e-3)
    assert res.success
    amp_end = np.max(np.abs(res.position(block)[-10:, 0]))
    assert amp_end < 1e-3 * 1.001   # never grows (unconditional stability)


def test_stiff_chain_slow_mode():
    """Stiff spring 1e4 x the soft one, released on the slow mode: its motion against the two-mass closed
    form."""
    model, b1, b2, k1, k2, m = _two_mass()
    # eigenfrequencies of [[k1 + k2, -k2], [-k2, k2]] / m
    K = np.array([[k1 + k2, -k2], [-k2, k2]]) / m
    lam, vec = np.linalg.eigh(K)
    ws, wf = np.sqrt(lam)
    # start on the slow mode shape exactly
    mode = vec[:, 0] / vec[0, 0] * 0.01
    model2 = mb.Model("chain", gravity=(0.0, 0.0, 0.0))
    c1 = model2.add_body("b1", m, inertia=(0.1, 0.1, 0.1), position=(1.0 + mode[0], 0.0, 0.0))
    c2 = model2.add_body("b2", m, inertia=(0.1, 0.1, 0.1), position=(2.0 + mode[1], 0.0, 0.0))
    model2.add_translational("s1", "ground", c1, (1.0, 0, 0), (1, 0, 0))
    model2.add_translational("s2", "ground", c2, (2.0, 0, 0), (1, 0, 0))
    model2.add_spring_damper("k1", ("ground", (0.0, 0.0, 0.0)), (c1, (1.0 + mode[0], 0.0, 0.0)), stiffness=k1,
                             free_length=1.0)
    model2.add_spring_damper("k2", (c1, (1.0 + mode[0], 0.0, 0.0)), (c2, (2.0 + mode[1], 0.0, 0.0)),
                             stiffness=k2, free_length=1.0)
    T = 2 * np.pi / ws
    res = mb.simulate(model2, T, T / 50, method="hht", rtol=1e-6)
    assert res.success and "compiled" in res.stats["method"]
    x1 = res.position(c1)[:, 0] - 1.0
    exact = mode[0] * np.cos(ws * res.time)
    assert np.max(np.abs(x1 - exact)) / abs(mode[0]) < 2e-3


def test_closed_loop_matches_dop853():
    """A planar four-bar (absolute coordinates, tree elimination with loop rows) against the compiled DOP853
    at a tight tolerance; the constraints hold at the outputs."""
    from mbdsim._warmup import _four_bar
    model = _four_bar(False)
    ref = mb.simulate(model, 0.5, 0.01, method="dop853", rtol=1e-11)
    res = mb.simulate(model, 0.5, 0.01, method="hht", rtol=1e-8)
    assert res.success and "compiled" in res.stats["method"]
    d = np.max(np.abs(res.joint_coordinate("O2") - ref.joint_coordinate("O2")))
    assert d < 1e-4, d
    E = res.kinetic_energy() + res.potential_energy()   # no damping: energy is conserved
    scale = np.max(np.abs(res.kinetic_energy())) + np.ptp(res.potential_energy())
    assert np.max(np.abs(E - E[0])) < 1e-4 * scale
    assert np.all(np.isfinite(res.reaction_force("B")))


def test_reference_hht_agrees():
    """The compiled run and the reference (Python) HHT integrate the same method: same answer within the
    tolerance."""
    from mbdsim.solvers.assembly import assemble_state
    from mbdsim.system.assemble import assemble_system
    model, block = _oscillator()
    sys = assemble_system(model)
    rep = assemble_state(sys, sys.q0, sys.v0, 0.0)
    times = np.linspace(0.0, 0.5, 51)
    ref = hht.integrate_hht(sys, rep, times, 1e-7, 1e-9, None)
    res = mb.simulate(model, 0.5, 0.01, method="hht", rtol=1e-7)
    d = np.max(np.abs(res.position(block)[:, 0] - ref.position(block)[:, 0]))
    assert d < 1e-4 * 0.05, d   # two second-order runs at rtol 1e-7: within the tolerance's order


def test_dense_output_between_outputs():
    """Result.at between outputs: the run's own Hermite interpolant, projected."""
    model, block = _oscillator()
    w = np.sqrt(200.0)
    res = mb.simulate(model, 0.5, 0.1, method="hht", rtol=1e-9)
    x = res.at(0.2345).position(block)[0, 0]
    assert abs(x - 0.05 * np.cos(w * 0.2345)) < 1e-5 * 0.05 * 10


def test_pendulum_half_period_at_rtol_1e7():
    """A pendulum released horizontally: the time of its lowest swing against the elliptic-integral closed
    form, compiled."""
    from scipy.special import ellipk
    model = mb.Model("pendulum", gravity=(0.0, -9.81, 0.0))
    rod = model.add_body("rod", 2.0, inertia=(1e-4, 1.0 / 6.0, 1.0 / 6.0), position=(0.5, 0, 0))
    pin = model.add_revolute("pin", "ground", rod, (0, 0, 0), (0, 0, 1))
    w0 = np.sqrt(3 * 9.81 / 2)
    half_period = 2 / w0 * ellipk(0.5)
    res = mb.simulate(model, 1.2, 0.01, rtol=1e-7, atol=1e-7, method="hht")
    assert res.success and res.stats["method"] == "HHT (compiled)"
    t_min, th_min = res.minimum(lambda r: r.joint_coordinate(pin))
    assert abs(t_min - half_period) < 1e-4
    assert abs(th_min + np.pi) < 1e-5
    assert 1 <= res.stats["njev"] < res.stats["steps"] / 5   # tangents reused across steps


def test_compiled_hht_steps_never_turn_a_spinning_body_past_its_branch():
    """A shaft in a closed loop (revolute + coaxial cylindrical: absolute coordinates) spun up by a constant
    torque from -1 rad/s to ~74 rad/s: theta = w0 t + T t^2 / (2 J). Constant accelerations leave HHT's
    error estimate near zero; without a bound on the rotation per step it took 0.1 s steps (7 rad each)
    and ended 3 rad off."""
    import warnings
    J, T, w0 = 0.004, 0.2, -1.0
    m = mb.Model("shaft_loop", gravity=(0.0, 0.0, 0.0))
    s1 = m.add_body("s1", 1.0, inertia=(J, J, J))
    m.add_revolute("R1", m.ground, s1, (0, 0, 0), (0, 0, 1), initial_velocity=w0)
    m.add_cylindrical("C1", m.ground, s1, (0, 0, 0), (0, 0, 1))
    m.add_torque("T", "s1", (0.0, 0.0, T))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = mb.simulate(m, 1.5, 0.01, method="hht")
    assert res.success and res.stats["method"] == "HHT (compiled)"
    th = res.joint_coordinate("R1")
    assert th.max() > 50.0
    assert np.max(np.abs(th - (w0 * res.time + 0.5 * T / J * res.time**2))) < 1e-3
