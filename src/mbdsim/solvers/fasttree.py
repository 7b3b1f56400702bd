"""Articulated-body dynamics in joint coordinates for trees of one-degree-of-freedom joints (numba).

State y = [theta (nj), theta_dot (nj)] (system.jointtree: one angle [rad] or slide [m] per revolute /
translational joint, from the assembled configuration). Spatial vectors are (angular, linear) in
ground axes, referred to each body's centre of mass: velocity V = (w, v_cm), force F = (torque about
the CM, force). Between parent p and child c (l = r_c - r_p):

    V_c = X V_p + S theta_dot,    X = [[I, 0], [-l~, I]],    X^T F_c = (tau_c + l x f_c, f_c)
    revolute about unit axis a through P:  S = (a, a x (r_c - P))
    translational along a:                 S = (0, a)

and the accelerations A_c = X A_p + S theta_ddot + zeta_c with the velocity-product terms
    revolute:      zeta = (w_p x a thd,  w_p x (v_P - v_p) + (w_p x a thd) x (r_c - P) + w_c x (v_c - v_P))
    translational: zeta = (0,  w_p x (v_c - v_p) + (w_p x a) thd)
    fixed:         zeta = (0,  w_p x (v_c - v_p))
Featherstone's articulated-body algorithm then runs leaves first (IA = M + sum X^T Ia X,
pA = -F_ext + sum X^T pa; U = IA S, D = S^T U, u = -S^T pA; Ia = IA - U U^T / D,
pa = pA + Ia zeta + U u / D) and roots first (a' = X a_p + zeta, thdd = (u - U.a') / D, a = a' + S thdd).
F_ext are the loads of `fastdyn.loads_into` (gravity, gyroscopic torques, applied loads and force
elements), so every load the compiled core carries acts here too. The work tuple `tw` holds per-frame
scratch: IA (nf, 6, 6), pA, U, zeta, S, acc (nf, 6), D, u (nf,), P (nf, 3) joint points.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import entry, kernel  # noqa: F401  (njit without the wrappers that dominate compilation; issue 32)


@kernel(_nrt=False)
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@kernel(_nrt=False)
def _rot_axis(a, th, R):
    """R = rotation by th [rad] about the unit axis a (Rodrigues)."""
    c, s = np.cos(th), np.sin(th)
    k = 1.0 - c
    R[0, 0] = c + k * a[0] * a[0]
    R[0, 1] = k * a[0] * a[1] - s * a[2]
    R[0, 2] = k * a[0] * a[2] + s * a[1]
    R[1, 0] = k * a[1] * a[0] + s * a[2]
    R[1, 1] = c + k * a[1] * a[1]
    R[1, 2] = k * a[1] * a[2] - s * a[0]
    R[2, 0] = k * a[2] * a[0] - s * a[1]
    R[2, 1] = k * a[2] * a[1] + s * a[0]
    R[2, 2] = c + k * a[2] * a[2]


@kernel(_nrt=False)
def kinematics(tree, y, nj, r, A, rd, w, P, Rtmp):
    """Frames r, A, rd, w (ground axes, CM) of every body and joint points P from the joint state y."""
    parent, jtype, axis, spt, c0, R0, order, qadr = tree
    nf = r.shape[0]
    for k in range(3):
        r[0, k] = 0.0
        rd[0, k] = 0.0
        w[0, k] = 0.0
        for m in range(3):
            A[0, k, m] = 1.0 if k == m else 0.0
    for ii in range(order.shape[0]):
        c = order[ii]
        p = parent[c]
        jt = jtype[c]
        th, thd = 0.0, 0.0
        if qadr[c] >= 0:
            th, thd = y[qadr[c]], y[nj + qadr[c]]
        # child axes in parent axes: Rot(axis, th) R0 (revolute) or R0
        for k in range(3):
            for m in range(3):
                Rtmp[1, k, m] = R0[c, k, m]
        if jt == 1:
            _rot_axis(axis[c], th, Rtmp[0])
            for k in range(3):
                for m in range(3):
                    s = 0.0
                    for j in range(3):
                        s += Rtmp[0, k, j] * R0[c, j, m]
                    Rtmp[1, k, m] = s
        for k in range(3):
            for m in range(3):
                s = 0.0
                for j in range(3):
                    s += A[p, k, j] * Rtmp[1, j, m]
                A[c, k, m] = s
        # child CM in parent axes: spt + Rot (c0 - spt) | c0 + axis d | c0
        x0, x1, x2 = c0[c, 0], c0[c, 1], c0[c, 2]
        if jt == 1:
            d0, d1, d2 = c0[c, 0] - spt[c, 0], c0[c, 1] - spt[c, 1], c0[c, 2] - spt[c, 2]
            x0 = spt[c, 0] + Rtmp[0, 0, 0] * d0 + Rtmp[0, 0, 1] * d1 + Rtmp[0, 0, 2] * d2
            x1 = spt[c, 1] + Rtmp[0, 1, 0] * d0 + Rtmp[0, 1, 1] * d1 + Rtmp[0, 1, 2] * d2
            x2 = spt[c, 2] + Rtmp[0, 2, 0] * d0 + Rtmp[0, 2, 1] * d1 + Rtmp[0, 2, 2] * d2
        elif jt == 2:
            x0 += axis[c, 0] * th
            x1 += axis[c, 1] * th
            x2 += axis[c, 2] * th
        for k in range(3):
            r[c, k] = r[p, k] + A[p, k, 0] * x0 + A[p, k, 1] * x1 + A[p, k, 2] * x2
            P[c, k] = r[p, k] + A[p, k, 0] * spt[c, 0] + A[p, k, 1] * spt[c, 1] + A[p, k, 2] * spt[c, 2]
        a0 = A[p, 0, 0] * axis[c, 0] + A[p, 0, 1] * axis[c, 1] + A[p, 0, 2] * axis[c, 2]
        a1 = A[p, 1, 0] * axis[c, 0] + A[p, 1, 1] * axis[c, 1] + A[p, 1, 2] * axis[c, 2]
        a2 = A[p, 2, 0] * axis[c, 0] + A[p, 2, 1] * axis[c, 1] + A[p, 2, 2] * axis[c, 2]
        w[c, 0], w[c, 1], w[c, 2] = w[p, 0], w[p, 1], w[p, 2]
        l0, l1, l2 = r[c, 0] - r[p, 0], r[c, 1] - r[p, 1], r[c, 2] - r[p, 2]
        if jt == 1:
            w[c, 0] += a0 * thd
            w[c, 1] += a1 * thd
            w[c, 2] += a2 * thd
            e0, e1, e2 = P[c, 0] - r[p, 0], P[c, 1] - r[p, 1], P[c, 2] - r[p, 2]
            t0, t1, t2 = _cross(w[p, 0], w[p, 1], w[p, 2], e0, e1, e2)
            vP0, vP1, vP2 = rd[p, 0] + t0, rd[p, 1] + t1, rd[p, 2] + t2
            g0, g1, g2 = _cross(w[c, 0], w[c, 1], w[c, 2], r[c, 0] - P[c, 0], r[c, 1] - P[c, 1], r[c, 2] - P[c, 2])
            rd[c, 0], rd[c, 1], rd[c, 2] = vP0 + g0, vP1 + g1, vP2 + g2
        else:
            t0, t1, t2 = _cross(w[p, 0], w[p, 1], w[p, 2], l0, l1, l2)
            rd[c, 0], rd[c, 1], rd[c, 2] = rd[p, 0] + t0, rd[p, 1] + t1, rd[p, 2] + t2
            if jt == 2:
                rd[c, 0] += a0 * thd
                rd[c, 1] += a1 * thd
                rd[c, 2] += a2 * thd


@kernel(_nrt=False)
def aba(tree, y, nj, r, A, rd, w, P, F, mass, inertia, tw, ydot):
    """theta_ddot into ydot[nj:] (and theta_dot into ydot[:nj]) from frames at y and loads F (nf, 6):
    force [N] ground axes, moment about the CM [N m] body axes (fastdyn's layout). False if singular."""
    parent, jtype, axis, spt, c0, R0, order, qadr = tree
    IA, pA, U, zeta, S, acc, D, u = tw[0], tw[1], tw[2], tw[3], tw[4], tw[5], tw[6], tw[7]
    nf = r.shape[0]
    for f in range(1, nf):   # body spatial inertia (ground axes, CM) and bias pA = -F_ext
        for i in range(6):
            for j in range(6):
                IA[f, i, j] = 0.0
        Ia = tw[8]   # scratch: A J, then A J A^T (symmetric)
        for i in range(3):
            for m in range(3):
                Ia[i, m] = A[f, i, 0] * inertia[f, 0, m] + A[f, i, 1] * inertia[f, 1, m] + A[f, i, 2] * inertia[f, 2, m]
        for i in range(3):
            for j in range(i + 1):
                s = Ia[i, 0] * A[f, j, 0] + Ia[i, 1] * A[f, j, 1] + Ia[i, 2] * A[f, j, 2]
                IA[f, i, j] = s
                IA[f, j, i] = s
            IA[f, 3 + i, 3 + i] = mass[f]
        for i in range(3):
            pA[f, i] = -(A[f, i, 0] * F[f, 3] + A[f, i, 1] * F[f, 4] + A[f, i, 2] * F[f, 5])
            pA[f, 3 + i] = -F[f, i]
    for ii in range(order.shape[0]):   # motion subspaces and velocity-product terms
        c = order[ii]
        p = parent[c]
        jt = jtype[c]
        thd = y[nj + qadr[c]] if qadr[c] >= 0 else 0.0
        a0 = A[p, 0, 0] * axis[c, 0] + A[p, 0, 1] * axis[c, 1] + A[p, 0, 2] * axis[c, 2]
        a1 = A[p, 1, 0] * axis[c, 0] + A[p, 1, 1] * axis[c, 1] + A[p, 1, 2] * axis[c, 2]
        a2 = A[p, 2, 0] * axis[c, 0] + A[p, 2, 1] * axis[c, 1] + A[p, 2, 2] * axis[c, 2]
        for k in range(6):
            S[c, k] = 0.0
            zeta[c, k] = 0.0
        if jt == 1:
            m0, m1, m2 = r[c, 0] - P[c, 0], r[c, 1] - P[c, 1], r[c, 2] - P[c, 2]
            S[c, 0], S[c, 1], S[c, 2] = a0, a1, a2
            S[c, 3], S[c, 4], S[c, 5] = _cross(a0, a1, a2, m0, m1, m2)
            z0, z1, z2 = _cross(w[p, 0], w[p, 1], w[p, 2], a0 * thd, a1 * thd, a2 * thd)
            zeta[c, 0], zeta[c, 1], zeta[c, 2] = z0, z1, z2
            e0, e1, e2 = P[c, 0] - r[p, 0], P[c, 1] - r[p, 1], P[c, 2] - r[p, 2]
            t0, t1, t2 = _cross(w[p, 0], w[p, 1], w[p, 2], e0, e1, e2)        # v_P - v_p
            vP0, vP1, vP2 = rd[p, 0] + t0, rd[p, 1] + t1, rd[p, 2] + t2
            h0, h1, h2 = _cross(w[p, 0], w[p, 1], w[p, 2], t0, t1, t2)
            k0, k1, k2 = _cross(z0, z1, z2, m0, m1, m2)
            g0, g1, g2 = _cross(w[c, 0], w[c, 1], w[c, 2], rd[c, 0] - vP0, rd[c, 1] - vP1, rd[c, 2] - vP2)
            zeta[c, 3], zeta[c, 4], zeta[c, 5] = h0 + k0 + g0, h1 + k1 + g1, h2 + k2 + g2
        else:
            h0, h1, h2 = _cross(w[p, 0], w[p, 1], w[p, 2], rd[c, 0] - rd[p, 0], rd[c, 1] - rd[p, 1],
                                rd[c, 2] - rd[p, 2])
            zeta[c, 3], zeta[c, 4], zeta[c, 5] = h0, h1, h2
            if jt == 2:
                S[c, 3], S[c, 4], S[c, 5] = a0, a1, a2
                k0, k1, k2 = _cross(w[p, 0], w[p, 1], w[p, 2], a0, a1, a2)
                zeta[c, 3] += k0 * thd
                zeta[c, 4] += k1 * thd
                zeta[c, 5] += k2 * thd
    Ia, pa = tw[8], tw[9]
    for ii in range(order.shape[0] - 1, -1, -1):   # leaves first
        c = order[ii]
        p = parent[c]
        for i in range(6):
            for j in range(6):
                Ia[i, j] = IA[c, i, j]
            pa[i] = pA[c, i]
        if jtype[c] > 0:
            dd = 0.0
            uu = 0.0
            for i in range(6):
                s = 0.0
                for j in range(6):
                    s += IA[c, i, j] * S[c, j]
                U[c, i] = s
                dd += S[c, i] * s
                uu -= S[c, i] * pA[c, i]
            if not dd > 0.0:
                return False
            D[c] = dd
            u[c] = uu
            inv = 1.0 / dd   # one division per body (36 of them cost a quarter of the sweep)
            for i in range(6):
                ui = U[c, i] * inv
                for j in range(6):
                    Ia[i, j] -= ui * U[c, j]
                pa[i] += ui * uu
        for i in range(6):   # pa += Ia zeta
            s = 0.0
            for j in range(6):
                s += Ia[i, j] * zeta[c, j]
            pa[i] += s
        if p == 0:
            continue
        # X^T Ia X and X^T pa with X = [[I, 0], [-l~, I]], l = r_c - r_p
        l0, l1, l2 = r[c, 0] - r[p, 0], r[c, 1] - r[p, 1], r[c, 2] - r[p, 2]
        for i in range(6):     # Y = Ia X: angular columns += row b of Ia[:, 3:] times -l~ = (l x b)^T
            c0_, c1_, c2_ = _cross(l0, l1, l2, Ia[i, 3], Ia[i, 4], Ia[i, 5])
            Ia[i, 0] += c0_
            Ia[i, 1] += c1_
            Ia[i, 2] += c2_
        for j in range(6):     # X^T Y: angular rows += l~ Y[3:]
            t0, t1, t2 = _cross(l0, l1, l2, Ia[3, j], Ia[4, j], Ia[5, j])
            Ia[0, j] += t0
            Ia[1, j] += t1
            Ia[2, j] += t2
        t0, t1, t2 = _cross(l0, l1, l2, pa[3], pa[4], pa[5])
        pa[0] += t0
        pa[1] += t1
        pa[2] += t2
        for i in range(6):
            for j in range(6):
                IA[p, i, j] += Ia[i, j]
            pA[p, i] += pa[i]
    for i in range(6):
        acc[0, i] = 0.0
    for ii in range(order.shape[0]):   # roots first
        c = order[ii]
        p = parent[c]
        l0, l1, l2 = r[c, 0] - r[p, 0], r[c, 1] - r[p, 1], r[c, 2] - r[p, 2]
        t0, t1, t2 = _cross(acc[p, 0], acc[p, 1], acc[p, 2], l0, l1, l2)   # w_dot_p x l = -l~ w_dot_p
        acc[c, 0] = acc[p, 0] + zeta[c, 0]
        acc[c, 1] = acc[p, 1] + zeta[c, 1]
        acc[c, 2] = acc[p, 2] + zeta[c, 2]
        acc[c, 3] = acc[p, 3] + t0 + zeta[c, 3]
        acc[c, 4] = acc[p, 4] + t1 + zeta[c, 4]
        acc[c, 5] = acc[p, 5] + t2 + zeta[c, 5]
        if jtype[c] > 0:
            s = 0.0
            for i in range(6):
                s += U[c, i] * acc[c, i]
            qdd = (u[c] - s) / D[c]
            for i in range(6):
                acc[c, i] += S[c, i] * qdd
            ydot[nj + qadr[c]] = qdd
            ydot[qadr[c]] = y[nj + qadr[c]]
    return True


@entry(_nrt=False)
def to_maximal(tree, p_idx, r_idx, rd_idx, w_idx, rigid_fid, r, A, rd, w, yout, prev):
    """Absolute coordinates and velocities (system layout) of the frames into yout (auxiliary coordinates
    untouched: `treecoord.write_aux`); Euler parameters with
    the sign nearest to prev's (continuous in time) when prev has the same size, else e0 >= 0."""
    nq = 0
    for k in range(r_idx.shape[0]):
        for c in range(3):
            yout[r_idx[k, c]] = r[k + 1, c]
        nq += 3
    nq += 4 * p_idx.shape[0]
    # auxiliary coordinates (continuous angles of coupled joints: one q and one v slot each) end the q part
    nq += (yout.shape[0] - nq - 3 * (r_idx.shape[0] + p_idx.shape[0])) // 2
    for k in range(p_idx.shape[0]):
        f = rigid_fid[k]
        a00, a01, a02 = A[f, 0, 0], A[f, 0, 1], A[f, 0, 2]
        a10, a11, a12 = A[f, 1, 0], A[f, 1, 1], A[f, 1, 2]
        a20, a21, a22 = A[f, 2, 0], A[f, 2, 1], A[f, 2, 2]
        tr = a00 + a11 + a22
        if tr >= a00 and tr >= a11 and tr >= a22:
            s = 2.0 * np.sqrt(max(1.0 + tr, 0.0))
            e0, e1, e2, e3 = 0.25 * s, (a21 - a12) / s, (a02 - a20) / s, (a10 - a01) / s
        elif a00 >= a11 and a00 >= a22:
            s = 2.0 * np.sqrt(max(1.0 + a00 - a11 - a22, 0.0))
            e0, e1, e2, e3 = (a21 - a12) / s, 0.25 * s, (a01 + a10) / s, (a02 + a20) / s
        elif a11 >= a22:
            s = 2.0 * np.sqrt(max(1.0 + a11 - a00 - a22, 0.0))
            e0, e1, e2, e3 = (a02 - a20) / s, (a01 + a10) / s, 0.25 * s, (a12 + a21) / s
        else:
            s = 2.0 * np.sqrt(max(1.0 + a22 - a00 - a11, 0.0))
            e0, e1, e2, e3 = (a10 - a01) / s, (a02 + a20) / s, (a12 + a21) / s, 0.25 * s
        nrm = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2 + e3 * e3)
        e0, e1, e2, e3 = e0 / nrm, e1 / nrm, e2 / nrm, e3 / nrm
        if prev.shape[0] == yout.shape[0]:
            dot = (e0 * prev[p_idx[k, 0]] + e1 * prev[p_idx[k, 1]] + e2 * prev[p_idx[k, 2]]
                   + e3 * prev[p_idx[k, 3]])
            if dot < 0.0:
                e0, e1, e2, e3 = -e0, -e1, -e2, -e3
        elif e0 < 0.0:
            e0, e1, e2, e3 = -e0, -e1, -e2, -e3
        yout[p_idx[k, 0]], yout[p_idx[k, 1]], yout[p_idx[k, 2]], yout[p_idx[k, 3]] = e0, e1, e2, e3
    for k in range(r_idx.shape[0]):
        for c in range(3):
            yout[nq + rd_idx[k, c]] = rd[k + 1, c]
    for k in range(p_idx.shape[0]):
        f = rigid_fid[k]
        for c in range(3):   # angular velocity in body axes: A^T w
            yout[nq + w_idx[k, c]] = A[f, 0, c] * w[f, 0] + A[f, 1, c] * w[f, 1] + A[f, 2, c] * w[f, 2]


@kernel(_nrt=False)
def from_maximal(tree, nj, r, A, rd, w, y):
    """Joint state y from frames (the inverse of `kinematics`; angles in (-pi, pi], which the dynamics
    only see through their sines and cosines)."""
    parent, jtype, axis, spt, c0, R0, order, qadr = tree
    for ii in range(order.shape[0]):
        c = order[ii]
        if qadr[c] < 0:
            continue
        p = parent[c]
        ax = axis[c]
        a0 = A[p, 0, 0] * ax[0] + A[p, 0, 1] * ax[1] + A[p, 0, 2] * ax[2]
        a1 = A[p, 1, 0] * ax[0] + A[p, 1, 1] * ax[1] + A[p, 1, 2] * ax[2]
        a2 = A[p, 2, 0] * ax[0] + A[p, 2, 1] * ax[1] + A[p, 2, 2] * ax[2]
        if jtype[c] == 1:
            # R = A_p^T A_c R0^T = Rot(axis, th): sin th = axis . axial(R), cos th = (tr R - 1) / 2
            tr, s0, s1, s2 = 0.0, 0.0, 0.0, 0.0
            for k in range(3):
                for m in range(3):
                    x = 0.0
                    for j in range(3):
                        for i in range(3):
                            x += A[p, i, k] * A[c, i, j] * R0[c, m, j]
                    if k == m:
                        tr += x
                    elif k == 2 and m == 1:
                        s0 += 0.5 * x
                    elif k == 1 and m == 2:
                        s0 -= 0.5 * x
                    elif k == 0 and m == 2:
                        s1 += 0.5 * x
                    elif k == 2 and m == 0:
                        s1 -= 0.5 * x
                    elif k == 1 and m == 0:
                        s2 += 0.5 * x
                    elif k == 0 and m == 1:
                        s2 -= 0.5 * x
            y[qadr[c]] = np.arctan2(ax[0] * s0 + ax[1] * s1 + ax[2] * s2, 0.5 * (tr - 1.0))
            y[nj + qadr[c]] = a0 * (w[c, 0] - w[p, 0]) + a1 * (w[c, 1] - w[p, 1]) + a2 * (w[c, 2] - w[p, 2])
        else:
            d = 0.0
            for k in range(3):
                x = 0.0
                for i in range(3):
                    x += A[p, i, k] * (r[c, i] - r[p, i])
                d += ax[k] * (x - c0[c, k])
            y[qadr[c]] = d
            t0, t1, t2 = _cross(w[p, 0], w[p, 1], w[p, 2], r[c, 0] - r[p, 0], r[c, 1] - r[p, 1], r[c, 2] - r[p, 2])
            y[nj + qadr[c]] = (a0 * (rd[c, 0] - rd[p, 0] - t0) + a1 * (rd[c, 1] - rd[p, 1] - t1)
                               + a2 * (rd[c, 2] - rd[p, 2] - t2))
