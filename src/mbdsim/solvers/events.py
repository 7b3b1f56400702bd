"""Event location on dense output: force elements with switching functions (contact onset, stick/slip).

A force-element evaluator may define `switch(sys, fr, elem, t) -> array` (the signed switching
functions) and `on_event(sys, elem, t, q, v)` (called after the state at the event is accepted).
A step whose end changes the sign of a switching function is cut at the root, located with brentq
on the dense output to 1e-13 s, and the integrator restarts there, so no discontinuity is stepped over.
"""
from __future__ import annotations

import numpy as np
import scipy.optimize as so

from ..system.force_elements import evaluator
from ..system.frames import body_frames
from .common import normalize


class EventTracker:
    """Watches the switching functions of the model's force elements between accepted steps."""

    def __init__(self, sys, rows, sf):
        self.sys = sys
        self.items = [(e, evaluator(e)) for e in sys.model.forces.values()
                      if hasattr(evaluator(e), "switch")]
        self.prev = None

    def values(self, t, y):
        if not self.items:
            return np.zeros(0)
        q, v = normalize(self.sys, y[:self.sys.nq]), y[self.sys.nq:]
        fr = body_frames(self.sys, q, v)
        return np.concatenate([np.atleast_1d(ev.switch(self.sys, fr, e, t)) for e, ev in self.items])

    def start(self, t, y):
        self.prev = self.values(t, y)

    def check(self, t_old, t_new, dense):
        """Earliest event time in (t_old, t_new], or None."""
        if not self.items:
            return None
        g1 = self.values(t_new, dense(t_new))
        cross = np.where((np.sign(g1) != np.sign(self.prev)) & (self.prev != 0))[0]
        if len(cross) == 0:
            self.prev = g1
            return None
        best = t_new
        for k in cross:
            f = lambda t: self.values(t, dense(t))[k]  # noqa: E731
            try:
                tk = so.brentq(f, t_old, t_new, xtol=1e-13, rtol=1e-15)
            except ValueError:
                continue
            best = min(best, tk)
        return best if best > t_old else None

    def after(self, t, y):
        q, v = y[:self.sys.nq], y[self.sys.nq:]
        for e, ev in self.items:
            if hasattr(ev, "on_event"):
                ev.on_event(self.sys, e, t, q, v)
        g = self.values(t, y)
        # values exactly at the root: take the sign just after the event
        self.prev = np.where(np.abs(g) < 1e-12, -self.prev if self.prev is not None else g, g)
