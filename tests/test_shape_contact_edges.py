"""Issue 30: edge-edge contact of convex hulls (hull/hull, hull/box) and a hull ridge on a box face,
against the IMPACT law's closed-form penetration (m g = k d^e summed over the contact points)."""
import numpy as np
import pytest

import mbdsim as mb

G = 9.81
S, L = 0.05, 0.4   # bar cross-section side and length [m]


def _rot(axis, ang):
    c, s = np.cos(ang), np.sin(ang)
    return {"x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]), "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])}[axis]


def _bar_hull(along):
    """A square bar (side S, length L) as a convex hull, its long axis `along` (x or y)."""
    h = 0.5 * np.array([L, S, S]) if along == "x" else 0.5 * np.array([S, L, S])
    return mb.ConvexMesh(np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h)


@pytest.mark.parametrize("lower", ["hull", "box"])
def test_crossed_bars_rest_edge_on_edge_at_the_impact_penetration(lower):
    """A bar turned 45 deg about its axis (ridge up, along y) and a second one across it (ridge down, along x):
    one point at the crossing, normal vertical, the upper bar's weight m g = k d^e."""
    k, e, mass = 1e6, 1.5, 1.0
    d = (mass * G / k) ** (1 / e)
    ridge = S / np.sqrt(2.0)   # half diagonal of the cross-section
    m = mb.Model(gravity=(0, 0, -G))
    base = m.add_body("base", 1.0, (0.01,) * 3)
    m.add_fixed("fix", m.ground, base)
    geo = _bar_hull("y") if lower == "hull" else mb.Box((S, L, S))
    low = base.add_shape("bar", geo, orientation=_rot("y", np.pi / 4))
    z0 = 2 * ridge - d
    top = m.add_body("top", mass, (0.005, 0.02, 0.02), position=(0, 0, z0))
    up = top.add_shape("bar", _bar_hull("x"), orientation=_rot("x", np.pi / 4))
    m.add_contact("c", low, up, k, e, 300.0, 1e-5)
    res = mb.simulate(m, 0.3, 0.01, method="dop853", rtol=1e-7)
    assert res.success
    z = res.position("top")[:, 2]
    assert abs(z[-1] - z0) < 1e-3 * d, (z[-1] - z0, d)
    pts = res.contact_points("c")
    last = pts[pts.time == pts.time.max()]
    assert len(last) == 1
    assert np.allclose(last[["nx", "ny"]].to_numpy(), 0.0, atol=1e-9)
    assert abs(last["normal_force"].iloc[0] - mass * G) < 1e-3 * mass * G


def test_hull_wedge_rests_ridge_down_on_a_box_face():
    """A triangular prism (hull) ridge-down across a box's top face: line contact, the two ridge ends
    carry m g = 2 k d^e and the wedge stays level."""
    k, e, mass, w, hgt = 1e6, 1.5, 2.0, 0.06, 0.05
    d = (mass * G / (2 * k)) ** (1 / e)
    m = mb.Model(gravity=(0, 0, -G))
    base = m.add_body("base", 1.0, (0.01,) * 3)
    m.add_fixed("fix", m.ground, base)
    box = base.add_shape("box", mb.Box((0.5, 0.5, 0.1)), center=(0, 0, -0.05))
    tri = np.array([[-w / 2, hgt], [w / 2, hgt], [0.0, 0.0]])   # (x, z), the ridge at z = 0
    v = np.array([[x, y, z] for y in (-L / 2, L / 2) for x, z in tri])
    zc = hgt * 2 / 3   # the prism's centroid above its ridge
    wedge = m.add_body("wedge", mass, (0.01, 0.002, 0.01), position=(0, 0, zc - d))
    geo = wedge.add_shape("geo", mb.ConvexMesh(v - (0, 0, zc)))
    m.add_contact("c", box, geo, k, e, 300.0, 1e-5)
    res = mb.simulate(m, 0.3, 0.01, method="dop853", rtol=1e-7)
    assert res.success
    assert abs(res.position("wedge")[-1, 2] - (zc - d)) < 1e-3 * d
    pts = res.contact_points("c")
    last = pts[pts.time == pts.time.max()]
    assert len(last) == 2
    assert np.allclose(last["penetration"].to_numpy(), d, rtol=1e-3)


def _brute_edge_axes(verts, edges, poses):
    """All edge pairs of two convex hulls: the axes along which each edge supports its shape (a's edge
    along +L, b's along -L), by the support over every vertex: (any separates, least depth, its L)."""
    X = [v @ R.T + o for v, (o, R) in zip(verts, poses)]
    best, L_best, separated = np.inf, None, False
    for i0, i1 in edges[0]:
        ea = X[0][i1] - X[0][i0]
        for j0, j1 in edges[1]:
            eb = X[1][j1] - X[1][j0]
            L = np.cross(ea, eb)
            if np.linalg.norm(L) < 1e-6 * np.linalg.norm(ea) * np.linalg.norm(eb):
                continue
            L /= np.linalg.norm(L)
            for sgn in (1.0, -1.0):
                x = sgn * L
                pa, pb = X[0] @ x, X[1] @ x
                tol = 1e-9
                if min(pa[i0], pa[i1]) < pa.max() - tol or max(pb[j0], pb[j1]) > pb.min() + tol:
                    continue   # an edge that does not support its shape along the axis
                D = pa.max() - pb.min()
                separated |= not D > 0.0
                if D < best:
                    best, L_best = D, x
    return separated, best, L_best


@pytest.mark.parametrize("seed", range(6))
def test_gauss_map_edge_axes_match_the_support_of_every_edge_pair(seed):
    """fastedges.hull_edges tests only the edge pairs whose Gauss-map arcs cross: its verdict (separated or
    not), least depth and axis match testing every edge pair by the support of all vertices."""
    from mbdsim.geometry.pack import pack_contacts
    from mbdsim.solvers.fastedges import hull_edges
    from mbdsim.system.assemble import assemble_system
    from mbdsim.system.frames import body_frames
    from mbdsim.solvers.fastnarrow import pose
    rng = np.random.default_rng(seed)
    m = mb.Model()
    a = m.add_body("a", 1.0, (1, 1, 1))
    b = m.add_body("b", 1.0, (1, 1, 1), position=tuple(rng.normal(size=3) * 0.08))
    ga = mb.ConvexMesh(rng.normal(size=(14, 3)) * (0.1, 0.06, 0.08))
    gb = mb.ConvexMesh(rng.normal(size=(10, 3)) * 0.07) if seed % 2 else mb.Box((0.1, 0.14, 0.06))
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    Rb = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                   [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                   [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    c = m.add_contact("c", a.add_shape("g", ga), b.add_shape("g", gb, orientation=Rb), 1e5, 1.5, 10, 1e-3)
    sys = assemble_system(m)
    sc = pack_contacts(sys, [c])
    fr = body_frames(sys, sys.q0, sys.v0)
    P = [pose(fr.r, fr.A, sc[0][s], sc[2][s], sc[3][s]) for s in range(2)]
    st, p0, p1, p2, L0, L1, L2, D = hull_edges(sc, 0, 1, P[0], P[1], np.inf, 0.0, 0.0, 0.0)
    verts = [sc[7][sc[6][s, 0]:sc[6][s, 1]] for s in range(2)]
    edges = [sc[32][sc[31][s, 0]:sc[31][s, 1]] - sc[6][s, 0] for s in range(2)]
    poses = [(np.array(p[:3]), np.array(p[3:]).reshape(3, 3)) for p in P]
    separated, best, L_ref = _brute_edge_axes(verts, edges, poses)
    assert st == (-1 if separated else 1), (st, separated, best)
    if not separated:
        assert abs(D - best) < 1e-12 and np.allclose((L0, L1, L2), L_ref, atol=1e-9), (D, best)
