"""Compiled narrow phase of shape contact (issue 30): poses, candidate points and separating-axis tests.

A shape (geometry.pack) has a kind, a frame, a local frame (origin c and axes R in body axes), three
parameters and, for polyhedra, local vertices and face planes (n . x <= d inside).  A pose is the 12-tuple
(o, G) of the local frame in ground (o [m], G row-major 3x3) at the current state: nothing is allocated.

Kinds: SPHERE (p = r), PLANE (local z = outward normal), BOX (p = half extents), CYLINDER (p = r, half
length; local z = axis), CAPSULE (p = r, half length of the segment; local z = axis), ELLIPSOID (p = semi-axes),
HULL (vertices and planes), MESH (vertices; non-convex).
"""
from __future__ import annotations

import numpy as np
from .._jit import kernel

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)

SPHERE, PLANE, BOX, CYLINDER, CAPSULE, ELLIPSOID, HULL, MESH = 0, 1, 2, 3, 4, 5, 6, 7
POLYTOPES = (BOX, HULL)
LINE_SIN = 0.02   # sine of the largest angle between two axes (or an axis and an edge) that still touch along a line
KIND_NAMES = ("sphere", "plane", "box", "cylinder", "capsule", "ellipsoid", "convex mesh", "mesh")
_BOX_SIGNS = np.array([[sx, sy, sz] for sx in (-1.0, 1.0) for sy in (-1.0, 1.0) for sz in (-1.0, 1.0)])


@kernel(_nrt=False)
def pose(r, A, f, c, R):
    """(o, G) of a shape's local frame in ground: o = r_f + A_f c, G = A_f R (row-major)."""
    o0 = r[f, 0] + A[f, 0, 0] * c[0] + A[f, 0, 1] * c[1] + A[f, 0, 2] * c[2]
    o1 = r[f, 1] + A[f, 1, 0] * c[0] + A[f, 1, 1] * c[1] + A[f, 1, 2] * c[2]
    o2 = r[f, 2] + A[f, 2, 0] * c[0] + A[f, 2, 1] * c[1] + A[f, 2, 2] * c[2]
    return (o0, o1, o2,
            A[f, 0, 0] * R[0, 0] + A[f, 0, 1] * R[1, 0] + A[f, 0, 2] * R[2, 0],
            A[f, 0, 0] * R[0, 1] + A[f, 0, 1] * R[1, 1] + A[f, 0, 2] * R[2, 1],
            A[f, 0, 0] * R[0, 2] + A[f, 0, 1] * R[1, 2] + A[f, 0, 2] * R[2, 2],
            A[f, 1, 0] * R[0, 0] + A[f, 1, 1] * R[1, 0] + A[f, 1, 2] * R[2, 0],
            A[f, 1, 0] * R[0, 1] + A[f, 1, 1] * R[1, 1] + A[f, 1, 2] * R[2, 1],
            A[f, 1, 0] * R[0, 2] + A[f, 1, 1] * R[1, 2] + A[f, 1, 2] * R[2, 2],
            A[f, 2, 0] * R[0, 0] + A[f, 2, 1] * R[1, 0] + A[f, 2, 2] * R[2, 0],
            A[f, 2, 0] * R[0, 1] + A[f, 2, 1] * R[1, 1] + A[f, 2, 2] * R[2, 1],
            A[f, 2, 0] * R[0, 2] + A[f, 2, 1] * R[1, 2] + A[f, 2, 2] * R[2, 2])


@kernel(_nrt=False)
def to_ground(P, x0, x1, x2):
    """Ground point [m] of the local point x."""
    return (P[0] + P[3] * x0 + P[4] * x1 + P[5] * x2, P[1] + P[6] * x0 + P[7] * x1 + P[8] * x2,
            P[2] + P[9] * x0 + P[10] * x1 + P[11] * x2)


@kernel(_nrt=False)
def dir_ground(P, x0, x1, x2):
    """Ground components of the local direction x."""
    return (P[3] * x0 + P[4] * x1 + P[5] * x2, P[6] * x0 + P[7] * x1 + P[8] * x2,
            P[9] * x0 + P[10] * x1 + P[11] * x2)


@kernel(_nrt=False)
def dir_local(P, y0, y1, y2):
    """Local components of the ground direction y (G^T y)."""
    return (P[3] * y0 + P[6] * y1 + P[9] * y2, P[4] * y0 + P[7] * y1 + P[10] * y2,
            P[5] * y0 + P[8] * y1 + P[11] * y2)


@kernel(_nrt=False)
def to_local(P, y0, y1, y2):
    """Local coordinates of the ground point y."""
    return dir_local(P, y0 - P[0], y1 - P[1], y2 - P[2])


@kernel(_nrt=False)
def n_candidates(kind, nvert):
    """How many candidate points a shape offers against a half-space (see `candidate`)."""
    if kind == SPHERE or kind == ELLIPSOID:
        return 1
    if kind == CAPSULE:
        return 2
    if kind == CYLINDER:
        return 6
    return nvert


@kernel(_nrt=False)
def candidate(kind, P, p, verts, v0, m0, m1, m2, k):
    """Ground position [m] of candidate point k of a shape against the half-space with outward unit normal
    m (ground; the shape lies on its +m side): the deepest point along -m of a sphere, an ellipsoid and
    each end of a capsule; on each end rim of a cylinder the deepest point and the two at 120 and 240
    degrees from it (a cylinder lying on a face touches along a line, one standing on an end on a tripod of
    its rim); the vertices of polyhedra (their deepest points are vertices)."""
    if kind == SPHERE:
        return P[0] - p[0] * m0, P[1] - p[0] * m1, P[2] - p[0] * m2
    if kind == CAPSULE:
        s = p[1] if k == 0 else -p[1]
        x0, x1, x2 = to_ground(P, 0.0, 0.0, s)
        return x0 - p[0] * m0, x1 - p[0] * m1, x2 - p[0] * m2
    if kind == ELLIPSOID:
        u0, u1, u2 = dir_local(P, -m0, -m1, -m2)
        a0, a1, a2 = p[0] * p[0] * u0, p[1] * p[1] * u1, p[2] * p[2] * u2
        nrm = np.sqrt(p[0] * p[0] * u0 * u0 + p[1] * p[1] * u1 * u1 + p[2] * p[2] * u2 * u2)
        return to_ground(P, a0 / nrm, a1 / nrm, a2 / nrm)
    if kind == CYLINDER:
        u0, u1, _u2 = dir_local(P, -m0, -m1, -m2)
        L = np.sqrt(u0 * u0 + u1 * u1)
        if L > 1e-12:
            c, s = u0 / L, u1 / L
        else:
            c, s = 1.0, 0.0
        j = k % 3
        if j == 1:
            c, s = -0.5 * c - 0.8660254037844386 * s, 0.8660254037844386 * c - 0.5 * s
        elif j == 2:
            c, s = -0.5 * c + 0.8660254037844386 * s, -0.8660254037844386 * c - 0.5 * s
        return to_ground(P, p[0] * c, p[0] * s, p[1] if k < 3 else -p[1])
    return to_ground(P, verts[v0 + k, 0], verts[v0 + k, 1], verts[v0 + k, 2])


@kernel(_nrt=False)
def support_depth(kind, P, p, verts, v0, nv, q0, q1, q2, m0, m1, m2):
    """Largest depth [m] of the shape below the plane through q with outward normal m (<= 0: clear)."""
    best = -np.inf
    for k in range(n_candidates(kind, nv)):
        x0, x1, x2 = candidate(kind, P, p, verts, v0, m0, m1, m2, k)
        d = m0 * (q0 - x0) + m1 * (q1 - x1) + m2 * (q2 - x2)
        if d > best:
            best = d
    return best


@kernel(_nrt=False)
def face(P, planes, pl, g):
    """Face plane g of a polyhedron in ground: (a point q on it, outward unit normal m)."""
    n0, n1, n2 = dir_ground(P, planes[pl + g, 0], planes[pl + g, 1], planes[pl + g, 2])
    d = planes[pl + g, 3]
    return P[0] + n0 * d, P[1] + n1 * d, P[2] + n2 * d, n0, n1, n2


@kernel(_nrt=False)
def inside_except(P, planes, pl, npl, skip, x0, x1, x2, tol):
    """Whether the ground point x is inside every face plane of a polyhedron but `skip`, within tol [m]."""
    y0, y1, y2 = to_local(P, x0, x1, x2)
    for g in range(npl):
        if g != skip and planes[pl + g, 0] * y0 + planes[pl + g, 1] * y1 + planes[pl + g, 2] * y2 \
                - planes[pl + g, 3] > tol:
            return False
    return True


@kernel(_nrt=False)
def segment_closest(a0, a1, a2, b0, b1, b2, x0, x1, x2):
    """Closest point to x on the segment a-b."""
    d0, d1, d2 = b0 - a0, b1 - a1, b2 - a2
    dd = d0 * d0 + d1 * d1 + d2 * d2
    t = ((x0 - a0) * d0 + (x1 - a1) * d1 + (x2 - a2) * d2) / dd if dd > 0.0 else 0.0
    t = min(max(t, 0.0), 1.0)
    return a0 + t * d0, a1 + t * d1, a2 + t * d2


@kernel(_nrt=False)
def segments_closest(a0, a1, a2, b0, b1, b2, c0, c1, c2, e0, e1, e2):
    """Closest points (on a-b, on c-e) of two segments (clamped parameters, a few alternations)."""
    d0, d1, d2 = b0 - a0, b1 - a1, b2 - a2
    f0, f1, f2 = e0 - c0, e1 - c1, e2 - c2
    r0, r1, r2 = a0 - c0, a1 - c1, a2 - c2
    A_ = d0 * d0 + d1 * d1 + d2 * d2
    E = f0 * f0 + f1 * f1 + f2 * f2
    B = d0 * f0 + d1 * f1 + d2 * f2
    C = d0 * r0 + d1 * r1 + d2 * r2
    Fv = f0 * r0 + f1 * r1 + f2 * r2
    den = A_ * E - B * B
    s = min(max((B * Fv - C * E) / den, 0.0), 1.0) if den > 1e-14 * A_ * E and A_ > 0.0 else 0.0
    t = (B * s + Fv) / E if E > 0.0 else 0.0
    if t < 0.0:
        t = 0.0
        s = min(max(-C / A_, 0.0), 1.0) if A_ > 0.0 else 0.0
    elif t > 1.0:
        t = 1.0
        s = min(max((B - C) / A_, 0.0), 1.0) if A_ > 0.0 else 0.0
    return (a0 + s * d0, a1 + s * d1, a2 + s * d2), (c0 + t * f0, c1 + t * f1, c2 + t * f2)


@kernel(_nrt=False)
def deepest_on_face(sc, x, ref, g, Px, Pr, q0, q1, q2, m0, m1, m2):
    """Whether a deepest candidate point of the curved shape x below face g (point q, outward normal m) of
    the polyhedron ref lies over that face (inside its other planes): then the face's normal is the contact
    normal (a cylinder lying on the face, a sphere on it); else x presses on an edge or a vertex."""
    kind, prm, sv, verts, spl, planes, rad = sc[1], sc[4], sc[6], sc[7], sc[8], sc[9], sc[5]
    nc = n_candidates(kind[x], sv[x, 1] - sv[x, 0])
    D = support_depth(kind[x], Px, prm[x], verts, sv[x, 0], sv[x, 1] - sv[x, 0], q0, q1, q2, m0, m1, m2)
    tol = 1e-6 * rad[ref] + 1e-12
    for k in range(nc):
        c0, c1, c2 = candidate(kind[x], Px, prm[x], verts, sv[x, 0], m0, m1, m2, k)
        if m0 * (q0 - c0) + m1 * (q1 - c1) + m2 * (q2 - c2) >= D - tol and \
                inside_except(Pr, planes, spl[ref, 0], spl[ref, 1] - spl[ref, 0], g, c0, c1, c2, tol):
            return True
    return False


@kernel(_nrt=False)
def exit_depth(P, planes, p0_, p1_, v0, v1, v2, m0, m1, m2):
    """Distance [m] from the point v inside a polyhedron (pose P) to its surface along -m."""
    y0, y1, y2 = to_local(P, v0, v1, v2)
    u0, u1, u2 = dir_local(P, m0, m1, m2)
    best = np.inf
    for g in range(p0_, p1_):
        nm = planes[g, 0] * u0 + planes[g, 1] * u1 + planes[g, 2] * u2
        if nm < -1e-12:
            t = (planes[g, 0] * y0 + planes[g, 1] * y1 + planes[g, 2] * y2 - planes[g, 3]) / nm
            if t < best:
                best = t
    return best


@kernel(_nrt=False)
def pressed(Px, Pr, verts, x0_, x1_, planes, p0_, p1_, g, v0, v1, v2, m0, m1, m2, q0, q1, q2, tol):
    """Whether an incident vertex that `_against` used (below the reference face g, inside the reference)
    lies on the normal line through the reference vertex v (within tol [m])."""
    for k in range(x0_, x1_):
        u0, u1, u2 = to_ground(Px, verts[k, 0], verts[k, 1], verts[k, 2])
        if not m0 * (q0 - u0) + m1 * (q1 - u1) + m2 * (q2 - u2) > 0.0:
            continue
        if not inside_except(Pr, planes, p0_, p1_ - p0_, g, u0, u1, u2, tol):
            continue
        e0, e1, e2 = u0 - v0, u1 - v1, u2 - v2
        en = e0 * m0 + e1 * m1 + e2 * m2
        e0, e1, e2 = e0 - en * m0, e1 - en * m1, e2 - en * m2
        if e0 * e0 + e1 * e1 + e2 * e2 <= tol * tol:
            return True
    return False
