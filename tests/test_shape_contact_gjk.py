"""Issue 30: general convex pairs (GJK/EPA over support functions), a cylinder's line contact on a box, and
the sweep-and-prune broad phase (it passes only pairs whose bounding boxes overlap).  Closed forms only."""
import numpy as np
import pytest

import mbdsim as mb
from mbdsim.system.assemble import assemble_system
from mbdsim.system.force_elements.shape_contact import loads, packed
from mbdsim.system.frames import body_frames

G = 9.81


def test_cylinder_lying_on_a_box_incline_rolls_at_the_closed_form_acceleration():
    """The cylinder touches the box's top face along a line (two points), so it rolls instead of rocking:
    a = g sin(theta) / (1 + I / (m r^2))."""
    theta, r, rho, K, E = np.radians(15), 0.05, 1000.0, 1e6, 1.0
    n = np.array([-np.sin(theta), 0.0, np.cos(theta)])
    R = np.array([[np.cos(theta), 0, -np.sin(theta)], [0, 1, 0], [np.sin(theta), 0, np.cos(theta)]])
    t = np.array([-np.cos(theta), 0.0, -np.sin(theta)])   # downhill
    m = mb.Model(gravity=(0, 0, -G))
    ramp = m.add_body("ramp", 1.0, (1.0,) * 3, position=-0.05 * n, orientation=R)
    m.add_fixed("fix", m.ground, ramp)
    top = ramp.add_shape("geo", mb.Box((2.0, 0.4, 0.1)))
    geo = mb.Cylinder(r, 0.1, axis="y")
    mass, I = geo.mass_properties(rho)[:2]
    delta = (mass * G * np.cos(theta) / (2 * K)) ** (1 / E)
    b = m.add_body("roller", 0.0, position=n * (r - delta))
    shape = b.add_shape("geo", geo, density=rho)
    c = m.add_contact("c", top, shape, K, E, 200.0, 1e-4, mu=0.5, friction_velocity=1e-4)
    res = mb.simulate(m, 0.4, 0.005, method="dop853", rtol=1e-8)
    assert res.success
    s = res.position("roller") @ t
    keep = res.time >= 0.1
    a = 2.0 * np.polyfit(res.time[keep], s[keep], 2)[0]
    ref = G * np.sin(theta) / (1 + I[1, 1] / (mass * r * r))
    assert abs(a / ref - 1) < 1e-3, (a, ref)
    pts = res.contact_points("c")
    assert c and (pts.groupby("time").size() == 2).all()   # the line: one point at each end


def _ellipsoid_on(base_geo, top_height):
    """An ellipsoid (radii a, a, c; c vertical) let go at rest on a fixed base shape at the height where
    the IMPACT law carries its weight; returns (result, closed-form height of its centre)."""
    k, e, a, c, mass = 1e5, 1.5, 0.06, 0.03, 0.5
    d = (mass * G / k) ** (1 / e)
    m = mb.Model(gravity=(0, 0, -G))
    base = m.add_body("base", 1.0, (0.01,) * 3)
    m.add_fixed("fix", m.ground, base)
    s_base = base.add_shape("geo", base_geo)
    z = top_height + c - d
    inertia = (mass * (a * a + c * c) / 5, mass * (a * a + c * c) / 5, mass * 2 * a * a / 5)
    b = m.add_body("top", mass, inertia, position=(0, 0, z))
    m.add_contact("c", s_base, b.add_shape("geo", mb.Ellipsoid((a, a, c))), k, e, 20.0, 1e-3)
    return mb.simulate(m, 0.3, 0.01, method="dop853", rtol=1e-8), z, d


@pytest.mark.parametrize("base", ["sphere", "capsule"])
def test_ellipsoid_rests_on_a_sphere_and_a_capsule_at_the_impact_penetration(base):
    """The centre rests at top + c - (m g / k)^(1/e) (the sphere's centre, the capsule's segment at their
    distance from the ellipsoid: a pair that was refused)."""
    geo = {"sphere": mb.Sphere(radius=0.1), "capsule": mb.Capsule(0.05, 0.2, axis="x")}[base]
    top = 0.1 if base == "sphere" else 0.05
    res, z, d = _ellipsoid_on(geo, top)
    assert res.success
    p = res.position("top")
    assert abs(p[-1, 2] - z) < 1e-3 * d, (p[-1, 2] - z, d)
    assert np.max(np.abs(p[:, :2])) < 1e-3 * d   # no sideways drift from the normal


def test_sphere_rests_on_an_ellipsoid_and_on_a_lying_cylinder():
    """A sphere on a fixed ellipsoid and one on a fixed cylinder's side, at the IMPACT penetration."""
    k, e, mass = 1e5, 1.5, 0.5
    d = (mass * G / k) ** (1 / e)
    m = mb.Model(gravity=(0, 0, -G))
    base = m.add_body("base", 1.0, (0.01,) * 3)
    m.add_fixed("fix", m.ground, base)
    ell = base.add_shape("ell", mb.Ellipsoid((0.2, 0.15, 0.08)))
    cyl = base.add_shape("cyl", mb.Cylinder(0.04, 0.3, axis="x"), center=(1, 0, 0))
    s1 = m.add_body("s1", mass, (1e-3,) * 3, position=(0, 0, 0.08 + 0.05 - d))
    s2 = m.add_body("s2", mass, (1e-3,) * 3, position=(1.05, 0, 0.04 + 0.03 - d))
    m.add_contact("c", [ell, cyl], [s1.add_shape("g", mb.Sphere(radius=0.05)),
                                    s2.add_shape("g", mb.Sphere(radius=0.03))], k, e, 20.0, 1e-3)
    res = mb.simulate(m, 0.3, 0.01, method="dop853", rtol=1e-8)
    assert res.success
    assert abs(res.position("s1")[-1, 2] - (0.13 - d)) < 1e-3 * d
    assert abs(res.position("s2")[-1, 2] - (0.07 - d)) < 1e-3 * d


@pytest.mark.parametrize("case", ["ellipsoid on cylinder", "crossed cylinders", "ellipsoid on ellipsoid"])
def test_epa_depth_and_normal_against_closed_forms(case):
    """GJK/EPA (the pairs without a rounded side) on configurations whose depth is known: depth to 1e-9
    relative to the shapes' size, normal to 1e-4 (EPA stops within 1e-10 of the size: its normal is good
    to about the square root of that)."""
    from mbdsim.geometry.pack import pack_contacts
    from mbdsim.solvers.fastgjk import penetration
    dz = 2e-4
    geo_a, geo_b, top = {"ellipsoid on cylinder": (mb.Cylinder(0.05, 0.3, axis="x"), mb.Ellipsoid((0.06, 0.05, 0.03)),
                                                   0.05 + 0.03),
                         "crossed cylinders": (mb.Cylinder(0.04, 0.3, axis="x"), mb.Cylinder(0.03, 0.2, axis="y"),
                                               0.07),
                         "ellipsoid on ellipsoid": (mb.Ellipsoid((0.2, 0.1, 0.05)), mb.Ellipsoid((0.06, 0.05, 0.03)),
                                                    0.08)}[case]
    m = mb.Model()
    a = m.add_body("a", 1.0, (1, 1, 1))
    b = m.add_body("b", 1.0, (1, 1, 1), position=(0, 0, top - dz))
    c = m.add_contact("c", a.add_shape("g", geo_a), b.add_shape("g", geo_b), 1e5, 1.5, 10, 1e-3)
    sys = assemble_system(m)
    sc = pack_contacts(sys, [c])
    fr = body_frames(sys, sys.q0, sys.v0)
    from mbdsim.solvers.fastnarrow import pose
    P = [pose(fr.r, fr.A, sc[0][s], sc[2][s], sc[3][s]) for s in range(2)]
    depth, n0, n1, n2, *pt = penetration(sc, 0, 1, P[0], P[1], 1e-10 * (sc[5][0] + sc[5][1]))
    assert abs(depth - dz) < 1e-9 * (sc[5][0] + sc[5][1]), (depth, dz)
    assert abs(n2 - 1.0) < 1e-8 and abs(n0) < 1e-4 and abs(n1) < 1e-4
    top_a = {"ellipsoid on cylinder": 0.05, "crossed cylinders": 0.04, "ellipsoid on ellipsoid": 0.05}[case]
    assert abs(pt[2] - (top_a - 0.5 * dz)) < 1e-6   # midway in the overlap


def _narrow_count(m, elem):
    """Pairs the broad phase passes to the narrow phase at the model's initial state."""
    sys = assemble_system(m)
    fr = body_frames(sys, sys.q0, sys.v0)
    loads(sys, (fr.r, fr.A, fr.rd, fr.w), elem)
    return int(packed(sys, elem)[20][0])


def test_broad_phase_passes_no_pair_of_far_apart_bodies():
    geos = [mb.Box((0.1, 0.2, 0.3)), mb.Cylinder(0.1, 0.3, axis="y"), mb.Ellipsoid((0.1, 0.2, 0.15)),
            mb.Capsule(0.05, 0.2, axis="z"), mb.Sphere(radius=0.1),
            mb.ConvexMesh(np.random.default_rng(1).normal(size=(12, 3)) * 0.1)]
    m = mb.Model()
    shapes = []
    for i in range(30):
        b = m.add_body(f"b{i}", 1.0, (0.01,) * 3, position=(i % 5, (i // 5) * 1.0, 0.3 * i))
        shapes.append(b.add_shape("g", geos[i % len(geos)]))
    c = m.add_contact("c", shapes, shapes, 1e5, 1.5, 10.0, 1e-3)
    assert len(c.pairs) == 30 * 29 // 2
    assert _narrow_count(m, c) == 0
    res = mb.simulate(m, 0.01, 0.005, method="dop853")
    assert res.success


def _aabb_box(p, half):
    return p - half, p + half


def test_broad_phase_passes_only_the_pairs_whose_boxes_overlap_in_a_pile():
    """Three towers of three boxes on a floor, apart: 9 touching pairs among 45 (floor included); the
    broad phase passes exactly those (counted independently from the boxes' corners)."""
    a, k, e, mass = 0.1, 1e6, 1.0, 1.0
    m = mb.Model(gravity=(0, 0, -G))
    floor = mb.Plane(m.ground, (0, 0, 0), (0, 0, 1))
    shapes, boxes = [], []
    for tower in range(3):
        z = 0.0
        for i in range(3):
            delta = ((3 - i) * mass * G / (4 * k)) ** (1 / e)
            z += -delta + (a / 2 if i == 0 else a)
            pos = np.array([0.5 * tower, 0.2 * tower, z])
            b = m.add_body(f"b{tower}{i}", mass, (mass * a * a / 6,) * 3, position=pos)
            shapes.append(b.add_shape("geo", mb.Box((a, a, a))))
            boxes.append(_aabb_box(pos, a / 2))
    c = m.add_contact("c", [floor] + shapes, shapes, k, e, 400.0, 1e-5, mu=0.5, friction_velocity=1e-3)
    assert len(c.pairs) == 9 + 36
    touching = sum(lo[2] < 0.0 for lo, _ in boxes)
    touching += sum(bool(np.all(boxes[i][0] <= boxes[j][1]) and np.all(boxes[j][0] <= boxes[i][1]))
                    for i in range(9) for j in range(i + 1, 9))
    assert touching == 9
    assert _narrow_count(m, c) == touching
    res = mb.simulate(m, 0.2, 0.01, method="dop853", rtol=1e-6)
    assert res.success
    for name in (f"b{t}{i}" for t in range(3) for i in range(3)):
        p = res.position(name)
        assert np.max(np.abs(p - p[0])) < 2e-4


def test_box_balanced_edge_on_edge_rests_on_the_edge_edge_axis():
    """A box whose lower edge crosses a fixed box's upper edge at right angles: no vertex of either is in
    the other, the edge-edge separating axis gives the point contact, at the IMPACT penetration."""
    from scipy.spatial.transform import Rotation
    a, mass, k, e = 0.1, 1.0, 1e6, 1.0
    d = (mass * G / k) ** (1 / e)
    m = mb.Model(gravity=(0, 0, -G))
    low = m.add_body("low", 1.0, (0.01,) * 3, orientation=Rotation.from_rotvec((np.pi / 4, 0, 0)).as_matrix())
    m.add_fixed("fix", m.ground, low)
    z = np.sqrt(2) * a - d
    top = m.add_body("top", mass, (mass * a * a / 6,) * 3, position=(0, 0, z),
                     orientation=Rotation.from_rotvec((0, np.pi / 4, 0)).as_matrix())
    c = m.add_contact("c", low.add_shape("g", mb.Box((a, a, a))), top.add_shape("g", mb.Box((a, a, a))),
                      k, e, 100.0, 1e-5)
    res = mb.simulate(m, 0.1, 0.01, method="dop853", rtol=1e-8)
    assert res.success
    assert abs(res.position("top")[-1, 2] - z) < 1e-3 * d
    pts = res.contact_points("c")
    assert c and (pts.groupby("time").size() == 1).all()
    assert np.allclose(pts[["nx", "ny"]].to_numpy(), 0.0, atol=1e-9) and np.allclose(pts.nz, 1.0)
