"""Issue 30: shape-shape pairs (box-box, sphere/capsule, shapes on boxes), lists of shapes, piles."""
import numpy as np
import pytest

import mbdsim as mb

G = 9.81


def test_three_boxes_stacked_stay_stacked():
    a, mass, k, e = 0.1, 1.0, 1e6, 1.0
    m = mb.Model(gravity=(0, 0, -G))
    floor = mb.Plane(m.ground, (0, 0, 0), (0, 0, 1))
    shapes, z = [], 0.0
    offsets = (0.0, 0.02, -0.01)   # partly overhanging: the support polygon's corners carry the load
    for i in range(3):
        delta = ((3 - i) * mass * G / (4 * k)) ** (1 / e)
        z += -delta + (a / 2 if i == 0 else a)
        b = m.add_body(f"b{i}", mass, (mass * a * a / 6,) * 3, position=(offsets[i], 0, z))
        shapes.append(b.add_shape("geo", mb.Box((a, a, a))))
    c = m.add_contact("c", [floor] + shapes, shapes, k, e, 400.0, 1e-5, mu=0.5, friction_velocity=1e-3)
    assert len(c.pairs) == 3 + 3   # floor with each box, each pair of boxes once
    res = mb.simulate(m, 0.5, 0.01, method="dop853", rtol=1e-6)
    assert res.success
    for i in range(3):
        p = res.position(f"b{i}")
        assert np.max(np.abs(p - p[0])) < 2e-4, (i, np.max(np.abs(p - p[0]), axis=0))
        assert np.max(np.abs(res.angular_velocity(f"b{i}"))) < 1e-2


def test_box_on_a_smaller_box_rests_on_the_smaller_face():
    """The reference face's corners inside the incident box carry the load (big box on a small one)."""
    k, e = 1e6, 1.0
    m = mb.Model(gravity=(0, 0, -G))
    low = m.add_body("low", 1.0, (0.01,) * 3, position=(0, 0, 0))
    m.add_fixed("fix", m.ground, low)
    d = (2.0 * G / (4 * k)) ** (1 / e)
    top = m.add_body("top", 2.0, (0.02,) * 3, position=(0, 0, 0.05 + 0.1 - d))
    c = m.add_contact("c", low.add_shape("geo", mb.Box((0.1, 0.1, 0.1))), top.add_shape("geo", mb.Box((0.4, 0.3, 0.2))),
                      k, e, 400.0, 1e-4)
    res = mb.simulate(m, 0.3, 0.01, method="dop853", rtol=1e-6)
    assert res.success
    assert abs(res.position("top")[-1, 2] - (0.15 - d)) < 1e-3 * d + 1e-9
    assert np.max(np.abs(res.orientation("top")[-1] - np.eye(3))) < 1e-6
    pts = c and res.contact_points("c")
    last = pts[pts.time == pts.time.max()]
    assert len(last) == 4 and np.allclose(np.abs(last[["x", "y"]].to_numpy()), 0.05, atol=1e-9)


def test_capsule_on_capsule_and_sphere_on_box_rest_at_the_hertz_like_penetration():
    k, e, r = 1e5, 1.5, 0.05
    m = mb.Model(gravity=(0, 0, -G))
    base = m.add_body("base", 1.0, (0.01,) * 3)
    m.add_fixed("fix", m.ground, base)
    cap = base.add_shape("cap", mb.Capsule(r, 0.3, axis="x"))
    box = base.add_shape("box", mb.Box((0.2, 0.2, 0.1)), center=(1, 0, 0))
    d = (1.0 * G / k) ** (1 / e)
    s1 = m.add_body("s1", 1.0, (0.001,) * 3, position=(0, 0, 2 * r - d))
    s2 = m.add_body("s2", 1.0, (0.001,) * 3, position=(1, 0, 0.05 + r - d))
    m.add_contact("c", [cap, box], [s1.add_shape("g", mb.Capsule(r, 0.2, axis="y")), s2.add_shape("g", mb.Sphere(radius=r))],
                  k, e, 50.0, 1e-3)
    res = mb.simulate(m, 0.3, 0.01, method="dop853", rtol=1e-6)
    assert res.success
    assert abs(res.position("s1")[-1, 2] - (2 * r - d)) < 1e-3 * d
    assert abs(res.position("s2")[-1, 2] - (0.05 + r - d)) < 1e-3 * d


def test_pile_of_eight_boxes_settles():
    rng = np.random.default_rng(3)
    from scipy.spatial.transform import Rotation
    a, k, e = 0.1, 1e5, 1.5
    m = mb.Model(gravity=(0, 0, -G))
    shapes = []
    for i in range(8):
        layer = i // 4   # two layers of four, apart; the upper one shifted to land across the lower boxes
        pos = (0.18 * (i % 2) + 0.09 * layer, 0.18 * ((i // 2) % 2) + 0.09 * layer, 0.1 + 0.2 * layer)
        b = m.add_body(f"b{i}", 1.0, (a * a / 6,) * 3, position=pos,
                       orientation=Rotation.from_rotvec(rng.uniform(-0.4, 0.4, 3)).as_matrix())
        shapes.append(b.add_shape("geo", mb.Box((a, a, a))))
    m.add_contact("c", [mb.Plane(m.ground, (0, 0, 0), (0, 0, 1))] + shapes, shapes, k, e, 50.0, 1e-3, mu=0.5,
                  friction_velocity=1e-2)
    res = mb.simulate(m, 1.5, 0.01, method="dop853", rtol=1e-5)
    assert res.success
    for i in range(8):
        p = res.position(f"b{i}")
        assert np.all(np.isfinite(p)) and p[:, 2].min() > 0.0
        assert np.linalg.norm(res.velocity(f"b{i}")[-1]) < 0.05
