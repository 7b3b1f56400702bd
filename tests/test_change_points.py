"""Issue 8: parallelogram linkages through their change points (all links collinear, loop rows dependent)
at default settings, against minimal-coordinate references."""
import warnings

import numpy as np
from scipy.integrate import solve_ivp

import mbdsim as mb

from test_compiled_core import _parallelogram


def _run(m, T):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        return mb.simulate(m, T, output_step=0.01)


def _crank_angle(res):
    """Crank angle from +x [rad], continuous (the crank starts pointing up, +y)."""
    return np.pi / 2 + res.joint_coordinate("A")


def test_parallelogram_under_gravity_against_its_one_dof_equation():
    """Gravity -y, links of 1 kg: crank and rocker rods b (I about the pivot b^2/3), coupler translating.
    T = (5 b^2 / 6) th'^2, V = 2 g b sin(th), so th'' = -(6 g / (5 b)) cos(th); it goes over the top every
    turn and passes two change points (th = 0, pi) per turn."""
    g, b, w0, T = 9.81, 0.4, 12.0, 2.0
    m = _parallelogram(w0, b=b)
    m.gravity = np.array([0.0, -g, 0.0])
    res = _run(m, T)
    assert res.success and res.stats["method"].startswith("auto: DOP853")
    k = 6 * g / (5 * b)
    ref = solve_ivp(lambda t, y: [y[1], -k * np.cos(y[0])], (0, T), [np.pi / 2, w0], method="DOP853",
                    rtol=1e-12, atol=1e-12, t_eval=res.time)
    assert ref.y[0, -1] - ref.y[0, 0] > 4 * np.pi                       # two turns: four change points
    assert np.max(np.abs(_crank_angle(res) - ref.y[0])) < 1e-5
    # the parallelogram branch is kept through every change point: the rocker turns with the crank
    assert np.max(np.abs(res.angular_velocity("rocker")[:, 2] - ref.y[1])) < 1e-4
    assert np.max(np.abs(res.angular_velocity("coupler")[:, 2])) < 1e-6


def test_driven_parallelogram_through_change_points():
    """Crank driven at 2 pi rad/s: a 0-DOF run through four change points; the rocker follows the
    crank (parallelogram branch) and the coupler translates on a circle of radius b."""
    b, w = 0.4, 2 * np.pi
    m = _parallelogram(w, b=b)
    m.gravity = np.array([0.0, -9.81, 0.0])
    m.add_motion("drive", m.joints["A"], displacement="2*pi*t")
    res = _run(m, 2.0)
    # zero DOF, but its change points leave the rates to continuity: integrated, not a kinematic sweep
    assert res.success and res.stats["method"] == "auto: DOP853 (compiled)"
    th = np.pi / 2 + w * res.time
    assert np.max(np.abs(_crank_angle(res) - th)) < 1e-8
    assert np.max(np.abs(res.angular_velocity("rocker")[:, 2] - w)) < 1e-6
    c = res.position("coupler")
    assert np.max(np.abs(c[:, 0] - (0.5 + b * np.cos(th)))) < 1e-7
    assert np.max(np.abs(c[:, 1] - b * np.sin(th))) < 1e-7
