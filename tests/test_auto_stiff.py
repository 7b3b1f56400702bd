"""Issue 8, the default method on stiff and non-stiff models: which method the automatic choice takes,
the hand-over to the compiled Radau IIA at the detection time (outputs, dense output, step states, statistics and the order
history joined), and the accuracy against closed forms (linear stiff oscillators, static contact
penetration, a rod pendulum's quarter period, a driven slider-crank)."""
import numpy as np
import pytest
from scipy.special import ellipk

import mbdsim as mb

G = 9.81


# --------------------------------------------------------------------------- closed forms
def oscillator(t, u0, k, c, m=1.0):
    """Deviation u(t) from equilibrium of m u'' + c u' + k u = 0, u(0) = u0, u'(0) = 0, and u''(t)."""
    disc = complex(c * c - 4 * k * m)
    r1, r2 = (-c + np.sqrt(disc)) / (2 * m), (-c - np.sqrt(disc)) / (2 * m)
    a = -r2 * u0 / (r1 - r2)
    b = u0 - a
    e1, e2 = np.exp(r1 * t), np.exp(r2 * t)
    return np.real(a * e1 + b * e2), np.real(a * r1 ** 2 * e1 + b * r2 ** 2 * e2)


# --------------------------------------------------------------------------- stiff models
def stiff_spring(k=1e8, c=1e6, u0=1e-3):
    """1 kg on a translational joint (x), spring-damper k [N/m], c [N s/m] of free length 1 m to the
    origin, gravity -x; starts u0 [m] beyond the static equilibrium x_e = 1 - g / k, at rest."""
    m = mb.Model("stiff spring", gravity=(-G, 0, 0))
    p = m.add_particle("p", 1.0, position=(1.0 - G / k + u0, 0, 0))
    m.add_translational("slide", m.ground, p, (1.0, 0, 0), (1, 0, 0))
    m.add_spring_damper("k", m.ground, p, k, c, 1.0)
    return m, p


def stiff_bushing(k=1e8, zeta=0.7, mass=2.0):
    """A free body (2 kg) held at its CM by a bushing to ground, translational stiffness k [N/m] with
    damping ratio zeta, rotational 1e5 N m/rad; starts at rest at the bushing's unloaded position under
    gravity -y: y(t) follows the damped oscillator towards -m g / k, x = z = 0, no rotation."""
    c = 2 * zeta * np.sqrt(k * mass)
    m = mb.Model("bushing", gravity=(0, -G, 0))
    b = m.add_body("b", mass, (0.01, 0.02, 0.03))
    m.add_bushing("bush", (m.ground, (0, 0, 0)), (b, (0, 0, 0)), stiffness=(k,) * 3 + (1e5,) * 3,
                  damping=(c,) * 3 + (10.0,) * 3)
    return m, b, c


def test_stiff_spring_damper_hands_over_to_compiled_radau_and_matches_the_exact_solution():
    k, c, u0 = 1e8, 1e6, 1e-3   # eigenvalues -100 and -1e6 1/s
    m, p = stiff_spring(k, c, u0)
    res = mb.simulate(m, 0.05, output_step=5e-4)
    assert res.success
    st = res.stats
    assert "stiffness detected" in st["method"] and st["method"].startswith("auto: DOP853")
    t_s = st["switch_time"]
    assert 0 < t_s < 0.01   # the stiffness test fires early, not after most of the run
    assert st["order_history"] == [(0.0, "DOP853 (compiled)", 8), (t_s, "Radau", 5)] and st["order"] == 5
    assert "then Radau IIA (compiled)" in st["method"]
    u, ud2 = oscillator(res.time, u0, k, c)
    x_e = 1.0 - G / k
    assert np.max(np.abs(res.position(p)[:, 0] - x_e - u)) < 1e-3 * u0
    assert np.max(np.abs(res.acceleration(p)[:, 0] - ud2)[res.time > 0.01]) < 2e-3 * np.abs(ud2).max()


def test_stiff_bushing_settles_as_the_damped_oscillator():
    k, mass = 1e8, 2.0
    m, b, c = stiff_bushing(k, 0.7, mass)
    res = mb.simulate(m, 0.2, output_step=1e-3)
    assert res.success and "stiffness detected" in res.stats["method"]
    u, _ = oscillator(res.time, G * mass / k, k, c, mass)
    y = res.position(b)[:, 1]
    assert np.max(np.abs(y - (u - G * mass / k))) < 1e-3 * G * mass / k
    assert np.max(np.abs(res.position(b)[:, [0, 2]])) < 1e-14


def test_stiff_contact_runs_compiled_radau_and_rests_at_the_static_penetration():
    """A ball resting on a 1e9 N/m^1.5 penalty plane: the automatic method starts with the compiled DOP853
    (contact is compiled), detects the stiffness and hands over to the compiled Radau IIA; final penetration (m g / k)^(1 / e)."""
    k, e, mass, R = 1e9, 1.5, 1.0, 0.05
    m = mb.Model(gravity=(0, 0, -G))
    ball = m.add_body("ball", mass, (0.4 * mass * R * R,) * 3, position=(0, 0, R))
    m.add_contact("floor", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), mb.Sphere(ball, R), k, e, 2e3, 1e-6)
    res = mb.simulate(m, 0.2, output_step=1e-3)
    assert res.success and "stiffness detected" in res.stats["method"] and "then Radau IIA (compiled)" in res.stats["method"]
    delta = (mass * G / k) ** (1 / e)
    assert abs((R - res.position(ball)[-1, 2]) - delta) < 1e-3 * delta


def test_hand_over_keeps_dense_output_steps_and_files_consistent(tmp_path):
    m, p = stiff_spring()
    times = []
    out = tmp_path / "run.csv"
    res = mb.simulate(m, 0.05, output_step=5e-4, progress=times.append, out=out)
    t_s = res.stats["switch_time"]
    assert res.success and "stiffness" in res.stats["method"]
    assert np.all(np.diff(res.time) > 0) and len(res.time) == 101
    # Result.at gives the stored samples at output times on both sides of the switch
    for t in (res.time[1], res.time[-2], res.time[np.searchsorted(res.time, t_s)]):
        a = res.at(t)
        k = int(np.argmin(np.abs(res.time - t)))
        assert np.allclose(a.q[0], res.q[k], rtol=0, atol=1e-15) and np.allclose(a.v[0], res.v[k], rtol=0, atol=1e-15)
    # between samples, on each side and at the switch: close to the exact solution
    tq = np.array([0.5 * t_s, t_s, t_s + 1e-5, 0.0301, 0.04977])
    u, _ = oscillator(tq, 1e-3, 1e8, 1e6)
    assert np.max(np.abs(res.at(tq).position(p)[:, 0] - (1.0 - G / 1e8) - u)) < 2e-6
    ts, q, v = res.steps() if callable(res.steps) else res.steps
    assert ts[0] == 0.0 and ts[-1] == res.time[-1] and np.all(np.diff(ts) > 0) and t_s in ts
    assert len(ts) == res.stats["steps"] + 1
    assert np.all(np.diff(times) >= 0) and times[-1] == pytest.approx(0.05)
    import pandas as pd
    df = pd.read_csv(out)
    assert len(df) == len(res.time) and np.allclose(df.iloc[:, 0], res.time)


def test_order_history_of_named_methods():
    m, _ = stiff_spring()
    bdf = mb.simulate(m, 0.01, method="bdf")
    hist = bdf.stats["order_history"]
    assert all(name == "BDF" and 1 <= order <= 5 for _, name, order in hist)
    assert len(hist) > 1 and np.all(np.diff([t for t, _, _ in hist]) > 0)   # BDF varies its order
    assert mb.simulate(m, 0.01, method="radau").stats["order_history"] == [(0.0, "Radau", 5)]
    hht = mb.simulate(m, 0.01, method="hht").stats
    assert hht["order_history"] == [(0.0, "HHT", 2)] and hht["order"] == 2


# --------------------------------------------------------------------------- non-stiff models
def rod_pendulum(theta0, L=1.0, mass=1.0):
    """A uniform rod hinged at one end (origin, axis z), released at rest theta0 [rad] from hanging."""
    m = mb.Model("pendulum", gravity=(0, -G, 0))
    c, s = np.cos(theta0), np.sin(theta0)
    R = np.array([[s, c, 0], [-c, s, 0], [0, 0, 1]])   # body x along the rod
    rod = m.add_body("rod", mass, (mass * 1e-4, mass * L * L / 12, mass * L * L / 12),
                     position=(0.5 * L * s, -0.5 * L * c, 0), orientation=R)
    m.add_revolute("hinge", m.ground, rod, (0, 0, 0), (0, 0, 1))
    return m, rod


def planar_chain(n, L=0.1):
    m = mb.Model("chain", gravity=(0, -G, 0))
    prev = m.ground
    for k in range(n):
        b = m.add_body(f"rod{k}", 1.0, (1e-4, L * L / 12, L * L / 12), position=((k + 0.5) * L, 0, 0))
        m.add_revolute(f"j{k}", prev, b, (k * L, 0, 0), (0, 0, 1))
        prev = b
    return m


def spherical_chain(n, L=0.2):
    m = mb.Model("chain3d", gravity=(0, -G, 0))
    prev, o = m.ground, np.zeros(3)
    for k in range(n):
        d = np.array([1.0, 0.35 * np.sin(0.9 * k), 0.5 * np.cos(0.7 * k)])
        d /= np.linalg.norm(d)
        b = m.add_body(f"b{k}", 0.1, (1e-5, 0.1 * L * L / 12, 0.1 * L * L / 12), position=o + 0.5 * L * d)
        m.add_spherical(f"j{k}", prev, b, o)
        prev, o = b, o + L * d
    return m


def slider_crank(r=0.1, l=0.35):
    """Crank driven theta = pi/6 + 3 t + 2 t^2 (spherical + universal joints: no redundancy)."""
    m = mb.Model("slider-crank", gravity=(0, -G, 0))
    th = np.pi / 6
    ph = -np.arcsin(r * np.sin(th) / l)
    A = r * np.array([np.cos(th), np.sin(th), 0.0])
    B = A + l * np.array([np.cos(ph), np.sin(ph), 0.0])
    rz = lambda a: np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])  # noqa: E731
    crank = m.add_body("crank", 1.5, (1e-4, 1.25e-3, 1.25e-3), position=A / 2, orientation=rz(th))
    rod = m.add_body("rod", 2.0, (2e-3, 0.0204, 0.0204), position=(A + B) / 2, orientation=rz(ph))
    slider = m.add_body("slider", 0.8, (0.01, 0.01, 0.01), position=B)
    o = m.add_revolute("O", m.ground, crank, (0, 0, 0), (0, 0, 1))
    m.add_spherical("A", crank, rod, A)
    m.add_universal("B", rod, slider, B, axis_i=(0, 0, 1), axis_j=(0, 1, 0))
    m.add_translational("slide", m.ground, slider, B, (1, 0, 0))
    m.add_motion("drive", o, displacement="3*t + 2*t**2")
    return m, slider


def heavy_top():
    tilt, spin, arm = np.radians(30.0), 100.0, 0.1
    c, s = np.cos(tilt), np.sin(tilt)
    R0 = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    w0, cm0 = R0 @ np.array([0.0, spin, 0.0]), R0 @ np.array([0.0, arm, 0.0])
    m = mb.Model("top", gravity=(0, -G, 0))
    top = m.add_body("top", 1.0, (0.002, 0.004, 0.002), position=cm0, orientation=R0,
                     velocity=np.cross(w0, cm0), angular_velocity=w0)
    m.add_spherical("pivot", m.ground, top, (0, 0, 0))
    return m


def _explicit_only(res):
    st = res.stats
    return res.success and st["method"] == "auto: DOP853 (compiled)" and \
        st["order_history"] == [(0.0, "DOP853 (compiled)", 8)]


@pytest.mark.filterwarnings("ignore::mbdsim.results.diagnostics.MonitorWarning")   # rtol 1e-2: the energy monitor's tolerance
@pytest.mark.parametrize("rtol", [1e-2, 1e-6, 1e-10])
def test_pendulum_stays_explicit_and_meets_the_quarter_period(rtol):
    theta0 = 2.0
    m, rod = rod_pendulum(theta0)
    w0 = np.sqrt(1.5 * G / 1.0)
    quarter = ellipk(np.sin(theta0 / 2) ** 2) / w0   # release to the lowest point
    res = mb.simulate(m, quarter, output_step=quarter / 4, rtol=rtol)
    assert _explicit_only(res)
    x = res.position(rod)[-1, 0]   # 0 at the lowest point; |x| / (L / 2) is the angle error there
    assert abs(x) / 0.5 < 2 * rtol + 1e-12


@pytest.mark.parametrize("rtol", [1e-2, 1e-6, 1e-10])
def test_slider_crank_stays_explicit_and_follows_the_kinematics(rtol):
    """Driven (zero DOF): "auto" solves it as a kinematic analysis (no stiffness test, no hand-over;
    tests/test_kinematic_dof0.py), the named DOP853 integrates it without flagging stiffness."""
    m, slider = slider_crank()
    res = mb.simulate(m, 1.0, output_step=0.01, rtol=rtol)
    assert res.success and res.stats["order_history"] == [(0.0, "kinematic (0 DOF)", None)]
    th = np.pi / 6 + 3 * res.time + 2 * res.time ** 2
    x = 0.1 * np.cos(th) + np.sqrt(0.35 ** 2 - (0.1 * np.sin(th)) ** 2)
    assert np.max(np.abs(res.position(slider)[:, 0] - x)) < 1e-10
    from mbdsim.solvers.compiled_run import integrate_compiled
    from mbdsim.solvers.assembly import assemble
    rep = assemble(m)
    res = integrate_compiled(rep.system, rep, res.time, 0.05 * rtol, 0.05 * rtol * 1e-2, None, stiff_check=True)
    assert res.success and res.stats["method"] == "DOP853 (compiled)"   # (Stiff would have been raised)
    th = np.pi / 6 + 3 * res.time + 2 * res.time ** 2
    x = 0.1 * np.cos(th) + np.sqrt(0.35 ** 2 - (0.1 * np.sin(th)) ** 2)
    assert np.max(np.abs(res.position(slider)[:, 0] - x)) < 1e-10   # driven: the constraints decide


@pytest.mark.parametrize("rtol", [1e-2, 1e-6, 1e-10])
def test_heavy_top_and_spherical_chain_stay_explicit(rtol):
    for m in (heavy_top(), spherical_chain(8)):
        res = mb.simulate(m, 0.5, output_step=0.01, rtol=rtol)
        assert _explicit_only(res), (m.name, res.stats["method"])
        E = res.kinetic_energy() + res.potential_energy()
        assert np.max(np.abs(E - E[0])) < max(5 * rtol, 1e-9) * np.max(res.kinetic_energy())


@pytest.mark.parametrize("n,rtol", [(8, 1e-2), (8, 1e-10), (32, 1e-6), (128, 1e-2), (128, 1e-6), (128, 1e-10)])
def test_planar_chains_stay_explicit(n, rtol):
    res = mb.simulate(planar_chain(n), 0.3, output_step=0.01, rtol=rtol)
    assert _explicit_only(res), res.stats["method"]
    E = res.kinetic_energy() + res.potential_energy()
    assert np.max(np.abs(E - E[0])) < max(5 * rtol, 1e-9) * np.max(res.kinetic_energy())


@pytest.mark.parametrize("joint", ["spherical", "revolute"])
def test_hand_over_on_a_jointed_model_keeps_constraints_accelerations_and_energy(joint):
    """A rod on a spherical joint (absolute coordinates) or a revolute joint (a tree: joint coordinates),
    its tip held by a damped 1e8 N/m spring to ground (slightly stretched at t = 0): stiff after the
    ringing decays. After the switch the outputs stay on the constraints, the on-demand accelerations
    equal the index-1 solve at the output states, and the energy balance E + dissipated = E(0) holds."""
    from mbdsim.solvers.common import accelerations
    from mbdsim.results.state import state_factory
    from mbdsim.system.equations import constraint_terms
    m = mb.Model("held rod", gravity=(0, -G, 0))
    rod = m.add_body("rod", 1.0, (1e-4, 1.0 / 12, 1.0 / 12), position=(0.5, 0, 0))
    if joint == "spherical":
        m.add_spherical("ball", m.ground, rod, (0, 0, 0))
        m.add_spring_damper("tip", (m.ground, (1.0, 0.3, 0.1)), (rod, (1.0, 0, 0)), 1e8, 2e4, np.sqrt(0.1) - 1e-5)
    else:
        m.add_revolute("hinge", m.ground, rod, (0, 0, 0), (0, 0, 1))
        m.add_spring_damper("tip", (m.ground, (1.0, 0.3, 0)), (rod, (1.0, 0, 0)), 1e8, 2e4, 0.3 - 1e-5)
    res = mb.simulate(m, 0.04, output_step=1e-3)
    assert res.success and "stiffness detected" in res.stats["method"]
    assert res.stats["formulation"].startswith("absolute" if joint == "spherical" else "joint")
    after = np.flatnonzero(res.time > res.stats["switch_time"])[::10]
    sys, rows = res.system, res.stats["assembly"].rows
    sf = state_factory(sys)
    for k in after:
        q, v, t = res.q[k], res.v[k], res.time[k]
        phi, J, nu, _ = constraint_terms(sys, q, v, t)
        assert np.max(np.abs(phi)) < 1e-11 and np.max(np.abs(J @ v - nu)) < 1e-9
        vd, lam = accelerations(sys, q, v, t, rows, sf)
        # at rest vd is the small difference of the gravity and spring loads (~G): their round-off is the floor
        assert np.allclose(res.vd[k], vd, rtol=1e-8, atol=1e-8 * max(np.abs(vd).max(), G))
        assert np.allclose(res.lambda_[k], lam, rtol=1e-8, atol=1e-8 * np.abs(lam).max())
    a = res.at(res.time[after])   # dense output at output times: the stored samples
    assert np.array_equal(a.q, res.q[after]) and np.array_equal(a.v, res.v[after])
    assert np.allclose(a.vd, res.vd[after], rtol=0, atol=1e-12 * np.abs(res.vd).max())
    E = res.kinetic_energy() + res.potential_energy()
    D = res.dissipated_energy()
    assert np.max(np.abs(E + D - E[0])) < 5e-3 * E[0]   # E[0]: the spring's 0.5 k (1e-5 m)^2


def test_hand_over_keeps_the_outputs_tolerance():
    """Default settings: the outputs' target is 1e-7 and the compiled Radau IIA continues at that target
    (no AccuracyWarning, res.stats["rtol_reached"] the target); a given rtol is the target, likewise."""
    import warnings
    m, p = stiff_spring(1e8, 1e6, 1e-3)
    for rtol, target in ((None, 1e-7), (1e-5, 1e-5)):
        with warnings.catch_warnings():
            warnings.simplefilter("error", mb.AccuracyWarning)
            res = mb.simulate(m, 0.02, output_step=5e-4, rtol=rtol)
        assert "stiffness detected" in res.stats["method"] and res.stats["rtol_reached"] == target
        u, _ = oscillator(res.time, 1e-3, 1e8, 1e6)
        assert np.max(np.abs(res.position(p)[:, 0] - (1.0 - G / 1e8) - u)) < target * 1e-3
