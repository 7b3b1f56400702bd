"""Issue 3 contact: sphere-plane and sphere-sphere with the Adams IMPACT law, events, friction, energy."""
import numpy as np
import pytest

import mbdsim as mb
from mbdsim.functions import impact
from mbdsim.system.force_elements._common import element_state
from mbdsim.system.force_elements.contact import normal_force

TIGHT = dict(method="dop853", rtol=1e-11, atol=1e-13)
G = 9.81
PATHS = pytest.mark.parametrize("path", ["compiled", "reference"])


def _use(path, monkeypatch):
    """Run on the compiled core (the contact law in the step loop, no events at onset and separation) or
    on the event-driven reference path (onset and separation located as events)."""
    from mbdsim.solvers import dynamic
    monkeypatch.setattr(dynamic, "USE_COMPILED", path == "compiled")


def _contact_times(res, path, name):
    """Onsets and separations [s]: the reference path's events, or the gap's zero crossings located on
    the compiled run's dense output."""
    assert ("(compiled)" in res.stats["method"]) == (path == "compiled"), res.stats["method"]
    if path == "reference":
        return list(element_state(res.system, name)["events"])
    return list(res.crossings(lambda r: r.spring_length(name), 0.0))


def ball_on_floor(h=0.3, R=0.05, mass=1.0, k=1e5, e=1.5, c=20.0, mu=0.0, v=(0, 0, 0), w=(0, 0, 0), vs=1e-2,
                  particle=False):
    m = mb.Model(gravity=(0, 0, -G))
    if particle:
        ball = m.add_particle("ball", mass, position=(0, 0, R + h), velocity=v)
    else:
        ball = m.add_body("ball", mass, (0.4 * mass * R * R,) * 3, position=(0, 0, R + h), velocity=v,
                          angular_velocity=w)
    m.add_contact("floor", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), mb.Sphere(ball, R), k, e, c, 1e-3,
                  mu=mu, friction_velocity=vs)
    return m, ball


def test_normal_force_is_the_adams_impact_function():
    el = ball_on_floor()[0].forces["floor"]
    g = np.linspace(-3e-3, 1e-3, 41)
    for gd in (-2.0, -0.1, 0.0, 0.05, 3.0):
        ref = impact(g, np.full_like(g, gd), 0.0, el.stiffness, el.exponent, el.damping, el.penetration)
        assert np.allclose(normal_force(el, g, np.full_like(g, gd)), ref, rtol=1e-13, atol=1e-12)


# --------------------------------------------------------------------------- must-show 5
@PATHS
def test_ball_drop_onset_time_and_rebounds(path, monkeypatch):
    _use(path, monkeypatch)
    h = 0.3
    m, ball = ball_on_floor(h=h)
    res = mb.simulate(m, 1.2, 0.002, **TIGHT)
    assert res.success
    t_fall = np.sqrt(2 * h / G)
    events = _contact_times(res, path, "floor")
    assert abs(events[0] - t_fall) < 1e-9                      # onset (an event on the reference path)
    gap = res.crossings(lambda r: r.spring_length("floor"), 0.0)
    assert abs(gap[0] - t_fall) < 1e-9 and len(events) >= 6    # several bounces, onset + separation each
    assert np.allclose(gap[:len(events)], events[:len(gap)], rtol=0, atol=1e-9)
    # apex heights between contacts: monotone decrease, never above the drop height (no energy gain)
    z = lambda r: r.position(ball)[:, 2]  # noqa: E731
    apex = []
    for a, b in zip(events[1::2], events[2::2]):
        t_apex, z_apex = res.maximum(lambda r: np.where((r.time > a) & (r.time < b), z(r), -1.0))
        apex.append(z_apex - 0.05)
    assert len(apex) >= 2 and apex[0] < h and np.all(np.diff(apex) < 0)
    # restitution from the energy dissipated in each contact
    D = res.dissipated_energy()
    E = res.kinetic_energy() + res.potential_energy()
    assert np.max(np.abs(E + D - E[0])) < 1e-7 * E[0]
    assert np.all(np.diff(D) > -1e-12)


@PATHS
def test_undamped_contact_conserves_energy_and_rebounds_to_drop_height(path, monkeypatch):
    _use(path, monkeypatch)
    h = 0.3
    m, ball = ball_on_floor(h=h, c=0.0)
    res = mb.simulate(m, 2 * np.sqrt(2 * h / G) + 0.06, 0.002, **TIGHT)
    E = res.kinetic_energy() + res.potential_energy()
    assert np.max(np.abs(E - E[0])) < 1e-9 * E[0]
    events = _contact_times(res, path, "floor")
    t_apex, z_apex = res.maximum(lambda r: np.where(r.time > events[1], r.position(ball)[:, 2], -1.0))
    assert abs(z_apex - (h + 0.05)) < 1e-8


@PATHS
def test_linear_contact_duration_closed_form(path, monkeypatch):
    """e = 1, no damping, no gravity: half a period pi sqrt(m/k) in contact, speed reversed."""
    _use(path, monkeypatch)
    mass, k, v0 = 0.5, 2e4, 1.2
    m = mb.Model()
    p = m.add_particle("p", mass, position=(0.1, 0.2, 0.06), velocity=(0, 0, -v0))
    m.add_contact("c", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), mb.Sphere(p, 0.05), k, 1.0, 0.0, 1e-3)
    res = mb.simulate(m, 0.05, 0.001, **TIGHT)
    ev = _contact_times(res, path, "c")
    assert abs(ev[0] - 0.01 / v0) < 1e-9
    assert abs(ev[1] - ev[0] - np.pi * np.sqrt(mass / k)) < 1e-9
    assert np.allclose(res.at(0.05).velocity(p)[0], (0, 0, v0), atol=1e-9)


@PATHS
def test_sphere_sphere_elastic_exchange(path, monkeypatch):
    """Equal spheres, head-on, linear undamped contact: velocities exchange; duration pi sqrt(m_red/k)."""
    _use(path, monkeypatch)
    mass, k, v0, R = 1.0, 1e4, 2.0, 0.1
    m = mb.Model()
    a = m.add_body("a", mass, (0.004,) * 3, position=(0, 0, 0), velocity=(v0, 0, 0))
    b = m.add_body("b", mass, (0.004,) * 3, position=(0.3, 0, 0))
    m.add_contact("c", mb.Sphere(a, R), mb.Sphere(b, R), k, 1.0, 0.0, 1e-3)
    res = mb.simulate(m, 0.1, 0.001, **TIGHT)
    ev = _contact_times(res, path, "c")
    assert abs(ev[0] - 0.1 / v0) < 1e-9
    assert abs(ev[1] - ev[0] - np.pi * np.sqrt(0.5 * mass / k)) < 1e-9
    end = res.at(0.1)
    assert np.allclose(end.velocity(a)[0], 0, atol=1e-9) and np.allclose(end.velocity(b)[0], (v0, 0, 0), atol=1e-9)
    assert np.allclose(res.spring_force("c")[res.time < ev[0]], 0.0)


@PATHS
def test_sliding_sphere_ends_rolling_at_five_sevenths(path, monkeypatch):
    """Thrown without spin on a rough floor: angular momentum about the contact line is conserved, so
    the final rolling speed is v0 / (1 + I / (m R'^2)) with R' the centre-to-contact-point distance."""
    _use(path, monkeypatch)
    R, mass, k, v0 = 0.05, 1.0, 1e5, 1.0
    delta = mass * G / k                      # static penetration of the linear contact
    m = mb.Model(gravity=(0, 0, -G))
    ball = m.add_body("ball", mass, (0.4 * mass * R * R,) * 3, position=(0, 0, R - delta), velocity=(v0, 0, 0))
    m.add_contact("floor", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), mb.Sphere(ball, R), k, 1.0, 5.0, 1e-3,
                  mu=0.3, friction_velocity=1e-2)
    res = mb.simulate(m, 0.3, 0.005, **TIGHT)
    assert ("(compiled)" in res.stats["method"]) == (path == "compiled")
    Rp = R - delta / 2
    v_end = res.velocity(ball)[-1, 0]
    assert abs(v_end - v0 / (1 + 0.4 * R**2 / Rp**2)) < 1e-6
    # while sliding the friction decelerates at mu g (to within the regularisation)
    a = np.gradient(res.velocity(ball)[:, 0], res.time)[2:10]
    assert np.allclose(a, -0.3 * G, rtol=1e-3)


# --------------------------------------------------------------------------- must-show 6
@PATHS
def test_energy_balance_damped_frictional_contacting_model(path, monkeypatch):
    """Spinning ball thrown at a tilted plane with damping and friction, plus a bushing-tethered second
    ball hitting it and a constant applied force: KE + PE + dissipated = E0 + work of the force."""
    _use(path, monkeypatch)
    m = mb.Model(gravity=(0, 0, -G))
    R = 0.05
    ball = m.add_body("ball", 1.0, (1e-3,) * 3, position=(0, 0, 0.15), velocity=(0.8, 0.2, 0),
                      angular_velocity=(5.0, -20.0, 3.0))
    other = m.add_body("other", 0.5, (5e-4,) * 3, position=(0.12, 0.0, 0.2))
    m.add_contact("floor", mb.Plane(m.ground, (0, 0, 0), (0.05, 0.0, 1.0)), mb.Sphere(ball, R),
                  1e5, 1.5, 30.0, 1e-3, mu=0.4, friction_velocity=1e-2)
    m.add_contact("balls", mb.Sphere(ball, R), mb.Sphere(other, 0.04), 5e4, 1.5, 10.0, 1e-3, mu=0.2,
                  friction_velocity=1e-2)
    m.add_bushing("tether", (m.ground, (0.12, 0.0, 0.2)), (other, (0.12, 0.0, 0.2)),
                  stiffness=(400, 400, 400, 0.5, 0.5, 0.5), damping=(0.5, 0.5, 0.5, 1e-3, 1e-3, 1e-3))
    F = np.array([0.5, 0.0, 1.0])
    m.add_force("push", (ball, (0, 0, 0.15)), F)
    res = mb.simulate(m, 0.6, 0.002, method="dop853", rtol=1e-10, atol=1e-12)
    assert res.success
    assert len(_contact_times(res, path, "floor")) >= 2
    assert len(_contact_times(res, path, "balls")) >= 2
    W = (res.position(ball) - res.position(ball)[0]) @ F
    E = res.kinetic_energy() + res.potential_energy()
    D = res.dissipated_energy()
    scale = np.max(np.abs(E))
    assert D[-1] > 0.01 * scale
    assert np.max(np.abs(E + D - E[0] - W)) < 1e-6 * scale


def test_energy_balance_joint_friction_stop_and_contact_on_moving_body():
    """Block sliding down an incline with Coulomb joint friction into a damped Hertzian end stop, while a
    spinning ball bounces on its top face (contact between two moving bodies, with friction)."""
    a = np.radians(20.0)
    down = np.array([np.cos(a), 0.0, -np.sin(a)])
    m = mb.Model(gravity=(0, 0, -G))
    block = m.add_body("block", 2.0, (0.02, 0.03, 0.04), velocity=tuple(0.5 * down))
    sl = m.add_translational("slide", m.ground, block, (0, 0, 0), tuple(down))
    m.add_friction("fr", sl, 0.25, 0.2, preload=0.5)
    m.add_stop("end", sl, upper=0.3, stiffness=1e6, exponent=1.5, damping=300.0, penetration=1e-3)
    ball = m.add_body("ball", 0.2, (2e-4,) * 3, position=(0.0, 0, 0.25), velocity=(0.1, 0, 0),
                      angular_velocity=(0, 4, 0))
    m.add_contact("hit", mb.Plane(block, (0, 0, 0.05), (0, 0, 1)), mb.Sphere(ball, 0.03), 1e5, 1.5, 10.0, 1e-3,
                  mu=0.3, friction_velocity=1e-2)
    res = mb.simulate(m, 0.8, 0.002, method="dop853", rtol=1e-10, atol=1e-12)
    assert res.success
    for name, n in (("end", 2), ("hit", 4)):   # stop hits and bounces: onsets of the element's force
        on = np.abs(res.spring_force(name)) > 0.0
        assert np.count_nonzero(on[1:] & ~on[:-1]) >= n, name
    E = res.kinetic_energy() + res.potential_energy()
    D = res.dissipated_energy()
    assert D[-1] > E[0]                                       # gravity work was dissipated too
    assert np.max(np.abs(E + D - E[0])) < 1e-6 * np.max(np.abs(E))
    assert abs(res.joint_velocity(sl)[-1]) < 1e-9             # stuck against the stop at the end


# --------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("make, field", [
    (lambda m, a, b: (mb.Plane(a, (0, 0, 0), (0, 0, 1)), mb.Plane(b, (0, 0, 0), (0, 0, 1))), "shape_j"),
    (lambda m, a, b: (mb.Sphere(a, 0.1), mb.Sphere(a, 0.2)), "shape_j"),
    (lambda m, a, b: (a, mb.Sphere(b, 0.2)), "shape_i"),
    (lambda m, a, b: (mb.Sphere(mb.Model().add_body("x", 1.0), 0.1), mb.Sphere(b, 0.2)), "shape_i"),
    (lambda m, a, b: (mb.Sphere(a, 0.1), mb.Plane(m.bodies["p"], (0, 0, 0), (0, 0, 1))), "shape_j"),
])
def test_bad_shapes(make, field):
    m = mb.Model()
    a = m.add_body("a", 1.0, (1, 1, 1))
    b = m.add_body("b", 1.0, (1, 1, 1))
    m.add_particle("p", 1.0)
    si, sj = make(m, a, b)
    with pytest.raises(mb.ModelError) as err:
        m.add_contact("c", si, sj, 1e4, 1.5, 1.0, 1e-3)
    assert err.value.entity == "contact 'c'" and err.value.field == field
    assert "c" not in m.forces


@pytest.mark.parametrize("kw, field", [
    (dict(stiffness=-1.0), "stiffness"), (dict(exponent=0.0), "exponent"), (dict(damping=-2.0), "damping"),
    (dict(penetration=0.0), "penetration"), (dict(mu=-0.1), "mu"), (dict(friction_velocity=0.0), "friction_velocity"),
    (dict(stiffness="stiff"), "stiffness"),
])
def test_bad_contact_parameters(kw, field):
    m = mb.Model()
    a = m.add_body("a", 1.0, (1, 1, 1))
    args = dict(stiffness=1e4, exponent=1.5, damping=1.0, penetration=1e-3)
    args.update(kw)
    with pytest.raises(mb.ModelError) as err:
        m.add_contact("c", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), mb.Sphere(a, 0.1), **args)
    assert err.value.entity == "contact 'c'" and err.value.field == field


def test_bad_shape_geometry():
    with pytest.raises(mb.ModelError) as err:
        mb.Sphere("a", -0.1)
    assert err.value.field == "radius"
    with pytest.raises(mb.ModelError) as err:
        mb.Plane("a", (0, 0, 0), (0, 0, 0))
    assert err.value.field == "normal"
    with pytest.raises(mb.ModelError) as err:
        mb.Sphere("a", 0.1, center=(0, 1))
    assert err.value.field == "center"
