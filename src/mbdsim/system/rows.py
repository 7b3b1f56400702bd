"""Rank decisions on constraint rows: a maximal independent subset (dense pivoted QR, or the spanning
tree's rows plus the independent loop rows for large systems), minimum-norm solves, the joints taking
part in a dependency, and the switched rows in force at a time.  Rows are those of phi_q (nc, nv)."""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla

DENSE_LIMIT = 600   # velocity variables; larger systems use sparse factorisations (O(N) for chains, trees)


def independent_rows(J, tol=1e-9, sys=None):
    """Indices of a maximal independent subset of the rows of J (all nc rows of `sys` when sys is given).
    With sys: the spanning tree's rows first (every tree joint keeps all its rows), then the loop rows
    that are independent of them, so that redundancy is always removed from the loop-closing joints and
    the O(N) solve's dense loop block is as small as it can be; otherwise (or when the tree rows turn out
    dependent) a rank-revealing pivoted QR."""
    if J.shape[0] == 0:
        return np.arange(0)
    if sys is not None and J.shape[0] == sys.nc:
        rows = _tree_first_rows(sys, J, tol)
        if rows is not None:
            return rows
    _, R, piv = sla.qr(J.T, mode="economic", pivoting=True)
    d = np.abs(np.diag(R))
    rank = int(np.sum(d > tol * max(1.0, d[0] if len(d) else 1.0)))
    return np.sort(piv[:rank])


def _tree_first_rows(sys, J, tol):
    """Tree rows (checked independent, each block on its child body's own velocities too) plus the loop
    rows whose projection on the tree rows' null space is independent (pivoted QR of that small block);
    None when the tree rows are dependent (the caller's pivoted QR decides). Dense factorisations for
    small systems, sparse (O(N) for chains and trees) beyond DENSE_LIMIT velocity variables."""
    from .topology import system_topology
    topo = system_topology(sys, np.arange(J.shape[0]))
    tree = np.sort(topo.blk_rows)
    loop = np.asarray(topo.loop_rows)
    if len(tree) == 0:
        return None
    scale = max(1.0, float(np.abs(J).max()))
    if not _blocks_independent(sys, J, topo, tol * scale):
        return None
    if J.shape[1] > DENSE_LIMIT:
        P = _projected_loop_sparse(J, tree, loop)
    else:
        Q, R = np.linalg.qr(J[tree].T)
        d = np.abs(np.diag(R))
        if d.min() <= tol * max(scale, d.max()):
            return None
        P = J[loop] - (J[loop] @ Q) @ Q.T      # loop rows projected onto null(J_T)
    if P is None:
        return None
    if len(loop) == 0:
        return tree
    _, R, piv = sla.qr(P.T, mode="economic", pivoting=True)
    dd = np.abs(np.diag(R))
    rank = int(np.sum(dd > tol * scale))
    return np.sort(np.concatenate([tree, loop[piv[:rank]]]))


def _blocks_independent(sys, J, topo, thr):
    """Every tree block's rows independent on its child body's velocity variables (what the O(N) solve
    needs: S_j = JC_j D^-1 JC_j^T positive definite)."""
    vadr, rigid = sys.frame_v_adr, sys.frame_rigid
    for b, c in enumerate(topo.blk_child):
        rows = topo.blk_rows[topo.blk_ptr[b]:topo.blk_ptr[b + 1]]
        if len(rows) == 0:
            continue
        cols = J[np.ix_(rows, np.arange(vadr[c], vadr[c] + (6 if rigid[c] else 3)))]
        if len(rows) > cols.shape[1]:
            return False
        s = np.linalg.svd(cols, compute_uv=False)
        if s.min() <= thr:
            return False
    return True


def _projected_loop_sparse(J, tree, loop):
    """Loop rows projected onto the null space of the tree rows (sparse normal equations, O(N) for
    chains and trees); None when the tree rows are dependent."""
    from scipy import sparse
    from scipy.sparse.linalg import splu
    JT = sparse.csr_matrix(J[tree])
    try:
        lu = splu((JT @ JT.T).tocsc())
    except RuntimeError:          # singular: dependent rows inside the tree
        return None
    d = np.abs(lu.U.diagonal())
    if d.min() <= 1e-13 * d.max():
        return None
    if len(loop) == 0:
        return np.zeros((0, J.shape[1]))
    K = J[loop]
    X = lu.solve(np.asarray(JT @ K.T))
    return K - (JT.T @ X).T


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
