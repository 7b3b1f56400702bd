"""Radau IIA of order 5 (Hairer & Wanner's RADAU5) compiled with numba: the implicit stepper of stiff models.

Three-stage collocation at c = (4 - sqrt 6) / 10, (4 + sqrt 6) / 10, 1, solved by simplified Newton
iterations in the transformed variables W = T^-1 Z: one real system (gamma / h - J) and one complex
system ((alpha + i beta) / h - J) of the state's size per iteration, J the Jacobian of the compiled
right-hand side (`fastdyn.rhs`, the O(N) equations of motion) by forward differences (n evaluations, or
one per group of columns sharing no nonzero row between full Jacobians: `_jacobian`).
J is kept across steps while Newton converges well (recomputed after a step that needed more than two
iterations at a contraction rate above 1e-3, or when Newton fails with an old J); the two LU
factorisations (partial pivoting, `_lu`) are kept while h is unchanged (h is kept when the controller
proposes a change below 20 %). The error estimate is Hairer's, filtered through (gamma0 h)^-1: err =
(gamma / h - J)^-1 (f + sum_i e_i Z_i / h), re-filtered once more after a rejection; step control is
Gustafsson's predictive controller (factor limits 0.2..10, safety 0.9 (2 k_max + 1) / (2 k_max +
k)). The starting guess of each step's stages extrapolates the previous step's collocation
polynomial, which is also the dense output of the outputs between steps (third order,
y(t_old + x h) = y_old + sum_j Q_j x^(j+1)). Constants and the Newton stopping rule follow scipy's
`Radau` (scipy.integrate._ivp.radau, itself after radau5.f).

As `fastdop.run`: coordinate projection after each accepted step and at each output (absolute
coordinates; none in joint-coordinate tree mode), outputs written by `fastdyn.write_state`, a return to
Python after a bounded amount of work (EVALS_PER_RETURN), at most NEWTON_MAXITER iterations per
attempt, h halved after a failed Newton attempt (TINY_STEP below the round-off limit), max_steps.
Every array is passed in (no allocation inside: `_nrt=False`). No expression sensors here (the Python
side keeps the models with sensors on the other paths).
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import entry, kernel
from .fastdop import CHECKPOINTS_FULL, EVENTS_FULL, _project
from .fastdopstep import initial_step
from .fastdyn import CALLBACK_FAILED, MAX_STEPS, NONFINITE, OK, TINY_STEP, accept_state, read_state, rhs, write_state
from .kkt_tree import lu_factor, lu_solve
from .fastswitch import (dense, friction_event, sensor_event, sensor_stop, start,  # noqa: F401  (dense: the steps'
                         stop_at)                                                   # polynomial, also HHT's)

S6 = 6.0 ** 0.5
C = np.array([(4.0 - S6) / 10.0, (4.0 + S6) / 10.0, 1.0])
E = np.array([-13.0 - 7.0 * S6, -13.0 + 7.0 * S6, -1.0]) / 3.0
MU_REAL = 3.0 + 3.0 ** (2.0 / 3.0) - 3.0 ** (1.0 / 3.0)
MU_COMPLEX = 3.0 + 0.5 * (3.0 ** (1.0 / 3.0) - 3.0 ** (2.0 / 3.0)) - 0.5j * (3.0 ** (5.0 / 6.0) + 3.0 ** (7.0 / 6.0))
T = np.array([[0.09443876248897524, -0.14125529502095421, 0.03002919410514742],
              [0.25021312296533332, 0.20412935229379994, -0.38294211275726192],
              [1.0, 1.0, 0.0]])
TI = np.array([[4.17871859155190428, 0.32768282076106237, 0.52337644549944951],
               [-4.17871859155190428, -0.32768282076106237, 0.47662355450055044],
               [0.50287263494578682, -2.57192694985560522, 0.59603920482822492]])
P = np.array([[13.0 / 3.0 + 7.0 * S6 / 3.0, -23.0 / 3.0 - 22.0 * S6 / 3.0, 10.0 / 3.0 + 5.0 * S6],
              [13.0 / 3.0 - 7.0 * S6 / 3.0, -23.0 / 3.0 + 22.0 * S6 / 3.0, 10.0 / 3.0 - 5.0 * S6],
              [1.0 / 3.0, -8.0 / 3.0, 10.0 / 3.0]])
COEFFS = (C, E, T, TI, P)   # the `co` argument of `run`

NEWTON_MAXITER = 6
# Newton corrections that stop contracting (rate above this) while already below the error tolerance
# (RMS of dW / scale < 1) are the round-off of the right-hand side, not divergence: the iteration is
# converged. (An overdamped 1e9 N/m spring at rest: k eps |x| = 1e-7 m/s^2 of noise in f against a
# velocity atol of 5e-11 m/s held the step near 1e-8 s without this.)
STAGNATION = 0.9
FAC_MIN, FAC_MAX = 0.2, 10.0
EVALS_PER_RETURN = 1_000_000   # state entries x right-hand-side evaluations between returns to Python
CALLBACK_RETRIES = 24          # as fastdop: failed Python-callable loads in a row before the run ends
N_SCRATCH = 23                 # rows of the scratch S (n columns) that `run` takes
# rows of S: Z 0-2, W 3-5, F 6-8, Q 9-11 (the last accepted step's dense output), dW 12-14, ynew 15,
# scale 16, err 17, tmp 18, yo 19, yq 20 (the start of the step Q belongs to), the Jacobian's column groups
# 21, the columns' difference steps 22
# st: t, h, h_old, err_old, J current (0/1), h of the LU factors (0: none), Q valid (0/1), t of Q's step,
#     h of Q's step, J computed (0/1), column groups (0: none), grouped Jacobians since the last full one
N_ST = 12
JAC_REFRESH = 8   # grouped Jacobians between full ones (`_jacobian`)


@kernel(_nrt=False)
def _lu(A, piv):
    """In-place LU factorisation with partial pivoting of A (n x n, real or complex: `kkt_tree.lu_factor`,
    the project's one LU); piv: row swaps. False when a pivot is zero or not finite."""
    return lu_factor(A, A.shape[0], piv, 0.0)


@kernel(_nrt=False)
def _lu_solve(A, piv, b):
    """Solve with the factors of `_lu` in place of b (real or complex: `kkt_tree.lu_solve`)."""
    lu_solve(A, piv, A.shape[0], b)


@kernel(_nrt=False, inline="always")
def _fd_step(y_j):
    """Forward-difference step for a state component y_j: sqrt(eps max(1e-5, |y_j|)), as radau5.f."""
    return np.sqrt(2.220446049250313e-16 * max(1e-5, abs(y_j)))


@kernel(_nrt=False, inline="always")
def _fd_entry(ft_i, f_i, d):
    """The difference quotient (ft_i - f_i) / d; 1e-300 where it rounds to 0 although f_i changed (the
    entry stays in the sparsity pattern the column groups are made from)."""
    v = (ft_i - f_i) / d
    return v if v != 0.0 or ft_i == f_i else 1e-300


@kernel(_nrt=False)
def _full_jacobian(cm, wk, t, y, f, Jm, yt, ft):
    """Jm = df/dy at (t, y) (f = f(t, y)) by forward differences, step sqrt(eps max(1e-5, |y_j|)) as
    radau5.f; yt, ft: scratch. Returns a status (not OK: an evaluation failed)."""
    n = y.shape[0]
    for i in range(n):
        yt[i] = y[i]
    for j in range(n):
        yt[j] = y[j] + _fd_step(y[j])
        d = yt[j] - y[j]   # the step actually taken (representable)
        s_ = rhs(cm, wk, t, yt, ft, bool(True))
        yt[j] = y[j]
        if s_ != OK:
            return s_
        for i in range(n):
            Jm[i, j] = _fd_entry(ft[i], f[i], d)
    return OK


@kernel(_nrt=False)
def _column_groups(Jm, grp, mark):
    """Columns of Jm that share no nonzero row, in groups (Curtis, Powell and Reid): grp[j] the group of
    column j; mark: scratch (n). Greedy, one group per pass over the columns left; returns the number of
    groups, or 0 when grouping saves less than half of the columns (a dense Jacobian: no groups)."""
    n = Jm.shape[0]
    for j in range(n):
        grp[j] = -1.0
        mark[j] = -1.0
    left, g = n, 0
    while left > 0:
        if 2 * g >= n:
            return 0
        taken = 0
        for j in range(n):
            if grp[j] >= 0.0:
                continue
            ok = True
            for i in range(n):
                if Jm[i, j] != 0.0 and mark[i] == g:
                    ok = False
                    break
            if ok:
                grp[j] = g
                taken += 1
                for i in range(n):
                    if Jm[i, j] != 0.0:
                        mark[i] = g
        left -= taken
        g += 1
    return g if 2 * g < n else 0


@kernel(_nrt=False)
def _jacobian(cm, wk, t, y, f, Jm, S, st, stats):
    """Jm = df/dy at (t, y) (f = f(t, y)): by forward differences over every column (`_full_jacobian`, n
    evaluations) after each JAC_REFRESH grouped ones, and in between one evaluation per group of columns
    that share no nonzero row of the last full Jacobian (`_column_groups`: the free bodies of a pile of
    parts touch a few others; each group's columns are perturbed together, each difference read back on its
    column's rows). A coupling that appeared since the last full Jacobian is missing until the next one, or
    until Newton fails (then st[11] forces a full one): it slows Newton, not the accuracy, which the error
    estimate controls. Counts evaluations and Jacobians into stats; returns a status."""
    n = y.shape[0]
    yt, ft, grp, dj = S[18], S[17], S[21], S[22]
    G = int(st[10])
    if G == 0 or st[11] >= JAC_REFRESH:
        s_ = _full_jacobian(cm, wk, t, y, f, Jm, yt, ft)
        stats[2] += n
        stats[4] += 1
        st[10] = _column_groups(Jm, grp, dj) if s_ == OK else 0.0
        st[11] = 0.0
        return s_
    for i in range(n):
        yt[i] = y[i]
    for g in range(G):
        for j in range(n):
            if grp[j] == g:
                yt[j] = y[j] + _fd_step(y[j])
                dj[j] = yt[j] - y[j]
        s_ = rhs(cm, wk, t, yt, ft, bool(True))
        stats[2] += 1
        for j in range(n):
            if grp[j] == g:
                yt[j] = y[j]
                for i in range(n):
                    if Jm[i, j] != 0.0:   # the row's one column in this group (of the last full pattern,
                        # kept: an exact zero is stored as 1e-300, so the entry is read again next time)
                        v = _fd_entry(ft[i], f[i], dj[j])
                        Jm[i, j] = v if v != 0.0 else 1e-300
        if s_ != OK:
            st[11] = JAC_REFRESH
            return s_
    stats[4] += 1
    st[11] += 1.0
    return OK


@kernel(_nrt=False)
def _factor(Jm, LR, LC, piv, h):
    """LR = MU_REAL / h - Jm and LC = MU_COMPLEX / h - Jm, factorised; False when singular."""
    n = Jm.shape[0]
    mr = MU_REAL / h
    mc = MU_COMPLEX / h
    for i in range(n):
        for j in range(n):
            LR[i, j] = -Jm[i, j]
            LC[i, j] = -Jm[i, j]
        LR[i, i] += mr
        LC[i, i] += mc
    return _lu(LR, piv[0]) and _lu(LC, piv[1])


@kernel(_nrt=False)
def _newton(cm, wk, co, t, y, h, S, LR, LC, piv, cv, newton_tol, stats):
    """Simplified Newton iterations on the collocation system from the stages Z = S[0:3] (the guess);
    returns (converged, iterations, last contraction rate (-1: none), status of the evaluations)."""
    Cc, Tm, TIm = co[0], co[2], co[3]
    n = y.shape[0]
    Z, W, F, dW, scale, tmp = S[0:3], S[3:6], S[6:9], S[12:15], S[16], S[18]
    mr = MU_REAL / h
    mc = MU_COMPLEX / h
    for s in range(3):
        for i in range(n):
            W[s, i] = TIm[s, 0] * Z[0, i] + TIm[s, 1] * Z[1, i] + TIm[s, 2] * Z[2, i]
    norm_old = -1.0
    rate = -1.0
    for k in range(NEWTON_MAXITER):
        for s in range(3):
            for i in range(n):
                tmp[i] = y[i] + Z[s, i]
            s_ = rhs(cm, wk, t + Cc[s] * h, tmp, F[s], bool(True))
            stats[2] += 1
            if s_ != OK:
                return False, k + 1, rate, s_
        for i in range(n):
            fr = TIm[0, 0] * F[0, i] + TIm[0, 1] * F[1, i] + TIm[0, 2] * F[2, i]
            fi1 = TIm[1, 0] * F[0, i] + TIm[1, 1] * F[1, i] + TIm[1, 2] * F[2, i]
            fi2 = TIm[2, 0] * F[0, i] + TIm[2, 1] * F[1, i] + TIm[2, 2] * F[2, i]
            dW[0, i] = fr - mr * W[0, i]
            cv[i] = (fi1 + 1j * fi2) - mc * (W[1, i] + 1j * W[2, i])
        _lu_solve(LR, piv[0], dW[0])
        _lu_solve(LC, piv[1], cv)
        acc = 0.0
        for i in range(n):
            dW[1, i] = cv[i].real
            dW[2, i] = cv[i].imag
            for s in range(3):
                acc += (dW[s, i] / scale[i]) ** 2
        dnorm = np.sqrt(acc / (3 * n))
        if not np.isfinite(dnorm):
            return False, k + 1, rate, OK
        if norm_old >= 0.0:
            rate = dnorm / norm_old if norm_old > 0.0 else 0.0
            if rate >= 1.0 or rate ** (NEWTON_MAXITER - k) / (1.0 - rate) * dnorm > newton_tol:
                if rate > STAGNATION and dnorm < 1.0:   # no contraction, corrections below the tolerance:
                    return True, k + 1, rate, OK        # the round-off floor of f (see STAGNATION)
                return False, k + 1, rate, OK
        for s in range(3):
            for i in range(n):
                W[s, i] += dW[s, i]
        for s in range(3):
            for i in range(n):
                Z[s, i] = Tm[s, 0] * W[0, i] + Tm[s, 1] * W[1, i] + Tm[s, 2] * W[2, i]
        if dnorm == 0.0 or (rate >= 0.0 and rate / (1.0 - rate) * dnorm < newton_tol):
            return True, k + 1, rate, OK
        norm_old = dnorm
    return False, NEWTON_MAXITER, rate, OK


@kernel(_nrt=False)
def _error(cm, wk, co, t, y, f, h, S, LR, piv, rtol, atol, refilter, stats):
    """Hairer's error norm of the step (Z = S[0:3], ynew = S[15]): err = (MU_REAL / h - J)^-1 (f + sum_i
    E_i Z_i / h) in S[17], RMS against atol + rtol max(|y|, |ynew|); with `refilter`, the filter applied
    once more at y + err (after a rejection, as radau5.f). inf when not finite."""
    Eco = co[1]
    n = y.shape[0]
    Z, ynew, scale, err, tmp, ze = S[0:3], S[15], S[16], S[17], S[18], S[19]
    for i in range(n):
        ze[i] = (Eco[0] * Z[0, i] + Eco[1] * Z[1, i] + Eco[2] * Z[2, i]) / h
        err[i] = f[i] + ze[i]
        scale[i] = atol + max(abs(y[i]), abs(ynew[i])) * rtol
    _lu_solve(LR, piv[0], err)
    e = 0.0
    for i in range(n):
        e += (err[i] / scale[i]) ** 2
    e = np.sqrt(e / n)
    if refilter and e > 1.0 and np.isfinite(e):
        for i in range(n):
            tmp[i] = y[i] + err[i]
        s_ = rhs(cm, wk, t, tmp, err, bool(True))
        stats[2] += 1
        if s_ != OK:
            return np.inf
        for i in range(n):
            err[i] += ze[i]
        _lu_solve(LR, piv[0], err)
        e = 0.0
        for i in range(n):
            e += (err[i] / scale[i]) ** 2
        e = np.sqrt(e / n)
    return e if np.isfinite(e) else np.inf


@kernel(_nrt=False)
def _predict(h, h_old, e, e_old):
    """Gustafsson's predictive step-size factor (before safety and limits)."""
    if e == 0.0:
        return np.inf
    mult = 1.0
    if h_old > 0.0 and e_old > 0.0:
        mult = min(1.0, h / h_old * (e_old / e) ** 0.25)
    return mult * e ** -0.25


@entry(_nrt=False)
def run(cm, wk, co, st, y, f, t_end, tout, iout, Y, rtol, atol, max_step, max_steps, chunk, proj_tol, stats,
        Jm, LR, LC, piv, S, cv, SY, ST, SQ, ns, start_row):
    """Integrate from st[0] = t with state y (consistent) up to t_end, writing the projected output states
    at tout[iout:] into Y; stops after `chunk` outputs; returns (status, next iout). st (N_ST): the
    stepper's state between calls (st[1] = h = 0: the start, where f and the starting step are computed
    first, and with start_row a joint-coordinate tree's y from the absolute row Y[0]). f: f(t, y) on return.
    stats (int64): steps, rejected (failed Newton attempts included), rhs evaluations, projections,
    Jacobians, LU factorisations (pairs), accumulated. Jm, LR (n x n), LC (n x n complex), piv (2 x n
    int64), S (N_SCRATCH x n), cv (n complex): work arrays kept between calls (J, factors, last step).
    Checkpoints: when SY has rows, each accepted step's start state goes to SY[ns[0]], its (t, h) to
    ST[ns[0]] and its dense output coefficients to SQ[ns[0]] (3 x n); full: CHECKPOINTS_FULL."""
    Cc, Pm = co[0], co[4]
    nq = cm[31][0]
    n = y.shape[0]
    Z, Q, ynew, scale, yo, yq = S[0:3], S[9:12], S[15], S[16], S[19], S[20]
    t, h = st[0], st[1]
    if h <= 0.0:
        if start_row and cm[31][5] == 1:
            read_state(cm, wk, Y[0], y)
        s_ = rhs(cm, wk, t, y, f, bool(True))
        if s_ != OK:
            return s_, iout
        h = initial_step(cm, wk, t, y, f, rtol, atol, max_step, S[17], S[16], S[18], 3)
        st[1] = h
        start(cm, wk, t, y, S[17])   # joint friction: the switching values at the (re)start
        for k in range(2, N_ST):
            st[k] = 0.0
    n_sensors = wk[44][2].shape[0]
    eps = 2.220446049250313e-16
    newton_tol = max(10.0 * eps / rtol, min(0.03, np.sqrt(rtol)))
    budget = max(EVALS_PER_RETURN // max(n, 1), 200)
    nfev0, steps0 = stats[2], stats[0]
    written = 0
    rejected = False
    failed = 0
    while iout < tout.shape[0]:
        if stats[2] - nfev0 >= budget:
            break
        if not (h > 0.0 and np.isfinite(h)):
            st[0], st[1] = t, h
            return TINY_STEP, iout
        if stats[0] >= max_steps:
            st[0], st[1] = t, h
            return MAX_STEPS, iout
        if SY.shape[0] > 0 and ns[0] >= SY.shape[0]:
            st[0], st[1] = t, h
            return CHECKPOINTS_FULL, iout
        if n_sensors > 0 and wk[44][5][0] + n_sensors > wk[44][4].shape[0]:
            st[0], st[1] = t, h
            return EVENTS_FULL, iout
        hmin = 10.0 * eps * max(abs(t), 1.0)
        h = min(h, max_step, t_end - t)
        if h < hmin:
            if t_end - t > hmin:
                st[0], st[1] = t, h
                return TINY_STEP, iout
            h = t_end - t
        if st[6] != 0.0:   # the stages' starting guess: the last step's collocation polynomial extrapolated
            for s in range(3):
                dense(Q, yq, st[7], st[8], t + Cc[s] * h, Z[s])
                for i in range(n):
                    Z[s, i] -= y[i]
        else:
            for s in range(3):
                for i in range(n):
                    Z[s, i] = 0.0
        for i in range(n):
            scale[i] = atol + abs(y[i]) * rtol
        converged, n_iter, rate, s_ = False, 0, -1.0, OK
        for attempt in range(2):
            if st[9] == 0.0:
                s_ = _jacobian(cm, wk, t, y, f, Jm, S, st, stats)
                if s_ != OK:
                    break
                st[9], st[4], st[5] = 1.0, 1.0, 0.0
            if st[5] != h:
                stats[5] += 1
                st[5] = h
                if not _factor(Jm, LR, LC, piv, h):
                    st[5] = 0.0
                    break
            if attempt > 0:   # the guess again (the failed attempt changed Z)
                for s in range(3):
                    if st[6] != 0.0:
                        dense(Q, yq, st[7], st[8], t + Cc[s] * h, Z[s])
                        for i in range(n):
                            Z[s, i] -= y[i]
                    else:
                        for i in range(n):
                            Z[s, i] = 0.0
            converged, n_iter, rate, s_ = _newton(cm, wk, co, t, y, h, S, LR, LC, piv, cv, newton_tol, stats)
            if converged or st[4] != 0.0 or s_ != OK:
                break
            st[9], st[11] = 0.0, JAC_REFRESH   # Newton failed with an old Jacobian: a fresh, full one at (t, y)
        if s_ != OK and wk[48][1][1] != 0:   # a Python-callable load failed (as fastdop)
            wk[48][1][1] = 0
            failed += 1
            if failed >= CALLBACK_RETRIES:
                st[0], st[1] = t, h
                return CALLBACK_FAILED, iout
        if not converged:
            stats[1] += 1
            h *= 0.5
            st[5] = 0.0
            rejected = True
            continue
        failed = 0
        for i in range(n):
            ynew[i] = y[i] + Z[2, i]
        err = _error(cm, wk, co, t, y, f, h, S, LR, piv, rtol, atol, rejected or stats[0] == 0, stats)
        safety = 0.9 * (2 * NEWTON_MAXITER + 1) / (2 * NEWTON_MAXITER + n_iter)
        if err > 1.0:
            stats[1] += 1
            h *= max(FAC_MIN, safety * _predict(h, st[2], err, st[3])) if np.isfinite(err) else 0.25
            st[5] = 0.0
            rejected = True
            continue
        rejected = False
        recompute_jac = n_iter > 2 and rate > 1e-3
        fac = min(FAC_MAX, safety * _predict(h, st[2], err, st[3]))
        if not recompute_jac and fac < 1.2:
            fac = 1.0
        t_new = t + h
        stats[0] += 1
        for j in range(3):   # Q = Z^T P: the step's collocation polynomial
            for i in range(n):
                Q[j, i] = Z[0, i] * Pm[0, j] + Z[1, i] * Pm[1, j] + Z[2, i] * Pm[2, j]
        if SY.shape[0] > 0:
            for i in range(n):
                SY[ns[0], i] = y[i]
                for j in range(3):
                    SQ[ns[0], j, i] = Q[j, i]
            ST[ns[0], 0] = t
            ST[ns[0], 1] = h
            ns[0] += 1
        tol_end = 1e-14 * max(1.0, abs(t_new))
        while iout < tout.shape[0] and tout[iout] < t_new - tol_end:   # outputs inside the step
            to = tout[iout]
            dense(Q, y, t, h, to, yo)
            s_ = _project(cm, wk, to, yo, proj_tol, bool(False))   # a tree: its coordinate constraints and drivers
            stats[3] += 1
            if s_ != OK:
                st[0], st[1] = t, h
                return s_, iout
            write_state(cm, wk, yo, Y[iout], Y[iout - 1] if iout > 0 else Y[iout, :0])
            iout += 1
            written += 1
        if cm[48][0].shape[0]:   # a stick/slip event in the step: the state there, back to the caller
            t_ev = friction_event(cm, wk, Q, y, t, h, ynew, S[17], S[18])
            if t_ev < np.inf:
                return stop_at(cm, wk, Q, y, t, h, t_ev, tout, iout, proj_tol, st, stats, yo)
        if n_sensors > 0:   # the sensors' crossings in the step (fastswitch): a "stop" ends the run there,
            t_stop, t_cut = sensor_event(cm, wk, Q, y, t, h, ynew, S[17], S[18])   # a switching zero the step
            if t_stop < np.inf or t_cut < np.inf:
                return sensor_stop(cm, wk, Q, y, t, h, t_stop, t_cut, tout, iout, proj_tol, st, stats, yo)
        for i in range(n):
            yq[i] = y[i]
            y[i] = ynew[i]
        st[6], st[7], st[8] = 1.0, t, h
        if cm[31][5] != 1 or cm[47][3].shape[0] > 1:   # a tree: only with coordinate constraints or drivers
            s_ = _project(cm, wk, t_new, y, proj_tol, bool(True))
            stats[3] += 1
            if s_ != OK:
                st[0], st[1] = t, h
                return s_, iout
        for i in range(n):
            if not np.isfinite(y[i]):
                st[0], st[1] = t, h
                return NONFINITE, iout
        s_ = rhs(cm, wk, t_new, y, f, bool(True))
        stats[2] += 1
        if s_ != OK:
            st[0], st[1] = t_new, h
            return s_, iout
        accept_state(cm, wk)   # joint angles read from the frames: continued from this state on
        while iout < tout.shape[0] and tout[iout] <= t_new + tol_end:   # outputs at the step's end
            write_state(cm, wk, y, Y[iout], Y[iout - 1] if iout > 0 else Y[iout, :0])
            iout += 1
            written += 1
        if recompute_jac:
            s_ = _jacobian(cm, wk, t_new, y, f, Jm, S, st, stats)
            st[5] = 0.0
            if s_ == OK:
                st[9], st[4] = 1.0, 1.0
            else:
                st[9], st[4] = 0.0, 0.0
        else:
            st[4] = 0.0
        st[2], st[3] = h, err
        t = t_new
        h *= fac
        if (written >= chunk or stats[0] - steps0 >= 50 * chunk) and iout < tout.shape[0]:
            break
    st[0], st[1] = t, h
    return OK, iout
