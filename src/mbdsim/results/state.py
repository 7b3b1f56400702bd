"""The `state` handed to force/torque callables: Result measures at the current instant, one sample."""
from __future__ import annotations

import bisect

import numpy as np
from ..model.joint_kinds import is_angle
from ..system.frames import Frames, point_state


class State:
    """Measures of a single instant (t [s]); methods mirror Result but return one sample (no time axis).

    Light: the common measures of a body or marker without `frame=` / `relative_to=` (position [m],
    velocity [m/s], angular velocity [rad/s], all in ground axes; orientation, the body-to-ground
    rotation) are read straight from the instant's body frames; every other Result method works too, on a
    one-sample Result built on first use. `q`, `v`: the coordinates and velocity variables (1-D)."""

    def __init__(self, system, t, q, v, frames=None, maximal=None):
        """q, v: the coordinates and velocity variables, or None with `maximal() -> (q, v)` computing them
        on first use (from the compiled kernels' frames)."""
        self.t = float(t)
        self.system = system
        self._q, self._v, self._maximal = q, v, maximal
        # the single-instant Frames (nframes, ...) of (q, v) already computed (the compiled kernels'), or None
        self._fr = frames
        self._result = None

    @property
    def time(self) -> float:
        return self.t

    @property
    def q(self):
        """Coordinates (nq,) of this instant (positions [m], Euler parameters)."""
        if self._q is None:
            self._q, self._v = self._maximal()
        return self._q

    @property
    def v(self):
        """Velocity variables (nv,) of this instant ([m/s], body-axes angular velocities [rad/s])."""
        if self._v is None:
            self._q, self._v = self._maximal()
        return self._v

    @property
    def _res(self):
        """The one-sample Result of this instant (built on first use)."""
        if self._result is None:
            from .result import Result
            res = Result(self.system, np.array((self.t,)), self.q[None, :], self.v[None, :], None, None)
            fr = self._fr
            if fr is not None:   # the same arrays, with a sample axis
                res.inject_frames(Frames(fr.r[None], fr.A[None], fr.rd[None], fr.w[None]))
            self._result = res
        return self._result

    def _frames(self):
        fr = self._fr
        if fr is None:
            f = self._res.frames
            fr = self._fr = Frames(f.r[0], f.A[0], f.rd[0], f.w[0])
        return fr

    def position(self, target, frame=None):
        """Position [m] (3,) of a body's CM or a marker origin (Result.position at this instant)."""
        if frame is not None:
            return _one(self._res.position(target, frame))
        fid, s_B, _ = _where(self.system, target)
        fr = self._frames()
        return point_state(fr, fid, s_B, False)[0] if s_B is not None else fr.r[fid].copy()

    def velocity(self, target, frame=None, relative_to=None):
        """Velocity [m/s] (3,) of a body's CM or a marker origin (Result.velocity at this instant)."""
        if frame is not None or relative_to is not None:
            return _one(self._res.velocity(target, frame, relative_to))
        fid, s_B, _ = _where(self.system, target)
        fr = self._frames()
        return point_state(fr, fid, s_B, False)[1] if s_B is not None else fr.rd[fid].copy()

    def angular_velocity(self, target, frame=None, relative_to=None):
        """Angular velocity [rad/s] (3,) of the body of `target`, ground axes (Result.angular_velocity)."""
        if frame is not None or relative_to is not None:
            return _one(self._res.angular_velocity(target, frame, relative_to))
        return self._frames().w[_where(self.system, target)[0]].copy()

    def orientation(self, target):
        """Rotation matrix (3, 3) from the axes of `target` to ground (Result.orientation at this instant)."""
        fid, _, R_BM = _where(self.system, target)
        A = self._frames().A[fid]
        return A.dot(R_BM) if R_BM is not None else A.copy()

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
        if name.startswith("_"):
            raise AttributeError(name)
        from .result import Result
        attr = getattr(self._res, name)
        if not callable(attr):
            return attr
        if callable(getattr(Result, name, None)):
            # a Result method: its one-sample wrapper made once, as a method of the class (the callables of
            # loads call it at every evaluation of the step loop, each with a new State)
            def method(self, *args, _name=name, **kwargs):
                return _one(getattr(self._res, _name)(*args, **kwargs))
            method.__name__ = name
            method.__doc__ = getattr(Result, name).__doc__
            setattr(State, name, method)
            return getattr(self, name)
        return lambda *args, **kwargs: _one(attr(*args, **kwargs))


def _where(sys, target):
    """(frame index, s_B or None, R_BM or None) of a target (None: a body's CM and axes), cached on the
    System per target (a Body or Marker by identity, a name by value)."""
    cache = sys.run_state.setdefault("state_targets", {})
    key = target if isinstance(target, str) else id(target)
    hit = cache.get(key)
    if hit is None or hit[0] is not target and not isinstance(target, str):
        from ..model.body import Marker
        from ..system.measures import locate, resolve
        fid, s_B, R_BM = locate(sys, target)
        marker = isinstance(resolve(sys, target), Marker)
        hit = (target, (fid, np.array(s_B, dtype=float) if marker else None,
                        np.array(R_BM, dtype=float) if marker else None))
        cache[key] = hit
    return hit[1]


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
