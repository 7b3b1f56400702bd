"""The compiled Radau IIA (mbdsim.solvers.fastradau, radau_run): method "radau" on models the compiled
kernels carry, and the automatic method's hand-over to it when DOP853 detects stiffness. Checked against
closed forms (the modal solution of a two-mass chain, an overdamped spring-damper) and an independent
ODE solve (scipy's DOP853 at rtol 1e-12 on the pendulum's own equation), constraint residuals and the
energy balance of a closed loop."""
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import eigh

import mbdsim as mb

G = 9.81
RADAU = "Radau IIA (compiled)"


def chain(k1, k2, x0, m1=1.0, m2=2.0):
    """ground -k1- m1 -k2- m2 along x on translational joints; the springs' free lengths put the static
    equilibrium at x = (1, 2) m; the masses start displaced by x0 [m] from it, at rest."""
    m = mb.Model("two-mass chain", gravity=(0, 0, 0))
    p1 = m.add_particle("p1", m1, position=(1.0 + x0[0], 0, 0))
    p2 = m.add_particle("p2", m2, position=(2.0 + x0[1], 0, 0))
    m.add_translational("s1", m.ground, p1, (1.0, 0, 0), (1, 0, 0))
    m.add_translational("s2", m.ground, p2, (2.0, 0, 0), (1, 0, 0))
    m.add_spring_damper("k1", m.ground, p1, k1, 0.0, 1.0)
    m.add_spring_damper("k2", p1, p2, k2, 0.0, 1.0)
    return m, p1, p2, np.diag([m1, m2]), np.array([[k1 + k2, -k2], [-k2, k2]])


def simulate_quietly(*args, **kw):
    """simulate with AccuracyWarning an error (the tolerance must be met, not warned about)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", mb.AccuracyWarning)
        warnings.simplefilter("ignore", mb.MonitorWarning)
        return mb.simulate(*args, **kw)


@pytest.mark.parametrize("k2, shape", [(1e6, "equal"), (1e10, "slow mode")])
def test_stiff_two_mass_chain_hands_over_to_compiled_radau_and_keeps_the_slow_mode(k2, shape):
    """k2 = 1e4 k1 (both masses displaced alike: the fast mode is excited at 1e-4 of the slow one and
    resolved) and 1e10 N/m (released on the slow mode's shape): the default method detects stiffness,
    continues with the compiled Radau IIA and matches the exact modal solution on the slow mode to 1e-6."""
    k1, d = 100.0, 0.01
    M, K = np.diag([1.0, 2.0]), np.array([[k1 + k2, -k2], [-k2, k2]])
    w2, V = eigh(K, M)   # M-orthonormal modes, slow first
    x0 = np.array([d, d]) if shape == "equal" else d * V[:, 0] / V[0, 0]
    m, p1, p2, _, _ = chain(k1, k2, x0)
    T = 0.5 if k2 < 1e8 else 0.3
    res = simulate_quietly(m, T, output_step=T / 100)
    st = res.stats
    assert res.success and "stiffness detected" in st["method"] and f"then {RADAU}" in st["method"]
    hist = [h[1:] for h in st["order_history"]]
    assert hist[0][0] == "DOP853 (compiled)" and hist[1] == ("Radau", 5)
    if shape == "equal":   # the fast mode excited above the tolerance: Radau's trial needs more evaluations
        assert hist[-1] == ("DOP853 (compiled)", 8) and "without the stiffness test" in st["method"]   # than DOP853
    else:
        assert hist[-1] == ("Radau", 5)
    assert st["rtol_reached"] == 1e-7 and st["njev"] >= 1 and st["nlu"] >= 2
    x = np.stack([res.position(p1)[:, 0] - 1.0, res.position(p2)[:, 0] - 2.0], 1)
    eta0 = V.T @ M @ x0
    slow = x @ M @ V[:, 0]
    exact = eta0[0] * np.cos(np.sqrt(w2[0]) * res.time)
    assert np.max(np.abs(slow - exact)) < 1e-6 * abs(eta0[0])
    # dense output between the samples after the switch: the same closed form
    tq = np.linspace(st["switch_time"], T, 37)[1:]
    a = res.at(tq)
    xa = np.stack([a.position(p1)[:, 0] - 1.0, a.position(p2)[:, 0] - 2.0], 1)
    assert np.max(np.abs(xa @ M @ V[:, 0] - eta0[0] * np.cos(np.sqrt(w2[0]) * tq))) < 1e-6 * abs(eta0[0])


def test_radau_on_a_pendulum_tree_matches_an_independent_ode_solve():
    """A uniform rod (1 kg, 1 m) on a revolute joint released at 1 rad: theta'' = -(3 g / 2 L) sin theta,
    solved by scipy's DOP853 at rtol 1e-12, against method='radau' (joint coordinates, compiled)."""
    L, th0 = 1.0, 1.0
    m = mb.Model("pendulum", gravity=(0, -G, 0))
    c, s = np.cos(th0), np.sin(th0)
    R = np.array([[s, c, 0], [-c, s, 0], [0, 0, 1]])
    rod = m.add_body("rod", 1.0, (1e-4, L * L / 12, L * L / 12), position=(0.5 * L * s, -0.5 * L * c, 0), orientation=R)
    m.add_revolute("hinge", m.ground, rod, (0, 0, 0), (0, 0, 1))
    res = mb.simulate(m, 2.0, output_step=0.01, method="radau")
    assert res.success and res.stats["method"] == RADAU and res.stats["formulation"].startswith("joint")
    assert res.stats["order_history"] == [(0.0, "Radau", 5)]
    ref = solve_ivp(lambda t, y: [y[1], -1.5 * G / L * np.sin(y[0])], (0, 2.0), [th0, 0.0], method="DOP853",
                    rtol=1e-12, atol=1e-14, t_eval=res.time)
    r = res.position(rod)
    theta = np.arctan2(r[:, 0], -r[:, 1])
    assert np.max(np.abs(theta - ref.y[0])) < 1e-6 * th0
    tq = np.array([0.123, 0.777, 1.5055])   # dense output (collocation polynomial) between samples
    ra = res.at(tq).position(rod)
    ya = solve_ivp(lambda t, y: [y[1], -1.5 * G / L * np.sin(y[0])], (0, 2.0), [th0, 0.0], method="DOP853",
                   rtol=1e-12, atol=1e-14, t_eval=tq).y[0]
    assert np.max(np.abs(np.arctan2(ra[:, 0], -ra[:, 1]) - ya)) < 1e-6 * th0


def test_stiff_four_bar_stays_on_its_constraints_and_balances_energy():
    """A planar four-bar (a closed loop: absolute coordinates, projected) whose coupler is held by a
    damped 1e9 N/m spring from the rocker's tip to ground (method='radau'): constraint residual at round-off at every output, and the energy balance
    T + V + dissipated = E(0) to 1e-6 of E(0)."""
    m = mb.Model("fourbar", gravity=(0.0, -G, 0.0))
    crank = m.add_body("crank", 1.0, inertia=(0.1, 0.1, 0.1), position=(0.0, 0.5, 0.0))
    coupler = m.add_body("coupler", 1.0, inertia=(0.1, 0.1, 0.1), position=(1.0, 1.0, 0.0))
    rocker = m.add_body("rocker", 1.0, inertia=(0.1, 0.1, 0.1), position=(2.0, 0.5, 0.0))
    m.add_revolute("A", m.ground, crank, (0, 0, 0), (0, 0, 1), initial_velocity=3.0)
    m.add_revolute("B", crank, coupler, (0, 1, 0), (0, 0, 1))
    m.add_revolute("C", coupler, rocker, (2, 1, 0), (0, 0, 1))
    m.add_revolute("D", rocker, m.ground, (2, 0, 0), (0, 0, 1))
    m.add_spring_damper("k", (rocker, (2.0, 1.0, 0)), (m.ground, (3.0, 1.0, 0)), stiffness=1e9, damping=3e4,
                        free_length=1.0)
    res = simulate_quietly(m, 0.1, output_step=1e-3, method="radau")
    assert res.success and res.stats["formulation"].startswith("absolute")
    assert res.stats["method"] == RADAU
    from mbdsim.system.equations import constraint_terms
    sys = res.system
    for k in range(0, len(res.time), 10):
        phi, J, nu, _ = constraint_terms(sys, res.q[k], res.v[k], res.time[k])
        assert np.max(np.abs(phi)) < 1e-11 and np.max(np.abs(J @ res.v[k] - nu)) < 1e-9
    E = res.kinetic_energy() + res.potential_energy()
    D = res.dissipated_energy()
    assert D[-1] > 0 and np.max(np.abs(E + D - E[0])) < 1e-6 * E[0]


@pytest.mark.parametrize("method", [None, "radau"])
def test_overdamped_stiff_spring_matches_its_closed_form(method):
    """1 kg on a slider, spring 1e9 N/m with 1e5 N s/m (eigenvalues -1.01e4 and -9.9e4 1/s) under gravity
    -x, starting at the spring's free length: x(t) = 1 - g / k + a e^(r1 t) + (u0 - a) e^(r2 t)."""
    k, c = 1e9, 1e5
    m = mb.Model("spring 1e9", gravity=(-G, 0, 0))
    p = m.add_particle("p", 1.0, position=(1.0, 0, 0))
    m.add_translational("slide", m.ground, p, (1.0, 0, 0), (1, 0, 0))
    m.add_spring_damper("k", m.ground, p, k, c, 1.0)
    res = simulate_quietly(m, 0.01, output_step=1e-4, method=method)
    assert res.success and RADAU in res.stats["method"]
    r1, r2 = (-c + np.sqrt(c * c - 4 * k)) / 2, (-c - np.sqrt(c * c - 4 * k)) / 2
    u0 = G / k
    a = -r2 * u0 / (r1 - r2)
    x = 1.0 - G / k + a * np.exp(r1 * res.time) + (u0 - a) * np.exp(r2 * res.time)
    assert np.max(np.abs(res.position(p)[:, 0] - x)) < 1e-3 * u0
