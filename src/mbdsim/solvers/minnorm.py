"""Minimum-norm Lagrange multipliers of redundant constraint sets, all samples in one compiled call.

The compiled integrator solves for the multipliers of the independent rows only (lambda_r, zero on the
d dependent rows).  Every lambda_ with phi_q^T lambda_ = phi_q,r^T lambda_r gives the same motion; the
reported one is the minimum-norm solution, so that the determinate reaction components are exact
(mbdsim.system.determinacy).  With J_d = C_d J_r (C_d = J_d J_r^T G^-1, G = J_r J_r^T, r x r) the
least-norm solution is w = (I + C_d^T C_d)^-1 lambda_r (Woodbury: a d x d solve), lambda_[rows] = w,
lambda_[dep] = C_d w (called by `compiled_run._full_multipliers`).

Per sample: Cholesky factors of G (r x r) and of S = I + C_d C_d^T (d x d), triangular solves, and the
residual |J^T lambda_ - J_r^T lambda_r| checked against 1e-9 of the load; a sample where G is not
positive definite (the rows are dependent at this configuration too: a change point) or the check fails
is flagged `bad` (the caller then uses the SVD pseudo-inverse there).  The products J_r J_r^T,
J_r J_d^T and J^T lambda_ are summed column by column over the rows that have an entry in that column
(in any sample of the call): a joint's rows touch the 6 columns of two bodies, so most of the nv-long
dot products of a dense Jacobian are zeros; only exact zeros are left out (same sums, same order), and
the saving grows with the number of bodies.  Plain loops: for the small matrices of a mechanism (tens
of rows) numpy's batched LAPACK calls cost more in overhead than the arithmetic.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .._jit import entry, kernel  # noqa: F401  (njit without the wrappers that dominate compilation; issue 32)

__all__ = ["min_norm_multipliers"]

# reassociation (vectorised dot products) but no finite-math assumption: the isfinite check must stay
_FAST = {"reassoc", "contract", "nsz", "arcp"}


@kernel(fastmath=_FAST)
def _cholesky(A, n):
    """Lower Cholesky factor of A[:n, :n] in place (upper part untouched); False if not positive definite
    to 1e-12 of the pivot's diagonal (for G = J_r J_r^T: rows dependent to about 1e-6 in the relative
    singular values of J_r, which the SVD decides better)."""
    for j in range(n):
        s = A[j, j]
        floor = 1e-12 * abs(s)
        for k in range(j):
            s -= A[j, k] * A[j, k]
        if not s > floor:
            return False
        d = np.sqrt(s)
        A[j, j] = d
        for i in range(j + 1, n):
            s = A[i, j]
            for k in range(j):
                s -= A[i, k] * A[j, k]
            A[i, j] = s / d
    return True


@kernel(fastmath=_FAST)
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


@entry(fastmath=_FAST)
def min_norm_multipliers(J, LAM, rows, dep, out, bad):
    """out (N, nc): minimum-norm multipliers from J (N, nc, nv) and LAM (N, nc) (the solved values on
    `rows`, zero elsewhere); bad (N,) set where the sample needs the SVD pseudo-inverse instead."""
    N, nc, nv = J.shape
    r, d = len(rows), len(dep)
    m_ = r + d
    glob = np.empty(m_, np.int64)
    for i in range(r):
        glob[i] = rows[i]
    for m in range(d):
        glob[r + m] = dep[m]
    # column structure over all samples: the local rows with an entry in column c
    nz = np.zeros((nv, m_), np.bool_)
    for n in range(N):
        for li in range(m_):
            g = glob[li]
            for c in range(nv):
                if J[n, g, c] != 0.0:
                    nz[c, li] = True
    ptr = np.zeros(nv + 1, np.int64)
    for c in range(nv):
        k = 0
        for li in range(m_):
            if nz[c, li]:
                k += 1
        ptr[c + 1] = ptr[c] + k
    idx = np.empty(ptr[nv], np.int64)
    for c in range(nv):
        k = ptr[c]
        for li in range(m_):
            if nz[c, li]:
                idx[k] = li
                k += 1
    nr = np.zeros(nv, np.int64)   # entries of column c on independent rows (they come first: li < r)
    for c in range(nv):
        k = 0
        for p in range(ptr[c], ptr[c + 1]):
            if idx[p] < r:
                k += 1
        nr[c] = k
    vals = np.empty(ptr[nv])                 # one sample's entries, column by column
    G, B = np.zeros((r, r)), np.zeros((r, max(d, 1)))
    X, S = np.zeros((max(d, 1), r)), np.zeros((max(d, 1), max(d, 1)))
    col, rhs = np.zeros(r), np.zeros(max(d, 1))
    w = np.zeros(m_)
    for n in range(N):
        Jn, lam, o = J[n], LAM[n], out[n]
        for c in range(nv):
            for p in range(ptr[c], ptr[c + 1]):
                vals[p] = Jn[glob[idx[p]], c]
        for i in range(r):
            for k in range(i + 1):
                G[i, k] = 0.0
            for m in range(d):
                B[i, m] = 0.0
        for c in range(nv):                # G = J_r J_r^T, B = J_r J_d^T: column by column
            p0, p1, pr = ptr[c], ptr[c + 1], ptr[c] + nr[c]
            for a in range(p0, pr):
                va, ia = vals[a], idx[a]
                for b in range(p0, a + 1):
                    G[ia, idx[b]] += va * vals[b]
                for b in range(pr, p1):
                    B[ia, idx[b] - r] += va * vals[b]
        ok = _cholesky(G, r)
        if ok:
            for m in range(d):             # X[m] = G^-1 J_r J_d[m]^T = C_d[m, :]
                for i in range(r):
                    col[i] = B[i, m]
                _chol_solve(G, r, col)
                for i in range(r):
                    X[m, i] = col[i]
            for m in range(d):
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
            ok = _cholesky(S, d)
        if ok:
            _chol_solve(S, d, rhs)
            for i in range(r):
                s = lam[rows[i]]
                for m in range(d):
                    s -= X[m, i] * rhs[m]
                w[i] = s
                o[rows[i]] = s
            for m in range(d):
                s = 0.0
                for i in range(r):
                    s += X[m, i] * w[i]
                w[r + m] = s
                o[dep[m]] = s
            worst, scale = 0.0, 0.0        # J^T lambda_ against the constraint load J_r^T lambda_r
            for c in range(nv):
                a, b = 0.0, 0.0
                for p in range(ptr[c], ptr[c + 1]):
                    li = idx[p]
                    if li < r:
                        a += vals[p] * lam[rows[li]]
                    b += vals[p] * w[li]
                scale = max(scale, abs(a))
                worst = max(worst, abs(b - a))
            for k in range(m_):
                if not np.isfinite(w[k]):
                    ok = False
            ok = ok and worst <= 1e-9 * (scale + 1e-300)
        bad[n] = not ok
