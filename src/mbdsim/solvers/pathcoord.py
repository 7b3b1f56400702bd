"""Point-on-curve (path) constraints on the absolute-coordinate core (numba), issue 29; formulation in
system.pathcoords (the two normal components of d = P_j - C_i(s*) solved, s* the foot point near the state's
s). pc = cm[49], pw = wk[51] (layouts in system.pathcoords). The rows' multipliers are written back as the
ground-axes components of the constraint force lambda_1 n1 + lambda_2 n2, as the reference path's x, y, z rows.
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from ..system.exprvm import eval_program
from ..system.kernels import _put, _sph_row, row_rate


@kernel(_nrt=False)
def _curve(pc, pw, p, s):
    """c, c', c'' of constraint p at parameter s in body-i axes into pw[8][p] (rows 0, 1, 2)."""
    x, stack, out = pw[0], pw[1], pw[8]
    if pc[13][p] == 1:
        _spline(pc, p, s, out)
    else:
        x[0] = s
        for m in range(3):
            for k in range(3):
                b = 9 * p + 3 * m + k
                out[p, m, k] = eval_program(pc[8], pc[9], pc[10], pc[11][b], pc[12][b], x, stack)
    A0T, r0 = pc[4], pc[5]
    for m in range(3):
        v0, v1, v2 = out[p, m, 0], out[p, m, 1], out[p, m, 2]
        if m == 0:
            v0, v1, v2 = v0 - r0[p, 0], v1 - r0[p, 1], v2 - r0[p, 2]
        for k in range(3):
            out[p, m, k] = A0T[p, k, 0] * v0 + A0T[p, k, 1] * v1 + A0T[p, k, 2] * v2


@kernel(_nrt=False)
def _spline(pc, p, s, out):
    """C, C', C'' [m, ground axes at t = 0] of constraint p's cubic spline at s into out[p] (rows 0, 1, 2): the
    segment found by bisection, the end segments extrapolated (a closed spline: s taken modulo its length)."""
    c0, c1 = pc[14][p], pc[14][p + 1]
    b0 = c0 + p
    br, cf = pc[15], pc[16]
    nseg = c1 - c0
    x0, xe = br[b0], br[b0 + nseg]
    if pc[17][p] == 1:
        s = x0 + (s - x0) % (xe - x0)
    lo, hi = 0, nseg - 1
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if br[b0 + mid] <= s:
            lo = mid
        else:
            hi = mid - 1
    i = c0 + lo
    u = s - br[b0 + lo]
    for k in range(3):
        a3, a2, a1, a0 = cf[i, 0, k], cf[i, 1, k], cf[i, 2, k], cf[i, 3, k]
        out[p, 0, k] = ((a3 * u + a2) * u + a1) * u + a0
        out[p, 1, k] = (3.0 * a3 * u + 2.0 * a2) * u + a1
        out[p, 2, k] = 6.0 * a3 * u + 2.0 * a2


@kernel(_nrt=False)
def _foot(pc, pw, p, r, A, s):
    """The foot point s* of P_j on the curve near s (Newton on c' . (c - P) = 0 in body-i axes, at most 8
    steps); leaves c, c', c'' at s* in pw[8][p]."""
    bi, bj, sj = pc[1][p], pc[2][p], pc[3]
    P = (r[bj, 0] + A[bj, 0, 0] * sj[p, 0] + A[bj, 0, 1] * sj[p, 1] + A[bj, 0, 2] * sj[p, 2],
                                   r[bj, 1] + A[bj, 1, 0] * sj[p, 0] + A[bj, 1, 1] * sj[p, 1] + A[bj, 1, 2] * sj[p, 2],
                                   r[bj, 2] + A[bj, 2, 0] * sj[p, 0] + A[bj, 2, 1] * sj[p, 1] + A[bj, 2, 2] * sj[p, 2])
    d0, d1, d2 = P[0] - r[bi, 0], P[1] - r[bi, 1], P[2] - r[bi, 2]
    Pi0 = A[bi, 0, 0] * d0 + A[bi, 1, 0] * d1 + A[bi, 2, 0] * d2   # body-i axes
    Pi1 = A[bi, 0, 1] * d0 + A[bi, 1, 1] * d1 + A[bi, 2, 1] * d2
    Pi2 = A[bi, 0, 2] * d0 + A[bi, 1, 2] * d1 + A[bi, 2, 2] * d2
    c = pw[8]
    for it in range(8):
        _curve(pc, pw, p, s)
        e0, e1, e2 = c[p, 0, 0] - Pi0, c[p, 0, 1] - Pi1, c[p, 0, 2] - Pi2
        g = c[p, 1, 0] * e0 + c[p, 1, 1] * e1 + c[p, 1, 2] * e2
        dg = (c[p, 1, 0] ** 2 + c[p, 1, 1] ** 2 + c[p, 1, 2] ** 2 + c[p, 2, 0] * e0 + c[p, 2, 1] * e1
              + c[p, 2, 2] * e2)
        if not dg > 0.0:
            break
        ds = -g / dg
        s += ds
        if abs(ds) <= 1e-15 * (1.0 + abs(s)):
            _curve(pc, pw, p, s)
            return s
    _curve(pc, pw, p, s)
    return s


@kernel(_nrt=False)
def path_rows(pc, pw, q, r, A, rd, w, rigid, phi, Jc, nu, gamma):
    """phi, Jc, nu, gamma of every path constraint's two normal rows (rows[:, 0:2]) and the tangential
    residual (rows[:, 2], no Jacobian) at the frames of the state with positions q (which holds s)."""
    rows, tbi, tbj, sjv = pc[0], pc[1], pc[2], pc[3]
    sst, sdv, F, tn, Jd, qd, c = pw[2], pw[3], pw[4], pw[5], pw[6], pw[7], pw[8]
    for p in range(rows.shape[0]):
        bi, bj = tbi[p], tbj[p]
        s = _foot(pc, pw, p, r, A, q[pc[6][p]])
        sst[p] = s
        ci = (c[p, 0, 0], c[p, 0, 1], c[p, 0, 2])
        sj = (sjv[p, 0], sjv[p, 1], sjv[p, 2])
        d = (0.0, 0.0, 0.0)
        dd0, dd1, dd2, q0, q1, q2 = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        for k in range(3):
            ph, Jri, Jpi, Jrj, Jpj, quad = _sph_row(k, r, A, w, bi, bj, ci, sj)
            _put(Jd[p], k, 0, bi, Jri, Jpi, A, rigid)
            _put(Jd[p], k, 1, bj, Jrj, Jpj, A, rigid)
            rate = row_rate(rd, w, bi, bj, Jri, Jpi, Jrj, Jpj)
            if k == 0:
                d, dd0, q0 = (ph, d[1], d[2]), rate, quad
            elif k == 1:
                d, dd1, q1 = (d[0], ph, d[2]), rate, quad
            else:
                d, dd2, q2 = (d[0], d[1], ph), rate, quad
        t0 = A[bi, 0, 0] * c[p, 1, 0] + A[bi, 0, 1] * c[p, 1, 1] + A[bi, 0, 2] * c[p, 1, 2]   # A_i c'
        t1 = A[bi, 1, 0] * c[p, 1, 0] + A[bi, 1, 1] * c[p, 1, 1] + A[bi, 1, 2] * c[p, 1, 2]
        t2 = A[bi, 2, 0] * c[p, 1, 0] + A[bi, 2, 1] * c[p, 1, 1] + A[bi, 2, 2] * c[p, 1, 2]
        u0 = A[bi, 0, 0] * c[p, 2, 0] + A[bi, 0, 1] * c[p, 2, 1] + A[bi, 0, 2] * c[p, 2, 2]   # A_i c''
        u1 = A[bi, 1, 0] * c[p, 2, 0] + A[bi, 1, 1] * c[p, 2, 1] + A[bi, 1, 2] * c[p, 2, 2]
        u2 = A[bi, 2, 0] * c[p, 2, 0] + A[bi, 2, 1] * c[p, 2, 1] + A[bi, 2, 2] * c[p, 2, 2]
        tt = t0 * t0 + t1 * t1 + t2 * t2
        sd = (t0 * dd0 + t1 * dd1 + t2 * dd2) / tt   # s' from d'|_s = t s'
        sdv[p] = sd
        wi0, wi1, wi2 = w[bi, 0], w[bi, 1], w[bi, 2]
        x0, x1, x2 = wi1 * t2 - wi2 * t1, wi2 * t0 - wi0 * t2, wi0 * t1 - wi1 * t0   # w_i x t
        qd[p, 0] = q0 - 2.0 * sd * x0 - sd * sd * u0
        qd[p, 1] = q1 - 2.0 * sd * x1 - sd * sd * u1
        qd[p, 2] = q2 - 2.0 * sd * x2 - sd * sd * u2
        n = np.sqrt(tt)
        tn[p] = n
        h0, h1, h2 = t0 / n, t1 / n, t2 / n
        a0, a1, a2 = abs(h0), abs(h1), abs(h2)   # perpendicular frame (math.rotation.perpendicular_frame)
        e0, e1, e2 = (1.0, 0.0, 0.0) if a0 <= a1 and a0 <= a2 else ((0.0, 1.0, 0.0) if a1 <= a2 else (0.0, 0.0, 1.0))
        f0, f1, f2 = e1 * h2 - e2 * h1, e2 * h0 - e0 * h2, e0 * h1 - e1 * h0
        fn = np.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
        f0, f1, f2 = f0 / fn, f1 / fn, f2 / fn
        g0, g1, g2 = h1 * f2 - h2 * f1, h2 * f0 - h0 * f2, h0 * f1 - h1 * f0
        F[p, 0, 0], F[p, 0, 1], F[p, 0, 2] = h0, h1, h2
        F[p, 1, 0], F[p, 1, 1], F[p, 1, 2] = f0, f1, f2
        F[p, 2, 0], F[p, 2, 1], F[p, 2, 2] = g0, g1, g2
        for a in range(3):   # rows 0, 1: n1 = f, n2 = g; row 2: the tangential residual
            row = rows[p, a]
            m = 1 + a if a < 2 else 0
            phi[row] = F[p, m, 0] * d[0] + F[p, m, 1] * d[1] + F[p, m, 2] * d[2]
            nu[row] = 0.0
            for side in range(2):
                for k in range(6):
                    Jc[row, side, k] = 0.0
                    if a < 2:
                        for kk in range(3):
                            Jc[row, side, k] += F[p, m, kk] * Jd[p, kk, side, k]
            gamma[row] = 0.0 if a == 2 else -(F[p, m, 0] * qd[p, 0] + F[p, m, 1] * qd[p, 1] + F[p, m, 2] * qd[p, 2])


@kernel(_nrt=False)
def _dvec(pc, pw, p, k, x6):
    """Row k of constraint p's Jacobian blocks times x6 (six slots per frame)."""
    s = 0.0
    for side in range(2):
        f = pc[1][p] if side == 0 else pc[2][p]
        if f != 0:
            for m in range(6):
                s += pw[6][p, k, side, m] * x6[f, m]
    return s


@kernel(_nrt=False)
def _along(pc, pw, p, x6, with_quad):
    """t . (J_d x6 (+ quad_d)) / |t|^2: the parameter's rate (or acceleration) for body rates x6."""
    F, tn, qd = pw[4], pw[5], pw[7]
    s = 0.0
    for k in range(3):
        u = _dvec(pc, pw, p, k, x6)
        if with_quad:
            u += qd[p, k]
        s += F[p, 0, k] * u
    return s / tn[p]


@kernel(_nrt=False)
def aux_rates(pc, pw, x6, vd, lam):
    """s'' into vd from the solved accelerations x6; the rows' multipliers as the ground-axes components
    lambda_1 n1 + lambda_2 n2 (the reference path's x, y, z rows)."""
    F, rows = pw[4], pc[0]
    for p in range(rows.shape[0]):
        vd[pc[7][p]] = _along(pc, pw, p, x6, True)
        l1, l2 = lam[rows[p, 0]], lam[rows[p, 1]]
        for k in range(3):
            lam[rows[p, k]] = l1 * F[p, 1, k] + l2 * F[p, 2, k]


@kernel(_nrt=False)
def aux_qdot(pc, pw, qd):
    """s' of every constraint into qd (positions' rates)."""
    for p in range(pc[0].shape[0]):
        qd[pc[6][p]] = pw[3][p]


@kernel(_nrt=False)
def sync_q(pc, pw, q):
    """s <- s*, the foot point of the last `path_rows` (after a converged position projection)."""
    for p in range(pc[0].shape[0]):
        q[pc[6][p]] = pw[2][p]


@kernel(_nrt=False)
def sync_v(pc, pw, v6, v):
    """s' <- t . d'|_s / |t|^2 at the projected velocities v6 (six slots per frame) into v."""
    for p in range(pc[0].shape[0]):
        v[pc[7][p]] = _along(pc, pw, p, v6, False)
