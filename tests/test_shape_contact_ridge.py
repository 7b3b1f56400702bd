"""Issue 30: the ridges (convex edges) and peaks (convex vertices) of a triangle mesh pressing into a box or
convex hull face: a box lying across two ridges of a mesh terrain rests level on four points (the ends of the
two lines inside it), one on four peaks on four points; a mesh wedge smaller than a box rests ridge down on
its face.  Closed forms: at rest the n points each carry m g / n, so each is k d^e = m g / n deep."""
import numpy as np
import pytest
import trimesh

import mbdsim as mb

G = 9.81
A, H = 0.1, 0.02   # box side, ridge / peak height [m]


def _up(v, f):
    """Faces turned so that each normal points up (+z)."""
    f = np.array(f)
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    f[n[:, 2] < 0] = f[n[:, 2] < 0][:, ::-1]
    return f


def ridges():
    """Two tents along y (ridges at x = -0.03 and 0.03, height H) on a flat floor, 0.6 m square."""
    prof = [(-0.3, 0.0), (-0.06, 0.0), (-0.03, H), (0.0, 0.0), (0.03, H), (0.06, 0.0), (0.3, 0.0)]
    v = np.array([(x, y, z) for x, z in prof for y in (-0.3, 0.3)])
    f = []
    for i in range(len(prof) - 1):
        f += [(2 * i, 2 * i + 2, 2 * i + 3), (2 * i, 2 * i + 3, 2 * i + 1)]
    return v, _up(v, f)


def peaks():
    """A grid of 0.03 m cells on z = 0 with four peaks of height H at (+-0.03, +-0.03)."""
    h, n = 0.03, 20
    xs = -0.3 + h * np.arange(n + 1)
    X, Y = np.meshgrid(xs, xs, indexing="ij")
    Z = np.where((np.abs(np.abs(X) - 0.03) < 1e-9) & (np.abs(np.abs(Y) - 0.03) < 1e-9), H, 0.0)
    v = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    idx = lambda i, j: i * (n + 1) + j  # noqa: E731
    f = []
    for i in range(n):
        for j in range(n):
            f += [(idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)), (idx(i, j), idx(i + 1, j + 1), idx(i, j + 1))]
    return v, _up(v, f)


def _cube(kind):
    if kind == "box":
        return mb.Box((A, A, A))
    return mb.ConvexMesh(0.5 * A * np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]))


@pytest.mark.parametrize("terrain, c", [("ridges", 0.0), ("ridges", 0.01), ("peaks", 0.0)])
@pytest.mark.parametrize("kind", ["box", "convex"])
def test_box_rests_on_the_ridges_and_peaks_of_a_mesh_terrain(terrain, c, kind):
    """The box's centre of mass c off the middle between the ridges (x = -+0.03): the lever rule gives the
    ridges m g (0.03 -+ x) / 0.06, half of it at each of the two points (the ridge crossing the box's side
    faces y = +-a/2), x = c + (a / 2) theta the centre's final abscissa once the box has tilted by theta =
    (d2 - d1) / 0.06 about its bottom face (the points do not slip; the normal forces' horizontal parts and the
    friction balance at the bottom face); four peaks at (+-0.03, +-0.03) carry m g / 4 each."""
    k, e, mass = 1e6, 1.5, 1.0
    v, f = ridges() if terrain == "ridges" else peaks()
    m = mb.Model(gravity=(0, 0, -G))
    x = c
    for _ in range(20):   # fixed point of the lever rule and the tilt
        F = mass * G * np.array([0.03 - x, 0.03 + x]) / 0.06 / 2   # per point, on the ridges x = -0.03, 0.03
        d = (F / k) ** (1 / e)
        x = c + 0.5 * A * (d[1] - d[0]) / 0.06
    zf = H + A / 2 - (d[0] + (c + 0.03) * (d[1] - d[0]) / 0.06)   # the bottom face through both ridge lines
    b = m.add_body("box", mass, (mass * A * A / 6,) * 3, position=(c, 0.0, H + A / 2 - d.mean()))
    floor = m.ground.add_shape("floor", mb.Mesh(v, f))
    con = m.add_contact("c", floor, b.add_shape("geo", _cube(kind)), k, e, 300.0, 1e-5, mu=0.5,
                        friction_velocity=1e-3)
    res = mb.simulate(m, 0.3, 0.01, method="dop853", rtol=1e-8)
    assert res.success
    assert abs(res.position("box")[-1, 2] - zf) < 1e-2 * d.min(), (res.position("box")[-1, 2] - zf, d)
    assert abs(res.position("box")[-1, 0] - x) < 5e-2 * abs(x - c) + 1e-9, (res.position("box")[-1, 0], x)   # (creep)
    pts = con and res.contact_points("c")
    last = pts[pts.time == pts.time.max()]
    last = last.iloc[np.lexsort((last.y.round(4), last.x.round(4)))]
    assert len(last) == 4
    xy = last[["x", "y"]].to_numpy()
    yb = res.position("box")[-1, 1]
    ref = [(-0.03, yb - A / 2), (-0.03, yb + A / 2), (0.03, yb - A / 2), (0.03, yb + A / 2)] \
        if terrain == "ridges" else [(-0.03, -0.03), (-0.03, 0.03), (0.03, -0.03), (0.03, 0.03)]
    assert np.allclose(xy, ref, atol=1e-4), xy
    assert np.allclose(last.normal_force, np.repeat(F, 2), rtol=1e-3), (last.normal_force, F)
    assert abs(last.normal_force.sum() - mass * G) < 1e-3 * mass * G
    if c == 0.0:
        assert np.max(np.abs(res.orientation("box")[-1] - np.eye(3))) < 1e-6
        assert np.allclose(last.penetration, d[0], rtol=1e-3)
        assert np.allclose(last[["nx", "ny"]].to_numpy(), 0.0, atol=1e-9)


def test_mesh_wedge_rests_ridge_down_on_a_box_face(tmp_path):
    """A triangular prism from an STL file (smaller than the box below it) ridge down on the box's top face:
    the two ridge ends carry m g = 2 k d^e and the wedge stays level."""
    k, e, mass, w, hgt, L = 1e6, 1.5, 2.0, 0.06, 0.05, 0.3
    d = (mass * G / (2 * k)) ** (1 / e)
    m = mb.Model(gravity=(0, 0, -G))
    base = m.add_body("base", 1.0, (0.01,) * 3)
    m.add_fixed("fix", m.ground, base)
    box = base.add_shape("box", mb.Box((0.5, 0.5, 0.1)), center=(0, 0, -0.05))
    zc = hgt * 2 / 3   # the prism's centroid above its ridge
    tri = np.array([[-w / 2, hgt - zc], [w / 2, hgt - zc], [0.0, -zc]])   # (x, z), the ridge at z = -zc
    prism = trimesh.Trimesh(np.array([[x, y, z] for y in (-L / 2, L / 2) for x, z in tri])).convex_hull
    path = tmp_path / "wedge.stl"
    prism.export(path)
    wedge = m.add_body("wedge", mass, (0.015, 0.001, 0.015), position=(0, 0, zc - d))
    geo = wedge.add_shape("geo", mb.Mesh(path))
    m.add_contact("c", box, geo, k, e, 300.0, 1e-5)
    res = mb.simulate(m, 0.3, 0.01, method="dop853", rtol=1e-8)
    assert res.success
    assert abs(res.position("wedge")[-1, 2] - (zc - d)) < 1e-3 * d
    assert np.max(np.abs(res.orientation("wedge")[-1] - np.eye(3))) < 1e-6
    pts = res.contact_points("c")
    last = pts[pts.time == pts.time.max()]
    assert len(last) == 2
    assert np.allclose(last["penetration"].to_numpy(), d, rtol=1e-3)
    assert np.allclose(np.sort(last["y"].to_numpy()), (-L / 2, L / 2), atol=1e-9)
