"""Velocity and acceleration drivers integrated in closed form (mbdsim._exprint), so they run compiled.

Antiderivatives against scipy's adaptive quadrature; driven mechanisms against the same motion written as
a displacement (and against closed forms); the compiled core must report that it ran.
"""
import warnings

import numpy as np
import pytest
from scipy.integrate import quad

import mbdsim as mb
from mbdsim._exprint import antiderivative
from mbdsim._exprtree import _eval
from mbdsim.expressions import parse

CLOSED = ["18.85", "3*t**2 + 1", "10*sin(2*t)", "t*cos(3*t + 1)", "exp(-t)*t**2", "STEP(t, 0, 0, 1, 18.85)",
          "STEP5(2*t, 0.5, 1, 2, 3)", "HAVSIN(t, 0.2, -1, 1.5, 2)", "POLY(t, 1, 2, 3, 4)", "sqrt(2*t + 1)",
          "(3*t + 1)**2.5", "SHF(t, 0.1, 2, 3, 0.5, 1)", "2*STEP(t, 0, 0, 1, 1) + sin(t)", "cosh(t/2) - sinh(t)",
          "-STEP(t, 1, 0, 2, 3)/4", "STEP(t, 0, 0, 1, 2, order=1)", "2*(t + 1)*(t - 3)/5"]
BREAKS = [0.1, 0.2, 0.25, 0.5, 1.0, 1.5, 2.0]


def _quad(f, t, times):
    w = (lambda x: 1.0) if times == 1 else (lambda x: t - x)
    return quad(lambda x: w(x) * _eval(f, {"t": x}), 0.0, t, epsabs=1e-14, epsrel=1e-13, limit=400,
                points=[b for b in BREAKS if b < t] or None)[0]


@pytest.mark.parametrize("text", CLOSED)
@pytest.mark.parametrize("times", [1, 2])
def test_antiderivative_matches_quadrature(text, times):
    f = parse(text).node
    F = antiderivative(f, "t", times)
    assert F is not None, text
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for t in (0.0, 0.3, 0.77, 1.2, 2.5, 4.0):
            ref = _quad(f, t, times)
            assert abs(_eval(F, {"t": t}) - ref) <= 1e-12 * max(1.0, abs(ref)), (text, times, t)


@pytest.mark.parametrize("text", ["sin(t**2)", "sin(t)*cos(t)", "abs(t - 1)", "1/(1 + t**2)"])
def test_no_closed_form_falls_back_to_quadrature(text):
    assert antiderivative(parse(text).node, "t", 1) is None
    tf = mb.expressions.integrated(text, 0.5)
    assert tf.expr is None and "closed form" not in tf.description
    ref = 0.5 + quad(lambda x: _eval(parse(text).node, {"t": x}), 0.0, 1.3, epsabs=1e-13, epsrel=1e-13)[0]
    assert tf.value(1.3) == pytest.approx(ref, abs=1e-10)


def test_integrated_time_functions_are_exact_expressions():
    tf = mb.expressions.double_integrated("6*t", 0.2, -1.0)       # x = 0.2 - t + t^3
    assert tf.expr is not None and "closed form" in tf.description
    for t in (0.0, 0.4, 1.7):
        assert tf.value(t) == pytest.approx(0.2 - t + t**3, abs=1e-14)
        assert tf.d1(t) == pytest.approx(-1.0 + 3 * t**2, abs=1e-14)
        assert tf.d2(t) == pytest.approx(6 * t, abs=1e-14)
    c = mb.expressions.integrated(18.85, 0.3)
    assert c.expr is not None and c.value(2.0) == pytest.approx(0.3 + 37.7, abs=1e-13)
    assert c.d1(5.0) == 18.85 and c.d2(5.0) == 0.0


# ----------------------------------------------------------------------------- mechanisms
L_ARM, L_PEND, M_PEND = 0.3, 0.5, 1.2


def _carousel(**drive):
    """A horizontal arm turned about the vertical z axis by a motion, with a pendulum hinged at its tip
    about the arm's axis (one free degree of freedom), under gravity -z."""
    model = mb.Model("carousel", gravity=(0.0, 0.0, -9.81))
    arm = model.add_body("arm", 2.0, inertia=(0.002, 0.02, 0.02), position=(L_ARM / 2, 0, 0))
    pend = model.add_body("pend", M_PEND, inertia=(M_PEND * L_PEND**2 / 12, M_PEND * L_PEND**2 / 12, 1e-3),
                          position=(L_ARM, 0, -L_PEND / 2))
    hub = model.add_revolute("hub", model.ground, arm, (0, 0, 0), (0, 0, 1))
    model.add_revolute("tip", arm, pend, (L_ARM, 0, 0), (1, 0, 0))
    model.add_motion("spin", hub, **drive)
    return model


def _run(model):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return mb.simulate(model, end_time=1.5, output_step=0.01)


# 6*STEP(t, 0, 0, 0.5, 3) integrated by hand: with s = clamp(2 t, 0, 1), the cubic step's integral is
# 18 (0.5 s^3 - 0.25 s^4) up to t = 0.5, then grows by 18 (t - 0.5)
SC = "((abs(2*t) - abs(2*t - 1) + 1)/2)"
STEP_BY_HAND = f"0.4 + 18*(0.5*{SC}**3 - 0.25*{SC}**4) + 18*(t - 0.5 + abs(t - 0.5))/2"


@pytest.mark.parametrize("drive, same", [
    (dict(velocity="18.85"), dict(displacement="18.85*t")),
    (dict(velocity=18.85), dict(displacement="18.85*t")),
    (dict(velocity="6*STEP(t, 0, 0, 0.5, 3)", initial_displacement=0.4), dict(displacement=STEP_BY_HAND)),
])
def test_velocity_driver_runs_compiled_like_the_displacement(drive, same):
    a, b = _run(_carousel(**drive)), _run(_carousel(**same))
    assert a.success and b.success
    assert "compiled" in a.stats["method"], a.stats["method"]
    for name in ("hub", "tip"):
        qa, qb = a.joint_coordinate(name), b.joint_coordinate(name)
        assert np.max(np.abs(qa - qb)) < 1e-8, name
    # the spin follows the closed form of the integrated driver
    t = a.time
    if "STEP" not in str(drive["velocity"]):
        assert np.max(np.abs(a.joint_coordinate("hub") - 18.85 * t)) < 1e-9


def test_acceleration_driver_runs_compiled_like_the_displacement():
    a = _run(_carousel(acceleration="8 - 3*t", initial_displacement=0.2, initial_velocity=1.5))
    b = _run(_carousel(displacement="0.2 + 1.5*t + 4*t**2 - t**3/2"))
    assert a.success and "compiled" in a.stats["method"], a.stats["method"]
    assert np.max(np.abs(a.joint_coordinate("tip") - b.joint_coordinate("tip"))) < 1e-8
    th = 0.2 + 1.5 * a.time + 4 * a.time**2 - a.time**3 / 2
    assert np.max(np.abs(a.joint_coordinate("hub") - th)) < 1e-9


def test_velocity_driven_slider_crank_kinematics_closed_form():
    """Zero-DOF slider-crank driven at constant crank speed w: slider x = r cos(w t) + sqrt(l^2 - r^2 sin^2)."""
    r, l, w = 0.1, 0.35, 18.85
    model = mb.Model("sc")
    crank = model.add_body("crank", 1.0, inertia=(1e-4, 1e-3, 1e-3), position=(r / 2, 0, 0))
    rod = model.add_body("rod", 1.0, inertia=(1e-4, 1e-2, 1e-2), position=(r + l / 2, 0, 0))
    slider = model.add_body("slider", 0.5, inertia=(1e-3, 1e-3, 1e-3), position=(r + l, 0, 0))
    o = model.add_revolute("O", model.ground, crank, (0, 0, 0), (0, 0, 1))
    model.add_revolute("A", crank, rod, (r, 0, 0), (0, 0, 1))
    model.add_spherical("B", rod, slider, (r + l, 0, 0))
    model.add_translational("slide", model.ground, slider, (r + l, 0, 0), (1, 0, 0))
    model.add_motion("drive", o, velocity=str(w))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = mb.kinematics(model, end_time=0.5, output_step=0.005)
    assert res.success and "compiled" in res.stats.get("method", "compiled"), res.stats
    t = res.time
    x = r * np.cos(w * t) + np.sqrt(l**2 - (r * np.sin(w * t))**2)
    assert np.max(np.abs(res.position(slider)[:, 0] - x)) < 1e-9


def test_velocity_and_acceleration_motions_survive_a_file_round_trip(tmp_path):
    model = _carousel(velocity="3 + STEP(t, 0, 0, 1, 2)", initial_displacement=0.25)
    path = tmp_path / "m.yaml"
    mb.save_model(model, path)
    back = mb.load_model(path)
    m = back.motions["spin"]
    assert m.kind == "velocity" and m.initial[0] == 0.25 and m.function.expr is not None
    for t in (0.0, 0.5, 2.0):
        assert m.function.value(t) == pytest.approx(model.motions["spin"].function.value(t), abs=1e-14)
    model = _carousel(acceleration="2", initial_displacement=0.1, initial_velocity=-0.5)
    mb.save_model(model, path)
    m = mb.load_model(path).motions["spin"]
    assert m.kind == "acceleration" and m.initial == (0.1, -0.5)
    assert m.function.value(2.0) == pytest.approx(0.1 - 1.0 + 4.0, abs=1e-14)
