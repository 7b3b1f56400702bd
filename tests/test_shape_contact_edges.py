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
