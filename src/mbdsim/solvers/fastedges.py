"""Edge-edge axes of two polyhedra at least one of which is a convex hull (issue 30).

`hull_edges(sc, a, b, Pa, Pb, face_depth, m0, m1, m2)` tests the axes L = e_a x e_b of the pairs of an edge of
shape a and an edge of shape b (sc[31] edge ranges, sc[32] edges as pairs of vertex rows of sc[7], sc[36] the
outward normals of each edge's two faces; geometry.pack) that build a face of the shapes' Minkowski difference:
the arcs of the two edges on the Gauss map (from one face normal to the other; b's negated) cross
(Gregorius, "The separating axis test between convex polyhedra", GDC 2013). Only those axes can separate two
convex polyhedra beyond their face normals, and along such an axis (oriented out of a, into the arc of a's
edge) each edge supports its shape, so the depth along L is D = L.(p_a - p_b) for a point of each edge [m]:
a test of a few products per pair instead of the support of both shapes' vertices (a 64-gon cam's 192 edges
against a box's 12: 0.4 ms of each evaluation before). Returns (status, p0, p1, p2, L0, L1, L2, D): status -1
when an axis separates the shapes, 1 when the least D is clearly below the best face depth (under 0.95 of
it: faces are preferred for resting contact) and L is not within FACE_COS of the reference face's normal m
(an edge lying on that face, a box across a hull's ridge: the face's contact, with a point where the edge
crosses each side face, solvers.fastcross; the face depth of the separating-axis test counts the
incident's parts beyond the face, so a long ridge under a tilted box went below 0.95 of it and the contact
jumped between two points and one) (p: the midpoint of the edges' closest points [m], ground), else 0.
Boxes use fastcontact._box_edges (three edge directions each).
"""
from __future__ import annotations

import numpy as np
from .._jit import kernel

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from ..system.exprloads_kernel import _cross
from .fastnarrow import dir_ground, dir_local, segments_closest, to_ground, to_local

FACE_COS = 0.999   # an edge-edge axis within this cosine of the reference face's normal is that face's contact


@kernel(_nrt=False)
def _end(P, verts, k):
    return to_ground(P, verts[k, 0], verts[k, 1], verts[k, 2])


@kernel(_nrt=False)
def hull_edges(sc, a, b, Pa, Pb, face_depth, m0, m1, m2):
    """Edge-edge axes of shapes a and b (module docstring); the tests run in a's axes."""
    verts, se, E, N = sc[7], sc[31], sc[32], sc[36]
    best, bi, bj, L0, L1, L2 = 0.95 * face_depth, -1, -1, 0.0, 0.0, 0.0
    n0, n1, n2 = dir_local(Pa, m0, m1, m2)   # the reference face's normal
    for j in range(se[b, 0], se[b, 1]):
        g0, g1, g2 = _end(Pb, verts, E[j, 0])
        p0, p1, p2 = to_local(Pa, g0, g1, g2)   # a point of b's edge, and its faces' normals negated
        g0, g1, g2 = dir_ground(Pb, -N[j, 0], -N[j, 1], -N[j, 2])
        c0, c1, c2 = dir_local(Pa, g0, g1, g2)
        g0, g1, g2 = dir_ground(Pb, -N[j, 3], -N[j, 4], -N[j, 5])
        d0, d1, d2 = dir_local(Pa, g0, g1, g2)
        f0, f1, f2 = _cross(d0, d1, d2, c0, c1, c2)   # along b's edge
        nf = np.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
        for i in range(se[a, 0], se[a, 1]):
            a0, a1, a2, b0, b1, b2 = N[i, 0], N[i, 1], N[i, 2], N[i, 3], N[i, 4], N[i, 5]
            e0, e1, e2 = _cross(b0, b1, b2, a0, a1, a2)   # along a's edge
            cba = c0 * e0 + c1 * e1 + c2 * e2
            dba = d0 * e0 + d1 * e1 + d2 * e2
            if not cba * dba < 0.0:
                continue
            adc = a0 * f0 + a1 * f1 + a2 * f2
            bdc = b0 * f0 + b1 * f1 + b2 * f2
            if not (adc * bdc < 0.0 and cba * bdc > 0.0):
                continue   # the arcs do not cross: not a face of the Minkowski difference
            x0, x1, x2 = _cross(e0, e1, e2, f0, f1, f2)
            nrm = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
            if nrm < 1e-6 * np.sqrt(e0 * e0 + e1 * e1 + e2 * e2) * nf:
                continue   # parallel edges: the face axes cover them
            x0, x1, x2 = x0 / nrm, x1 / nrm, x2 / nrm
            if x0 * (a0 + b0) + x1 * (a1 + b1) + x2 * (a2 + b2) < 0.0:
                x0, x1, x2 = -x0, -x1, -x2   # out of a: within the arc of a's edge
            k = E[i, 0]
            D = x0 * (verts[k, 0] - p0) + x1 * (verts[k, 1] - p1) + x2 * (verts[k, 2] - p2)
            if not D > 0.0:
                return -1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
            if not D < best or abs(x0 * n0 + x1 * n1 + x2 * n2) > FACE_COS:
                continue   # not the least, or the reference face's own contact (an edge lying on the face)
            best, bi, bj, L0, L1, L2 = D, i, j, x0, x1, x2
    if bi < 0:
        return 0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    L0, L1, L2 = dir_ground(Pa, L0, L1, L2)
    a0, a1, a2 = _end(Pa, verts, E[bi, 0])
    b0, b1, b2 = _end(Pa, verts, E[bi, 1])
    d0, d1, d2 = _end(Pb, verts, E[bj, 0])
    e0, e1, e2 = _end(Pb, verts, E[bj, 1])
    X, Y = segments_closest(a0, a1, a2, b0, b1, b2, d0, d1, d2, e0, e1, e2)
    return 1, 0.5 * (X[0] + Y[0]), 0.5 * (X[1] + Y[1]), 0.5 * (X[2] + Y[2]), L0, L1, L2, best
