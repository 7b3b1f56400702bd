"""Event location on dense output: force elements with switching functions (contact onset, stick/slip).

A force-element evaluator may define `switch(sys, fr, elem, t) -> array` (the signed switching
functions) and `on_event(sys, elem, t, q, v)` (called after the state at the event is accepted).
Optional: `on_start(sys, elem, t, q, v)` (called once before the first step: initial modes),
`needs_lambda = True` (the frames handed to `switch` then carry `q`, `v` and the multipliers
`lambda_` (nc,) at that state: stick/slip friction) and `restart_positive = True` (a switching
function that is zero right after an event is taken as positive, i.e. its new mode persists,
instead of the default 'opposite sign of before').
A step whose end changes the sign of a switching function is cut at the root, located with brentq
on the dense output to 1e-13 s, and the integrator restarts there, so no discontinuity is stepped over.
"""
from __future__ import annotations

import numpy as np

from ..system.force_elements import evaluator
from ..system.frames import body_frames
from .common import accelerations, normalize


class EventTracker:
    """Watches the switching functions of the model's force elements between accepted steps."""

    def __init__(self, sys, rows, sf):
        self.sys = sys
        self.items = [(e, evaluator(e)) for e in sys.model.forces.values()
                      if hasattr(evaluator(e), "switch")]
        self.prev = None
        self.rows, self.sf = rows, sf
        self.need_lam = any(getattr(ev, "needs_lambda", False) for _, ev in self.items)
        self.positive = np.zeros(0, dtype=bool)
        from .sensors import sensor_items   # sensors (issue 11): switching functions after the elements'
        self.sensors = sensor_items(sys)
        self.sensor_events, self.stop, self.fired, self.nforce = [], False, [], 0

    def values(self, t, y):
        if not self.items and not self.sensors:
            return np.zeros(0)
        q, v = normalize(self.sys, y[:self.sys.nq]), y[self.sys.nq:]
        if not self.items:
            return self._with_sensors(np.zeros(0), t, q, v)
        fr = body_frames(self.sys, q, v)
        if self.need_lam:
            fr.q, fr.v = q, v
            fr.lambda_ = accelerations(self.sys, q, v, t, self.rows, self.sf)[1]
        gs = [np.atleast_1d(ev.switch(self.sys, fr, e, t)) for e, ev in self.items]
        self.positive = np.concatenate([np.full(len(g), bool(getattr(ev, "restart_positive", False)))
                                        for g, (_, ev) in zip(gs, self.items)])
        return self._with_sensors(np.concatenate(gs), t, q, v)

    def _with_sensors(self, g, t, q, v):
        self.nforce = len(g)
        if not self.sensors:
            return g
        self.positive = np.concatenate([self.positive[:len(g)], np.zeros(len(self.sensors), dtype=bool)])
        return np.concatenate([g, [s.value(t, q, v) for s in self.sensors]])

    def start(self, t, y):
        q, v = normalize(self.sys, y[:self.sys.nq]), y[self.sys.nq:]
        for e, ev in self.items:
            if hasattr(ev, "on_start"):
                ev.on_start(self.sys, e, t, q, v)
        self.prev = self.values(t, y)

    def check(self, t_old, t_new, dense):
        """Earliest event time in (t_old, t_new], or None."""
        best, fired, g1 = self.locate(t_old, t_new, dense)
        if g1 is not None and not fired:
            self.prev = g1
        self.fired = fired
        return best

    def locate(self, t_old, t_new, dense):
        """(earliest root in (t_old, t_new] of a switching function that changed sign since the last
        accepted event state, or None; the indices crossing there; the values at t_new, or None when
        there is nothing to watch), without changing the tracker."""
        if not self.items and not self.sensors:
            return None, [], None
        g1 = self.values(t_new, dense(t_new))
        cross = np.where((np.sign(g1) != np.sign(self.prev)) & (self.prev != 0))[0]
        if len(cross) == 0:
            return None, [], g1
        best, roots = t_new, {}
        for k in cross:
            f = lambda t: self.values(t, dense(t))[k]  # noqa: E731
            try:
                from scipy.optimize import brentq
                tk = brentq(f, t_old, t_new, xtol=1e-13, rtol=1e-15)
            except ValueError:
                continue
            best = min(best, tk)
            roots[k] = tk
        fired = [k for k, tk in roots.items() if tk <= best + 1e-12 * max(1.0, abs(best))]
        return (best if best > t_old else None), fired, g1

    def after(self, t, y):
        q, v = y[:self.sys.nq], y[self.sys.nq:]
        for e, ev in self.items:
            if hasattr(ev, "on_event"):
                ev.on_event(self.sys, e, t, q, v)
        for k in self.fired:   # sensors met at this event: record, maybe stop
            if k >= self.nforce and self.prev is not None and self.prev[k] != 0:
                item = self.sensors[k - self.nforce]
                self.stop |= item.fire(t, self.prev[k], -self.prev[k], self.sensor_events)
        self.fired = []
        g = self.values(t, y)
        # values exactly at the root: take the sign just after the event
        flip = np.where(self.positive, 1.0, -self.prev if self.prev is not None else g)
        self.prev = np.where(np.abs(g) < 1e-12, flip, g)
