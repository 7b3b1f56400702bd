"""Issue 30: an eccentric cam (a cylinder, or a convex mesh of its section) drives a flat-faced follower on a
spring: the lift follows e (1 - cos w t) and the follower lifts off above the closed-form speed."""
import numpy as np
import pytest

import mbdsim as mb

E_CAM, R_CAM, MASS, KS, F0 = 0.01, 0.03, 0.5, 200.0, 5.0
KC = 1e7


def lift_off_speed():
    """Contact force at the top of the stroke: F0 + 2 KS E - m E w^2 (no gravity) = 0."""
    return np.sqrt((F0 + 2 * KS * E_CAM) / (MASS * E_CAM))


def cam_model(w, geometry="cylinder"):
    m = mb.Model()   # no gravity: the spring alone holds the follower on the cam
    cam = m.add_body("cam", 1.0, (1e-3, 1e-3, 1e-3), position=(0, 0, -E_CAM))   # lowest point of the stroke
    m.add_revolute("shaft", m.ground, cam, (0, 0, 0), (0, 1, 0))
    m.add_motion("turn", "shaft", displacement=f"{w}*t")
    if geometry == "cylinder":
        g = mb.Cylinder(R_CAM, 0.02, axis="y")
    else:
        a = np.linspace(0, 2 * np.pi, 65)[:-1]
        ring = np.column_stack([R_CAM * np.cos(a), np.zeros_like(a), R_CAM * np.sin(a)])
        g = mb.ConvexMesh(np.vstack([ring + (0, -0.01, 0), ring + (0, 0.01, 0)]))
    cam_shape = cam.add_shape("disc", g)
    delta = (F0 / 2 / KC)   # two points (the line's ends) share the preload
    z0 = -E_CAM + R_CAM + 0.01 - delta
    fol = m.add_body("follower", MASS, (1e-4, 1e-4, 1e-4), position=(0, 0, z0))
    m.add_translational("guide", m.ground, fol, (0, 0, z0), (0, 0, 1))
    face = fol.add_shape("face", mb.Box((0.08, 0.04, 0.02)))
    H = 0.2
    m.add_spring_damper("spring", (m.ground, (0, 0, H)), (fol, (0, 0, z0)), KS, 0.0, free_length=H - z0 + F0 / KS)
    m.add_contact("touch", cam_shape, face, KC, 1.0, 50.0, 1e-6, mu=0.0)
    return m, z0


@pytest.mark.parametrize("geometry", ["cylinder", "convex"])
def test_follower_lift_follows_the_eccentric_profile(geometry):
    # a polygonal cam shakes the follower at n w with accelerations of about R pi^2 w^2 / 2 (whatever n):
    # turned slowly enough for the spring to hold the follower on it
    w = (0.7 if geometry == "cylinder" else 0.15) * lift_off_speed()
    m, z0 = cam_model(w, geometry)
    T = 2 * np.pi / w
    res = mb.simulate(m, T, T / 100, method="dop853", rtol=1e-8)
    assert res.success
    lift = res.position("follower")[:, 2] - z0
    ref = E_CAM * (1 - np.cos(w * res.time))
    # a 64-gon: its height varies by R (1 - cos(pi / 64)) = 0.4 % of the stroke, and each corner passing under
    # the follower kicks it (a jump of the profile's slope, 0.02 m/s) into a small bounce
    tol = 2e-3 * E_CAM if geometry == "cylinder" else 2e-2 * E_CAM
    assert np.max(np.abs(lift - ref)) < tol, np.max(np.abs(lift - ref)) / E_CAM


@pytest.mark.parametrize("factor, lifts_off", [(0.95, False), (1.05, True)])
def test_follower_lifts_off_above_the_closed_form_speed(factor, lifts_off):
    w = factor * lift_off_speed()
    m, z0 = cam_model(w)
    T = 2 * np.pi / w
    res = mb.simulate(m, T, T / 200, method="dop853", rtol=1e-8)
    assert res.success
    lift = res.position("follower")[:, 2] - z0
    gap = lift - E_CAM * (1 - np.cos(w * res.time))
    assert (gap.max() > 1e-2 * E_CAM) == lifts_off, gap.max() / E_CAM
