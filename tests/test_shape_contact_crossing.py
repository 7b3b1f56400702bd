"""Issue 30: contact polygons whose corners are edge crossings, and closed meshes thinner than the shape on them.

A box resting across a convex hull's ridge or a box's edge touches along the ridge's part under its bottom
face, with no vertex of either shape inside the other: the two points where the ridge leaves the box's bottom
face (through its side faces) carry the weight by the lever rule.  A box resting off-centre on another
touches over the overlap of the two squares, two of whose corners are edge crossings; with linear springs
(exponent 1) the four corners carry m g / 4 (1 + c_x x_i / X^2 + c_y y_i / Y^2) (c: the centre of mass from
the polygon's centre, x_i = +-X, y_i = +-Y its corners), the static equilibrium of a rigid plate on four
equal springs.  A box or a standing cylinder on a closed mesh plate thinner than itself rests on the top face
alone (n points of k d^e = m g / n), the plate's far face pushing nothing.
"""
import numpy as np
import pytest
import trimesh

import mbdsim as mb

G = 9.81
A = 0.1   # box side [m]


def _last(res, name):
    pts = res.contact_points(name)
    return pts[pts.time == pts.time.max()]


def _roof(kind):
    """A ridge along x at z = 0, 0.4 m long (longer than the box): a hull prism, or a box turned 45 degrees."""
    if kind == "hull":
        tri = np.array([[-0.05, -0.05], [0.05, -0.05], [0.0, 0.0]])   # (y, z)
        pts = np.array([[x, y, z] for x in (-0.2, 0.2) for y, z in tri])
        return mb.ConvexMesh(pts), (0.0, 0.0, 0.0), None
    c, s = np.cos(np.pi / 4), np.sin(np.pi / 4)
    return mb.Box((0.4, A, A)), (0.0, 0.0, -A / np.sqrt(2)), np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


@pytest.mark.parametrize("roof", ["hull", "box"])
@pytest.mark.parametrize("cube", ["box", "convex"])
@pytest.mark.parametrize("c", [0.0, 0.01])
def test_box_rests_across_a_ridge_on_the_two_crossings_by_the_lever_rule(roof, cube, c):
    """The ridge crosses the box's bottom face from x = -a/2 to a/2; the centre of mass c off the box's middle
    along the ridge: F+- = m g (1/2 +- c / a), each k d^e deep (IMPACT), the normals up."""
    k, e, mass = 1e6, 1.5, 1.0
    m = mb.Model(gravity=(0, 0, -G))
    geo, at, R = _roof(roof)
    ridge = m.ground.add_shape("roof", geo, center=at, orientation=R)
    d = (mass * G / 2 / k) ** (1 / e)
    b = m.add_body("box", mass, (mass * A * A / 6,) * 3, position=(c, 0.0, A / 2 - d))
    g = mb.Box((A, A, A)) if cube == "box" else \
        mb.ConvexMesh(0.5 * A * np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]))
    b.add_shape("geo", g, center=(0.0, 0.0, A / 2 - d))
    m.add_contact("c", ridge, b.shapes["geo"], k, e, 300.0, 1e-5, mu=0.5, friction_velocity=1e-3)
    res = mb.simulate(m, 0.2, 0.01, method="dop853", rtol=1e-8)
    assert res.success
    last = _last(res, "c").sort_values("x")
    assert len(last) == 2, last
    xb = res.position("box")[-1, 0] - c   # the box's middle
    assert np.allclose(last.x, [xb - A / 2, xb + A / 2], atol=1e-4), last.x
    assert np.allclose(last.y, 0.0, atol=1e-6) and np.allclose(last.nz, 1.0, atol=1e-4)
    F = mass * G * np.array([0.5 - c / A, 0.5 + c / A])
    assert np.allclose(last.normal_force, F, rtol=2e-3), (last.normal_force, F)
    assert np.allclose(last.penetration, (F / k) ** (1 / e), rtol=2e-3)
    if c == 0.0:
        assert abs(res.position("box")[-1, 2] - (A / 2 - d)) < 1e-3 * d


def test_off_centre_box_on_a_box_rests_on_the_four_corners_of_the_overlap():
    """Upper box shifted by (s, s): the overlap is the square [-a/2 + s, a/2]^2, whose corners (-a/2 + s, a/2)
    and (a/2, -a/2 + s) are edge crossings; linear springs (e = 1) give the closed-form corner forces."""
    k, mass, s = 1e6, 1.0, 0.01
    m = mb.Model(gravity=(0, 0, -G))
    base = m.ground.add_shape("base", mb.Box((A, A, A)), center=(0, 0, -A / 2))
    b = m.add_body("top", mass, (mass * A * A / 6,) * 3, position=(s, s, A / 2 - mass * G / 4 / k))
    m.add_contact("c", base, b.add_shape("geo", mb.Box((A, A, A))), k, 1.0, 300.0, 1e-5, mu=0.5,
                  friction_velocity=1e-3)
    res = mb.simulate(m, 0.2, 0.01, method="dop853", rtol=1e-8)
    assert res.success
    last = _last(res, "c")
    assert len(last) == 4, last
    X = (A - s) / 2
    cx = cy = s / 2   # the centre of mass from the overlap's centre (s / 2, s / 2)
    xi, yi = last.x.to_numpy() - s / 2, last.y.to_numpy() - s / 2
    assert np.allclose(np.abs(xi), X, atol=1e-5) and np.allclose(np.abs(yi), X, atol=1e-5), (xi, yi)
    F = mass * G / 4 * (1 + cx * np.sign(xi) / X + cy * np.sign(yi) / X)
    assert np.allclose(last.normal_force, F, rtol=1e-3), (last.normal_force.to_numpy(), F)
    assert np.max(np.abs(res.orientation("top")[-1] - np.eye(3))) < 1e-3


@pytest.mark.parametrize("shape, n", [("box", 4), ("cylinder", 3)])
def test_shape_on_a_closed_mesh_plate_thinner_than_itself_rests_on_the_top_face(shape, n):
    """A 0.03 m plate (a closed trimesh box) under a 0.1 m box (four corners) or a cylinder standing on its
    end (the tripod of its rim): k d^e = m g / n at each point, the rest height from that."""
    k, e, mass, t = 1e6, 1.5, 1.0, 0.03
    plate = trimesh.creation.box((0.4, 0.4, t))
    m = mb.Model(gravity=(0, 0, -G))
    d = (mass * G / n / k) ** (1 / e)
    z = t / 2 + A / 2 - d
    b = m.add_body("part", mass, (mass * A * A / 6,) * 3, position=(0, 0, z))
    geo = mb.Box((A, A, A)) if shape == "box" else mb.Cylinder(A / 2, A, axis="z")
    floor = m.ground.add_shape("plate", mb.Mesh(plate.vertices, plate.faces))
    m.add_contact("c", floor, b.add_shape("geo", geo), k, e, 300.0, 1e-5, mu=0.5, friction_velocity=1e-3)
    res = mb.simulate(m, 0.2, 0.01, method="dop853", rtol=1e-8)
    assert res.success
    last = _last(res, "c")
    assert len(last) == n, last
    assert np.allclose(last.nz, 1.0, atol=1e-9)
    assert np.allclose(last.normal_force, mass * G / n, rtol=1e-3)
    assert abs(res.position("part")[-1, 2] - z) < 1e-3 * d
