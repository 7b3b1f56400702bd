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
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from .fastnarrow import dir_ground, to_ground, to_local


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
