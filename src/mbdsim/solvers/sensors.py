"""Sensors during a dynamic run (issue 11): switching functions for the EventTracker (mbdsim.solvers.events).

Each sensor contributes g = signal(t, state) - value.  The tracker cuts the step at a sign change,
located with brentq on the dense output to 1e-13 s; `fire` then records the event (a crossing in the
sensor's direction) and, for action "stop", asks the driver loop to end the run there.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class SensorEvent:
    """A sensor met: its name, time [s], the signal's value there and the action taken."""

    name: str
    time: float
    value: float
    action: str


class SensorItem:
    """Event-tracker item of one Sensor."""

    def __init__(self, sys, sensor):
        from ..results.state import State
        self.sys, self.sensor, self._State = sys, sensor, State
        self.last = None      # sign of g at the last accepted state

    def value(self, t, q, v) -> float:
        s = self.sensor
        return float(s.signal(float(t), self._State(self.sys, t, q, v))) - s.value

    def fire(self, t, g_before, g_after, events) -> bool:
        """Record a crossing at t (g_before: value before the event, g_after: the sign after);
        True when the run must stop."""
        s = self.sensor
        rising = g_after > g_before
        if s.direction and (s.direction > 0) != rising:
            return False
        events.append(SensorEvent(s.name, float(t), float(s.value), s.action))
        return s.action == "stop"


def sensor_items(sys):
    return [SensorItem(sys, s) for s in getattr(sys.model, "sensors", {}).values()]


def sensor_table(events):
    """Result.sensor_events as a list of SensorEvent, in time order."""
    return sorted(events, key=lambda e: e.time)


def _sign(x):
    return np.sign(x)
