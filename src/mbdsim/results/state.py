"""The `state` handed to force/torque callables: Result measures at the current instant, one sample."""
from __future__ import annotations

import bisect

import numpy as np
from ..model.joint_kinds import is_angle


class State:
    """Measures of a single instant (t [s]); methods mirror Result but return one sample (no time axis)."""

    def __init__(self, system, t, q, v, frames=None):
        from .result import Result
        self.t = float(t)
        self._res = Result(system, np.array((self.t,)), q[None, :], v[None, :], None, None)
        if frames is not None:   # the frames of (q, v) already computed (the compiled kernels' own)
            self._res.inject_frames(frames)

    @property
    def time(self) -> float:
        return self.t

    def joint_coordinate(self, joint):
        """Joint coordinate at this instant; an angle continues beyond +-pi along the analysis, as in a Result."""
        res = self._res
        x = np.array(res.joint_coordinate(joint)[0], dtype=float)
        jt = res._joint(joint)
        if is_angle(jt.kind) and not jt.body_j.is_particle:
            ang = x.reshape(-1)
            ang[0] = _continued(res.system, jt.name, self.t, float(ang[0]))
        return x[()] if x.ndim == 0 else x

    def __getattr__(self, name):
        from .result import Result
        attr = getattr(self._res, name)
        if not callable(attr):
            return attr
        if callable(getattr(Result, name, None)) and not name.startswith("__"):
            # a Result method: its one-sample wrapper made once, as a method of the class (the callables of
            # loads call it at every evaluation of the step loop, each with a new State)
            def method(self, *args, _name=name, **kwargs):
                return _one(getattr(self._res, _name)(*args, **kwargs))
            method.__name__ = name
            method.__doc__ = getattr(Result, name).__doc__
            setattr(State, name, method)
            return getattr(self, name)
        return lambda *args, **kwargs: _one(attr(*args, **kwargs))


def _one(out):
    """A Result measure's value at its one sample (the time axis dropped)."""
    return out[0] if isinstance(out, np.ndarray) and out.ndim >= 1 and len(out) == 1 else out


def _continued(sys, name, t, raw):
    """Angle [rad] closest to the reference in force at time t (the last anchor at or before t, 0 before
    any); an anchor (t, angle) is recorded on the System whenever the angle moves pi/4 from it, so the
    angle of a joint read by a load callable is continuous over the analysis (the System is per analysis)."""
    hist = sys.run_state.setdefault("angles", {}).setdefault(name, [])
    k = bisect.bisect_right(hist, (t, np.inf)) - 1
    ref = hist[k][1] if k >= 0 else 0.0
    x = ref + (raw - ref + np.pi) % (2 * np.pi) - np.pi
    if abs(x - ref) > 0.25 * np.pi:
        bisect.insort(hist, (t, x))
    return x


def state_factory(sys):
    """Callable (t, q, v) -> State, or None when no load is a callable (saves the work); also kept in
    sys.run_state['state_factory'] for the system layer."""
    needs = any(callable(getattr(e, "force", None)) or callable(getattr(e, "torque", None))
                or getattr(e, "needs_state", False) for e in sys.model.forces.values())
    factory = (lambda t, q, v: State(sys, t, q, v)) if needs else None
    # the system layer (joint friction's mode decisions) evaluates loads too: it finds the factory here
    sys.run_state["state_factory"] = factory
    return factory
