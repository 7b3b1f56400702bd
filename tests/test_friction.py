"""Coulomb joint friction with event-driven stick/slip, against closed forms (issue 3, must-show 3)."""
from __future__ import annotations

import numpy as np
import pytest

import mbdsim as mb

G = 9.81


def incline(theta_deg, v0, mu_s=0.4, mu_d=0.4, rigid=False, mass=50.0):
    """Block on a translational joint down the slope (cos, -sin, 0); joint coordinate = distance down."""
    th = np.radians(theta_deg)
    down = np.array([np.cos(th), -np.sin(th), 0.0])
    m = mb.Model("incline", gravity=(0, -G, 0))
    if rigid:
        block = m.add_body("block", mass, (0.5, 0.8, 0.6), velocity=v0 * down)
    else:
        block = m.add_particle("block", mass, velocity=v0 * down)
    joint = m.add_translational("slope", m.ground, block, (0, 0, 0), down)
    m.add_friction("friction", joint, mu_s, mu_d)
    return m, joint


def run(model, end, step=0.01):
    res = mb.simulate(model, end, output_step=step, method="dop853")
    assert res.success, res.message
    return res


# ----------------------------------------------------------------------------- must-show 3
@pytest.mark.parametrize("rigid", [False, True], ids=["particle", "rigid"])
def test_block_stops_where_v2_2as_predicts_and_stays(rigid):
    mu, v0 = 0.4, 7.0
    a = G * (np.sin(np.radians(15)) - mu * np.cos(np.radians(15)))      # < 0: decelerates
    t_stop, x_stop = -v0 / a, -v0**2 / (2 * a)
    model, joint = incline(15, v0, mu, mu, rigid)
    res = run(model, 8.0)
    ev = res.friction_events("friction")
    assert [m for _, m, _ in ev] == ["slip", "stick"]
    assert ev[1][0] == pytest.approx(t_stop, rel=1e-9)
    x = res.joint_coordinate(joint)
    assert float(res.at(ev[1][0]).joint_coordinate(joint)[0]) == pytest.approx(x_stop, rel=1e-9)
    after = res.time > ev[1][0]
    assert np.all(np.abs(x[after] - x_stop) < 1e-9 * x_stop)            # stays stopped
    assert np.all(np.abs(res.joint_velocity(joint)[after]) < 1e-12)
    before = res.time < ev[1][0] - 1e-3
    assert np.allclose(res.joint_acceleration(joint)[before], a, rtol=1e-9)
    # sliding: mu_d N against the motion; stuck: the static friction carries m g sin
    F = res.friction_force("friction")
    assert np.allclose(F[before], -mu * 50 * G * np.cos(np.radians(15)), rtol=1e-12)
    assert np.allclose(F[after], -50 * G * np.sin(np.radians(15)), rtol=1e-9)


def test_sliding_at_30_deg_has_the_closed_form_acceleration():
    mu = 0.4
    a = G * (np.sin(np.radians(30)) - mu * np.cos(np.radians(30)))
    for v0 in (0.0, 2.0):     # released at rest (breaks away at once) or projected
        model, joint = incline(30, v0, mu, mu, rigid=True)
        res = run(model, 2.0, 0.05)
        assert [m for _, m, _ in res.friction_events("friction")] == ["slip"]
        assert np.allclose(res.joint_acceleration(joint), a, rtol=1e-6, atol=0)
        assert np.allclose(res.at([0.5, 1.7]).joint_acceleration(joint), a, rtol=1e-6, atol=0)
        assert res.joint_coordinate(joint)[-1] == pytest.approx(v0 * 2 + 0.5 * a * 4, rel=1e-6)


@pytest.mark.parametrize("rigid", [False, True], ids=["particle", "rigid"])
def test_block_at_rest_below_the_friction_angle_does_not_creep(rigid):
    model, joint = incline(15, 0.0, 0.4, 0.3, rigid, mass=2.0)
    res = run(model, 10.0, 0.1)
    assert [m for _, m, _ in res.friction_events("friction")] == ["stick"]
    assert np.max(np.abs(res.joint_coordinate(joint))) < 1e-6
    assert np.max(np.abs(res.joint_coordinate(joint))) < 1e-12      # in fact: position-level lock
    assert np.allclose(res.friction_force("friction"), -2.0 * G * np.sin(np.radians(15)), rtol=1e-9)


def test_block_thrown_up_the_slope_stops_then_slides_back():
    th, mu, v0 = np.radians(30), 0.4, 5.0
    model, joint = incline(30, -v0, mu, mu)
    res = run(model, 2.0)
    ev = res.friction_events("friction")
    assert [(m, d) for _, m, d in ev] == [("slip", -1.0), ("slip", 1.0)]
    assert ev[1][0] == pytest.approx(v0 / (G * (np.sin(th) + mu * np.cos(th))), rel=1e-9)
    late = res.time > ev[1][0] + 1e-3
    assert np.allclose(res.joint_acceleration(joint)[late], G * (np.sin(th) - mu * np.cos(th)), rtol=1e-9)


# ----------------------------------------------------------------------------- normal load models
def test_bending_moment_of_the_friction_force_raises_the_normal_load():
    """Rail along x, joint point a distance d below the CM, effective_length L: the friction force
    mu N at the joint point needs a reaction moment d mu N, so N = m g + d mu N / L (coupled through
    the multipliers) -> deceleration mu g / (1 - mu d / L)."""
    mass, mu, d, L, v0 = 3.0, 0.3, 0.1, 0.2, 4.0
    m = mb.Model("rail", gravity=(0, -G, 0))
    car = m.add_body("car", mass, (0.1, 0.1, 0.1), position=(0, d, 0), velocity=(v0, 0, 0))
    rail = m.add_translational("rail", m.ground, car, (0, 0, 0), (1, 0, 0))
    m.add_friction("friction", rail, mu, mu, effective_length=L)
    res = run(m, 3.0)
    a = mu * G / (1 - mu * d / L)
    t_stop = res.friction_events("friction")[1][0]
    assert t_stop == pytest.approx(v0 / a, rel=1e-9)
    sliding = res.time < t_stop - 1e-3
    assert np.allclose(res.joint_acceleration(rail)[sliding], -a, rtol=1e-9)
    assert np.allclose(res.friction_force("friction")[sliding], -mass * a, rtol=1e-9)


def test_revolute_friction_decelerates_a_spinning_wheel_and_holds_it():
    mass, Izz, r, mu_s, mu_d, w0 = 3.0, 0.05, 0.02, 0.3, 0.2, 10.0
    m = mb.Model("wheel", gravity=(0, -G, 0))
    wheel = m.add_body("wheel", mass, (0.03, 0.03, Izz), angular_velocity=(0, 0, w0))
    pin = m.add_revolute("pin", m.ground, wheel, (0, 0, 0), (0, 0, 1))
    m.add_friction("friction", pin, mu_s, mu_d, pin_radius=r)
    res = run(m, 6.0)
    alpha = mu_d * mass * G * r / Izz         # radial load m g through the pin of radius r
    ev = res.friction_events("friction")
    assert [m_ for _, m_, _ in ev] == ["slip", "stick"]
    assert ev[1][0] == pytest.approx(w0 / alpha, rel=1e-9)
    th = res.joint_coordinate(pin)
    after = res.time > ev[1][0]
    assert np.allclose(th[after], w0**2 / (2 * alpha), rtol=1e-9)
    assert np.all(np.abs(res.joint_velocity(pin)[after]) < 1e-12)
    sliding = res.time < ev[1][0] - 1e-3
    assert np.allclose(res.friction_force("friction")[sliding], -mu_d * mass * G * r, rtol=1e-12)
    # energy: kinetic + dissipated = initial (friction power integrated on the dense output)
    E = res.kinetic_energy() + res.dissipated_energy()
    assert np.max(np.abs(E - E[0])) < 1e-9 * E[0]


def test_thrust_load_on_a_tilted_axle():
    """Axle tilted by beta from the vertical: radial load m g sin(beta) on the pin radius and axial
    load m g cos(beta) on the friction arm -> torque mu m g (r sin + arm cos)."""
    mass, Izz, r, arm, mu, w0, beta = 2.0, 0.04, 0.01, 0.03, 0.25, 8.0, np.radians(35)
    axis = np.array([np.sin(beta), np.cos(beta), 0.0])
    m = mb.Model("axle", gravity=(0, -G, 0))
    rotor = m.add_body("rotor", mass, (Izz, Izz, Izz), angular_velocity=w0 * axis)
    pin = m.add_revolute("pin", m.ground, rotor, (0, 0, 0), axis)
    m.add_friction("friction", pin, mu, mu, pin_radius=r, friction_arm=arm)
    res = run(m, 1.0, 0.05)
    T = mu * mass * G * (r * np.sin(beta) + arm * np.cos(beta))
    assert np.allclose(res.friction_force("friction"), -T, rtol=1e-12)
    assert np.allclose(res.joint_acceleration(pin), -T / Izz, rtol=1e-9)


@pytest.mark.parametrize("factor, moves", [(0.9, False), (1.5, True)])
def test_breakaway_under_a_ramped_torque(factor, moves):
    mass, Izz, r, mu_s, mu_d = 3.0, 0.05, 0.02, 0.3, 0.2
    T_s = mu_s * mass * G * r
    m = mb.Model("wheel", gravity=(0, -G, 0))
    wheel = m.add_body("wheel", mass, (0.03, 0.03, Izz))
    pin = m.add_revolute("pin", m.ground, wheel, (0, 0, 0), (0, 0, 1))
    m.add_friction("friction", pin, mu_s, mu_d, pin_radius=r)
    slope = factor * T_s        # torque = slope * t up to t = 1 s
    m.add_torque("drive", wheel, lambda t, s: (0, 0, slope * min(t, 1.0)))
    res = run(m, 2.0)
    ev = res.friction_events("friction")
    if not moves:
        assert [e[1] for e in ev] == ["stick"] and np.max(np.abs(res.joint_coordinate(pin))) < 1e-12
        return
    assert [e[1] for e in ev] == ["stick", "slip"]
    assert ev[1][0] == pytest.approx(T_s / slope, rel=1e-8)
    t = res.time[res.time > 1.0]
    acc = res.at(t).joint_acceleration(pin)
    assert np.allclose(acc, (slope - mu_d * mass * G * r) / Izz, rtol=1e-9)


def test_energy_balance_of_a_sliding_and_sticking_block():
    model, joint = incline(15, 7.0, 0.4, 0.4)
    res = run(model, 8.0, 0.05)
    E = res.kinetic_energy() + res.potential_energy()
    D = res.dissipated_energy()
    assert D[-1] > 0.9 * (E[0] - E[-1])
    assert np.max(np.abs(E + D - E[0])) < 1e-9 * abs(res.kinetic_energy()[0])


# ----------------------------------------------------------------------------- input and methods
def test_bad_input_names_entity_and_field():
    m = mb.Model("bad")
    a = m.add_body("a", 1.0, (1, 1, 1))
    b = m.add_body("b", 1.0, (1, 1, 1))
    rev = m.add_revolute("rev", m.ground, a, (0, 0, 0), (0, 0, 1))
    tr = m.add_translational("tr", a, b, (0, 0, 0), (1, 0, 0))
    sph = m.add_spherical("sph", m.ground, b, (1, 0, 0))
    cases = [
        (lambda: m.add_friction("f", sph, 0.3, 0.2), "joint"),
        (lambda: m.add_friction("f", "nojoint", 0.3, 0.2), "joint"),
        (lambda: m.add_friction("f", tr, -0.1, 0.0), "mu_static"),
        (lambda: m.add_friction("f", tr, 0.3, "x"), "mu_dynamic"),
        (lambda: m.add_friction("f", tr, 0.2, 0.3), "mu_dynamic"),
        (lambda: m.add_friction("f", tr, 0.3, 0.2, pin_radius=0.1), "pin_radius"),
        (lambda: m.add_friction("f", tr, 0.3, 0.2, effective_length=0.0), "effective_length"),
        (lambda: m.add_friction("f", rev, 0.3, 0.2), "pin_radius"),
        (lambda: m.add_friction("f", rev, 0.3, 0.2, pin_radius=-1), "pin_radius"),
        (lambda: m.add_friction("f", rev, 0.3, 0.2, pin_radius=0.1, reaction_arm=1), "reaction_arm"),
    ]
    for make, field in cases:
        with pytest.raises(mb.ModelError) as err:
            make()
        assert err.value.field == field and "friction 'f'" in err.value.entity, (err.value, field)
    m.add_friction("f", rev, 0.3, 0.2, pin_radius=0.1)        # the failed attempts did not claim the name
    with pytest.raises(mb.ModelError) as err:
        m.add_friction("f", tr, 0.3, 0.2)
    assert err.value.field == "name"


def test_methods_without_stick_slip_logic_refuse_friction():
    model, _ = incline(15, 0.0)
    with pytest.raises(mb.ModelError) as err:
        mb.equilibrium(model)
    assert err.value.field == "method" and "dop853" in str(err.value)


def test_one_friction_per_joint_and_none_on_driven_joints():
    m = mb.Model("driven")
    a = m.add_body("a", 1.0, (1, 1, 1))
    rev = m.add_revolute("rev", m.ground, a, (0, 0, 0), (0, 0, 1))
    m.add_friction("f1", rev, 0.3, 0.2, pin_radius=0.01)
    with pytest.raises(mb.ModelError) as err:
        m.add_friction("f2", rev, 0.3, 0.2, pin_radius=0.01)
    assert err.value.field == "joint" and "f1" in str(err.value)
    m.add_motion("spin", rev, velocity=1.0)
    with pytest.raises(mb.ModelError) as err:
        mb.simulate(m, 1.0, method="dop853")
    assert err.value.field == "joint" and "spin" in str(err.value)


@pytest.mark.parametrize("method", ["rk45", "radau", "bdf"])
def test_other_index1_methods_locate_the_stop(method):
    mu, v0 = 0.4, 7.0
    a = G * (np.sin(np.radians(15)) - mu * np.cos(np.radians(15)))
    model, joint = incline(15, v0, mu, mu)
    res = mb.simulate(model, 8.0, output_step=0.05, method=method)
    ev = res.friction_events("friction")
    assert [e[1] for e in ev] == ["slip", "stick"]
    assert ev[1][0] == pytest.approx(-v0 / a, rel=1e-6)
    assert res.joint_coordinate(joint)[-1] == pytest.approx(-v0**2 / (2 * a), rel=1e-6)


def test_default_method_with_friction_is_the_event_driven_dop853(monkeypatch):
    """mb.simulate without a method picks dop853 for stick/slip friction; an explicit 'hht' runs the
    compiled HHT (its events on the steps' polynomials, issue 29), and where the compiled core is off
    (the reference HHT has no stick/slip events) it is refused, naming the methods that can."""
    model, joint = incline(15, 0.0)
    res = mb.simulate(model, 0.5, 0.1)
    assert res.success and res.stats["method"].startswith("auto: DOP853")   # the automatic method falls back to it
    res = mb.simulate(model, 0.5, 0.1, method="hht")
    assert res.success and res.stats["method"] == "HHT (compiled)"
    assert np.max(np.abs(res.joint_coordinate(joint))) < 1e-12   # tan(15 deg) = 0.27 < mu_s = 0.4: held
    from mbdsim.solvers import dynamic
    monkeypatch.setattr(dynamic, "USE_COMPILED", False)
    with pytest.raises(mb.ModelError) as err:
        mb.simulate(model, 0.5, 0.1, method="hht")
    assert err.value.field == "method" and "dop853" in str(err.value)
