"""Issue 30: curved shapes (sphere, capsule, cylinder, ellipsoid) on the edges of boxes and on the ridges and
peaks of triangle meshes, where no vertex or rim point of the curved shape lies over a face: a box edge on a
sphere or across a cylinder, a cylinder lying along a ridge, an ellipsoid on a peak.  Closed forms: the depth
of each point from the geometry (the distance of the edge or ridge from the solid), its force k d^e (IMPACT,
no damping at rest), the normal of the nearest surface point; at rest on two ridges the lever rule."""
import numpy as np
import pytest

import mbdsim as mb
from test_shape_contact_ridge import _up, ridges   # faces turned up; two tents along y, ridges at x = +-0.03

G, K, E = 9.81, 1e6, 1.5
H, W = 0.02, 0.04   # tent: ridge height and half width [m]


def tent():
    """A tent along x (one ridge edge at y = 0, z = H, x in [-0.3, 0.3]) on a flat floor z = 0."""
    prof = [(-0.3, 0.0), (-W, 0.0), (0.0, H), (W, 0.0), (0.3, 0.0)]
    v = np.array([(x, y, z) for y, z in prof for x in (-0.3, 0.3)])
    f = []
    for i in range(len(prof) - 1):
        f += [(2 * i, 2 * i + 2, 2 * i + 3), (2 * i, 2 * i + 3, 2 * i + 1)]
    return v, _up(v, f)


def pyramid():
    """A square pyramid of height H over a 0.06 m square (faces at 34 degrees): a peak at (0, 0, H)."""
    v = np.array([[-0.03, -0.03, 0], [0.03, -0.03, 0], [0.03, 0.03, 0], [-0.03, 0.03, 0], [0, 0, H]], float)
    return v, _up(v, [(0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)])


def _rot(axis, ang):
    c, s = np.cos(ang), np.sin(ang)
    return {"x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]), "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])}[axis]


def _points(ground_geo, geo, pos, orient=None, center=None, gorient=None):
    """The contact points at t = 0 of a body (mass 1) carrying geo at pos over the ground shape."""
    m = mb.Model(gravity=(0, 0, -G))
    b = m.add_body("b", 1.0, (1e-3,) * 3, position=pos, orientation=orient)
    fl = m.ground.add_shape("floor", ground_geo, center=center, orientation=gorient)
    m.add_contact("c", fl, b.add_shape("g", geo), K, E, 0.0, 1e-5)
    res = mb.simulate(m, 1e-4, 1e-4, method="dop853", rtol=1e-8, monitor=False)
    pts = res.contact_points("c")
    return pts[pts.time == 0.0].sort_values("x")


def _hull_cube():
    """The 0.2 m cube as a convex hull of its corners."""
    return mb.ConvexMesh(0.1 * np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]))


D = 3e-4   # depth [m]
EDGE = dict(gorient=_rot("x", np.pi / 4), center=(0, 0, -0.1 * np.sqrt(2)))   # a 0.2 m box, its top edge on x


@pytest.mark.parametrize("geo, pos, n_ref, tol", [
    (mb.Sphere(radius=0.05), (0.03, 0.0, 0.05 - D), (0, 0, 1), 1e-9),
    (mb.Sphere(radius=0.05), (0.0, 0.6 * (0.05 - D), 0.8 * (0.05 - D)), (0, 0.6, 0.8), 1e-9),
    (mb.Capsule(0.05, 0.1, axis="y"), (0.02, 0.0, 0.05 - D), (0, 0, 1), 1e-7),  # golden section
    (mb.Cylinder(0.05, 0.1, axis="y"), (0.0, 0.0, 0.05 - D), (0, 0, 1), 1e-5),    # GJK/EPA
    (mb.Ellipsoid((0.08, 0.05, 0.03)), (0.0, 0.0, 0.03 - D), (0, 0, 1), 1e-5),  # GJK/EPA
])
@pytest.mark.parametrize("edge", ["box", "hull"])
def test_curved_shape_on_a_box_edge_is_one_point_of_the_exact_depth(geo, pos, n_ref, tol, edge):
    """A box's top edge (along x, at z = 0) under a sphere (also off to the side: the normal along the line from
    the edge to the centre), a capsule and a cylinder across it, an ellipsoid on it: one point, as deep as the
    radius (semi-axis) less the centre's distance from the edge, its force k d^e; the normal to tol (EPA's
    polytope on a curved Minkowski difference: a few 1e-6; the same for the box as a convex hull, by EPA)."""
    if edge == "hull":
        box, tol = _hull_cube(), 1e-5
    else:
        box = mb.Box((0.2, 0.2, 0.2))
    p = _points(box, geo, pos, **EDGE)
    assert len(p) == 1, p
    assert abs(p.penetration.iloc[0] - D) < 1e-6 * D, p.penetration.iloc[0]
    assert abs(p.normal_force.iloc[0] - K * D ** E) < 1e-5 * K * D ** E
    assert np.allclose(p[["nx", "ny", "nz"]].to_numpy()[0], n_ref, atol=tol), p[["nx", "ny", "nz"]]
    assert abs(p.x.iloc[0] - pos[0]) < 1e-6


@pytest.mark.parametrize("geo", [mb.Capsule(0.05, 0.1, axis="x"), mb.Cylinder(0.05, 0.1, axis="x")])
@pytest.mark.parametrize("theta", [0.0, 0.004])
@pytest.mark.parametrize("edge", ["box", "hull"])
def test_capsule_and_cylinder_lying_along_a_box_edge_touch_at_both_ends(geo, theta, edge):
    """Lying along the box's top edge, tilted by theta about y: a line contact, a point at each end of the
    axis (x = +-h cos theta on the edge), each as deep as the radius less the distance of that edge point
    from the axis (its end at axial coordinate +-h): the deeper end carries more, as a line contact must."""
    r, h, zc = 0.05, 0.05, 0.05 - D
    box = mb.Box((0.2, 0.2, 0.2)) if edge == "box" else _hull_cube()
    p = _points(box, geo, (0.0, 0.0, zc), _rot("y", -theta), **EDGE)
    assert len(p) == 2, p
    u = np.array([np.cos(theta), 0.0, np.sin(theta)])   # the axis, tilted: end +x up
    for s, (_, row) in zip((-1, 1), p.iterrows()):
        xq = (s * h + zc * u[2]) / u[0]   # the edge point (xq, 0, 0) at axial coordinate s h
        dist = np.linalg.norm(np.array([xq, 0, 0]) - (np.array([0, 0, zc]) + s * h * u))
        d = r - dist
        assert abs(row.penetration - d) < 1e-9, (row.penetration, d)
        assert abs(row.normal_force - K * d ** E) < 1e-6 * K * d ** E
        assert abs(row.x - xq) < 1e-6
    if theta > 0.0:
        assert p.normal_force.iloc[0] > p.normal_force.iloc[1]   # the lower (x < 0) end


@pytest.mark.parametrize("geo, zc, npts", [
    (mb.Cylinder(0.05, 0.2, axis="x"), H + 0.05 - D, 2),   # along the ridge: a line, both ends
    (mb.Cylinder(0.05, 0.2, axis="y"), H + 0.05 - D, 1),   # across it
    (mb.Capsule(0.05, 0.2, axis="y"), H + 0.05 - D, 1),    # across it: the middle of the core
    (mb.Ellipsoid((0.08, 0.05, 0.03)), H + 0.03 - D, 1),
])
def test_curved_shape_on_a_mesh_ridge(geo, zc, npts):
    """A cylinder, capsule or ellipsoid on the ridge of a tent mesh (no rim point or end sphere over a face):
    the points on the ridge, each D deep (the radius less the height of the axis over the ridge), the normal
    up (between the two faces'), k D^e each; along the ridge at x = +-L/2."""
    p = _points(mb.Mesh(*tent()), geo, (0.0, 0.0, zc))
    assert len(p) == npts, p
    assert np.allclose(p.penetration, D, rtol=1e-6), p.penetration
    assert np.allclose(p.normal_force, K * D ** E, rtol=1e-5)
    assert np.allclose(p[["nx", "ny", "nz"]].to_numpy(), (0, 0, 1), atol=1e-6)
    assert np.allclose(p.y, 0.0, atol=1e-6) and np.allclose(p.z, H - D / 2, atol=1e-6)
    if npts == 2:
        assert np.allclose(p.x, (-0.1, 0.1), atol=1e-9)


def test_ellipsoid_and_cylinder_on_a_mesh_peak():
    """A pyramid's apex under an ellipsoid and under a lying cylinder: one point at the apex, D deep."""
    for geo, zc in ((mb.Ellipsoid((0.04, 0.05, 0.03)), H + 0.03 - D), (mb.Cylinder(0.05, 0.1, axis="x"), H + 0.05 - D)):
        p = _points(mb.Mesh(*pyramid()), geo, (0.0, 0.0, zc))
        assert len(p) == 1, p
        assert abs(p.penetration.iloc[0] - D) < 1e-6 * D
        assert np.allclose(p[["x", "y", "z"]].to_numpy()[0], (0, 0, H - D / 2), atol=1e-6)


def test_cylinder_beside_a_ridge_pushes_on_the_face_alone():
    """A cylinder lying along the tent's ridge but resting on one sloped face beside it (its axis over the
    face, the ridge inside its chord): the face's normal cone excludes the ridge, so only the face pushes
    (two rim points, each k d^e with d the depth below that face), nothing doubled."""
    r, d = 0.05, D
    a = np.arctan2(H, W)
    m1 = np.array([0.0, -np.sin(a), np.cos(a)])   # the face on y < 0
    s = 0.002   # the foot this far down the face from the ridge, which is then D - s^2 / (2 r) inside
    foot = np.array([0.0, 0.0, H]) - s * np.array([0.0, np.cos(a), np.sin(a)])
    c = foot + (r - d) * m1
    p = _points(mb.Mesh(*tent()), mb.Cylinder(r, 0.2, axis="x"), tuple(c))
    assert len(p) == 2, p
    assert np.allclose(p.penetration, d, rtol=1e-6), p.penetration
    assert np.allclose(p[["nx", "ny", "nz"]].to_numpy(), m1, atol=1e-6)


@pytest.mark.parametrize("geo", ["cylinder", "capsule"])
@pytest.mark.parametrize("c", [0.0, 0.01])
def test_cylinder_and_capsule_rest_across_two_ridges_by_the_lever_rule(geo, c):
    """Lying across two ridges (x = -+0.03) with the centre of mass at c: the ridges carry m g (0.03 -+ x) / 0.06
    (x the centre's final abscissa, c + r theta once the axis has tilted by theta = (d2 - d1) / 0.06 about y),
    and the centre rests r above the line through the two ridge points (the IMPACT law's depths)."""
    k, e, mass, r = 1e6, 1.5, 1.0, 0.02
    x = c
    for _ in range(20):   # fixed point of the lever rule and the tilt
        F = mass * G * np.array([0.03 - x, 0.03 + x]) / 0.06
        d = (F / k) ** (1 / e)
        x = c + r * (d[1] - d[0]) / 0.06
    zf = H + r - (d[0] + (c + 0.03) * (d[1] - d[0]) / 0.06)
    shape = mb.Cylinder(r, 0.1, axis="x") if geo == "cylinder" else mb.Capsule(r, 0.1, axis="x")
    m = mb.Model(gravity=(0, 0, -G))
    b = m.add_body("b", mass, (1e-4, 2e-4, 2e-4), position=(c, 0.0, H + r - d.mean()))
    fl = m.ground.add_shape("floor", mb.Mesh(*ridges()))
    m.add_contact("c", fl, b.add_shape("geo", shape), k, e, 300.0, 1e-5, mu=0.5, friction_velocity=1e-3)
    res = mb.simulate(m, 0.3, 0.01, method="dop853", rtol=1e-8)
    assert res.success
    assert abs(res.position("b")[-1, 2] - zf) < 1e-2 * d.min(), (res.position("b")[-1, 2] - zf, d)
    pts = res.contact_points("c")
    last = pts[pts.time == pts.time.max()].sort_values("x")
    assert len(last) == 2, last
    assert np.allclose(last.x, (-0.03, 0.03), atol=1e-4)
    assert np.allclose(last.normal_force, F, rtol=2e-3), (last.normal_force, F)
    assert abs(last.normal_force.sum() - mass * G) < 1e-3 * mass * G


@pytest.mark.parametrize("c", [0.0, 0.012])
def test_cylinder_standing_across_a_ridge_is_a_line_load_on_the_chord(c):
    """A cylinder (r = 0.03) standing on its end across the tent's ridge (along x), its axis c off the ridge: the
    ridge touches the end disc along the chord |x| <= sqrt(r^2 - c^2), D deep all along, a uniform line load whose
    resultant (k D^e at each end of the chord) acts at the chord's middle: the moment about the centre is that of
    the line-load integral, int (s, -c, -z) x (0, 0, q) ds = (-c F, 0, 0), zero through the axis."""
    r, hl = 0.03, 0.05
    zc = H + hl - D
    p = _points(mb.Mesh(*tent()), mb.Cylinder(r, 2 * hl, axis="z"), (0.0, c, zc))
    assert len(p) == 2, p
    half = np.sqrt(r * r - c * c)
    assert np.allclose(p.x, (-half, half), atol=1e-9) and np.allclose(p.y, 0.0, atol=1e-9)
    assert np.allclose(p.penetration, D, rtol=1e-9)
    assert np.allclose(p[["nx", "ny", "nz"]].to_numpy(), (0, 0, 1), atol=1e-12)
    Fz = p.normal_force.to_numpy()
    arm = p[["x", "y", "z"]].to_numpy() - (0.0, c, zc)
    moment = np.cross(arm, np.column_stack([0 * Fz, 0 * Fz, Fz])).sum(axis=0)
    assert np.allclose(moment, (-c * 2 * K * D ** E, 0.0, 0.0), rtol=1e-9, atol=1e-12), moment


def test_cylinder_standing_across_a_ridge_through_its_axis_stays_upright():
    """The ridge through the axis carries the weight at the chord's two ends, m g / 2 = k d^e each: the cylinder,
    let down from half that depth, settles upright at the IMPACT penetration, no moment turning it (the choice
    of the chord by the line's geometry, not by the deepest point along the level chord, keeps the force smooth:
    7 steps to 0.01 s, where the deepest point's end-or-side switch took 85 000)."""
    r, hl, mass = 0.03, 0.05, 1.0
    d = (mass * G / 2 / K) ** (1 / E)
    z0 = H + hl - d
    m = mb.Model(gravity=(0, 0, -G))
    Ix = mass * (3 * r * r + 4 * hl * hl) / 12   # a solid cylinder's
    b = m.add_body("b", mass, (Ix, Ix, mass * r * r / 2), position=(0.0, 0.0, z0 + d / 2))   # settles from d / 2
    fl = m.ground.add_shape("floor", mb.Mesh(*tent()))
    m.add_contact("c", fl, b.add_shape("geo", mb.Cylinder(r, 2 * hl, axis="z")), K, E, 300.0, 1e-5, mu=0.5,
                  friction_velocity=1e-3)
    res = mb.simulate(m, 0.3, 0.01, method="dop853", rtol=1e-8)
    assert res.success
    assert abs(res.position("b")[-1, 2] - z0) < 1e-3 * d
    assert np.max(np.abs(res.orientation("b")[-1] - np.eye(3))) < 1e-9
    pts = res.contact_points("c")
    last = pts[pts.time == pts.time.max()].sort_values("x")
    assert len(last) == 2, last
    assert np.allclose(last.x, (-r, r), atol=1e-6)
    assert np.allclose(last.normal_force, mass * G / 2, rtol=1e-3)
