"""Rank decisions on small dense matrices by calling LAPACK directly (scipy.linalg.lapack).

The same LAPACK routines, with the same workspace sizes, as scipy.linalg.qr(pivoting=True) and
scipy.linalg.null_space, so the results are bit for bit theirs, without their argument handling (tens of
microseconds a call, which dominate for the constraint Jacobians of small models).  Inputs are finite
float64 matrices; a matrix with an inf or a NaN raises ValueError as scipy's functions do.
"""
from __future__ import annotations

import numpy as np
from scipy.linalg import lapack

_LWORK: dict = {}   # (routine, m, n) -> optimal workspace size from LAPACK's query


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
        lwork = _LWORK[key] = int(lapack.dgeqp3(a, lwork=-1)[3][0].real)
    qr, jpvt, _, _, info = lapack.dgeqp3(a, lwork=lwork)
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
        work, info = lapack.dgesdd_lwork(m, n, compute_uv=1, full_matrices=1)
        if info != 0:
            raise ValueError(f"Internal work array size computation failed: {info}")
        lwork = _LWORK[key] = int(work.real)
    _, s, vh, info = lapack.dgesdd(a, compute_uv=1, full_matrices=1, lwork=lwork)
    if info > 0:
        raise np.linalg.LinAlgError("SVD did not converge")
    if info < 0:
        raise ValueError(f"illegal value in {-info}th argument of internal gesdd")
    tol = np.amax(s, initial=0.0) * (np.finfo(float).eps * max(m, n))
    return vh[np.sum(s > tol, dtype=int):, :].T.copy()


def cho_solve_spd(a, b) -> np.ndarray:
    """x with a x = b for a symmetric positive-definite a, as scipy.linalg.cho_solve(cho_factor(a), b)
    (LAPACK dpotrf, dpotrs, upper factor); np.linalg.LinAlgError when a is not positive definite,
    ValueError for an inf or a NaN."""
    a, b = _finite(a), _finite(b)
    if a.size == 0 or b.size == 0 or a.ndim != 2 or a.shape[0] != a.shape[1] or a.shape[0] != b.shape[0]:
        import scipy.linalg as sla
        return sla.cho_solve(sla.cho_factor(a), b)   # edge cases and errors exactly as scipy's
    c, info = lapack.dpotrf(a, lower=0, clean=0)
    if info > 0:
        raise np.linalg.LinAlgError(f"{info}-th leading minor of the array is not positive definite")
    if info < 0:
        raise ValueError(f'LAPACK reported an illegal value in {-info}-th argument on entry to "POTRF".')
    x, info = lapack.dpotrs(c, b, lower=0)
    if info != 0:
        raise ValueError(f"illegal value in {-info}th argument of internal potrs")
    return x
