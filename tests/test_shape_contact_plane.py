"""Issue 30: shapes against a plane (box, convex and triangle mesh, cylinder, capsule, sphere, ellipsoid):
sliding and sticking on an incline, rolling without slipping, resting flat, tipping, restitution.
Closed-form references only."""
import numpy as np
import pytest

import mbdsim as mb

G = 9.81
K, E = 1e6, 1.0


def incline(theta):
    """(normal, rotation whose z is the normal, downhill unit tangent) of a plane through the origin."""
    n = np.array([-np.sin(theta), 0.0, np.cos(theta)])
    R = np.array([[np.cos(theta), 0, -np.sin(theta)], [0, 1, 0], [np.sin(theta), 0, np.cos(theta)]])
    g = np.array([0.0, 0.0, -1.0])
    t = g - (g @ n) * n
    return n, R, t / np.linalg.norm(t)


def box_geometry(kind, a, tmp_path):
    if kind == "box":
        return mb.Box((a, a, a))
    v = 0.5 * a * np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)
    if kind == "convex":
        return mb.ConvexMesh(v)
    import trimesh
    path = tmp_path / "cube.stl"
    trimesh.creation.box((a, a, a)).export(path)
    return mb.Mesh(path)


def box_on_incline(theta, kind, tmp_path, v0=0.0, **friction):
    n, R, t = incline(theta)
    a, mass = 0.1, 1.0
    m = mb.Model(gravity=(0, 0, -G))
    delta = (mass * G * np.cos(theta) / (4 * K)) ** (1 / E)   # four corners share the weight
    b = m.add_body("box", mass, (mass * a * a / 6,) * 3, position=n * (a / 2 - delta), orientation=R,
                   velocity=v0 * t)
    shape = b.add_shape("geo", box_geometry(kind, a, tmp_path))
    m.add_contact("c", mb.Plane(m.ground, (0, 0, 0), n), shape, K, E, 400.0, 1e-4, **friction)
    return m, t


def fitted_acceleration(res, t_dir, t0):
    s = res.position("box") @ t_dir
    keep = res.time >= t0
    return 2.0 * np.polyfit(res.time[keep], s[keep], 2)[0]


@pytest.mark.parametrize("kind", ["box", "convex", "stl"])
def test_box_slides_down_an_incline_at_g_sin_minus_mu_cos(kind, tmp_path):
    theta, mu = np.radians(30), 0.3
    m, t = box_on_incline(theta, kind, tmp_path, v0=0.5, mu=mu, friction_velocity=1e-3)
    res = mb.simulate(m, 0.4, 0.005, method="dop853", rtol=1e-8)
    assert res.success
    a = fitted_acceleration(res, t, 0.1)
    ref = G * (np.sin(theta) - mu * np.cos(theta))
    assert abs(a / ref - 1) < 1e-3, (a, ref)


def test_box_stays_on_an_incline_steeper_friction_than_tan(tmp_path):
    theta = np.radians(20)
    m, t = box_on_incline(theta, "box", tmp_path, mu_static=0.6, mu_dynamic=0.5, stiction_velocity=1e-3,
                          transition_velocity=1e-2)
    res = mb.simulate(m, 0.5, 0.01)
    assert res.success
    v = res.velocity("box") @ t
    assert np.max(np.abs(v[10:])) < 1e-3   # creep below the stiction velocity only
    s = res.position("box") @ t
    assert abs(s[-1] - s[0]) < 5e-4
