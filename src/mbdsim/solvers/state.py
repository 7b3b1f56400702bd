"""The `state` handed to force/torque callables: Result measures at the current instant, one sample."""
from __future__ import annotations

import numpy as np


class State:
    """Measures of a single instant (t [s]); methods mirror Result but return one sample (no time axis)."""

    def __init__(self, system, t, q, v):
        from ..results.result import Result
        self.t = float(t)
        self._res = Result(system, [t], q[None, :], v[None, :], None, None)

    @property
    def time(self) -> float:
        return self.t

    def __getattr__(self, name):
        attr = getattr(self._res, name)
        if not callable(attr):
            return attr

        def one(*args, **kwargs):
            out = attr(*args, **kwargs)
            return out[0] if isinstance(out, np.ndarray) and out.ndim >= 1 and len(out) == 1 else out
        return one


def state_factory(sys):
    """Callable (t, q, v) -> State, or None when no load is a callable (saves the work)."""
    needs = any(callable(getattr(e, "force", None)) or callable(getattr(e, "torque", None))
                or getattr(e, "needs_state", False) for e in sys.model.forces.values())
    return (lambda t, q, v: State(sys, t, q, v)) if needs else None
