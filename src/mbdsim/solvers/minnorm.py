"""Minimum-norm Lagrange multipliers of redundant constraint sets, all samples in one compiled call.

The compiled integrator solves for the multipliers of the independent rows only (lambda_r, zero on the
d dependent rows).  Every lambda_ with phi_q^T lambda_ = phi_q,r^T lambda_r gives the same motion; the
reported one is the minimum-norm solution, so that the determinate reaction components are exact
(mbdsim.system.determinacy).  With J_d = C_d J_r (C_d = J_d J_r^T G^-1, G = J_r J_r^T, r x r) the
least-norm solution is w = (I + C_d^T C_d)^-1 lambda_r (Woodbury: a d x d solve), lambda_[rows] = w,
lambda_[dep] = C_d w (the algebra of `compiled_run._full_multipliers`, which calls this).

Per sample: Cholesky factors of G (r x r) and of S = I + C_d C_d^T (d x d), triangular solves, and the
residual |J^T lambda_ - J_r^T lambda_r| checked against 1e-9 of the load; a sample where G is not
positive definite (the rows are dependent at this configuration too: a change point) or the check fails
is flagged `bad` (the caller then uses the SVD pseudo-inverse there).  Plain loops: for the small
matrices of a mechanism (tens of rows) numpy's batched LAPACK calls cost more in overhead than the
arithmetic.  Not a kernel of the integrator (not in _jitcache.KERNEL_SOURCES: it calls no other
compiled module, so numba's own per-file cache check suffices).
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["min_norm_multipliers"]

# reassociation (vectorised dot products) but no finite-math assumption: the isfinite check must stay
_FAST = {"reassoc", "contract", "nsz", "arcp"}


@njit(cache=True, fastmath=_FAST)
def _cholesky(A, n):
    """Lower Cholesky factor of A[:n, :n] in place (upper part untouched); False if not positive definite."""
    for j in range(n):
        s = A[j, j]
        for k in range(j):
            s -= A[j, k] * A[j, k]
        if not s > 0.0:
            return False
        d = np.sqrt(s)
        A[j, j] = d
        for i in range(j + 1, n):
            s = A[i, j]
            for k in range(j):
                s -= A[i, k] * A[j, k]
            A[i, j] = s / d
    return True


@njit(cache=True, fastmath=_FAST)
def _chol_solve(L, n, b):
    """Solve (L L^T) x = b in place (b: length n)."""
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= L[i, k] * b[k]
        b[i] = s / L[i, i]
    for i in range(n - 1, -1, -1):
        s = b[i]
        for k in range(i + 1, n):
            s -= L[k, i] * b[k]
        b[i] = s / L[i, i]


@njit(cache=True, fastmath=_FAST)
def _sample(J, lam, rows, dep, out, G, X, S, col, rhs, load):
    """Minimum-norm multipliers of one sample into out; False when the sample needs the SVD fallback."""
    r, d = len(rows), len(dep)
    nc, nv = J.shape
    for i in range(r):
        for k in range(i + 1):
            s = 0.0
            for c in range(nv):
                s += J[rows[i], c] * J[rows[k], c]
            G[i, k] = s
            G[k, i] = s
    if not _cholesky(G, r):
        return False
    for m in range(d):                      # X[:, m] = G^-1 J_r J_d[m]^T, i.e. C_d[m, :]
        for i in range(r):
            s = 0.0
            for c in range(nv):
                s += J[rows[i], c] * J[dep[m], c]
            col[i] = s
        _chol_solve(G, r, col)
        for i in range(r):
            X[m, i] = col[i]
    for m in range(d):                      # S = I + C_d C_d^T
        for k in range(m + 1):
            s = 1.0 if m == k else 0.0
            for i in range(r):
                s += X[m, i] * X[k, i]
            S[m, k] = s
            S[k, m] = s
        s = 0.0
        for i in range(r):
            s += X[m, i] * lam[rows[i]]
        rhs[m] = s
    if not _cholesky(S, d):
        return False
    _chol_solve(S, d, rhs)                  # z
    for i in range(r):                      # w = lambda_r - C_d^T z
        s = lam[rows[i]]
        for m in range(d):
            s -= X[m, i] * rhs[m]
        out[rows[i]] = s
    for m in range(d):                      # lambda_[dep] = C_d w
        s = 0.0
        for i in range(r):
            s += X[m, i] * out[rows[i]]
        out[dep[m]] = s
    worst, scale = 0.0, 0.0
    for c in range(nv):                     # J^T lambda_ against the constraint load J_r^T lambda_r
        a, b = 0.0, 0.0
        for i in range(r):
            a += J[rows[i], c] * lam[rows[i]]
        for k in range(nc):
            b += J[k, c] * out[k]
        load[c] = a
        scale = max(scale, abs(a))
        worst = max(worst, abs(b - a))
    for k in range(nc):
        if not np.isfinite(out[k]):
            return False
    return worst <= 1e-9 * (scale + 1e-300)


@njit(cache=True, fastmath=_FAST)
def min_norm_multipliers(J, LAM, rows, dep, out, bad):
    """out (N, nc): minimum-norm multipliers from J (N, nc, nv) and LAM (N, nc) (the solved values on
    `rows`, zero elsewhere); bad (N,) set where the sample needs the SVD pseudo-inverse instead."""
    n = J.shape[0]
    r, d, nv = len(rows), len(dep), J.shape[2]
    G, X, S = np.zeros((r, r)), np.zeros((max(d, 1), r)), np.zeros((max(d, 1), max(d, 1)))
    col, rhs, load = np.zeros(r), np.zeros(max(d, 1)), np.zeros(nv)
    for k in range(n):
        bad[k] = not _sample(J[k], LAM[k], rows, dep, out[k], G, X, S, col, rhs, load)
