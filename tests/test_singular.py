"""Singular configurations in kinematic analysis (issue 16): a slider-driven slider-crank through its
dead centre.  Closed form: cos(th) = (x^2 + r^2 - L^2) / (2 r x), the crank turning on through th = 0
(continuity), and near the dead centre |th_dot| = sqrt(2 c / (r (1 + r / L))) for x = r + L - c (t - tc)^2.
"""
import warnings

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.results.result import Result
from test_initial_conditions import L, R, slider_crank, slider_law

TH0, TC = np.radians(60.0), 0.5
X0 = slider_law(TH0, 0.0)[0]
C = (R + L - X0) / TC**2


def closed_form(t, x):
    return np.sign(TC - t) * np.arccos(np.clip((x**2 + R**2 - L**2) / (2 * R * x), -1.0, 1.0))


@pytest.fixture(scope="module")
def run():
    model, slider = slider_crank(TH0)
    model.add_motion("push", "slide", displacement=f"{float(C)!r}*(2*{TC}*t - t**2)")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = mb.kinematics(model, 1.0, 0.01)
    return res, slider, [w for w in caught if issubclass(w.category, mb.SingularConfigurationWarning)]


def test_dead_centre_is_warned_with_its_time_and_recorded(run):
    res, _, warned = run
    assert len(warned) == 1 and "t = 0.5 s" in str(warned[0].message) and "push" in str(warned[0].message)
    assert [r["time"] for r in res.stats["singular"]] == [0.5]
    assert res.stats["singular"][0]["conditioning"] < 1e-4 and "O" in res.stats["singular"][0]["joints"]


def test_the_crank_keeps_turning_through_the_dead_centre(run):
    res, slider, _ = run
    th = TH0 + res.joint_coordinate("O")
    cf = closed_form(res.time, res.position(slider)[:, 0])
    far = np.abs(res.time - TC) > 0.015
    np.testing.assert_allclose(th[far], cf[far], atol=1e-9)
    assert np.max(np.abs(th - cf)) < 1e-5                  # at the singular sample (Newton is linear there)
    rate = np.sqrt(2 * C / (R * (1 + R / L)))
    assert res.joint_velocity("O")[50] == pytest.approx(-rate, rel=1e-4)   # not the min-norm 0
    assert np.all(np.diff(th) < 0)


@pytest.mark.parametrize("t", [0.497, 0.4999, 0.5001, 0.503])
def test_at_near_the_dead_centre_stays_on_the_branch_of_the_bracketing_samples(run, t):
    res, slider, _ = run
    for r in (res, Result(res.system, res.time, res.q, res.v, res.vd, res.lambda_)):   # dense, Hermite
        a = r.at(t)
        th = TH0 + a.joint_coordinate("O")[0]
        assert np.sign(th) == np.sign(TC - t)
        assert th == pytest.approx(closed_form(t, a.position(slider)[0, 0]), abs=2e-6)


def test_a_crank_driven_slider_crank_is_not_flagged():
    model, _ = slider_crank(TH0)
    model.add_motion("turn", "O", velocity=2 * np.pi)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = mb.kinematics(model, 1.0, 0.01)
    assert res.stats["singular"] == []
    assert not [w for w in caught if issubclass(w.category, mb.SingularConfigurationWarning)]
