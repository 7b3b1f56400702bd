"""Rank decisions on small dense matrices by calling LAPACK directly (scipy.linalg.lapack).

The same LAPACK routines, with the same workspace sizes, as scipy.linalg.qr(pivoting=True) and
scipy.linalg.null_space, so the results are bit for bit theirs, without their argument handling (tens of
microseconds a call, which dominate for the constraint Jacobians of small models).  Inputs are finite
float64 matrices; a matrix with an inf or a NaN raises ValueError as scipy's functions do.  scipy.linalg
is imported on first use only; `cho_solve_spd` uses numpy's LAPACK (a simple model's first run then
needs no scipy.linalg at all).
"""
from __future__ import annotations

import numpy as np

from .._blas import scipy_linalg

_LWORK: dict = {}   # (routine, m, n) -> optimal workspace size from LAPACK's query


def _lapack():
    """scipy.linalg.lapack, imported on first use (scipy.linalg costs ~0.3 s at start-up, and a model
    whose rows need no rank decision never needs it); later calls: a sys.modules look-up."""
    return scipy_linalg().lapack


def _finite(a: np.ndarray) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    if not np.isfinite(a).all():
        raise ValueError("array must not contain infs or NaNs")
    return a


def pivoted_qr(a) -> tuple[np.ndarray, np.ndarray]:
    """(|diag R|, column permutation) of the column-pivoted QR a[:, piv] = Q R (LAPACK dgeqp3), as
    scipy.linalg.qr(a, mode='economic', pivoting=True) gives them; a: (m, n) float64."""
    a = _finite(a)
    m, n = a.shape
    if a.size == 0:
        return np.zeros(0), np.arange(n)
    key = ("geqp3", m, n)
    lwork = _LWORK.get(key)
    if lwork is None:
        lwork = _LWORK[key] = int(_lapack().dgeqp3(a, lwork=-1)[3][0].real)
    qr, jpvt, _, _, info = _lapack().dgeqp3(a, lwork=lwork)
    if info < 0:
        raise ValueError(f"illegal value in {-info}th argument of internal geqp3")
    return np.abs(np.diagonal(qr)).copy(), jpvt - 1


def rank_of(a, tol: float) -> tuple[int, np.ndarray]:
    """(numerical rank, pivots) of a: the diagonal entries of the pivoted QR's R above
    tol * max(1, |R_00|), the rule of system.rows.independent_rows."""
    d, piv = pivoted_qr(a)
    return int(np.sum(d > tol * max(1.0, d[0] if len(d) else 1.0))), piv


def null_space(a) -> np.ndarray:
    """Orthonormal basis (columns) of the null space of a, as scipy.linalg.null_space(a) (full SVD by
    dgesdd, singular values above eps * max(m, n) * s_max count)."""
    a = _finite(a)
    m, n = a.shape
    if a.size == 0:
        return np.eye(n)
    key = ("gesdd", m, n)
    lwork = _LWORK.get(key)
    if lwork is None:
        work, info = _lapack().dgesdd_lwork(m, n, compute_uv=1, full_matrices=1)
        if info != 0:
            raise ValueError(f"Internal work array size computation failed: {info}")
        lwork = _LWORK[key] = int(work.real)
    _, s, vh, info = _lapack().dgesdd(a, compute_uv=1, full_matrices=1, lwork=lwork)
    if info > 0:
        raise np.linalg.LinAlgError("SVD did not converge")
    if info < 0:
        raise ValueError(f"illegal value in {-info}th argument of internal gesdd")
    tol = np.amax(s, initial=0.0) * (np.finfo(float).eps * max(m, n))
    return vh[np.sum(s > tol, dtype=int):, :].T.copy()


def cho_solve_spd(a, b) -> np.ndarray:
    """x with a x = b for a symmetric positive-definite a (r, r), b (r,) or (r, k): numpy's Cholesky
    factor L (a = L L^T), then L y = b and L^T x = y (to round-off as scipy.linalg.cho_solve(cho_factor(a),
    b); numpy's LAPACK, so that the velocity assembly of a simple model needs no scipy.linalg, ~0.3 s
    at start-up).  np.linalg.LinAlgError when a is not positive definite, ValueError for an inf or a NaN
    or mismatched shapes."""
    a, b = _finite(a), _finite(b)
    if a.ndim != 2 or a.shape[0] != a.shape[1] or b.ndim not in (1, 2) or a.shape[0] != b.shape[0]:
        raise ValueError(f"cho_solve_spd: shapes {a.shape} and {b.shape} do not match")
    if a.size == 0:
        return np.zeros(b.shape)
    L = np.linalg.cholesky(a)
    return np.linalg.solve(L.T, np.linalg.solve(L, b))
