"""Compiled (numba) kernels of the constraint equations: `row_terms` is the one implementation of the
constraint primitives, evaluated row by row with scalar arithmetic, scattered straight into phi,
phi_q, nu, gamma by `rows_kernel`, or returned with ground-axes Jacobian rows by `ground_rows` (the
`constraints.primitives` API: measures, force elements, the rows of screw, constant-velocity, couplers
and path constraints, batched over time samples); tests/test_core_jacobians.py holds every row kind
against finite differences.  Row kinds: 0-2 spherical component x/y/z, 3 dot1, 4 dot2, 5 angle
(driver), 6 slide (driver), 7 screw, 8 constant velocity.  A row's vectors V[row] (up to six) are in
body axes, its parameter par[row] (see `system.packing.pack_rows`).
"""
from __future__ import annotations

import numpy as np

from numba import njit

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import entry, kernel  # noqa: F401  (njit without the wrappers that dominate compilation; issue 32)

KIND = {"dot1": 3, "dot2": 4, "angle": 5, "slide": 6, "screw": 7, "cvel": 8}


@kernel(_nrt=False)
def _mv(A, b, x):
    return (A[b, 0, 0] * x[0] + A[b, 0, 1] * x[1] + A[b, 0, 2] * x[2],
            A[b, 1, 0] * x[0] + A[b, 1, 1] * x[1] + A[b, 1, 2] * x[2],
            A[b, 2, 0] * x[0] + A[b, 2, 1] * x[1] + A[b, 2, 2] * x[2])

@kernel(_nrt=False)
def _cr(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])

@kernel(_nrt=False)
def _dt(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]

@kernel(_nrt=False)
def _add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])

@kernel(_nrt=False)
def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])

@kernel(_nrt=False)
def _sc(s, a):
    return (s * a[0], s * a[1], s * a[2])

@kernel(_nrt=False)
def _put(Jc, row, side, b, Jr, Jp, A, rigid):
    """Row coefficients of frame b (side 0: body_i, 1: body_j): translation, then body-axes rotation Jp A."""
    for k in range(6):
        Jc[row, side, k] = 0.0
    if b == 0:
        return
    Jc[row, side, 0] = Jr[0]
    Jc[row, side, 1] = Jr[1]
    Jc[row, side, 2] = Jr[2]
    if rigid[b]:
        for k in range(3):  # body axes: Jp A
            Jc[row, side, 3 + k] = Jp[0] * A[b, 0, k] + Jp[1] * A[b, 1, k] + Jp[2] * A[b, 2, k]

@kernel
def scatter_dense(Jc, bi_, bj_, vadr, rigid, J):
    """Dense phi_q (nc, nv) from the compact rows Jc (nc, 2, 6); J zeroed by the caller."""
    for row in range(Jc.shape[0]):
        for side in range(2):
            b = bi_[row] if side == 0 else bj_[row]
            if b == 0:
                continue
            c = vadr[b]
            n = 6 if rigid[b] else 3
            for k in range(n):
                J[row, c + k] += Jc[row, side, k]

@kernel(_nrt=False)
def _dot1(A, w, bi, bj, ai_B, aj_B):
    """a_i . a_j of unit vectors fixed on frames bi and bj (body axes ai_B, aj_B): (value, c = a_i x a_j
    (the ground-axes rotation row of bi; -c that of bj), quad, rate [1/s])."""
    ai = _mv(A, bi, ai_B)
    aj = _mv(A, bj, aj_B)
    wi = (w[bi, 0], w[bi, 1], w[bi, 2])
    wj = (w[bj, 0], w[bj, 1], w[bj, 2])
    c = _cr(ai, aj)
    wai, waj = _cr(wi, ai), _cr(wj, aj)
    quad = _dt(_cr(wi, wai), aj) + 2.0 * _dt(wai, waj) + _dt(ai, _cr(wj, waj))
    rate = _dt(c, wi) - _dt(c, wj)
    return _dt(ai, aj), c, quad, rate


@kernel(_nrt=False, inline="always")
def _sph_row(k, r, A, w, bi, bj, a, b):
    """Spherical row k (0, 1, 2): component k of P_j - P_i (a = s_i, b = s_j)."""
    wi = (w[bi, 0], w[bi, 1], w[bi, 2])
    wj = (w[bj, 0], w[bj, 1], w[bj, 2])
    si = _mv(A, bi, a)
    sj = _mv(A, bj, b)
    e = (1.0 if k == 0 else 0.0, 1.0 if k == 1 else 0.0, 1.0 if k == 2 else 0.0)
    # row k of the skew matrices: J_pi = e x s_i, J_pj = s_j x e
    return (r[bj, k] + sj[k] - r[bi, k] - si[k], _sc(-1.0, e), _cr(e, si), e, _cr(sj, e),
            _cr(wj, _cr(wj, sj))[k] - _cr(wi, _cr(wi, si))[k])


@kernel(_nrt=False, inline="always")
def _dot1_row(A, w, bi, bj, a, b):
    """dot1 row a_i . a_j (a = a_i, b = a_j)."""
    val, cc, quad, _ = _dot1(A, w, bi, bj, a, b)
    return val, (0.0, 0.0, 0.0), cc, (0.0, 0.0, 0.0), _sc(-1.0, cc), quad


@kernel(_nrt=False, inline="always")
def _dot2_row(r, A, rd, w, bi, bj, a, b, c):
    """dot2 row a_i . (P_j - P_i) (a = a_i, b = s_i, c = s_j)."""
    wi = (w[bi, 0], w[bi, 1], w[bi, 2])
    wj = (w[bj, 0], w[bj, 1], w[bj, 2])
    ai = _mv(A, bi, a)
    si = _mv(A, bi, b)
    sj = _mv(A, bj, c)
    d = _sub(_add((r[bj, 0], r[bj, 1], r[bj, 2]), sj), _add((r[bi, 0], r[bi, 1], r[bi, 2]), si))
    dd = _sub(_add((rd[bj, 0], rd[bj, 1], rd[bj, 2]), _cr(wj, sj)),
              _add((rd[bi, 0], rd[bi, 1], rd[bi, 2]), _cr(wi, si)))
    wai = _cr(wi, ai)
    quad = (_dt(_cr(wi, wai), d) + 2.0 * _dt(wai, dd)
            + _dt(ai, _sub(_cr(wj, _cr(wj, sj)), _cr(wi, _cr(wi, si)))))
    return _dt(ai, d), _sc(-1.0, ai), _cr(ai, _add(d, si)), ai, _cr(sj, ai), quad


@kernel(_nrt=False, inline="always")
def _angle_row(A, w, bi, bj, a, b, c):
    """Angle row atan2(g_i . f_j, f_i . f_j) (a = f_i, b = g_i, c = f_j)."""
    S, cS, qS, Sd = _dot1(A, w, bi, bj, b, c)
    C, cC, qC, Cd = _dot1(A, w, bi, bj, a, c)
    rho2 = S * S + C * C
    N = C * Sd - S * Cd
    Jp = _sc(1.0 / rho2, _sub(_sc(C, cS), _sc(S, cC)))
    quad = (C * qS - S * qC) / rho2 - N * (2.0 * S * Sd + 2.0 * C * Cd) / (rho2 * rho2)
    return np.arctan2(S, C), (0.0, 0.0, 0.0), Jp, (0.0, 0.0, 0.0), _sc(-1.0, Jp), quad


@kernel(_nrt=False, inline="always")
def _screw_row(r, A, rd, w, bi, bj, V, c):
    """Screw row c wrap(s / c - theta): s = h_i . (P_j - P_i), theta the angle of j about h_i (V: f_i, g_i,
    f_j, h_i, s_i, s_j; c = lead / 2 pi [m/rad]); J = J_s - c J_theta, quad = quad_s - c quad_theta."""
    s, sri, spi, srj, spj, sq = _dot2_row(r, A, rd, w, bi, bj, V[3], V[4], V[5])
    th, tri, tpi, trj, tpj, tq = _angle_row(A, w, bi, bj, V[0], V[1], V[2])
    x = s / c - th
    return (c * ((x + np.pi) % (2.0 * np.pi) - np.pi), _sub(sri, _sc(c, tri)), _sub(spi, _sc(c, tpi)),
            _sub(srj, _sc(c, trj)), _sub(spj, _sc(c, tpj)), sq - c * tq)


@kernel(_nrt=False, inline="always")
def _cvel_row(A, w, bi, bj, V):
    """Constant-velocity row f_i . g_j - g_i . f_j (V: f_i, g_i, f_j, g_j)."""
    a, _, api, _, apj, aq = _dot1_row(A, w, bi, bj, V[0], V[3])
    b, _, bpi, _, bpj, bq = _dot1_row(A, w, bi, bj, V[1], V[2])
    zero = (0.0, 0.0, 0.0)
    return a - b, zero, _sub(api, bpi), zero, _sub(apj, bpj), aq - bq


@kernel(_nrt=False)
def row_terms(k, r, A, rd, w, bi, bj, V, p):
    """One constraint row of kind k between frames bi and bj, the single implementation of Haug's basic
    constraints (every evaluation goes through it or, in `rows_kernel`'s loop, through the same
    per-kind functions): (phi, J_ri, J_pi, J_rj, J_pj, quad) with the Jacobian rows on each frame's CM
    translation [m] and ground-axes virtual rotation [rad], and quad the velocity term of phi's second
    derivative (phi_dd = J vd + quad; gamma = -quad).  V: the row's vectors (rows of V, body axes); p:
    its parameter:
      k = 0, 1, 2  spherical, component k of P_j - P_i [m] (V: s_i, s_j: points from the CMs)
      k = 3        dot1: a_i . a_j (V: a_i, a_j; unit vectors)
      k = 4, 6     dot2: a_i . (P_j - P_i) [m] (V: a_i, s_i, s_j); 6 is a slide driver's row
      k = 5        angle of j about f_i x g_i, atan2(g_i . f_j, f_i . f_j) [rad] in (-pi, pi]
                   (V: f_i, g_i, f_j); an angle driver's row before its target is taken off
      k = 7        screw: p wrap(s / p - theta) [m], s the dot2 slide along h_i, theta the angle
                   (V: f_i, g_i, f_j, h_i, s_i, s_j; p = lead / 2 pi [m/rad])
      k = 8        constant velocity: f_i . g_j - g_i . f_j (V: f_i, g_i, f_j, g_j)"""
    if k <= 2:
        return _sph_row(k, r, A, w, bi, bj, V[0], V[1])
    if k == 3:
        return _dot1_row(A, w, bi, bj, V[0], V[1])
    if k == 4 or k == 6:
        return _dot2_row(r, A, rd, w, bi, bj, V[0], V[1], V[2])
    if k == 5:
        return _angle_row(A, w, bi, bj, V[0], V[1], V[2])
    if k == 7:
        return _screw_row(r, A, rd, w, bi, bj, V, p)
    return _cvel_row(A, w, bi, bj, V)


@kernel(_nrt=False)
def row_rate(rd, w, bi, bj, Jri, Jpi, Jrj, Jpj):
    """phi's rate J v of a row [its unit / s] (no explicit time term) from its Jacobian rows."""
    return (_dt(Jri, (rd[bi, 0], rd[bi, 1], rd[bi, 2])) + _dt(Jpi, (w[bi, 0], w[bi, 1], w[bi, 2]))
            + _dt(Jrj, (rd[bj, 0], rd[bj, 1], rd[bj, 2])) + _dt(Jpj, (w[bj, 0], w[bj, 1], w[bj, 2])))


@kernel(_nrt=False)
def rows_kernel(r, A, rd, w, kind, bi_, bj_, V, par, drv, f, fd, fdd, rigid, phi, Jc, nu, gamma):
    """Fill phi, the compact Jacobian rows Jc (nc, 2, 6), nu and gamma for every row (`row_terms`, the
    drivers' targets f(t) [m or rad] and their rates taken off; V (nc, 6, 3) the rows' vectors, par
    (nc,) their parameters); the kinds are dispatched here with each kind's function inlined by numba
    (inline="always") and its rows stored in its own branch, where the zero and unit entries fold:
    calling `row_terms` per row, or storing after the branches, took 25-35 % longer (measured on the
    slider-crank's Jacobians).

    Jc[row, 0] holds the row's coefficients on body_i's velocity variables (CM velocity [m/s],
    body-axes angular velocity [rad/s]), Jc[row, 1] those on body_j's (zero for ground)."""
    for row in range(kind.shape[0]):
        k = kind[row]
        bi, bj = bi_[row], bj_[row]
        Vr = V[row]
        nu[row] = 0.0
        if k <= 2:
            ph, Jri, Jpi, Jrj, Jpj, quad = _sph_row(k, r, A, w, bi, bj, Vr[0], Vr[1])
            _put(Jc, row, 0, bi, Jri, Jpi, A, rigid)
            _put(Jc, row, 1, bj, Jrj, Jpj, A, rigid)
            phi[row] = ph
            gamma[row] = -quad
        elif k == 3:
            ph, Jri, Jpi, Jrj, Jpj, quad = _dot1_row(A, w, bi, bj, Vr[0], Vr[1])
            _put(Jc, row, 0, bi, Jri, Jpi, A, rigid)
            _put(Jc, row, 1, bj, Jrj, Jpj, A, rigid)
            phi[row] = ph
            gamma[row] = -quad
        elif k == 4 or k == 6:
            ph, Jri, Jpi, Jrj, Jpj, quad = _dot2_row(r, A, rd, w, bi, bj, Vr[0], Vr[1], Vr[2])
            _put(Jc, row, 0, bi, Jri, Jpi, A, rigid)
            _put(Jc, row, 1, bj, Jrj, Jpj, A, rigid)
            phi[row] = ph
            gamma[row] = -quad
        elif k == 5:
            ph, Jri, Jpi, Jrj, Jpj, quad = _angle_row(A, w, bi, bj, Vr[0], Vr[1], Vr[2])
            _put(Jc, row, 0, bi, Jri, Jpi, A, rigid)
            _put(Jc, row, 1, bj, Jrj, Jpj, A, rigid)
            phi[row] = ph
            gamma[row] = -quad
        elif k == 7:
            ph, Jri, Jpi, Jrj, Jpj, quad = _screw_row(r, A, rd, w, bi, bj, Vr, par[row])
            _put(Jc, row, 0, bi, Jri, Jpi, A, rigid)
            _put(Jc, row, 1, bj, Jrj, Jpj, A, rigid)
            phi[row] = ph
            gamma[row] = -quad
        else:
            ph, Jri, Jpi, Jrj, Jpj, quad = _cvel_row(A, w, bi, bj, Vr)
            _put(Jc, row, 0, bi, Jri, Jpi, A, rigid)
            _put(Jc, row, 1, bj, Jrj, Jpj, A, rigid)
            phi[row] = ph
            gamma[row] = -quad
        if k == 5 or k == 6:   # drivers: phi - f(t), nu = f'(t), gamma + f''(t); an angle's difference wrapped
            n = drv[row]
            if k == 5:
                phi[row] = (phi[row] - f[n] + np.pi) % (2.0 * np.pi) - np.pi
            else:
                phi[row] -= f[n]
            nu[row] = fd[n]
            gamma[row] += fdd[n]


@entry(_nrt=False)
def ground_rows(kind, r, A, rd, w, bi_, bj_, V, par, phi, Jri, Jpi, Jrj, Jpj, quad, rate):
    """`row_terms` of every row with its Jacobian rows in ground axes (Jri, Jpi, Jrj, Jpj: (n, 3)) and
    its rate J v: the rows of `constraints.primitives` (frames may carry time samples flattened into
    the frame axis; V (n, 6, 3) and par (n,) as in `rows_kernel`)."""
    for row in range(kind.shape[0]):
        bi, bj = bi_[row], bj_[row]
        ph, a, b, c, d, qd = row_terms(kind[row], r, A, rd, w, bi, bj, V[row], par[row])
        phi[row] = ph
        quad[row] = qd
        for m in range(3):
            Jri[row, m], Jpi[row, m], Jrj[row, m], Jpj[row, m] = a[m], b[m], c[m], d[m]
        rate[row] = row_rate(rd, w, bi, bj, a, b, c, d)


@entry
def constraint_kernel(r, A, rd, w, kind, bi_, bj_, V, par, drv, f, fd, fdd, vadr, rigid,
                      phi, J, nu, gamma):
    """Fill phi, the dense J (nc, nv; zeroed by the caller), nu, gamma for every row."""
    Jc = np.empty((kind.shape[0], 2, 6))
    rows_kernel(r, A, rd, w, kind, bi_, bj_, V, par, drv, f, fd, fdd, rigid, phi, Jc, nu, gamma)
    scatter_dense(Jc, bi_, bj_, vadr, rigid, J)


@entry
def jacobian_batch(Q, r_idx, p_idx, rd_idx, w_idx, rigid_fid, nf, kind, bi_, bj_, V, par, drv, nd, vadr,
                   rigid, nv):
    """Constraint Jacobians phi_q (N, nc, nv) at the position samples Q (N, nq); phi_q does not depend on
    the velocities or on the driver values (those enter phi, nu and gamma only)."""
    N, nc = Q.shape[0], kind.shape[0]
    out = np.zeros((N, nc, nv))
    r, A, rd, w = np.zeros((nf, 3)), np.zeros((nf, 3, 3)), np.zeros((nf, 3)), np.zeros((nf, 3))
    v0 = np.zeros(nv)
    z = np.zeros(max(nd, 1))
    phi, nu, gamma, Jc = np.zeros(nc), np.zeros(nc), np.zeros(nc), np.zeros((nc, 2, 6))
    for n in range(N):
        frames_into(Q[n], v0, r_idx, p_idx, rd_idx, w_idx, rigid_fid, r, A, rd, w)
        rows_kernel(r, A, rd, w, kind, bi_, bj_, V, par, drv, z, z, z, rigid, phi, Jc, nu, gamma)
        scatter_dense(Jc, bi_, bj_, vadr, rigid, out[n])
    return out


@entry
def jacobian_blocks(R, A, kind, bi_, bj_, V, par, drv, nd, rigid):
    """Compact Jacobian rows Jc (N, nr, 2, 6) of the rows given (kind ... drv sliced to them; column block
    0 on frame bi_, 1 on bj_, in the velocity variables' axes as `scatter_dense` places them) at the
    frames R (N, nf, 3), A (N, nf, 3, 3): O(N nr), whatever the size of the system (the reactions of
    one joint of a 10,000-body chain do not build its 60,000-column Jacobian)."""
    N, nr, nf = R.shape[0], kind.shape[0], R.shape[1]
    out = np.zeros((N, nr, 2, 6))
    rd, w = np.zeros((nf, 3)), np.zeros((nf, 3))
    z = np.zeros(max(nd, 1))
    phi, nu, gamma = np.zeros(nr), np.zeros(nr), np.zeros(nr)
    for n in range(N):
        rows_kernel(R[n], A[n], rd, w, kind, bi_, bj_, V, par, drv, z, z, z, rigid, phi, out[n], nu, gamma)
    return out


@kernel(_nrt=False)
def frames_into(q, v, r_idx, p_idx, rd_idx, w_idx, rigid_fid, r, A, rd, w):
    """Frames of one state into r, A, rd, w (nf, ...), ground axes; ground (0) at rest at the origin."""
    nf = r.shape[0]
    for f in range(nf):
        for c in range(3):
            r[f, c] = 0.0
            rd[f, c] = 0.0
            w[f, c] = 0.0
            for d in range(3):
                A[f, c, d] = 1.0 if c == d else 0.0
    for k in range(r_idx.shape[0]):
        for c in range(3):
            r[k + 1, c] = q[r_idx[k, c]]
            rd[k + 1, c] = v[rd_idx[k, c]]
    for k in range(rigid_fid.shape[0]):
        f = rigid_fid[k]
        e0, e1, e2, e3 = q[p_idx[k, 0]], q[p_idx[k, 1]], q[p_idx[k, 2]], q[p_idx[k, 3]]
        n = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2 + e3 * e3)
        e0, e1, e2, e3 = e0 / n, e1 / n, e2 / n, e3 / n
        A[f, 0, 0] = e0 * e0 + e1 * e1 - e2 * e2 - e3 * e3
        A[f, 0, 1] = 2 * (e1 * e2 - e0 * e3)
        A[f, 0, 2] = 2 * (e1 * e3 + e0 * e2)
        A[f, 1, 0] = 2 * (e1 * e2 + e0 * e3)
        A[f, 1, 1] = e0 * e0 - e1 * e1 + e2 * e2 - e3 * e3
        A[f, 1, 2] = 2 * (e2 * e3 - e0 * e1)
        A[f, 2, 0] = 2 * (e1 * e3 - e0 * e2)
        A[f, 2, 1] = 2 * (e2 * e3 + e0 * e1)
        A[f, 2, 2] = e0 * e0 - e1 * e1 - e2 * e2 + e3 * e3
        for c in range(3):
            w[f, c] = (A[f, c, 0] * v[w_idx[k, 0]] + A[f, c, 1] * v[w_idx[k, 1]]
                       + A[f, c, 2] * v[w_idx[k, 2]])

@entry
def frames_kernel(q, v, r_idx, p_idx, rd_idx, w_idx, rigid_fid, nf):
    """Single-state frames: r, A, rd, w (ground axes) of all nf frames (ground = 0)."""
    r = np.zeros((nf, 3))
    A = np.zeros((nf, 3, 3))
    rd = np.zeros((nf, 3))
    w = np.zeros((nf, 3))
    frames_into(q, v, r_idx, p_idx, rd_idx, w_idx, rigid_fid, r, A, rd, w)
    return r, A, rd, w


@kernel(_nrt=False)
def quat_step(q, p_idx, k, x, y, z):
    """Euler parameters p_idx[k] of q <- p (x) exp((x, y, z) / 2), normalised, in place: the rotation by
    the body-axes rotation vector (x, y, z) [rad] applied on the right."""
    ang = np.sqrt(x * x + y * y + z * z)
    c0 = np.cos(0.5 * ang)
    s = np.sin(0.5 * ang) / ang if ang > 1e-8 else 0.5 - ang * ang / 48.0
    b0, b1, b2, b3 = c0, s * x, s * y, s * z
    a0, a1, a2, a3 = q[p_idx[k, 0]], q[p_idx[k, 1]], q[p_idx[k, 2]], q[p_idx[k, 3]]
    p0 = a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3
    p1 = a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2
    p2 = a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1
    p3 = a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0
    n = np.sqrt(p0 * p0 + p1 * p1 + p2 * p2 + p3 * p3)
    q[p_idx[k, 0]], q[p_idx[k, 1]], q[p_idx[k, 2]], q[p_idx[k, 3]] = p0 / n, p1 / n, p2 / n, p3 / n


@entry
def increment_kernel(q, dx, r_idx, rd_idx, p_idx, w_idx):
    """q (+) dx: CM translations plus p <- p (x) exp(dx_w / 2) for body-axes rotation vectors."""
    out = q.copy()
    for k in range(r_idx.shape[0]):
        for c in range(3):
            out[r_idx[k, c]] += dx[rd_idx[k, c]]
    for k in range(p_idx.shape[0]):
        quat_step(out, p_idx, k, dx[w_idx[k, 0]], dx[w_idx[k, 1]], dx[w_idx[k, 2]])
    return out


@entry
def qdot_kernel(q, v, r_idx, rd_idx, p_idx, w_idx, nq):
    """dq/dt: rd for CM positions, pdot = 1/2 p (x) (0, w_B) for Euler parameters."""
    qd = np.zeros(nq)
    for k in range(r_idx.shape[0]):
        for c in range(3):
            qd[r_idx[k, c]] = v[rd_idx[k, c]]
    for k in range(p_idx.shape[0]):
        e0, e1, e2, e3 = q[p_idx[k, 0]], q[p_idx[k, 1]], q[p_idx[k, 2]], q[p_idx[k, 3]]
        x, y, z = v[w_idx[k, 0]], v[w_idx[k, 1]], v[w_idx[k, 2]]
        qd[p_idx[k, 0]] = 0.5 * (-e1 * x - e2 * y - e3 * z)
        qd[p_idx[k, 1]] = 0.5 * (e0 * x + e2 * z - e3 * y)
        qd[p_idx[k, 2]] = 0.5 * (e0 * y - e1 * z + e3 * x)
        qd[p_idx[k, 3]] = 0.5 * (e0 * z + e1 * y - e2 * x)
    return qd


@entry
def inertial_forces_kernel(A, w, mass, inertia_B, rd_idx, w_idx, rigid_fid, g, nv):
    """Q (nv,) of gravity m g on every CM and the gyroscopic term -w_B x (J w_B) (body axes)."""
    Q = np.zeros(nv)
    for k in range(rd_idx.shape[0]):
        for c in range(3):
            Q[rd_idx[k, c]] += mass[k + 1] * g[c]
    for k in range(rigid_fid.shape[0]):
        f = rigid_fid[k]
        wb = np.zeros(3)
        for i in range(3):
            wb[i] = A[f, 0, i] * w[f, 0] + A[f, 1, i] * w[f, 1] + A[f, 2, i] * w[f, 2]
        h = np.zeros(3)   # J_B w_B by hand: numba's `@` calls scipy's BLAS (loading scipy.linalg mid-run)
        for i in range(3):
            h[i] = inertia_B[f, i, 0] * wb[0] + inertia_B[f, i, 1] * wb[1] + inertia_B[f, i, 2] * wb[2]
        Q[w_idx[k, 0]] -= wb[1] * h[2] - wb[2] * h[1]
        Q[w_idx[k, 1]] -= wb[2] * h[0] - wb[0] * h[2]
        Q[w_idx[k, 2]] -= wb[0] * h[1] - wb[1] * h[0]
    return Q
