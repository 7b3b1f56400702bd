"""Constraint rows packed for the compiled kernels (system.kernels), vectorised per row group: one numpy
assignment per group instead of one per row.  `assemble_system` keeps the result in
sys.derived["packed"], where system.equations and compile_system look for it.
"""
from __future__ import annotations

import numpy as np


def pack_rows(sys):
    """(kind, bi, bj, V, par, driver index, driver functions) of every row: kinds 0-2 spherical x/y/z
    (point-on-curve rows too, V[row, 0] = 0 for the caller's curve point), 3 dot1, 4 dot2, 5 angle,
    6 slide, 7 screw (par = lead / 2 pi [m/rad]), 8 constant velocity; V (nc, 6, 3) the rows' vectors in
    body axes (`kernels.row_terms`); rows of kinds the kernel does not evaluate (couplers) stay
    ground-ground spherical rows of zeros, driver index -1."""
    from .constraints.screw import lead_per_radian
    from .kernels import KIND
    nc = sys.nc
    kind = np.zeros(nc, np.int64)
    bi = np.zeros(nc, np.int64)
    bj = np.zeros(nc, np.int64)
    V = np.zeros((nc, 6, 3))
    par = np.zeros(nc)
    drv = -np.ones(nc, np.int64)
    fns = []
    for g in sys.groups:
        if g.kind not in KIND and g.kind not in ("sph", "curve"):
            continue
        n = len(g.bi)
        if not n:
            continue
        first = 1 if g.kind == "curve" else 0      # curve: vecs[0] is the marker point s_j
        r0 = np.asarray(g.row_adr, dtype=np.int64)
        if g.kind in ("sph", "curve"):             # three rows each: x, y, z
            rows = (r0[:, None] + np.arange(3)).ravel()
            kind[rows] = np.tile(np.arange(3), n)
            bi[rows], bj[rows] = np.repeat(g.bi, 3), np.repeat(g.bj, 3)
            for m, vec in enumerate(g.vecs):
                V[rows, first + m] = np.repeat(vec, 3, axis=0)
        else:
            kind[r0] = KIND[g.kind]
            bi[r0], bj[r0] = g.bi, g.bj
            for m, vec in enumerate(g.vecs):
                V[r0, m] = vec
            if g.kind == "screw":
                par[r0] = lead_per_radian(g)
            if g.kind in ("angle", "slide"):
                drv[r0] = len(fns) + np.arange(n)
                fns.extend(g.fns)
    return kind, bi, bj, V, par, drv, fns
