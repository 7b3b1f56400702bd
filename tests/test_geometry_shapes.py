"""Issue 30: geometry classes, Body.add_shape, mass properties against closed forms and trimesh, errors."""
import numpy as np
import pytest
import trimesh

import mbdsim as mb
from mbdsim.errors import ModelError

CUBE = 0.5 * np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)


def test_mass_properties_of_meshes_match_the_closed_forms(tmp_path):
    rho, a, b, c = 700.0, 0.2, 0.3, 0.5
    m_box, I_box = mb.Box((a, b, c)).mass_properties(rho)
    hull = mb.ConvexMesh(CUBE * (a, b, c))
    m_h, c_h, I_h = hull.mass_properties(rho)
    assert np.isclose(m_h, m_box, rtol=1e-12) and np.allclose(c_h, 0, atol=1e-15)
    assert np.allclose(I_h, I_box, rtol=1e-12, atol=1e-15)
    path = tmp_path / "box.stl"
    trimesh.creation.box((a, b, c)).export(path)
    m_s, _, I_s = mb.Mesh(path).mass_properties(rho)
    assert np.isclose(m_s, m_box, rtol=1e-6) and np.allclose(I_s, I_box, rtol=1e-6)   # (STL: float32)


def test_capsule_and_ellipsoid_mass_properties_against_fine_tessellations():
    rho, r, L = 1000.0, 0.05, 0.2
    m, I = mb.Capsule(r, L, axis="x").mass_properties(rho)
    t = trimesh.creation.capsule(height=L, radius=r, count=[128, 128])
    t.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, (0, 1, 0)))   # z -> x
    t.density = rho
    assert np.isclose(m, t.mass, rtol=2e-3)
    assert np.allclose(I, t.moment_inertia, rtol=5e-3, atol=1e-9)
    radii = np.array([0.1, 0.2, 0.3])
    m, I = mb.Ellipsoid(radii).mass_properties(rho)
    s = trimesh.creation.icosphere(subdivisions=5)
    s.vertices = s.vertices * radii
    s.density = rho
    assert np.isclose(m, s.mass, rtol=2e-3)
    assert np.allclose(np.diag(I), np.diag(s.moment_inertia), rtol=5e-3)


def test_add_shape_with_density_adds_mass_and_parallel_axis_inertia():
    m = mb.Model()
    b = m.add_body("dumbbell", 0.0, position=(1, 2, 3))
    for side, x in (("left", -0.5), ("right", 0.5)):
        b.add_shape(side, mb.Sphere(radius=0.1), center=(1 + x, 2, 3), density=1000.0)
    ms, Is = mb.Sphere(radius=0.1).mass_properties(1000.0)
    assert np.isclose(b.mass, 2 * ms)
    assert np.allclose(b.inertia, 2 * Is + 2 * ms * 0.25 * np.diag([0, 1, 1]))
    cyl = b.add_shape("rod", mb.Cylinder(0.02, 1.0, axis=(1, 0, 0)))
    assert np.allclose(cyl.center, (1, 2, 3)) and cyl.geometry.axis == (1.0, 0.0, 0.0)


def test_bad_geometry_and_pairs_are_named_errors(tmp_path):
    m = mb.Model()
    b = m.add_body("b", 1.0, (1, 1, 1))
    c = m.add_body("c", 1.0, (1, 1, 1), position=(1, 0, 0))
    with pytest.raises(ModelError, match="mesh 'nofile.stl'.path"):
        mb.Mesh("nofile.stl")
    with pytest.raises(ModelError, match="convex mesh.vertices"):
        mb.ConvexMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])   # flat
    with pytest.raises(ModelError, match="shape 'b.x'.geometry"):
        b.add_shape("x", "box")
    cb = b.add_shape("cyl", mb.Cylinder(0.1, 0.2))
    tri = (np.vstack([np.eye(3), np.zeros((1, 3))]), [[0, 1, 2], [3, 1, 0]])
    with pytest.raises(ModelError, match="contact 'k'.shape_j.*plane-plane"):
        m.add_contact("k", mb.Plane(b, (0, 0, 0), (0, 0, 1)), mb.Plane(c, (0, 0, 0), (0, 0, 1)), 1e5, 1.5, 10, 1e-3)
    m.add_contact("mm", b.add_shape("m", mb.Mesh(*tri)), c.add_shape("m", mb.Mesh(*tri)), 1e5, 1.5, 10, 1e-3)
    with pytest.raises(ModelError, match="contact 'k'.transition_velocity"):
        m.add_contact("k", cb, c.add_shape("box", mb.Box((1, 1, 1))), 1e5, 1.5, 10, 1e-3, mu_static=0.5,
                      mu_dynamic=0.4, stiction_velocity=0.1, transition_velocity=0.01)
    with pytest.raises(ModelError, match="contact 'k'.restitution"):
        m.add_contact("k", cb, c.shapes["box"], 1e5, 1.5, 10, 1e-3, restitution=1.5)


def test_contact_results_in_the_dataframe():
    m = mb.Model(gravity=(0, 0, -9.81))
    b = m.add_body("box", 1.0, (1e-3,) * 3, position=(0, 0, 0.05 - (9.81 / 4e6)))
    m.add_contact("floor", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), b.add_shape("g", mb.Box((0.1, 0.1, 0.1))),
                  1e6, 1.0, 100.0, 1e-5)
    res = mb.simulate(m, 0.05, 0.01, method="dop853", rtol=1e-6)
    df = res.to_dataframe()
    assert np.allclose(df["floor.Fz [N]"], 9.81, rtol=5e-2)   # (rtol 1e-6: a 6e-8 m ripple about the rest)
    assert (df["floor.points [-]"] == 4).all()
    assert np.allclose(res.contact_force("floor")[:, :2], 0, atol=1e-9)
    pts = res.contact_points("floor")
    assert set(pts.shape_j) == {"box.g"} and np.allclose(pts.penetration, 9.81 / 4e6, rtol=5e-2)
