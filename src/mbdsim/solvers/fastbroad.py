"""Compiled broad phase of shape contact (issue 30): world bounding boxes and sweep and prune.

`boxes(sc, r, A)` writes every packed shape's pose (sc[17], the 12-tuple of solvers.fastnarrow.pose as
a row) and its ground-axes bounding box (sc[18]: lower corner [m], upper corner [m]): exact extents of
spheres, boxes, cylinders, capsules and ellipsoids, the box of the local bounding box (sc[14]) for hulls
and meshes; a plane is the half-space behind it, unbounded but along its normal when that is a ground
axis.  `sweep` sorts the shapes along the axis where their centres spread most (insertion sort of the
order kept from the last call, sc[19]: almost sorted, so linear) and walks the sorted list, a shape
against the following ones until their lower bound passes its upper bound; the pairs of overlapping boxes
that the contact elements name (sc[15], sc[16]: per shape, its partners sorted, with the pair index) go
to the narrow phase.  Cost: the number of shapes plus the number of overlaps along the sweep axis, not
the number of pairs.  sc[20] counts (0) the pairs passed to the narrow phase in the last call, (1) in
all calls, (2) the calls.
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from .fastnarrow import BOX, CAPSULE, CYLINDER, ELLIPSOID, PLANE, SPHERE, pose


@kernel(_nrt=False)
def boxes(sc, r, A):
    """Poses (sc[17]) and ground bounding boxes (sc[18]) of every shape at the frames r, A."""
    sh_f, kind, sh_c, sh_R, prm, lb, PS, BB = sc[0], sc[1], sc[2], sc[3], sc[4], sc[14], sc[17], sc[18]
    for s in range(kind.shape[0]):
        P = pose(r, A, sh_f[s], sh_c[s], sh_R[s])
        for k in range(12):
            PS[s, k] = P[k]
        kd, p = kind[s], prm[s]
        for k in range(3):
            g0, g1, g2 = P[3 + 3 * k], P[4 + 3 * k], P[5 + 3 * k]   # row k of G
            if kd == SPHERE:
                e = p[0]
            elif kd == BOX:
                e = abs(g0) * p[0] + abs(g1) * p[1] + abs(g2) * p[2]
            elif kd == CYLINDER:
                e = abs(g2) * p[1] + p[0] * np.sqrt(max(0.0, 1.0 - g2 * g2))
            elif kd == CAPSULE:
                e = abs(g2) * p[1] + p[0]
            elif kd == ELLIPSOID:
                e = np.sqrt((g0 * p[0]) ** 2 + (g1 * p[1]) ** 2 + (g2 * p[2]) ** 2)
            elif kd == PLANE:
                lo, hi = -np.inf, np.inf
                if abs(g2) > 1.0 - 1e-12:   # the normal along this ground axis: the solid is behind it
                    if g2 > 0.0:
                        hi = P[k]
                    else:
                        lo = P[k]
                BB[s, k], BB[s, 3 + k] = lo, hi
                continue
            else:
                e = abs(g0) * lb[s, 3] + abs(g1) * lb[s, 4] + abs(g2) * lb[s, 5]
                c = P[k] + g0 * lb[s, 0] + g1 * lb[s, 1] + g2 * lb[s, 2]
                BB[s, k], BB[s, 3 + k] = c - e, c + e
                continue
            BB[s, k], BB[s, 3 + k] = P[k] - e, P[k] + e


@kernel(_nrt=False)
def sweep_axis(BB):
    """The ground axis along which the finite boxes' centres spread most."""
    best, ax = -1.0, 0
    for k in range(3):
        n, s, s2 = 0, 0.0, 0.0
        for i in range(BB.shape[0]):
            c = 0.5 * (BB[i, k] + BB[i, 3 + k])
            if np.isfinite(c):
                n += 1
                s += c
                s2 += c * c
        v = s2 / n - (s / n) ** 2 if n > 0 else 0.0
        if v > best:
            best, ax = v, k
    return ax


@kernel(_nrt=False)
def sort_order(order, BB, ax):
    """Insertion sort of row ax of `order` by the boxes' lower bounds along ax (linear on an almost sorted
    list)."""
    for i in range(1, order.shape[1]):
        s = order[ax, i]
        key = BB[s, ax]
        j = i - 1
        while j >= 0 and BB[order[ax, j], ax] > key:
            order[ax, j + 1] = order[ax, j]
            j -= 1
        order[ax, j + 1] = s


@kernel(_nrt=False)
def partner(ptr, adj, i, j):
    """First row of shape i's partner list (sorted) naming shape j, or -1."""
    lo, hi = ptr[i], ptr[i + 1]
    while lo < hi:
        mid = (lo + hi) // 2
        if adj[mid, 0] < j:
            lo = mid + 1
        else:
            hi = mid
    return lo if lo < ptr[i + 1] and adj[lo, 0] == j else -1
