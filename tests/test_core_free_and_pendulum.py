"""Core engine, must-show 1 and 2: particle free flight and the rigid rod pendulum (closed forms)."""
import numpy as np
import pytest
from scipy.special import ellipk

import mbdsim as mb

G = 9.81


# ----------------------------------------------------------------------------- 1. free flight
def test_particle_free_flight_is_exact():
    """r(t) = r0 + v0 t + g t^2 / 2 and v(t) = v0 + g t to 1e-9 (dop853 integrates a quadratic exactly)."""
    g = np.array([0.0, -G, 0.0])
    r0, v0 = np.array([1.0, 2.0, -3.0]), np.array([3.0, 25.0, -1.0])
    model = mb.Model("flight", gravity=g)
    ball = model.add_particle("ball", mass=2.0, position=r0, velocity=v0)
    res = mb.simulate(model, 5.0, output_step=0.05, method="dop853")
    assert res.success, res.message
    t = res.time[:, None]
    assert np.allclose(res.position(ball), r0 + v0 * t + 0.5 * g * t**2, rtol=0, atol=1e-9)
    assert np.allclose(res.velocity(ball), v0 + g * t, rtol=0, atol=1e-9)
    assert np.allclose(res.acceleration(ball), np.broadcast_to(g, (len(t), 3)), rtol=0, atol=1e-9)
    # dense output between samples and the apex time from crossings(): t_apex = v0y / g
    sub = res.at([0.1234, 4.321])
    ts = sub.time[:, None]
    assert np.allclose(sub.position(ball), r0 + v0 * ts + 0.5 * g * ts**2, rtol=0, atol=1e-9)
    apex = res.crossings(lambda r: r.velocity(ball)[:, 1], 0.0, direction=-1)
    assert apex == pytest.approx([v0[1] / G], abs=1e-9)
    t_max, y_max = res.maximum(lambda r: r.position(ball)[:, 1])
    assert t_max == pytest.approx(v0[1] / G, abs=1e-6)
    assert y_max == pytest.approx(r0[1] + v0[1] ** 2 / (2 * G), abs=1e-9)


def test_particle_free_flight_energy():
    """Kinetic + potential energy of the flight is constant (closed form m g . r)."""
    model = mb.Model("flight", gravity=(0.0, 0.0, -G))
    ball = model.add_particle("ball", mass=0.5, position=(0, 0, 1), velocity=(2, 0, 10))
    res = mb.simulate(model, 1.0, output_step=0.1, method="dop853")
    E = res.kinetic_energy() + res.potential_energy()
    assert np.allclose(E, 0.5 * 0.5 * (4 + 100) + 0.5 * G * 1.0, rtol=0, atol=1e-9)
    assert np.allclose(res.potential_energy(), 0.5 * G * res.position(ball)[:, 2], atol=1e-12)


# ----------------------------------------------------------------------------- 2. rod pendulum
L, MASS = 1.2, 2.0


def rod_pendulum():
    """Uniform rod of length L pinned at its end at the origin, released from the +x (horizontal) position."""
    model = mb.Model("rod_pendulum", gravity=(0.0, -G, 0.0))
    izz = MASS * L**2 / 12
    rod = model.add_body("rod", MASS, inertia=(izz / 100, izz, izz), position=(L / 2, 0, 0))
    pin = model.add_revolute("pin", model.ground, rod, point=(0, 0, 0), axis=(0, 0, 1))
    return model, rod, pin


@pytest.fixture(scope="module")
def pendulum_run():
    model, rod, pin = rod_pendulum()
    w0 = np.sqrt(3 * G / (2 * L))                   # small-oscillation frequency of the rod
    period = 4 * ellipk(np.sin(np.pi / 4) ** 2) / w0  # amplitude 90 deg: T = 4 K(k) / w0, k = sin(45 deg)
    # rtol 1e-11: the closed-form checks below hold to 1e-8 absolute (w^2 ~ 25 rad^2/s^2)
    res = mb.simulate(model, 1.1 * period, output_step=period / 40, method="dop853", rtol=1e-11)
    assert res.success, res.message
    return res, rod, pin, period


def test_rod_pendulum_period_matches_complete_elliptic_integral(pendulum_run):
    res, _, pin, period = pendulum_run
    # the rod returns to the horizontal with zero speed after one period: rate crosses 0 upwards at T/2
    # (lowest swing point theta = -pi) and downwards at T
    ups = res.crossings(lambda r: r.joint_velocity(pin), 0.0, direction=+1)
    downs = res.crossings(lambda r: r.joint_velocity(pin), 0.0, direction=-1)
    assert ups == pytest.approx([period / 2], abs=1e-6)
    assert downs[-1] == pytest.approx(period, abs=1e-6)
    # the lowest point of the rod's CM (theta = -pi/2) is passed at T/4 and 3T/4
    t_low, y_low = res.minimum(lambda r: r.position(pin.body_j)[:, 1])
    assert min(abs(t_low - period / 4), abs(t_low - 3 * period / 4)) < 1e-6
    assert y_low == pytest.approx(-L / 2, abs=1e-9)


def test_rod_pendulum_motion_and_pivot_reaction_closed_form(pendulum_run):
    """Energy: w^2 = -(3 g / L) sin(theta); moment about the pivot: alpha = -(3 g / 2L) cos(theta);
    pivot reaction on the rod R = m a_cm - m g with a_cm from (theta, w, alpha)."""
    res, rod, pin, _ = pendulum_run
    sub = res.at(np.linspace(0.0, res.time[-1], 57))   # also between output samples (dense output)
    for r in (res, sub):
        th, w, al = r.joint_coordinate(pin), r.joint_velocity(pin), r.joint_acceleration(pin)
        assert np.allclose(w**2, -3 * G / L * np.sin(th), rtol=0, atol=1e-8)
        assert np.allclose(al, -1.5 * G / L * np.cos(th), rtol=0, atol=1e-8)
        e_r = np.stack([np.cos(th), np.sin(th), 0 * th], -1)
        e_t = np.stack([-np.sin(th), np.cos(th), 0 * th], -1)
        a_cm = L / 2 * (al[:, None] * e_t - (w**2)[:, None] * e_r)
        R = MASS * a_cm - MASS * np.array([0.0, -G, 0.0])
        assert np.allclose(r.reaction_force(pin), R, rtol=0, atol=1e-6)
        assert np.allclose(r.reaction_force(pin, on=rod), R, rtol=0, atol=1e-6)
        assert np.allclose(r.reaction_force(pin, on=res.system.model.ground), -R,
                           rtol=0, atol=1e-6)
        # a revolute with its axis along z transmits no torque about z; the x/y torques vanish (planar, symmetric)
        assert np.allclose(r.reaction_torque(pin), 0.0, atol=1e-6)
        # radial/tangential reaction in the rod's own axes: frame= expresses it there
        R_rod = r.reaction_force(pin, frame=rod)
        assert np.allclose(R_rod[:, 0], np.einsum("ni,ni->n", R, e_r), atol=1e-6)
        assert np.allclose(R_rod[:, 1], np.einsum("ni,ni->n", R, e_t), atol=1e-6)


def test_rod_pendulum_energy_and_constraint_drift(pendulum_run):
    res, rod, pin, _ = pendulum_run
    th = res.joint_coordinate(pin)
    assert np.all(th <= 1e-9) and th.min() == pytest.approx(-np.pi, abs=1e-6)   # swings to the -x side
    E = res.kinetic_energy() + res.potential_energy()
    assert np.ptp(E) < 1e-9 * MASS * G * L
    # the pivot point of the rod stays at the origin (constraint drift)
    tip = res.position(rod) - np.einsum("nij,j->ni", res.orientation(rod), np.array([L / 2, 0, 0]))
    assert np.abs(tip).max() < 1e-10
