"""Compiled (numba) loads written as expressions (issue 14): measures, programs, forces into F.

`expr_loads(ex, ew, t, y, r, A, rd, w, rigid, F)` fills the variable vector x (x[0] = t [s], x[1 + m] the
value of measure m) from the frames of one state, runs each load component's postfix program with the
expression interpreter of `system.exprvm` and adds the loads into F (six slots per frame: CM force in
ground axes, torque in body axes), as `solvers.fastdyn.loads_into` does for the built-in elements.
No Python runs per evaluation. `ex` is `system.exprloads_pack.pack(...)`'s tuple, `ew` its work tuple.

Measure kinds (mbdsim.model.loadexpr): 0-2 DX DY DZ, 3 DM, 4-6 VX VY VZ, 7 VM, 8 VR, 9-11 WX WY WZ,
12 WM, 13-15 AX AY AZ, 20 joint angle (joint-coordinate path only: offset + sign theta), 21 its rate,
22 joint slide, 23 its rate. Load kinds: 0 point force, 1 torque (components in the axes of frame
ld_f[e, 2] rotated by ld_R), 2 line force (magnitude along the line, positive pulling together),
3 joint torque (about the joint axis; the angle's Jacobian rows), 4 joint force (along the axis).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import entry, kernel  # noqa: F401  (njit without the wrappers that dominate compilation; issue 32)
from .exprvm import eval_program
from .kernels import row_rate, row_terms


@kernel(_nrt=False)
def _rot(A, f, s0, s1, s2):
    """A[f] s (body axes -> ground)."""
    return (A[f, 0, 0] * s0 + A[f, 0, 1] * s1 + A[f, 0, 2] * s2,
            A[f, 1, 0] * s0 + A[f, 1, 1] * s1 + A[f, 1, 2] * s2,
            A[f, 2, 0] * s0 + A[f, 2, 1] * s1 + A[f, 2, 2] * s2)


@kernel(_nrt=False)
def _axis(A, f, R, c):
    """Column c of A[f] R (a marker's axis c in ground)."""
    return _rot(A, f, R[0, c], R[1, c], R[2, c])


@kernel(_nrt=False)
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@kernel(_nrt=False)
def _point(r, A, rd, w, f, s):
    """Ground position and velocity of the point s (body axes, from the CM) of frame f."""
    s0, s1, s2 = _rot(A, f, s[0], s[1], s[2])
    v0, v1, v2 = _cross(w[f, 0], w[f, 1], w[f, 2], s0, s1, s2)
    return (r[f, 0] + s0, r[f, 1] + s1, r[f, 2] + s2), (rd[f, 0] + v0, rd[f, 1] + v1, rd[f, 2] + v2)


@kernel(_nrt=False)
def _in_axes(A, f, R, v0, v1, v2, c):
    """Component c of the ground vector v in the axes A[f] R."""
    a = _axis(A, f, R, c)
    return a[0] * v0 + a[1] * v1 + a[2] * v2


@kernel(_nrt=False)
def measure(k, fi, fj, fk, si, sj, Ri, Rj, Rk, v, r, A, rd, w):
    """Value of a measure of kind k at one state (frames r, A, rd, w; ground = frame 0)."""
    if k <= 8:
        pi, vi = _point(r, A, rd, w, fi, si)
        pj, vj = _point(r, A, rd, w, fj, sj)
        d0, d1, d2 = pi[0] - pj[0], pi[1] - pj[1], pi[2] - pj[2]
        e0, e1, e2 = vi[0] - vj[0], vi[1] - vj[1], vi[2] - vj[2]
        if k <= 2:
            return _in_axes(A, fk, Rk, d0, d1, d2, k)
        if k == 3:
            return np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if k <= 6:
            return _in_axes(A, fk, Rk, e0, e1, e2, k - 4)
        if k == 7:
            return np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        L = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        return (d0 * e0 + d1 * e1 + d2 * e2) / L if L > 0.0 else 0.0
    if k <= 12:
        o0, o1, o2 = w[fi, 0] - w[fj, 0], w[fi, 1] - w[fj, 1], w[fi, 2] - w[fj, 2]
        if k == 12:
            return np.sqrt(o0 * o0 + o1 * o1 + o2 * o2)
        return _in_axes(A, fk, Rk, o0, o1, o2, k - 9)
    if k <= 15:
        if k == 13:     # AX = atan2(-zi.yj, zi.zj)
            a, b, c = _axis(A, fi, Ri, 2), _axis(A, fj, Rj, 1), _axis(A, fj, Rj, 2)
            return np.arctan2(-(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]), a[0] * c[0] + a[1] * c[1] + a[2] * c[2])
        if k == 14:     # AY = atan2(zi.xj, zi.zj)
            a, b, c = _axis(A, fi, Ri, 2), _axis(A, fj, Rj, 0), _axis(A, fj, Rj, 2)
        else:           # AZ = atan2(xi.yj, xi.xj)
            a, b, c = _axis(A, fi, Ri, 0), _axis(A, fj, Rj, 1), _axis(A, fj, Rj, 0)
        return np.arctan2(a[0] * b[0] + a[1] * b[1] + a[2] * b[2], a[0] * c[0] + a[1] * c[1] + a[2] * c[2])
    # joint angle rate (21; absolute coordinates: the angle row's J v), slide (22) and its rate (23): the
    # rows of kernels.row_terms (v: f_i, g_i, f_j or h_i, s_i, s_j in body axes)
    ph, Jri, Jpi, Jrj, Jpj, _ = row_terms(5 if k == 21 else 4, r, A, rd, w, fi, fj, v, 0.0)
    if k == 22:
        return ph
    return row_rate(rd, w, fi, fj, Jri, Jpi, Jrj, Jpj)


@kernel(_nrt=False)
def _force(F, A, f, s0, s1, s2, F0, F1, F2, rigid):
    """Ground-axes force at ground offset s from the CM of frame f, into F (nf, 6)."""
    if f == 0:
        return
    F[f, 0] += F0
    F[f, 1] += F1
    F[f, 2] += F2
    if rigid[f]:
        m0, m1, m2 = _cross(s0, s1, s2, F0, F1, F2)
        for k in range(3):
            F[f, 3 + k] += A[f, 0, k] * m0 + A[f, 1, k] * m1 + A[f, 2, k] * m2


@kernel(_nrt=False)
def _row_load(F, A, f, s, Jr, Jp, rigid):
    """s times a constraint row's Jacobian rows on frame f (J_r [-], J_p ground axes) into F: the force
    s J_r [N] and the ground-axes torque s J_p turned into body axes."""
    if f == 0:
        return
    for k in range(3):
        F[f, k] += s * Jr[k]
    if rigid[f]:
        for k in range(3):
            F[f, 3 + k] += s * (A[f, 0, k] * Jp[0] + A[f, 1, k] * Jp[1] + A[f, 2, k] * Jp[2])


@kernel(_nrt=False)
def _torque(F, A, f, T0, T1, T2, rigid):
    """Ground-axes torque on frame f, into F (body axes)."""
    if f == 0 or not rigid[f]:
        return
    for k in range(3):
        F[f, 3 + k] += A[f, 0, k] * T0 + A[f, 1, k] * T1 + A[f, 2, k] * T2


@kernel(_nrt=False)
def _value(code, consts, tables, start, end, p, x, stack):
    return 0.0 if p < 0 else eval_program(code, consts, tables, start[p], end[p], x, stack)


@kernel(_nrt=False)
def expr_measures(ex, ew, t, y, r, A, rd, w):
    """The variable vector x = ew[0] at one state: x[0] = t [s], x[1 + m] the value of measure m (frames
    r, A, rd, w; y: the joint-coordinate state [theta, theta_dot] on the tree path, read by joint
    measures that have a tree coordinate, else unused; a joint angle in absolute coordinates is continued
    from its reference ew[7][m], the angle at the last accepted state)."""
    ms_kind, ms_f, ms_s, ms_R, ms_v, ms_jq, ms_jc = ex[0], ex[1], ex[2], ex[3], ex[4], ex[5], ex[6]
    x = ew[0]
    x[0] = t
    nj = y.shape[0] // 2
    ref = ew[7]
    for m in range(ms_kind.shape[0]):
        k = ms_kind[m]
        q = ms_jq[m]
        if k >= 20 and q >= 0:
            if k == 20 or k == 22:
                x[1 + m] = ms_jc[m, 0] + ms_jc[m, 1] * y[q]
            else:
                x[1 + m] = ms_jc[m, 1] * y[nj + q]
            continue
        if k == 20:   # absolute coordinates: the angle from the frames, continued from its reference
            x[1 + m] = continued(ref[m], row_terms(5, r, A, rd, w, ms_f[m, 0], ms_f[m, 1], ms_v[m], 0.0)[0])
            continue
        x[1 + m] = measure(k, ms_f[m, 0], ms_f[m, 1], ms_f[m, 2], ms_s[m, 0], ms_s[m, 1], ms_R[m, 0],
                           ms_R[m, 1], ms_R[m, 2], ms_v[m], r, A, rd, w)


@kernel(_nrt=False)
def continued(ref, theta):
    """The angle [rad] congruent to theta (mod 2 pi) nearest to ref: ref + wrap(theta - ref)."""
    d = theta - ref
    return ref + (d - 2.0 * np.pi * np.floor((d + np.pi) / (2.0 * np.pi)))


@kernel(_nrt=False)
def accept_angles(ex, ew, r, A, rd, w):
    """At an accepted state (frames r, A, rd, w): the reference ew[7][m] of every joint angle measure read
    from the frames (absolute coordinates: ms_jq = -1) becomes its continued value there, so that the
    angle continues beyond +-pi step by step (a step turns a joint by less than pi)."""
    ms_kind, ms_f, ms_v, ms_jq, ref = ex[0], ex[1], ex[4], ex[5], ew[7]
    for m in range(ms_kind.shape[0]):
        if ms_kind[m] == 20 and ms_jq[m] < 0:
            ref[m] = continued(ref[m], row_terms(5, r, A, rd, w, ms_f[m, 0], ms_f[m, 1], ms_v[m], 0.0)[0])


@kernel(_nrt=False)
def wrapped_angles(ex, r, A, rd, w, out):
    """The angle [rad] in (-pi, pi] from the frames of every joint angle measure read from them
    (absolute coordinates) into out[m] (0 for the other measures)."""
    ms_kind, ms_f, ms_v, ms_jq = ex[0], ex[1], ex[4], ex[5]
    for m in range(ms_kind.shape[0]):
        out[m] = 0.0
        if ms_kind[m] == 20 and ms_jq[m] < 0:
            out[m] = row_terms(5, r, A, rd, w, ms_f[m, 0], ms_f[m, 1], ms_v[m], 0.0)[0]


@kernel(_nrt=False)
def sensor_values(ex, ew, t, y, r, A, rd, w, g):
    """g[s] = signal - threshold of each expression sensor at one state (frames r, A, rd, w; y as in
    `expr_measures`)."""
    expr_measures(ex, ew, t, y, r, A, rd, w)
    code, consts, tables, start, end = ex[13], ex[14], ex[15], ex[16], ex[17]
    for s in range(ex[18].shape[0]):
        g[s] = _value(code, consts, tables, start, end, ex[18][s], ew[0], ew[1]) - ex[21][s]


@kernel(_nrt=False)
def expr_loads(ex, ew, t, y, r, A, rd, w, rigid, F, pw):
    """Measures, expression programs and their loads at one state into F (see the module docstring).
    y: the joint-coordinate state [theta, theta_dot] on the tree path (read by joint measures that have
    a tree coordinate), else unused. With pw[0] != 0 (solvers.fastenergy) the power of the point forces and
    torques [W] is added to pw[2], and the dissipation program of a joint load (its second program,
    ld_prog[e, 1] >= 0: torsion springs' and stops' damping power, system.exprloads_pack) to pw[1]."""
    ld_kind, ld_f, ld_s, ld_R, ld_v, ld_prog = ex[7], ex[8], ex[9], ex[10], ex[11], ex[12]
    code, consts, tables, start, end = ex[13], ex[14], ex[15], ex[16], ex[17]
    x, stack = ew[0], ew[1]
    expr_measures(ex, ew, t, y, r, A, rd, w)
    for e in range(ld_kind.shape[0]):
        k = ld_kind[e]
        fi, fj = ld_f[e, 0], ld_f[e, 1]
        v0 = _value(code, consts, tables, start, end, ld_prog[e, 0], x, stack)
        if k <= 1:
            v1 = _value(code, consts, tables, start, end, ld_prog[e, 1], x, stack)
            v2 = _value(code, consts, tables, start, end, ld_prog[e, 2], x, stack)
            R = ld_R[e]
            l0 = R[0, 0] * v0 + R[0, 1] * v1 + R[0, 2] * v2
            l1 = R[1, 0] * v0 + R[1, 1] * v1 + R[1, 2] * v2
            l2 = R[2, 0] * v0 + R[2, 1] * v1 + R[2, 2] * v2
            G0, G1, G2 = _rot(A, ld_f[e, 2], l0, l1, l2)
            if k == 1:
                _torque(F, A, fi, G0, G1, G2, rigid)
                if pw[0] != 0.0 and fi != 0 and rigid[fi]:
                    pw[2] += G0 * w[fi, 0] + G1 * w[fi, 1] + G2 * w[fi, 2]
            else:
                s0, s1, s2 = _rot(A, fi, ld_s[e, 0, 0], ld_s[e, 0, 1], ld_s[e, 0, 2])
                _force(F, A, fi, s0, s1, s2, G0, G1, G2, rigid)
                if pw[0] != 0.0 and fi != 0:
                    c0, c1, c2 = _cross(w[fi, 0], w[fi, 1], w[fi, 2], s0, s1, s2)
                    pw[2] += G0 * (rd[fi, 0] + c0) + G1 * (rd[fi, 1] + c1) + G2 * (rd[fi, 2] + c2)
        elif k == 2:        # line force: +T u on i, -T u on j, u from point i to point j
            si = _rot(A, fi, ld_s[e, 0, 0], ld_s[e, 0, 1], ld_s[e, 0, 2])
            sj = _rot(A, fj, ld_s[e, 1, 0], ld_s[e, 1, 1], ld_s[e, 1, 2])
            d0 = r[fj, 0] + sj[0] - r[fi, 0] - si[0]
            d1 = r[fj, 1] + sj[1] - r[fi, 1] - si[1]
            d2 = r[fj, 2] + sj[2] - r[fi, 2] - si[2]
            L = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            inv = v0 / L if L > 0.0 else 0.0
            _force(F, A, fi, si[0], si[1], si[2], d0 * inv, d1 * inv, d2 * inv, rigid)
            _force(F, A, fj, sj[0], sj[1], sj[2], -d0 * inv, -d1 * inv, -d2 * inv, rigid)
        else:               # joint torque (3) or force (4): T or F times the joint angle's or slide's
            #                   Jacobian rows (kernels.row_terms), the generalized force J^T T
            _, Jri, Jpi, Jrj, Jpj, _ = row_terms(5 if k == 3 else 4, r, A, rd, w, fi, fj, ld_v[e], 0.0)
            _row_load(F, A, fi, v0, Jri, Jpi, rigid)
            _row_load(F, A, fj, v0, Jrj, Jpj, rigid)
            if pw[0] != 0.0 and ld_prog[e, 1] >= 0:   # its dissipation power (torsion springs, stops)
                pw[1] += _value(code, consts, tables, start, end, ld_prog[e, 1], x, stack)
