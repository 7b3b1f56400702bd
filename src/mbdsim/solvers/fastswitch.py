"""Stick/slip events of joint friction in the compiled implicit steppers (issue 29): Radau IIA
(`fastradau.run`) and HHT-alpha (`fasthht.run`).

Both steppers keep, for each accepted step (t0, h) from y0, a cubic polynomial of the state
(`dense`: y0 + x (Q0 + x (Q1 + x Q2)), x = (t - t0) / h; Radau's collocation polynomial, HHT's Hermite
polynomial). The switching functions of the friction elements (`fastfriction.switching`, through
`fastdop._friction_g`: the coupled solve at the state, modes as decided in wk[50]) are evaluated at the
end of every accepted step; one that was positive at the last accepted step and is no longer is located
on that polynomial by the Illinois variant of regula falsi (to fastdop.SENSOR_XTOL, as DOP853's friction
and sensor events on its own dense output). The stepper then ends the step there and returns
fastdop.FRICTION_EVENT with the state at the event; the caller (`solvers.radau_run`, `solvers.friction_run`)
decides the modes (one decision for every stepper: `FrictionModes.decide`) and restarts the stepper at
the event. The model's sensors are watched the same way (`sensor_event`: DOP853's `sensor_crossings` and
`locate_sensors` on the implicit step's polynomial): a "stop" ends the step at its time (SENSOR_STOP), a
sensor whose value is not finite ends the run at the step's start (SENSOR_FAILED), and a zero of a
switching entry (the clearances of stops, the gaps of sphere/plane contacts: system.exprloads_pack, action
2) ends the step there (SWITCH_EVENT): the caller restarts the stepper at that state, as the reference
path cuts its steps at these events, so that no step integrates across the kink of the contact law.
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from .fastdop import FRICTION_EVENT, SENSOR_FAILED, SENSOR_STOP, SWITCH_EVENT, _friction_g
from .fastdopstep import _dense_cubic, _end_at, _sensor_g, _sensor_time, drop_after, locate_sensors, sensor_crossings


dense = _dense_cubic   # the step's polynomial (fastdopstep)


@kernel(_nrt=False)
def start(cm, wk, t, y, yo):
    """The switching values (wk[50][2]) and the sensors' values (wk[44][2]) at the stepper's (re)start
    (t [s], state y) as the last accepted ones; yo: scratch (n)."""
    if cm[48][0].shape[0]:
        _friction_g(cm, wk, t, y, yo, wk[50][2])
    if wk[44][2].shape[0]:
        _sensor_g(cm, wk, t, y, yo, wk[44][2])


@kernel(_nrt=False)
def sensor_event(cm, wk, Q, y0, t0, h, ynew, yd, yo):
    """After the accepted step (t0, h) from y0 to ynew (polynomial Q): the sensors' crossings since the last
    accepted step located on the polynomial and recorded (`fastdopstep.sensor_crossings`, `locate_sensors`:
    DOP853's sensor machinery on the implicit step's interpolant), and the first zero of a switching entry
    (stops, contacts). Returns (the time [s] of the first "stop" event, of the first switching zero; np.inf
    if none; (-np.inf, np.inf) when a sensor's value is not finite). yd, yo: scratch (n)."""
    crossed = sensor_crossings(cm, wk, t0 + h, ynew, yo, True)
    if crossed < 0:
        return -np.inf, np.inf
    return locate_sensors(cm, wk, Q, y0, t0, h, yd, yo, True, True)


@kernel(_nrt=False, inline="always")
def sensor_stop(cm, wk, Q, y, t0, h, t_ev, t_cut, tout, iout, proj_tol, st, stats, yo):
    """End the step (t0, h) from y at a sensor's time: a switching zero t_cut [s] (finite: the state there
    on the step's polynomial, projected exactly; SWITCH_EVENT, the caller restarts there), a "stop" t_ev
    (finite: the state there, projected; SENSOR_STOP), or a sensor whose value is not finite (t_ev = -inf:
    the run ends at the step's start t0, the outputs up to it kept; SENSOR_FAILED). (status, next iout)."""
    if t_ev == -np.inf:
        st[0], st[1] = t0, h
        return SENSOR_FAILED, drop_after(tout, iout, t0)
    if t_cut < np.inf:
        return _end_at(cm, wk, Q, y, t0, h, t_cut, tout, iout, proj_tol, st, stats, yo, bool(True), bool(True),
                       SWITCH_EVENT)
    return _end_at(cm, wk, Q, y, t0, h, t_ev, tout, iout, proj_tol, st, stats, yo, bool(True), bool(False),
                   SENSOR_STOP)


@kernel(_nrt=False)
def friction_event(cm, wk, Q, y0, t0, h, ynew, yd, yo):
    """After the accepted step (t0, h) from y0 to ynew (polynomial Q): the first time [s] at which a
    switching function that was positive at the last accepted step reaches zero, or np.inf when none did
    (the values at ynew then become the last accepted ones). yd, yo: scratch (n)."""
    fw = wk[50]
    gp, gn = fw[2], fw[16]
    if gp.shape[0] == 0:
        return np.inf
    _friction_g(cm, wk, t0 + h, ynew, yo, gn)
    t_ev = np.inf
    for e in range(gn.shape[0]):
        if gp[e] > 0.0 and not gn[e] > 0.0:
            te = _sensor_time(cm, wk, Q, y0, t0, h, e, yd, yo, fw[18], 1, True, True)
            t_ev = min(t_ev, te if te > t0 else t0 + h)
    if t_ev == np.inf:
        for e in range(gn.shape[0]):
            gp[e] = gn[e]
    return t_ev


@kernel(_nrt=False)
def stop_at(cm, wk, Q, y, t0, h, t_ev, tout, iout, proj_tol, st, stats, yo):
    """End the step (t0, h) from y at the event t_ev [s]: the outputs after it are dropped (the restart
    writes them again), y becomes the step's polynomial state at t_ev projected onto the constraints
    (positions and velocities), st[0] = t_ev; (FRICTION_EVENT or the projection's failure, next iout)."""
    return _end_at(cm, wk, Q, y, t0, h, t_ev, tout, iout, proj_tol, st, stats, yo, bool(True), bool(True),
                   FRICTION_EVENT)
