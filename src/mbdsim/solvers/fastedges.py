"""Edge-edge axes of two polyhedra at least one of which is a convex hull (issue 30).

`hull_edges(sc, a, b, Pa, Pb, face_depth, m0, m1, m2)` tests the axes L = e_a x e_b over the edges of shape a
and of shape b (sc[31] edge ranges, sc[32] edges as pairs of vertex rows of sc[7]; geometry.pack): the depth along L
(oriented from a's centre towards b's) is D = max over a's vertices of L.x - min over b's vertices of L.x [m].
Returns (status, p0, p1, p2, L0, L1, L2, D): status -1 when an axis separates the shapes, 1 when the least D
is clearly below the best face depth (under 0.95 of it: faces are preferred for resting contact), L is not
within FACE_COS of the reference face's normal m (an edge lying on that face, a box across a hull's ridge:
the face's contact, with a point where the edge crosses each side face, solvers.fastcross; the face depth
of the separating-axis test counts the incident's parts beyond the face, so a long ridge under a tilted box
went below 0.95 of it and the contact jumped between two points and one) and both edges support their
shapes along it (p: the midpoint of the edges' closest points [m], ground), else 0.
Boxes use fastcontact._box_edges (three edge directions each).
"""
from __future__ import annotations

import numpy as np
from .._jit import kernel

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from ..system.exprloads_kernel import _cross
from .fastnarrow import dir_ground, segments_closest, to_ground

FACE_COS = 0.999   # an edge-edge axis within this cosine of the reference face's normal is that face's contact


@kernel(_nrt=False)
def _extreme(P, verts, v0, v1, L0, L1, L2, sgn):
    """max over the vertices rows v0..v1 (ground, pose P) of sgn L.x [m]."""
    m = -np.inf
    for k in range(v0, v1):
        x0, x1, x2 = to_ground(P, verts[k, 0], verts[k, 1], verts[k, 2])
        s = sgn * (L0 * x0 + L1 * x1 + L2 * x2)
        if s > m:
            m = s
    return m


@kernel(_nrt=False)
def _end(P, verts, k):
    return to_ground(P, verts[k, 0], verts[k, 1], verts[k, 2])


@kernel(_nrt=False)
def hull_edges(sc, a, b, Pa, Pb, face_depth, m0, m1, m2):
    """Edge-edge axes of shapes a and b (module docstring)."""
    sv, verts, rad, se, E = sc[6], sc[7], sc[5], sc[31], sc[32]
    c0, c1, c2 = Pb[0] - Pa[0], Pb[1] - Pa[1], Pb[2] - Pa[2]
    tol = 1e-9 * (rad[a] + rad[b])
    best, bi, bj, L0, L1, L2 = 0.95 * face_depth, -1, -1, 0.0, 0.0, 0.0
    for i in range(se[a, 0], se[a, 1]):
        i0, i1 = E[i, 0], E[i, 1]
        ea0, ea1, ea2 = dir_ground(Pa, verts[i1, 0] - verts[i0, 0], verts[i1, 1] - verts[i0, 1],
                                   verts[i1, 2] - verts[i0, 2])
        na = np.sqrt(ea0 * ea0 + ea1 * ea1 + ea2 * ea2)
        for j in range(se[b, 0], se[b, 1]):
            j0, j1 = E[j, 0], E[j, 1]
            eb0, eb1, eb2 = dir_ground(Pb, verts[j1, 0] - verts[j0, 0], verts[j1, 1] - verts[j0, 1],
                                       verts[j1, 2] - verts[j0, 2])
            x0, x1, x2 = _cross(ea0, ea1, ea2, eb0, eb1, eb2)
            nrm = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
            if nrm < 1e-6 * na * np.sqrt(eb0 * eb0 + eb1 * eb1 + eb2 * eb2):
                continue   # parallel edges: the face axes cover them
            x0, x1, x2 = x0 / nrm, x1 / nrm, x2 / nrm
            if x0 * c0 + x1 * c1 + x2 * c2 < 0.0:
                x0, x1, x2 = -x0, -x1, -x2
            hi = _extreme(Pa, verts, sv[a, 0], sv[a, 1], x0, x1, x2, 1.0)
            lo = -_extreme(Pb, verts, sv[b, 0], sv[b, 1], x0, x1, x2, -1.0)
            D = hi - lo
            if not D > 0.0:
                return -1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
            if not D < best or abs(x0 * m0 + x1 * m1 + x2 * m2) > FACE_COS:
                continue   # not the least, or the reference face's own contact (an edge lying on the face)
            # both edges must be the supporting features along the axis
            p0, p1, p2 = _end(Pa, verts, i0)
            q0, q1, q2 = _end(Pa, verts, i1)
            if x0 * p0 + x1 * p1 + x2 * p2 < hi - tol or x0 * q0 + x1 * q1 + x2 * q2 < hi - tol:
                continue
            p0, p1, p2 = _end(Pb, verts, j0)
            q0, q1, q2 = _end(Pb, verts, j1)
            if x0 * p0 + x1 * p1 + x2 * p2 > lo + tol or x0 * q0 + x1 * q1 + x2 * q2 > lo + tol:
                continue
            best, bi, bj, L0, L1, L2 = D, i, j, x0, x1, x2
    if bi < 0:
        return 0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    a0, a1, a2 = _end(Pa, verts, E[bi, 0])
    b0, b1, b2 = _end(Pa, verts, E[bi, 1])
    d0, d1, d2 = _end(Pb, verts, E[bj, 0])
    e0, e1, e2 = _end(Pb, verts, E[bj, 1])
    X, Y = segments_closest(a0, a1, a2, b0, b1, b2, d0, d1, d2, e0, e1, e2)
    return 1, 0.5 * (X[0] + Y[0]), 0.5 * (X[1] + Y[1]), 0.5 * (X[2] + Y[2]), L0, L1, L2, best
