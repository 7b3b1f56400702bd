"""Model method for sensors (Adams SENSOR, issue 11): a condition on a signal that stops a run or records
the time it is met, located on the integrator's dense output to solver precision (1e-13 s).

The signal is an expression string in t [s], the coordinates of one-coordinate joints by name
(revolute/screw angle [rad], continuous; translational slide [m]) and their rates `<joint>_dot`
[rad/s, m/s], and the measures of load expressions (DX ... AZ, TIME; mbdsim.model.loadexpr); or a callable signal(t, state) -> float receiving the same `state` as load callables
(Result measures at one instant: state.position("ball")[2], state.joint_coordinate("pin"), ...).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ..errors import ModelError
from ._check import scalar
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .._types import Signal

ACTIONS = ("stop", "record")


@dataclass(eq=False)
class Sensor:
    """signal(t, state) - value changing sign in `direction` (+1 rising, -1 falling, 0 both) triggers
    `action` ("stop": end the run there; "record": note the time and go on).  `text`: the expression
    given, if any."""

    name: str
    signal: Any
    value: float
    direction: int
    action: str
    text: str | None = None

    def __repr__(self) -> str:
        return f"Sensor({self.name!r}: {self.text or 'callable'} crossing {self.value:g}, {self.action})"


class SensorsMixin:
    """add_sensor."""

    def add_sensor(self, name: str, signal: Signal, value: float = 0.0, direction: int = 0, action: str = "stop",
                   threshold: float | None = None) -> Sensor:
        """Sensor on `signal` reaching `value` (alias `threshold`) in `direction` (+1 rising, -1 falling,
        0 either); action "stop" ends the simulation at that instant (the Result's last sample), "record"
        notes it.  The times are in `Result.sensor_events`.  The signal is watched inside the compiled
        DOP853's step loop (method "auto" or "dop853"): an expression as a compiled program, a callable
        through a callback from that loop (solvers.pyloads; its crossing located on the dense output the
        same way); the compiled Radau IIA and HHT watch them on their steps' polynomials (method "radau",
        "hht", and the automatic method's stiff continuation); a named scipy method runs the reference path.
        A callable that raises ends the run at once (success False, the error naming the sensor and the
        time, the outputs before it kept)."""
        entity = f"sensor '{name}'"
        self._claim(name, "sensor")
        try:
            if threshold is not None:
                if value != 0.0:
                    raise ModelError(entity, "threshold", "give value or threshold, not both")
                value = threshold
            v = scalar(entity, "value", value)
            if direction not in (-1, 0, 1) or isinstance(direction, bool):
                raise ModelError(entity, "direction", f"expected +1 (rising), -1 (falling) or 0, got {direction!r}")
            if action not in ACTIONS:
                raise ModelError(entity, "action", f"expected one of {ACTIONS}, got {action!r}")
            text = None
            if isinstance(signal, str):
                text, signal = signal, self._sensor_expression(entity, signal)
            elif not callable(signal):
                raise ModelError(entity, "signal", f"expected an expression string or a callable "
                                 f"signal(t, state), got {signal!r}")
        except ModelError:
            self._names.discard(name)
            raise
        s = Sensor(name, signal, v, int(direction), action, text)
        self.__dict__.setdefault("sensors", {})[name] = s
        return s

    def _sensor_expression(self, entity, text):
        """signal(t, state) of an expression in the language of load expressions (mbdsim.model.loadexpr:
        t, TIME, joint coordinates by name and <joint>_dot, measures DX ... AZ of bodies and markers)."""
        import numpy as np

        from .loadexpr import parse_load
        le = parse_load(self, text, entity, "signal")

        def signal(t, state):
            from ..system.exprmeasures import evaluate
            res = state._res

            def joint_value(joint, dof, rate):
                return np.atleast_1d(state.joint_velocity(joint) if rate else state.joint_coordinate(joint))
            return float(evaluate(res.system, res.frames, le, t, joint_value)[0])
        return signal
