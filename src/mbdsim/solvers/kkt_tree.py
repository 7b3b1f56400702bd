"""O(N) solve of the augmented equations of motion over a spanning tree (numba).

    M vd + J_T^T lambda_T + K^T lambda_L = F,    J_T vd = c_T,    K vd = c_L

Bodies are eliminated leaves first (Baraff's linear-time block elimination): for the block j joining
child body c to its parent p,

    D_c = M_c + sum_k JP_k^T S_k^-1 JP_k      (k: blocks whose parent is c)
    S_j = JC_j D_c^-1 JC_j^T                   (m_j x m_j, symmetric positive definite)

both formed from triangular solves with the Cholesky factors (D = L L^T: S_j = Z Z^T, Z = L_D^-1 JC^T;
JP^T S^-1 JP = Y^T Y, Y = L_S^-1 JP),
and the solve is one backward and one forward sweep. The loop rows K enter through the Schur complement
(K W) lambda_L = K vd0 - c_L with W = tree solve of K^T, so the cost is O(N (1 + n_loop)); the tree
rows' multipliers of those solves (LT) are kept with W, so that a solve is one tree solve and the loop
correction vd = vd0 - W lambda_L, lambda_T = lambda_T0 - LT lambda_L (linearity). Every body has
six velocity slots here (CM velocity [m/s], body-axes angular velocity [rad/s]); a particle's rotational
slots carry a unit dummy inertia and no load. Rows are global row indices into the compact Jacobian
Jc (nc, 2, 6) of `system.kernels.rows_kernel`. Kernels return False when a pivot is not positive
(a dependent or singular set of rows).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import entry, kernel  # noqa: F401  (njit without the wrappers that dominate compilation; issue 32)


@kernel(_nrt=False)
def chol(A, n, L3, il):
    """Cholesky factor L3[il] (lower; its diagonal holds the reciprocals) of the leading n x n block of A;
    False if not positive definite."""
    for i in range(n):
        for j in range(i + 1):
            s = A[i, j]
            for k in range(j):
                s -= L3[il, i, k] * L3[il, j, k]
            if i == j:
                if not s > 1e-300:
                    return False
                L3[il, i, i] = 1.0 / np.sqrt(s)
            else:
                L3[il, i, j] = s * L3[il, j, j]
    return True


@kernel(_nrt=False)
def _fwd(L3, il, n, b2, ib):
    """b2[ib] <- L^-1 b2[ib] (forward substitution with L = L3[il] from `chol`)."""
    for i in range(n):
        s = b2[ib, i]
        for k in range(i):
            s -= L3[il, i, k] * b2[ib, k]
        b2[ib, i] = s * L3[il, i, i]


@kernel(_nrt=False)
def _bwd(L3, il, n, b2, ib):
    """b2[ib] <- L^-T b2[ib] (back substitution with L = L3[il] from `chol`)."""
    for i in range(n - 1, -1, -1):
        s = b2[ib, i]
        for k in range(i + 1, n):
            s -= L3[il, k, i] * b2[ib, k]
        b2[ib, i] = s * L3[il, i, i]


@kernel(_nrt=False)
def chol_solve(L3, il, n, b2, ib):
    """Solve (L L^T) x = b in place for the leading n entries of b2[ib] (L = L3[il] from `chol`)."""
    _fwd(L3, il, n, b2, ib)
    _bwd(L3, il, n, b2, ib)


@kernel(_nrt=False)
def _side(bi, bj, row, f):
    return 0 if bi[row] == f else 1


@kernel(_nrt=False)
def tree_factor(Jc, bi, bj, M6, order, pblk, blk_child, blk_parent, blk_ptr, blk_rows, ch_ptr, ch_blk,
                LD, Y, LS, JC, JP, D, Z):
    """Factor the tree part, leaves first: LD[c] = chol(D_c), LS[j] = chol(S_j), Y[j] = LS_j^-1 JP_j
    (so that JP^T S^-1 JP = Y^T Y); JC, JP: each block's child- and parent-side rows. D (6, 6) and
    Z (>= 6, 6) are scratch. False on a pivot that is not positive (dependent rows)."""
    for b in range(blk_child.shape[0]):   # gather each block's child- and parent-side rows
        c, p = blk_child[b], blk_parent[b]
        for a in range(blk_ptr[b + 1] - blk_ptr[b]):
            row = blk_rows[blk_ptr[b] + a]
            sc = _side(bi, bj, row, c)
            for k in range(6):
                JC[b, a, k] = Jc[row, sc, k]
                JP[b, a, k] = Jc[row, 1 - sc, k] if p != 0 else 0.0
    for ii in range(order.shape[0] - 1, -1, -1):
        c = order[ii]
        for i in range(6):
            for j in range(6):
                D[i, j] = M6[c, i, j]
        for a in range(ch_ptr[c], ch_ptr[c + 1]):   # D += Y_k^T Y_k of each child block
            k = ch_blk[a]
            m = blk_ptr[k + 1] - blk_ptr[k]
            for i in range(6):
                for j in range(i + 1):
                    s = 0.0
                    for r in range(m):
                        s += Y[k, r, i] * Y[k, r, j]
                    D[i, j] += s
                    if j != i:
                        D[j, i] += s
        if not chol(D, 6, LD, c):
            return False
        j = pblk[c]
        if j < 0:
            continue
        m = blk_ptr[j + 1] - blk_ptr[j]
        for r in range(m):          # Z rows: L_D^-1 JC_j^T, so that S_j = JC D^-1 JC^T = Z Z^T
            for k in range(6):
                Z[r, k] = JC[j, r, k]
            _fwd(LD, c, 6, Z, r)
        for r in range(m):
            for q in range(r + 1):
                s = 0.0
                for k in range(6):
                    s += Z[r, k] * Z[q, k]
                D[r, q] = s
                D[q, r] = s
        if not chol(D, m, LS, j):
            return False
        if blk_parent[j] != 0:      # Y_j = LS_j^-1 JP_j, column by column
            for k in range(6):
                for r in range(m):
                    Z[0, r] = JP[j, r, k]
                _fwd(LS, j, m, Z, 0)
                for r in range(m):
                    Y[j, r, k] = Z[0, r]
    return True


@kernel(_nrt=False)
def tree_solve(order, pblk, blk_parent, blk_ptr, blk_rows, LD, Y, LS, JC, JP, F, c_rows, vd, lam, Qt, u, X):
    """Solve the tree system for loads F (nf, 6) and row right-hand sides c_rows (nc,) (global rows);
    writes vd (nf, 6) and lam (nc,) at the tree rows. Qt (nf, 6), u (nblk, 6), X (>= 2, 6) are work."""
    for f in range(F.shape[0]):
        for k in range(6):
            Qt[f, k] = F[f, k]
            vd[f, k] = 0.0
    for ii in range(order.shape[0] - 1, -1, -1):
        c = order[ii]
        j = pblk[c]
        if j < 0:
            continue
        m = blk_ptr[j + 1] - blk_ptr[j]
        for k in range(6):
            X[0, k] = Qt[c, k]
        chol_solve(LD, c, 6, X, 0)                  # D_c^-1 Qt_c
        for r in range(m):
            s = -c_rows[blk_rows[blk_ptr[j] + r]]
            for k in range(6):
                s += JC[j, r, k] * X[0, k]
            u[j, r] = s
        chol_solve(LS, j, m, u, j)                  # u_j = S^-1 (JC D^-1 Qt - c)
        p = blk_parent[j]
        if p != 0:
            for k in range(6):
                s = 0.0
                for r in range(m):
                    s += JP[j, r, k] * u[j, r]
                Qt[p, k] -= s
    for ii in range(order.shape[0]):
        c = order[ii]
        j = pblk[c]
        for k in range(6):
            X[0, k] = Qt[c, k]
        if j >= 0:
            m = blk_ptr[j + 1] - blk_ptr[j]
            p = blk_parent[j]
            for r in range(m):                      # lambda_j = u_j + LS^-T (Y_j vd_p)
                s = 0.0
                if p != 0:
                    for k in range(6):
                        s += Y[j, r, k] * vd[p, k]
                X[1, r] = s
            if p != 0:
                _bwd(LS, j, m, X, 1)
            for r in range(m):
                X[1, r] += u[j, r]
                lam[blk_rows[blk_ptr[j] + r]] = X[1, r]
            for k in range(6):
                s = 0.0
                for r in range(m):
                    s += JC[j, r, k] * X[1, r]
                X[0, k] -= s
        chol_solve(LD, c, 6, X, 0)
        for k in range(6):
            vd[c, k] = X[0, k]


@kernel(_nrt=False)
def _row_dot(Jc, bi, bj, row, x):
    s = 0.0
    for side in range(2):
        f = bi[row] if side == 0 else bj[row]
        if f != 0:
            for k in range(6):
                s += Jc[row, side, k] * x[f, k]
    return s


@kernel(_nrt=False)
def kkt_factor(Jc, bi, bj, M6, order, pblk, blk_child, blk_parent, blk_ptr, blk_rows, ch_ptr, ch_blk,
               loop_rows, LD, G, LS, JC, JP, Qt, u, W, KW, LK, c0, LT, F, D, Z, perm):
    """Factor the whole system (tree, then the loop rows' Schur complement K W); False if singular.
    W (nl, nf, 6) and LT (nl, nc): the tree solve of each loop row's K^T (velocity slots, and the tree
    rows' multipliers). F (nf, 6), D (6, 6) and Z (6, 6) are scratch."""
    if not tree_factor(Jc, bi, bj, M6, order, pblk, blk_child, blk_parent, blk_ptr, blk_rows, ch_ptr, ch_blk,
                       LD, G, LS, JC, JP, D, Z):
        return False
    nl = loop_rows.shape[0]
    if nl == 0:
        return True
    for i in range(c0.shape[0]):
        c0[i] = 0.0
    for f in range(F.shape[0]):
        for k in range(6):
            F[f, k] = 0.0
    for i in range(nl):
        row = loop_rows[i]
        for side in range(2):
            f = bi[row] if side == 0 else bj[row]
            if f != 0:
                for k in range(6):
                    F[f, k] = Jc[row, side, k]
        tree_solve(order, pblk, blk_parent, blk_ptr, blk_rows, LD, G, LS, JC, JP, F, c0, W[i], LT[i], Qt, u, D)
        for side in range(2):
            f = bi[row] if side == 0 else bj[row]
            if f != 0:
                for k in range(6):
                    F[f, k] = 0.0
    for a in range(nl):
        for b in range(nl):
            KW[a, b] = _row_dot(Jc, bi, bj, loop_rows[a], W[b])
    for a in range(nl):
        for b in range(a):
            s = 0.5 * (KW[a, b] + KW[b, a])
            KW[a, b] = s
            KW[b, a] = s
    return pivoted_chol(KW, nl, LK, perm) >= 0


@kernel(_nrt=False)
def pivoted_chol(A, n, L3, perm):
    """Cholesky with diagonal pivoting of the symmetric positive semi-definite A (overwritten): the
    factor of the permuted leading block goes to L3[0] (reciprocal diagonal, as `chol`), the order to
    perm[1:], the rank to perm[0]. Pivots below 1e-10 of the largest diagonal count as zero: rows that
    are (nearly) dependent at this configuration, such as a four-bar's loop at a change point, are left
    out of the solve (their multipliers are zero) instead of making it singular. Returns the rank."""
    big = 0.0
    for i in range(n):
        perm[1 + i] = i
        big = max(big, A[i, i])
    tol = 1e-10 * big
    rank = n
    for k in range(n):
        p = k
        for i in range(k + 1, n):
            if A[perm[1 + i], perm[1 + i]] > A[perm[1 + p], perm[1 + p]]:
                p = i
        perm[1 + k], perm[1 + p] = perm[1 + p], perm[1 + k]
        for j in range(k):
            L3[0, k, j], L3[0, p, j] = L3[0, p, j], L3[0, k, j]
        pk = perm[1 + k]
        if not A[pk, pk] > tol:
            rank = k
            break
        d = np.sqrt(A[pk, pk])
        L3[0, k, k] = 1.0 / d
        for i in range(k + 1, n):
            L3[0, i, k] = A[perm[1 + i], pk] / d
        for i in range(k + 1, n):
            pi_ = perm[1 + i]
            for j in range(k + 1, i + 1):
                pj = perm[1 + j]
                A[pi_, pj] -= L3[0, i, k] * L3[0, j, k]
                A[pj, pi_] = A[pi_, pj]
    perm[0] = rank
    return rank


@kernel(_nrt=False)
def kkt_solve(Jc, bi, bj, order, pblk, blk_parent, blk_ptr, blk_rows, loop_rows, LD, G, LS, JC, JP, Qt, u,
              W, LK, lamL, LT, F, c_rows, vd, lam, X, perm):
    """Solve the factored system for loads F (nf, 6) and row right-hand sides c_rows (nc,);
    writes vd (nf, 6) and lam (nc,) at every tree and loop row: one tree solve, then the loop rows'
    multipliers from the Schur complement and their correction through W and LT of `kkt_factor`.
    X (>= 2, 6) is scratch."""
    tree_solve(order, pblk, blk_parent, blk_ptr, blk_rows, LD, G, LS, JC, JP, F, c_rows, vd, lam, Qt, u, X)
    nl = loop_rows.shape[0]
    if nl == 0:
        return
    rank = perm[0]
    for a in range(nl):   # in pivot order; dependent rows (beyond the rank) get zero multipliers
        row = loop_rows[perm[1 + a]]
        lamL[0, a] = _row_dot(Jc, bi, bj, row, vd) - c_rows[row] if a < rank else 0.0
    chol_solve(LK, 0, rank, lamL, 0)
    for a in range(nl):
        i = perm[1 + a]
        la = lamL[0, a]
        lam[loop_rows[i]] = la
        if la == 0.0:
            continue
        for f in range(vd.shape[0]):
            for k in range(6):
                vd[f, k] -= W[i, f, k] * la
        for r in range(blk_rows.shape[0]):
            row = blk_rows[r]
            lam[row] -= LT[i, row] * la


@kernel(_nrt=False)
def dense_factor(Jc, bi, bj, M6, active, KD, piv):
    """Dense LU (partial pivoting) of the augmented matrix over six slots per body and the active rows,
    for models with a singular body mass matrix (massless links, point masses on rigid frames)."""
    nb = M6.shape[0] - 1
    n = KD.shape[0]
    for i in range(n):
        for j in range(n):
            KD[i, j] = 0.0
    for f in range(1, nb + 1):
        for i in range(6):
            for j in range(6):
                KD[6 * (f - 1) + i, 6 * (f - 1) + j] = M6[f, i, j]
    for a in range(active.shape[0]):
        row = active[a]
        for side in range(2):
            f = bi[row] if side == 0 else bj[row]
            if f != 0:
                for k in range(6):
                    KD[6 * nb + a, 6 * (f - 1) + k] += Jc[row, side, k]
                    KD[6 * (f - 1) + k, 6 * nb + a] += Jc[row, side, k]
    return lu_factor(KD, n, piv, 1e-13)


@kernel(_nrt=False)
def lu_factor(A, n, piv, rel_tol):
    """LU with partial pivoting of the leading n x n block of A in place (L unit lower below the diagonal,
    U on and above it), the row swaps in piv[:n]; False when a pivot is not above rel_tol times the
    largest entry (singular to that tolerance). Used by `dense_factor`, `kkt_square.square_factor` and the
    implicit steppers (fastradau._lu: real and complex)."""
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
        if not abs(A[p, k]) > rel_tol * scale:
            return False
        if p != k:
            for j in range(n):
                A[k, j], A[p, j] = A[p, j], A[k, j]
        r = 1.0 / A[k, k]   # one division per column (the multipliers by product)
        for i in range(k + 1, n):
            A[i, k] *= r
            m = A[i, k]
            if m != 0.0:
                for j in range(k + 1, n):
                    A[i, j] -= m * A[k, j]
    return True


@kernel(_nrt=False)
def lu_solve(A, piv, n, x):
    """x <- A^-1 x (leading n entries) with the LU of `lu_factor`."""
    for k in range(n):
        p = piv[k]
        if p != k:
            x[k], x[p] = x[p], x[k]
    for i in range(n):
        for k in range(i):
            x[i] -= A[i, k] * x[k]
    for i in range(n - 1, -1, -1):
        for k in range(i + 1, n):
            x[i] -= A[i, k] * x[k]
        x[i] /= A[i, i]


@kernel(_nrt=False)
def lu_solve_transposed(A, piv, n, x):
    """x <- A^-T x (leading n entries) with the LU of `lu_factor` (U^T w = x, L^T z = w, then the row
    swaps undone)."""
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


@kernel(_nrt=False)
def dense_solve(active, KD, piv, F, c_rows, vd, lam, x):
    """Solve with the LU of `dense_factor` for loads F (nf, 6) and row right-hand sides c_rows; x scratch (n)."""
    nb = F.shape[0] - 1
    n = KD.shape[0]
    for f in range(1, nb + 1):
        for k in range(6):
            x[6 * (f - 1) + k] = F[f, k]
    for a in range(active.shape[0]):
        x[6 * nb + a] = c_rows[active[a]]
    lu_solve(KD, piv, n, x)
    for k in range(6):
        vd[0, k] = 0.0
    for f in range(1, nb + 1):
        for k in range(6):
            vd[f, k] = x[6 * (f - 1) + k]
    for a in range(active.shape[0]):
        lam[active[a]] = x[6 * nb + a]
