"""Point-on-curve on the compiled core (issue 29): a bead on a helix (expression curve, spline, Python
callable) and on a straight spline against the closed form of uniform acceleration along the curve.

Closed form: a particle of mass m on a fixed curve C(s) with |C'| constant, gravity -g e_z and
C = (R cos s, R sin s, c s) (helix) has T = m (R^2 + c^2) sd^2 / 2, V = m g c s, so
sdd = -g c / (R^2 + c^2) (uniform angular acceleration) and z(t) = z0 + c (sd0 t + sdd t^2 / 2).
A straight line C = u s (|u| = 1): sdd = g_along = -g u_z.

`test_helix_default_settings_compiled` states the issue's contract (default settings, 'compiled' in
res.stats["method"], 1e-6 relative) for expression curves, splines and Python-callable curves (tabulated
to the run's tolerance as splines: system.pathtable), all run by solvers.pathcoord.
"""
from __future__ import annotations

import numpy as np
import pytest

import mbdsim as mb

G, R, C, SD0, T_END = 9.81, 0.3, 0.1, 2.0, 1.0
SDD = -G * C / (R ** 2 + C ** 2)
HELIX = ("0.3*cos(s)", "0.3*sin(s)", "0.1*s")


def helix(s):
    return np.array([R * np.cos(s), R * np.sin(s), C * s])


def bead_on(curve, s0=0.5):
    m = mb.Model("bead", gravity=(0, 0, -G))
    P, T = helix(s0), np.array([-R * np.sin(s0), R * np.cos(s0), C])
    bead = m.add_particle("bead", 0.2, position=P, velocity=SD0 * T)
    m.add_point_on_curve("path", bead.add_marker("c"), m.ground, curve)
    return m


def angle_error(res, s0=0.5):
    """Max |s(t) - closed form| / |s(T) - s0| with s = unwrapped atan2(y, x) of the bead."""
    p = res.position("bead")
    s = np.unwrap(np.arctan2(p[:, 1], p[:, 0]))
    s += s0 - s[0]
    ref = s0 + SD0 * res.time + 0.5 * SDD * res.time ** 2
    return float(np.max(np.abs(s - ref)) / abs(ref[-1] - s0))


def test_expression_curve_has_exact_derivatives():
    c = mb.Curve(HELIX, (-4, 3))
    for s in (0.1, 1.7, 4.0):
        X, X1, X2 = c.derivatives(s)
        assert np.allclose(X, helix(s), atol=1e-15)
        assert np.allclose(X1, [-R * np.sin(s), R * np.cos(s), C], atol=1e-15)
        assert np.allclose(X2, [-R * np.cos(s), -R * np.sin(s), 0], atol=1e-15)
    assert [e.text for e in c.expressions] == list(HELIX)


def test_expression_curve_bad_input_names_the_field():
    with pytest.raises(mb.ModelError, match=r"function\[y\]"):
        mb.Curve(("s", "sin(s", "0"), (0, 1))
    with pytest.raises(mb.ModelError, match="d1"):
        mb.Curve(("s", "s", "s"), (0, 1), d1=lambda s: (1, 1, 1))


def test_helix_expression_closed_form_reference_path():
    """The closed form itself, on today's reference path at a tight tolerance."""
    res = mb.simulate(bead_on(mb.Curve(HELIX, (-4, 3))), T_END, output_step=0.05, method="dop853", rtol=1e-10)
    assert angle_error(res) < 1e-7


def test_python_callable_agrees_with_expression_curve():
    kw = dict(output_step=0.05, method="dop853", rtol=1e-10)
    a = mb.simulate(bead_on(mb.Curve(HELIX, (-4, 3))), T_END, **kw)
    b = mb.simulate(bead_on(mb.Curve(helix, (-4, 3))), T_END, **kw)
    assert np.allclose(a.position("bead"), b.position("bead"), atol=1e-8)


@pytest.mark.parametrize("kind", ["expression", "callable", "spline"])
def test_helix_default_settings_compiled(kind):
    curve = {"expression": lambda: mb.Curve(HELIX, (-4, 3)), "callable": lambda: mb.Curve(helix, (-4, 3)),
             "spline": lambda: mb.Spline([helix(s) for s in np.linspace(-4, 3, 141)])}[kind]()
    res = mb.simulate(bead_on(curve), T_END, output_step=0.05)
    assert "(compiled)" in res.stats["method"]
    assert angle_error(res) < 1e-6   # spline of 141 knots: 2.6e-8 (h^4, 1.4e-9 at 281)


def test_straight_spline_uniform_acceleration_compiled():
    u = np.array([0.6, 0.0, -0.8])
    m = mb.Model("slide", gravity=(0, 0, -G))
    bead = m.add_particle("bead", 0.2, position=(0, 0, 0), velocity=0.5 * u)
    m.add_point_on_curve("line", bead.add_marker("c"), m.ground, mb.Spline([k * u for k in np.linspace(-1, 5, 7)]))
    res = mb.simulate(m, T_END, output_step=0.05)
    assert "(compiled)" in res.stats["method"]
    x = res.position("bead") @ u
    ref = 0.5 * res.time + 0.5 * (G * 0.8) * res.time ** 2
    assert np.max(np.abs(x - ref)) < 1e-6 * abs(ref[-1])


def test_helix_compiled_parameter_and_constraint_force():
    """Compiled expression helix at a tight tolerance: the curve parameter s (an auxiliary coordinate of the
    state, synced to the foot point) follows the closed form, and the path's multipliers are the ground-axes
    constraint force on the bead, lambda = m (g - a) (M vd + phi_q^T lambda = F, phi = P - C(s))."""
    res = mb.simulate(bead_on(mb.Curve(HELIX, (-4, 3))), T_END, output_step=0.05, rtol=1e-10, atol=1e-12)
    assert "(compiled)" in res.stats["method"]
    sys_ = res.system
    s = np.asarray(res.q)[:, sys_.aux_q_idx[0]]
    assert np.max(np.abs(s - (0.5 + SD0 * res.time + 0.5 * SDD * res.time ** 2))) < 1e-9
    lam = np.asarray(res.lambda_)[:, sys_.owner_rows["path"]]
    a = np.asarray(res.vd)[:, sys_.rd_idx[0]]
    F = 0.2 * (np.array([0.0, 0.0, -G]) - a)
    assert np.max(np.abs(lam - F)) < 1e-9 * np.max(np.abs(F))
    T = np.stack([-R * np.sin(s), R * np.cos(s), np.full_like(s, C)], -1)
    assert np.max(np.abs(np.sum(lam * T, -1))) < 1e-9   # frictionless: no force along the curve


def _bead_on_a_spinning_drum():
    """A helix fixed on a drum that turns freely about z (body i moves: the curve's w_i terms), the bead
    starting with the drum's rate; conservative."""
    m = mb.Model("drum", gravity=(0, 0, -G))
    drum = m.add_body("drum", 2.0, inertia=(0.05, 0.05, 0.08), position=(0, 0, 0))
    m.add_revolute("z", m.ground, drum, (0, 0, 0), (0, 0, 1), initial_velocity=3.0)
    P = np.array([R * np.cos(0.5), R * np.sin(0.5), C * 0.5])
    bead = m.add_particle("bead", 0.2, position=P, velocity=np.cross([0, 0, 3.0], P))
    m.add_point_on_curve("path", bead.add_marker("c"), drum, mb.Curve(HELIX, (-20, 5)))
    return m


def test_helix_on_a_spinning_drum_compiled_conserves_energy_and_matches_the_reference_rows(monkeypatch):
    import mbdsim.solvers.dynamic as dynamic
    kw = dict(output_step=0.05, rtol=1e-10, atol=1e-12)
    a = mb.simulate(_bead_on_a_spinning_drum(), T_END, **kw)
    assert "(compiled)" in a.stats["method"]
    E = a.kinetic_energy() + a.potential_energy()
    assert np.ptp(E) < 1e-9 * np.max(np.abs(E))
    s = np.asarray(a.q)[:, a.system.aux_q_idx[0]]
    assert s.min() < -np.pi                               # the bead runs down more than half a turn
    monkeypatch.setattr(dynamic, "USE_COMPILED", False)   # the reference rows (three rows and an s column)
    b = mb.simulate(_bead_on_a_spinning_drum(), T_END, method="dop853", **kw)
    assert "compiled" not in b.stats["method"]
    assert np.max(np.abs(a.position("bead") - b.position("bead"))) < 1e-9
    assert np.max(np.abs(a.joint_coordinate("z") - b.joint_coordinate("z"))) < 1e-9
    rows = a.system.owner_rows["path"]
    assert np.max(np.abs(np.asarray(a.lambda_)[:, rows] - np.asarray(b.lambda_)[:, rows])) < 1e-8


def test_closed_spline_bead_runs_round_compiled_at_constant_speed():
    """A bead on a closed spline circle (r = 0.3 m, horizontal, gravity normal to it) at 2 m/s runs round
    more than once (the parameter continues past the spline's length; the kernel takes it modulo the length):
    constant speed and radius (a frictionless curve does no work)."""
    pts = [(R * np.cos(a), R * np.sin(a), 0.0) for a in np.linspace(0, 2 * np.pi, 73)[:-1]]
    m = mb.Model("ring", gravity=(0, 0, -G))
    bead = m.add_particle("bead", 0.2, position=pts[0], velocity=(0.0, 2.0, 0.0))
    m.add_point_on_curve("ring", bead.add_marker("c"), m.ground, mb.Spline(pts, closed=True))
    res = mb.simulate(m, 1.5, output_step=0.01, rtol=1e-10, atol=1e-12)
    assert "(compiled)" in res.stats["method"]
    p, v = res.position("bead"), res.velocity("bead")
    assert np.max(np.abs(np.linalg.norm(v, axis=1) - 2.0)) < 1e-7
    assert np.max(np.abs(np.linalg.norm(p[:, :2], axis=1) - R)) < 1e-6   # the spline's own radius error
    assert np.max(np.abs(p[:, 2])) < 1e-12
    s = np.asarray(res.q)[:, res.system.aux_q_idx[0]]
    assert s[-1] > 1.2 * m.path_constraints["ring"].curve.s_range[1]   # more than one lap
