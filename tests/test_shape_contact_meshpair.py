"""Issue 30: a triangle mesh against a triangle mesh (the vertices of each against the other's triangles, a
penalty approximation): a mesh box resting on a mesh floor, sliding down a mesh incline.  Closed forms."""
import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

import mbdsim as mb

G = 9.81


def grid_surface(x0, y0, n, h):
    """Triangles of the plane z = 0 over an n x n grid of cells of side h from (x0, y0), normals up."""
    xs, ys = x0 + h * np.arange(n + 1), y0 + h * np.arange(n + 1)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    v = np.column_stack([X.ravel(), Y.ravel(), 0.0 * X.ravel()])
    idx = lambda i, j: i * (n + 1) + j  # noqa: E731
    f = []
    for i in range(n):
        for j in range(n):
            f += [(idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)), (idx(i, j), idx(i + 1, j + 1), idx(i, j + 1))]
    return v, np.array(f)


def box_mesh(a, tmp_path):
    """A cube of side a as a triangle mesh: an STL written by trimesh, read back by mb.Mesh."""
    path = tmp_path / "cube.stl"
    trimesh.creation.box(extents=(a, a, a)).export(path)
    return mb.Mesh(str(path))


@pytest.mark.parametrize("grid, n", [((-0.6, -0.62, 5, 0.25), 4), ((-0.5, -0.5, 10, 0.1), 5)])
def test_mesh_box_rests_flat_on_a_mesh_floor_at_the_impact_penetration(tmp_path, grid, n):
    """The n supporting vertices carry the weight: the box's four bottom vertices on the floor's triangles
    and (second grid) the floor vertex under the centre of the box's bottom face, each at delta = (m g / (n k))^(1/e),
    the centre at a/2 - delta, no tilt."""
    a, mass, k, e = 0.1, 1.0, 1e6, 1.0
    v, f = grid_surface(*grid)
    m = mb.Model(gravity=(0, 0, -G))
    d = (mass * G / (n * k)) ** (1 / e)
    b = m.add_body("box", mass, (mass * a * a / 6,) * 3, position=(0.0, 0.0, a / 2 - d))
    floor = m.ground.add_shape("floor", mb.Mesh(v, f))
    c = m.add_contact("c", floor, b.add_shape("geo", box_mesh(a, tmp_path)), k, e, 400.0, 1e-5, mu=0.5,
                      friction_velocity=1e-3)
    res = mb.simulate(m, 0.3, 0.01, method="dop853", rtol=1e-7, monitor=False)
    assert res.success
    assert abs(res.position("box")[-1, 2] - (a / 2 - d)) < 1e-3 * d
    assert np.max(np.abs(res.orientation("box")[-1] - np.eye(3))) < 1e-6
    pts = c and res.contact_points("c")
    last = pts[pts.time == pts.time.max()]
    assert len(last) == n and np.allclose(last.penetration, d, rtol=1e-3)
    assert np.allclose(np.abs(last[["x", "y"]].to_numpy()[:4]), a / 2, atol=1e-9)   # floor side first
    assert np.allclose(last.normal_force.sum(), mass * G, rtol=1e-6)


def test_mesh_box_slides_down_a_mesh_incline_at_g_sin_minus_mu_cos(tmp_path):
    a, mass, k, e, mu, th = 0.1, 1.0, 1e6, 1.0, 0.2, 0.3
    v, f = grid_surface(-1.0, -0.62, 8, 0.25)
    Rot = Rotation.from_rotvec((0.0, th, 0.0)).as_matrix()   # the incline falls towards +x (s_hat)
    m = mb.Model(gravity=(0, 0, -G))
    d = (mass * G * np.cos(th) / (4 * k)) ** (1 / e)
    s_hat, n_hat = Rot @ (1.0, 0.0, 0.0), Rot @ (0.0, 0.0, 1.0)
    b = m.add_body("box", mass, (mass * a * a / 6,) * 3, position=(a / 2 - d) * n_hat, orientation=Rot,
                   velocity=0.1 * s_hat)
    floor = m.ground.add_shape("floor", mb.Mesh(v @ Rot.T, f))
    m.add_contact("c", floor, b.add_shape("geo", box_mesh(a, tmp_path)), k, e, 400.0, 1e-5, mu=mu,
                  friction_velocity=1e-5)
    res = mb.simulate(m, 0.3, 0.01, method="dop853", rtol=1e-8)
    assert res.success
    t = res.time
    sel = t >= 0.05
    vs = res.velocity("box")[sel] @ s_hat
    acc = np.polyfit(t[sel], vs, 1)[0]
    ref = G * (np.sin(th) - mu * np.cos(th))
    assert abs(acc / ref - 1) < 1e-3, (acc, ref)
    assert np.max(np.abs(res.position("box")[:, 1])) < 1e-9


def test_mesh_box_dropped_tilted_on_a_mesh_floor_comes_to_rest_flat(tmp_path):
    """Vertices of both meshes push (floor vertices under the box, box corners on the floor) while the box
    lands on an edge and tips over; a face ends down at the penetration of its n supporting vertices."""
    a, mass, k, e = 0.1, 1.0, 1e6, 1.0
    v, f = grid_surface(-0.52, -0.535, 10, 0.1)
    m = mb.Model(gravity=(0, 0, -G))
    b = m.add_body("box", mass, (mass * a * a / 6,) * 3, position=(0.0, 0.0, 0.12),
                   orientation=Rotation.from_rotvec((0.3, 0.2, 0.1)).as_matrix())
    floor = m.ground.add_shape("floor", mb.Mesh(v, f))
    c = m.add_contact("c", floor, b.add_shape("geo", box_mesh(a, tmp_path)), k, e, 400.0, 1e-5, mu=0.5,
                      friction_velocity=1e-3)
    res = mb.simulate(m, 1.5, 0.01, method="dop853", rtol=1e-6, monitor=False)   # (contact dissipates)
    assert res.success
    Rf = res.orientation("box")[-1]
    assert abs(abs(Rf[2, 2]) + abs(Rf[2, 1]) + abs(Rf[2, 0]) - 1.0) < 1e-4   # a face down
    pts = c and res.contact_points("c")
    last = pts[pts.time == pts.time.max()]
    assert 4 <= len(last) <= 6
    # at rest (e = 1) the points' forces k delta_i add up to the weight, whatever their share
    assert abs(last.penetration.mean() - mass * G / (len(last) * k)) < 1e-3 * mass * G / (len(last) * k)
    assert abs(last.normal_force.sum() - mass * G) < 1e-3 * mass * G



def _below(V, T, cap):
    """Per vertex of V (n, 3) the least depth below the triangles T (m, 3, 3) whose plane it is less than
    cap under and whose foot is on the triangle (0 where none): the brute-force count over all pairs (the
    nearest face; the faces here are planar, so the triangles of one face agree)."""
    a, b, c = T[:, 0], T[:, 1], T[:, 2]
    m = np.cross(b - a, c - a)
    m /= np.linalg.norm(m, axis=1, keepdims=True)
    d = np.einsum("mk,nmk->nm", m, a[None] - V[:, None])
    foot = V[:, None] + d[..., None] * m[None]
    ab, ac, ap = b - a, c - a, foot - a[None]
    d00, d01, d11 = (ab * ab).sum(1), (ab * ac).sum(1), (ac * ac).sum(1)
    d20, d21 = (ap * ab[None]).sum(2), (ap * ac[None]).sum(2)
    den = d00 * d11 - d01 * d01
    v = (d11 * d20 - d01 * d21) / den
    w = (d00 * d21 - d01 * d20) / den
    ok = (d > 0) & (d < cap) & (v >= -1e-9) & (w >= -1e-9) & (v + w <= 1 + 1e-9)
    best = np.where(ok, d, np.inf).min(axis=1)
    return np.where(np.isfinite(best), best, 0.0)


def test_mesh_pair_walk_finds_every_vertex_a_brute_force_count_finds():
    """A finely meshed box pressed 0.3-1.7 mm (slightly turned) into a fine mesh floor: the points of the
    walk of both hierarchies are those of every vertex against every triangle of the other mesh.  The flat
    leaves have no thickness: only their boxes swept along the inward normals meet the vertices below them."""
    from mbdsim.solvers.fastcontact import REC_FIELDS
    from mbdsim.solvers.fastmeshpair import SKIN
    from mbdsim.system.assemble import assemble_system
    from mbdsim.system.force_elements.shape_contact import loads
    from mbdsim.system.frames import body_frames
    vf, ff = grid_surface(-0.2, -0.2, 20, 0.02)
    cube = trimesh.creation.box(extents=(0.1, 0.1, 0.1))
    vb, fb = trimesh.remesh.subdivide(*trimesh.remesh.subdivide(cube.vertices, cube.faces))
    Rb = Rotation.from_rotvec((0.01, -0.015, 0.3)).as_matrix()
    pb = np.array([0.003, -0.002, 0.05 - 0.001])
    m = mb.Model()
    box = m.add_body("b", 1.0, (1e-3,) * 3, position=pb, orientation=Rb)
    c = m.add_contact("c", m.ground.add_shape("floor", mb.Mesh(vf, ff)), box.add_shape("g", mb.Mesh(vb, fb)),
                      1e6, 1.0, 0.0, 1e-5)
    sys_ = assemble_system(m)
    fr = body_frames(sys_, sys_.q0, sys_.v0)
    _, rec = loads(sys_, (fr.r, fr.A, fr.rd, fr.w), c, np.zeros((4096, len(REC_FIELDS))))
    Vb = vb @ Rb.T + pb
    cap = SKIN * min(np.linalg.norm(vb, axis=1).max(), np.linalg.norm(vf, axis=1).max())
    ref = np.concatenate([_below(Vb, vf[ff], cap), _below(vf, Vb[fb], cap)])
    ref = np.sort(ref[ref > 0])
    got = np.sort(rec[:, REC_FIELDS.index("penetration")])
    assert len(ref) >= 20 and ref.max() > 1.5e-3 and ref.min() < 5e-4
    assert len(got) == len(ref) and np.allclose(got, ref, rtol=1e-9, atol=1e-15), (len(got), len(ref))
