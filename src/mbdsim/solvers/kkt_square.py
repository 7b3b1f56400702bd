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

from numba import njit

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import entry, kernel  # noqa: F401  (njit without the wrappers that dominate compilation; issue 32)
from .kkt_tree import lu_factor, lu_solve, lu_solve_transposed
from .minnorm import _chol_solve, _cholesky

SQUARE_PIVOT = 1e-6    # a pivot below this fraction of J's largest entry: near-singular, tree instead


@kernel(_nrt=False, inline="always")
def _add_row(Jc, bi, bj, vadr, rigid, row, X, i):
    """Add the compact row `row` of Jc (nc, 2, 6) into row i of X, dense over the velocity variables v
    (frame f's slot k at vadr[f] + k; a particle's translational slots only). Inlined where it is called,
    with X and i rather than a row view: as a call, or on a view, it made the LU's scatter twice as slow."""
    for side in range(2):
        f = bi[row] if side == 0 else bj[row]
        if f != 0:
            nk = 6 if rigid[f] else 3
            for k in range(nk):
                X[i, vadr[f] + k] += Jc[row, side, k]


@kernel(_nrt=False)
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
        _add_row(Jc, bi, bj, vadr, rigid, active[a], A, a)
    if not lu_factor(A, n, piv, SQUARE_PIVOT):
        return False
    piv[n] = 1
    return True


@kernel(_nrt=False)
def square_solve(active, vadr, rigid, M6, A, piv, F, c_rows, x6, lam, x):
    """With the LU of `square_factor`: x6 = J^-1 c (c = c_rows at the active rows) per frame slot, and
    lam[active] = J^-T (F - M x6) (the other entries of lam untouched); F (nf, 6) loads per frame slot,
    x (nv) scratch."""
    n = active.shape[0]
    for a in range(n):
        x[a] = c_rows[active[a]]
    lu_solve(A, piv, n, x)                  # vd = J^-1 c
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
    lu_solve_transposed(A, piv, n, x)       # lambda_ = J^-T r
    for a in range(n):
        lam[active[a]] = x[a]


@kernel(_nrt=False)
def square_min_norm(Jc, bi, bj, vadr, rigid, active, A, piv, lam, C, S, y):
    """The multipliers lam (nc) solved on the rows `active` (zero elsewhere), with the LU of
    `square_factor` and the compact rows Jc at the same positions, replaced by the minimum-norm
    multipliers of all rows with the same constraint load (J^T lam = J_r^T lam_r), as
    `solvers.minnorm` computes them: with C = J_d J_r^-1 (d x nv, d the rows not in `active`) and
    S = I + C C^T, lam_d = S^-1 C lam_r and lam_r - C^T lam_d on the active rows. C (>= d, nv),
    S (>= d, >= d), y (>= max(d, nv)) scratch. False (lam untouched) when no valid LU is in A or S is
    not positive definite (rows not finite)."""
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
            C[m, i] = 0.0
        _add_row(Jc, bi, bj, vadr, rigid, row, C, m)
        for i in range(n):
            y[i] = C[m, i]
        lu_solve_transposed(A, piv, n, y)        # row m of C: J_d[m] J_r^-1
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
    if not _cholesky(S, d):                      # S lam_d = C lam_r (S: I plus a semi-definite matrix)
        return False
    _chol_solve(S, d, y)
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
