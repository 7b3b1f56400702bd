"""Result: one row per output time, with measures computed from (system, coordinates).

Vectors are (N, 3) in ground axes unless `frame=` names a Body or Marker (then expressed in its axes;
positions then measured from its origin).  SI units: m, m/s, m/s^2, rad, rad/s, rad/s^2, N, N m, J.
"""
from __future__ import annotations

from typing import Callable

import numpy as np
import scipy.optimize as so

from ..errors import ModelError
from ..model.joints import Joint
from ..system import measures as ms
from ..system.force_elements import evaluator
from ..system.frames import body_frames


class Result:
    """Time history of an analysis; a failed run keeps every step computed before the failure."""

    def __init__(self, system, time, q, v, vd, lambda_, evaluate: Callable | None = None,
                 success=True, status=0, message="ok", stats=None):
        self.system = system
        self.time = np.atleast_1d(np.asarray(time, dtype=float))   # [s]
        self.q, self.v = np.atleast_2d(q), np.atleast_2d(v)         # coordinates, velocity variables
        self.vd = None if vd is None else np.atleast_2d(vd)          # accelerations of v
        self.lambda_ = None if lambda_ is None else np.atleast_2d(lambda_)  # multipliers (N, nc)
        self._evaluate = evaluate
        self.success, self.status, self.message = success, status, message
        self.stats = stats or {}
        self._fr = None
        self._parent = None
        self.error = None   # the MbdsimError that stopped a failed run (time, joints, last good state)

    # ------------------------------------------------------------ basics
    def __len__(self):
        return len(self.time)

    def __repr__(self):
        return f"Result({len(self)} samples, t=[{self.time[0]:.6g}, {self.time[-1]:.6g}] s, success={self.success})"

    def _repr_html_(self):  # Jupyter summary
        from ..viewer.notebook import result_html; return result_html(self)  # noqa: E702

    @property
    def frames(self):
        if self._fr is None:
            self._fr = body_frames(self.system, self.q, self.v, self.vd)
            self._fr.t = self.time   # sample times, for time-dependent element measures
            self._fr.lambda_ = self.lambda_   # multipliers, for friction measures (force_elements.friction)
        return self._fr

    def at(self, t) -> "Result":
        """The same Result API at time(s) t [s], evaluated from the solver's dense output."""
        ts = np.atleast_1d(np.asarray(t, dtype=float))
        lo, hi = self.time[0], self.time[-1]
        if not np.all(np.isfinite(ts)) or np.any(ts < lo - 1e-12 * max(1, abs(lo))) or \
                np.any(ts > hi + 1e-12 * max(1, abs(hi))):
            raise ValueError(f"time(s) {ts} outside the result's range [{lo}, {hi}] s")
        if self._evaluate is None:
            idx = [int(np.argmin(np.abs(self.time - x))) for x in ts]
            return self._subset(idx)
        q, v, vd, lam = self._evaluate(np.clip(ts, lo, hi))
        out = Result(self.system, ts, q, v, vd, lam, self._evaluate, self.success, self.status, self.message)
        out._parent = self._parent or self
        return out

    def _subset(self, idx):
        take = lambda a: None if a is None else a[idx]  # noqa: E731
        out = Result(self.system, self.time[idx], self.q[idx], self.v[idx], take(self.vd), take(self.lambda_),
                     self._evaluate, self.success, self.status, self.message)
        out._parent = self._parent or self
        return out

    # ------------------------------------------------------------ points and bodies
    def position(self, target, frame=None):
        """Position [m] of a body's CM or a marker origin (N, 3)."""
        return ms.position(self.system, self.frames, target, frame)

    def velocity(self, target, frame=None):
        """Absolute velocity [m/s] (N, 3), in ground axes or expressed in `frame` axes."""
        return ms.express(self.system, self.frames, ms.point_kinematics(self.system, self.frames, target)[1], frame)

    def acceleration(self, target, frame=None):
        """Absolute acceleration [m/s^2] (N, 3), in ground axes or expressed in `frame` axes."""
        self._need_acc("acceleration")
        return ms.express(self.system, self.frames, ms.point_kinematics(self.system, self.frames, target)[2], frame)

    def orientation(self, body):
        """Rotation matrices body->ground (N, 3, 3)."""
        return self.frames.A[:, ms.locate(self.system, body)[0]]

    def angular_velocity(self, body, frame=None):
        """Angular velocity [rad/s] (N, 3) of a body, ground axes or `frame` axes."""
        return ms.express(self.system, self.frames, self.frames.w[:, ms.locate(self.system, body)[0]], frame)

    def angular_acceleration(self, body, frame=None):
        """Angular acceleration [rad/s^2] (N, 3), ground axes or `frame` axes."""
        self._need_acc("angular_acceleration")
        return ms.express(self.system, self.frames, self.frames.alpha[:, ms.locate(self.system, body)[0]], frame)

    def _need_acc(self, what):
        if self.vd is None:
            raise ValueError(f"{what} is not available: this result holds no accelerations")

    # ------------------------------------------------------------ joints
    def _joint(self, joint) -> Joint:
        if isinstance(joint, str):
            joint = self.system.model.joints.get(joint, joint)
        if not isinstance(joint, Joint) or joint.name not in self.system.geoms:
            raise ModelError(f"joint {getattr(joint, 'name', joint)!r}", "joint", "is not a joint of the analysed model")
        return joint

    def _coord(self, joint):
        ang, angd, sl, sld = ms.joint_coordinate(self.system, self.frames, self._joint(joint))
        if ang is not None:
            if self._parent is None:
                ref = _angle_anchor(self.system, self._joint(joint), self.time)
                if ref is not None:   # a torsion spring / stop on the joint continued the angle in the run
                    ang = ref + (ang - ref + np.pi) % (2 * np.pi) - np.pi
                ang = _unwrap_with_rate(self.time, ang, angd)
            else:  # continue the parent's unwrapped history from its nearest sample
                p = self._parent
                p_ang, p_rate = p._coord(joint)[:2]
                k = np.clip(np.searchsorted(p.time, self.time), 0, len(p.time) - 1)
                prev = np.maximum(k - 1, 0)
                k = np.where(np.abs(p.time[prev] - self.time) < np.abs(p.time[k] - self.time), prev, k)
                ref = p_ang[k] + 0.5 * (p_rate[k] + angd) * (self.time - p.time[k])
                ang = ref + (ang - ref + np.pi) % (2 * np.pi) - np.pi
        return ang, angd, sl, sld

    def joint_coordinate(self, joint):
        """Relative angle [rad] or displacement [m] of body_j w.r.t. body_i, unwrapped; (N, 2) [angle, slide]
        for a cylindrical joint; (N, 3) [u, v along the plane axes, angle] for a planar joint; for
        spherical, universal and fixed joints the rotation vector [rad] (N, 3) of j relative to its initial
        attitude, in body_i axes."""
        jt = self._joint(joint)
        if jt.kind in ROTATION_JOINTS:
            return ms.relative_rotation_vector(self.system, self.frames, jt)
        if jt.kind == "planar":
            return ms.planar_coordinates(self.system, self.frames, jt)[0]
        ang, _, sl, _ = self._coord(joint)
        return _pick(ang, sl)

    def joint_velocity(self, joint):
        """Rate of the joint coordinate [rad/s or m/s]; for spherical, universal and fixed joints the
        angular velocity of j relative to i [rad/s] in body_i axes."""
        jt = self._joint(joint)
        if jt.kind in ROTATION_JOINTS:
            return ms.relative_angular_velocity(self.system, self.frames, jt)[0]
        if jt.kind == "planar":
            return ms.planar_coordinates(self.system, self.frames, jt)[1]
        _, angd, _, sld = self._coord(joint)
        return _pick(angd, sld)

    def joint_acceleration(self, joint):
        """Second derivative of the joint coordinate [rad/s^2 or m/s^2]; for spherical, universal and fixed
        joints the time derivative, in body_i axes, of the relative angular velocity [rad/s^2]."""
        self._need_acc("joint_acceleration")
        jt = self._joint(joint)
        if jt.kind in ROTATION_JOINTS:
            return ms.relative_angular_velocity(self.system, self.frames, jt)[1]
        if jt.kind == "planar":
            raise ModelError(f"joint '{jt.name}'", "joint", "joint_acceleration of a planar joint is not "
                             "available; use acceleration()/angular_acceleration() of its bodies")
        g = self.system.geoms[jt.name]
        fr = self.frames
        rel_acc_rot = fr.alpha[:, g.bj] - fr.alpha[:, g.bi]
        h = np.einsum("nij,j->ni", fr.A[:, g.bi], g.h_i)
        ang = sl = None
        if jt.kind in ("revolute", "cylindrical") and not g.particle_j:
            # d/dt (h . (w_j - w_i)) = h . (alpha_j - alpha_i) + (w_i x h) . (w_j - w_i)
            dw = fr.w[:, g.bj] - fr.w[:, g.bi]
            ang = np.einsum("ni,ni->n", h, rel_acc_rot) + np.einsum("ni,ni->n", np.cross(fr.w[:, g.bi], h), dw)
        if jt.kind in ("translational", "cylindrical"):
            sl = self._slide_acc(g, fr, h)
        return _pick(ang, sl)

    def _slide_acc(self, g, fr, h):
        si = np.einsum("nij,j->ni", fr.A[:, g.bi], g.s_i)
        sj = np.einsum("nij,j->ni", fr.A[:, g.bj], g.s_j)
        wi, wj = fr.w[:, g.bi], fr.w[:, g.bj]
        d = fr.r[:, g.bj] + sj - fr.r[:, g.bi] - si
        dd = fr.rd[:, g.bj] + np.cross(wj, sj) - fr.rd[:, g.bi] - np.cross(wi, si)
        ddd = (fr.rdd[:, g.bj] + np.cross(fr.alpha[:, g.bj], sj) + np.cross(wj, np.cross(wj, sj))
               - fr.rdd[:, g.bi] - np.cross(fr.alpha[:, g.bi], si) - np.cross(wi, np.cross(wi, si)))
        hd = np.cross(wi, h)
        hdd = np.cross(fr.alpha[:, g.bi], h) + np.cross(wi, hd)
        dot = lambda a, b: np.einsum("ni,ni->n", a, b)  # noqa: E731
        return dot(hdd, d) + 2 * dot(hd, dd) + dot(h, ddd)

    def reaction_force(self, joint, on=None, frame=None):
        """Force [N] (N, 3) the joint exerts on body `on` (default body_j), ground or `frame` axes."""
        return self._reaction(joint, on, frame)[0]

    def reaction_torque(self, joint, on=None, frame=None):
        """Torque [N m] (N, 3) the joint exerts on body `on`, reduced to the joint point."""
        return self._reaction(joint, on, frame)[1]

    def _reaction(self, joint, on, frame):
        from ..system.reactions import joint_reaction
        if self.lambda_ is None:
            raise ValueError("reaction forces are not available: this result holds no multipliers")
        jt = self._joint(joint) if not (isinstance(joint, str) and joint in self.system.owner_rows) else joint
        F, T = joint_reaction(self.system, self.q, self.lambda_, jt, on)
        return (ms.express(self.system, self.frames, F, frame), ms.express(self.system, self.frames, T, frame))

    # ------------------------------------------------------------ springs and energy
    def _element(self, spring):
        forces = self.system.model.forces
        name = spring if isinstance(spring, str) else getattr(spring, "name", None)
        if name not in forces:
            raise ModelError(f"force element {name!r}", "spring", "is not part of the analysed model")
        return forces[name]

    def spring_length(self, spring):
        """Spring length [m] (translational) or angle [rad] (torsional), (N,)."""
        el = self._element(spring)
        return evaluator(el).measure(self.system, self.frames, el)[0] if hasattr(evaluator(el), "measure") \
            else _spring(self, el)[0]

    def spring_velocity(self, spring):
        """Rate of spring length [m/s] or angle [rad/s], (N,)."""
        el = self._element(spring)
        return evaluator(el).measure(self.system, self.frames, el)[1] if hasattr(evaluator(el), "measure") \
            else _spring(self, el)[1]

    def spring_force(self, spring):
        """Spring force [N] (tension > 0) or torque [N m], (N,)."""
        el = self._element(spring)
        ev = evaluator(el)
        if not hasattr(ev, "tension"):
            raise ModelError(f"force element {el.name!r}", "spring", f"a {type(el).__name__} has no scalar "
                             "spring force (spring measures are for spring-dampers, torsion springs, stops, contacts)")
        L, Ld = self.spring_length(el), self.spring_velocity(el)
        return ev.tension(el, L, Ld)

    def kinetic_energy(self):
        """Total kinetic energy [J], (N,)."""
        return ms.kinetic_energy(self.system, self.frames)

    def potential_energy(self):
        """Gravity plus every elastic element's potential energy [J], (N,)."""
        V = ms.gravity_potential(self.system, self.frames)
        for el in self.system.model.forces.values():
            ev = evaluator(el)
            if hasattr(ev, "potential"):
                V = V + ev.potential(self.system, self.frames, el)
        return V

    def dissipated_energy(self):
        """Energy dissipated by damping, friction and contact since the first sample [J], (N,)."""
        from .energy import dissipated_energy
        return dissipated_energy(self)

    def friction_force(self, friction):
        """Joint friction force [N] (translational) or torque [N m] (revolute) on body_j along / about the
        joint axis, (N,); it opposes the joint's motion (or the impending motion while sticking)."""
        from ..system.force_elements.friction import friction_force
        return friction_force(self, friction)

    def friction_events(self, friction):
        """Stick/slip history of a joint friction element: [(time [s], "stick" or "slip", direction)]."""
        from ..system.force_elements.friction import friction_events
        return friction_events(self, friction)

    # ------------------------------------------------------------ events and extrema
    def crossings(self, signal, value, direction=0):
        """Times [s] where signal(res) crosses value (direction +1 rising, -1 falling, 0 both), refined with at()."""
        y = np.asarray(signal(self), dtype=float) - value
        out = []
        for k in range(len(y) - 1):
            a, b = y[k], y[k + 1]
            if a == 0.0 and (k == 0 or y[k - 1] != 0.0) and _dir_ok(y, k, direction):
                out.append(self.time[k])
                continue
            if a * b < 0 and (direction == 0 or np.sign(b - a) == np.sign(direction)):
                f = lambda t: float(np.asarray(signal(self.at(t)))[0]) - value  # noqa: E731
                out.append(so.brentq(f, self.time[k], self.time[k + 1], xtol=1e-14, rtol=1e-15, maxiter=200))
        if len(y) and y[-1] == 0.0:
            out.append(self.time[-1])
        return np.array(sorted(set(out)))

    def maximum(self, signal):
        """(time [s], value) of the maximum of signal(res), refined on the dense output."""
        return self._extremum(signal, +1)

    def minimum(self, signal):
        """(time [s], value) of the minimum of signal(res), refined on the dense output."""
        return self._extremum(signal, -1)

    def _extremum(self, signal, sign):
        y = sign * np.asarray(signal(self), dtype=float)
        # the first sample at the maximum up to rounding (a plateau - a joint stopped by friction - counts from
        # its start, not from wherever the last bit of noise happens to peak)
        tol = 1e-12 * np.max(np.abs(y))
        k = int(np.argmax(y >= np.max(y) - tol))
        if k in (0, len(y) - 1) or self._evaluate is None:
            return float(self.time[k]), float(sign * y[k])
        f = lambda t: -sign * float(np.asarray(signal(self.at(t)))[0])  # noqa: E731
        flat = False
        try:
            r = so.minimize_scalar(f, bracket=(self.time[k - 1], self.time[k], self.time[k + 1]),
                                   method="brent", tol=1e-12)
        except ValueError:   # flat top (a neighbour sample equals the maximum): bounded search instead
            r = so.minimize_scalar(f, bounds=(self.time[k - 1], self.time[k + 1]), method="bounded",
                                   options={"xatol": 1e-12})
            flat = True
        t = float(r.x) if self.time[k - 1] <= r.x <= self.time[k + 1] else float(self.time[k])
        val = float(np.asarray(signal(self.at(t)))[0])
        better = sign * val > y[k] + tol if flat else sign * val >= y[k]   # a plateau keeps its first sample
        return (t, val) if better else (float(self.time[k]), float(sign * y[k]))

    # ------------------------------------------------------------ export
    def to_dataframe(self):
        """Tidy pandas DataFrame: time and each body's position/velocity, joint coordinates; units in names."""
        from .export import to_dataframe
        return to_dataframe(self)


def _angle_anchor(system, joint, times):
    """The angle references (N,) recorded during the analysis by a force element on `joint` (torsion
    spring, rotational stop), or None."""
    from ..system.force_elements._common import _ref, element_state
    for e in system.model.forces.values():
        if getattr(e, "joint", None) is joint and element_state(system, e.name).get("angle_ref"):
            return _ref(system, e.name, times)
    return None


def _unwrap_with_rate(t, ang, rate):
    """Continue wrapped angles (N,) beyond +-pi: each increment is the one closest to the trapezoidal
    prediction from the rates, so more than pi per output step is followed (np.unwrap is not)."""
    if len(ang) < 2:
        return ang
    pred = 0.5 * (rate[1:] + rate[:-1]) * np.diff(t)
    inc = pred + (np.diff(ang) - pred + np.pi) % (2 * np.pi) - np.pi
    cont = ang[0] + np.concatenate([[0.0], np.cumsum(inc)])
    return ang + 2 * np.pi * np.round((cont - ang) / (2 * np.pi))   # the raw values, shifted by whole turns


ROTATION_JOINTS = ("spherical", "universal", "fixed")


def _pick(ang, sl):
    if ang is not None and sl is not None:
        return np.stack([ang, sl], -1)
    return ang if ang is not None else sl


def _dir_ok(y, k, direction):
    if direction == 0:
        return True
    prev = y[k - 1] if k > 0 else 0.0
    nxt = y[k + 1]
    return np.sign(nxt - prev) == np.sign(direction)


def _spring(res, el):
    from ..system.force_elements.loads import spring_state
    L, Ld, *_ = spring_state(res.system, res.frames, el)
    return L, Ld
