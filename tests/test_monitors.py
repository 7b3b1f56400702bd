"""Issue 10, monitors: constraint violation, energy balance and contact penetration checked on every run;
the first exceedance warns with time, quantity and element; Result.diagnostics keeps the history."""
import warnings

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.results.diagnostics import MonitorWarning, monitor
from mbdsim.results.result import Result


def pendulum():
    m = mb.Model("p", gravity=(0.0, -9.81, 0.0))
    b = m.add_body("b", 1.0, inertia=(0.01, 0.01, 0.01), position=(1.0, 0.0, 0.0))
    m.add_revolute("j", m.ground, b, (0, 0, 0), (0, 0, 1))
    return m, b


def test_conservative_run_is_quiet_and_keeps_the_history():
    m, _ = pendulum()
    with warnings.catch_warnings():
        warnings.simplefilter("error", MonitorWarning)
        res = mb.simulate(m, 2.0, 0.01)
    d = res.diagnostics
    assert len(d.time) == len(res.time) and len(d.energy_error) == len(res.time)
    assert d.energy_scale > 9.0   # the pendulum falls from rest through 1 m: T reaches m g L = 9.81 J
    assert np.max(np.abs(d.energy_error)) < 1e-6 * d.energy_scale
    assert np.max(d.constraint_violation) < 1e-10 and not d.exceedances


def test_energy_drift_of_a_loose_run_warns_with_time_and_element():
    m, _ = pendulum()
    with pytest.warns(MonitorWarning, match=r"model 'p': energy error .* first at t = ") as rec:
        res = mb.simulate(m, 2.0, 0.01, rtol=1e-3, method="rk45")
    first = res.diagnostics.exceedances[0]
    assert first["quantity"] == "energy_error" and first["element"] == "model 'p'"
    assert abs(first["value"]) > first["tolerance"] and 0 < first["time"] <= 2.0
    i = int(np.searchsorted(res.time, first["time"]))   # the first sample past the tolerance
    assert np.all(np.abs(res.diagnostics.energy_error[:i]) <= first["tolerance"])
    assert len([w for w in rec if issubclass(w.category, MonitorWarning)]) == 1   # once per quantity and element


def test_energy_balance_counts_the_work_of_applied_loads():
    m, b = pendulum()
    m.add_torque("tq", b, lambda t, state: (0.0, 0.0, 2.0 * np.sin(3.0 * t)))
    with warnings.catch_warnings():
        warnings.simplefilter("error", MonitorWarning)
        res = mb.simulate(m, 2.0, 0.002, method="rk45", rtol=1e-10)
    d = res.diagnostics
    W = d._carry["W"]
    assert abs(W) > 0.05 * d.energy_scale   # the torque did work: without W the balance would fail
    assert np.max(np.abs(d.energy_error)) < 1e-4 * d.energy_scale


def test_constraint_violation_names_the_joint_and_time():
    m, _ = pendulum()
    res = mb.simulate(m, 0.5, 0.01, monitor=False)
    assert res.diagnostics is None
    q = res.q.copy()
    q[20:, 1] += 1e-3   # the body's CM moved off the pin circle from sample 20 on
    bad = Result(res.system, res.time, q, res.v, None, None)
    with pytest.warns(MonitorWarning, match=r"joint 'j': constraint violation 0.001 .* t = 0.2 s"):
        d = monitor(bad)
    assert d.exceedances[0]["element"] == "joint 'j'" and d.exceedances[0]["time"] == pytest.approx(0.2)


def test_contact_penetration_warns_naming_the_contact():
    m = mb.Model("c", gravity=(0, 0, -9.81))
    ball = m.add_body("ball", 1.0, inertia=(0.1, 0.1, 0.1), position=(0, 0, 0.3))
    m.add_contact("c", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), mb.Sphere(ball, 0.2), stiffness=1e3, exponent=1.5,
                  damping=1.0, penetration=1e-3)   # far too soft: the 1 kg ball sinks over half its radius
    with pytest.warns(MonitorWarning, match=r"contact 'c': penetration"):
        res = mb.simulate(m, 1.0, 0.001)
    d = res.diagnostics
    assert d.exceedances[0]["element"] == "contact 'c'" and np.max(d.penetration["c"]) > 0.1
    # free fall from 0.1 m: first contact at t = sqrt(2 h / g); the exceedance comes after it
    assert d.exceedances[0]["time"] > np.sqrt(2 * 0.1 / 9.81)


def test_streamed_run_monitors_every_chunk(tmp_path, monkeypatch):
    from mbdsim.solvers import stream
    monkeypatch.setattr(stream, "CHUNK_ROWS", 300)
    m, _ = pendulum()
    res = mb.simulate(m, 2.0, 0.002, out=tmp_path / "r.parquet")
    ref = mb.simulate(m, 2.0, 0.002)
    d = res.diagnostics   # one entry per chunk (its extreme values): bounded history
    assert len(d.time) == res.stats["chunks"] and d.time[-1] == 2.0
    assert np.max(np.abs(d.energy_error)) == pytest.approx(np.max(np.abs(ref.diagnostics.energy_error)), abs=1e-12)
    assert np.max(d.constraint_violation) == pytest.approx(np.max(ref.diagnostics.constraint_violation), abs=1e-15)


def _driven_slider_crank():
    m = mb.Model("sc", gravity=(0.0, -9.81, 0.0))
    crank = m.add_body("crank", 1.0, inertia=(0.01, 0.01, 0.01), position=(0.05, 0.0, 0.0))
    rod = m.add_body("rod", 1.0, inertia=(0.01, 0.01, 0.01), position=(0.25, 0.0, 0.0))
    slider = m.add_body("slider", 1.0, inertia=(0.01, 0.01, 0.01), position=(0.4, 0.0, 0.0))
    m.add_revolute("pin", m.ground, crank, (0, 0, 0), (0, 0, 1))
    m.add_revolute("crank_rod", crank, rod, (0.1, 0, 0), (0, 0, 1))
    m.add_revolute("rod_slider", rod, slider, (0.4, 0, 0), (0, 0, 1))
    m.add_translational("slide", m.ground, slider, (0.4, 0, 0), (1, 0, 0))
    m.add_motion("drive", "pin", "3*t")
    return m


@pytest.mark.parametrize("case", ["tree", "loop", "driven"])
def test_compiled_residual_check_matches_the_rows_evaluated_sample_by_sample(case):
    """The run monitors read a compiled run's constraint residuals in one compiled call
    (Result.residual_check); they equal max |phi| of the rows evaluated one sample at a time by the
    reference path, for a joint-coordinate tree, an absolute-coordinate loop and a driven (kinematic
    sweep) model, also where a sample is moved off the constraints (the row and its value)."""
    from mbdsim.system.equations import constraint_terms
    if case == "tree":
        m, _ = pendulum()
        res = mb.simulate(m, 0.5, 0.01)
    else:
        m = _driven_slider_crank()
        if case == "loop":
            del m.motions["drive"]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = mb.simulate(m, 0.5, 0.01)
    method = res.stats["method"]
    assert ("kinematic" in method) if case == "driven" else ("(compiled)" in method), method
    assert res.residual_check is not None
    sys = res.system
    n = len(res.time)
    for i in (7, n - 1):   # the last body moved off its joints at samples 7 and n - 1
        res.q[i, sys.r_idx[-1]] += np.array([2e-4, -3e-4, 1e-4])
    idx = np.array([0, 7, n - 1])
    rows = np.asarray(sys.fixed_rows)
    val, arg = res.residual_check(idx, rows)
    for k, i in enumerate(idx):
        phi = constraint_terms(sys, res.q[i], np.zeros(sys.nv), res.time[i], jacobian=False)[0][rows]
        assert val[k] == pytest.approx(np.max(np.abs(phi)), rel=1e-12, abs=1e-15)
        if i > 0:
            assert val[k] > 1e-4 and arg[k] == rows[np.argmax(np.abs(phi))]
    with pytest.warns(MonitorWarning, match=r"constraint violation .* t = 0.5 s"):
        monitor(res)   # a compiled run's monitors check the first and the last sample


def _bushing_top(kt):
    """A free body on a bushing to ground, spun to a large rotation (no gravity, no damping)."""
    m = mb.Model("bt")
    b = m.add_body("b", 2.0, inertia=(0.3, 0.2, 0.1), position=(0.0, 0.0, 0.0), angular_velocity=(3.0, 2.0, 1.0))
    m.add_bushing("bu", (m.ground, (0, 0, 0)), (b, (0, 0, 0)), stiffness=(100.0, 100.0, 100.0) + tuple(kt))
    return m


def test_unequal_rotational_bushing_is_adams_small_angle_not_conservative():
    """Issue 35: Adams' BUSHING torque -K a (a: rotation vector) is not a potential force when the
    rotational stiffnesses differ: T + V drifts by percent whatever the tolerance, so the monitor
    names the bushing instead of reporting an error; with equal stiffnesses it is conservative and
    the monitor checks it."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error", mb.MonitorWarning)
        iso = mb.simulate(_bushing_top((5.0, 5.0, 5.0)), 4.0, 0.01, rtol=1e-10)
        aniso = [mb.simulate(_bushing_top((2.0, 5.0, 9.0)), 4.0, 0.01, rtol=r) for r in (1e-8, 1e-10)]
    E = lambda res: res.kinetic_energy() + res.potential_energy()  # noqa: E731
    assert iso.diagnostics.energy_error is not None
    assert np.max(np.abs(E(iso) - E(iso)[0])) < 1e-7 * E(iso)[0]
    drift = [np.max(np.abs(E(r) - E(r)[0])) / E(r)[0] for r in aniso]
    assert min(drift) > 1e-3 and abs(drift[0] - drift[1]) < 1e-4   # the model's, not the integrator's
    for r in aniso:
        assert r.diagnostics.energy_error is None and any("bushing 'bu'" in n for n in r.diagnostics.notes)


def _stiff_damped_chain(k2=1e8, c2=20.0):
    """ground -100 N/m- p1 (1 kg) -k2, c2- p2 (2 kg) on translational joints, p1 displaced 10 mm at rest:
    the damped fast mode rings at ~1.9 kHz; returns (model, fast period [s], state-space A, x0)."""
    from scipy.linalg import eigh
    m = mb.Model("stiff damped chain", gravity=(0, 0, 0))
    p1 = m.add_particle("p1", 1.0, position=(1.01, 0, 0))
    p2 = m.add_particle("p2", 2.0, position=(2.0, 0, 0))
    m.add_translational("s1", m.ground, p1, (1.0, 0, 0), (1, 0, 0))
    m.add_translational("s2", m.ground, p2, (2.0, 0, 0), (1, 0, 0))
    m.add_spring_damper("k1", m.ground, p1, 100.0, 0.0, 1.0)
    m.add_spring_damper("k2", p1, p2, k2, c2, 1.0)
    M, K, C = np.diag([1.0, 2.0]), np.array([[100 + k2, -k2], [-k2, k2]]), np.array([[c2, -c2], [-c2, c2]])
    Mi = np.linalg.inv(M)
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-Mi @ K, -Mi @ C]])
    return m, 2 * np.pi / np.sqrt(eigh(K, M)[0][1]), A, (M, K, C), np.array([0.01, 0.0, 0.0, 0.0])


def test_stiff_damped_model_handed_to_radau_is_quiet_with_output_step_in_phase_with_the_ringing():
    """False alarm (a): the output step is 4 periods of the fast mode, so every sample sees it at rest and
    a trapezoid on the samples' damping power misses nearly all of the 5 kJ dissipated.  The monitor's D is
    the Result's dense-output integral: no warning, and the balance closes against the exact solution
    (matrix exponential of the linear state space): E(0) - E(T) = D(T) to 1e-6 of E(0)."""
    from scipy.linalg import expm
    m, Tf, A, (M, K, C), y0 = _stiff_damped_chain()
    with warnings.catch_warnings():
        warnings.simplefilter("error", MonitorWarning)
        res = mb.simulate(m, 0.5, output_step=4 * Tf)
    assert "then Radau IIA (compiled)" in res.stats["method"]
    d = res.diagnostics
    E0 = 0.5 * y0[:2] @ K @ y0[:2]
    y = np.array([expm(A * t) @ y0 for t in res.time])
    E = 0.5 * np.einsum("ni,ij,nj->n", y[:, :2], K, y[:, :2]) + 0.5 * np.einsum("ni,ij,nj->n", y[:, 2:], M, y[:, 2:])
    D_exact = E0 - E
    assert D_exact[-1] > 0.99 * E0   # the fast mode's energy is gone
    assert np.max(np.abs(res.dissipated_energy() - D_exact)) < 1e-6 * E0
    assert np.max(np.abs(d.energy_error)) < 1e-6 * E0 < d.tolerances["energy_error"]
    # the trapezoid on the samples (the old monitor's D) is off by most of E(0): this model exercises it
    P = np.einsum("ni,ij,nj->n", y[:, 2:], C, y[:, 2:])
    trap = np.sum(0.5 * (P[1:] + P[:-1]) * np.diff(res.time))
    assert abs(trap - D_exact[-1]) > 0.5 * E0


def test_damping_hidden_from_the_energy_account_still_warns(monkeypatch):
    """Not weakened: the same model with the spring-damper's dissipation reported as zero (a
    non-conservative force the energy account does not see) must warn."""
    from mbdsim.system.force_elements import evaluator
    m, Tf, *_ = _stiff_damped_chain(k2=1e6, c2=20.0)
    ev = evaluator(m.forces["k2"])   # the spring-damper evaluator (class attribute: undone by monkeypatch)
    monkeypatch.setattr(ev, "dissipation", staticmethod(lambda sys, fr, el, t: np.zeros(len(np.atleast_1d(t)))),
                        raising=True)
    # (and not the compiled step loop's own account of it, which the evaluator does not reach: the run keeps
    # the post-run quadrature of that zero power)
    from mbdsim.solvers import energy_run
    monkeypatch.setattr(energy_run, "DISSIPATIVE", tuple(t for t in energy_run.DISSIPATIVE
                                                         if t is not type(m.forces["k2"])))
    with pytest.warns(MonitorWarning, match=r"model 'stiff damped chain': energy error"):
        mb.simulate(m, 0.5, output_step=4 * Tf)


def test_box_dropped_on_a_plane_balances_with_the_shape_contact_damping_and_friction():
    """False alarm (b): a 10 cm box (density 1000 kg/m^3) dropped 5 cm, sliding at 0.5 m/s, on a plane
    (IMPACT damping, Coulomb friction): no warning, and the loss of T + V equals the contact's damping and
    friction power integrated in this test from the contact points, forces and the box's point velocities
    on a fine grid of the dense output (to 3e-3 of the loss)."""
    a, rho, k, cmax, mu = 0.1, 1000.0, 1e6, 400.0, 0.3
    m = mb.Model("box drop", gravity=(0, 0, -9.81))
    b = m.add_body("box", 0.0, position=(0, 0, a / 2 + 0.05), velocity=(0.5, 0, 0))
    sh = b.add_shape("geo", mb.Box((a, a, a)), density=rho)
    m.add_contact("c", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), sh, k, 1.0, cmax, 1e-4, mu=mu)
    T_end = 0.35
    with warnings.catch_warnings():
        warnings.simplefilter("error", MonitorWarning)
        res = mb.simulate(m, T_end)
    E = res.kinetic_energy() + res.potential_energy()
    loss = E[0] - E[-1]
    assert loss > 0.4   # 1 kg: the fall (0.49 J) and the slide (0.125 J) are mostly dissipated
    # independent power: per contact point, damping (Fn - k delta) times the penetration rate and the
    # friction force on the box against the point's velocity; the point velocity from the box's motion
    t_c = np.sqrt(2 * 0.05 / 9.81)
    ts = np.concatenate([np.linspace(0.0, t_c - 1e-3, 5), np.linspace(t_c - 1e-3, T_end, 30001)[1:]])
    r = res.at(ts)
    x, v, w = r.position("box"), r.velocity("box"), r.angular_velocity("box")
    pts = r.contact_points("c")
    P = np.zeros(len(ts))
    n_t = np.searchsorted(ts, pts["time"].to_numpy())
    X = pts[["x", "y", "z"]].to_numpy()
    Ft = pts[["friction_x", "friction_y", "friction_z"]].to_numpy()
    delta, Fn = pts["penetration"].to_numpy(), pts["normal_force"].to_numpy()
    vp = v[n_t] + np.cross(w[n_t], X - x[n_t])
    p_pt = -(Fn - k * delta) * vp[:, 2] - np.sum(Ft * vp, axis=1)
    np.add.at(P, n_t, p_pt)
    D_ind = np.sum(0.5 * (P[1:] + P[:-1]) * np.diff(ts))
    assert abs(D_ind - loss) < 3e-3 * loss, (D_ind, loss)
    d = res.diagnostics
    assert abs(d.energy_error[-1]) < 3e-3 * loss and np.max(np.abs(d.energy_error)) < d.tolerances["energy_error"]


def test_undamped_springs_skip_the_dissipation_quadrature_but_still_balance(monkeypatch):
    """A spring chain with zero damping dissipates nothing: the monitor checks T + V without integrating
    an identically zero dissipation power, and still catches a drift (a spring with damping does run it)."""
    m = mb.Model("springs", gravity=(0, 0, 0))
    a = m.add_body("a", 1.0, inertia=(1, 1, 1), position=(1, 0, 0), velocity=(0.3, 0, 0))
    b = m.add_body("b", 2.0, inertia=(1, 1, 1), position=(2, 0, 0))
    m.add_translational("sa", "ground", a, (1, 0, 0), (1, 0, 0))
    m.add_translational("sb", "ground", b, (2, 0, 0), (1, 0, 0))
    m.add_spring_damper("k1", m.ground.add_marker("o", (0, 0, 0)), a.add_marker("pa", (1, 0, 0)), 100.0, 0.0, 1.0)
    m.add_spring_damper("k2", a.add_marker("qa", (1, 0, 0)), b.add_marker("pb", (2, 0, 0)), 1e4, 0.0, 1.0)
    calls = []
    original = Result.dissipated_energy
    monkeypatch.setattr(Result, "dissipated_energy", lambda self: calls.append(1) or original(self))
    with warnings.catch_warnings():
        warnings.simplefilter("error", MonitorWarning)
        res = mb.simulate(m, 1.0, 0.01)
    assert not calls
    d = res.diagnostics
    assert d.energy_scale > 0.04 and np.max(np.abs(d.energy_error)) < 1e-6 * d.energy_scale
    m.forces["k2"].damping = 1.0
    mb.simulate(m, 0.2, 0.01)
    assert calls
