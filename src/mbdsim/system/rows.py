"""Rank decisions on constraint rows: a maximal independent subset (dense pivoted QR, or the spanning
tree's rows plus the independent loop rows for large systems), minimum-norm solves, the joints taking
part in a dependency, and the switched rows in force at a time.  Rows are those of phi_q (nc, nv)."""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla

DENSE_LIMIT = 600   # velocity variables; larger systems use sparse factorisations (O(N) for chains, trees)


def independent_rows(J, tol=1e-9, sys=None):
    """Indices of a maximal independent subset of the rows of J: rank-revealing pivoted QR, or for a
    large System (sys given) its spanning-tree rows plus the loop rows that are independent of them."""
    if J.shape[0] == 0:
        return np.arange(0)
    if sys is not None and J.shape[1] > DENSE_LIMIT:
        rows = _independent_rows_sparse(sys, J, tol)
        if rows is not None:
            return rows
    _, R, piv = sla.qr(J.T, mode="economic", pivoting=True)
    d = np.abs(np.diag(R))
    rank = int(np.sum(d > tol * max(1.0, d[0] if len(d) else 1.0)))
    return np.sort(piv[:rank])


def _independent_rows_sparse(sys, J, tol):
    """Tree rows (independent by construction, checked by the sparse factorisation of J_T J_T^T) plus
    the loop rows whose projection on the tree rows' null space is independent (pivoted QR of the small
    projected block); None when the tree rows turn out dependent (then the dense QR decides)."""
    from scipy import sparse
    from scipy.sparse.linalg import splu
    from .topology import system_topology
    topo = system_topology(sys, np.arange(J.shape[0]))
    tree = np.sort(topo.blk_rows)
    loop = np.asarray(topo.loop_rows)
    JT = sparse.csr_matrix(J[tree])
    try:
        lu = splu((JT @ JT.T).tocsc())
    except RuntimeError:          # singular: dependent rows inside the tree
        return None
    d = np.abs(lu.U.diagonal())
    if d.min() <= 1e-13 * d.max():
        return None
    if len(loop) == 0:
        return tree
    K = J[loop]
    X = lu.solve(np.asarray(JT @ K.T))
    P = K - (JT.T @ X).T          # loop rows projected onto null(J_T)
    _, R, piv = sla.qr(P.T, mode="economic", pivoting=True)
    dd = np.abs(np.diag(R))
    rank = int(np.sum(dd > tol * max(1.0, dd[0] if len(dd) else 1.0)))
    return np.sort(np.concatenate([tree, loop[piv[:rank]]]))


def min_norm_solve(J, r):
    """Minimum-norm x with J x = r (least squares when inconsistent): dense lstsq for small systems,
    else the sparse normal equations (J J^T + eps I) y = r, x = J^T y (eps: 1e-14 of the largest diagonal)."""
    if J.shape[1] <= DENSE_LIMIT or J.shape[0] == 0:
        return np.linalg.lstsq(J, r, rcond=None)[0]
    from scipy import sparse
    from scipy.sparse.linalg import splu
    Js = sparse.csr_matrix(J)
    S = (Js @ Js.T).tocsc()
    S = S + 1e-14 * max(float(S.diagonal().max()), 1e-300) * sparse.identity(S.shape[0], format="csc")
    return Js.T @ splu(S).solve(np.asarray(r, dtype=float))


def dependent_owners(sys, J, rows):
    """Names of the joints/motions whose rows take part in the dependencies of J."""
    removed = np.setdiff1d(np.arange(J.shape[0]), rows)
    if len(removed) == 0:
        return []
    ns = sla.null_space(J.T)
    involved = np.where(np.any(np.abs(ns) > 1e-8, axis=1))[0]
    names = []
    for r in np.concatenate([involved, removed]):
        if sys.row_owner[r] not in names:
            names.append(sys.row_owner[r])
    return names


def active_rows(sys, rows, t):
    """rows plus the switched rows in force at t (stick locks of joint friction, force_elements.friction)."""
    if not len(sys.lock_rows):
        return rows
    from .force_elements.friction import locks_at
    locks = locks_at(sys, t)
    return np.union1d(rows, locks).astype(int) if locks else rows
