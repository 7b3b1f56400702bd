"""Zero-DOF (fully driven) models under the automatic method: a kinematic sweep, not an integration.

Physics against closed forms: a crank driven at constant speed (positions, velocities, centripetal
acceleration, driver torque m g L/2 cos(theta), pin reaction m (a_cm - g)); the slider-crank's slider
x = r cos(theta) + sqrt(l^2 - r^2 sin^2(theta)) and agreement with a tightly integrated DOP853 run;
dense output between samples; a driver moving a slider-crank into lock-up; dof > 0 models unchanged.
"""
import math
import warnings

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.errors import SolverError
from mbdsim.studies.models import slider_crank

G = 9.81
M, L, OMEGA = 2.0, 0.6, 3.0   # rod mass [kg], length [m], drive speed [rad/s]
KIN = "auto: kinematic (0 DOF)"


@pytest.fixture(autouse=True)
def _quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # the slider-crank's redundant-constraint warnings
        yield


def driven_crank(speed=OMEGA):
    """A uniform rod of mass M and length L pinned at its end (origin, axis z), drawn along +x, driven
    at theta = speed * t; gravity -y."""
    model = mb.Model("crank", gravity=(0, -G, 0))
    rod = model.add_body("rod", mass=M, inertia=(1e-6, M * L**2 / 12, M * L**2 / 12), position=(L / 2, 0, 0))
    model.add_revolute("pin", model.ground, rod, point=(0, 0, 0), axis=(0, 0, 1))
    model.add_motion("drive", "pin", displacement=f"{speed!r}*t")
    return model


def crank_closed_form(t):
    th = OMEGA * t
    c, s = np.cos(th), np.sin(th)
    z = np.zeros_like(t)
    r = np.stack([L / 2 * c, L / 2 * s, z], axis=1)
    v = np.stack([-L / 2 * OMEGA * s, L / 2 * OMEGA * c, z], axis=1)
    a = np.stack([-L / 2 * OMEGA**2 * c, -L / 2 * OMEGA**2 * s, z], axis=1)
    torque = M * G * L / 2 * c                               # constant speed: I theta_dd = 0
    force = M * (a - np.array([0.0, -G, 0.0]))              # pin on the rod: m (a_cm - g)
    return r, v, a, torque, force


def test_crank_against_closed_form():
    res = mb.simulate(driven_crank(), 2.0, 0.01)
    assert res.success and res.stats["method"] == KIN
    assert res.stats["order_history"] == [(0.0, "kinematic (0 DOF)", None)]
    assert res.stats["nfev"] == 0 and res.stats["steps"] == len(res.time) == 201
    assert res.stats["projections"] >= 200 and res.stats["factorizations"] >= res.stats["projections"]
    r, v, a, torque, force = crank_closed_form(res.time)
    np.testing.assert_allclose(res.position("rod"), r, atol=1e-9)
    np.testing.assert_allclose(res.velocity("rod"), v, atol=1e-9)
    np.testing.assert_allclose(res.acceleration("rod"), a, atol=1e-9)
    np.testing.assert_allclose(res.angular_velocity("rod")[:, 2], OMEGA, atol=1e-9)
    np.testing.assert_allclose(res.angular_acceleration("rod"), 0.0, atol=1e-9)
    np.testing.assert_allclose(res.driver_effort("drive"), torque, atol=1e-9)
    np.testing.assert_allclose(res.reaction_force("pin"), force, atol=1e-9)
    np.testing.assert_allclose(res.reaction_torque("pin")[:, :2], 0.0, atol=1e-9)
    # the outputs are the steps (no integration steps exist)
    ts, q, vv = res.steps() if callable(res.steps) else res.steps
    np.testing.assert_array_equal(ts, res.time)
    np.testing.assert_array_equal(q, res.q)


def test_crank_dense_output_and_extrema():
    res = mb.simulate(driven_crank(), 2.0, 0.05)
    ts = np.array([0.0123, 0.4567, 1.2345, 1.999])
    out = res.at(ts)
    r, v, a, torque, force = crank_closed_form(ts)
    np.testing.assert_allclose(out.position("rod"), r, atol=1e-9)
    np.testing.assert_allclose(out.velocity("rod"), v, atol=1e-9)
    np.testing.assert_allclose(out.acceleration("rod"), a, atol=1e-9)
    np.testing.assert_allclose(out.driver_effort("drive"), torque, atol=1e-9)
    # an output time gives its own sample
    np.testing.assert_array_equal(res.at(res.time[7]).q[0], res.q[7])
    # maximum of the CM height L/2 sin(theta): at theta = pi/2, refined between samples
    t_max, y_max = res.maximum(lambda r: r.position("rod")[:, 1])
    assert abs(t_max - math.pi / 2 / OMEGA) < 1e-6 and abs(y_max - L / 2) < 1e-12
    t_min, y_min = res.minimum(lambda r: r.driver_effort("drive"))
    assert abs(t_min - math.pi / OMEGA) < 1e-6 and abs(y_min + M * G * L / 2) < 1e-9


def test_large_output_step_keeps_the_branch():
    """An output step of 2/3 turn: sub-steps between outputs, the same solution."""
    res = mb.simulate(driven_crank(), 6.0, 1.4)
    assert res.success and res.stats["method"] == KIN and res.stats["substeps"] > len(res.time)
    r, v, a, _, _ = crank_closed_form(res.time)
    np.testing.assert_allclose(res.position("rod"), r, atol=1e-9)
    np.testing.assert_allclose(res.acceleration("rod"), a, atol=1e-9)


def _slider_x(t, crank=0.2, rod=0.4, speed=2 * math.pi):
    th = speed * t
    return crank * np.cos(th) + np.sqrt(rod**2 - crank**2 * np.sin(th) ** 2)


def test_slider_crank_against_dop853_and_closed_form():
    model = slider_crank()
    kin = mb.simulate(model, 1.0, 0.01)
    dop = mb.simulate(model, 1.0, 0.01, method="dop853", rtol=1e-10)
    assert kin.success and kin.stats["method"] == KIN and dop.stats["method"] == "DOP853 (compiled)"
    np.testing.assert_allclose(kin.position("slider")[:, 0], _slider_x(kin.time), atol=1e-10)
    np.testing.assert_allclose(kin.position("slider")[:, 1:], 0.0, atol=1e-10)

    def close(a, b, rel=1e-7):
        np.testing.assert_allclose(a, b, atol=rel * max(np.max(np.abs(b)), 1e-300))

    close(kin.q, dop.q)
    close(kin.v, dop.v)
    close(kin.vd, dop.vd)
    for joint in ("crank_pin", "crank_rod", "rod_slider", "slide"):
        close(kin.reaction_force(joint), dop.reaction_force(joint))
    close(kin.driver_effort("drive"), dop.driver_effort("drive"))
    # slider acceleration by differentiating the closed form twice (central differences of x(t))
    t, h = np.array([0.13, 0.37, 0.81]), 1e-4
    xdd = (_slider_x(t + h) - 2 * _slider_x(t) + _slider_x(t - h)) / h**2
    np.testing.assert_allclose(kin.at(t).acceleration("slider")[:, 0], xdd, rtol=1e-5, atol=1e-5)


def test_lock_up_fails_with_the_time():
    """A rod shorter than the crank: the loop closes only while crank sin(theta) <= rod."""
    crank, rod, speed = 0.2, 0.15, 2 * math.pi
    t_lock = math.asin(rod / crank) / speed     # 0.13497 s
    res = mb.simulate(slider_crank(crank=crank, rod=rod), 0.5, 0.01)
    assert not res.success and res.stats["method"] == KIN
    assert isinstance(res.error, SolverError) and abs(res.error.time - t_lock) < 1e-3
    assert res.time[-1] == pytest.approx(0.13) and len(res.time) == 14
    assert "t = " in res.message and "last good output at t = 0.13 s" in res.message
    np.testing.assert_allclose(res.position("slider")[:, 0], _slider_x(res.time, crank, rod), atol=1e-9)


def test_dof_positive_and_named_methods_unchanged():
    free = mb.Model("pendulum", gravity=(0, -G, 0))
    rod = free.add_body("rod", mass=M, inertia=(1e-6, M * L**2 / 12, M * L**2 / 12), position=(L / 2, 0, 0))
    free.add_revolute("pin", free.ground, rod, point=(0, 0, 0), axis=(0, 0, 1))
    res = mb.simulate(free, 0.5, 0.01)
    assert res.success and "kinematic" not in res.stats["method"] and res.stats["nfev"] > 0
    res = mb.simulate(driven_crank(), 0.5, 0.01, method="dop853")
    assert res.success and res.stats["method"] == "DOP853 (compiled)" and res.stats["nfev"] > 0
    r, _, _, _, _ = crank_closed_form(res.time)
    np.testing.assert_allclose(res.position("rod"), r, atol=1e-8)


def test_kinematics_uses_the_compiled_sweep_and_agrees_with_the_reference_solve(monkeypatch):
    """mb.kinematics on a compiled, non-singular driven model runs the compiled sweep; the Python
    position/velocity/acceleration solve (kept for singular passages) gives the same states and
    reactions."""
    import mbdsim.solvers.kinematic as kin
    from mbdsim.studies.models import slider_crank
    m = slider_crank(crank=0.15, rod=0.5, speed=9.0)
    seen = []
    res = mb.kinematics(m, 1.0, 0.01, progress=seen.append)
    assert res.stats["method"] == "kinematic (compiled sweep)" and res.stats["singular"] == []
    assert len(seen) == len(res.time) == 101 and seen[-1] == pytest.approx(1.0)
    monkeypatch.setattr(kin, "_compiled_sweep", lambda *a: None)
    ref = mb.kinematics(m, 1.0, 0.01)
    assert "method" not in ref.stats or ref.stats["method"] != res.stats["method"]
    assert np.allclose(res.q, ref.q, rtol=0, atol=1e-10) and np.allclose(res.v, ref.v, rtol=0, atol=1e-9)
    assert np.allclose(res.vd, ref.vd, rtol=0, atol=1e-7)
    f, fr = res.reaction_force("crank_rod"), ref.reaction_force("crank_rod")
    assert np.allclose(f, fr, rtol=1e-8, atol=1e-8 * np.abs(fr).max())


def test_kinematics_of_a_model_with_sensors_runs_the_compiled_sweep():
    """Sensors end or mark simulations; mb.kinematics does not watch them (neither path does), so a model
    carrying one (a Python callable here) is still solved by the compiled sweep, exactly."""
    model = driven_crank()
    model.add_sensor("low", lambda t, s: s.position("rod")[1] + 0.2, 0.0, direction=-1, action="record")
    res = mb.kinematics(model, 2.0, 0.01)
    assert res.success and res.stats["method"] == "kinematic (compiled sweep)"
    r, v, a, torque, force = crank_closed_form(res.time)
    np.testing.assert_allclose(res.position("rod"), r, atol=1e-9)
    np.testing.assert_allclose(res.driver_effort("drive"), torque, atol=1e-8)
