"""Compiled GJK and EPA over support functions (issue 30): the penetration of any two convex shapes.

`support` gives the ground point of a shape farthest along a ground direction, for every convex kind of
solvers.fastnarrow (sphere, box, cylinder, capsule, ellipsoid, convex hull).  `penetration` runs GJK (the
boolean form: a simplex of the Minkowski difference A - B that encloses the origin, or a direction that
separates) and then EPA (the polytope grown towards the boundary point of A - B nearest the origin) in the
scratch arrays of the packed contacts (geometry.pack: sc[23] vertices, sc[24] faces, sc[25] face normals,
sc[26] horizon edges): nothing is allocated.  It returns the depth [m], the unit normal n from A towards B
(moving B by depth along n separates them) and the point midway between the two witness points [m].
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from .fastnarrow import BOX, CAPSULE, CYLINDER, ELLIPSOID, SPHERE, dir_ground, dir_local, to_ground

MAX_ITER = 120     # EPA iterations (each adds one vertex); geometry.pack sizes the scratch from it


@kernel(_nrt=False)
def support(kind, P, p, verts, v0, nv, d0, d1, d2):
    """Ground point of the shape (pose P, parameters p, polytope vertices verts[v0:v0+nv]) farthest along
    the ground direction d (any length)."""
    u0, u1, u2 = dir_local(P, d0, d1, d2)
    if kind == SPHERE or kind == CAPSULE:
        L = np.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
        s = p[0] / L if L > 0.0 else 0.0
        z = 0.0
        if kind == CAPSULE:
            z = p[1] if u2 >= 0.0 else -p[1]
        return to_ground(P, s * u0, s * u1, z + s * u2)
    if kind == BOX:
        return to_ground(P, p[0] if u0 >= 0.0 else -p[0], p[1] if u1 >= 0.0 else -p[1],
                         p[2] if u2 >= 0.0 else -p[2])
    if kind == CYLINDER:
        L = np.sqrt(u0 * u0 + u1 * u1)
        s = p[0] / L if L > 0.0 else 0.0
        return to_ground(P, s * u0, s * u1, p[1] if u2 >= 0.0 else -p[1])
    if kind == ELLIPSOID:
        a0, a1, a2 = p[0] * p[0] * u0, p[1] * p[1] * u1, p[2] * p[2] * u2
        L = np.sqrt(a0 * u0 + a1 * u1 + a2 * u2)
        s = 1.0 / L if L > 0.0 else 0.0
        return to_ground(P, a0 * s, a1 * s, a2 * s)
    best, kb = -np.inf, v0
    for k in range(v0, v0 + nv):
        x = verts[k, 0] * u0 + verts[k, 1] * u1 + verts[k, 2] * u2
        if x > best:
            best, kb = x, k
    return to_ground(P, verts[kb, 0], verts[kb, 1], verts[kb, 2])


@kernel(_nrt=False)
def _vertex(sc, a, b, Pa, Pb, d0, d1, d2, V, i):
    """Vertex i of V: the support point of A - B along d (columns 0-2) and A's support point (3-5); its
    component along d."""
    kind, prm, sv, verts = sc[1], sc[4], sc[6], sc[7]
    x0, x1, x2 = support(kind[a], Pa, prm[a], verts, sv[a, 0], sv[a, 1] - sv[a, 0], d0, d1, d2)
    y0, y1, y2 = support(kind[b], Pb, prm[b], verts, sv[b, 0], sv[b, 1] - sv[b, 0], -d0, -d1, -d2)
    V[i, 0], V[i, 1], V[i, 2] = x0 - y0, x1 - y1, x2 - y2
    V[i, 3], V[i, 4], V[i, 5] = x0, x1, x2
    return V[i, 0] * d0 + V[i, 1] * d1 + V[i, 2] * d2


@kernel(_nrt=False)
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@kernel(_nrt=False)
def _copy(V, i, j):
    for c in range(6):
        V[j, c] = V[i, c]


@kernel(_nrt=False)
def _perp(a0, a1, a2):
    """A direction perpendicular to a."""
    if abs(a0) < abs(a1) and abs(a0) < abs(a2):
        return _cross(a0, a1, a2, 1.0, 0.0, 0.0)
    if abs(a1) < abs(a2):
        return _cross(a0, a1, a2, 0.0, 1.0, 0.0)
    return _cross(a0, a1, a2, 0.0, 0.0, 1.0)


@kernel(_nrt=False)
def _line(V):
    """Simplex V[0] (older), V[1] (newest): (count, direction towards the origin)."""
    ab0, ab1, ab2 = V[0, 0] - V[1, 0], V[0, 1] - V[1, 1], V[0, 2] - V[1, 2]
    ao0, ao1, ao2 = -V[1, 0], -V[1, 1], -V[1, 2]
    if ab0 * ao0 + ab1 * ao1 + ab2 * ao2 > 0.0:
        t0, t1, t2 = _cross(ab0, ab1, ab2, ao0, ao1, ao2)
        d0, d1, d2 = _cross(t0, t1, t2, ab0, ab1, ab2)
        if d0 * d0 + d1 * d1 + d2 * d2 <= 1e-30 * (ab0 * ab0 + ab1 * ab1 + ab2 * ab2) ** 2:
            d0, d1, d2 = _perp(ab0, ab1, ab2)   # the origin on the segment
        return 2, d0, d1, d2
    _copy(V, 1, 0)
    return 1, ao0, ao1, ao2


@kernel(_nrt=False)
def _triangle(V):
    """Simplex V[0], V[1] (older), V[2] (newest): (count, direction towards the origin)."""
    a0, a1, a2 = V[2, 0], V[2, 1], V[2, 2]
    ab0, ab1, ab2 = V[1, 0] - a0, V[1, 1] - a1, V[1, 2] - a2
    ac0, ac1, ac2 = V[0, 0] - a0, V[0, 1] - a1, V[0, 2] - a2
    n0, n1, n2 = _cross(ab0, ab1, ab2, ac0, ac1, ac2)
    e0, e1, e2 = _cross(n0, n1, n2, ac0, ac1, ac2)
    if -(e0 * a0 + e1 * a1 + e2 * a2) > 0.0:
        if -(ac0 * a0 + ac1 * a1 + ac2 * a2) > 0.0:   # edge AC: keep C (V[0]) and A
            _copy(V, 2, 1)
            return _line(V)
        _copy(V, 1, 0)   # edge AB
        _copy(V, 2, 1)
        return _line(V)
    f0, f1, f2 = _cross(ab0, ab1, ab2, n0, n1, n2)
    if -(f0 * a0 + f1 * a1 + f2 * a2) > 0.0:
        _copy(V, 1, 0)
        _copy(V, 2, 1)
        return _line(V)
    if -(n0 * a0 + n1 * a1 + n2 * a2) >= 0.0:
        return 3, n0, n1, n2
    return 3, -n0, -n1, -n2


@kernel(_nrt=False)
def _tetrahedron(V):
    """Simplex V[0..2] (older), V[3] (newest): (count 4 when it encloses the origin, else the face's
    triangle and its direction)."""
    for f in range(3):
        # faces through the newest vertex: (3, i, j) with the left-out vertex o
        i, j, o = (0, 1, 2) if f == 0 else ((1, 2, 0) if f == 1 else (2, 0, 1))
        a0, a1, a2 = V[3, 0], V[3, 1], V[3, 2]
        n0, n1, n2 = _cross(V[i, 0] - a0, V[i, 1] - a1, V[i, 2] - a2, V[j, 0] - a0, V[j, 1] - a1, V[j, 2] - a2)
        if n0 * (V[o, 0] - a0) + n1 * (V[o, 1] - a1) + n2 * (V[o, 2] - a2) > 0.0:
            n0, n1, n2 = -n0, -n1, -n2
        if -(n0 * a0 + n1 * a1 + n2 * a2) > 0.0:
            _copy(V, i, 4)
            _copy(V, j, 5)
            _copy(V, 4, 0)
            _copy(V, 5, 1)
            _copy(V, 3, 2)
            return _triangle(V)
    return 4, 0.0, 0.0, 0.0


@kernel(_nrt=False)
def gjk(sc, a, b, Pa, Pb, V):
    """Whether A and B overlap (GJK, boolean); on True V[0:4] is a tetrahedron of A - B around the origin."""
    d0, d1, d2 = Pa[0] - Pb[0], Pa[1] - Pb[1], Pa[2] - Pb[2]
    if d0 * d0 + d1 * d1 + d2 * d2 == 0.0:
        d0 = 1.0
    _vertex(sc, a, b, Pa, Pb, d0, d1, d2, V, 0)
    n, d0, d1, d2 = 1, -V[0, 0], -V[0, 1], -V[0, 2]
    for _ in range(64):
        if d0 * d0 + d1 * d1 + d2 * d2 == 0.0:
            return False   # the origin on a vertex: touching
        if not _vertex(sc, a, b, Pa, Pb, d0, d1, d2, V, n) > 0.0:
            return False   # a separating direction
        n += 1
        if n == 2:
            n, d0, d1, d2 = _line(V)
        elif n == 3:
            n, d0, d1, d2 = _triangle(V)
        else:
            n, d0, d1, d2 = _tetrahedron(V)
            if n == 4:
                return True
    return False


@kernel(_nrt=False)
def _face(V, F, FN, f, i, j, k):
    """Face f = (i, j, k) with its unit normal and distance from the origin (FN[f, 4] = 1: alive)."""
    F[f, 0], F[f, 1], F[f, 2] = i, j, k
    n0, n1, n2 = _cross(V[j, 0] - V[i, 0], V[j, 1] - V[i, 1], V[j, 2] - V[i, 2],
                        V[k, 0] - V[i, 0], V[k, 1] - V[i, 1], V[k, 2] - V[i, 2])
    L = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
    FN[f, 4] = 1.0
    if L > 0.0:
        FN[f, 0], FN[f, 1], FN[f, 2] = n0 / L, n1 / L, n2 / L
        FN[f, 3] = (n0 * V[i, 0] + n1 * V[i, 1] + n2 * V[i, 2]) / L
    else:
        FN[f, 0], FN[f, 1], FN[f, 2], FN[f, 3] = 0.0, 0.0, 0.0, np.inf


@kernel(_nrt=False)
def _add_edge(E, ne, i, j):
    """Horizon edge (i, j): removed if its reverse is there (shared by two removed faces), else added."""
    for e in range(ne):
        if E[e, 0] == j and E[e, 1] == i:
            E[e, 0], E[e, 1] = E[ne - 1, 0], E[ne - 1, 1]
            return ne - 1
    if ne < E.shape[0]:
        E[ne, 0], E[ne, 1] = i, j
        return ne + 1
    return ne


@kernel(_nrt=False)
def penetration(sc, a, b, Pa, Pb, tol):
    """(depth [m], n from A towards B, midpoint of the witness points) of shapes a, b (poses Pa, Pb);
    depth 0 when they do not overlap.  EPA stops when the support along the nearest face's normal is
    within tol [m] of it."""
    V, F, FN, E = sc[23], sc[24], sc[25], sc[26]
    if not gjk(sc, a, b, Pa, Pb, V):
        return 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0
    # the tetrahedron's faces, outward
    nf = 0
    for f in range(4):
        i, j, k = (0, 1, 2) if f == 0 else ((0, 3, 1) if f == 1 else ((0, 2, 3) if f == 2 else (1, 3, 2)))
        o = 6 - i - j - k
        _face(V, F, FN, nf, i, j, k)
        if FN[nf, 0] * (V[o, 0] - V[i, 0]) + FN[nf, 1] * (V[o, 1] - V[i, 1]) + FN[nf, 2] * (V[o, 2] - V[i, 2]) > 0.0:
            _face(V, F, FN, nf, i, k, j)
        nf += 1
    nv = 4
    best = 0
    for _ in range(MAX_ITER):
        best, dmin = -1, np.inf
        for f in range(nf):
            if FN[f, 4] > 0.0 and FN[f, 3] < dmin:
                best, dmin = f, FN[f, 3]
        if best < 0:
            return 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0
        if nv >= V.shape[0] or nf + E.shape[0] > F.shape[0]:
            break
        n0, n1, n2 = FN[best, 0], FN[best, 1], FN[best, 2]
        if _vertex(sc, a, b, Pa, Pb, n0, n1, n2, V, nv) - dmin <= tol:
            break
        w0, w1, w2 = V[nv, 0], V[nv, 1], V[nv, 2]
        ne = 0
        for f in range(nf):
            if FN[f, 4] > 0.0:
                i = F[f, 0]
                if FN[f, 0] * (w0 - V[i, 0]) + FN[f, 1] * (w1 - V[i, 1]) + FN[f, 2] * (w2 - V[i, 2]) > 0.0:
                    FN[f, 4] = 0.0
                    ne = _add_edge(E, ne, F[f, 0], F[f, 1])
                    ne = _add_edge(E, ne, F[f, 1], F[f, 2])
                    ne = _add_edge(E, ne, F[f, 2], F[f, 0])
        for e in range(ne):
            _face(V, F, FN, nf, E[e, 0], E[e, 1], nv)
            nf += 1
        nv += 1
    # witness points from the barycentric coordinates of the nearest point on the face
    dist = max(FN[best, 3], 0.0)
    n0, n1, n2 = FN[best, 0], FN[best, 1], FN[best, 2]
    i, j, k = F[best, 0], F[best, 1], F[best, 2]
    p0, p1, p2 = dist * n0, dist * n1, dist * n2
    e00, e01, e02 = V[j, 0] - V[i, 0], V[j, 1] - V[i, 1], V[j, 2] - V[i, 2]
    e10, e11, e12 = V[k, 0] - V[i, 0], V[k, 1] - V[i, 1], V[k, 2] - V[i, 2]
    r0, r1, r2 = p0 - V[i, 0], p1 - V[i, 1], p2 - V[i, 2]
    d00 = e00 * e00 + e01 * e01 + e02 * e02
    d01 = e00 * e10 + e01 * e11 + e02 * e12
    d11 = e10 * e10 + e11 * e11 + e12 * e12
    d20 = r0 * e00 + r1 * e01 + r2 * e02
    d21 = r0 * e10 + r1 * e11 + r2 * e12
    den = d00 * d11 - d01 * d01
    lj = (d11 * d20 - d01 * d21) / den if den > 0.0 else 0.0
    lk = (d00 * d21 - d01 * d20) / den if den > 0.0 else 0.0
    li = 1.0 - lj - lk
    x0 = li * V[i, 3] + lj * V[j, 3] + lk * V[k, 3]
    x1 = li * V[i, 4] + lj * V[j, 4] + lk * V[k, 4]
    x2 = li * V[i, 5] + lj * V[j, 5] + lk * V[k, 5]
    h = 0.5 * dist
    return dist, n0, n1, n2, x0 - h * n0, x1 - h * n1, x2 - h * n2


@kernel(_nrt=False)
def _ellipsoid_closest(a0, a1, a2, y0, y1, y2):
    """Closest point of the ellipsoid surface (semi-axes a) to the point y (local), for y outside or inside:
    x_i = a_i^2 y_i / (t + a_i^2) with t the root of sum (a_i y_i / (t + a_i^2))^2 = 1, by Newton from the
    right (the function is convex and decreasing there, so the iterates fall monotonically to the root)."""
    t = max(a0, a1, a2) * np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
    lo = -min(a0, a1, a2) ** 2
    for _ in range(100):
        q0, q1, q2 = a0 * y0 / (t + a0 * a0), a1 * y1 / (t + a1 * a1), a2 * y2 / (t + a2 * a2)
        f = q0 * q0 + q1 * q1 + q2 * q2 - 1.0
        df = -2.0 * (q0 * q0 / (t + a0 * a0) + q1 * q1 / (t + a1 * a1) + q2 * q2 / (t + a2 * a2))
        if not df < 0.0:
            break
        tn = t - f / df
        if tn <= lo:
            tn = 0.5 * (t + lo)
        if abs(tn - t) <= 1e-13 * (abs(t) + a0 * a0):
            t = tn
            break
        t = tn
    return a0 * a0 * y0 / (t + a0 * a0), a1 * a1 * y1 / (t + a1 * a1), a2 * a2 * y2 / (t + a2 * a2)


@kernel(_nrt=False)
def _cylinder_closest(r, h, y0, y1, y2):
    """Closest point of the cylinder's surface (radius r, half length h, local z axis) to the local point y."""
    rho = np.sqrt(y0 * y0 + y1 * y1)
    c, s = (y0 / rho, y1 / rho) if rho > 0.0 else (1.0, 0.0)
    if abs(y2) <= h and rho <= r:   # inside: the nearer of the side and the end
        if r - rho < h - abs(y2):
            return r * c, r * s, y2
        return y0, y1, h if y2 >= 0.0 else -h
    return min(rho, r) * c, min(rho, r) * s, min(max(y2, -h), h)


@kernel(_nrt=False)
def _box_closest(h0, h1, h2, y0, y1, y2):
    """Closest point of the box's surface (half sizes h, local axes) to the local point y, outside or inside."""
    if abs(y0) <= h0 and abs(y1) <= h1 and abs(y2) <= h2:   # inside: onto the nearest face
        g0, g1, g2 = h0 - abs(y0), h1 - abs(y1), h2 - abs(y2)
        if g0 <= g1 and g0 <= g2:
            return (h0 if y0 >= 0.0 else -h0), y1, y2
        if g1 <= g2:
            return y0, (h1 if y1 >= 0.0 else -h1), y2
        return y0, y1, (h2 if y2 >= 0.0 else -h2)
    return min(max(y0, -h0), h0), min(max(y1, -h1), h1), min(max(y2, -h2), h2)


@kernel(_nrt=False)
def _signed_distance(kind, P, p, x0, x1, x2):
    """(signed distance [m] of the ground point x to a cylinder, an ellipsoid or a box, < 0 inside; the unit
    normal of the surface there, outward, ground; the closest surface point)."""
    y0, y1, y2 = dir_local(P, x0 - P[0], x1 - P[1], x2 - P[2])
    if kind == CYLINDER:
        c0, c1, c2 = _cylinder_closest(p[0], p[1], y0, y1, y2)
        inside = abs(y2) <= p[1] and y0 * y0 + y1 * y1 <= p[0] * p[0]
    elif kind == BOX:
        c0, c1, c2 = _box_closest(p[0], p[1], p[2], y0, y1, y2)
        inside = abs(y0) <= p[0] and abs(y1) <= p[1] and abs(y2) <= p[2]
    else:
        c0, c1, c2 = _ellipsoid_closest(p[0], p[1], p[2], y0, y1, y2)
        inside = (y0 / p[0]) ** 2 + (y1 / p[1]) ** 2 + (y2 / p[2]) ** 2 < 1.0
    d0, d1, d2 = y0 - c0, y1 - c1, y2 - c2
    L = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    g0, g1, g2 = to_ground(P, c0, c1, c2)
    if L > 0.0:
        s = -1.0 / L if inside else 1.0 / L
        n0, n1, n2 = dir_ground(P, d0 * s, d1 * s, d2 * s)
    else:
        n0, n1, n2 = dir_ground(P, 0.0, 0.0, 1.0)
    return (-L if inside else L), n0, n1, n2, g0, g1, g2


@kernel(_nrt=False)
def segment_penetration(kind_s, Ps, ps, a0, a1, a2, b0, b1, b2, radius):
    """(depth [m], unit normal from the solid s (a cylinder, an ellipsoid or a box) towards the segment a-b
    swept by radius [m] (0: the bare segment), the point midway in the overlap, the segment's parameter
    t in [0, 1] of its nearest point): radius less the distance of the segment from s, the nearest point
    found by golden-section search (the signed distance to a convex solid is convex along a segment)."""
    t = 0.0
    dd = (b0 - a0) ** 2 + (b1 - a1) ** 2 + (b2 - a2) ** 2
    if dd > 0.0:
        lo, hi = 0.0, 1.0
        g = 0.6180339887498949
        u, v = hi - g * (hi - lo), lo + g * (hi - lo)
        fu = _signed_distance(kind_s, Ps, ps, a0 + u * (b0 - a0), a1 + u * (b1 - a1), a2 + u * (b2 - a2))[0]
        fv = _signed_distance(kind_s, Ps, ps, a0 + v * (b0 - a0), a1 + v * (b1 - a1), a2 + v * (b2 - a2))[0]
        for _ in range(60):
            if fu < fv:
                hi, v, fv = v, u, fu
                u = hi - g * (hi - lo)
                fu = _signed_distance(kind_s, Ps, ps, a0 + u * (b0 - a0), a1 + u * (b1 - a1), a2 + u * (b2 - a2))[0]
            else:
                lo, u, fu = u, v, fv
                v = lo + g * (hi - lo)
                fv = _signed_distance(kind_s, Ps, ps, a0 + v * (b0 - a0), a1 + v * (b1 - a1), a2 + v * (b2 - a2))[0]
        t = 0.5 * (lo + hi)
        # the ends themselves (the search's bracket never reaches them)
        f0 = _signed_distance(kind_s, Ps, ps, a0, a1, a2)[0]
        f1 = _signed_distance(kind_s, Ps, ps, b0, b1, b2)[0]
        ft = _signed_distance(kind_s, Ps, ps, a0 + t * (b0 - a0), a1 + t * (b1 - a1), a2 + t * (b2 - a2))[0]
        if f0 < ft and f0 <= f1:
            t = 0.0
        elif f1 < ft:
            t = 1.0
    dist, n0, n1, n2, g0, g1, g2 = _signed_distance(kind_s, Ps, ps, a0 + t * (b0 - a0), a1 + t * (b1 - a1),
                                                    a2 + t * (b2 - a2))
    depth = radius - dist
    if not depth > 0.0:
        return 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, t
    hd = 0.5 * depth
    return depth, n0, n1, n2, g0 - hd * n0, g1 - hd * n1, g2 - hd * n2, t


@kernel(_nrt=False)
def rounded_penetration(kind_r, Pr, pr, kind_s, Ps, ps):
    """(depth [m], unit normal from the solid shape s (a cylinder, an ellipsoid or a box) towards the rounded
    one r (a sphere or capsule: a point or a segment swept by its radius), the point midway in the overlap):
    `segment_penetration` of r's core."""
    h = pr[1] if kind_r == CAPSULE else 0.0
    a0, a1, a2 = to_ground(Pr, 0.0, 0.0, -h)
    b0, b1, b2 = to_ground(Pr, 0.0, 0.0, h)
    depth, n0, n1, n2, p0, p1, p2, _t = segment_penetration(kind_s, Ps, ps, a0, a1, a2, b0, b1, b2, pr[0])
    return depth, n0, n1, n2, p0, p1, p2
