"""Sensors on the compiled implicit steppers (issue 29): Radau IIA and HHT-alpha watch the model's sensors
after every accepted step and locate a crossing on the step's polynomial (Radau's collocation polynomial,
HHT's Hermite cubic) with DOP853's sensor machinery; a "stop" ends the run exactly there. Closed form: a
1 kg particle on a stiff spring-damper (k = 1e8 N/m, c = 1e6 N s/m: eigenvalues -100 and -1e6 1/s, a
stiffness ratio of 1e4) released u0 from its equilibrium: u(t) = a e^(r1 t) + b e^(r2 t); the sensor
stops the run when u falls to u0 / 2 (the time by brentq on the closed form)."""
import numpy as np
import pytest
from scipy.optimize import brentq

import mbdsim as mb

K, C, U0 = 1e8, 1e6, 1e-3


def u(t):
    r1, r2 = (-C + np.sqrt(C * C - 4 * K)) / 2, (-C - np.sqrt(C * C - 4 * K)) / 2
    a = -r2 * U0 / (r1 - r2)
    return a * np.exp(r1 * t) + (U0 - a) * np.exp(r2 * t)


def stiff(signal, action="stop", direction=-1):
    """The particle (x = 1 + u on a translational joint, no gravity) with a sensor on `signal`."""
    m = mb.Model("stiff spring", gravity=(0, 0, 0))
    p = m.add_particle("p", 1.0, position=(1.0 + U0, 0, 0))
    m.add_translational("slide", m.ground, p, (1.0, 0, 0), (1, 0, 0))
    m.add_spring_damper("k", m.ground, p, K, C, 1.0)
    m.add_sensor("half", signal, value=1.0 + U0 / 2, direction=direction, action=action)
    return m


T_HALF = brentq(lambda t: u(t) - U0 / 2, 1e-6, 0.1)


@pytest.mark.parametrize("method, rtol, tol", [("radau", 1e-10, 1e-9), ("hht", 1e-8, 3e-5), ("auto", 1e-9, 1e-9)])
def test_stop_sensor_on_the_implicit_steppers_at_the_closed_form_time(method, rtol, tol):
    """The crossing is exact on the stepper's own solution (its state at the stop on the level to 1e-9 of
    u0); against the closed form: Radau 7e-12 relative at rtol 1e-10, HHT (second order) 1.1e-5 at rtol
    1e-8, its solution's own error there (3.4e-6 u0, over a slope of 50 u0 / s). "auto": DOP853 detects the
    stiffness and the compiled Radau IIA continues, watching the sensor."""
    res = mb.simulate(stiff("DX(p)"), 0.05, output_step=1e-3, method=method, rtol=rtol)
    if method == "auto":
        assert "then Radau IIA (compiled)" in res.stats["method"], res.stats["method"]
    assert res.success and "compiled" in res.stats["method"], res.stats["method"]
    assert "stopped by sensor 'half'" in res.message
    (ev,) = res.sensor_events
    assert abs(ev.time - T_HALF) < tol * T_HALF, (ev.time, T_HALF)
    assert res.time[-1] == ev.time and np.all(np.diff(res.time) > 0)
    assert abs(res.position("p")[-1, 0] - (1.0 + U0 / 2)) < 1e-9 * U0   # the state on the crossing
    assert res.stats["steps"] < 600   # long steps over the decayed fast mode (DOP853's stability: > 2000)


def test_record_and_callable_sensors_on_radau():
    """A "record" sensor lets the run go on (its event at the closed-form time), a rising one never fires,
    and a Python-callable signal (called back from the Radau step loop) stops at the same time."""
    m = stiff("DX(p)", action="record")
    m.add_sensor("rising", "DX(p)", value=1.0 + U0 / 2, direction=+1, action="record")
    res = mb.simulate(m, 0.02, output_step=1e-3, method="radau", rtol=1e-10)
    assert res.success and res.time[-1] == pytest.approx(0.02)
    assert [e.name for e in res.sensor_events] == ["half"]
    assert abs(res.sensor_events[0].time - T_HALF) < 1e-8 * T_HALF
    cb = mb.simulate(stiff(lambda t, s: s.position("p")[0]), 0.05, output_step=1e-3, method="radau", rtol=1e-10)
    assert "compiled" in cb.stats["method"] and "stopped by sensor 'half'" in cb.message
    assert abs(cb.sensor_events[0].time - T_HALF) < 1e-8 * T_HALF


@pytest.mark.parametrize("method", ["radau", "hht"])
def test_failing_callable_sensor_ends_an_implicit_run_at_once(method):
    """A sensor callable that raises at t > 5 ms ends the run there (success False, the error naming the
    sensor and the time), with the outputs before it kept."""
    from mbdsim.errors import EvaluationError

    def signal(t, s):
        if t > 0.005:
            raise RuntimeError("probe lost")
        return s.position("p")[0]
    res = mb.simulate(stiff(signal, action="record"), 0.05, output_step=1e-3, method=method)
    assert not res.success and isinstance(res.error, EvaluationError)
    assert "sensor 'half'" in str(res.error) and "probe lost" in str(res.error)
    assert 0.005 < res.error.time < 0.01
    assert 0.003 <= res.time[-1] <= 0.005 + 1e-12


def pendulum_on_a_stop():
    """A 1 m rod (1 kg) hinged at one end, released horizontal, falls onto a stop at -0.8 rad (Adams
    IMPACT: k = 1e4 N m/rad^1.5, c_max 5 N m s/rad over 1e-3 rad) and bounces."""
    m = mb.Model("stop", gravity=(0, -9.81, 0))
    b = m.add_body("rod", 1.0, inertia=(1e-3, 1 / 12, 1 / 12), position=(0.5, 0, 0))
    j = m.add_revolute("pin", m.ground, b, (0, 0, 0), (0, 0, 1))
    m.add_stop("st", j, lower=-0.8, stiffness=1e4, exponent=1.5, damping=5.0, penetration=1e-3)
    return m


def test_radau_cuts_its_steps_at_the_stop_and_contact_zeros():
    """Switching functions (a stop's clearance, a contact's gap) on the compiled Radau IIA: the step ends at
    their zero and the stepper restarts there (as the reference path cuts its steps), so that no step
    integrates across the kink of the contact law. The bouncing rod at rtol 1e-6 is 1.9e-7 rad from the
    compiled DOP853 at 1e-12 (4.4e-5 when Radau integrated through the impacts); a ball dropped 0.9 m onto
    a plane touches it at sqrt(2 h / g) to 1e-12 s."""
    ref = mb.simulate(pendulum_on_a_stop(), 2.0, 0.01, method="dop853", rtol=1e-12, atol=1e-14, monitor=False)
    res = mb.simulate(pendulum_on_a_stop(), 2.0, 0.01, method="radau", rtol=1e-6, monitor=False)
    assert res.success and "compiled" in res.stats["method"]
    assert ref.joint_coordinate("pin").min() < -0.81   # it hits the stop (three times)
    assert np.max(np.abs(res.joint_coordinate("pin") - ref.joint_coordinate("pin"))) < 1e-6
    m = mb.Model(gravity=(0, -9.81, 0))
    ball = m.add_body("ball", 1.0, (0.004, 0.004, 0.004), position=(0, 1.0, 0))
    m.add_contact("c", mb.Sphere(ball, 0.1), mb.Plane(m.ground, (0, 0, 0), (0, 1, 0)), 1e5, 1.5, 10.0, 1e-3)
    res = mb.simulate(m, 0.6, 0.01, method="radau", monitor=False)
    assert res.success and "compiled" in res.stats["method"]
    t_on = res.crossings(lambda r: r.position(ball)[:, 1], 0.1)[0]
    assert abs(t_on - np.sqrt(2 * 0.9 / 9.81)) < 1e-12


@pytest.mark.parametrize("method", ["radau", "hht"])
def test_implicit_sensor_events_beyond_the_buffer(method):
    """sin(40 t) crosses zero at k pi / 40, 127 times in 10 s, more than the kernel's event buffer holds
    (handed to Python when full, EVENTS_FULL): every crossing at its time to 1e-12 s."""
    from mbdsim.system import exprloads_pack
    m = mb.Model("drop", gravity=(0, 0, -9.81))
    m.add_body("ball", 0.5, inertia=(0.01, 0.01, 0.01), position=(0, 0, 1e3))
    m.add_sensor("wave", "sin(40*t)", action="record")
    res = mb.simulate(m, 10.0, 0.1, method=method, rtol=1e-8, max_step=0.01, monitor=False)
    t = np.array([e.time for e in res.sensor_events])
    assert len(t) == 127 > exprloads_pack.EVENT_CAPACITY
    assert np.max(np.abs(t - np.arange(1, 128) * np.pi / 40)) < 1e-12
