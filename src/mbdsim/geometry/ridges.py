"""The ridges and peaks of a triangle mesh (issue 30), marked per triangle for solvers.fastridge.

A ridge is an edge shared by exactly two faces that meet at a convex angle (the far corner of either face
below the other's plane) that is not flat; a peak is a vertex all of whose neighbours lie on or below the
planes of all its faces, some strictly below.  Each is owned by one of its triangles (the first in the
given order), so that a walk over the triangles meets each once.  Boundary edges of an open mesh are not
ridges.
"""
from __future__ import annotations

import numpy as np


def ridge_masks(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Per triangle of faces (m, 3: rows of vertices [m]) the bits of fastridge: 1 << e the triangle owns
    the ridge from its corner e to corner e + 1 (mod 3), 8 << j it owns the peak at corner j, 64 << j its
    corner j is a peak."""
    v = np.asarray(vertices, float)
    f = np.asarray(faces, np.int64).reshape(-1, 3)
    m = len(f)
    mask = np.zeros(m, np.int64)
    if m == 0:
        return mask
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    tol = 1e-9 * max(float(np.ptp(v, axis=0).max()), 1e-300)
    # directed edges (face, corner e): vertices f[e], f[e + 1]; the opposite corner f[e + 2]
    fi = np.repeat(np.arange(m), 3)
    ci = np.tile(np.arange(3), m)
    a, b, o = f[fi, ci], f[fi, (ci + 1) % 3], f[fi, (ci + 2) % 3]
    key = np.minimum(a, b) * len(v) + np.maximum(a, b)
    srt = np.argsort(key, kind="stable")
    ks = key[srt]
    first = np.r_[True, ks[1:] != ks[:-1]]
    start = np.flatnonzero(first)
    count = np.diff(np.r_[start, len(ks)])
    two = start[count == 2]
    e1, e2 = srt[two], srt[two + 1]   # the two directed edges of each interior edge, e1 of the earlier face
    f1, f2 = fi[e1], fi[e2]
    below = np.einsum("ij,ij->i", n[f1], v[o[e2]] - v[a[e1]]) < -tol
    sharp = np.einsum("ij,ij->i", n[f1], n[f2]) < 1.0 - 1e-9
    r = e1[below & sharp]
    np.bitwise_or.at(mask, fi[r], 1 << ci[r])
    # peaks: every neighbour (over the edges) against every face plane at the vertex
    nb_v = np.r_[a, b]
    nb_u = np.r_[b, a]
    inc_v, inc_f = f.ravel(), np.repeat(np.arange(m), 3)
    so = np.argsort(nb_v, kind="stable")
    nb_v, nb_u = nb_v[so], nb_u[so]
    nb_start = np.searchsorted(nb_v, np.arange(len(v)))
    nb_cnt = np.searchsorted(nb_v, np.arange(len(v)), side="right") - nb_start
    rep = nb_cnt[inc_v]
    which = np.repeat(np.arange(len(inc_v)), rep)
    offs = np.arange(rep.sum()) - np.repeat(np.cumsum(rep) - rep, rep)
    u = nb_u[nb_start[inc_v[which]] + offs]
    vv = inc_v[which]
    h = np.einsum("ij,ij->i", n[inc_f[which]], v[u] - v[vv])
    hi = np.full(len(v), -np.inf)
    lo = np.full(len(v), np.inf)
    np.maximum.at(hi, vv, h)
    np.minimum.at(lo, vv, h)
    peak = (hi <= tol) & (lo < -tol)
    corner_peak = peak[f]   # (m, 3)
    for j in range(3):
        mask[corner_peak[:, j]] |= 64 << j
    pv = np.flatnonzero(peak[inc_v])
    _, own = np.unique(inc_v[pv], return_index=True)   # the first triangle at each peak
    own = pv[own]
    np.bitwise_or.at(mask, own // 3, 8 << (own % 3))
    return mask


def ridge_neighbours(faces: np.ndarray) -> np.ndarray:
    """Per triangle of faces (m, 3) and corner e, the triangle across its edge from corner e to e + 1 (mod 3)
    (an edge shared by exactly two triangles), else -1 (solvers.fastridge's normal-cone test)."""
    f = np.asarray(faces, np.int64).reshape(-1, 3)
    m = len(f)
    out = np.full((m, 3), -1, np.int64)
    if m == 0:
        return out
    nv = int(f.max()) + 1
    fi = np.repeat(np.arange(m), 3)
    ci = np.tile(np.arange(3), m)
    a, b = f[fi, ci], f[fi, (ci + 1) % 3]
    key = np.minimum(a, b) * nv + np.maximum(a, b)
    srt = np.argsort(key, kind="stable")
    ks = key[srt]
    start = np.flatnonzero(np.r_[True, ks[1:] != ks[:-1]])
    count = np.diff(np.r_[start, len(ks)])
    two = start[count == 2]
    e1, e2 = srt[two], srt[two + 1]
    out[fi[e1], ci[e1]] = fi[e2]
    out[fi[e2], ci[e2]] = fi[e1]
    return out
