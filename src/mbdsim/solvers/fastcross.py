"""Edge crossings of two polyhedra in face contact (issue 30): the corners of the contact polygon that are
neither polyhedron's vertex.

Two boxes or hulls in face contact (solvers.fastcontact._polytope_pair: the reference face of least
penetration, outward normal m) touch over the overlap of the reference face with the incident polyhedron.
The corners of that polygon are the incident's vertices inside the reference (fastcontact._against), the
reference's vertices inside the incident (the second loop of _polytope_pair) and the points where an
incident edge leaves the reference through one of its side planes.  Without the last kind a box resting
across a hull's ridge or a box's edge (no vertex of either inside the other) fell through, and a box
resting off-centre on another touched at two diagonal corners and could rock about the diagonal.

`edge_crossings` clips each incident edge (sc[31] ranges, sc[32] vertex rows; geometry.pack) on the
reference's face planes (fastridge._clip, Cyrus-Beck) and writes, for each end of the part inside whose
edge vertex there lies outside the reference by more than tol (else _against has that vertex: the two are
complementary), that lies below the reference face's plane by more than tol and that does not coincide
with a reference vertex inside the incident (two edges flush), a row of the slot buffer S
(solvers.fastmesh layout: used, depth [m], point midway [m], normal m, weight 1).
"""
from __future__ import annotations

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from .fastnarrow import inside_except, to_ground, to_local
from .fastridge import _clip

@kernel(_nrt=False)
def _on_reference_vertex(sc, rs, xs, Pr, Px, c0, c1, c2, m0, m1, m2, tol):
    """Whether a vertex of the reference rs inside the incident xs lies within tol [m] of the point c across
    the normal m (the same corner, already pushing)."""
    verts, sv, spl, planes = sc[7], sc[6], sc[8], sc[9]
    for k in range(sv[rs, 0], sv[rs, 1]):
        v0, v1, v2 = to_ground(Pr, verts[k, 0], verts[k, 1], verts[k, 2])
        e0, e1, e2 = v0 - c0, v1 - c1, v2 - c2
        en = e0 * m0 + e1 * m1 + e2 * m2
        e0, e1, e2 = e0 - en * m0, e1 - en * m1, e2 - en * m2
        if e0 * e0 + e1 * e1 + e2 * e2 <= tol * tol and \
                inside_except(Px, planes, spl[xs, 0], spl[xs, 1] - spl[xs, 0], -1, v0, v1, v2, tol):
            return True
    return False


@kernel(_nrt=False)
def edge_crossings(sc, xs, rs, g, Px, Pr, q0, q1, q2, m0, m1, m2, tol, S):
    """Rows of S (from 0) for the incident xs's (pose Px) edges leaving the reference rs (pose Pr) through
    its side planes below the reference face g (a point q on it, outward normal m), tol [m] (module
    docstring); returns how many."""
    verts, spl, planes, eran, edges = sc[7], sc[8], sc[9], sc[31], sc[32]
    p0, p1 = spl[rs, 0], spl[rs, 1]
    n = 0
    for k in range(eran[xs, 0], eran[xs, 1]):
        if n + 2 > S.shape[0]:
            return n
        ia, ib = edges[k, 0], edges[k, 1]
        a0, a1, a2 = to_ground(Px, verts[ia, 0], verts[ia, 1], verts[ia, 2])
        b0, b1, b2 = to_ground(Px, verts[ib, 0], verts[ib, 1], verts[ib, 2])
        y0, y1, y2 = to_local(Pr, a0, a1, a2)
        z0, z1, z2 = to_local(Pr, b0, b1, b2)
        t0, t1 = _clip(planes, p0, p1, y0, y1, y2, z0 - y0, z1 - y1, z2 - y2)
        if not t0 < t1:
            continue
        for end in range(2):
            tt = t0 if end == 0 else t1
            if end == 0 and (tt <= 0.0 or inside_except(Pr, planes, p0, p1 - p0, -1, a0, a1, a2, tol)):
                continue   # the edge's own vertex inside the reference (within tol): fastcontact._against has it
            if end == 1 and (tt >= 1.0 or inside_except(Pr, planes, p0, p1 - p0, -1, b0, b1, b2, tol)):
                continue
            c0, c1, c2 = a0 + tt * (b0 - a0), a1 + tt * (b1 - a1), a2 + tt * (b2 - a2)
            dep = m0 * (q0 - c0) + m1 * (q1 - c1) + m2 * (q2 - c2)
            if not dep > tol or _on_reference_vertex(sc, rs, xs, Pr, Px, c0, c1, c2, m0, m1, m2, tol):
                continue
            h = 0.5 * dep
            S[n, 0], S[n, 1], S[n, 2], S[n, 3], S[n, 4] = 1.0, dep, c0 + h * m0, c1 + h * m1, c2 + h * m2
            S[n, 5], S[n, 6], S[n, 7], S[n, 8] = m0, m1, m2, 1.0
            n += 1
    return n
