"""Point-on-curve (path) constraint: Jacobian and gamma against finite differences, conservation laws
(energy, angular momentum) and a closed-form reaction; curves; bad input."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mbdsim as mb
from mbdsim.solvers.common import increment
from mbdsim.system.assemble import assemble_system
from mbdsim.system.equations import constraint_terms

G = 9.81


def helix(s):
    return np.array([0.4 * np.cos(s), 0.3 * np.sin(s), 0.2 * s])


def track(s):
    return np.array([s, 0.3 * np.sin(2 * s), 0.5 * np.cos(s)])


# ----------------------------------------------------------------------------- curves
def test_curve_derivatives_complex_step_and_richardson():
    exact1 = lambda s: np.array([-0.4 * np.sin(s), 0.3 * np.cos(s), 0.2])  # noqa: E731
    exact2 = lambda s: np.array([-0.4 * np.cos(s), -0.3 * np.sin(s), 0.0])  # noqa: E731
    cs = mb.Curve(helix, (0, 6))                     # numpy callable: complex step
    no_complex = mb.Curve(lambda s: [0.4 * math.cos(s), 0.3 * math.sin(s), 0.2 * s], (0, 6))  # math: Richardson
    given = mb.Curve(helix, (0, 6), d1=exact1, d2=exact2)
    for s in (0.3, 2.0, 5.1):
        for c, tol1, tol2 in ((cs, 1e-14, 1e-9), (no_complex, 1e-9, 1e-8), (given, 0, 0)):
            C, C1, C2 = c.derivatives(s)
            assert np.allclose(C, helix(s), atol=1e-15)
            assert np.allclose(C1, exact1(s), atol=tol1 + 1e-16)
            assert np.allclose(C2, exact2(s), atol=tol2 + 1e-16)


def test_spline_interpolates_and_is_c2():
    ss = np.linspace(0, 6, 40)
    sp = mb.Spline([helix(s) for s in ss])
    u = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff([helix(s) for s in ss], axis=0), axis=1))])
    for k in (0, 7, 39):
        assert np.allclose(sp.point(u[k]), helix(ss[k]), atol=1e-14)
    for uk in u[1:-1:5]:   # second derivative continuous at the knots
        assert np.allclose(sp.derivatives(uk - 1e-9)[2], sp.derivatives(uk + 1e-9)[2], atol=1e-6)
    ring = mb.Spline([(np.cos(a), np.sin(a), 0) for a in np.linspace(0, 2 * np.pi, 12, endpoint=False)], closed=True)
    L = ring.s_range[1]
    for k in range(3):
        assert np.allclose(ring.derivatives(0.3)[k], ring.derivatives(0.3 + L)[k], atol=1e-12)


# ----------------------------------------------------------------------------- equations
def _moving_model(curve):
    """Rigid curve body and rigid marker body, both rotated and spinning."""
    m = mb.Model("fd")
    plate = m.add_body("plate", 2.0, (0.1, 0.2, 0.3), position=(0.1, 0.2, 0.3),
                       orientation=Rotation.from_rotvec([0.3, -0.5, 0.7]), angular_velocity=(0.4, -1.1, 0.8))
    P = curve.point(0.7)
    rider = m.add_body("rider", 1.0, (0.1, 0.1, 0.1), position=P + (0.05, -0.02, 0.03),
                       orientation=Rotation.from_rotvec([-0.2, 0.4, 0.1]), velocity=(0.3, 0.1, -0.2),
                       angular_velocity=(1.2, 0.3, -0.6))
    m.add_point_on_curve("path", rider.add_marker("pin", point=P), plate, curve)
    return m


@pytest.mark.parametrize("curve", [mb.Curve(helix, (-3, 9)), mb.Spline([helix(s) for s in np.linspace(-3, 9, 50)])],
                         ids=["curve", "spline"])
def test_jacobian_and_gamma_against_finite_differences(curve):
    sys = assemble_system(_moving_model(curve))
    rng = np.random.default_rng(3)
    q = increment(sys, sys.q0, 0.05 * rng.standard_normal(sys.nv))
    v = rng.standard_normal(sys.nv)
    phi0, J, nu, gamma = constraint_terms(sys, q, v, 0.0)
    assert np.all(nu == 0)
    f = lambda x: constraint_terms(sys, increment(sys, q, x), v, 0.0, jacobian=False)[0]  # noqa: E731
    h = 1e-6
    J_fd = np.column_stack([(f(h * e) - f(-h * e)) / (2 * h) for e in np.eye(sys.nv)])
    assert np.allclose(J, J_fd, atol=1e-8)
    assert J[:, sys.aux_v_idx].any()
    # flow q(t) = q (+) t v with constant v: phi_dd = -gamma (vd = 0)
    h = 1e-3
    d2 = (-f(2 * h * v) + 16 * f(h * v) - 30 * phi0 + 16 * f(-h * v) - f(-2 * h * v)) / (12 * h * h)
    assert np.allclose(d2, -gamma, atol=1e-7 * (1 + np.abs(gamma).max()))


# ----------------------------------------------------------------------------- dynamics
def _bead_on_track(curve, s0=0.2):
    m = mb.Model("track", gravity=(0, 0, -G))
    bead = m.add_particle("bead", 0.5, position=track(s0))
    m.add_point_on_curve("path", bead.add_marker("c"), m.ground, curve)
    return m, bead


@pytest.mark.parametrize("curve", [mb.Curve(track, (-1, 8)),
                                   mb.Spline([track(s) for s in np.linspace(-1, 8, 80)])], ids=["curve", "spline"])
def test_particle_on_track_speed_from_energy(curve):
    m, bead = _bead_on_track(curve)
    res = mb.simulate(m, 3.0, output_step=0.05, method="dop853")
    assert res.success, res.message
    z0 = res.position(bead)[0, 2]
    at = res.at([0.6, 1.45, 2.3])
    v = np.linalg.norm(at.velocity(bead), axis=1)
    v_energy = np.sqrt(2 * G * (z0 - at.position(bead)[:, 2]))
    assert np.all(v_energy > 0.5)
    assert np.allclose(v, v_energy, rtol=1e-6, atol=0)
    # the bead is on the curve at its parameter s
    s = at.q[:, sys_aux(res)]
    assert np.allclose([curve.point(x) for x in s], at.position(bead), atol=1e-10)


def sys_aux(res):
    return res.system.aux_q_idx[0]


def test_bead_on_spinning_wheel_conserves_energy_and_angular_momentum():
    Izz, m_b, w0 = 0.2, 0.3, 3.0
    spiral = mb.Curve(lambda s: (0.1 + 0.1 * s) * np.array([np.cos(s), np.sin(s), 0.0]), (0, 8))
    m = mb.Model("wheel")
    wheel = m.add_body("wheel", 2.0, (0.1, 0.1, Izz), angular_velocity=(0, 0, w0))
    m.add_revolute("axle", m.ground, wheel, (0, 0, 0), (0, 0, 1))
    P = spiral.point(0.5)
    bead = m.add_particle("bead", m_b, position=P, velocity=np.cross([0, 0, w0], P))
    m.add_point_on_curve("path", bead.add_marker("c"), wheel, spiral)
    res = mb.simulate(m, 1.5, output_step=0.01, method="dop853")
    assert res.success, res.message
    s = res.q[:, res.system.aux_q_idx[0]]
    assert s[-1] > 1.0                      # the bead really slides outwards along the curve
    T = res.kinetic_energy()
    r, v = res.position(bead), res.velocity(bead)
    Lz = Izz * res.angular_velocity(wheel)[:, 2] + m_b * np.cross(r, v)[:, 2]
    assert np.max(np.abs(T - T[0])) < 1e-8 * T[0]
    assert np.max(np.abs(Lz - Lz[0])) < 1e-8 * abs(Lz[0])


def test_bead_on_vertical_circle_reaction_force():
    R, mass, th0 = 0.8, 0.4, 1.0
    circle = mb.Curve(lambda s: R * np.array([np.sin(s), -np.cos(s), 0.0]), (-np.pi, np.pi))
    m = mb.Model("loop", gravity=(0, -G, 0))
    bead = m.add_particle("bead", mass, position=circle.point(th0))
    m.add_point_on_curve("ring", bead.add_marker("c"), m.ground, circle)
    res = mb.simulate(m, 2.0, output_step=0.01, method="dop853")
    assert res.success, res.message
    cos_th = -res.position(bead)[:, 1] / R
    F = res.reaction_force("ring")
    assert np.allclose(np.linalg.norm(F, axis=1), mass * G * (3 * cos_th - 2 * np.cos(th0)), atol=1e-8)
    assert np.allclose(np.cross(F, res.position(bead))[:, 2], 0, atol=1e-8)   # radial


def test_bead_laps_a_closed_spline_ring():
    """No gravity: the speed stays constant and s runs over several periods of the closed spline."""
    ring = mb.Spline([(np.cos(a), 0.6 * np.sin(a), 0.1 * np.sin(3 * a))
                      for a in np.linspace(0, 2 * np.pi, 24, endpoint=False)], closed=True)
    P, C1 = ring.point(0.0), ring.derivatives(0.0)[1]
    m = mb.Model("ring")
    bead = m.add_particle("bead", 0.2, position=P, velocity=3.0 * C1 / np.linalg.norm(C1))
    m.add_point_on_curve("ring", bead.add_marker("c"), m.ground, ring)
    res = mb.simulate(m, 5.0, output_step=0.05, method="dop853")
    assert res.success, res.message
    assert res.q[-1, res.system.aux_q_idx[0]] > 2.5 * ring.s_range[1]
    assert np.allclose(np.linalg.norm(res.velocity(bead), axis=1), 3.0, rtol=1e-8)


# ----------------------------------------------------------------------------- bad input
def test_bad_input_names_entity_and_field():
    m = mb.Model("bad")
    b = m.add_body("b", 1.0, (1, 1, 1))
    p = m.add_particle("p", 1.0)
    c = mb.Curve(helix, (0, 6))
    cases = [
        (lambda: m.add_point_on_curve("x", p.add_marker("a"), m.ground, "curve"), "curve"),
        (lambda: m.add_point_on_curve("x", p.add_marker("b2"), p, c), "body"),
        (lambda: m.add_point_on_curve("x", b.add_marker("m"), b, c), "body"),
        (lambda: m.add_point_on_curve("x", 42, m.ground, c), "marker"),
        (lambda: m.add_point_on_curve("x", (p, (0, 0, 0)), "nobody", c), "body"),
        (lambda: mb.Curve(3, (0, 1)), "function"),
        (lambda: mb.Curve(helix, (1, 0)), "s_range"),
        (lambda: mb.Curve(helix, "ab"), "s_range"),
        (lambda: mb.Curve(lambda s: (s, s), (0, 1)), "function"),
        (lambda: mb.Curve(helix, (0, 1), d1=lambda s: np.zeros(3)), "d1"),
        (lambda: mb.Spline([(0, 0, 0), (1, 0, 0)]), "points"),
        (lambda: mb.Spline([(0, 0, 0), (1, 0, 0), (1, 0, 0), (2, 0, 0)]), "points"),
        (lambda: mb.Spline([(0, 0), (1, 0), (2, 1)]), "points"),
    ]
    for make, field in cases:
        with pytest.raises(mb.ModelError) as err:
            make()
        assert err.value.field == field, (err.value, field)
    m.add_point_on_curve("ok", p.add_marker("c"), m.ground, c)
    with pytest.raises(mb.ModelError) as err:
        m.add_point_on_curve("ok", p.add_marker("d"), m.ground, c)
    assert err.value.field == "name" and "ok" in err.value.entity
