"""Zero-degree-of-freedom models: the augmented equations solved through one LU of the square Jacobian.

When the independent rows in force fix every velocity (nv rows for nv velocity variables: a driven
mechanism), their Jacobian J (nv x nv) is square and nonsingular, and the augmented equations

    M vd + J^T lambda_ = F,    J vd = c

decouple: vd = J^-1 c and lambda_ = J^-T (F - M vd), both from one LU factorisation of J (partial
pivoting). For the small mechanisms this is chosen for (at most `system.compiled.SQUARE_MAX` velocity
variables) it costs less than the tree elimination of `kkt_tree` with its loop Schur complement
(slider-crank, nv = 18: 1.0-1.5 us against 3.4 us per factorisation). The Newton steps and velocity
projections of `fastdyn` solve the same system with F = 0, where the unique solution is the
mass-weighted minimum-norm one as well.

Near a change point (a driven parallelogram with its links collinear) J loses rank; the tree
factorisation decides there which loop rows drop out (`kkt_tree.pivoted_chol`), so `square_factor`
declines (returns False) when a pivot falls below SQUARE_PIVOT of the largest entry and the caller
factors the tree instead.

With redundant rows (a planar loop of 3D revolutes) the same LU gives the minimum-norm multipliers of
all rows at little cost (`square_min_norm`: d transposed solves and a d x d Cholesky, d dependent
rows), so a kinematic sweep stores them directly instead of a separate pass over the samples
(`solvers.minnorm`). Velocity slots as `fastdyn`: x6 (nf, 6) per frame [m/s^2 in ground axes, rad/s^2
in body axes]; J's columns are the velocity variables v (frame f's slot k at vadr[f] + k; a particle
has its three translational slots only).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)

SQUARE_PIVOT = 1e-6    # a pivot below this fraction of J's largest entry: near-singular, tree instead


@njit(cache=True, _nrt=False)
def square_factor(Jc, bi, bj, vadr, rigid, active, A, piv):
    """LU of the square Jacobian of the rows `active` (compact rows Jc (nc, 2, 6) of
    `system.kernels.rows_kernel`) into A (nv, nv) with the row swaps in piv[:nv]; piv[nv] = 1 when A
    holds a valid factorisation, 0 (and False returned) when a pivot is below SQUARE_PIVOT of the
    largest entry."""
    n = active.shape[0]
    piv[n] = 0
    for i in range(n):
        for j in range(n):
            A[i, j] = 0.0
    for a in range(n):
        row = active[a]
        for side in range(2):
            f = bi[row] if side == 0 else bj[row]
            if f != 0:
                nk = 6 if rigid[f] else 3
                for k in range(nk):
                    A[a, vadr[f] + k] += Jc[row, side, k]
    scale = 0.0
    for i in range(n):
        for j in range(n):
            scale = max(scale, abs(A[i, j]))
    for k in range(n):
        p = k
        for i in range(k + 1, n):
            if abs(A[i, k]) > abs(A[p, k]):
                p = i
        piv[k] = p
        if not abs(A[p, k]) > SQUARE_PIVOT * scale:
            return False
        if p != k:
            for j in range(n):
                A[k, j], A[p, j] = A[p, j], A[k, j]
        r = 1.0 / A[k, k]
        for i in range(k + 1, n):
            A[i, k] *= r
            m = A[i, k]
            if m != 0.0:
                for j in range(k + 1, n):
                    A[i, j] -= m * A[k, j]
    piv[n] = 1
    return True


@njit(cache=True, _nrt=False)
def _transposed_solve(A, piv, n, x):
    """x <- A^-T x with the LU of `square_factor` (U^T w = x, L^T z = w, then the row swaps undone)."""
    for i in range(n):
        s = x[i]
        for k in range(i):
            s -= A[k, i] * x[k]
        x[i] = s / A[i, i]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, n):
            s -= A[k, i] * x[k]
        x[i] = s
    for k in range(n - 1, -1, -1):
        p = piv[k]
        if p != k:
            x[k], x[p] = x[p], x[k]


@njit(cache=True, _nrt=False)
def square_solve(active, vadr, rigid, M6, A, piv, F, c_rows, x6, lam, x):
    """With the LU of `square_factor`: x6 = J^-1 c (c = c_rows at the active rows) per frame slot, and
    lam[active] = J^-T (F - M x6) (the other entries of lam untouched); F (nf, 6) loads per frame slot,
    x (nv) scratch."""
    n = active.shape[0]
    for a in range(n):
        x[a] = c_rows[active[a]]
    for k in range(n):                      # P c
        p = piv[k]
        if p != k:
            x[k], x[p] = x[p], x[k]
    for i in range(n):                      # L y = P c (unit lower)
        s = x[i]
        for k in range(i):
            s -= A[i, k] * x[k]
        x[i] = s
    for i in range(n - 1, -1, -1):          # U vd = y
        s = x[i]
        for k in range(i + 1, n):
            s -= A[i, k] * x[k]
        x[i] = s / A[i, i]
    for k in range(6):
        x6[0, k] = 0.0
    for f in range(1, x6.shape[0]):
        nk = 6 if rigid[f] else 3
        for k in range(6):
            x6[f, k] = x[vadr[f] + k] if k < nk else 0.0
    for f in range(1, x6.shape[0]):         # r = F - M vd, in the v layout
        nk = 6 if rigid[f] else 3
        for i in range(nk):
            s = F[f, i]
            for j in range(6):
                s -= M6[f, i, j] * x6[f, j]
            x[vadr[f] + i] = s
    _transposed_solve(A, piv, n, x)         # lambda_ = J^-T r
    for a in range(n):
        lam[active[a]] = x[a]


@njit(cache=True, _nrt=False)
def square_min_norm(Jc, bi, bj, vadr, rigid, active, A, piv, lam, C, S, y):
    """The multipliers lam (nc) solved on the rows `active` (zero elsewhere), with the LU of
    `square_factor` and the compact rows Jc at the same positions, replaced by the minimum-norm
    multipliers of all rows with the same constraint load (J^T lam = J_r^T lam_r), as
    `solvers.minnorm` computes them: with C = J_d J_r^-1 (d x nv, d the rows not in `active`) and
    S = I + C C^T, lam_d = S^-1 C lam_r and lam_r - C^T lam_d on the active rows. C (>= d, nv),
    S (>= d, >= d), y (>= max(d, nv)) scratch. False (lam untouched) when no valid LU is in A."""
    n, nc = active.shape[0], Jc.shape[0]
    d = nc - n
    if d == 0:
        return True
    if piv[n] != 1:
        return False
    m, a = 0, 0
    for row in range(nc):
        if a < n and active[a] == row:
            a += 1
            continue
        for i in range(n):
            y[i] = 0.0
        for side in range(2):
            f = bi[row] if side == 0 else bj[row]
            if f != 0:
                nk = 6 if rigid[f] else 3
                for k in range(nk):
                    y[vadr[f] + k] += Jc[row, side, k]
        _transposed_solve(A, piv, n, y)          # row m of C: J_d[m] J_r^-1
        for i in range(n):
            C[m, i] = y[i]
        m += 1
    for p in range(d):                           # S = I + C C^T (lower Cholesky in place), y = C lam_r
        for q in range(p + 1):
            s = 1.0 if p == q else 0.0
            for i in range(n):
                s += C[p, i] * C[q, i]
            S[p, q] = s
        s = 0.0
        for i in range(n):
            s += C[p, i] * lam[active[i]]
        y[p] = s
    for j in range(d):
        s = S[j, j]
        for k in range(j):
            s -= S[j, k] * S[j, k]
        S[j, j] = np.sqrt(s)                     # >= 1: S is I plus a positive semi-definite matrix
        for i in range(j + 1, d):
            s = S[i, j]
            for k in range(j):
                s -= S[i, k] * S[j, k]
            S[i, j] = s / S[j, j]
    for i in range(d):                           # S lam_d = C lam_r
        s = y[i]
        for k in range(i):
            s -= S[i, k] * y[k]
        y[i] = s / S[i, i]
    for i in range(d - 1, -1, -1):
        s = y[i]
        for k in range(i + 1, d):
            s -= S[k, i] * y[k]
        y[i] = s / S[i, i]
    for i in range(n):                           # lam_r - C^T lam_d
        s = 0.0
        for p in range(d):
            s += C[p, i] * y[p]
        lam[active[i]] -= s
    m, a = 0, 0
    for row in range(nc):
        if a < n and active[a] == row:
            a += 1
            continue
        lam[row] = y[m]
        m += 1
    return True
