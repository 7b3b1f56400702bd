"""HHT-alpha compiled with numba: the named implicit method "hht" on the compiled O(N) equations of motion.

The ODE form of Hilber, Hughes & Taylor's method on the second-order system qdd = f(q, qd) that the
compiled right-hand side (`fastdyn.rhs`: the tree elimination in absolute coordinates, the articulated-
body algorithm in joint coordinates) gives after eliminating the constraints. Unknowns of a step: the
accelerations a = a_{n+1} (nv, the velocity layout of the state's second half):

    dx      = h v_n + h^2 ((1/2 - beta) a_n + beta a)      (tangent increment: CM translations, body-axes
    q_{n+1} = q_n (+) dx                                    rotation vectors; joint coordinates: a sum)
    v_{n+1} = v_n + h ((1 - gamma) a_n + gamma a)
    r(a)    = a - (1 + alpha) f(t_{n+1}, q_{n+1}, v_{n+1}) + alpha f(t_n, q_n, v_n) = 0

with beta = (1 - alpha)^2 / 4, gamma = 1/2 - alpha, alpha in [-1/3, 0] (`solvers.hht.ALPHA`, numerical
damping of the high frequencies at second order). Simplified Newton iterations on r with the matrix
I - (1 + alpha) (beta h^2 K + gamma h C), where K = df/dx (tangent positions) and C = df/dv are forward
differences of f (2 nv evaluations), kept across steps while Newton converges and refactored (`fastradau._lu`)
when h changes by more than 20 %. Local error (Zienkiewicz & Xie): e = h^2 |beta - 1/6| (a_{n+1} - a_n),
weighted as the reference implementation (`solvers.hht._error`) by atol + rtol max(|h v_n|, |h v_{n+1}|)
+ 1e-3 rtol; step factor 0.9 err^(-1/3) within 0.5..2 (0.2 after a rejection). After each accepted step
the state is projected onto the constraints (`fastdop._project`, as the other compiled steppers) and f is
evaluated there. Dense output: the cubic Hermite polynomial of the state y = [q, v] from (y_n, [qdot_n,
a_n]) to (y_{n+1}, [qdot_{n+1}, a_{n+1}]) in the form of `fastradau.dense` (y0 + x (Q0 + x (Q1 + x Q2))),
projected at each output; the same checkpoints as Radau's (`solvers.radau_run`), so `Result.at` between
outputs is this run's own interpolant.

Every loop is bounded (NEWTON_MAXITER, max_steps, a return to Python after EVALS_PER_RETURN state entries x
evaluations so that Ctrl-C is honoured); no allocation inside (`_nrt=False`).
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import entry, kernel
from .fastdop import CHECKPOINTS_FULL, EVENTS_FULL, _project
from .fastdyn import (CALLBACK_FAILED, MAX_STEPS, NONFINITE, OK, TINY_STEP, _to6, accept_state, increment_into, read_state,
                      rhs, write_state)
from .fastradau import _lu, _lu_solve
from .fastswitch import dense, friction_event, sensor_event, sensor_stop, start, stop_at

NEWTON_MAXITER = 8
STAGNATION = 0.9        # as fastradau: corrections that stop contracting below the tolerance are converged
EVALS_PER_RETURN = 1_000_000
CALLBACK_RETRIES = 24
N_SCRATCH = 19
# rows of S (n columns): a_n 0, a 1, f_n 2, y1 3, f1 4, r 5, dx 6, ynew 7, yo 8, tmp 9, Q 10-12, yq 13,
# scale 14, da 15, y_n copy for the FD tangent 16, f at the perturbed state 17, a_n at Q's end 18
# st: t, h, J current (0/1), h of the LU factors (0: none), Q valid (0/1), t of Q's step, h of Q's step,
#     J computed (0/1), a_n valid (0/1)
N_ST = 9
ROT_STEP = 0.25   # rad: the most one step turns a rigid body (`_rotation_step`)


@kernel(_nrt=False)
def split(cm, n):
    """Index of the first velocity entry of a state of size n: nq (absolute coordinates) or n / 2 (a
    joint-coordinate tree, y = [theta, theta_dot])."""
    if cm[31][5] == 1:
        return n // 2
    return cm[31][0]


@kernel(_nrt=False)
def advance(cm, y0, dx, dv, y1, D6):
    """y1 = [q0 (+) dx, v0 + dv] (dx, dv: nv); D6 (nf, 6): scratch of the absolute increment."""
    n = y0.shape[0]
    m = split(cm, n)
    for i in range(n - m):
        y1[m + i] = y0[m + i] + dv[i]
    if cm[31][5] == 1:
        for i in range(m):
            y1[i] = y0[i] + dx[i]
        return
    for i in range(m):
        y1[i] = y0[i]
    _to6(cm, dx, D6)
    increment_into(cm, y1[:m], D6)


@kernel(_nrt=False)
def _state(cm, co, y, a0, a, h, S, D6):
    """S[3] = the Newmark state of the step h from y with accelerations a0 (start) and a (end)."""
    beta, gam = co[1], co[2]
    n = y.shape[0]
    m = split(cm, n)
    nv = n - m
    dx, dv = S[6], S[9]
    for i in range(nv):
        dx[i] = h * y[m + i] + h * h * ((0.5 - beta) * a0[i] + beta * a[i])
        dv[i] = h * ((1.0 - gam) * a0[i] + gam * a[i])
    advance(cm, y, dx[:nv], dv[:nv], S[3], D6)


@kernel(_nrt=False)
def _trial(cm, wk, co, t1, y, a0, fa0, a, h, S, D6):
    """The state S[3] of the acceleration guess a, f there (S[4]) and the residual r(a) (S[5]); a status."""
    alpha = co[0]
    n = y.shape[0]
    m = split(cm, n)
    nv = n - m
    y1, f1, r = S[3], S[4], S[5]
    _state(cm, co, y, a0, a, h, S, D6)
    s_ = rhs(cm, wk, t1, y1, f1)
    if s_ != OK:
        return s_
    for i in range(nv):
        r[i] = a[i] - (1.0 + alpha) * f1[m + i] + alpha * fa0[i]
    return OK


@kernel(_nrt=False)
def _tangent(cm, wk, t, y, f, Jm, S, D6):
    """Jm = [K | C] (nv x 2 nv): df/dx (tangent position increments) and df/dv at (t, y), f = f(t, y), by
    forward differences; a status (not OK: an evaluation failed)."""
    n = y.shape[0]
    m = split(cm, n)
    nv = n - m
    yt, ft, dx, dv = S[16], S[17], S[15], S[9]
    scale = 1e-3
    for i in range(m):
        scale = max(scale, abs(y[i]))
    eps = 1.4901161193847656e-08
    for j in range(2 * nv):
        for i in range(nv):
            dx[i] = 0.0
            dv[i] = 0.0
        if j < nv:
            d = eps * scale
            dx[j] = d
        else:
            d = eps * max(1e-3, abs(y[m + j - nv]))
            dv[j - nv] = d
        advance(cm, y, dx[:nv], dv[:nv], yt, D6)
        s_ = rhs(cm, wk, t, yt, ft)
        if s_ != OK:
            return s_
        for i in range(nv):
            Jm[i, j] = (ft[m + i] - f[m + i]) / d
    return OK


@kernel(_nrt=False)
def _factor(co, Jm, LR, piv, h):
    """LR = I - (1 + alpha) (beta h^2 K + gamma h C), factorised; False when singular."""
    alpha, beta, gam = co[0], co[1], co[2]
    nv = LR.shape[0]
    ck, cc = (1.0 + alpha) * beta * h * h, (1.0 + alpha) * gam * h
    for i in range(nv):
        for j in range(nv):
            LR[i, j] = -ck * Jm[i, j] - cc * Jm[i, nv + j]
        LR[i, i] += 1.0
    return _lu(LR, piv)


@kernel(_nrt=False)
def _newton(cm, wk, co, t1, y, h, S, LR, piv, newton_tol, stats, D6):
    """Simplified Newton iterations on r(a) from a = S[1] (the guess); returns (converged, iterations,
    last contraction rate (-1: none), status). The scale of the corrections: beta h^2 da against the
    position weights S[14]."""
    beta = co[1]
    n = y.shape[0]
    m = split(cm, n)
    nv = n - m
    a0, a, fa0, r, scale = S[0], S[1], S[2], S[5], S[14]
    norm_old = -1.0
    rate = -1.0
    for k in range(NEWTON_MAXITER):
        s_ = _trial(cm, wk, co, t1, y, a0, fa0[m:], a, h, S, D6)
        stats[2] += 1
        if s_ != OK:
            return False, k + 1, rate, s_
        for i in range(nv):
            r[i] = -r[i]
        _lu_solve(LR, piv, r[:nv])
        acc = 0.0
        for i in range(nv):
            a[i] += r[i]
            acc += (beta * h * h * r[i] / scale[i]) ** 2
        dnorm = np.sqrt(acc / max(nv, 1))
        if not np.isfinite(dnorm):
            return False, k + 1, rate, OK
        if norm_old >= 0.0:
            rate = dnorm / norm_old if norm_old > 0.0 else 0.0
            if rate >= 1.0 or rate ** (NEWTON_MAXITER - k) / (1.0 - rate) * dnorm > newton_tol:
                if rate > STAGNATION and dnorm < 1.0:
                    return True, k + 1, rate, OK
                return False, k + 1, rate, OK
        if dnorm == 0.0 or (rate >= 0.0 and rate / (1.0 - rate) * dnorm < newton_tol) or dnorm < 1e-3 * newton_tol:
            return True, k + 1, rate, OK
        norm_old = dnorm
    return False, NEWTON_MAXITER, rate, OK


@kernel(_nrt=False)
def _error(co, y, ynew, a0, a, h, m, rtol, atol):
    """Zienkiewicz-Xie error norm of the step (RMS over the velocity layout)."""
    beta = co[1]
    nv = y.shape[0] - m
    c = h * h * abs(beta - 1.0 / 6.0)
    e = 0.0
    for i in range(nv):
        sc = atol + rtol * max(abs(h * y[m + i]), abs(h * ynew[m + i])) + rtol * 1e-3
        e += (c * (a[i] - a0[i]) / sc) ** 2
    e = np.sqrt(e / max(nv, 1))
    return e if np.isfinite(e) else np.inf


@kernel(_nrt=False)
def _hermite(y0, yd0, y1, yd1, h, Q):
    """Q (3 x n): y(t0 + x h) = y0 + x (Q0 + x (Q1 + x Q2)), the cubic Hermite polynomial of (y0, yd0) and
    (y1, yd1) over the step h (the form of `fastradau.dense`)."""
    for i in range(y0.shape[0]):
        d = y1[i] - y0[i]
        Q[0, i] = h * yd0[i]
        Q[1, i] = 3.0 * d - 2.0 * h * yd0[i] - h * yd1[i]
        Q[2, i] = h * (yd0[i] + yd1[i]) - 2.0 * d


@kernel(_nrt=False)
def _slope(y, f, a, m, out):
    """[qdot, a]: the state's rate with HHT's accelerations a in place of f's."""
    for i in range(m):
        out[i] = f[i]
    for i in range(y.shape[0] - m):
        out[m + i] = a[i]


@kernel(_nrt=False, inline="always")
def _rotation_step(cm, y, m):
    """The longest step [s] that turns no rigid body by more than ROT_STEP at its angular velocity in y
    (absolute coordinates; np.inf for joint coordinates). With constant accelerations the Zienkiewicz-Xie
    estimate is near zero, and a step that turns a body by more than about pi leaves the Euler parameters'
    and the auxiliary angles' branches (a gear in a loop spun up by a torque ran 3 rad off)."""
    if cm[31][5] != 0:
        return np.inf
    W = cm[3]
    w2 = 0.0
    for k in range(W.shape[0]):
        s2 = 0.0
        for j in range(3):
            s2 += y[m + W[k, j]] ** 2
        w2 = max(w2, s2)
    return ROT_STEP / np.sqrt(w2) if w2 > 0.0 else np.inf


@entry(_nrt=False)
def run(cm, wk, co, st, y, f, t_end, tout, iout, Y, rtol, atol, max_step, max_steps, chunk, proj_tol, stats,
        Jm, LR, piv, S, D6, SY, ST, SQ, ns, start_row):
    """Integrate from st[0] = t with state y (consistent) up to t_end, writing the projected output states at
    tout[iout:] into Y; stops after `chunk` outputs; returns (status, next iout). co = (alpha, beta, gamma).
    st (N_ST): the stepper's state between calls (st[1] = h = 0: the start; with start_row a joint-coordinate
    tree's y from the absolute row Y[0]). f: f(t, y) on return. stats (int64): steps, rejected (failed Newton
    attempts included), rhs evaluations, projections, tangents, LU factorisations, accumulated. Jm (nv x 2 nv),
    LR (nv x nv), piv (nv int64), S (N_SCRATCH x n), D6 (nf x 6): work arrays kept between calls. Checkpoints
    as fastradau.run (SY, ST, SQ: start state, (t, h), Hermite coefficients of each accepted step)."""
    n = y.shape[0]
    m = split(cm, n)
    nv = n - m
    a0, a, fn, Q, yq, scale, ynew, yo, slope = S[0], S[1], S[2], S[10:13], S[13], S[14], S[7], S[8], S[16]
    t, h = st[0], st[1]
    if h <= 0.0:
        if start_row and cm[31][5] == 1:
            read_state(cm, wk, Y[0], y)
        s_ = rhs(cm, wk, t, y, f)
        stats[2] += 1
        if s_ != OK:
            return s_, iout
        if st[8] == 0.0:   # a_0 = f(t_0, y_0) (consistent start)
            for i in range(nv):
                a0[i] = f[m + i]
        an = 0.0
        for i in range(nv):
            sc = atol + rtol * max(abs(y[m + i]), 1e-3)
            an += (a0[i] / sc) ** 2
        an = np.sqrt(an / max(nv, 1))
        h = 0.1 * (1.0 / max(an, 1e-10)) ** 0.5 if an > 0.0 else 1e-2
        h = min(h, max_step)
        if t_end > t:
            h = min(h, (t_end - t) / 100.0)
        st[1] = h
        for k in range(2, N_ST):
            st[k] = 0.0
        st[8] = 1.0
        start(cm, wk, t, y, S[9])   # joint friction: the switching values at the (re)start
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
        h = min(h, max_step, t_end - t, _rotation_step(cm, y, m))
        if h < hmin:
            if t_end - t > hmin:
                st[0], st[1] = t, h
                return TINY_STEP, iout
            h = t_end - t
        for i in range(n):
            fn[i] = f[i]
        for i in range(nv):   # Newton's weights: at most 1e-6 relative, whatever a loose rtol asks
            scale[i] = min(atol, 1e-8) + min(rtol, 1e-6) * max(abs(h * y[m + i]), 1e-3)
        converged, n_iter, rate, s_ = False, 0, -1.0, OK
        for attempt in range(2):
            if st[7] == 0.0:
                s_ = _tangent(cm, wk, t, y, f, Jm, S, D6)
                stats[2] += 2 * nv
                stats[4] += 1
                if s_ != OK:
                    break
                st[7], st[2], st[3] = 1.0, 1.0, 0.0
            if st[3] != h:
                stats[5] += 1
                st[3] = h
                if not _factor(co, Jm, LR, piv, h):
                    st[3] = 0.0
                    break
            for i in range(nv):   # the guess: a_{n+1} = a_n
                a[i] = a0[i]
            converged, n_iter, rate, s_ = _newton(cm, wk, co, t + h, y, h, S, LR, piv, newton_tol, stats, D6)
            if converged or st[2] != 0.0 or s_ != OK:
                break
            st[7] = 0.0   # Newton failed with an old tangent: a fresh one at (t, y)
        if s_ != OK and wk[48][1][1] != 0:   # a Python-callable load failed (as fastdop)
            wk[48][1][1] = 0
            failed += 1
            if failed >= CALLBACK_RETRIES:
                st[0], st[1] = t, h
                return CALLBACK_FAILED, iout
        if not converged:
            stats[1] += 1
            h *= 0.25
            st[3] = 0.0
            rejected = True
            continue
        failed = 0
        _state(cm, co, y, a0, a, h, S, D6)   # the state of the converged a
        for i in range(n):
            ynew[i] = S[3, i]
        err = _error(co, y, ynew, a0, a, h, m, rtol, atol)
        if err > 1.0:
            stats[1] += 1
            h *= max(0.2, 0.9 * err ** (-1.0 / 3.0)) if np.isfinite(err) else 0.25
            st[3] = 0.0
            rejected = True
            continue
        fac = min(2.0, max(0.5, 0.9 * max(err, 1e-10) ** (-1.0 / 3.0)))
        if rejected:
            fac = min(fac, 1.0)
        if 1.0 <= fac < 1.2:
            fac = 1.0   # keep h (and the factors)
        rejected = False
        recompute = n_iter > 2 and rate > 1e-3
        t_new = t + h
        stats[0] += 1
        if cm[31][5] != 1 or cm[47][3].shape[0] > 1:   # as fastradau: a tree only with coordinate rows
            s_ = _project(cm, wk, t_new, ynew, proj_tol)
            stats[3] += 1
            if s_ != OK:
                st[0], st[1] = t, h
                return s_, iout
        for i in range(n):
            if not np.isfinite(ynew[i]):
                st[0], st[1] = t, h
                return NONFINITE, iout
        s_ = rhs(cm, wk, t_new, ynew, f)
        stats[2] += 1
        if s_ != OK:
            st[0], st[1] = t_new, h
            return s_, iout
        accept_state(cm, wk)   # joint angles read from the frames: continued from this state on
        _slope(y, fn, a0, m, slope)   # the step's Hermite polynomial: rates [qdot, a] at both ends
        _slope(ynew, f, a, m, yo)
        _hermite(y, slope, ynew, yo, h, Q)
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
            s_ = _project(cm, wk, to, yo, proj_tol, False)
            stats[3] += 1
            if s_ != OK:
                st[0], st[1] = t, h
                return s_, iout
            write_state(cm, wk, yo, Y[iout], Y[iout - 1] if iout > 0 else Y[iout, :0])
            iout += 1
            written += 1
        if cm[48][0].shape[0]:   # a stick/slip event in the step (fastswitch): the state there, to the caller
            t_ev = friction_event(cm, wk, Q, y, t, h, ynew, S[9], S[17])
            if t_ev < np.inf:
                return stop_at(cm, wk, Q, y, t, h, t_ev, tout, iout, proj_tol, st, stats, yo)
        if n_sensors > 0:   # the sensors' crossings in the step (fastswitch): a "stop" ends the run there,
            t_stop, t_cut = sensor_event(cm, wk, Q, y, t, h, ynew, S[9], S[17])   # a switching zero the step
            if t_stop < np.inf or t_cut < np.inf:
                return sensor_stop(cm, wk, Q, y, t, h, t_stop, t_cut, tout, iout, proj_tol, st, stats, yo)
        for i in range(n):
            yq[i] = y[i]
            y[i] = ynew[i]
        for i in range(nv):
            a0[i] = a[i]
        st[4], st[5], st[6] = 1.0, t, h
        while iout < tout.shape[0] and tout[iout] <= t_new + tol_end:   # outputs at the step's end
            write_state(cm, wk, y, Y[iout], Y[iout - 1] if iout > 0 else Y[iout, :0])
            iout += 1
            written += 1
        if recompute:
            st[7], st[2] = 0.0, 0.0
        else:
            st[2] = 0.0
        t = t_new
        h *= fac
        if (written >= chunk or stats[0] - steps0 >= 50 * chunk) and iout < tout.shape[0]:
            break
    st[0], st[1] = t, h
    return OK, iout
