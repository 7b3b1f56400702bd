"""Issue 3 force elements: torsion springs, bushings, stops, state-dependent loads, dissipated energy.

Every check is against a closed form, a conservation law or finite differences of a potential.
"""
import warnings

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.solvers.common import increment
from mbdsim.system.assemble import assemble_system
from mbdsim.system.force_elements import evaluator
from mbdsim.system.force_elements._common import element_state
from mbdsim.system.frames import body_frames

TIGHT = dict(method="dop853", rtol=1e-11, atol=1e-13)


def damped(t, x0, v0, wn, zeta):
    """Closed-form free response of x'' + 2 zeta wn x' + wn^2 x = 0 (underdamped)."""
    wd = wn * np.sqrt(1 - zeta**2)
    a = zeta * wn
    return np.exp(-a * t) * (x0 * np.cos(wd * t) + (v0 + a * x0) / wd * np.sin(wd * t))


def damped_rate(t, x0, v0, wn, zeta):
    wd = wn * np.sqrt(1 - zeta**2)
    a = zeta * wn
    c1, c2 = x0, (v0 + a * x0) / wd
    return np.exp(-a * t) * ((-a * c1 + wd * c2) * np.cos(wd * t) + (-a * c2 - wd * c1) * np.sin(wd * t))


# --------------------------------------------------------------------------- must-show 1
M_, K_, C_, X0 = 3.0, 108.0, 18.0, 0.3          # wn = 6 rad/s, zeta = 0.5


def test_spring_mass_damper_closed_form():
    m = mb.Model()
    b = m.add_body("block", M_, (1, 1, 1), position=(X0, 0, 0))
    m.add_translational("slide", m.ground, b, (0, 0, 0), (1, 0, 0))
    m.add_spring_damper("s", (m.ground, (0, 0, 0)), (b, (X0, 0, 0)), K_, C_, free_length=0.0)
    res = mb.simulate(m, 3.0, 0.01, **TIGHT)
    assert res.success
    x = res.position(b)[:, 0]
    xc = damped(res.time, X0, 0.0, 6.0, 0.5)
    assert np.max(np.abs(x - xc)) < 1e-7
    # dissipated energy against the closed-form energy loss
    E = 0.5 * M_ * damped_rate(res.time, X0, 0.0, 6.0, 0.5) ** 2 + 0.5 * K_ * xc**2
    assert np.allclose(res.dissipated_energy(), E[0] - E, rtol=0, atol=1e-9)


def test_bushing_spring_mass_damper_closed_form():
    """The same oscillator made of a bushing's x component (free body, no joint)."""
    m = mb.Model()
    b = m.add_body("block", M_, (1, 2, 3), position=(X0, 0, 0))
    m.add_bushing("bush", (m.ground, (0, 0, 0)), (b, (X0, 0, 0)), stiffness=(K_, 50, 50, 10, 10, 10),
                  damping=(C_, 1, 1, 1, 1, 1))
    res = mb.simulate(m, 3.0, 0.01, **TIGHT)
    x = res.position(b)
    assert np.max(np.abs(x[:, 0] - damped(res.time, X0, 0.0, 6.0, 0.5))) < 1e-7
    assert np.max(np.abs(x[:, 1:])) < 1e-12
    E = res.kinetic_energy() + res.potential_energy()
    assert np.allclose(E + res.dissipated_energy(), E[0], rtol=0, atol=1e-9 * E[0])


# --------------------------------------------------------------------------- must-show 2
def rotor(J=0.5, w0=0.0, kind="revolute"):
    m = mb.Model()
    b = m.add_body("disk", 2.0, (0.3, 0.3, J), angular_velocity=(0, 0, w0))
    jt = getattr(m, f"add_{kind}")("pin", m.ground, b, (0, 0, 0), (0, 0, 1))
    return m, b, jt


@pytest.mark.parametrize("path", ["compiled", "reference"])
def test_torsional_pendulum_frequency_and_decay(path, monkeypatch):
    """Compiled: the spring is a joint torque of the tree's own (continuous) angle, and the Result continues
    the angle its measures read; reference: the angle continued by events, anchored on the System."""
    from mbdsim.solvers import dynamic
    monkeypatch.setattr(dynamic, "USE_COMPILED", path == "compiled")
    J, k, c, w0 = 0.5, 8.0, 0.4, 20.0      # amplitude ~4.3 rad: the angle is continued past +-pi
    m, b, jt = rotor(J, w0)
    m.add_torsion_spring("ts", jt, k, c)
    res = mb.simulate(m, 5.0, 0.01, **TIGHT)
    assert ("(compiled)" in res.stats["method"]) == (path == "compiled"), res.stats["method"]
    wn, zeta = np.sqrt(k / J), c / (2 * np.sqrt(k * J))
    wd = wn * np.sqrt(1 - zeta**2)
    th = res.spring_length("ts")
    assert np.max(np.abs(th - damped(res.time, 0.0, w0, wn, zeta))) < 1e-7
    assert np.max(np.abs(th)) > np.pi
    if path == "reference":
        assert len(element_state(res.system, "ts")["angle_ref"]) >= 2
    assert np.allclose(res.spring_velocity("ts"), damped_rate(res.time, 0.0, w0, wn, zeta), atol=1e-6)
    assert np.allclose(res.spring_force("ts"), k * th + c * res.spring_velocity("ts"))
    # frequency: zero crossings half a damped period apart
    zc = res.crossings(lambda r: r.spring_length("ts"), 0.0)
    assert np.allclose(np.diff(zc), np.pi / wd, rtol=0, atol=1e-9)
    # decay: successive maxima shrink by exp(-zeta wn Td)
    t1, a1 = res.maximum(lambda r: np.where(r.time < 2 * np.pi / wd, r.spring_length("ts"), -1))
    t2, a2 = res.maximum(lambda r: np.where((r.time > t1 + 1) & (r.time < t1 + 2 * np.pi / wd + 0.5),
                                            r.spring_length("ts"), -1))
    assert abs(t2 - t1 - 2 * np.pi / wd) < 1e-7
    assert abs(a2 / a1 - np.exp(-zeta * wn * 2 * np.pi / wd)) < 1e-8
    E = res.kinetic_energy() + res.potential_energy() + res.dissipated_energy()
    assert np.max(np.abs(E - E[0])) < 1e-8 * E[0]


def test_compiled_torsion_spring_matches_the_reference_path_through_several_turns(monkeypatch):
    """A pendulum spun through several turns against a torsion spring with free angle and preload, under
    gravity: the compiled joint-coordinate run and the event-driven reference run agree on the motion and
    on the spring's measures and potential energy past +-pi (the Result continues the angle the element
    reads), and neither run's energy monitor warns."""
    import warnings
    from mbdsim.results.diagnostics import MonitorWarning
    from mbdsim.solvers import dynamic

    def model():
        m = mb.Model(gravity=(0, -9.81, 0))
        m.add_body("rod", mass=1.2, inertia=(0.01, 0.1, 0.1), position=(0.5, 0, 0), angular_velocity=(0, 0, 25.0))
        m.add_revolute("pin", "ground", "rod", (0, 0, 0), (0, 0, 1))
        m.add_torsion_spring("ts", "pin", 0.4, 0.05, free_angle=0.3, preload=0.1)
        return m
    runs = {}
    for compiled in (True, False):
        monkeypatch.setattr(dynamic, "USE_COMPILED", compiled)
        with warnings.catch_warnings():
            warnings.simplefilter("error", MonitorWarning)
            r = mb.simulate(model(), 1.0, 0.02, method="dop853", rtol=1e-12)
        assert ("(compiled)" in r.stats["method"]) == compiled
        runs[compiled] = r
    a, b = runs[True], runs[False]
    assert np.max(np.abs(a.joint_coordinate("pin"))) > 4 * np.pi
    for f in (lambda r: r.joint_coordinate("pin"), lambda r: r.spring_length("ts"), lambda r: r.spring_force("ts"),
              lambda r: r.potential_energy()):
        assert np.max(np.abs(f(a) - f(b))) < 1e-8 * max(1.0, np.max(np.abs(f(b))))
    assert np.allclose(a.spring_length("ts"), a.joint_coordinate("pin"), rtol=0, atol=1e-12)


def test_torsion_spring_free_angle_and_preload_equilibrium():
    m, b, jt = rotor(kind="cylindrical")
    m.add_torsion_spring("ts", jt, 40.0, 1.0, free_angle=0.7, preload=-6.0)
    res = mb.equilibrium(m)
    # k (theta - free) + preload = 0
    assert abs(res.spring_length("ts")[0] - (0.7 + 6.0 / 40.0)) < 1e-9
    assert abs(res.spring_force("ts")[0]) < 1e-8


# --------------------------------------------------------------------------- bushing
def test_bushing_rotation_closed_form_large_angle():
    """About one axis the bushing's rotation vector is the angle itself: harmonic even at 1 rad."""
    Jz, kt = 0.25, 9.0
    m = mb.Model()
    b = m.add_body("b", 1.0, (1.0, 1.0, Jz), angular_velocity=(0, 0, 6.0))
    m.add_bushing("bush", m.ground.add_marker("g"), b.add_marker("m"), stiffness=(1e3, 1e3, 1e3, 1e2, 1e2, kt))
    res = mb.simulate(m, 2.0, 0.01, **TIGHT)
    w = np.sqrt(kt / Jz)
    A = res.orientation(b)
    ang = np.unwrap(np.arctan2(A[:, 1, 0], A[:, 0, 0]))
    assert np.max(np.abs(ang - 6.0 / w * np.sin(w * res.time))) < 1e-7


def test_bushing_energy_balance_3d():
    """Anisotropic translation, isotropic rotation (exactly conservative), damping, offset markers, gravity."""
    m = mb.Model(gravity=(0, 0, -9.81))
    b = m.add_body("b", 2.0, (0.1, 0.2, 0.3), position=(0.1, 0.2, -0.3),
                   velocity=(0.3, -0.2, 0.5), angular_velocity=(1.0, -2.0, 3.0))
    R = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1.0]])
    mi = m.ground.add_marker("mi", (0.0, 0.0, 0.1), R)
    mj = b.add_marker("mj", (0.15, 0.25, -0.2))
    m.add_bushing("bush", mi, mj, stiffness=(300, 500, 800, 20, 20, 20), damping=(2, 3, 4, 0.05, 0.05, 0.05),
                  preload=(1.0, -2.0, 3.0, 0, 0, 0))
    res = mb.simulate(m, 2.0, 0.01, **TIGHT)
    E = res.kinetic_energy() + res.potential_energy()
    D = res.dissipated_energy()
    assert D[-1] > 0.05 * E[0] - 0 and np.all(np.diff(D) >= -1e-15)
    assert np.max(np.abs(E + D - E[0])) < 1e-6 * np.max(np.abs(E))


def test_bushing_preload_equilibrium():
    m = mb.Model(gravity=(0, 0, -9.81))
    b = m.add_body("b", 2.0, (0.1, 0.1, 0.1))
    m.add_bushing("bush", (m.ground, (0, 0, 0)), (b, (0, 0, 0)), stiffness=(1e3, 1e3, 400, 50, 50, 50),
                  preload=(0, 0, 5.0, 0, 0, 0))
    res = mb.equilibrium(m)
    # -k z + F0 - m g = 0
    assert abs(res.position(b)[0, 2] - (5.0 - 2.0 * 9.81) / 400) < 1e-10


# --------------------------------------------------------------------------- stops
def _stop_contacts(res, path, name, jt, levels):
    """Times [s] the joint coordinate meets the stop's walls: the contact events of the reference path
    (located there as events), or the crossings of the walls on the compiled run's dense output."""
    if path == "reference":
        return np.array(element_state(res.system, name)["events"])
    return np.sort(np.concatenate([res.crossings(lambda r: r.joint_coordinate(jt), w) for w in levels]))


@pytest.mark.parametrize("path", ["compiled", "reference"])
def test_translational_bump_stop_linear_closed_form(path, monkeypatch):
    """Linear undamped stop: contact lasts half a period pi sqrt(m/k) and returns the speed reversed.
    Compiled: the stop is the IMPACT law of the joint slide in the step loop (no event at the walls);
    reference: wall contacts located as events."""
    from mbdsim.solvers import dynamic
    monkeypatch.setattr(dynamic, "USE_COMPILED", path == "compiled")
    mass, k, v0, gap = 2.0, 5e4, 1.5, 0.05
    m = mb.Model()
    b = m.add_body("slider", mass, (1, 1, 1), velocity=(v0, 0, 0))
    jt = m.add_translational("slide", m.ground, b, (0, 0, 0), (1, 0, 0))
    m.add_stop("bump", jt, upper=gap, stiffness=k, exponent=1.0, damping=0.0, penetration=1e-3)
    res = mb.simulate(m, 0.06, 0.001, **TIGHT)
    assert ("(compiled)" in res.stats["method"]) == (path == "compiled")
    ev = _stop_contacts(res, path, "bump", jt, [gap])
    t_on = gap / v0
    assert abs(ev[0] - t_on) < 1e-9
    assert abs(ev[1] - (t_on + np.pi * np.sqrt(mass / k))) < 1e-9
    after = res.at(0.06)
    assert abs(after.joint_velocity(jt)[0] + v0) < 1e-8
    x = res.at(t_on + 0.5 * np.pi * np.sqrt(mass / k))
    assert abs(x.joint_coordinate(jt)[0] - gap - v0 * np.sqrt(mass / k)) < 1e-9   # max penetration v0/w
    assert abs(x.spring_force("bump")[0] + k * v0 * np.sqrt(mass / k)) < 1e-5


def test_slide_stop_in_a_closed_loop_compiled_against_the_reference_path(monkeypatch):
    """A free slider-crank under gravity (a closed loop: absolute coordinates) whose slider hits a damped
    Hertzian end stop: the compiled run (the stop as IMPACT of the slide, in the step loop) and the
    event-driven reference run agree on the motion and on the stop's force, and the slider reaches the
    wall and comes back."""
    from mbdsim.solvers import dynamic

    def model():
        m = mb.Model(gravity=(0, -9.81, 0))
        crank = m.add_body("crank", 1.0, (1e-4, 1e-3, 1e-3), position=(0.05, 0, 0))
        rod = m.add_body("rod", 1.0, (1e-4, 7.5e-3, 7.5e-3), position=(0.25, 0, 0))
        slider = m.add_body("slider", 1.0, (1e-3, 1e-3, 1e-3), position=(0.4, 0, 0))
        m.add_revolute("pin", m.ground, crank, (0, 0, 0), (0, 0, 1), initial_velocity=-20.0)
        m.add_revolute("crank_rod", crank, rod, (0.1, 0, 0), (0, 0, 1))
        m.add_revolute("rod_slider", rod, slider, (0.4, 0, 0), (0, 0, 1))
        sl = m.add_translational("slide", m.ground, slider, (0.4, 0, 0), (1, 0, 0))
        m.add_stop("end", sl, lower=-0.05, stiffness=1e5, exponent=1.5, damping=50.0, penetration=1e-3)
        return m, sl
    runs = {}
    for compiled in (True, False):
        monkeypatch.setattr(dynamic, "USE_COMPILED", compiled)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")   # the planar loop of 3D revolutes: redundant rows (reported)
            r = mb.simulate(model()[0], 0.3, 0.002, method="dop853", rtol=1e-10, atol=1e-12)
        assert r.success and ("(compiled)" in r.stats["method"]) == compiled
        assert "joint coordinates" not in r.stats.get("formulation", "")
        runs[compiled] = r
    a, b = runs[True], runs[False]
    x = b.joint_coordinate("slide")
    assert x.min() < -0.05 and x[-1] > -0.05   # into the wall and back out
    assert np.max(np.abs(a.joint_coordinate("slide") - x)) < 1e-7
    assert np.max(np.abs(a.spring_force("end") - b.spring_force("end"))) < 1e-5 * np.max(np.abs(b.spring_force("end")))


@pytest.mark.parametrize("path", ["compiled", "reference"])
def test_revolute_two_sided_stop_period_and_energy(path, monkeypatch):
    """BISTOP on the tree's own angle (compiled) and the event-driven reference path."""
    from mbdsim.solvers import dynamic
    monkeypatch.setattr(dynamic, "USE_COMPILED", path == "compiled")
    J, k, w0, lo, hi = 0.5, 2e3, 3.0, -0.4, 0.3
    m, b, jt = rotor(J, w0)
    m.add_stop("limits", jt, lower=lo, upper=hi, stiffness=k, exponent=1.0, damping=0.0, penetration=1e-2)
    res = mb.simulate(m, 1.5, 0.005, **TIGHT)
    assert ("(compiled)" in res.stats["method"]) == (path == "compiled")
    half = np.pi * np.sqrt(J / k)
    period = (hi - lo) / w0 * 2 + 2 * half
    ev = _stop_contacts(res, path, "limits", jt, [lo, hi])
    expect = np.array([hi / w0, hi / w0 + half, hi / w0 + half + (hi - lo) / w0, hi / w0 + 2 * half + (hi - lo) / w0])
    assert np.allclose(ev[:4], expect, rtol=0, atol=1e-9)
    assert abs(ev[4] - ev[0] - period) < 1e-9
    E = res.kinetic_energy() + res.potential_energy()
    assert np.max(np.abs(E - E[0])) < 1e-8 * E[0]


def test_damped_stop_dissipates_and_balances():
    """Hertzian damped stop with gravity and a constant applied force: KE + PE + D = E0 + work."""
    m = mb.Model(gravity=(-9.81, 0, 0))
    b = m.add_body("slider", 1.0, (1, 1, 1), velocity=(2.0, 0, 0))
    jt = m.add_translational("slide", m.ground, b, (0, 0, 0), (1, 0, 0))
    m.add_stop("ends", jt, lower=-0.05, upper=0.02, stiffness=1e6, exponent=1.5, damping=200.0, penetration=1e-3)
    m.add_force("push", (b, (0, 0, 0)), (3.0, 0, 0))
    res = mb.simulate(m, 1.0, 0.002, **TIGHT)
    x = res.joint_coordinate(jt)
    E = res.kinetic_energy() + res.potential_energy()
    D = res.dissipated_energy()
    W = 3.0 * (x - x[0])
    assert D[-1] > 0.1 and np.all(np.diff(D) > -1e-12)
    assert np.max(np.abs(E + D - E[0] - W)) < 1e-6 * np.max(np.abs(E))
    assert np.min(x) > -0.05 - 0.01 and np.max(x) < 0.02 + 0.01


# --------------------------------------------------------------------------- potentials vs forces
def _gradient_check(model, q_shift=None, h=1e-6):
    """Generalized force of every conservative element = -dV/dx on the configuration manifold."""
    sys = assemble_system(model)
    q = sys.q0 if q_shift is None else increment(sys, sys.q0, q_shift)
    zero = np.zeros(sys.nv)
    for el in model.forces.values():
        ev = evaluator(el)
        Q = ev.generalized(sys, body_frames(sys, q, zero), el, 0.0, None)
        V = lambda qq: ev.potential(sys, body_frames(sys, qq[None], zero[None]), el)[0]  # noqa: E731
        grad = np.array([(V(increment(sys, q, h * e)) - V(increment(sys, q, -h * e))) / (2 * h)
                         for e in np.eye(sys.nv)])
        assert np.abs(Q).max() > 1e-3, f"{el.name} is not loaded in this configuration"
        assert np.allclose(Q, -grad, rtol=1e-6, atol=1e-7 * np.abs(Q).max()), el.name


def test_forces_are_gradients_of_potentials():
    m = mb.Model()
    a = m.add_body("a", 1.0, (1, 1, 1), position=(0.2, 0.1, 0.0))
    b = m.add_body("b", 1.0, (1, 1, 1), position=(0.5, 0.3, 0.2))
    c = m.add_body("c", 1.0, (1, 1, 1), position=(0.0, 0.0, -1.0))
    rev = m.add_revolute("rev", a, b, (0.3, 0.2, 0.1), (0.3, 0.4, 0.8))
    sl = m.add_translational("sl", m.ground, c, (0, 0, -1), (0.2, 0.1, 1))
    m.add_torsion_spring("ts", rev, 30.0, free_angle=0.2, preload=1.5)
    m.add_stop("st", rev, lower=0.05, upper=0.5, stiffness=1e3, exponent=1.7, penetration=0.01)
    m.add_stop("bump", sl, upper=-0.02, stiffness=5e4, exponent=1.3, penetration=0.01)
    m.add_bushing("bu", a.add_marker("ma", (0.25, 0.1, 0.0), np.eye(3)), b.add_marker("mb", (0.45, 0.3, 0.1)),
                  stiffness=(100, 200, 300, 40, 40, 40), preload=(1, 2, 3, 0, 0, 0))
    m.add_contact("ct", mb.Sphere(a, 0.3), mb.Sphere(b, 0.2), 1e4, 1.5, 0.0, 1e-3)
    m.add_contact("cp", mb.Plane(c, (0, 0, -0.25), (0.1, 0, 1)), mb.Sphere(a, 0.3), 1e4, 2.2, 0.0, 1e-3)
    # every element is loaded near the initial configuration (stops and contacts penetrated)
    dx = np.random.default_rng(3).normal(scale=0.01, size=assemble_system(m).nv)
    _gradient_check(m, dx)


# --------------------------------------------------------------------------- state-dependent loads
def test_pd_controller_through_state():
    J, kp, kd, target = 0.2, 20.0, 1.2, 0.3
    m, b, jt = rotor(J)
    m.add_torque("pd", b, lambda t, s: (0, 0, -kp * (s.joint_coordinate(jt) - target) - kd * s.joint_velocity(jt)))
    res = mb.simulate(m, 2.0, 0.01, **TIGHT)
    wn, zeta = np.sqrt(kp / J), kd / (2 * np.sqrt(kp * J))
    assert np.max(np.abs(res.joint_coordinate(jt) - target - damped(res.time, -target, 0.0, wn, zeta))) < 1e-7


def test_aerodynamic_drag_through_state():
    mass, c, v0 = 2.0, 0.5, 10.0
    m = mb.Model()
    p = m.add_particle("p", mass, velocity=(v0, 0, 0))
    m.add_force("drag", (p, (0, 0, 0)), lambda t, s: -c * np.linalg.norm(s.velocity(p)) * s.velocity(p))
    res = mb.simulate(m, 2.0, 0.01, **TIGHT)
    x = res.position(p)[:, 0]
    assert np.max(np.abs(x - mass / c * np.log1p(c * v0 * res.time / mass))) < 1e-8


# --------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("call, entity, field", [
    (lambda m, jt, b: m.add_torsion_spring("t", "nope", 1.0), "torsion spring 't'", "joint"),
    (lambda m, jt, b: m.add_torsion_spring("t", jt, -1.0), "torsion spring 't'", "stiffness"),
    (lambda m, jt, b: m.add_torsion_spring("t", jt, 1.0, damping="x"), "torsion spring 't'", "damping"),
    (lambda m, jt, b: m.add_torsion_spring("t", m.joints["sl"], 1.0), "torsion spring 't'", "joint"),
    (lambda m, jt, b: m.add_bushing("u", (m.ground, (0, 0, 0)), (b, (0, 0, 0)), stiffness=(1, 2, 3)),
     "bushing 'u'", "stiffness"),
    (lambda m, jt, b: m.add_bushing("u", (m.ground, (0, 0, 0)), (b, (0, 0, 0)), damping=(1, 1, 1, 1, -1, 1)),
     "bushing 'u'", "damping[4]"),
    (lambda m, jt, b: m.add_bushing("u", (b, (0, 0, 0)), (b, (1, 0, 0))), "bushing 'u'", "marker_j"),
    (lambda m, jt, b: m.add_bushing("u", "b", (b, (1, 0, 0))), "bushing 'u'", "marker_i"),
    (lambda m, jt, b: m.add_stop("s", jt, stiffness=1.0), "stop 's'", "lower"),
    (lambda m, jt, b: m.add_stop("s", jt, lower=1.0, upper=0.5, stiffness=1.0), "stop 's'", "upper"),
    (lambda m, jt, b: m.add_stop("s", jt, upper=0.5), "stop 's'", "stiffness"),
    (lambda m, jt, b: m.add_stop("s", jt, upper=0.5, stiffness=1.0, penetration=0.0), "stop 's'", "penetration"),
    (lambda m, jt, b: m.add_stop("s", jt, upper=0.5, stiffness=1.0, dof="translation"), "stop 's'", "dof"),
    (lambda m, jt, b: m.add_stop("s", m.joints["sph"], upper=0.5, stiffness=1.0), "stop 's'", "joint"),
])
def test_bad_input_names_entity_and_field(call, entity, field):
    m = mb.Model()
    b = m.add_body("b", 1.0, (1, 1, 1))
    c = m.add_body("c", 1.0, (1, 1, 1))
    d = m.add_body("d", 1.0, (1, 1, 1))
    jt = m.add_revolute("rev", m.ground, b, (0, 0, 0), (0, 0, 1))
    m.add_translational("sl", m.ground, c, (0, 0, 0), (0, 0, 1))
    m.add_spherical("sph", m.ground, d, (0, 0, 0))
    n = len(m.forces)
    with pytest.raises(mb.ModelError) as err:
        call(m, jt, b)
    assert err.value.entity == entity and err.value.field == field
    assert len(m.forces) == n


def test_duplicate_element_name_rejected():
    m, b, jt = rotor()
    m.add_torsion_spring("t", jt, 1.0)
    with pytest.raises(mb.ModelError) as err:
        m.add_stop("t", jt, upper=1.0, stiffness=1.0)
    assert err.value.field == "name"
