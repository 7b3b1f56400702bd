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
    path = tmp_path / f"cube.{kind}"   # stl, obj or ply, written by trimesh and read back by mb.Mesh
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


@pytest.mark.parametrize("kind", ["box", "convex", "stl", "obj", "ply"])
def test_box_slides_down_an_incline_at_g_sin_minus_mu_cos(kind, tmp_path):
    theta, mu = np.radians(30), 0.3
    m, t = box_on_incline(theta, kind, tmp_path, v0=0.5, mu=mu, friction_velocity=1e-3)
    res = mb.simulate(m, 0.4, 0.005, method="dop853", rtol=1e-8)
    assert res.success
    a = fitted_acceleration(res, t, 0.1)
    ref = G * (np.sin(theta) - mu * np.cos(theta))
    assert abs(a / ref - 1) < 1e-3, (a, ref)


@pytest.mark.parametrize("kind", ["box", "convex", "stl", "obj", "ply"])
def test_box_stays_on_an_incline_steeper_friction_than_tan(kind, tmp_path):
    theta = np.radians(20)
    m, t = box_on_incline(theta, kind, tmp_path, mu_static=0.6, mu_dynamic=0.5, stiction_velocity=1e-3,
                          transition_velocity=1e-2)
    res = mb.simulate(m, 0.5, 0.01)
    assert res.success
    v = res.velocity("box") @ t
    assert np.max(np.abs(v[10:])) < 1e-3   # creep below the stiction velocity only
    s = res.position("box") @ t
    assert abs(s[-1] - s[0]) < 5e-4


@pytest.mark.parametrize("kind", ["cylinder", "capsule", "sphere"])
def test_rolling_without_slipping_down_an_incline(kind):
    theta, r, rho = np.radians(15), 0.05, 1000.0
    n, _, t = incline(theta)
    geo = {"cylinder": mb.Cylinder(r, 0.1, axis="y"), "capsule": mb.Capsule(r, 0.1, axis="y"),
           "sphere": mb.Sphere(radius=r)}[kind]
    npts = 1 if kind == "sphere" else 2
    m = mb.Model(gravity=(0, 0, -G))
    mass, I = geo.mass_properties(rho)[:2]
    delta = (mass * G * np.cos(theta) / (npts * K)) ** (1 / E)
    b = m.add_body("roller", 0.0, position=n * (r - delta))
    shape = b.add_shape("geo", geo, density=rho)
    assert np.isclose(b.mass, mass) and np.allclose(b.inertia, I)
    m.add_contact("c", mb.Plane(m.ground, (0, 0, 0), n), shape, K, E, 200.0, 1e-4, mu=0.5, friction_velocity=1e-4)
    res = mb.simulate(m, 0.4, 0.005, method="dop853", rtol=1e-8)
    assert res.success
    s = res.position("roller") @ t
    keep = res.time >= 0.1
    a = 2.0 * np.polyfit(res.time[keep], s[keep], 2)[0]
    ref = G * np.sin(theta) / (1 + I[1, 1] / (mass * r * r))
    assert abs(a / ref - 1) < 1e-3, (a, ref)
    w = res.angular_velocity("roller")[-1, 1]   # rolling: omega r = v
    assert abs(abs(w) * r / (res.velocity("roller")[-1] @ t) - 1) < 1e-3


def test_box_dropped_tilted_rests_flat_at_the_impact_penetration():
    from scipy.spatial.transform import Rotation
    a, mass, k, e = 0.1, 1.0, 1e5, 1.5
    m = mb.Model(gravity=(0, 0, -G))
    R = Rotation.from_euler("xy", (0.35, 0.2)).as_matrix()
    b = m.add_body("box", mass, (mass * a * a / 6,) * 3, position=(0, 0, 0.15), orientation=R)
    m.add_contact("c", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), b.add_shape("geo", mb.Box((a, a, a))),
                  k, e, 60.0, 1e-3, mu=0.4, friction_velocity=1e-3)
    res = mb.simulate(m, 1.5, 0.01)
    assert res.success
    delta = (mass * G / (4 * k)) ** (1 / e)   # four corners carry the weight
    z = res.position("box")[-1, 2]
    assert abs(z - (a / 2 - delta)) < 1e-2 * delta, (z, a / 2 - delta)
    up = res.orientation("box")[-1]
    assert np.max(np.abs(up.T @ (0, 0, 1))) > 1 - 1e-6   # a face flat on the floor
    assert np.linalg.norm(res.velocity("box")[-1]) < 1e-3


@pytest.mark.parametrize("factor, tips", [(0.98, False), (1.02, True)])
def test_cube_tips_over_its_edge_at_the_closed_form_push(factor, tips):
    a, mass = 0.1, 1.0
    m = mb.Model(gravity=(0, 0, -G))
    delta = (mass * G / (4 * K)) ** (1 / E)
    b = m.add_body("cube", mass, (mass * a * a / 6,) * 3, position=(0, 0, a / 2 - delta))
    m.add_contact("c", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), b.add_shape("geo", mb.Box((a, a, a))),
                  K, E, 400.0, 1e-4, mu=0.9, friction_velocity=1e-4)
    F_crit = mass * G * (a / 2) / a   # push at the top edge: F a = m g a / 2 about the far bottom edge
    m.add_force("push", (b, (-a / 2, 0, a - delta)), (factor * F_crit, 0, 0))
    res = mb.simulate(m, 0.6, 0.01)
    assert res.success
    tilt = np.arccos(np.clip(res.orientation("cube")[:, 2, 2], -1, 1))
    if tips:
        assert tilt[-1] > 0.1
    else:
        assert tilt.max() < 0.01


def test_poisson_restitution_gives_the_rebound_height():
    eps, h, r = 0.6, 0.2, 0.05
    m = mb.Model(gravity=(0, 0, -G))
    b = m.add_body("ball", 0.0, position=(0, 0, r + h))
    m.add_contact("c", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), b.add_shape("geo", mb.Sphere(radius=r),
                  density=1000.0), 1e6, 1.5, 0.0, 1e-3, restitution=eps)
    t_up = np.sqrt(2 * h / G) * (1 + eps)   # down, then up to the apex
    res = mb.simulate(m, t_up + 0.02, 1e-4, method="dop853", rtol=1e-9)
    z = res.position("ball")[:, 2]
    after = res.time > np.sqrt(2 * h / G) + 0.01
    h2 = z[after].max() - r
    # energy: loading stores W = k d^2.5 / 2.5 = m g (h + d) at the deepest point d, unloading returns
    # eps^2 W = m g (h2 + d)
    from scipy.optimize import brentq
    mass, k = b.mass, 1e6
    d = brentq(lambda d: k * d ** 2.5 / 2.5 - mass * G * (h + d), 1e-9, 0.1)
    ref = eps ** 2 * (h + d) - d
    assert abs(h2 / ref - 1) < 1e-3, (h2, ref)
