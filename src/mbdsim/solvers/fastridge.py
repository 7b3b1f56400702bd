"""Ridges and peaks of a triangle mesh pressing into a box or convex hull (issue 30).

A box or hull met by a larger triangle mesh (solvers.fastmesh) pushes with its vertices below the mesh's
triangles; that misses a mesh feature that enters one of the polyhedron's faces without any polyhedron
vertex under a triangle: a ridge (a box lying across a roof's ridge, a rail's edge) or a peak.  geometry.pack
marks per triangle (sc[33], bits) the mesh's ridge edges (shared by two faces that meet at a convex, non-flat
angle) and its peaks (vertices with all their neighbours on or below all their faces' planes, some strictly),
each owned by one of its triangles, so that the hierarchy walk meets each once:

* bits 0-2: the triangle owns the ridge from its vertex e to vertex e + 1 (mod 3);
* bits 3-5: it owns the peak at its vertex j;
* bits 6-8: its vertex j is a peak (owned or not).

`ridge_points` adds, for the triangle's owned features inside the polyhedron (its planes, local axes):

* a ridge: its part inside the polyhedron, [t0, t1] along it (Cyrus-Beck clipping on the face planes); the
  face of least depth over that part is the reference (normal n outward); a point at each end of the part
  that is not a peak (peaks push on their own), depth the end's distance below that face: a ridge across a
  face is a line contact, one point at each end of the line (as a cylinder on a face);
* a peak: its depth below the nearest face plane, that face's normal.

Rows of the slot buffer S (solvers.fastmesh layout: used, depth [m], point [m], normal, weight), the point
midway between the feature and the face, the normal -n (from the mesh into the polyhedron, as a triangle's).

`curved_ridge_points` does the same for a capsule, a cylinder or an ellipsoid (whose candidate points against
the triangles' planes miss a ridge under their curved side): per owned ridge the deepest point by the
signed distance from the solid (fastgjk.segment_penetration; a capsule by the nearest points of its core and
the ridge, where that is not an end of the core, whose end sphere has it already), a cylinder lying along a
ridge (within LINE_SIN of its axis) a point at each end of the part of the ridge beside its side, each as
deep as the radius less its distance from the axis; per owned peak its depth in the solid.  A ridge point counts
only when its normal lies in the ridge's normal cone (between its two faces' normals, sc[35] naming the
neighbour across each edge): a cylinder resting on one face beside the ridge pushes on that face alone.
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from .fastgjk import _signed_distance, segment_penetration
from .fastnarrow import (CAPSULE, CYLINDER, LINE_SIN, dir_ground, dir_local, segment_closest, segments_closest, to_ground,
                         to_local)


@kernel(_nrt=False)
def _row(S, s, depth, y0, y1, y2, n0, n1, n2):
    """Slot row s: the point y [m] of the given depth below the face of outward normal n (ground)."""
    h = 0.5 * depth
    S[s, 0], S[s, 1], S[s, 2], S[s, 3], S[s, 4] = 1.0, depth, y0 + h * n0, y1 + h * n1, y2 + h * n2
    S[s, 5], S[s, 6], S[s, 7], S[s, 8] = -n0, -n1, -n2, 1.0


@kernel(_nrt=False)
def _peak(planes, p0, p1, y0, y1, y2):
    """(depth [m], plane row) of the local point y below the nearest face plane; depth <= 0: outside."""
    best, g = np.inf, -1
    for k in range(p0, p1):
        dep = planes[k, 3] - (planes[k, 0] * y0 + planes[k, 1] * y1 + planes[k, 2] * y2)
        if dep < best:
            best, g = dep, k
    return best, g


@kernel(_nrt=False)
def _clip(planes, p0, p1, a0, a1, a2, e0, e1, e2):
    """Parameter interval (t0, t1) of the local segment a + t e, 0 <= t <= 1, inside every face plane."""
    t0, t1 = 0.0, 1.0
    for k in range(p0, p1):
        num = planes[k, 3] - (planes[k, 0] * a0 + planes[k, 1] * a1 + planes[k, 2] * a2)
        den = planes[k, 0] * e0 + planes[k, 1] * e1 + planes[k, 2] * e2
        if den > 0.0:
            t1 = min(t1, num / den)
        elif den < 0.0:
            t0 = max(t0, num / den)
        elif num < 0.0:
            return 1.0, 0.0
        if not t0 < t1:
            return 1.0, 0.0
    return t0, t1


@kernel(_nrt=False)
def ridge_points(sc, x, Px, Pm, t, S, s):
    """The owned ridges and peaks of triangle t (mesh pose Pm) inside polyhedron x (pose Px) into the rows
    s, s + 1, ... of S while it has room (module docstring); returns the next free row."""
    mask = sc[33][t]
    if mask == 0:
        return s
    verts, tri, spl, planes = sc[7], sc[22], sc[8], sc[9]
    p0, p1 = spl[x, 0], spl[x, 1]
    for j in range(3):
        if s >= S.shape[0]:
            return s
        v = tri[t, j]
        g0, g1, g2 = to_ground(Pm, verts[v, 0], verts[v, 1], verts[v, 2])
        y0, y1, y2 = to_local(Px, g0, g1, g2)
        if mask & (8 << j):   # an owned peak
            dep, g = _peak(planes, p0, p1, y0, y1, y2)
            if dep > 0.0:
                n0, n1, n2 = dir_ground(Px, planes[g, 0], planes[g, 1], planes[g, 2])
                _row(S, s, dep, g0, g1, g2, n0, n1, n2)
                s += 1
        if not mask & (1 << j):
            continue
        w = tri[t, (j + 1) % 3]
        h0, h1, h2 = to_ground(Pm, verts[w, 0], verts[w, 1], verts[w, 2])
        z0, z1, z2 = to_local(Px, h0, h1, h2)
        e0, e1, e2 = z0 - y0, z1 - y1, z2 - y2
        t0, t1 = _clip(planes, p0, p1, y0, y1, y2, e0, e1, e2)
        if not t0 < t1:
            continue
        best, g = np.inf, -1   # the reference face: least depth over the part inside
        for k in range(p0, p1):
            da = planes[k, 3] - (planes[k, 0] * (y0 + t0 * e0) + planes[k, 1] * (y1 + t0 * e1)
                                 + planes[k, 2] * (y2 + t0 * e2))
            db = planes[k, 3] - (planes[k, 0] * (y0 + t1 * e0) + planes[k, 1] * (y1 + t1 * e1)
                                 + planes[k, 2] * (y2 + t1 * e2))
            if max(da, db) < best:
                best, g = max(da, db), k
        n0, n1, n2 = dir_ground(Px, planes[g, 0], planes[g, 1], planes[g, 2])
        for end in range(2):
            tt = t0 if end == 0 else t1
            if (end == 0 and tt == 0.0 and mask & (64 << j)) or \
                    (end == 1 and tt == 1.0 and mask & (64 << ((j + 1) % 3))):
                continue   # the end is a peak: it pushes on its own
            q0, q1, q2 = y0 + tt * e0, y1 + tt * e1, y2 + tt * e2
            dep = planes[g, 3] - (planes[g, 0] * q0 + planes[g, 1] * q1 + planes[g, 2] * q2)
            if dep > 0.0 and s < S.shape[0]:
                c0, c1, c2 = to_ground(Px, q0, q1, q2)
                _row(S, s, dep, c0, c1, c2, n0, n1, n2)
                s += 1
    return s


@kernel(_nrt=False)
def _core_row(S, s, kind, Px, p, y0, y1, y2, X0, X1, X2):
    """Row s for the mesh point y against a capsule or another curved solid, the point X its nearest point of
    the capsule's core; returns the next row (s unchanged when y is outside)."""
    if kind == CAPSULE:
        d0, d1, d2 = y0 - X0, y1 - X1, y2 - X2
        L = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if not (L < p[0] and L > 0.0):
            return s
        _row(S, s, p[0] - L, y0, y1, y2, d0 / L, d1 / L, d2 / L)
        return s + 1
    dist, n0, n1, n2, _g0, _g1, _g2 = _signed_distance(kind, Px, p, y0, y1, y2)
    if not dist < 0.0:
        return s
    _row(S, s, -dist, y0, y1, y2, n0, n1, n2)
    return s + 1


@kernel(_nrt=False)
def _at_end(a0, a1, a2, b0, b1, b2, X0, X1, X2, h):
    """Whether X lies within 1e-9 of the segment's length of its end a or b (of half length h)."""
    tol = 2e-9 * h
    return (X0 - a0) ** 2 + (X1 - a1) ** 2 + (X2 - a2) ** 2 <= tol * tol or \
        (X0 - b0) ** 2 + (X1 - b1) ** 2 + (X2 - b2) ** 2 <= tol * tol


@kernel(_nrt=False)
def curved_ridge_points(sc, x, Px, Pm, t, S, s):
    """The owned ridges and peaks of triangle t (mesh pose Pm) inside the curved shape x (pose Px): a capsule
    (the nearest points of its core; where that is an end of the core, the end sphere against the triangles
    has it already), a cylinder or an ellipsoid (the deepest point of the ridge, by its signed distance; a
    ridge within LINE_SIN of a cylinder's axis touches the side along a line: a point at each end of the
    part of the ridge beside the side).  Rows s, s + 1, ... of S while it has room; returns the next row."""
    mask = sc[33][t]
    if mask == 0:
        return s
    kind, prm, verts, tri = sc[1], sc[4], sc[7], sc[22]
    kd, p = kind[x], prm[x]
    h = p[1] if kd == CAPSULE else 0.0
    ca0, ca1, ca2 = to_ground(Px, 0.0, 0.0, -h)
    cb0, cb1, cb2 = to_ground(Px, 0.0, 0.0, h)
    for j in range(3):
        if s >= S.shape[0]:
            return s
        v = tri[t, j]
        g0, g1, g2 = to_ground(Pm, verts[v, 0], verts[v, 1], verts[v, 2])
        if mask & (8 << j):   # an owned peak
            X0, X1, X2 = segment_closest(ca0, ca1, ca2, cb0, cb1, cb2, g0, g1, g2)
            if not (kd == CAPSULE and _at_end(ca0, ca1, ca2, cb0, cb1, cb2, X0, X1, X2, h)):
                s = _core_row(S, s, kd, Px, p, g0, g1, g2, X0, X1, X2)
        if not mask & (1 << j) or s >= S.shape[0]:
            continue
        w = tri[t, (j + 1) % 3]
        e0, e1, e2 = to_ground(Pm, verts[w, 0], verts[w, 1], verts[w, 2])
        if kd == CAPSULE:
            Y, X = segments_closest(g0, g1, g2, e0, e1, e2, ca0, ca1, ca2, cb0, cb1, cb2)
            if _at_end(ca0, ca1, ca2, cb0, cb1, cb2, X[0], X[1], X[2], h) or \
                    _at_end(g0, g1, g2, e0, e1, e2, Y[0], Y[1], Y[2], 1.0):
                continue   # an end sphere, or the ridge's end vertex (a peak, or the next ridge's)
            s = _in_cone(sc, Pm, t, j, S, s, _core_row(S, s, kd, Px, p, Y[0], Y[1], Y[2], X[0], X[1], X[2]))
            continue
        if kd == CYLINDER:
            u0, u1, u2 = Px[5], Px[8], Px[11]
            f0, f1, f2 = e0 - g0, e1 - g1, e2 - g2
            fl = np.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
            x0, x1, x2 = u1 * f2 - u2 * f1, u2 * f0 - u0 * f2, u0 * f1 - u1 * f0
            if fl > 0.0 and x0 * x0 + x1 * x1 + x2 * x2 <= (LINE_SIN * fl) ** 2:
                # along the side: the ridge's part within the cylinder's length, a point at each end
                za = (g0 - Px[0]) * u0 + (g1 - Px[1]) * u1 + (g2 - Px[2]) * u2
                zb = (e0 - Px[0]) * u0 + (e1 - Px[1]) * u1 + (e2 - Px[2]) * u2
                if za != zb:
                    ta, tb = (-p[1] - za) / (zb - za), (p[1] - za) / (zb - za)
                    lo, hi = max(min(ta, tb), 0.0), min(max(ta, tb), 1.0)
                    if lo < hi:
                        for tt in (lo, hi):   # each end's depth: the radius less its distance from the axis
                            q0, q1, q2 = g0 + tt * f0, g1 + tt * f1, g2 + tt * f2
                            zq = min(max((q0 - Px[0]) * u0 + (q1 - Px[1]) * u1 + (q2 - Px[2]) * u2, -p[1]), p[1])
                            if s < S.shape[0]:
                                s = _in_cone(sc, Pm, t, j, S, s, _core_row(S, s, CAPSULE, Px, p, q0, q1, q2,
                                                                       Px[0] + zq * u0, Px[1] + zq * u1,
                                                                       Px[2] + zq * u2))
                        continue
        depth, n0, n1, n2, _q0, _q1, _q2, tt = segment_penetration(kd, Px, p, g0, g1, g2, e0, e1, e2, 0.0)
        if depth > 0.0 and 0.0 < tt < 1.0:
            _row(S, s, depth, g0 + tt * (e0 - g0), g1 + tt * (e1 - g1), g2 + tt * (e2 - g2), n0, n1, n2)
            s = _in_cone(sc, Pm, t, j, S, s, s + 1)
    return s


@kernel(_nrt=False)
def _in_cone(sc, Pm, t, j, S, s, s1):
    """s1 when the row s just written (s1 = s + 1; s1 = s: none) has its normal (from the mesh into the shape)
    in the normal cone of the ridge from corner j of triangle t (between the two faces' normals: n . t_i >= 0
    for each face i, t_i in that face, across the edge, away from the face; a curved shape resting on one face
    beside the ridge then pushes on that face alone, through its candidate points), else s."""
    if s1 == s:
        return s
    verts, tri, nbr = sc[7], sc[22], sc[35]
    nb = nbr[t, j]
    if nb < 0:
        return s1
    ia, ib, ic = tri[t, j], tri[t, (j + 1) % 3], tri[t, (j + 2) % 3]
    io = tri[nb, 0]
    if io == ia or io == ib:
        io = tri[nb, 1]
        if io == ia or io == ib:
            io = tri[nb, 2]
    m0, m1, m2 = dir_local(Pm, S[s, 5], S[s, 6], S[s, 7])   # in the mesh's axes, as its vertices
    a0, a1, a2 = verts[ia, 0], verts[ia, 1], verts[ia, 2]
    e0, e1, e2 = verts[ib, 0] - a0, verts[ib, 1] - a1, verts[ib, 2] - a2
    ee = e0 * e0 + e1 * e1 + e2 * e2
    for k in range(2):
        iv = ic if k == 0 else io
        c0, c1, c2 = verts[iv, 0] - a0, verts[iv, 1] - a1, verts[iv, 2] - a2
        f = (c0 * e0 + c1 * e1 + c2 * e2) / ee
        w0, w1, w2 = f * e0 - c0, f * e1 - c1, f * e2 - c2   # away from the far corner, across the edge
        if m0 * w0 + m1 * w1 + m2 * w2 < -1e-9 * np.sqrt(w0 * w0 + w1 * w1 + w2 * w2):
            return s
    return s1
