"""The pieces of the compiled DOP853 step (solvers.fastdop) that its step loop inlines: Hairer's starting
step, the projection after a step, the 12 stages and the 7th-order dense output of a step (scipy's tableau,
`_dop853_tableau`), and the watched signals located on a step's dense output: the model's expression
sensors (`_watch`) and the joint-friction switching functions (`_watch_friction`), both by the Illinois
variant of regula falsi on the dense output to SENSOR_XTOL (`_sensor_time`). The implicit steppers share
`_project` and `_friction_g` (solvers.fasthht, fastradau, fastswitch). Split from fastdop (issue 29: one
module a concern, none over ~500 lines); fastdop re-exports these names.
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from ._dop853_tableau import coefficients as _c   # scipy's tableau, without importing scipy.integrate

from ..system.exprloads_kernel import sensor_values
from ..system.kernels import frames_into
from . import fastenergy, fastfriction, fasttree
from .fastdyn import OK, _constraints, _to6, accelerations, normalize_into, project, rhs, tree_project

N_STAGES = _c.N_STAGES
SENSOR_XTOL = 1e-13    # [s]: sensor times are located on the dense output to this


@kernel(_nrt=False)
def _rms(x, scale):
    s = 0.0
    for i in range(x.shape[0]):
        s += (x[i] / scale[i]) ** 2
    return np.sqrt(s / x.shape[0])


@kernel(_nrt=False, inline="always")
def initial_step(cm, wk, t0, y0, f0, rtol, atol, max_step, work, scale, y1, order=7):
    """Hairer's starting step (as scipy's select_initial_step) for an error estimator of `order` (DOP853: 7,
    Radau IIA: 3); work, scale, y1: scratch vectors of the state's size."""
    n = y0.shape[0]
    for i in range(n):
        scale[i] = atol + abs(y0[i]) * rtol
    d0, d1 = _rms(y0, scale), _rms(f0, scale)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, max_step)
    for i in range(n):
        y1[i] = y0[i] + h0 * f0[i]
    if rhs(cm, wk, t0 + h0, y1, work, bool(True)) != OK:
        return h0
    for i in range(n):
        work[i] = work[i] - f0[i]
    d2 = _rms(work, scale) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / (order + 1.0))
    return min(100.0 * h0, h1, max_step)


@kernel(_nrt=False, inline="always")
def _project(cm, wk, t, y, tol, exact_factor=True):
    """`fastdyn.project` of the state y = [q, v], or on the joint-coordinate tree the projection onto its
    coordinate constraints (solvers.treecoord; nothing to do without them); status."""
    if cm[31][5] == 1:
        return tree_project(cm, wk, t, y, tol)[0]
    nq = cm[31][0]
    return project(cm, wk, t, y[:nq], y[nq:], tol, exact_factor)


@kernel(_nrt=False)
def _dense(F, y_old, t_old, h, t, out):
    x = (t - t_old) / h
    for i in range(out.shape[0]):
        out[i] = 0.0
    nF = F.shape[0]
    for a in range(nF):
        f = F[nF - 1 - a]
        for i in range(out.shape[0]):
            out[i] += f[i]
            out[i] *= x if a % 2 == 0 else (1.0 - x)
    for i in range(out.shape[0]):
        out[i] += y_old[i]


@kernel(_nrt=False, inline="always")
def _sensor_g(cm, wk, t, y, yo, g):
    """Each expression sensor's signal minus its threshold at the integrator's state y at t [s] into g
    (frames computed here from y: the tree's forward kinematics, or the absolute coordinates with the
    Euler parameters normalised in the copy yo)."""
    r, A, rd, w = wk[0], wk[1], wk[2], wk[3]
    for i in range(y.shape[0]):
        yo[i] = y[i]
    if cm[31][5] == 1:
        tw = wk[43]
        fasttree.kinematics(cm[42], yo, yo.shape[0] // 2, r, A, rd, w, tw[10], tw[11])
    else:
        nq = cm[31][0]
        normalize_into(cm, yo[:nq])
        frames_into(yo[:nq], yo[nq:], cm[0], cm[1], cm[2], cm[3], cm[4], r, A, rd, w)
    sensor_values(cm[43], wk[44], t, yo, r, A, rd, w, g)


@kernel(_nrt=False)
def _friction_g(cm, wk, t, y, yo, g):
    """Each joint-friction element's switching function (solvers.fastfriction.switching) at the
    integrator's state y at t [s] into g (Euler parameters normalised in the copy yo), from the coupled
    solve there; status of that solve. Where no element sticks or is held (slip or none only) the values
    are joint rates: the rows at y suffice, and no solve is made."""
    fw = wk[50]
    nq = cm[31][0]
    for i in range(y.shape[0]):
        yo[i] = y[i]
    normalize_into(cm, yo[:nq])
    rates = True
    for e in range(fw[0].shape[0]):
        if fw[0][e] == 2 or fw[20][e] >= 0:
            rates = False
    if rates:
        _constraints(cm, wk, t, yo[:nq], yo[nq:])
        s_ = OK
    else:
        s_ = accelerations(cm, wk, t, yo[:nq], yo[nq:], yo[:nq], fw[12], fw[13], bool(True))
    _to6(cm, yo[nq:], fw[14])
    fastfriction.switching(cm[48], fw, wk[5], cm[12], cm[13], wk[1], fw[13], fw[14], g)
    return s_


@kernel(_nrt=False)
def _dense_cubic(Q, y0, t0, h, t, out):
    """An implicit step's polynomial (t0, h) from y0 (coefficients Q, 3 x n: Radau's collocation
    polynomial, HHT's Hermite cubic; solvers.fastswitch) at t [s] into out."""
    x = (t - t0) / h
    for i in range(out.shape[0]):
        out[i] = y0[i] + x * (Q[0, i] + x * (Q[1, i] + x * Q[2, i]))


@kernel(_nrt=False)
def _at(F, y0, t0, h, t, out, cubic):
    """A step's interpolant at t [s] into out: DOP853's dense output (F, 7 x n), or with `cubic` an implicit
    step's polynomial (3 x n)."""
    if cubic:
        _dense_cubic(F, y0, t0, h, t, out)
    else:
        _dense(F, y0, t0, h, t, out)


@kernel(_nrt=False, inline="always")
def _end_at(cm, wk, F, y, t0, h, t_ev, tout, iout, proj_tol, st, stats, yo, cubic, exact, status):
    """End the step (t0, h) from y at an event t_ev [s]: the outputs after it are dropped (a restart writes
    them again), y becomes the step's interpolant (`_at`: DOP853's dense output, or with `cubic` an implicit
    step's polynomial) at t_ev projected onto the constraints (`_project` with `exact`), st = (t_ev, h);
    (`status`, or the projection's failure, and the next iout). Shared by DOP853's friction events and
    stop sensors (solvers.fastdop) and the implicit steppers' friction events (solvers.fastswitch)."""
    iout = drop_after(tout, iout, t_ev)
    _at(F, y, t0, h, t_ev, yo, cubic)
    s_ = _project(cm, wk, t_ev, yo, proj_tol, exact)
    stats[3] += 1
    for i in range(y.shape[0]):
        y[i] = yo[i]
    st[0], st[1] = t_ev, h
    return (status if s_ == OK else s_), iout


@kernel(_nrt=False)
def _signal(cm, wk, t, y, yo, g, which):
    """The watched signals at state y and t [s] into g: the sensors (which = 0, `_sensor_g`) or the
    joint-friction switching functions (1, `_friction_g`)."""
    if which == 0:
        _sensor_g(cm, wk, t, y, yo, g)
    else:
        _friction_g(cm, wk, t, y, yo, g)


@kernel(_nrt=False, inline="always")
def _sensor_time(cm, wk, F, y0, t0, h, k, yd, yo, g, which, cubic, right):
    """The time [s] in (t0, t0 + h] at which signal k (`_signal` `which`: a sensor's value, a friction
    element's switching function) changes sign on the interpolant (F, y0) of the step from t0 (`_at`:
    DOP853's dense output, or with `cubic` an implicit step's polynomial), by the Illinois variant of
    regula falsi to SENSOR_XTOL; -inf when its values at the step's ends do not bracket a sign change (the
    crossing is then not an event, as a failed bracket of the reference path's brentq). The located time
    is the bracket's midpoint, or with `right` its end on the crossed side (where the decision that follows
    sees the new sign)."""
    a, b = t0, t0 + h
    _at(F, y0, t0, h, a, yd, cubic)
    _signal(cm, wk, a, yd, yo, g, which)
    fa = g[k]
    _at(F, y0, t0, h, b, yd, cubic)
    _signal(cm, wk, b, yd, yo, g, which)
    fb = g[k]
    if fb == 0.0:
        return b
    if fa == 0.0 or (fa > 0.0) == (fb > 0.0):
        return -np.inf
    side = 0
    for _ in range(200):
        if b - a <= SENSOR_XTOL + 4e-16 * abs(b):
            break
        c = b - fb * (b - a) / (fb - fa)
        if not a < c < b:
            c = 0.5 * (a + b)
        _at(F, y0, t0, h, c, yd, cubic)
        _signal(cm, wk, c, yd, yo, g, which)
        fc = g[k]
        if fc == 0.0:
            return c
        if (fc > 0.0) == (fb > 0.0):   # c replaces b; a is kept (its value halved when kept twice)
            b, fb = c, fc
            if side == -1:
                fa *= 0.5
            side = -1
        else:                          # c replaces a
            a, fa = c, fc
            if side == 1:
                fb *= 0.5
            side = 1
    return b if right else 0.5 * (a + b)


@kernel(_nrt=False, inline="always")
def _watch(cm, wk, co, t, h, y, ynew, K, F, have_F, ys, scale):
    """Sensors after the accepted step (t, h) from y to ynew (DOP853): `sensor_crossings`, located on the
    step's dense output (F, computed here unless have_F, only when a value changed sign) by
    `locate_sensors`. Returns (the time [s] of the first "stop" event, np.inf if none, -np.inf when a
    sensor's value is not finite; whether F holds the step's dense output)."""
    crossed = sensor_crossings(cm, wk, t + h, ynew, scale, False)
    if crossed < 0:
        return -np.inf, have_F
    if crossed > 0 and not have_F:
        _dense_coeffs(cm, wk, co, t, h, y, ynew, K, ys, F)
        have_F = True
    return locate_sensors(cm, wk, F, y, t, h, ys, scale, False, False)[0], have_F


@kernel(_nrt=False)
def sensor_crossings(cm, wk, t_new, ynew, yo, cut):
    """The sensors' values at the end t_new [s] of an accepted step (state ynew; yo: scratch) into wk[44][3];
    the number of them whose sign differs from the last accepted values wk[44][2] (the switching entries,
    action 2, only with `cut`), or -1 when a value there or here is not finite (a Python-callable sensor
    that failed, a signal that is not a number)."""
    ew = wk[44]
    g_prev, g_new, action = ew[2], ew[3], cm[43][20]
    _sensor_g(cm, wk, t_new, ynew, yo, g_new)
    n = 0
    for k in range(g_new.shape[0]):
        gp, gn = g_prev[k], g_new[k]
        if not (np.isfinite(gp) and np.isfinite(gn)):
            return -1
        if gp != 0.0 and (gn == 0.0 or (gn > 0.0) != (gp > 0.0)) and (cut or action[k] != 2):
            n += 1
    return n


@kernel(_nrt=False, inline="always")
def locate_sensors(cm, wk, F, y, t, h, ys, scale, cubic, cut):
    """After `sensor_crossings` of the accepted step (t, h) from y: each sign change is located on the step's
    interpolant (F, y: DOP853's dense output, or with `cubic` an implicit step's polynomial; `_sensor_time`);
    a crossing in the sensor's direction is an event, appended (time [s], sensor) to the event buffer unless
    it comes after the step's first "stop" event or, with `cut`, after its first zero of a switching entry
    (action 2: stops' clearances and contact gaps, located on the crossed side). The values at the step's
    end become the last accepted ones (the sign after the event where a value is exactly zero). Returns
    (the time [s] of the first "stop" event, of the first switching zero; np.inf if none: a "stop" after
    the switching zero is dropped too, the restart there finds it again). ys, scale: scratch (n)."""
    ex, ew = cm[43], wk[44]
    g_prev, g_new, EVT, nev, g_tmp = ew[2], ew[3], ew[4], ew[5], ew[6]
    n_s = g_new.shape[0]
    t_stop, t_cut = np.inf, np.inf
    n0 = nev[0]
    for k in range(n_s):
        gp, gn = g_prev[k], g_new[k]
        if gp == 0.0 or (gn != 0.0 and (gn > 0.0) == (gp > 0.0)):
            continue
        if ex[20][k] == 2:   # a switching entry: the step is cut at its zero (implicit steppers only)
            if cut:
                tk = _sensor_time(cm, wk, F, y, t, h, k, ys, scale, g_tmp, 0, cubic, True)
                if tk > t:
                    t_cut = min(t_cut, tk)
            continue
        tk = _sensor_time(cm, wk, F, y, t, h, k, ys, scale, g_tmp, 0, cubic, False)
        rising = gn > gp
        if tk <= t or (ex[19][k] != 0 and (ex[19][k] > 0) != rising):
            continue
        EVT[nev[0], 0] = tk
        EVT[nev[0], 1] = k
        nev[0] += 1
        if ex[20][k] == 1:
            t_stop = min(t_stop, tk)
    if t_cut <= t_stop:
        t_stop = np.inf
    t_end = min(t_stop, t_cut)
    if t_end < np.inf:   # events after the stop or the cut did not happen (yet)
        m = n0
        for e in range(n0, nev[0]):
            if EVT[e, 0] <= t_end + 1e-12 * max(1.0, abs(t_end)):
                EVT[m, 0], EVT[m, 1] = EVT[e, 0], EVT[e, 1]
                m += 1
        nev[0] = m
    for k in range(n_s):
        if g_new[k] != 0.0:
            g_prev[k] = g_new[k]
        elif g_prev[k] != 0.0:   # exactly at the threshold: the sign after the crossing
            g_prev[k] = -g_prev[k]
    return t_stop, t_cut


@kernel(_nrt=False)
def drop_after(tout, iout, t):
    """The next output index once the outputs after t [s] are dropped (a run that ends at t)."""
    while iout > 0 and tout[iout - 1] > t + 1e-14 * max(1.0, abs(t)):
        iout -= 1
    return iout


@kernel(_nrt=False)
def _watch_friction(cm, wk, co, t, h, y, ynew, K, F, have_F, ys, scale):
    """Joint friction after the accepted step (t, h) from y to ynew: the first time a switching function
    that was positive at the last accepted step reaches zero, located on the step's dense output (F,
    computed here unless have_F), or np.inf when none did (the values at ynew then become the last
    accepted ones); and whether F holds the step's dense output."""
    fw = wk[50]
    gp, gn = fw[2], fw[16]
    _friction_g(cm, wk, t + h, ynew, scale, gn)
    t_ev = np.inf
    for e in range(gn.shape[0]):
        if gp[e] > 0.0 and not gn[e] > 0.0:
            if not have_F:
                _dense_coeffs(cm, wk, co, t, h, y, ynew, K, ys, F)
                have_F = True
            te = _sensor_time(cm, wk, F, y, t, h, e, ys, scale, fw[18], 1, False, False)
            t_ev = min(t_ev, te if te > t else t + h)
    if t_ev == np.inf:
        for e in range(gn.shape[0]):
            gp[e] = gn[e]
    return t_ev, have_F


@kernel(_nrt=False, inline="always")
def _stages(cm, wk, co, t, h, y, K, ys, ynew):
    """The 12 stages of a DOP853 step from y (K[0] = f(t, y) given), ynew and K[12] = f(t + h, ynew);
    False when an evaluation failed."""
    A, B, C = co[0], co[1], co[2]
    n = y.shape[0]
    for s in range(1, N_STAGES):
        for i in range(n):
            acc = 0.0
            for j in range(s):
                acc += A[s, j] * K[j, i]
            ys[i] = y[i] + h * acc
        if rhs(cm, wk, t + C[s] * h, ys, K[s], bool(True)) != OK:
            return False
        fastenergy.stage_power(wk, s)
    for i in range(n):
        acc = 0.0
        for j in range(N_STAGES):
            acc += B[j] * K[j, i]
        ynew[i] = y[i] + h * acc
    ok = rhs(cm, wk, t + h, ynew, K[N_STAGES], bool(True)) == OK
    fastenergy.stage_power(wk, N_STAGES)
    return ok


@kernel(_nrt=False, inline="always")
def _dense_coeffs(cm, wk, co, t, h, y, ynew, K, ys, F):
    """The 7th-order dense output coefficients F (7, n) of an accepted step (3 more evaluations)."""
    A, C, D = co[0], co[2], co[5]
    n = y.shape[0]
    for s in range(N_STAGES + 1, 16):
        for i in range(n):
            acc = 0.0
            for j in range(s):
                acc += A[s, j] * K[j, i]
            ys[i] = y[i] + h * acc
        rhs(cm, wk, t + C[s] * h, ys, K[s], bool(True))
        fastenergy.stage_power(wk, s)
    _dense_rows(D, h, y, ynew, K, F)


@kernel(_nrt=False)
def _dense_rows(D, h, y, ynew, K, F):
    """The dense output coefficients F (7, n) of a step of size h from y to ynew with the 16 stage
    derivatives K (16, n): the state's, and the energy bookkeeping's quadrature state (`energy_dense`)."""
    for i in range(y.shape[0]):
        dy = ynew[i] - y[i]
        F[0, i] = dy
        F[1, i] = h * K[0, i] - dy
        F[2, i] = 2.0 * dy - h * (K[N_STAGES, i] + K[0, i])
        for r in range(4):
            acc = 0.0
            for j in range(16):
                acc += D[r, j] * K[j, i]
            F[3 + r, i] = h * acc
