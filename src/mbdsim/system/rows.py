"""Rank decisions on constraint rows: a maximal independent subset (dense pivoted QR, or the spanning
tree's rows plus the independent loop rows for large systems), minimum-norm solves, the joints taking
part in a dependency, and the switched rows in force at a time.  Rows are those of phi_q (nc, nv)."""
from __future__ import annotations

import numpy as np

from .._blas import lazy_import
from ..math.lapack import null_space, pivoted_qr, rank_of

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
    rank, piv = rank_of(J.T, tol)
    return np.sort(piv[:rank])


def _tree_plan(sys):
    """What the tree-first selection needs of the System's structure alone (kept in sys.derived and
    shared by Systems of the same structure, topology.shared): the topology of all rows, its sorted
    tree rows, its loop rows, and the blocks as (rows (nb, k), first velocity column (nb,), width)
    stacks of equal shape, or None when a block has more rows than its body has velocities."""
    from .topology import shared
    return shared(sys, "tree_plan", _make_tree_plan)


def _make_tree_plan(sys):
    from .topology import _full_topology, _system_topology
    topo = _full_topology(sys)   # the shared topology of all rows (None when a joint has > 6 rows)
    if topo is None:
        topo = _system_topology(sys, np.arange(sys.nc))
    vadr, rigid = sys.frame_v_adr.tolist(), sys.frame_rigid.tolist()
    ptr, flat = topo.blk_ptr.tolist(), topo.blk_rows.tolist()
    shapes: dict = {}
    blocks: list | None = []
    for b, c in enumerate(topo.blk_child.tolist()):
        rows = flat[ptr[b]:ptr[b + 1]]
        width = 6 if rigid[c] else 3
        if len(rows) > width:
            blocks = None
            break
        if rows:
            shapes.setdefault((len(rows), width), []).append((rows, vadr[c]))
    if blocks is not None:
        blocks = [(np.array([r for r, _ in v]), np.array([a for _, a in v]), w) for (_, w), v in shapes.items()]
    return topo, np.sort(topo.blk_rows), np.asarray(topo.loop_rows), blocks


def _tree_first_rows(sys, J, tol):
    """Tree rows (checked independent, each block on its child body's own velocities too) plus the loop
    rows whose projection on the tree rows' null space is independent (pivoted QR of that small block);
    None when the tree rows are dependent (the caller's pivoted QR decides). Dense factorisations for
    small systems, sparse (O(N) for chains and trees) beyond DENSE_LIMIT velocity variables."""
    _, tree, loop, blocks = _tree_plan(sys)
    if len(tree) == 0:
        return None
    scale = max(1.0, float(np.abs(J).max()))
    if not _blocks_independent(J, blocks, tol * scale):
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
        return tree.copy()   # (the plan is shared)
    dd, piv = pivoted_qr(P.T)
    rank = int(np.sum(dd > tol * scale))
    return np.sort(np.concatenate([tree, loop[piv[:rank]]]))


def _blocks_independent(J, blocks, thr):
    """Every tree block's rows independent on its child body's velocity variables (what the O(N) solve
    needs: S_j = JC_j D^-1 JC_j^T positive definite); blocks: see _tree_plan (None: a block has more
    rows than velocities).  One batched SVD per block shape."""
    if blocks is None:
        return False
    for rows, adr, width in blocks:
        cols = J[rows[:, :, None], adr[:, None, None] + np.arange(width)]   # (nb, k, width)
        if np.linalg.svd(cols, compute_uv=False).min() <= thr:
            return False
    return True


def _projected_loop_sparse(J, tree, loop):
    """Loop rows projected onto the null space of the tree rows (sparse normal equations, O(N) for
    chains and trees); None when the tree rows are dependent."""
    sparse, splu = lazy_import("scipy.sparse"), lazy_import("scipy.sparse.linalg").splu
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


LOOP_BYTES = 2**30   # bytes of the dense projected loop (and extra) rows above which the sparse selection refuses


def child_columns(sys, Jc, bj, rows, adr, width):
    """(nb, k, width) coefficients of the compact rows Jc[rows] (rows (nb, k) on frames bi, bj: side 1
    when bj's velocity block starts at adr, else side 0) on the child bodies' velocity variables."""
    side = (sys.frame_v_adr[bj[rows]] == adr[:, None]).astype(np.int64)
    return Jc[rows, side, :width]


def compact_blocks_independent(sys, Jc, bj, blocks, thr) -> bool:
    """`_blocks_independent` on the compact rows Jc (nc, 2, 6) with their frames bj (no dense Jacobian)."""
    if blocks is None:
        return False
    return all(np.linalg.svd(child_columns(sys, Jc, bj, rows, adr, width), compute_uv=False).min() > thr
               for rows, adr, width in blocks)


def independent_rows_sparse(sys, J, Jc, bj, H=None, Hc=None, hbj=None, hblock=None, tol=1e-9, off=None):
    """`independent_rows` of all nc rows of a large System without dense (nc, nv) matrices, and of extra
    rows H of lower priority (held values), as (kept rows of J, kept rows of H), or None when the tree
    rows are dependent or the loop rows too many (more than LOOP_BYTES of dense projected rows).

    J: CSR (nc, nv) with its compact rows Jc (nc, 2, 6) on frames (bi, bj); H: CSR (m, nv), Hc, hbj
    likewise, hblock (m,): the tree block whose joint each H row measures (-1: none).  The tree rows
    are independent by structure once every block is independent on its child body's velocities (one
    batched SVD per block shape); an H row of a tree joint joins its block (a block that becomes
    dependent drops its H rows).  The loop rows, then the other H rows, are projected onto the null
    space of the kept tree rows (sparse normal equations, O(N) for chains and trees; the projection is
    dense: loop rows x nv) and kept by the pivoted QR of `_tree_first_rows` (same rule, same tolerance).
    Rows `off` (loop rows: switched rows not in force, such as friction locks) are left out."""
    sparse, splu = lazy_import("scipy.sparse"), lazy_import("scipy.sparse.linalg").splu
    topo, tree, loop, blocks = _tree_plan(sys)
    if off is not None and len(off):
        loop = np.setdiff1d(loop, off)
    scale = max(1.0, float(np.max(np.abs(J.data), initial=0.0)))
    if len(tree) == 0 or not compact_blocks_independent(sys, Jc, bj, blocks, tol * scale):
        return None
    m = 0 if H is None else H.shape[0]
    hscale = max(1.0, float(np.max(np.abs(H.data), initial=0.0))) if m else 1.0
    keep_h = np.zeros(m, dtype=bool)
    by_block: dict = {}
    for r, b in enumerate(hblock.tolist() if m else []):
        if b >= 0:
            by_block.setdefault(b, []).append(r)
    shapes: dict = {}
    ptr, flat = topo.blk_ptr, topo.blk_rows
    for b, hr in by_block.items():
        c = int(topo.blk_child[b])
        hard = flat[ptr[b]:ptr[b + 1]]
        shapes.setdefault((len(hard), len(hr), 6 if sys.frame_rigid[c] else 3), []).append(
            (hard, hr, sys.frame_v_adr[c]))
    thr = tol * max(scale, hscale)
    for (nhard, nh, width), items in shapes.items():
        adr = np.array([a for _, _, a in items])
        hard = np.array([x for x, _, _ in items]).reshape(len(items), -1)
        hr = np.array([y for _, y, _ in items])
        cols = np.concatenate([child_columns(sys, Jc, bj, hard, adr, width),
                               child_columns(sys, Hc, hbj, hr, adr, width)], axis=1)
        ok = np.linalg.svd(cols, compute_uv=False).min(axis=1) > thr if nhard + nh <= width else \
            np.zeros(len(items), dtype=bool)
        keep_h[hr[ok].ravel()] = True
        if not ok.all():   # the others one held row at a time, each kept where independent of those before
            keep_h[hr[~ok][_greedy_rows(cols[~ok], nhard, thr)]] = True
    tree_h = np.flatnonzero(keep_h)
    AT = sparse.vstack([J[tree]] + ([H[tree_h]] if len(tree_h) else [])).tocsr()
    extra = np.flatnonzero(hblock < 0) if m else np.zeros(0, dtype=int)
    if (len(loop) + len(extra)) * sys.nv * 8.0 > LOOP_BYTES:
        return None
    try:
        lu = splu((AT @ AT.T).tocsc())
    except RuntimeError:          # singular: dependent rows inside the tree
        return None
    d = np.abs(lu.U.diagonal())
    if d.min() <= 1e-13 * d.max():
        return None
    kept, PL = [tree], np.zeros((0, sys.nv))
    if len(loop):
        P = _project(AT, lu, J[loop])
        sel = _pivoted_rows(P, tol * scale)
        kept.append(loop[sel])
        PL = P[sel]
    if len(extra):
        P = _project(AT, lu, H[extra])
        if len(PL):   # minus its projection on the kept loop rows: P PL^T (PL PL^T)^-1 PL, PL^T = Q R
            st = lazy_import("scipy.linalg").solve_triangular
            R = np.linalg.qr(PL.T, mode="r")
            P -= st(R, st(R, (P @ PL.T).T, trans="T")).T @ PL
        keep_h[extra[_pivoted_rows(P, tol * hscale)]] = True
    return np.sort(np.concatenate(kept)), np.flatnonzero(keep_h)


def _greedy_rows(cols, nhard, thr):
    """(nb, k) mask of the rows nhard.. of the stacked small blocks cols (nb, k, width), each kept where
    its part outside the span of the rows before it that are kept (the first nhard always) exceeds thr
    (batched pseudo-inverse projections; the rows left out are zero rows of the span)."""
    nb, k, width = cols.shape
    M = np.zeros_like(cols)
    M[:, :nhard] = cols[:, :nhard]
    keep = np.zeros((nb, k), dtype=bool)
    for r in range(nhard, k):
        c = cols[:, r]
        P = np.linalg.pinv(M, rcond=1e-12) @ M   # (nb, width, width) projector on the kept rows' span
        out = c - np.einsum("ni,nij->nj", c, P)
        ok = np.linalg.norm(out, axis=1) > thr
        keep[:, r] = ok
        M[ok, r] = c[ok]
    return keep[:, nhard:]


def _pivoted_rows(P, thr):
    """Sorted rows of P kept by the column-pivoted QR of P^T (|R_kk| > thr), its R taken from the R of an
    unpivoted QR of P^T first when P^T is tall (the same pivots and |R_kk|, by blocked BLAS-3: a few
    hundred loop rows of a 10,000-body model in seconds, not minutes)."""
    A = np.linalg.qr(P.T, mode="r") if P.shape[1] > 2 * P.shape[0] else P.T
    dd, piv = pivoted_qr(np.asarray(A))
    return np.sort(piv[:int(np.sum(dd > thr))])


def _project(AT, lu, K):
    """Dense rows of the sparse K projected onto the null space of AT (lu: the factors of AT AT^T)."""
    X = lu.solve(np.asarray((AT @ K.T).toarray()))
    return K.toarray() - (AT.T @ X).T


def min_norm_solve(J, r):
    """Minimum-norm x with J x = r (least squares when inconsistent): dense lstsq for small systems,
    else the sparse normal equations (J J^T + eps I) y = r, x = J^T y (eps: 1e-14 of the largest diagonal)."""
    if J.shape[1] <= DENSE_LIMIT or J.shape[0] == 0:
        return np.linalg.lstsq(J, r, rcond=None)[0]
    sparse, splu = lazy_import("scipy.sparse"), lazy_import("scipy.sparse.linalg").splu
    Js = sparse.csr_matrix(J)
    S = (Js @ Js.T).tocsc()
    S = S + 1e-14 * max(float(S.diagonal().max()), 1e-300) * sparse.identity(S.shape[0], format="csc")
    return Js.T @ splu(S).solve(np.asarray(r, dtype=float))


def dependent_owners(sys, J, rows):
    """Names of the joints/motions whose rows take part in the dependencies of J."""
    if len(rows) == J.shape[0]:
        return []
    keep = np.ones(J.shape[0], dtype=bool)
    keep[rows] = False
    removed = np.flatnonzero(keep)
    ns = null_space(J.T)
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
