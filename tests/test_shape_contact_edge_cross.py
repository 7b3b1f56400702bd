"""Issue 30: an edge resting across a triangle mesh's ridge (a roof's edge), with no vertex of either shape inside
the other: a second triangle mesh (a prism's roof edge, a mesh box's edge), a convex hull's edge or a box's edge.
The contact is one point midway between the two edges' closest points, along their common normal
L = e_roof x e_upper (oriented up, out of the roof), as deep as the two lines' overlap along L; closed forms from
the geometry of two skew lines, and at rest the weight m g = k d^e (IMPACT) with no lateral force."""
import numpy as np
import pytest
import trimesh

import mbdsim as mb
from mbdsim.solvers.fastcontact import REC_FIELDS

G, K, E = 9.81, 1e6, 1.5
W, H, LR, B = 0.2, 0.05, 0.6, 0.2   # roof: width (x), ridge height, length (along y), base depth [m]
WU, HU, LU = 0.06, 0.05, 0.2   # upper prism: width, height, length (along its local x) [m]
S = 0.05                       # upper box's cross-section side [m]


def _rot(axis, ang):
    c, s = np.cos(ang), np.sin(ang)
    return {"x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]), "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]


def roof():
    """A closed house-shaped prism mesh, its ridge along y at (0, y, H), |y| <= LR / 2, eaves at z = 0 and base
    z = -B (B deeper than the mesh pair's skin: a vertex above the roof is not taken behind the base face)."""
    prof = [(-W / 2, -B), (W / 2, -B), (W / 2, 0.0), (0.0, H), (-W / 2, 0.0)]
    p = trimesh.Trimesh(np.array([[x, y, z] for y in (-LR / 2, LR / 2) for x, z in prof])).convex_hull
    return mb.Mesh(p.vertices, p.faces)


def upper(kind):
    """(geometry in body axes, its shape orientation, zr): a shape whose lowest edge runs along the body's x
    at z = -zr (body axes, from the centre of mass), LU long: a prism ridge down (triangle mesh or convex hull),
    a box turned 45 degrees about x (triangle mesh or mb.Box)."""
    if kind in ("mesh prism", "hull prism"):
        zc = 2 * HU / 3   # the centroid above the ridge
        tri = [(-WU / 2, HU - zc), (WU / 2, HU - zc), (0.0, -zc)]   # (y, z)
        v = np.array([[x, y, z] for x in (-LU / 2, LU / 2) for y, z in tri])
        if kind == "hull prism":
            return mb.ConvexMesh(v), None, zc
        p = trimesh.Trimesh(v).convex_hull
        return mb.Mesh(p.vertices, p.faces), None, zc
    if kind == "mesh box":
        b = trimesh.creation.box(extents=(LU, S, S))
        return mb.Mesh(b.vertices @ _rot("x", np.pi / 4).T, b.faces), None, S / np.sqrt(2)
    return mb.Box((LU, S, S)), _rot("x", np.pi / 4), S / np.sqrt(2)


def _model(kind, R, pos, mass=1.0, inertia=(1e-3,) * 3):
    m = mb.Model(gravity=(0, 0, -G))
    b = m.add_body("b", mass, inertia, position=pos, orientation=R)
    geo, Rs, _ = upper(kind)
    shape = b.add_shape("g", geo, center=pos, orientation=R if Rs is None else R @ Rs)
    con = m.add_contact("c", m.ground.add_shape("roof", roof()), shape, K, E, 300.0, 1e-5, mu=0.5,
                        friction_velocity=1e-3)
    return m, con


KINDS = ["mesh prism", "mesh box", "hull prism", "box"]


@pytest.mark.parametrize("kind", KINDS)
def test_skew_edge_across_a_mesh_ridge_is_one_point_on_the_common_normal(kind):
    """The upper edge turned 60 degrees from the ridge about z and pitched 0.05 rad, crossing it 0.05 m from
    the roof's middle and 0.03 m from its own: X on the ridge, Y = X - D L on the upper edge (L the common
    normal, D = 3e-4 m): one point at X - D L / 2, normal L, depth D, force k D^e; its moment about the centre
    of mass is then that of the closed-form force at that point."""
    D = 3e-4
    R = _rot("z", np.pi / 3) @ _rot("y", 0.05)
    ru = R[:, 0]                                  # the upper edge's direction
    L = np.cross([0.0, 1.0, 0.0], ru)
    L = L / np.linalg.norm(L) * np.sign(L[2])     # the common normal, up
    X = np.array([0.0, 0.05, H])
    Y = X - D * L
    zr = upper(kind)[2]
    pos = Y - 0.03 * ru - R @ np.array([0.0, 0.0, -zr])
    F, rec = _loads(*_model(kind, R, pos))
    assert len(rec) == 1, rec
    row = dict(zip(REC_FIELDS, rec[0]))
    assert abs(row["penetration"] - D) < 1e-6 * D, (row["penetration"], D)
    n = np.array([row["nx"], row["ny"], row["nz"]])
    assert np.allclose(n, L, atol=1e-9), (n, L)
    c = X - 0.5 * D * L
    assert np.allclose([row["x"], row["y"], row["z"]], c, atol=1e-9)
    f = K * D ** E * L
    assert abs(row["normal_force"] - K * D ** E) < 1e-6 * K * D ** E
    assert np.allclose(F[1, :3], f, rtol=1e-6, atol=1e-9 * K * D ** E)             # on the upper body
    assert np.allclose(F[1, 3:], R.T @ np.cross(c - pos, f), rtol=1e-6, atol=1e-12)  # the moment, body axes


def _loads(m, con):
    """The contact loads (F per frame: force ground axes, torque body axes about the centre of mass) and the
    records at t = 0."""
    from mbdsim.system.assemble import assemble_system
    from mbdsim.system.force_elements.shape_contact import loads
    from mbdsim.system.frames import body_frames
    sys_ = assemble_system(m)
    fr = body_frames(sys_, sys_.q0, sys_.v0)
    return loads(sys_, (fr.r, fr.A, fr.rd, fr.w), con, np.zeros((64, len(REC_FIELDS))))


@pytest.mark.parametrize("kind", KINDS)
def test_edge_balanced_across_a_mesh_ridge_carries_the_weight_at_the_impact_penetration(kind):
    """The upper edge crosswise (along x) over the roof's ridge, its centre of mass over the crossing: it rests
    at d = (m g / k)^(1/e), one point at the crossing, the normal vertical (no lateral force), not turning."""
    mass = 1.0
    d = (mass * G / K) ** (1 / E)
    zr = upper(kind)[2]
    z0 = H + zr - d
    m, _ = _model(kind, np.eye(3), (0.0, 0.0, z0), mass, (2e-4, 3e-3, 3e-3))
    res = mb.simulate(m, 0.1, 0.01, method="dop853", rtol=1e-8)   # three periods of the contact's bounce
    assert res.success
    assert abs(res.position("b")[-1, 2] - z0) < 1e-3 * d, (res.position("b")[-1, 2] - z0, d)
    assert np.max(np.abs(res.position("b")[-1, :2])) < 1e-9
    assert np.max(np.abs(res.orientation("b")[-1] - np.eye(3))) < 1e-9
    pts = res.contact_points("c")
    last = pts[pts.time == pts.time.max()]
    assert len(last) == 1, last
    assert np.allclose(last[["nx", "ny"]].to_numpy(), 0.0, atol=1e-9)
    assert np.allclose(last[["x", "y"]].to_numpy(), 0.0, atol=1e-9)
    assert abs(last.penetration.iloc[0] - d) < 1e-3 * d
    assert abs(last.normal_force.iloc[0] - mass * G) < 1e-3 * mass * G
