"""Coordinate constraints (couplers, gears, rack and pinion, user constraints) on the joint-coordinate tree (numba).

A tree of one-DOF joints (solvers.fasttree) integrated in joint coordinates theta, with m constraints
f_i(X, t) = 0 over joint coordinates X_k = x0_k + s_k theta_k (s_k = +-1 for a rotation, the axis
factor for a slide: system.jointtree.coord_arrays). With A the (m x nj) gradient (A_ik = f_i,k s_k),

    A theta_ddot = gamma,   gamma_i = -(sum_kl f_kl X'_k X'_l + 2 sum_k f_kt X'_k + f_tt),
    M theta_ddot = tau - A^T lambda

so theta_ddot = qdd_free - Minv A^T lambda, lambda = S^-1 (A qdd_free - gamma), S = A Minv A^T (m x m).
Minv A_i^T comes from one extra articulated-body pass per row with zero velocities and loads, reusing the
articulated inertias (U, D) of the same evaluation (`unit_pass`, O(N)). The constraint load along joint
coordinate X_k is -f_k lambda (as system.constraints.coupler). Positions and velocities are projected
after each step (`newton`: minimum-norm corrections in the metric Minv of the last evaluation).

co = cm[47] (system.jointtree.coord_arrays): term coordinate q (nt,), sign s (nt,), offset x0 (nt,),
ptr (m + 1,), program base of each row pbase (m,) [f, f_t, f_tt, f_k (n), f_kt (n), f_kl (n n)],
code, consts, tables, start, end (exprvm.pack), main row (m,), link row (nt,), aux q / v slot (nt,),
force frame (nt,) and point (nt, 3) of body_j (where a slide's load pair acts), tree frame (nt,), driver
index (m,) (-1: a coupler row; else a motion driver's row X - g(t), one term, with g, g', g'' taken from
fastdyn.drivers_at into cw[15] by `take_drivers`) and its wrap flag (m,) (1: an angle, wrapped to +-pi).
cw = wk[49]: x, stack, X (nt), Xd (nt), Av (nt), fv (m), gam (m), nu (m), MiAT (m, nj), Smat (m, m),
lam (m), b (m), ydot (2 nj), tau (nj), zero loads (nf, 6), driver values (m, 3), LU row swaps (m,).
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from .kkt_tree import lu_factor, lu_solve
from ..system.exprvm import eval_program
from . import fasttree


@kernel(_nrt=False)
def _prog(co, p, x, stack):
    return eval_program(co[5], co[6], co[7], co[8][p], co[9][p], x, stack)


@kernel(_nrt=False)
def values(co, cw, t, y, nj, accel):
    """X, X', f (cw[5]), A (cw[4]), nu (cw[7]) and with `accel` gamma (cw[6]) at (t, y); returns the largest
    |f| and the largest |X| (for the projection's tolerance)."""
    q, s, x0, ptr, pbase, drv = co[0], co[1], co[2], co[3], co[4], co[17]
    x, stack, X, Xd, Av, fv, gam, nu = cw[0], cw[1], cw[2], cw[3], cw[4], cw[5], cw[6], cw[7]
    fmax, xmax = 0.0, 0.0
    for i in range(ptr.shape[0] - 1):
        t0, t1 = ptr[i], ptr[i + 1]
        n = t1 - t0
        if drv[i] >= 0:   # a motion driver: X - g(t) (wrapped for an angle), g from drivers_at
            gd = cw[15][i]
            X[t0] = x0[t0] + s[t0] * y[q[t0]]
            Xd[t0] = s[t0] * y[nj + q[t0]]
            xmax = max(xmax, abs(X[t0]))
            u = X[t0] - gd[0]
            if co[18][i] == 1:
                u -= 2.0 * np.pi * np.floor((u + np.pi) / (2.0 * np.pi))
            fv[i] = u
            fmax = max(fmax, abs(u))
            nu[i] = gd[1]
            Av[t0] = s[t0]
            if accel:
                gam[i] = gd[2]
            continue
        x[0] = t
        for j in range(t0, t1):
            X[j] = x0[j] + s[j] * y[q[j]]
            Xd[j] = s[j] * y[nj + q[j]]
            x[1 + j - t0] = X[j]
            xmax = max(xmax, abs(X[j]))
        b = pbase[i]
        fv[i] = _prog(co, b, x, stack)
        fmax = max(fmax, abs(fv[i]))
        nu[i] = -_prog(co, b + 1, x, stack)
        for j in range(t0, t1):
            Av[j] = _prog(co, b + 3 + (j - t0), x, stack) * s[j]
        if accel:
            g = _prog(co, b + 2, x, stack)
            for j in range(t0, t1):
                g += 2.0 * _prog(co, b + 3 + n + (j - t0), x, stack) * Xd[j]
                for k in range(t0, t1):
                    g += _prog(co, b + 3 + 2 * n + n * (j - t0) + (k - t0), x, stack) * Xd[j] * Xd[k]
            gam[i] = -g
    return fmax, xmax


@kernel(_nrt=False)
def take_drivers(co, cw, f, fd, fdd):
    """The motion drivers' g, g', g'' (fastdyn.drivers_at's arrays) into cw[15], row by row."""
    drv, gd = co[17], cw[15]
    for i in range(drv.shape[0]):
        if drv[i] >= 0:
            gd[i, 0], gd[i, 1], gd[i, 2] = f[drv[i]], fd[drv[i]], fdd[drv[i]]


@kernel(_nrt=False)
def unit_pass(tree, tw, r, tau, out):
    """out = Minv tau (joint coordinates) by the articulated-body algorithm with zero velocities and loads,
    from the articulated inertias U, D, S in tw of the last `fasttree.aba` (frames r of that evaluation)."""
    parent, jtype, order, qadr = tree[0], tree[1], tree[6], tree[7]
    pA, U, S, acc, D, u = tw[1], tw[2], tw[4], tw[5], tw[6], tw[7]
    nf = r.shape[0]
    for f in range(nf):
        for k in range(6):
            pA[f, k] = 0.0
    for ii in range(order.shape[0] - 1, -1, -1):   # leaves first
        c = order[ii]
        p = parent[c]
        if jtype[c] > 0:
            uu = tau[qadr[c]]
            for k in range(6):
                uu -= S[c, k] * pA[c, k]
            u[c] = uu
            inv = uu / D[c]
            for k in range(6):
                pA[c, k] += U[c, k] * inv
        if p == 0:
            continue
        l0, l1, l2 = r[c, 0] - r[p, 0], r[c, 1] - r[p, 1], r[c, 2] - r[p, 2]
        a3, a4, a5 = pA[c, 3], pA[c, 4], pA[c, 5]
        pA[p, 0] += pA[c, 0] + l1 * a5 - l2 * a4
        pA[p, 1] += pA[c, 1] + l2 * a3 - l0 * a5
        pA[p, 2] += pA[c, 2] + l0 * a4 - l1 * a3
        pA[p, 3] += a3
        pA[p, 4] += a4
        pA[p, 5] += a5
    for k in range(6):
        acc[0, k] = 0.0
    for ii in range(order.shape[0]):   # roots first
        c = order[ii]
        p = parent[c]
        l0, l1, l2 = r[c, 0] - r[p, 0], r[c, 1] - r[p, 1], r[c, 2] - r[p, 2]
        w0, w1, w2 = acc[p, 0], acc[p, 1], acc[p, 2]
        acc[c, 0], acc[c, 1], acc[c, 2] = w0, w1, w2
        acc[c, 3] = acc[p, 3] + w1 * l2 - w2 * l1
        acc[c, 4] = acc[p, 4] + w2 * l0 - w0 * l2
        acc[c, 5] = acc[p, 5] + w0 * l1 - w1 * l0
        if jtype[c] > 0:
            s = 0.0
            for k in range(6):
                s += U[c, k] * acc[c, k]
            qdd = (u[c] - s) / D[c]
            for k in range(6):
                acc[c, k] += S[c, k] * qdd
            out[qadr[c]] = qdd


@kernel(_nrt=False)
def _gauss(cw, b, n):
    """b <- S^-1 b for S = cw[9] (n x n; destroyed) by `kkt_tree.lu_factor` (partial pivoting, the row
    swaps in cw[16]); False if singular."""
    if not lu_factor(cw[9], n, cw[16], 1e-13):
        return False
    lu_solve(cw[9], cw[16], n, b)
    return True


@kernel(_nrt=False)
def _metric(co, cw, tree, tw, r, nj):
    """MiAT[i] = Minv A_i^T for every row (the A in cw, the articulated inertias in tw)."""
    q, ptr = co[0], co[3]
    Av, MiAT, tau = cw[4], cw[8], cw[13]
    for k in range(nj):
        tau[k] = 0.0
    for i in range(ptr.shape[0] - 1):
        for j in range(ptr[i], ptr[i + 1]):
            tau[q[j]] += Av[j]
        unit_pass(tree, tw, r, tau, MiAT[i])
        for j in range(ptr[i], ptr[i + 1]):
            tau[q[j]] = 0.0


@kernel(_nrt=False)
def _schur(co, cw):
    """Smat = A MiAT^T (m x m) with the A in cw."""
    q, ptr = co[0], co[3]
    Av, MiAT, Sm = cw[4], cw[8], cw[9]
    m = ptr.shape[0] - 1
    for i in range(m):
        for k in range(m):
            s = 0.0
            for j in range(ptr[i], ptr[i + 1]):
                s += Av[j] * MiAT[k, q[j]]
            Sm[i, k] = s


@kernel(_nrt=False)
def constrain(co, cw, tree, tw, t, y, r, ydot):
    """Turn the free joint accelerations ydot[nj:] of `fasttree.aba` (articulated inertias in tw, frames r)
    into the constrained ones; the multipliers into cw[10]. False when the rows are dependent."""
    nj = y.shape[0] // 2
    q, ptr = co[0], co[3]
    values(co, cw, t, y, nj, True)
    _metric(co, cw, tree, tw, r, nj)
    _schur(co, cw)
    Av, gam, MiAT, lam = cw[4], cw[6], cw[8], cw[10]
    m = ptr.shape[0] - 1
    for i in range(m):
        s = -gam[i]
        for j in range(ptr[i], ptr[i + 1]):
            s += Av[j] * ydot[nj + q[j]]
        lam[i] = s
    if not _gauss(cw, lam, m):
        return False
    for i in range(m):
        li = lam[i]
        if li != 0.0:
            row = MiAT[i]
            for k in range(nj):
                ydot[nj + k] -= row[k] * li
    return True


@kernel(_nrt=False)
def residual(co, cw, t, y, tol):
    """True when the positions and velocities of y satisfy the rows to tol (relative to the coordinates'
    size); leaves X, A, f, nu in cw."""
    nj = y.shape[0] // 2
    q, ptr = co[0], co[3]
    fmax, xmax = values(co, cw, t, y, nj, False)
    if not fmax <= tol * max(1.0, xmax):
        return False
    Av, nu, Xd = cw[4], cw[7], cw[3]
    vmax, vres = 0.0, 0.0
    for i in range(ptr.shape[0] - 1):
        s = -nu[i]
        for j in range(ptr[i], ptr[i + 1]):
            s += Av[j] * y[nj + q[j]]
            vmax = max(vmax, abs(Xd[j]))
        vres = max(vres, abs(s))
    return vres <= tol * max(1.0, vmax)


@kernel(_nrt=False)
def newton(co, cw, t, y, tol):
    """Project y onto the rows (positions by Newton, velocities linearly) with corrections MiAT^T mu, the
    metric of the last `constrain` (at or near y); 0 when converged, 1 when not, 2 when singular."""
    nj = y.shape[0] // 2
    q, ptr = co[0], co[3]
    m = ptr.shape[0] - 1
    Av, fv, nu, MiAT, b = cw[4], cw[5], cw[7], cw[8], cw[11]
    done = False
    for it in range(12):
        fmax, xmax = values(co, cw, t, y, nj, False)
        if not np.isfinite(fmax):
            return 1
        if fmax <= tol * max(1.0, xmax):
            done = True
            break
        _schur(co, cw)
        for i in range(m):
            b[i] = fv[i]
        if not _gauss(cw, b, m):
            return 2
        for i in range(m):
            row = MiAT[i]
            for k in range(nj):
                y[k] -= row[k] * b[i]
    if not done:
        return 1
    _schur(co, cw)   # velocities: A theta_dot = nu at the projected positions
    for i in range(m):
        s = -nu[i]
        for j in range(ptr[i], ptr[i + 1]):
            s += Av[j] * y[nj + q[j]]
        b[i] = s
    if not _gauss(cw, b, m):
        return 2
    for i in range(m):
        row = MiAT[i]
        for k in range(nj):
            y[nj + k] -= row[k] * b[i]
    return 0


@kernel(_nrt=False)
def add_loads(co, cw, tree, r, A, F):
    """The constraint loads -A^T lambda (multipliers in cw[10]) as body loads F (nf, 6) at the frames r, A
    (fastdyn's layout): a torque about the joint axis on the tree child and its opposite on the parent
    (rotation), a force pair along the axis through body_j's joint point (slide, as the reference rows)."""
    q, ptr, ff, fpt, frame = co[0], co[3], co[14], co[15], co[16]
    parent, jtype, axis = tree[0], tree[1], tree[2]
    Av, lam = cw[4], cw[10]
    for i in range(ptr.shape[0] - 1):
        for j in range(ptr[i], ptr[i + 1]):
            Q = -Av[j] * lam[i]
            c = frame[j]
            p = parent[c]
            a0 = A[p, 0, 0] * axis[c, 0] + A[p, 0, 1] * axis[c, 1] + A[p, 0, 2] * axis[c, 2]
            a1 = A[p, 1, 0] * axis[c, 0] + A[p, 1, 1] * axis[c, 1] + A[p, 1, 2] * axis[c, 2]
            a2 = A[p, 2, 0] * axis[c, 0] + A[p, 2, 1] * axis[c, 1] + A[p, 2, 2] * axis[c, 2]
            g0, g1, g2 = Q * a0, Q * a1, Q * a2
            if jtype[c] == 1:
                _moment(A, F, c, g0, g1, g2)
                if p != 0:
                    _moment(A, F, p, -g0, -g1, -g2)
                continue
            f = ff[j]
            x0 = r[f, 0] + A[f, 0, 0] * fpt[j, 0] + A[f, 0, 1] * fpt[j, 1] + A[f, 0, 2] * fpt[j, 2]
            x1 = r[f, 1] + A[f, 1, 0] * fpt[j, 0] + A[f, 1, 1] * fpt[j, 1] + A[f, 1, 2] * fpt[j, 2]
            x2 = r[f, 2] + A[f, 2, 0] * fpt[j, 0] + A[f, 2, 1] * fpt[j, 1] + A[f, 2, 2] * fpt[j, 2]
            _pair(A, F, r, c, 1.0, x0, x1, x2, g0, g1, g2)
            _pair(A, F, r, p, -1.0, x0, x1, x2, g0, g1, g2)


@kernel(_nrt=False)
def _pair(A, F, r, b, sg, x0, x1, x2, g0, g1, g2):
    """F[b] += sg times the force (g0, g1, g2) [N, ground axes] acting at the point (x0, x1, x2) (ground skipped)."""
    if b == 0:
        return
    F[b, 0] += sg * g0
    F[b, 1] += sg * g1
    F[b, 2] += sg * g2
    d0, d1, d2 = x0 - r[b, 0], x1 - r[b, 1], x2 - r[b, 2]
    _moment(A, F, b, sg * (d1 * g2 - d2 * g1), sg * (d2 * g0 - d0 * g2), sg * (d0 * g1 - d1 * g0))


@kernel(_nrt=False)
def _moment(A, F, b, m0, m1, m2):
    """F[b] += the moment (m0, m1, m2) [N m, ground axes] in body b's axes."""
    for k in range(3):
        F[b, 3 + k] += A[b, 0, k] * m0 + A[b, 1, k] * m1 + A[b, 2, k] * m2


@kernel(_nrt=False)
def fill_outputs(co, cw, nj, ydot, vd, lam_rows):
    """The rows' multipliers (main row lambda, link rows f_k lambda) and the auxiliary coordinates'
    accelerations (s theta_ddot) into the system-layout vd and lambda (after `constrain` and `values`)."""
    q, s, ptr, mrow, lrow, av = co[0], co[1], co[3], co[10], co[11], co[13]
    Av, lam = cw[4], cw[10]
    for i in range(ptr.shape[0] - 1):
        lam_rows[mrow[i]] = lam[i]
        for j in range(ptr[i], ptr[i + 1]):
            if lrow[j] >= 0:
                lam_rows[lrow[j]] = Av[j] * s[j] * lam[i]
            if av[j] >= 0:
                vd[av[j]] = s[j] * ydot[nj + q[j]]


@kernel(_nrt=False)
def write_aux(co, y, nq, yout):
    """The auxiliary (continuous angle) coordinates and rates of the coupled rotations into the output row."""
    q, s, x0, aq, av = co[0], co[1], co[2], co[12], co[13]
    nj = y.shape[0] // 2
    for j in range(q.shape[0]):
        if aq[j] >= 0:
            yout[aq[j]] = x0[j] + s[j] * y[q[j]]
            yout[nq + av[j]] = s[j] * y[nj + q[j]]


@kernel(_nrt=False)
def read_aux(co, yrow, y):
    """Continuous joint angles of the coupled rotations from the auxiliary coordinates of an output row."""
    q, s, x0, aq = co[0], co[1], co[2], co[12]
    for j in range(q.shape[0]):
        if aq[j] >= 0:
            y[q[j]] = (yrow[aq[j]] - x0[j]) / s[j]


@kernel(_nrt=False)
def project(cm, wk, t, y, tol):
    """Project the joint state y (in place) onto the coordinate constraints at t [s] when it is off them by
    more than tol (relative): the metric Minv from the articulated inertias at y (one articulated-body
    sweep, zero loads), then `newton`. Returns (status: 0 OK, 1 singular, 2 no convergence (fastdyn's
    OK, SINGULAR, PROJECTION); whether y changed). Nothing to do without coordinate constraints."""
    co, cw, tw = cm[47], wk[49], wk[43]
    if co[3].shape[0] <= 1 or residual(co, cw, t, y, tol):
        return 0, False
    nj = y.shape[0] // 2
    r, A, rd, w = wk[0], wk[1], wk[2], wk[3]
    fasttree.kinematics(cm[42], y, nj, r, A, rd, w, tw[10], tw[11])
    if not fasttree.aba(cm[42], y, nj, r, A, rd, w, tw[10], cw[14], cm[9], cm[10], tw, cw[12]):
        return 1, True
    values(co, cw, t, y, nj, False)
    _metric(co, cw, cm[42], tw, r, nj)
    st = newton(co, cw, t, y, tol)
    return (0 if st == 0 else (1 if st == 2 else 2)), True
