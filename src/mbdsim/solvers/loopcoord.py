"""Coordinate constraints (couplers, gears, rack and pinion, user constraints) in closed loops: their rows on
the absolute-coordinate core (numba), issue 29.

Each constraint f(X, t) = 0 over joint coordinates X_k is one row of the step loop's KKT solve, in force
with the other rows (same factorisation, same projections):

    phi = f(X, t),  phi_q = sum_k f_k J_Xk,  nu = -f_t,
    gamma = -(sum_k f_k quad_Xk + sum_kl f_kl X'_k X'_l + 2 sum_k f_kt X'_k + f_tt)

with J_Xk, quad_Xk of the angle or slide primitive of term k's joint (system.kernels: `_angle_row`,
`_dot2_row`, the one implementation of those rows) and the exact symbolic derivatives of f compiled to
programs (system.exprvm). An angle is continued beyond +-pi from its auxiliary coordinate psi in the state,
X = psi + wrap(theta - psi): psi is integrated along (psi' = theta', psi'' = theta'': `aux_qdot`,
`aux_rates`) and set to X and theta' by every projection (`sync_q`, `sync_v`), so that it only picks the
branch; the link rows wrap(theta - psi) = 0 of the reference path (system.constraints.coupler) are not
solved for (their multipliers f_k lambda are written for the record).

A row whose terms move at most two bodies besides ground is written into the compact Jacobian Jc (two
blocks) and solved as a loop row of the tree elimination (or a row of the dense or square LU). A *wide* row
(lc[17]: three or more bodies, a differential or a planetary mesh through its carrier) has G_a = sum_k f_k
J_Xk on as many bodies as its terms move; it stays out of the rows factored and enters the solve bordered
(`fastsolve._factor`, `fastsolve._solve`): with E_a, EL_a the solve of the load G_a^T with the other rows
(accelerations, their multipliers; zero row right-hand sides) and P = G E (symmetric positive
semi-definite, factored by pivoted Cholesky: dependent wide rows get zero multipliers, as loop rows),
a solve for loads F and right-hand sides c is the solve x0, lambda0 with the other rows, then

    mu = P^-1 (G x0 - c_w),   x = x0 - E mu,   lambda = lambda0 - EL mu,   lambda_w = mu

so that M x + J^T lambda + G^T mu = F, J x = c, G x = c_w (`wide_unit_load`, `wide_schur`,
`wide_correct`): the cost of one more loop row per wide row.

lc = cm[50] (layout in system.loopcoords), lw = wk[52]: x, stack, X (nt), X' (nt), the terms' Jacobian
blocks Jt (nt, 2, 6) on their own frames (velocity-variable axes, as rows_kernel's Jc), quad (nt), f_k (nt),
then the wide rows' E, EL, P, its factor, pivots, right-hand side, a load, zero right-hand sides.
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from ..system.exprvm import eval_program
from ..system.kernels import _angle_row, _dot2_row, _put, row_rate
from .kkt_tree import chol_solve, pivoted_chol


@kernel(_nrt=False)
def _prog(lc, p, x, stack):
    return eval_program(lc[3], lc[4], lc[5], lc[6][p], lc[7][p], x, stack)


@kernel(_nrt=False)
def coord_rows(lc, lw, t, q, r, A, rd, w, rigid, phi, Jc, nu, gamma):
    """phi, Jc, nu, gamma of every coordinate constraint's main row at the frames r, A, rd, w (of the state
    with positions q, which holds the angles' psi) and time t [s]; each link row gets phi = wrap(theta -
    psi) [rad] (a residual only: no Jacobian, never solved for). Keeps X, X', Jt, quad, f_k in lw."""
    row_, ptr, pbase, kind, tbi, tbj, V = lc[0], lc[1], lc[2], lc[8], lc[9], lc[10], lc[11]
    aq, link, side = lc[12], lc[14], lc[15]
    x, stack, X, Xd, Jt, quad, fk = lw[0], lw[1], lw[2], lw[3], lw[4], lw[5], lw[6]
    for j in range(kind.shape[0]):
        bi, bj = tbi[j], tbj[j]
        Vj = V[j]
        if kind[j] == 0:
            th, Jri, Jpi, Jrj, Jpj, qd = _angle_row(A, w, bi, bj, Vj[0], Vj[1], Vj[2])
        else:
            th, Jri, Jpi, Jrj, Jpj, qd = _dot2_row(r, A, rd, w, bi, bj, Vj[0], Vj[1], Vj[2])
        _put(Jt, j, 0, bi, Jri, Jpi, A, rigid)
        _put(Jt, j, 1, bj, Jrj, Jpj, A, rigid)
        Xd[j] = row_rate(rd, w, bi, bj, Jri, Jpi, Jrj, Jpj)
        quad[j] = qd
        if kind[j] == 0:
            psi = q[aq[j]]
            d = th - psi
            d -= 2.0 * np.pi * np.floor((d + np.pi) / (2.0 * np.pi))
            X[j] = psi + d
            lr = link[j]
            phi[lr] = d
            nu[lr] = 0.0
            gamma[lr] = 0.0
            for s in range(2):
                for k in range(6):
                    Jc[lr, s, k] = 0.0
        else:
            X[j] = th
    for i in range(row_.shape[0]):
        t0, t1 = ptr[i], ptr[i + 1]
        n = t1 - t0
        x[0] = t
        for j in range(t0, t1):
            x[1 + j - t0] = X[j]
        b = pbase[i]
        row = row_[i]
        phi[row] = _prog(lc, b, x, stack)
        nu[row] = -_prog(lc, b + 1, x, stack)
        for s in range(2):
            for k in range(6):
                Jc[row, s, k] = 0.0
        g = _prog(lc, b + 2, x, stack)
        for j in range(t0, t1):
            f = _prog(lc, b + 3 + (j - t0), x, stack)
            fk[j] = f
            g += f * quad[j] + 2.0 * _prog(lc, b + 3 + n + (j - t0), x, stack) * Xd[j]
            for m in range(t0, t1):
                g += _prog(lc, b + 3 + 2 * n + n * (j - t0) + (m - t0), x, stack) * Xd[j] * Xd[m]
            for s in range(2):
                rs = side[j, s]
                if rs >= 0:
                    for k in range(6):
                        Jc[row, rs, k] += f * Jt[j, s, k]
        gamma[row] = -g


@kernel(_nrt=False)
def _term_dot(lc, lw, j, x6):
    """Jt_j . x6 (x6: six slots per frame) of term j."""
    s = 0.0
    for side in range(2):
        f = lc[9][j] if side == 0 else lc[10][j]
        if f != 0:
            for k in range(6):
                s += lw[4][j, side, k] * x6[f, k]
    return s


@kernel(_nrt=False)
def aux_rates(lc, lw, x6, vd, lam):
    """psi'' = theta'' = J_theta vd + quad of every angle term into vd (the system layout) from the solved
    accelerations x6 (six slots per frame), and the link rows' multipliers f_k lambda into lam."""
    for j in range(lc[8].shape[0]):
        if lc[8][j] == 0:
            vd[lc[13][j]] = _term_dot(lc, lw, j, x6) + lw[5][j]
            lam[lc[14][j]] = lw[6][j] * lam[lc[0][lc[16][j]]]


@kernel(_nrt=False)
def aux_qdot(lc, lw, qd):
    """psi' = theta' of every angle term into qd (positions' rates, system layout)."""
    for j in range(lc[8].shape[0]):
        if lc[8][j] == 0:
            qd[lc[12][j]] = lw[3][j]


@kernel(_nrt=False)
def sync_q(lc, lw, q):
    """psi <- X, the continued angle of the last `coord_rows` (after a converged position projection)."""
    for j in range(lc[8].shape[0]):
        if lc[8][j] == 0:
            q[lc[12][j]] = lw[2][j]


@kernel(_nrt=False)
def sync_v(lc, lw, v6, v):
    """psi' <- theta' = J_theta v (v6: the projected velocities, six slots per frame) into v."""
    for j in range(lc[8].shape[0]):
        if lc[8][j] == 0:
            v[lc[13][j]] = _term_dot(lc, lw, j, v6)


@kernel(_nrt=False)
def wide_dot(lc, lw, a, x6):
    """G_a . x6 of wide row a (x6: six slots per frame) from the terms' blocks of the last `coord_rows`."""
    i = lc[17][a]
    s = 0.0
    for j in range(lc[1][i], lc[1][i + 1]):
        s += lw[6][j] * _term_dot(lc, lw, j, x6)
    return s


@kernel(_nrt=False)
def wide_unit_load(lc, lw, a):
    """The load G_a^T of wide row a into lw[13] (zeroed first), lw[14] and EL_a zeroed: the right-hand
    sides of its unit solve (the caller solves into E_a, EL_a)."""
    F, zc, EL = lw[13], lw[14], lw[8]
    for f in range(F.shape[0]):
        for k in range(6):
            F[f, k] = 0.0
    for r in range(zc.shape[0]):
        zc[r] = 0.0
        EL[a, r] = 0.0
    i = lc[17][a]
    for j in range(lc[1][i], lc[1][i + 1]):
        fk = lw[6][j]
        for side in range(2):
            fr = lc[9][j] if side == 0 else lc[10][j]
            if fr != 0:
                for k in range(6):
                    F[fr, k] += fk * lw[4][j, side, k]


@kernel(_nrt=False)
def wide_schur(lc, lw):
    """P = G E (symmetrised) of the wide rows and its pivoted Cholesky factor (rank and order in lw[11]);
    True unless a pivot is not finite."""
    E, P, nw = lw[7], lw[9], lc[17].shape[0]
    for a in range(nw):
        for b in range(nw):
            P[a, b] = wide_dot(lc, lw, a, E[b])
    for a in range(nw):
        for b in range(a):
            s = 0.5 * (P[a, b] + P[b, a])
            P[a, b] = s
            P[b, a] = s
        if not np.isfinite(P[a, a]):
            return False
    pivoted_chol(P, nw, lw[10], lw[11])
    return True


@kernel(_nrt=False)
def wide_correct(lc, lw, c_rows, x6, lam):
    """The bordered correction of a solve x6, lam with the other rows (module docstring): the wide rows'
    multipliers mu = P^-1 (G x6 - c_w) (zero beyond the rank), x6 -= E mu, lam -= EL mu, lam_w = mu."""
    perm, b, E, EL = lw[11], lw[12], lw[7], lw[8]
    nw = lc[17].shape[0]
    rank = perm[0]
    for a in range(nw):
        w = perm[1 + a]
        b[0, a] = wide_dot(lc, lw, w, x6) - c_rows[lc[0][lc[17][w]]] if a < rank else 0.0
    chol_solve(lw[10], 0, rank, b, 0)
    for a in range(nw):
        w = perm[1 + a]
        mu = b[0, a]
        lam[lc[0][lc[17][w]]] = mu
        if mu == 0.0:
            continue
        for f in range(x6.shape[0]):
            for k in range(6):
                x6[f, k] -= E[w, f, k] * mu
        for r in range(lam.shape[0]):
            lam[r] -= EL[w, r] * mu


@kernel(_nrt=False)
def wide_residual(lc, phi):
    """Largest |phi| [m or rad] of the wide rows (NaN wins)."""
    res = 0.0
    for a in range(lc[17].shape[0]):
        r = abs(phi[lc[0][lc[17][a]]])
        if not r <= res:
            res = r
    return res


@kernel(_nrt=False)
def wide_velocity_rhs(lc, lw, nu, v6, c):
    """c_w = nu - G v6 of the wide rows (the velocity projection's right-hand sides)."""
    for a in range(lc[17].shape[0]):
        row = lc[0][lc[17][a]]
        c[row] = nu[row] - wide_dot(lc, lw, a, v6)
