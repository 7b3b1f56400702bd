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
  face is a line contact, one point at each end of the line (as a cylinder on a face); unless an edge of the
  polyhedron crosses the ridge inside it (`_edge_across`: `crossing`, the closest points inside both edges,
  their common normal L in the ridge's normal cone, the edge the polyhedron's lowest feature along -L) less
  deep along L than the whole ridge lies below any face plane (the separating-axis depth of the ridge as a
  segment; the part inside alone would make a steep wedge's slope the reference) and L not within FACE_COS of
  the reference face's normal (a box lying on the ridge keeps its face): then one point midway between the
  two edges, normal L (a wedge's or a box's edge resting crosswise on a roof's ridge);
* a peak: its depth below the nearest face plane, that face's normal.

Rows of the slot buffer S (solvers.fastmesh layout: used, depth [m], point [m], normal, weight), the point
midway between the feature and the face, the normal -n (from the mesh into the polyhedron, as a triangle's).

`curved_ridge_points` does the same for a capsule, a cylinder or an ellipsoid (whose candidate points against
the triangles' planes miss a ridge under their curved side): per owned ridge the deepest point by the
signed distance from the solid (fastgjk.segment_penetration; a capsule by the nearest points of its core and
the ridge, where that is not an end of the core, whose end sphere has it already), a cylinder lying along a
ridge (within LINE_SIN of its axis) a point at each end of the part of the ridge beside its side, each as
deep as the radius less its distance from the axis, a ridge within LINE_SIN of parallel to a cylinder's flat
end, the middle of its chord nearer the end's plane than the side, a line contact along the chord over the
end disc (`_end_chord`: a point at each end of the chord, so that equal depths act at the chord's middle, as
a uniform line load); per owned peak its depth in the solid.  A ridge point counts
only when its normal lies in the ridge's normal cone (between its two faces' normals, sc[35] naming the
neighbour across each edge): a cylinder resting on one face beside the ridge pushes on that face alone.
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from .fastedges import FACE_COS
from .fastgjk import _signed_distance, segment_penetration
from .fastnarrow import (CAPSULE, CYLINDER, LINE_SIN, dir_ground, dir_local, segment_closest, segments_closest,
                         support_depth, to_ground, to_local)


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
        best, g, full = np.inf, -1, np.inf   # the reference face: least depth over the part inside
        for k in range(p0, p1):
            full = min(full, max(planes[k, 3] - (planes[k, 0] * y0 + planes[k, 1] * y1 + planes[k, 2] * y2),
                                 planes[k, 3] - (planes[k, 0] * z0 + planes[k, 1] * z1 + planes[k, 2] * z2)))
            da = planes[k, 3] - (planes[k, 0] * (y0 + t0 * e0) + planes[k, 1] * (y1 + t0 * e1)
                                 + planes[k, 2] * (y2 + t0 * e2))
            db = planes[k, 3] - (planes[k, 0] * (y0 + t1 * e0) + planes[k, 1] * (y1 + t1 * e1)
                                 + planes[k, 2] * (y2 + t1 * e2))
            if max(da, db) < best:
                best, g = max(da, db), k
        n0, n1, n2 = dir_ground(Px, planes[g, 0], planes[g, 1], planes[g, 2])
        D, X0, X1, X2, L0, L1, L2 = _edge_across(sc, x, Px, Pm, t, j, g0, g1, g2, h0, h1, h2)
        if D < full and -(L0 * n0 + L1 * n1 + L2 * n2) <= FACE_COS:
            _row(S, s, D, X0, X1, X2, -L0, -L1, -L2)   # an edge of x across the ridge: the common normal L
            s += 1
            continue
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
        if kd == CYLINDER:
            s1 = _end_chord(sc, Px, p, Pm, t, j, mask, g0, g1, g2, e0, e1, e2, S, s)
            if s1 >= 0:
                s = s1
                continue
        depth, n0, n1, n2, _q0, _q1, _q2, tt = segment_penetration(kd, Px, p, g0, g1, g2, e0, e1, e2, 0.0)
        if depth > 0.0 and 0.0 < tt < 1.0:
            _row(S, s, depth, g0 + tt * (e0 - g0), g1 + tt * (e1 - g1), g2 + tt * (e2 - g2), n0, n1, n2)
            s = _in_cone(sc, Pm, t, j, S, s, s + 1)
    return s


@kernel(_nrt=False)
def _end_chord(sc, Px, p, Pm, t, j, mask, g0, g1, g2, e0, e1, e2, S, s):
    """The ridge g-e (ground; corner j of triangle t, mesh pose Pm) across a flat end of the cylinder (pose Px,
    p = r, h), within LINE_SIN of parallel to it, its line's point nearest the axis (the chord's middle) nearer
    that end's plane than the side: a line contact along the chord, the ridge's part over the end disc, a point
    at each end of the chord that is not a peak (peaks push on their own), each as deep as it lies inside the
    end's plane, the end's normal; equal depths put the resultant at the chord's middle, as a uniform line
    load does.  Rows from s while S has room; returns the next row, or -1 when the ridge is no such chord
    (decided by the geometry of the line, not by the deepest point, which is anywhere along a level chord)."""
    a0, a1, a2 = to_local(Px, g0, g1, g2)
    b0, b1, b2 = to_local(Px, e0, e1, e2)
    f0, f1, f2 = b0 - a0, b1 - a1, b2 - a2
    A_, B_, C_ = f0 * f0 + f1 * f1, a0 * f0 + a1 * f1, a0 * a0 + a1 * a1 - p[0] * p[0]
    if not (A_ > 0.0 and f2 * f2 <= LINE_SIN * LINE_SIN * (A_ + f2 * f2)):
        return -1
    tm = -B_ / A_   # the chord's middle: off the axis by cm, at height zm
    zm = a2 + tm * f2
    cm = np.sqrt(max(C_ + p[0] * p[0] - B_ * B_ / A_, 0.0))
    if not (cm < p[0] and abs(zm) < p[1] and p[1] - abs(zm) < p[0] - cm):
        return -1
    sg = 1.0 if zm > 0.0 else -1.0
    disc = B_ * B_ - A_ * C_
    lo, hi = max((-B_ - np.sqrt(disc)) / A_, 0.0), min((-B_ + np.sqrt(disc)) / A_, 1.0)
    if not lo < hi:
        return s
    u0, u1, u2 = sg * Px[5], sg * Px[8], sg * Px[11]   # the end's outward normal
    for end in range(2):
        tt = lo if end == 0 else hi
        if (tt == 0.0 and mask & (64 << j)) or (tt == 1.0 and mask & (64 << ((j + 1) % 3))) or s >= S.shape[0]:
            continue
        dep = p[1] - sg * (a2 + tt * f2)
        if dep > 0.0:
            _row(S, s, dep, g0 + tt * (e0 - g0), g1 + tt * (e1 - g1), g2 + tt * (e2 - g2), u0, u1, u2)
            s = _in_cone(sc, Pm, t, j, S, s, s + 1)
    return s


@kernel(_nrt=False)
def in_cone(sc, Pm, t, j, m0, m1, m2):
    """Whether the ground direction m (out of the mesh, pose Pm) lies in the normal cone of the ridge from corner j
    of triangle t (between its two faces' normals: m . w_i >= 0 for each face i, w_i in that face, across the edge,
    away from the face's far corner); an edge without a neighbour (a mesh's border) takes any direction."""
    verts, tri, nbr = sc[7], sc[22], sc[35]
    nb = nbr[t, j]
    if nb < 0:
        return True
    ia, ib, ic = tri[t, j], tri[t, (j + 1) % 3], tri[t, (j + 2) % 3]
    io = tri[nb, 0]
    if io == ia or io == ib:
        io = tri[nb, 1]
        if io == ia or io == ib:
            io = tri[nb, 2]
    m0, m1, m2 = dir_local(Pm, m0, m1, m2)   # in the mesh's axes, as its vertices
    a0, a1, a2 = verts[ia, 0], verts[ia, 1], verts[ia, 2]
    e0, e1, e2 = verts[ib, 0] - a0, verts[ib, 1] - a1, verts[ib, 2] - a2
    ee = e0 * e0 + e1 * e1 + e2 * e2
    for k in range(2):
        iv = ic if k == 0 else io
        c0, c1, c2 = verts[iv, 0] - a0, verts[iv, 1] - a1, verts[iv, 2] - a2
        f = (c0 * e0 + c1 * e1 + c2 * e2) / ee
        w0, w1, w2 = f * e0 - c0, f * e1 - c1, f * e2 - c2   # away from the far corner, across the edge
        if m0 * w0 + m1 * w1 + m2 * w2 < -1e-9 * np.sqrt(w0 * w0 + w1 * w1 + w2 * w2):
            return False
    return True


@kernel(_nrt=False)
def _in_cone(sc, Pm, t, j, S, s, s1):
    """s1 when the row s just written (s1 = s + 1; s1 = s: none) has its normal (from the mesh into the shape)
    in the normal cone of the ridge from corner j of triangle t (`in_cone`: a curved shape resting on one face
    beside the ridge then pushes on that face alone, through its candidate points), else s."""
    if s1 == s or in_cone(sc, Pm, t, j, S[s, 5], S[s, 6], S[s, 7]):
        return s1
    return s


@kernel(_nrt=False)
def crossing(a0, a1, a2, b0, b1, b2, c0, c1, c2, e0, e1, e2):
    """Two segments a-b and c-e that cross: (ok, X on a-b, Y on c-e [m], L): X, Y the closest points of the two
    lines, L the unit common normal (b - a) x (e - c) normalised; ok false when the segments are within 1e-6 of
    parallel or X or Y is not inside its segment (strictly: an end is a vertex's contact, not an edge's)."""
    d0, d1, d2 = b0 - a0, b1 - a1, b2 - a2
    f0, f1, f2 = e0 - c0, e1 - c1, e2 - c2
    L0, L1, L2 = d1 * f2 - d2 * f1, d2 * f0 - d0 * f2, d0 * f1 - d1 * f0
    A_, E_ = d0 * d0 + d1 * d1 + d2 * d2, f0 * f0 + f1 * f1 + f2 * f2
    nrm = np.sqrt(L0 * L0 + L1 * L1 + L2 * L2)
    if not nrm > 1e-6 * np.sqrt(A_ * E_):
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    r0, r1, r2 = a0 - c0, a1 - c1, a2 - c2
    B_, C_, F_ = d0 * f0 + d1 * f1 + d2 * f2, d0 * r0 + d1 * r1 + d2 * r2, f0 * r0 + f1 * r1 + f2 * r2
    u = (B_ * F_ - C_ * E_) / (nrm * nrm)   # A E - B^2 = |d x f|^2
    v = (B_ * u + F_) / E_
    if not (0.0 < u < 1.0 and 0.0 < v < 1.0):
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    return True, a0 + u * d0, a1 + u * d1, a2 + u * d2, c0 + v * f0, c1 + v * f1, c2 + v * f2, L0 / nrm, \
        L1 / nrm, L2 / nrm


@kernel(_nrt=False)
def cone_crossing(sc, Pm, t, j, a0, a1, a2, b0, b1, b2, c0, c1, c2, e0, e1, e2):
    """`crossing` of the ridge a-b (corner j of triangle t of a mesh of pose Pm) with the segment c-e, its common
    normal L turned into the ridge's normal cone (`in_cone`); ok False when they do not cross or neither L nor
    -L lies in the cone."""
    ok, X0, X1, X2, Y0, Y1, Y2, L0, L1, L2 = crossing(a0, a1, a2, b0, b1, b2, c0, c1, c2, e0, e1, e2)
    if ok and not in_cone(sc, Pm, t, j, L0, L1, L2):
        L0, L1, L2 = -L0, -L1, -L2
        ok = in_cone(sc, Pm, t, j, L0, L1, L2)
    return ok, X0, X1, X2, Y0, Y1, Y2, L0, L1, L2


@kernel(_nrt=False)
def _edge_across(sc, x, Px, Pm, t, j, g0, g1, g2, h0, h1, h2):
    """An edge of the box or hull x (pose Px) crossing the ridge g-h (ground; corner j of triangle t, mesh pose
    Pm) inside x: (D [m], X (the ridge's point) [m], L), the least depth D = L . X - min over x's vertices of
    L . v along the edges' common normal L (out of the mesh, in the ridge's normal cone, and -L in x's: the edge
    is x's lowest feature along L at both its ends); D = inf when no edge crosses."""
    verts, sv, rad, eran, edges = sc[7], sc[6], sc[5], sc[31], sc[32]
    tol = 1e-9 * rad[x]
    best, X0, X1, X2, L0, L1, L2 = np.inf, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0
    for k in range(eran[x, 0], eran[x, 1]):
        a0, a1, a2 = to_ground(Px, verts[edges[k, 0], 0], verts[edges[k, 0], 1], verts[edges[k, 0], 2])
        b0, b1, b2 = to_ground(Px, verts[edges[k, 1], 0], verts[edges[k, 1], 1], verts[edges[k, 1], 2])
        ok, y0, y1, y2, _z0, _z1, _z2, l0, l1, l2 = cone_crossing(sc, Pm, t, j, g0, g1, g2, h0, h1, h2, a0, a1, a2,
                                                                   b0, b1, b2)
        if not ok:
            continue
        lo = -support_depth(sc[1][x], Px, sc[4][x], verts, sv[x, 0], sv[x, 1] - sv[x, 0], 0.0, 0.0, 0.0, l0, l1, l2)
        if l0 * a0 + l1 * a1 + l2 * a2 > lo + tol or l0 * b0 + l1 * b1 + l2 * b2 > lo + tol:
            continue   # not x's supporting edge along -L
        D = l0 * y0 + l1 * y1 + l2 * y2 - lo
        if D > 0.0 and D < best:
            best, X0, X1, X2, L0, L1, L2 = D, y0, y1, y2, l0, l1, l2
    return best, X0, X1, X2, L0, L1, L2
