"""DOP853 (Hairer's explicit Runge-Kutta 8(5,3) with 7th-order dense output) compiled with numba.

The whole step loop runs in compiled code: stages (the O(N) equations of motion of `fastdyn`), the
error norm, step-size control, coordinate projection after every accepted step, the outputs at the
requested times (dense output, then projection; an output at a step's end is that step's projected
state, no dense output computed; accelerations and multipliers after the run, on
demand: `outputs_at`) and the model's expression sensors (`_watch`: crossings located on the step's
dense output). Python is re-entered only when a chunk of outputs is written, after a bounded amount of work
(EVALS_PER_RETURN: Ctrl-C within a fraction of a second), when the sensor event buffer is full, at a
sensor's stop, at the end, or on failure; every loop inside is bounded (the step size shrinks
geometrically on rejection down to the round-off limit, TINY_STEP; projections take at most 12 Newton
steps, PROJECTION). The Butcher tableau is scipy's
(`scipy.integrate._ivp.dop853_coefficients`); the control follows scipy's `DOP853`: error norm
|h| |e5|^2 / sqrt(n (|e5|^2 + 0.01 |e3|^2)) with scale atol + rtol max(|y_old|, |y_new|), safety 0.9,
factor limits 0.2..10, exponent -1/8. The step's pieces (starting step, stages, dense output, projection,
the watched sensors and friction switching functions) are in `fastdopstep`, re-exported here.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import entry, kernel  # noqa: F401  (njit without the wrappers that dominate compilation; issue 32)
from ._dop853_tableau import coefficients as _c   # scipy's tableau, without importing scipy.integrate

from .fastdopstep import (N_STAGES, SENSOR_XTOL, _dense, _dense_coeffs, _end_at, _friction_g, _project,  # noqa: F401
                          _rms, _sensor_g, _sensor_time, _signal, _stages, _watch, _watch_friction, drop_after,
                          initial_step, locate_sensors, sensor_crossings)
from .fastenergystep import (energy_dense, energy_event, energy_first, energy_flag, energy_kinetic, energy_output,
                             energy_refine, energy_step)
from .fastdyn import (CALLBACK_FAILED, MAX_STEPS, NONFINITE, OK, SINGULAR, STIFF, TINY_STEP, accelerations,
                      accept_state, joint_rows, project, read_state, rhs, tree_project, write_state)

CHECKPOINTS_FULL = 8   # run status: the checkpoint arrays are full (grow them and call again)
SENSOR_STOP = 9        # run status: a sensor with action "stop" was met; y is the state at its time st[0]
EVENTS_FULL = 10       # run status: the sensor event buffer is full (hand the events over and call again)
FRICTION_EVENT = 13    # run status: a joint-friction switching function crossed zero; y is the state at st[0]
SENSOR_FAILED = 14     # run status: a sensor's value is not finite (a Python-callable sensor raised); y, st[0]:
#                        the last accepted state before it (every stepper: fastdop, fasthht, fastradau)
SWITCH_EVENT = 15      # run status (implicit steppers): a stop's clearance or a contact's gap crossed zero; y is
#                        the state at st[0] (restart there: solvers.fastswitch)

# Hairer's stiffness test flags h |df|/|dy| above this; dop853.f uses 6.1, but stability-limited steps of an
# overdamped 1e9 N/m spring hovered at 5.7 and were never flagged (0.74 s against HHT's 0.08 s): 5.0 is
# ~0.8 of DOP853's real-axis stability bound, above what accuracy-limited steps give
STIFF_RATIO = 5.0
CALLBACK_RETRIES = 24   # a step whose Python-callable load fails is retried 4x shorter, this many times in a row
FAC_MIN, FAC_MAX = 0.2, 10.0   # step-size change bounds per step (scipy's; Hairer's 1/3..6 hid the
# stability-limited steps of stiff models from the stiffness test, tests/test_compiled_core.py)
# `run` returns to Python (progress, Ctrl-C) after this many state entries x right-hand-side evaluations
# (rejected steps included): a fraction of a second for any model size
EVALS_PER_RETURN = 1_000_000
COEFFS = (np.ascontiguousarray(_c.A), np.ascontiguousarray(_c.B), np.ascontiguousarray(_c.C),
          np.ascontiguousarray(_c.E3), np.ascontiguousarray(_c.E5), np.ascontiguousarray(_c.D))





@entry(_nrt=False)
def outputs_at(cm, wk, times, Y, YJ, VD, LAM):
    """Accelerations VD and multipliers LAM at the output states Y (rows at `times`), computed after the
    run and only when a result asks for them; returns the number of rows done (< len on failure).
    YJ: on the tree path the joint-coordinate state of each row (continuous angles: what joint loads
    read); in absolute coordinates the references of the joint angles read from the frames at each row
    (wk[44][7]: one column per measure, within pi of the row's continued angle), or empty (0 columns)."""
    nq = cm[31][0]
    tree = cm[31][5] == 1
    for k in range(times.shape[0]):
        y = YJ[k] if tree and YJ.shape[1] else Y[k, :nq]
        if not tree and YJ.shape[1]:   # the references of the joint angles read from the frames
            for m in range(YJ.shape[1]):
                wk[44][7][m] = YJ[k, m]
        if accelerations(cm, wk, times[k], Y[k, :nq], Y[k, nq:], y, VD[k], LAM[k], bool(True)) != OK:
            return k
    return times.shape[0]











@entry(_nrt=False)
def run(cm, wk, co, st, y, f, t_end, tout, iout, Y, rtol, atol, max_step, max_steps, chunk,
        proj_tol, stats, K, F, sc, stiff_check, SY, ST, ns, watch=False):
    """Integrate from st = [t, h] with state y (projected) and f = ydot(t, y) up to t_end (h = 0: the start,
    where f and the starting step are computed first, and a joint-coordinate tree's y from the absolute
    state in Y[0]; a failure there returns with h still 0), writing the
    projected output states at tout[iout:] into Y (accelerations: `outputs_at`, on demand); stops after
    `chunk` outputs. Returns (status, next iout).
    stats: steps, rejected, rhs evaluations, projections, stiffness counters (int64, accumulated);
    K (16, n), F (7, n) and sc (4, n) are scratch. With stiff_check, Hairer's test (h |df| / |dy| > STIFF_RATIO
    on the last stage, 15 times without 6 non-stiff steps between) stops the run with STIFF.
    Checkpoints: when SY has rows, each accepted step's start state goes to SY[ns[0]] and its (t, h) to
    ST[ns[0]] (so that `from_checkpoint` redoes exactly that step for dense output on demand); when they
    are full the run returns CHECKPOINTS_FULL before its next step for the caller to grow them.
    With `watch`, the model's expression sensors (cm[43] slots 18-21) are evaluated after every accepted
    step (`_watch`): events go to the buffer wk[44][4] (EVENTS_FULL when it may not hold the next step's:
    hand them over, reset the count wk[44][5] and call again), and a "stop" event ends the run with
    SENSOR_STOP, the outputs up to its time written and y the state at st[0] = that time; a sensor value
    that is not finite (a Python-callable sensor that raised) ends it with SENSOR_FAILED at the step's start.
    After every accepted step the joint angles read from the frames take their continued values there as
    references (`fastdyn.accept_state`). With `watch` and
    joint friction (cm[48]), its switching functions are watched the same way (`_watch_friction`; their values
    at the start computed here, with the modes the caller set in wk[50]): the first zero ends the run with
    FRICTION_EVENT, the outputs up to its time written and y the projected state at st[0] = that time (the
    caller decides the modes there and restarts with h = 0).
    Energy bookkeeping (when wk[53][0][0] != 0, solvers.fastenergy): the dissipated energy D and the applied
    loads' work W [J] since the run's start, a quadrature state z = wk[53][4] integrated with the steps'
    own stage powers (`fastenergystep`: where they do not resolve the power, an adaptive quadrature on the
    step's dense output), go to wk[53][8][iout] with each output (the dense output of z inside a step); at
    a friction event or a sensor's stop z is the value at its time."""
    E3, E5 = co[3], co[4]
    en = wk[53]
    energy = en[0][0] != 0.0
    ZO = en[8]
    nq = cm[31][0]
    n = y.shape[0]
    ys, ynew, yo, scale = sc[0], sc[1], sc[2], sc[3]
    t, h = st[0], st[1]
    if h <= 0.0:   # the start (st = [t0, 0]): f = ydot(t0, y) and Hairer's starting step, here rather than
        if cm[31][5] == 1:          # from Python, so that a run loads one kernel (not counted in stats);
            read_state(cm, wk, Y[0], y)   # a joint-coordinate tree's y from the absolute start row Y[0]
        s_ = rhs(cm, wk, t, y, f, bool(True))
        if s_ != OK:
            return s_, iout
        if energy:   # the powers at the state of f
            en[2][0], en[2][1] = en[0][1], en[0][2]
        h = initial_step(cm, wk, t, y, f, rtol, atol, max_step, sc[0], sc[1], sc[2], 7)
        st[1] = h
        if watch:   # the sensors' values at the start: a sign change from them is an event
            _sensor_g(cm, wk, t, y, sc[3], wk[44][2])
            if cm[48][0].shape[0]:   # and the friction switching functions (the modes set by the caller)
                _friction_g(cm, wk, t, y, sc[3], wk[50][2])
    n_sensors = wk[44][2].shape[0] if watch else 0
    n_friction = cm[48][0].shape[0] if watch else 0
    written = 0
    steps0, nfev0 = stats[0], stats[2]
    failed = 0   # consecutive steps a Python-callable load failed in (solvers.pyloads)
    budget = max(EVALS_PER_RETURN // max(n, 1), 20 * N_STAGES)
    rejected = False
    eps = 2.220446049250313e-16
    while iout < tout.shape[0]:
        if stats[2] - nfev0 >= budget:
            break   # back to Python now and then (progress, Ctrl-C), rejected steps counted too
        if not (h > 0.0 and np.isfinite(h)):   # (a step size that is not a number would never shrink)
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
        for i in range(n):
            K[0, i] = f[i]
        if energy:
            energy_first(wk, en[2])
        ok = _stages(cm, wk, co, t, h, y, K, ys, ynew)
        stats[2] += N_STAGES
        if not ok and wk[48][1][1] != 0:   # a Python-callable load failed: smaller steps reach up to
            wk[48][1][1] = 0               # the failure (its outputs before it kept), then the run ends
            failed += 1
            if failed >= CALLBACK_RETRIES:
                st[0], st[1] = t, h
                return CALLBACK_FAILED, iout
        elif ok:
            failed = 0
        err = np.inf
        if ok:
            e5, e3 = 0.0, 0.0
            for i in range(n):
                scale[i] = atol + max(abs(y[i]), abs(ynew[i])) * rtol
                a5, a3 = 0.0, 0.0
                for j in range(N_STAGES + 1):
                    a5 += E5[j] * K[j, i]
                    a3 += E3[j] * K[j, i]
                e5 += (a5 / scale[i]) ** 2
                e3 += (a3 / scale[i]) ** 2
            err = 0.0 if (e5 == 0.0 and e3 == 0.0) else h * e5 / np.sqrt((e5 + 0.01 * e3) * n)
            if not np.isfinite(err):
                err = np.inf
        if err >= 1.0:
            stats[1] += 1
            h *= max(FAC_MIN, 0.9 * err ** (-1.0 / 8.0)) if np.isfinite(err) else 0.25
            rejected = True
            continue
        fac = FAC_MAX if err == 0.0 else max(FAC_MIN, min(FAC_MAX, 0.9 * err ** (-1.0 / 8.0)))
        if rejected:
            fac = min(1.0, fac)
        rejected = False
        t_new = t + h
        stats[0] += 1
        if energy:   # (the frames in wk are still the last stage's, at ynew: the energy scale from them)
            energy_kinetic(cm, wk)
            energy_step(co, wk, h)
        if SY.shape[0] > 0:
            for i in range(n):
                SY[ns[0], i] = y[i]
            ST[ns[0], 0] = t
            ST[ns[0], 1] = h
            ns[0] += 1
        if stiff_check:   # stats[4]: consecutive stiff verdicts, stats[5]: non-stiff ones since
            num, den = 0.0, 0.0
            for i in range(n):
                num += (K[N_STAGES, i] - K[N_STAGES - 1, i]) ** 2
                den += (ynew[i] - ys[i]) ** 2
            if den > 0.0 and h * np.sqrt(num / den) > STIFF_RATIO:
                stats[5] = 0
                stats[4] += 1
                if stats[4] >= 15:
                    st[0], st[1] = t, h
                    return STIFF, iout
            else:
                stats[5] += 1
                if stats[5] >= 6:
                    stats[4] = 0
        have_F = False
        tol_end = 1e-14 * max(1.0, abs(t_new))
        if energy:   # z's increment over the step, refined where the stage powers do not resolve the power
            en[1][1] = 0
            if energy_flag(co, wk, h, rtol):
                _dense_coeffs(cm, wk, co, t, h, y, ynew, K, ys, F)
                energy_dense(co, wk, h)
                have_F = True
                stats[2] += 3 + energy_refine(cm, wk, F, y, t, h, rtol, ys, scale)
        if tout[iout] < t_new - tol_end:   # outputs inside this step (those at its end: below)
            if not have_F:
                _dense_coeffs(cm, wk, co, t, h, y, ynew, K, ys, F)
                stats[2] += 3
                have_F = True
                if energy:
                    energy_dense(co, wk, h)
            while iout < tout.shape[0] and tout[iout] < t_new - tol_end:
                to = tout[iout]
                if energy and iout < ZO.shape[0]:
                    energy_output(wk, t, h, to, ZO[iout])
                _dense(F, y, t, h, to, yo)
                s_ = _project(cm, wk, to, yo, proj_tol, bool(False))
                stats[3] += 1
                if s_ != OK:
                    st[0], st[1] = t, h
                    return s_, iout
                write_state(cm, wk, yo, Y[iout], Y[iout - 1] if iout > 0 else Y[iout, :0])
                iout += 1
                written += 1
        if n_friction > 0:   # a stick/slip event: the outputs up to its time, the state there, and back to
            computed = have_F   # the caller, which decides the modes from it and restarts
            t_ev, have_F = _watch_friction(cm, wk, co, t, h, y, ynew, K, F, have_F, ys, scale)
            if have_F and not computed:
                stats[2] += 3
            if t_ev < np.inf:
                if energy:
                    energy_event(co, wk, t, h, t_ev)
                return _end_at(cm, wk, F, y, t, h, t_ev, tout, iout, proj_tol, st, stats, yo, bool(False),
                               bool(True), FRICTION_EVENT)
        if n_sensors > 0:
            computed = have_F
            t_stop, have_F = _watch(cm, wk, co, t, h, y, ynew, K, F, have_F, ys, scale)
            if have_F and not computed:
                stats[2] += 3
            if t_stop == -np.inf:   # a sensor's value is not finite (a Python-callable sensor failed): the run
                st[0], st[1] = t, h   # ends at the step's start, the outputs up to it kept
                return SENSOR_FAILED, drop_after(tout, iout, t)
            if t_stop < np.inf:   # a "stop" sensor: the outputs up to its time, and the state there
                if energy:
                    energy_event(co, wk, t, h, t_stop)
                return _end_at(cm, wk, F, y, t, h, t_stop, tout, iout, proj_tol, st, stats, yo, bool(False),
                               bool(False), SENSOR_STOP)
        for i in range(n):
            y[i] = ynew[i]
        if energy:   # z at the step's end; the powers at the state of f set below
            en[4][0], en[4][1] = en[5][0], en[5][1]
        if cm[31][5] == 1:   # joint coordinates: f(t_new, ynew) is the last stage unless the projection onto
            s_, moved = tree_project(cm, wk, t_new, y, proj_tol)   # coordinate constraints or drivers moved ynew
            if s_ != OK:
                st[0], st[1] = t, h
                return s_, iout
            if moved:
                stats[3] += 1
                s_ = rhs(cm, wk, t_new, y, f, bool(True))
                stats[2] += 1
                if energy:
                    en[2][0], en[2][1] = en[0][1], en[0][2]
            else:
                for i in range(n):
                    f[i] = K[N_STAGES, i]
                if energy:
                    en[2][0], en[2][1] = en[3][N_STAGES, 0], en[3][N_STAGES, 1]
        else:
            s_ = project(cm, wk, t_new, y[:nq], y[nq:], proj_tol, bool(True))
            stats[3] += 1
            if s_ != OK:
                st[0], st[1] = t, h
                return s_, iout
            s_ = rhs(cm, wk, t_new, y, f, bool(False))   # the projection's factorisation is at these positions
            stats[2] += 1
            accept_state(cm, wk)   # joint angles read from the frames: continued from this state on
            if energy:
                en[2][0], en[2][1] = en[0][1], en[0][2]
        for i in range(n):
            if not np.isfinite(y[i]):
                st[0], st[1] = t, h
                return NONFINITE, iout
        while iout < tout.shape[0] and tout[iout] <= t_new + tol_end:   # outputs at the step's end: its
            if energy and iout < ZO.shape[0]:
                ZO[iout, 0], ZO[iout, 1] = en[4][0], en[4][1]
            write_state(cm, wk, y, Y[iout], Y[iout - 1] if iout > 0 else Y[iout, :0])   # projected state,
            iout += 1                                                    # no dense output needed
            written += 1
        t = t_new
        h *= fac
        if s_ != OK:
            st[0], st[1] = t, h
            return s_, iout
        if (written >= chunk or stats[0] - steps0 >= 50 * chunk) and iout < tout.shape[0]:
            break   # back to Python now and then (progress, Ctrl-C), also between sparse outputs
    st[0], st[1] = t, h
    return OK, iout


@entry(_nrt=False)
def span(cm, wk, co, st, y, f, tout, Y, YJ, VD, LAM, rtol, atol, max_step, max_steps, stats, K, F, sc):
    """Short re-integration in one compiled call (Result.at): from the consistent state y at t0 over all
    of tout (tout[0] == t0 is written as is), then accelerations and multipliers at the outputs; returns
    (status, outputs written); st = [t0, (step)] as in `run`. Same stepping as `run`; no stiffness test,
    no return to Python. YJ (len(tout), len(y)): scratch for a tree's joint states (0 columns otherwise)."""
    n = y.shape[0]
    t0 = st[0]
    status = rhs(cm, wk, t0, y, f, bool(True))
    iout = 0
    if status != OK:
        return status, 0
    if abs(tout[0] - t0) <= 1e-14 * max(1.0, abs(t0)):
        write_state(cm, wk, y, Y[0], Y[0, :0])
        iout = 1
    st[1] = initial_step(cm, wk, t0, y, f, rtol, atol, max_step, sc[0], sc[1], sc[2], 7)
    while status == OK and iout < tout.shape[0]:
        status, iout = run(cm, wk, co, st, y, f, tout[-1], tout, iout, Y, rtol, atol, max_step, max_steps,
                           tout.shape[0], 1e-12, stats, K, F, sc, False, Y[:0], Y[:0, :2], stats[:1], False)
    if cm[31][5] == 1:   # the outputs' joint states, angles continued from the final state y (one step on)
        for i in range(n):
            sc[0, i] = y[i]
        joint_rows(cm, wk, Y[:iout], sc[:1], YJ[:iout])
    done = outputs_at(cm, wk, tout[:iout], Y[:iout], YJ[:iout], VD[:iout], LAM[:iout])
    if done < iout:
        return SINGULAR, done
    return status, iout


@entry(_nrt=False)
def from_checkpoint(cm, wk, co, t0, h, y0, f, tq, Y, VD, LAM, K, F, sc):
    """States, accelerations and multipliers at the times tq (inside [t0, t0 + h]) from the dense output
    of the step (t0, h) redone from its checkpoint y0: the run's own step, so the same solution; status."""
    nq = cm[31][0]
    n = y0.shape[0]
    ys, ynew, yo = sc[0], sc[1], sc[2]
    if rhs(cm, wk, t0, y0, f, bool(True)) != OK:
        return SINGULAR
    for i in range(n):
        K[0, i] = f[i]
    if not _stages(cm, wk, co, t0, h, y0, K, ys, ynew):
        return SINGULAR
    _dense_coeffs(cm, wk, co, t0, h, y0, ynew, K, ys, F)
    for k in range(tq.shape[0]):
        _dense(F, y0, t0, h, tq[k], yo)
        s_ = _project(cm, wk, tq[k], yo, 1e-12, bool(True))
        if s_ != OK:
            return s_
        write_state(cm, wk, yo, Y[k], Y[k, :0])
        ys_ = yo if cm[31][5] == 1 else Y[k, :nq]   # a tree's joint state from the dense output
        if accelerations(cm, wk, tq[k], Y[k, :nq], Y[k, nq:], ys_, VD[k], LAM[k], cm[31][5] == 1) != OK:
            return SINGULAR
    return OK
