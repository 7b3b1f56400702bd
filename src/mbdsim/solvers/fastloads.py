"""Compiled built-in loads at one state (numba), for `fastdyn.loads_into`: gravity, gyroscopic torques,
constant point forces and torques, linear spring-dampers (`loads_kernel`), six-component bushings
(`bushings_kernel`) and sphere-sphere / sphere-plane contacts (`contacts_kernel`).

Frames as `system.kernels.frames_into` gives them (r, A, rd, w: CM position [m], rotation matrix, CM
velocity [m/s], angular velocity [rad/s], ground axes); loads are added into F (nf, 6): force [N] in
ground axes, torque [N m] about the CM in body axes. The numpy evaluators of `system.force_elements`
compute the same laws (the tests compare the two paths).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import entry, kernel  # noqa: F401  (njit without the wrappers that dominate compilation; issue 32)
from ..system.exprloads_kernel import _cross as _cross_into, _force as _point_force, _rot
from .fastlaw import normal_force, relative_velocity


@kernel(_nrt=False)
def _centre(r, A, f, s):
    """Ground position [m] of the body-axes point s of frame f."""
    x0, x1, x2 = _rot(A, f, s[0], s[1], s[2])
    return r[f, 0] + x0, r[f, 1] + x1, r[f, 2] + x2


@kernel(_nrt=False)
def contacts_kernel(ct_f, ct_kind, ct_s, ct_n, ct_par, r, A, rd, w, rigid, F, pw):
    """Compliant contacts (system.force_elements.contact) into F: signed gap g [m] between the shapes, normal
    n from body_i's shape towards body_j's, contact point cp in the middle of the overlap; while g < 0 the
    Adams IMPACT normal force max(0, k delta^e - STEP(delta, 0, 0, d, c_max) g_dot) along n and the
    regularised Coulomb friction -mu Fn v_t / sqrt(|v_t|^2 + v_s^2) (v_t: the tangential part of the
    relative velocity of the material points at cp) act on body_j at cp, their opposite on body_i.
    Arrays of `system.compiled._contacts`; frames r, A, rd, w (w in ground axes). With pw[0] != 0 their
    dissipation power (Fn - k delta^e) (-g_dot) + mu Fn |v_t|^2 / sqrt(|v_t|^2 + v_s^2) [W] is added to pw[1]
    (solvers.fastenergy)."""
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
        v0, v1, v2 = relative_velocity(r, rd, w, fi, fj, p0, p1, p2)
        gd = n0 * v0 + n1 * v1 + n2 * v2
        delta = -g
        Fn = normal_force(delta, gd, k, ex, cmax, dpen, -1.0)   # IMPACT
        t0, t1, t2 = v0 - gd * n0, v1 - gd * n1, v2 - gd * n2
        mf = mu * Fn / np.sqrt(t0 * t0 + t1 * t1 + t2 * t2 + vs * vs) if mu > 0.0 else 0.0
        G0, G1, G2 = Fn * n0 - mf * t0, Fn * n1 - mf * t1, Fn * n2 - mf * t2
        if pw[0] != 0.0:
            pw[1] += (Fn - k * delta ** ex) * (-gd) + mf * (t0 * t0 + t1 * t1 + t2 * t2)
        _point_force(F, A, fj, p0 - r[fj, 0], p1 - r[fj, 1], p2 - r[fj, 2], G0, G1, G2, rigid)
        _point_force(F, A, fi, p0 - r[fi, 0], p1 - r[fi, 1], p2 - r[fi, 2], -G0, -G1, -G2, rigid)


@kernel(_nrt=False)
def _rotT(A, f, x0, x1, x2):
    """A[f]^T x (ground -> body axes)."""
    return (A[f, 0, 0] * x0 + A[f, 1, 0] * x1 + A[f, 2, 0] * x2,
            A[f, 0, 1] * x0 + A[f, 1, 1] * x1 + A[f, 2, 1] * x2,
            A[f, 0, 2] * x0 + A[f, 1, 2] * x1 + A[f, 2, 2] * x2)


@kernel(_nrt=False)
def loads_kernel(mass, inertia, gravity, rigid, pf_f, pf_s, pf_v, pf_ff, pf_R, pf_torque, sp_f, sp_s, sp_par,
                 r, A, rd, w, F, pw):
    """Loads of `loads_into` with explicit arrays (six slots per frame); no allocation. With pw[0] != 0
    the power of the constant forces and torques [W] is added to pw[2] and the spring-dampers' damping power
    c L_dot^2 [W] to pw[1] (solvers.fastenergy)."""
    on = pw[0] != 0.0
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
                if on:
                    pw[2] += G0 * w[f, 0] + G1 * w[f, 1] + G2 * w[f, 2]
        else:
            s0, s1, s2 = _rot(A, f, pf_s[e, 0], pf_s[e, 1], pf_s[e, 2])
            _point_force(F, A, f, s0, s1, s2, G0, G1, G2, rigid)
            if on:
                c0, c1, c2 = _cross_into(w[f, 0], w[f, 1], w[f, 2], s0, s1, s2)
                pw[2] += G0 * (rd[f, 0] + c0) + G1 * (rd[f, 1] + c1) + G2 * (rd[f, 2] + c2)
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
        if on:
            pw[1] += sp_par[e, 1] * Ld * Ld
        u0, u1, u2 = d0 * inv * T, d1 * inv * T, d2 * inv * T
        _point_force(F, A, fi, si0, si1, si2, u0, u1, u2, rigid)
        _point_force(F, A, fj, sj0, sj1, sj2, -u0, -u1, -u2, rigid)


@kernel(_nrt=False)
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


@kernel(_nrt=False)
def bushings_kernel(bu_f, bu_s, bu_R, bu_k, bu_c, bu_f0, r, A, rd, w, rigid, F, Mi, Mj, pw):
    """Linear six-component bushings (Adams BUSHING semantics, see model.element_specs.Bushing) into F.
    Mi, Mj (3, 3): scratch for the markers' axes in ground. With pw[0] != 0 the damping power
    x_dot.C x_dot + w.C w [W] (marker_i components) is added to pw[1] (solvers.fastenergy)."""
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
        if pw[0] != 0.0:
            pw[1] += (c[e, 0] * xd0 * xd0 + c[e, 1] * xd1 * xd1 + c[e, 2] * xd2 * xd2 + c[e, 3] * w0 * w0
                      + c[e, 4] * w1 * w1 + c[e, 5] * w2 * w2)
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
