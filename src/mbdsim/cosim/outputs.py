"""Expressions of the state evaluated by compiled code between steps: the model's outputs, FMU inputs.

The expressions are packed as the expression sensors are (system.exprloads_pack: one postfix program each,
inputs as constants whose places go into the Simulator's input slots) and evaluated together at a state
by the sensors' compiled evaluator `solvers.fastdop._sensor_g` (frames from the integrator's state, the
joint-coordinate tree's or the absolute coordinates), on the kernels' tuples with the sensor slots
replaced by these programs: one compiled call for all of them, no Python per expression.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..solvers import fastdop
from ..system import exprloads_pack
from ._fastcall import Bound


@dataclass
class _Signal:
    """What exprloads_pack.pack reads of a sensor: an expression `text` crossing 0, recorded only."""

    name: str
    text: str
    value: float = 0.0
    direction: int = 0
    action: str = "record"


class ExprPrograms:
    """Compiled expressions {name: text} of the model's state and inputs (load-expression language),
    evaluated at the integrator's state of `run` (a CompiledRun). Input places are appended to `slots`
    {input: [(array, index)]}; `stale` is set by the Simulator whenever the state or an input changes."""

    def __init__(self, sys, run, rep, slots, exprs: dict):
        self.names = list(exprs)
        self.index = {n: k for k, n in enumerate(self.names)}
        self.stale, self._values = True, np.zeros(len(self.names))
        self.yo = np.zeros(run.state_size)   # scratch of the evaluator (a normalised copy of the state)
        self.arrays = None                   # the kernels' tuples with these programs as the sensors'
        if not self.names:
            return
        cm = run.cm
        places = []
        ex, stack = exprloads_pack.pack(sys, [], int(cm.dims[5]), cm.tree, (rep.q, rep.v),
                                        [_Signal(n, t) for n, t in exprs.items()], places)
        for name, k in places:
            slots[name].append((ex[14], k))
        a, w = cm.arrays(), run.work.arrays()
        self._a = a.replace(43, ex)   # (Slots: the kernels' argument types stay those of the run's)
        self._w = w.replace(44, exprloads_pack.work(ex, stack))
        self.arrays = (self._a, self._w)
        self._eval = Bound(fastdop._sensor_g)

    @property
    def buffer(self) -> np.ndarray:
        """The array the values are evaluated into (in the order of `names`)."""
        return self._values

    def read(self, name: str) -> float:
        """The last evaluated value of expression `name` (ModelError for a name that is not one)."""
        k = self.index.get(name)
        if k is None:
            from ..errors import ModelError
            raise ModelError(f"output '{name}'", "name", f"the model has no output {name!r} (outputs: "
                             f"{', '.join(self.names) or 'none; declare them with Model.add_output'})")
        return float(self._values[k])

    def values(self, t: float, y) -> dict:
        """{name: value} at time t [s] and integrator state y."""
        self._update(t, y)
        return dict(zip(self.names, self._values.tolist()))

    def value(self, name: str, t: float, y) -> float:
        """The value of expression `name` at time t [s] and integrator state y."""
        if name not in self.names:
            from ..errors import ModelError
            raise ModelError(f"output '{name}'", "name", f"the model has no output {name!r} (outputs: "
                             f"{', '.join(self.names) or 'none; declare them with Model.add_output'})")
        self._update(t, y)
        return float(self._values[self.names.index(name)])

    def _update(self, t, y):
        if self.stale and self.names:
            self._eval(self._a, self._w, float(t), y, self.yo, self._values)
            self.stale = False
