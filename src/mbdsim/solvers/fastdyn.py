"""Compiled equations of motion: right-hand side, projections and accelerations at one state (numba).

State y = [q, v] (system layout, docs/theory.md section 1). Every kernel takes the immutable compiled
model `cm` (a tuple of arrays, `system.compiled.CompiledModel.arrays()`) and a per-run work tuple `wk`
(`system.compiled.Work.arrays()`); see those for the field order. Loads and solves use six slots per
frame: CM translation in ground axes [N, m/s^2], rotation in body axes [N m, rad/s^2].
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)

try:   # the expression VM (system.exprvm) compiles drivers; without it drivers stay in Python
    from ..system.exprvm import eval_program
    HAVE_VM = True
except ImportError:   # pragma: no cover - transitional, until system.exprvm lands
    HAVE_VM = False

    @njit(cache=True, _nrt=False)
    def eval_program(code, consts, tables, start, end, x, stack):
        return 0.0
from ..system.exprloads_kernel import _cross as _cross_into, _force as _point_force, _rot, expr_loads
from ..system.kernels import frames_into, quat_step, rows_kernel
from .kkt_square import square_factor, square_solve
from .kkt_tree import _row_dot, dense_factor, dense_solve, kkt_factor, kkt_solve
from . import fasttree

OK, SINGULAR, PROJECTION, NONFINITE, TINY_STEP, MAX_STEPS, STIFF, INTERRUPTED = 0, 1, 2, 3, 4, 5, 6, 7


@njit(cache=True, _nrt=False)
def drivers_at(cm, wk, t):
    """Driver values f, f', f'' at time t [s] from the compiled expression programs."""
    code, consts, tables, start, end = cm[16], cm[17], cm[18], cm[19], cm[20]
    fv, x, stack = (wk[34], wk[35], wk[36]), wk[23], wk[24]
    nd = start.shape[0] // 3
    x[0] = t
    for d in range(nd):
        for k in range(3):
            p = 3 * d + k
            fv[k][d] = eval_program(code, consts, tables, start[p], end[p], x, stack)


@njit(cache=True, _nrt=False)
def loads_into(cm, wk, t, y, r, A, rd, w, F):
    """Gravity, gyroscopic torques, constant point forces/torques, linear spring-dampers, bushings and the
    loads written as expressions (system.exprloads_kernel; at time t [s], y: the joint-coordinate state on
    the tree path) into F."""
    loads_kernel(cm[9], cm[10], cm[8], cm[6], cm[21], cm[22], cm[23], cm[24], cm[25], cm[26], cm[27], cm[28],
                 cm[29], r, A, rd, w, F)
    if cm[36].shape[0]:
        bushings_kernel(cm[36], cm[37], cm[38], cm[39], cm[40], cm[41], r, A, rd, w, cm[6], F, wk[42][0],
                        wk[42][1])
    if cm[43][7].shape[0]:
        expr_loads(cm[43], wk[44], t, y, r, A, rd, w, cm[6], F)
    if cm[44][0].shape[0]:
        ct = cm[44]
        contacts_kernel(ct[0], ct[1], ct[2], ct[3], ct[4], r, A, rd, w, cm[6], F)


@njit(cache=True, _nrt=False)
def _centre(r, A, f, s):
    """Ground position [m] of the body-axes point s of frame f."""
    return (r[f, 0] + A[f, 0, 0] * s[0] + A[f, 0, 1] * s[1] + A[f, 0, 2] * s[2],
            r[f, 1] + A[f, 1, 0] * s[0] + A[f, 1, 1] * s[1] + A[f, 1, 2] * s[2],
            r[f, 2] + A[f, 2, 0] * s[0] + A[f, 2, 1] * s[1] + A[f, 2, 2] * s[2])


@njit(cache=True, _nrt=False)
def contacts_kernel(ct_f, ct_kind, ct_s, ct_n, ct_par, r, A, rd, w, rigid, F):
    """Compliant contacts (system.force_elements.contact) into F: signed gap g [m] between the shapes, normal
    n from body_i's shape towards body_j's, contact point cp in the middle of the overlap; while g < 0 the
    Adams IMPACT normal force max(0, k delta^e - STEP(delta, 0, 0, d, c_max) g_dot) along n and the
    regularised Coulomb friction -mu Fn v_t / sqrt(|v_t|^2 + v_s^2) (v_t: the tangential part of the
    relative velocity of the material points at cp) act on body_j at cp, their opposite on body_i.
    Arrays of `system.compiled._contacts`; frames r, A, rd, w (w in ground axes)."""
    for c in range(ct_f.shape[0]):
        fi, fj, kind = ct_f[c, 0], ct_f[c, 1], ct_kind[c]
        Ri, Rj, k, ex, cmax, dpen, mu, vs = (ct_par[c, 0], ct_par[c, 1], ct_par[c, 2], ct_par[c, 3],
                                            ct_par[c, 4], ct_par[c, 5], ct_par[c, 6], ct_par[c, 7])
        if kind == 0:   # sphere-sphere: along the line of centres
            a0, a1, a2 = _centre(r, A, fi, ct_s[c, 0])
            b0, b1, b2 = _centre(r, A, fj, ct_s[c, 1])
            d0, d1, d2 = b0 - a0, b1 - a1, b2 - a2
            L = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            inv = 1.0 / L if L > 0.0 else 1.0
            n0, n1, n2 = d0 * inv, d1 * inv, d2 * inv
            g = L - Ri - Rj
            if not g < 0.0:
                continue
            h = Ri + 0.5 * g
            p0, p1, p2 = a0 + h * n0, a1 + h * n1, a2 + h * n2
        else:           # sphere-plane: along the plane's normal
            fs, fp, R, sign = (fj, fi, Rj, 1.0) if kind == 1 else (fi, fj, Ri, -1.0)
            ss, sp = (ct_s[c, 1], ct_s[c, 0]) if kind == 1 else (ct_s[c, 0], ct_s[c, 1])
            c0, c1, c2 = _centre(r, A, fs, ss)
            q0, q1, q2 = _centre(r, A, fp, sp)
            m0, m1, m2 = _rot(A, fp, ct_n[c, 0], ct_n[c, 1], ct_n[c, 2])
            g = m0 * (c0 - q0) + m1 * (c1 - q1) + m2 * (c2 - q2) - R
            if not g < 0.0:
                continue
            h = R + 0.5 * g
            p0, p1, p2 = c0 - h * m0, c1 - h * m1, c2 - h * m2
            n0, n1, n2 = sign * m0, sign * m1, sign * m2
        # relative velocity of the material points at cp (body_j minus body_i)
        x0, x1, x2 = _cross_into(w[fj, 0], w[fj, 1], w[fj, 2], p0 - r[fj, 0], p1 - r[fj, 1], p2 - r[fj, 2])
        y0, y1, y2 = _cross_into(w[fi, 0], w[fi, 1], w[fi, 2], p0 - r[fi, 0], p1 - r[fi, 1], p2 - r[fi, 2])
        v0 = rd[fj, 0] + x0 - rd[fi, 0] - y0
        v1 = rd[fj, 1] + x1 - rd[fi, 1] - y1
        v2 = rd[fj, 2] + x2 - rd[fi, 2] - y2
        gd = n0 * v0 + n1 * v1 + n2 * v2
        delta = -g
        u = min(delta / dpen, 1.0)
        Fn = max(k * delta ** ex - cmax * u * u * (3.0 - 2.0 * u) * gd, 0.0)
        t0, t1, t2 = v0 - gd * n0, v1 - gd * n1, v2 - gd * n2
        mf = mu * Fn / np.sqrt(t0 * t0 + t1 * t1 + t2 * t2 + vs * vs) if mu > 0.0 else 0.0
        G0, G1, G2 = Fn * n0 - mf * t0, Fn * n1 - mf * t1, Fn * n2 - mf * t2
        _point_force(F, A, fj, p0 - r[fj, 0], p1 - r[fj, 1], p2 - r[fj, 2], G0, G1, G2, rigid)
        _point_force(F, A, fi, p0 - r[fi, 0], p1 - r[fi, 1], p2 - r[fi, 2], -G0, -G1, -G2, rigid)


@njit(cache=True, _nrt=False)
def _rotT(A, f, x0, x1, x2):
    """A[f]^T x (ground -> body axes)."""
    return (A[f, 0, 0] * x0 + A[f, 1, 0] * x1 + A[f, 2, 0] * x2,
            A[f, 0, 1] * x0 + A[f, 1, 1] * x1 + A[f, 2, 1] * x2,
            A[f, 0, 2] * x0 + A[f, 1, 2] * x1 + A[f, 2, 2] * x2)


@njit(cache=True, _nrt=False)
def loads_kernel(mass, inertia, gravity, rigid, pf_f, pf_s, pf_v, pf_ff, pf_R, pf_torque, sp_f, sp_s, sp_par,
                 r, A, rd, w, F):
    """Loads of `loads_into` with explicit arrays (six slots per frame); no allocation."""
    nf = F.shape[0]
    for f in range(nf):
        for k in range(6):
            F[f, k] = 0.0
    for f in range(1, nf):
        for k in range(3):
            F[f, k] = mass[f] * gravity[k]
        if rigid[f]:
            b0, b1, b2 = _rotT(A, f, w[f, 0], w[f, 1], w[f, 2])
            h0 = inertia[f, 0, 0] * b0 + inertia[f, 0, 1] * b1 + inertia[f, 0, 2] * b2
            h1 = inertia[f, 1, 0] * b0 + inertia[f, 1, 1] * b1 + inertia[f, 1, 2] * b2
            h2 = inertia[f, 2, 0] * b0 + inertia[f, 2, 1] * b1 + inertia[f, 2, 2] * b2
            c0, c1, c2 = _cross_into(b0, b1, b2, h0, h1, h2)
            F[f, 3] -= c0
            F[f, 4] -= c1
            F[f, 5] -= c2
    for e in range(pf_f.shape[0]):   # constant vector loads, axes of frame pf_ff (R: marker in body)
        f, ff = pf_f[e], pf_ff[e]
        if f == 0:
            continue
        l0 = pf_R[e, 0, 0] * pf_v[e, 0] + pf_R[e, 0, 1] * pf_v[e, 1] + pf_R[e, 0, 2] * pf_v[e, 2]
        l1 = pf_R[e, 1, 0] * pf_v[e, 0] + pf_R[e, 1, 1] * pf_v[e, 1] + pf_R[e, 1, 2] * pf_v[e, 2]
        l2 = pf_R[e, 2, 0] * pf_v[e, 0] + pf_R[e, 2, 1] * pf_v[e, 1] + pf_R[e, 2, 2] * pf_v[e, 2]
        G0, G1, G2 = _rot(A, ff, l0, l1, l2)
        if pf_torque[e]:
            if rigid[f]:
                t0, t1, t2 = _rotT(A, f, G0, G1, G2)
                F[f, 3] += t0
                F[f, 4] += t1
                F[f, 5] += t2
        else:
            s0, s1, s2 = _rot(A, f, pf_s[e, 0], pf_s[e, 1], pf_s[e, 2])
            _point_force(F, A, f, s0, s1, s2, G0, G1, G2, rigid)
    for e in range(sp_f.shape[0]):   # spring-dampers: tension k (L - L0) + c dL/dt + preload
        fi, fj = sp_f[e, 0], sp_f[e, 1]
        si0, si1, si2 = _rot(A, fi, sp_s[e, 0, 0], sp_s[e, 0, 1], sp_s[e, 0, 2])
        sj0, sj1, sj2 = _rot(A, fj, sp_s[e, 1, 0], sp_s[e, 1, 1], sp_s[e, 1, 2])
        vi0, vi1, vi2 = _cross_into(w[fi, 0], w[fi, 1], w[fi, 2], si0, si1, si2)
        vj0, vj1, vj2 = _cross_into(w[fj, 0], w[fj, 1], w[fj, 2], sj0, sj1, sj2)
        d0 = r[fj, 0] + sj0 - r[fi, 0] - si0
        d1 = r[fj, 1] + sj1 - r[fi, 1] - si1
        d2 = r[fj, 2] + sj2 - r[fi, 2] - si2
        e0 = rd[fj, 0] + vj0 - rd[fi, 0] - vi0
        e1 = rd[fj, 1] + vj1 - rd[fi, 1] - vi1
        e2 = rd[fj, 2] + vj2 - rd[fi, 2] - vi2
        L = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        inv = 1.0 / L if L > 0 else 0.0
        Ld = (d0 * e0 + d1 * e1 + d2 * e2) * inv
        T = sp_par[e, 0] * (L - sp_par[e, 2]) + sp_par[e, 1] * Ld + sp_par[e, 3]
        u0, u1, u2 = d0 * inv * T, d1 * inv * T, d2 * inv * T
        _point_force(F, A, fi, si0, si1, si2, u0, u1, u2, rigid)
        _point_force(F, A, fj, sj0, sj1, sj2, -u0, -u1, -u2, rigid)


@njit(cache=True, _nrt=False)
def _rotvec(r00, r01, r02, r10, r11, r12, r20, r21, r22):
    """Rotation vector [rad] of a rotation matrix (angle in [0, pi]), via the unit quaternion."""
    tr = r00 + r11 + r22
    if tr > 0.0:
        s = 2.0 * np.sqrt(tr + 1.0)
        w, x, y, z = 0.25 * s, (r21 - r12) / s, (r02 - r20) / s, (r10 - r01) / s
    elif r00 > r11 and r00 > r22:
        s = 2.0 * np.sqrt(1.0 + r00 - r11 - r22)
        w, x, y, z = (r21 - r12) / s, 0.25 * s, (r01 + r10) / s, (r02 + r20) / s
    elif r11 > r22:
        s = 2.0 * np.sqrt(1.0 + r11 - r00 - r22)
        w, x, y, z = (r02 - r20) / s, (r01 + r10) / s, 0.25 * s, (r12 + r21) / s
    else:
        s = 2.0 * np.sqrt(1.0 + r22 - r00 - r11)
        w, x, y, z = (r10 - r01) / s, (r02 + r20) / s, (r12 + r21) / s, 0.25 * s
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    n = np.sqrt(x * x + y * y + z * z)
    if n < 1e-300:
        return 0.0, 0.0, 0.0
    ang = 2.0 * np.arctan2(n, w)
    return ang * x / n, ang * y / n, ang * z / n


@njit(cache=True, _nrt=False)
def bushings_kernel(bu_f, bu_s, bu_R, bu_k, bu_c, bu_f0, r, A, rd, w, rigid, F, Mi, Mj):
    """Linear six-component bushings (Adams BUSHING semantics, see model.element_specs.Bushing) into F.
    Mi, Mj (3, 3): scratch for the markers' axes in ground."""
    for e in range(bu_f.shape[0]):
        fi, fj = bu_f[e, 0], bu_f[e, 1]
        for a in range(3):
            for b in range(3):
                si = 0.0
                sj = 0.0
                for k in range(3):
                    si += A[fi, a, k] * bu_R[e, 0, k, b]
                    sj += A[fj, a, k] * bu_R[e, 1, k, b]
                Mi[a, b] = si
                Mj[a, b] = sj
        pi0, pi1, pi2 = _rot(A, fi, bu_s[e, 0, 0], bu_s[e, 0, 1], bu_s[e, 0, 2])
        pj0, pj1, pj2 = _rot(A, fj, bu_s[e, 1, 0], bu_s[e, 1, 1], bu_s[e, 1, 2])
        vi0, vi1, vi2 = _cross_into(w[fi, 0], w[fi, 1], w[fi, 2], pi0, pi1, pi2)
        vj0, vj1, vj2 = _cross_into(w[fj, 0], w[fj, 1], w[fj, 2], pj0, pj1, pj2)
        d0 = r[fj, 0] + pj0 - r[fi, 0] - pi0
        d1 = r[fj, 1] + pj1 - r[fi, 1] - pi1
        d2 = r[fj, 2] + pj2 - r[fi, 2] - pi2
        c0, c1, c2 = _cross_into(w[fi, 0], w[fi, 1], w[fi, 2], d0, d1, d2)
        e0 = rd[fj, 0] + vj0 - rd[fi, 0] - vi0 - c0
        e1 = rd[fj, 1] + vj1 - rd[fi, 1] - vi1 - c1
        e2 = rd[fj, 2] + vj2 - rd[fi, 2] - vi2 - c2
        wr0, wr1, wr2 = w[fj, 0] - w[fi, 0], w[fj, 1] - w[fi, 1], w[fj, 2] - w[fi, 2]
        # relative rotation Mi^T Mj
        r00 = Mi[0, 0] * Mj[0, 0] + Mi[1, 0] * Mj[1, 0] + Mi[2, 0] * Mj[2, 0]
        r01 = Mi[0, 0] * Mj[0, 1] + Mi[1, 0] * Mj[1, 1] + Mi[2, 0] * Mj[2, 1]
        r02 = Mi[0, 0] * Mj[0, 2] + Mi[1, 0] * Mj[1, 2] + Mi[2, 0] * Mj[2, 2]
        r10 = Mi[0, 1] * Mj[0, 0] + Mi[1, 1] * Mj[1, 0] + Mi[2, 1] * Mj[2, 0]
        r11 = Mi[0, 1] * Mj[0, 1] + Mi[1, 1] * Mj[1, 1] + Mi[2, 1] * Mj[2, 1]
        r12 = Mi[0, 1] * Mj[0, 2] + Mi[1, 1] * Mj[1, 2] + Mi[2, 1] * Mj[2, 2]
        r20 = Mi[0, 2] * Mj[0, 0] + Mi[1, 2] * Mj[1, 0] + Mi[2, 2] * Mj[2, 0]
        r21 = Mi[0, 2] * Mj[0, 1] + Mi[1, 2] * Mj[1, 1] + Mi[2, 2] * Mj[2, 1]
        r22 = Mi[0, 2] * Mj[0, 2] + Mi[1, 2] * Mj[1, 2] + Mi[2, 2] * Mj[2, 2]
        a0, a1, a2 = _rotvec(r00, r01, r02, r10, r11, r12, r20, r21, r22)
        # marker_i components: x = Mi^T d, xd = Mi^T e, w = Mi^T wr
        x0 = Mi[0, 0] * d0 + Mi[1, 0] * d1 + Mi[2, 0] * d2
        x1 = Mi[0, 1] * d0 + Mi[1, 1] * d1 + Mi[2, 1] * d2
        x2 = Mi[0, 2] * d0 + Mi[1, 2] * d1 + Mi[2, 2] * d2
        xd0 = Mi[0, 0] * e0 + Mi[1, 0] * e1 + Mi[2, 0] * e2
        xd1 = Mi[0, 1] * e0 + Mi[1, 1] * e1 + Mi[2, 1] * e2
        xd2 = Mi[0, 2] * e0 + Mi[1, 2] * e1 + Mi[2, 2] * e2
        w0 = Mi[0, 0] * wr0 + Mi[1, 0] * wr1 + Mi[2, 0] * wr2
        w1 = Mi[0, 1] * wr0 + Mi[1, 1] * wr1 + Mi[2, 1] * wr2
        w2 = Mi[0, 2] * wr0 + Mi[1, 2] * wr1 + Mi[2, 2] * wr2
        k, c, f0 = bu_k, bu_c, bu_f0
        F0 = -k[e, 0] * x0 - c[e, 0] * xd0 + f0[e, 0]
        F1 = -k[e, 1] * x1 - c[e, 1] * xd1 + f0[e, 1]
        F2 = -k[e, 2] * x2 - c[e, 2] * xd2 + f0[e, 2]
        T0 = -k[e, 3] * a0 - c[e, 3] * w0 + f0[e, 3]
        T1 = -k[e, 4] * a1 - c[e, 4] * w1 + f0[e, 4]
        T2 = -k[e, 5] * a2 - c[e, 5] * w2 + f0[e, 5]
        G0 = Mi[0, 0] * F0 + Mi[0, 1] * F1 + Mi[0, 2] * F2
        G1 = Mi[1, 0] * F0 + Mi[1, 1] * F1 + Mi[1, 2] * F2
        G2 = Mi[2, 0] * F0 + Mi[2, 1] * F1 + Mi[2, 2] * F2
        H0 = Mi[0, 0] * T0 + Mi[0, 1] * T1 + Mi[0, 2] * T2
        H1 = Mi[1, 0] * T0 + Mi[1, 1] * T1 + Mi[1, 2] * T2
        H2 = Mi[2, 0] * T0 + Mi[2, 1] * T1 + Mi[2, 2] * T2
        _point_force(F, A, fj, pj0, pj1, pj2, G0, G1, G2, rigid)
        # body_i: -F at the same ground point (offset from its CM: r_j + p_j - r_i)
        oi0, oi1, oi2 = r[fj, 0] + pj0 - r[fi, 0], r[fj, 1] + pj1 - r[fi, 1], r[fj, 2] + pj2 - r[fi, 2]
        _point_force(F, A, fi, oi0, oi1, oi2, -G0, -G1, -G2, rigid)
        if fj != 0 and rigid[fj]:
            t0, t1, t2 = _rotT(A, fj, H0, H1, H2)
            F[fj, 3] += t0
            F[fj, 4] += t1
            F[fj, 5] += t2
        if fi != 0 and rigid[fi]:
            t0, t1, t2 = _rotT(A, fi, H0, H1, H2)
            F[fi, 3] -= t0
            F[fi, 4] -= t1
            F[fi, 5] -= t2


@njit(cache=True, _nrt=False)
def _constraints(cm, wk, t, q, v):
    """Frames, driver values and constraint rows at (q, v, t) into the work arrays."""
    r_idx, p_idx, rd_idx, w_idx, rigid_fid, rigid = cm[0], cm[1], cm[2], cm[3], cm[4], cm[6]
    r, A, rd, w, phi, Jc, nu, gamma = wk[0], wk[1], wk[2], wk[3], wk[4], wk[5], wk[6], wk[7]
    frames_into(q, v, r_idx, p_idx, rd_idx, w_idx, rigid_fid, r, A, rd, w)
    if cm[19].shape[0] > 0:
        drivers_at(cm, wk, t)
    rows_kernel(r, A, rd, w, cm[11], cm[12], cm[13], cm[33], cm[34], cm[15],
                wk[34], wk[35], wk[36], rigid, phi, Jc, nu, gamma)


@njit(cache=True, _nrt=False)
def residuals(cm, wk, times, Y, idx, rows, val, arg):
    """Run monitor: the largest |phi| [m or rad] over the constraint rows `rows` at the output rows
    Y[idx] = [q, v] (absolute coordinates, times [s]) into val, and the row where it occurs into arg
    (NaN wins); one call for all the samples checked."""
    nq = cm[31][0]
    phi = wk[4]
    for k in range(idx.shape[0]):
        i = idx[k]
        _constraints(cm, wk, times[i], Y[i, :nq], Y[i, nq:])
        best, at = 0.0, 0
        for a in range(rows.shape[0]):
            x = abs(phi[rows[a]])
            if not x <= best:
                best, at = x, rows[a]
                if not np.isfinite(x):
                    break
        val[k], arg[k] = best, at


@njit(cache=True, _nrt=False)
def _factor(cm, wk):
    """Factor the augmented matrix at the rows in wk: dense LU (dims[4] = 1, singular body masses), the
    square Jacobian's LU (dims[4] = 2, zero-DOF models, `kkt_square`; the tree instead where it declines)
    or the tree elimination of `kkt_tree`. False if singular."""
    if cm[31][4] == 1:
        return dense_factor(wk[5], cm[12], cm[13], cm[7], cm[32], wk[32], wk[33])
    if cm[31][4] == 2 and square_factor(wk[5], cm[12], cm[13], cm[5], cm[6], cm[32], wk[32], wk[33]):
        return True
    t = cm[30]
    return kkt_factor(wk[5], cm[12], cm[13], cm[7], t[0], t[1], t[2], t[3], t[4], t[5], t[6], t[7], t[8],
                      wk[9], wk[10], wk[11], wk[12], wk[13], wk[14], wk[15], wk[16], wk[17], wk[18],
                      wk[20], wk[21], wk[37], wk[38], wk[40], wk[41])


@njit(cache=True, _nrt=False)
def _solve(cm, wk, F, c_rows, x6, lam):
    if cm[31][4] == 1:
        dense_solve(cm[32], wk[32], wk[33], F, c_rows, x6, lam, wk[39])
        return
    if cm[31][4] == 2 and wk[33][cm[32].shape[0]] == 1:
        square_solve(cm[32], cm[5], cm[6], cm[7], wk[32], wk[33], F, c_rows, x6, lam, wk[39])
        return
    t = cm[30]
    kkt_solve(wk[5], cm[12], cm[13], t[0], t[1], t[3], t[4], t[5], t[8], wk[9], wk[10], wk[11], wk[12],
              wk[13], wk[14], wk[15], wk[16], wk[18], wk[19], wk[21], F, c_rows, x6, lam, wk[38], wk[41])


@njit(cache=True, _nrt=False)
def rows_dropped(cm, wk):
    """True when the factorisation in wk left dependent loop rows out of the solve (the tree's pivoted
    Cholesky at a change point, where the constraints do not determine the rates)."""
    if cm[31][4] == 1 or (cm[31][4] == 2 and wk[33][cm[32].shape[0]] == 1):
        return False
    return wk[41][0] < cm[30][8].shape[0]


@njit(cache=True, _nrt=False)
def accelerations(cm, wk, t, q, v, vd, lam, refactor=True):
    """vd (nv) and lam (nc, zero at inactive rows) from the equations of motion at (q, v, t); status.
    refactor=False reuses the factorisation in wk, valid when it was made at these positions q (the
    factorisation depends on q only), e.g. right after `project`."""
    _constraints(cm, wk, t, q, v)
    F = wk[8]
    r, A, rd, w = wk[0], wk[1], wk[2], wk[3]
    loads_into(cm, wk, t, q, r, A, rd, w, F)
    if refactor and not _factor(cm, wk):
        return SINGULAR
    x6 = wk[25]
    for i in range(lam.shape[0]):
        lam[i] = 0.0
    _solve(cm, wk, F, wk[7], x6, lam)
    _from6(cm, x6, vd)
    for i in range(vd.shape[0]):
        if not np.isfinite(vd[i]):
            return NONFINITE
    return OK


@njit(cache=True, _nrt=False)
def _from6(cm, x6, x):
    """Six slots per frame -> system velocity layout."""
    vadr, rigid = cm[5], cm[6]
    for f in range(1, x6.shape[0]):
        n = 6 if rigid[f] else 3
        for k in range(n):
            x[vadr[f] + k] = x6[f, k]


@njit(cache=True, _nrt=False)
def _to6(cm, x, x6):
    vadr, rigid = cm[5], cm[6]
    for f in range(x6.shape[0]):
        for k in range(6):
            x6[f, k] = 0.0
        if f == 0:
            continue
        n = 6 if rigid[f] else 3
        for k in range(n):
            x6[f, k] = x[vadr[f] + k]


@njit(cache=True, _nrt=False)
def qdot_into(cm, q, v, qd):
    """dq/dt: CM velocities and Euler-parameter rates 1/2 p (x) (0, w_B)."""
    qdot_kernel(cm[0], cm[1], cm[2], cm[3], q, v, qd)


@njit(cache=True, _nrt=False)
def qdot_kernel(r_idx, p_idx, rd_idx, w_idx, q, v, qd):
    """`qdot_into` with explicit index arrays."""
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


@njit(cache=True, _nrt=False)
def rhs(cm, wk, t, y, ydot, refactor=True):
    """ydot = [qdot, vd] at (t, y); returns a status code (OK when the solve succeeded). refactor=False:
    as in `accelerations`. A joint-coordinate tree (dims[5] == 1) has y = [theta, theta_dot] and
    ydot = [theta_dot, theta_ddot] from the articulated-body algorithm (solvers.fasttree)."""
    if cm[31][5] == 1:
        return tree_rhs(cm, wk, t, y, ydot)
    nq = cm[31][0]
    q = y[:nq]
    v = y[nq:]
    st = accelerations(cm, wk, t, q, v, ydot[nq:], wk[26], refactor)
    qdot_into(cm, q, v, ydot[:nq])
    return st


@njit(cache=True, _nrt=False)
def tree_rhs(cm, wk, t, y, ydot):
    """Joint-coordinate right-hand side: frames by forward kinematics, loads, articulated-body solve."""
    tw = wk[43]
    nj = y.shape[0] // 2
    r, A, rd, w = wk[0], wk[1], wk[2], wk[3]
    fasttree.kinematics(cm[42], y, nj, r, A, rd, w, tw[10], tw[11])
    F = wk[8]
    loads_into(cm, wk, t, y, r, A, rd, w, F)
    if not fasttree.aba(cm[42], y, nj, r, A, rd, w, tw[10], F, cm[9], cm[10], tw, ydot):
        return SINGULAR
    for i in range(ydot.shape[0]):
        if not np.isfinite(ydot[i]):
            return NONFINITE
    return OK


@njit(cache=True, _nrt=False)
def write_state(cm, wk, y, yout, prev):
    """The output row (absolute coordinates and velocities, system layout) of the integrator's state y:
    a copy, or for a joint-coordinate tree the forward kinematics (Euler parameters continuous with prev,
    the previous output row, when it has the same size)."""
    if cm[31][5] != 1:
        for i in range(y.shape[0]):
            yout[i] = y[i]
        return
    tw = wk[43]
    r, A, rd, w = wk[0], wk[1], wk[2], wk[3]
    fasttree.kinematics(cm[42], y, y.shape[0] // 2, r, A, rd, w, tw[10], tw[11])
    fasttree.to_maximal(cm[42], cm[1], cm[0], cm[2], cm[3], cm[4], r, A, rd, w, yout, prev)


@njit(cache=True, _nrt=False)
def read_state(cm, wk, yrow, y):
    """The integrator's state y of an output row (inverse of `write_state`)."""
    if cm[31][5] != 1:
        for i in range(y.shape[0]):
            y[i] = yrow[i]
        return
    nq = cm[31][0]
    r, A, rd, w = wk[0], wk[1], wk[2], wk[3]
    frames_into(yrow[:nq], yrow[nq:], cm[0], cm[1], cm[2], cm[3], cm[4], r, A, rd, w)
    fasttree.from_maximal(cm[42], y.shape[0] // 2, r, A, rd, w, y)


@njit(cache=True, _nrt=False)
def increment_into(cm, q, dx6):
    """q (+) dx: CM translations plus p <- p (x) exp(dx_w / 2) (body-axes rotation vectors), in place."""
    increment_kernel6(cm[0], cm[1], cm[4], q, dx6)


@njit(cache=True, _nrt=False)
def increment_kernel6(r_idx, p_idx, rigid_fid, q, dx6):
    """`increment_into` with explicit index arrays; dx6 (nf, 6) six slots per frame."""
    for k in range(r_idx.shape[0]):
        for c in range(3):
            q[r_idx[k, c]] += dx6[k + 1, c]
    for k in range(p_idx.shape[0]):
        f = rigid_fid[k]
        quat_step(q, p_idx, k, dx6[f, 3], dx6[f, 4], dx6[f, 5])


@njit(cache=True, _nrt=False)
def normalize_into(cm, q):
    normalize_kernel(cm[1], q)


@njit(cache=True, _nrt=False)
def normalize_kernel(p_idx, q):
    """Unit-normalise the Euler parameters in q."""
    for k in range(p_idx.shape[0]):
        n = 0.0
        for c in range(4):
            n += q[p_idx[k, c]] ** 2
        n = np.sqrt(n)
        for c in range(4):
            q[p_idx[k, c]] /= n


@njit(cache=True, _nrt=False)
def newton_positions(cm, wk, t, q, v, tol):
    """Newton on phi(q, t) = 0 from q, in place (Euler parameters normalised first; mass-weighted
    minimum-norm steps through the KKT factorisation in wk, at most 12), the rows in wk evaluated at the
    q returned. Returns (status: OK, NONFINITE (a residual not finite), SINGULAR (a factorisation
    failed) or PROJECTION (no convergence); the sum over the steps of the largest six-slot component
    [m or rad]; the number of factorisations)."""
    active = cm[32]
    x6, zero6, lam, c = wk[25], wk[27], wk[26], wk[29]
    normalize_into(cm, q)
    for f in range(zero6.shape[0]):
        for k in range(6):
            zero6[f, k] = 0.0
    size, nfactor = 0.0, 0
    for it in range(12):
        _constraints(cm, wk, t, q, v)   # phi and the Jacobian do not depend on v; nu, gamma are at (q, v)
        res = 0.0
        for i in range(active.shape[0]):
            r = abs(wk[4][active[i]])
            if not np.isfinite(r):
                return NONFINITE, size, nfactor
            res = max(res, r)
        if res <= tol:
            return OK, size, nfactor
        if not _factor(cm, wk):
            return SINGULAR, size, nfactor
        nfactor += 1
        for i in range(c.shape[0]):
            c[i] = -wk[4][i]
        _solve(cm, wk, zero6, c, x6, lam)
        step = 0.0
        for f in range(1, x6.shape[0]):
            for k in range(6):
                step = max(step, abs(x6[f, k]))
        size += step
        increment_into(cm, q, x6)
    return PROJECTION, size, nfactor


@njit(cache=True, _nrt=False)
def project(cm, wk, t, q, v, tol, exact_factor=True):
    """Project q onto phi(q, t) = 0 (`newton_positions`) and v onto phi_q v = nu.
    Leaves in wk the factorisation at the projected q (see `accelerations(refactor=False)`); with
    exact_factor=False the velocity step reuses the last Newton step's factorisation (positions a
    Newton step apart: the velocity residual is of the order of that step times the correction, far
    below round-off of the constraints), for outputs, after which the factorisation is not reused.
    A joint-coordinate tree satisfies its constraints by construction: nothing to do."""
    if cm[31][5] == 1:
        return OK
    status, _, nfactor = newton_positions(cm, wk, t, q, v, tol)
    if status != OK:
        return status
    return project_velocities(cm, wk, v, exact_factor or nfactor == 0)


@njit(cache=True, _nrt=False)
def project_velocities(cm, wk, v, refactor=True):
    """v onto phi_q v = nu (mass-weighted minimum-norm correction dv: M dv + J^T mu = 0, J dv = nu - J v)
    in place, with wk holding the constraint rows at the current positions (`_constraints`, after a
    converged position Newton); refactor=False reuses the factorisation in wk. Leaves in wk the
    factorisation used (at these positions when refactor). Returns OK or SINGULAR."""
    if refactor and not _factor(cm, wk):
        return SINGULAR
    active = cm[32]
    x6, zero6, lam, c = wk[25], wk[27], wk[26], wk[29]
    for f in range(zero6.shape[0]):
        for k in range(6):
            zero6[f, k] = 0.0
    v6 = wk[30]
    _to6(cm, v, v6)
    Jc, bi, bj, nu = wk[5], cm[12], cm[13], wk[6]
    for i in range(active.shape[0]):
        row = active[i]
        c[row] = nu[row] - _row_dot(Jc, bi, bj, row, v6)
    _solve(cm, wk, zero6, c, x6, lam)
    vadr, rigid = cm[5], cm[6]
    for f in range(1, x6.shape[0]):
        n = 6 if rigid[f] else 3
        for k in range(n):
            v[vadr[f] + k] += x6[f, k]
    return OK
