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
    assert res.stats["method"] == "kinematic (compiled sweep)"   # through the dead centre by continuity
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


# ----------------------------------------------------------------------------- issue 34: geometry, not mass
RB, RP, H = 1.0, 0.5, 1.0                                    # base and platform radii, height [m]
BASE = np.radians([-20.0, 20.0, 100.0, 140.0, 220.0, 260.0])
PLAT = np.radians([-40.0, 40.0, 80.0, 160.0, 200.0, 280.0])


def stewart(leg_mass):
    """6-UPS Stewart platform (platform 10 kg), each leg a cylinder and a piston of `leg_mass` [kg],
    the legs driven by 5 cm sines of staggered phase; the platform Jacobian's condition number is about
    4.6 as built and stays small over the motion."""
    m = mb.Model("stewart", gravity=(0, 0, -9.81))
    plat = m.add_body("platform", 10.0, inertia=(0.6, 0.6, 1.2), position=(0, 0, H))
    b = np.stack([RB * np.cos(BASE), RB * np.sin(BASE), np.zeros(6)], 1)
    p = np.stack([RP * np.cos(PLAT), RP * np.sin(PLAT), np.full(6, H)], 1)
    for k in range(6):
        d = p[k] - b[k]
        u = d / np.linalg.norm(d)
        a1 = np.cross((0, 0, 1.0), u)
        a1 /= np.linalg.norm(a1)
        inertia = (0.01 * leg_mass,) * 3
        cyl = m.add_body(f"cyl{k}", leg_mass, inertia=inertia, position=b[k] + 0.25 * d)
        pis = m.add_body(f"pis{k}", leg_mass, inertia=inertia, position=b[k] + 0.75 * d)
        m.add_universal(f"U{k}", "ground", cyl, b[k], a1, np.cross(u, a1))
        m.add_translational(f"P{k}", cyl, pis, b[k] + 0.5 * d, u)
        m.add_spherical(f"S{k}", pis, plat, p[k])
        ph = float(np.pi * k / 3)
        m.add_motion(f"leg{k}", f"P{k}", displacement=f"0.05*(sin(2*pi*t + {ph!r}) - {float(np.sin(ph))!r})")
    return m


def timed_kinematics(model):
    import time
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        t0 = time.perf_counter()
        res = mb.kinematics(model, 1.0, 0.01)
        wall = time.perf_counter() - t0
    return res, wall, [w for w in caught if issubclass(w.category, mb.SingularConfigurationWarning)]


def test_stewart_platform_with_near_massless_legs_is_not_flagged_singular():
    """Before issue 34 the test weighed the Jacobian's columns by 1/sqrt(mass): legs of 1e-6 kg made
    every sample 'singular' (101 flagged, the Python path instead of the compiled sweep, 16-56 s)."""
    timed_kinematics(stewart(1.0))                             # compiles / loads the kernels
    heavy, t_heavy, w_heavy = timed_kinematics(stewart(1.0))
    light, t_light, w_light = timed_kinematics(stewart(1e-6))
    for res, warned in ((heavy, w_heavy), (light, w_light)):
        assert res.success and res.stats["singular"] == [] and not warned
        assert res.stats["method"] == "kinematic (compiled sweep)"
    assert light.stats["steps"] == heavy.stats["steps"]
    np.testing.assert_allclose(light.position("platform"), heavy.position("platform"), atol=1e-9)
    assert t_light < 3 * t_heavy + 1.0


def test_dead_centre_with_near_massless_links_is_still_flagged():
    """The geometric test flags a true singularity whatever the masses: the slider-driven slider-crank
    through its dead centre with rod and slider of 1e-6 kg."""
    model, _ = slider_crank(TH0)
    for name in ("rod", "slider"):
        body = model.bodies[name]
        body.mass, body.inertia = body.mass * 1e-6, body.inertia * 1e-6
    model.add_motion("push", "slide", displacement=f"{float(C)!r}*(2*{TC}*t - t**2)")
    res, _, warned = timed_kinematics(model)
    assert [r["time"] for r in res.stats["singular"]] == [0.5] and len(warned) == 1


@pytest.mark.parametrize("mass, length", [(1e-6, 1e-4), (1e6, 1e3), (1e100, 1.0), (1e-100, 1.0), (1.0, 1e-6)])
def test_thresholds_are_relative_to_the_model_scale(mass, length):
    """Issue 35: a 1 mg, 0.1 mm pendulum (and masses of 1e+-100 kg) runs and is tabled: a uniform rod
    released from horizontal pulls on its pin with m g / 4 at t = 0 (a_cm = 3 g / 4), and its
    reactions, accelerations and the table are finite whatever the scale."""
    import warnings
    m = mb.Model("p", gravity=(0.0, -9.81, 0.0))
    inertia = mass * length ** 2 / 12.0
    rod = m.add_body("rod", mass, inertia=(inertia, inertia, inertia), position=(length / 2, 0.0, 0.0))
    m.add_revolute("pin", m.ground, rod, (0, 0, 0), (0, 0, 1))
    period = 2 * np.pi * np.sqrt(2 * length / 3 / 9.81)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = mb.simulate(m, period / 4, period / 40)
        df = res.to_dataframe()
    assert res.success and np.isfinite(df.to_numpy()).all()
    F = np.asarray(res.reaction_force("pin", on="rod"))
    assert F[0] / (mass * 9.81) == pytest.approx([0.0, 0.25, 0.0], abs=1e-9)
    assert res.acceleration("rod")[0, 1] / 9.81 == pytest.approx(-0.75, rel=1e-9)
