"""Issue 30: the viewer draws the shapes placed with Body.add_shape.  The scene data the page receives
(Scene.shapes: triangles in body axes, moved by the body's pose of each frame; Scene.bodies: the pose)
must put every geometry's surface where the shape is in ground at every frame, with its kind and size.

The reference pose is the body's rigid motion applied to the placement given to add_shape in ground at
t = 0 (p(t) = r(t) + R(t) R(0)^T (p(0) - r(0))), and each surface is checked by its own closed form."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mbdsim as mb

R0 = Rotation.from_rotvec((0.3, -0.2, 0.5)).as_matrix()
C0 = np.array([0.4, -0.1, 1.0])
TOL = 2e-5   # [m]: the page gets 6 significant digits of poses ~1 m from the origin


def placements():
    """(name, geometry, centre and axes in ground at t = 0) of the shapes on one tumbling body."""
    import trimesh
    rot = Rotation.from_rotvec
    tri = trimesh.creation.icosphere(subdivisions=1, radius=0.03)
    tri.vertices[:, 2] *= 2.0
    return [("box", mb.Box((0.2, 0.1, 0.05)), C0 + (0.1, 0.0, 0.0), rot((0.0, 0.0, 0.4)).as_matrix() @ R0),
            ("cyl", mb.Cylinder(0.04, 0.12, axis="x"), C0 + (-0.1, 0.05, 0.0), R0),
            ("cap", mb.Capsule(0.03, 0.1, axis=(0.0, 1.0, 1.0)), C0 + (0.0, -0.1, 0.05), None),
            ("ell", mb.Ellipsoid((0.05, 0.03, 0.02)), C0 + (0.0, 0.1, -0.05), rot((0.7, 0.0, 0.0)).as_matrix()),
            ("ball", mb.Sphere(radius=0.035), C0 + (0.05, 0.05, 0.1), None),
            ("hull", mb.ConvexMesh(np.array([[0, 0, 0], [0.06, 0, 0], [0, 0.05, 0], [0, 0, 0.04], [0.03, 0.03, 0.03]])),
             C0 + (-0.05, -0.05, -0.1), R0.T),
            ("tri", mb.Mesh(tri.vertices, tri.faces), C0 + (0.12, 0.1, 0.08), None)]


@pytest.fixture(scope="module")
def run():
    m = mb.Model("shapes", gravity=(0.0, 0.0, -9.81))
    b = m.add_body("part", 2.0, (0.02, 0.03, 0.04), position=C0, orientation=R0, velocity=(0.5, 0.0, 2.0),
                   angular_velocity=(3.0, -2.0, 5.0))
    given = placements()
    for name, geo, c, R in given:
        b.add_shape(name, geo, center=c, orientation=R)
    floor = m.ground.add_shape("floor", mb.Box((1.0, 1.0, 0.02)), center=(0.0, 0.0, -0.5))
    res = mb.simulate(m, 0.5, 0.01)
    assert res.success and floor
    return m, res, given


def test_every_shape_is_drawn_on_its_body_with_its_kind_and_size(run):
    m, res, given = run
    from mbdsim.viewer.scene import build_scene
    scene = build_scene(res)
    data = scene.to_json()
    part = next(b for b in data["bodies"] if b["name"] == "part")
    assert part["shape"] == {"kind": "shapes"}   # no equivalent box on top of its shapes
    drawn = {(s["body"], s["name"]): s for s in data["shapes"] if s["kind"] == "mesh"}
    assert set(drawn) == {(0, n) for n, *_ in given} | {(-1, "floor")}
    geo = {n: drawn[(0, n)]["geometry"] for n, *_ in given}
    assert geo["box"] == {"kind": "box", "size": [0.2, 0.1, 0.05]}
    assert geo["cyl"] == {"kind": "cylinder", "radius": 0.04, "length": 0.12, "axis": [1.0, 0.0, 0.0]}
    assert geo["cap"]["kind"] == "capsule" and geo["cap"]["radius"] == 0.03 and geo["cap"]["length"] == 0.1
    assert np.allclose(geo["cap"]["axis"], np.array([0, 1, 1]) / np.sqrt(2), atol=1e-6)
    assert geo["ell"] == {"kind": "ellipsoid", "radii": [0.05, 0.03, 0.02]}
    assert geo["ball"] == {"kind": "sphere", "radius": 0.035}
    assert geo["hull"] == {"kind": "convex_mesh", "vertices": 5, "faces": 6}
    assert geo["tri"]["kind"] == "mesh" and geo["tri"]["faces"] == 80
    assert all(drawn[(0, n)]["color"] == part["color"] for n, *_ in given)


def _surface_error(name, geometry, p):
    """Largest deviation [m] of points p (n, 3; the geometry's own axes) from the geometry's surface, and
    whether the points reach its extremes (so that a shrunken drawing fails too)."""
    if name == "box":
        h = geometry.size / 2
        return np.max(np.abs(np.abs(p) - h)), True   # trimesh's box: its 8 corners
    if name == "cyl":
        rad, ax = np.hypot(p[:, 1], p[:, 2]), p[:, 0]
        rim = np.isclose(rad, geometry.radius, atol=TOL)
        err = max(np.max(rad) - geometry.radius, np.max(np.abs(ax)) - geometry.length / 2)
        return err, rim.sum() >= 32 and np.isclose(np.max(ax), geometry.length / 2, atol=TOL)
    if name == "cap":
        a = geometry.axis
        s = np.clip(p @ a, -geometry.length / 2, geometry.length / 2)
        d = np.linalg.norm(p - s[:, None] * a, axis=1)
        return np.max(np.abs(d - geometry.radius)), np.isclose(np.max(p @ a), geometry.length / 2 + geometry.radius, atol=TOL)
    if name == "ell":
        return np.max(np.abs(np.linalg.norm(p / geometry.radii, axis=1) - 1)) * geometry.radii.min(), True
    if name == "ball":
        return np.max(np.abs(np.linalg.norm(p, axis=1) - geometry.radius)), True
    ref = geometry.vertices   # hull and triangle mesh: the very vertices, in some order
    d = np.linalg.norm(p[:, None] - ref[None], axis=2)
    return max(np.max(d.min(axis=1)), np.max(d.min(axis=0))), True


@pytest.mark.parametrize("frame", [0, 25, -1])
def test_drawn_vertices_lie_on_each_shape_at_its_pose_of_every_frame(run, frame):
    """Pose the drawn triangles as the page does (group at pos[k], quat[k]) and express them in the shape's
    axes at that time from the placement given at t = 0: they lie on the geometry's surface."""
    m, res, given = run
    from mbdsim.viewer.scene import build_scene
    data = build_scene(res).to_json()
    part = next(b for b in data["bodies"] if b["name"] == "part")
    k = frame % len(data["time"])
    t = data["time"][k]
    pos = np.reshape(part["pos"], (-1, 3))[k]
    quat = np.reshape(part["quat"], (-1, 4))[k]
    Rk = Rotation.from_quat(quat).as_matrix()
    n = int(np.argmin(np.abs(res.time - t)))
    r_t, A_t = res.position("part")[n], res.orientation("part")[n]
    assert np.allclose(pos, r_t, atol=1e-5) and np.allclose(Rk, A_t, atol=1e-5)
    if k:
        assert np.linalg.norm(pos - C0) > 0.05   # the body did move and turn
    shapes = {s["name"]: s for s in data["shapes"] if s["body"] == 0}
    for name, geo, c0, Rg0 in given:
        Rg0 = R0 if Rg0 is None else Rg0
        centre, axes = r_t + A_t @ R0.T @ (c0 - C0), A_t @ R0.T @ Rg0   # rigid motion of the t = 0 placement
        v_world = np.reshape(shapes[name]["vertices"], (-1, 3)) @ Rk.T + pos
        err, reaches = _surface_error(name, geo, (v_world - centre) @ axes)
        assert err < TOL, (name, err)
        assert reaches, name
    floor = next(s for s in data["shapes"] if s["body"] == -1)
    v = np.reshape(floor["vertices"], (-1, 3))   # ground: drawn in ground as placed
    assert np.allclose(np.sort(np.unique(v[:, 2])), [-0.51, -0.49]) and np.allclose(np.abs(v[:, :2]), 0.5)
