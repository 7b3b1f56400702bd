"""Result: one row per output time, with measures computed from (system, coordinates).

Vectors are (N, 3) in ground axes unless `frame=` names a Body or Marker (then expressed in its axes;
positions then measured from its origin).  SI units: m, m/s, m/s^2, rad, rad/s, rad/s^2, N, N m, J.
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

from ..errors import ModelError
from ..model.joints import Joint
from ..system import measures as ms
from . import joints as jm
from . import kinematics as kin
from ..system.force_elements import evaluator
from ..system.frames import Frames, acceleration_terms, body_frames
from ..system.reactions import jacobians_of, joint_reaction
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from scipy.spatial.transform import Rotation
    from .._types import Array, BodyRef, FrameRef, JointRef, PathLike, Signal, Target
    from numpy.typing import ArrayLike
    from typing import Any, Sequence
    import pandas as pd


class Result:
    """Time history of an analysis; a failed run keeps every step computed before the failure.

    `stats` (dict) of a dynamic analysis: "method" (what ran, and for the automatic method why), "steps",
    "rejected", "nfev" (function evaluations), "njev" (Jacobian evaluations), "factorizations",
    "order" (of the method that finished the run) and "order_history", a list of
    `(t_start, method, order)` segments in time order, t_start in seconds (two for an automatic run that
    handed over to the compiled Radau IIA on stiffness, at `stats["switch_time"]`; BDF's own order
    changes), plus
    "assembly" (the AssemblyReport)."""

    def __init__(self, system, time, q, v, vd, lambda_, evaluate: Callable | None = None,
                 success=True, status=0, message="ok", stats=None, accelerations: Callable | None = None):
        self.system = system
        self.time = np.atleast_1d(np.asarray(time, dtype=float))   # [s]
        self.q, self.v = np.atleast_2d(q), np.atleast_2d(v)         # coordinates, velocity variables
        self._vd = None if vd is None else np.atleast_2d(vd)
        self._lambda = None if lambda_ is None else np.atleast_2d(lambda_)
        self._accelerations = accelerations   # () -> (vd, lambda_), called once on first use
        self._evaluate = evaluate
        self.success, self.status, self.message = success, status, message
        self.stats = stats or {}
        self._fr = None
        self._parent = None
        self.steps = None   # (t, q, v) at the solver's step starts and the end, or a callable giving them
        self.error = None   # the MbdsimError that stopped a failed run (time, joints, last good state)
        self.diagnostics = None   # run monitors (mbdsim.results.diagnostics.Diagnostics), set by simulate
        # compiled runs: residual_check(idx, rows) -> (max |phi[rows]| [m or rad], its row) at the samples idx
        # in one compiled call (the run monitors use it instead of evaluating the rows sample by sample)
        self.residual_check = None
        # compiled runs of simulate(monitor=True): {"D": dissipated energy, "W": applied loads' work} [J] at
        # the samples since the first, accumulated in the step loop (None where not evaluated; solvers.energy_run)
        self.energy = None

    # ------------------------------------------------------------ basics
    def __len__(self):
        return len(self.time)

    def __repr__(self):
        return f"Result({len(self)} samples, t=[{self.time[0]:.6g}, {self.time[-1]:.6g}] s, success={self.success})"

    def _repr_html_(self):  # Jupyter summary
        from ..viewer.notebook import result_html; return result_html(self)  # noqa: E702

    @property
    def vd(self):
        """Accelerations of the velocity variables v (N, nv) [m/s^2, rad/s^2 in body axes], or None."""
        if self._vd is None and self._accelerations is not None:
            self._materialize()
        return self._vd

    @property
    def lambda_(self):
        """Lagrange multipliers of the constraint rows (N, nc) [N, N m], or None."""
        if self._lambda is None and self._accelerations is not None:
            self._materialize()
        return self._lambda

    def _materialize(self):
        """Compute the accelerations and multipliers of a run that left them for later (compiled runs)."""
        fn, self._accelerations = self._accelerations, None
        vd, lam = fn()
        self._vd, self._lambda = np.atleast_2d(vd), np.atleast_2d(lam)

    def inject_frames(self, fr: Frames) -> None:
        """Use Frames `fr` (with a sample axis) already computed for this Result's (q, v) instead of
        computing them on first use (solvers.pyloads hands over the compiled kernels' frames); they get
        the sample times (time-dependent element measures) and the angles continued by this Result."""
        fr.t = self.time
        fr.angle = lambda jt: jm.one_axis(self, jt)[0]
        self._fr = fr

    @property
    def frames(self):
        """Body frames of the samples (mbdsim.system.frames.Frames); the acceleration terms (rdd, alpha)
        and the multipliers are computed on first use (most measures need positions and velocities only)."""
        if self._fr is None:
            fr = body_frames(self.system, self.q, self.v)
            if self._vd is not None or self._accelerations is not None:
                fr = _LazyFrames(fr, self)
            self.inject_frames(fr)
        return self._fr

    def at(self, t: float | ArrayLike) -> "Result":
        """The same Result API at time(s) t [s], evaluated from the solver's dense output."""
        ts = np.atleast_1d(np.asarray(t, dtype=float))
        lo, hi = self.time[0], self.time[-1]
        if ts.size:   # the earliest and latest times checked (NaN and infinities fail isfinite)
            first, last = float(ts.min()), float(ts.max())
            if not (math.isfinite(first) and math.isfinite(last)) or first < lo - 1e-12 * max(1, abs(lo)) or \
                    last > hi + 1e-12 * max(1, abs(hi)):
                raise ValueError(f"time(s) {ts} outside the result's range [{lo}, {hi}] s")
        if self._evaluate is None:
            return self._bracketed(ts)
        q, v, vd, lam = self._evaluate(np.clip(ts, lo, hi))
        out = Result(self.system, ts, q, v, vd, lam, self._evaluate, self.success, self.status, self.message,
                     stats={"assembly": self.stats["assembly"]} if "assembly" in self.stats else None)
        out._parent = self._parent or self   # (the assembly's rows: no determinacy analysis without redundancy)
        return out

    def _bracketed(self, ts) -> "Result":
        """Without dense output: cubic Hermite between the two samples that bracket each t (q from q and
        dq/dt, v from v and vd when the result has accelerations, else linear; vd and lambda_ linear);
        Euler parameters renormalised."""
        if len(self.time) < 2:
            return self._subset([0] * len(ts))
        from ..system.coordinates import normalize, qdot
        k = np.clip(np.searchsorted(self.time, ts), 1, len(self.time) - 1)
        a, b = k - 1, k
        h = (self.time[b] - self.time[a])[:, None]
        s = (ts - self.time[a])[:, None] / h
        h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, 3 * s**2 - 2 * s**3, s**3 - s**2
        qd = lambda i: np.array([qdot(self.system, self.q[j], self.v[j]) for j in i])  # noqa: E731
        herm = lambda y, da, db: h00 * y[a] + h10 * h * da + h01 * y[b] + h11 * h * db  # noqa: E731
        lin = lambda y: None if y is None else (1 - s) * y[a] + s * y[b]  # noqa: E731
        q = np.array([normalize(self.system, x) for x in herm(self.q, qd(a), qd(b))])
        v = lin(self.v) if self.vd is None else herm(self.v, self.vd[a], self.vd[b])
        out = Result(self.system, ts, q, v, lin(self.vd), lin(self.lambda_), None, self.success, self.status,
                     self.message)
        out._parent = self._parent or self
        return out

    def _subset(self, idx):
        take = lambda a: None if a is None else a[idx]  # noqa: E731
        out = Result(self.system, self.time[idx], self.q[idx], self.v[idx], take(self.vd), take(self.lambda_),
                     self._evaluate, self.success, self.status, self.message)
        out._parent = self._parent or self
        return out

    # ------------------------------------------------------------ points and bodies
    # A target or frame is a Body (its CM), a Marker, or the name of one: "rod", "rod.tip".
    def position(self, target: Target, frame: FrameRef = None) -> Array:
        """Position [m] (N, 3) of a body's CM or a marker origin; in ground, or measured from `frame`'s
        origin and expressed in its axes."""
        return ms.position(self.system, self.frames, target, frame)

    def velocity(self, target: Target, frame: FrameRef = None, relative_to: FrameRef = None) -> Array:
        """Velocity [m/s] (N, 3) of a body's CM or a marker origin, in ground axes or `frame` axes.

        Absolute by default; with `relative_to=f` the time derivative, taken in frame f, of the position
        relative to f's origin (Adams VX(i, j, k, l) with j = l = f, k = frame):
        v = v_rel + v_O + w_f x rho (see mbdsim.results.kinematics)."""
        if relative_to is None:
            v = ms.point_kinematics(self.system, self.frames, target, False)[1]
        else:
            v = kin.relative_point_motion(self.system, self.frames, target, relative_to).v_rel
        return self._express(v, frame)

    def acceleration(self, target: Target, frame: FrameRef = None, relative_to: FrameRef = None) -> Array:
        """Acceleration [m/s^2] (N, 3) of a body's CM or a marker origin, in ground axes or `frame` axes.

        Absolute by default; with `relative_to=f` the second derivative taken in frame f, so that
        a = a_rel + a_transport + 2 w_f x v_rel (Coriolis); see mbdsim.results.kinematics."""
        self._need_acc("acceleration")
        if relative_to is None:
            a = ms.point_kinematics(self.system, self.frames, target)[2]
        else:
            a = kin.relative_point_motion(self.system, self.frames, target, relative_to).a_rel
        return self._express(a, frame)

    def orientation(self, target: Target) -> Array:
        """Rotation matrices (N, 3, 3) mapping the axes of `target` to ground: the body's orientation
        times the marker's (a body name or Body gives the body's own axes)."""
        return kin.orientation(self.system, self.frames, target)

    def rotation(self, target: Target) -> Rotation:
        """`scipy.spatial.transform.Rotation` stack (N rotations) of `orientation(target)`: use its
        as_quat() (scalar last), as_euler(seq) (any sequence), as_rotvec(), as_matrix()."""
        from scipy.spatial.transform import Rotation
        return Rotation.from_matrix(self.orientation(target))

    def angular_velocity(self, target: Target, frame: FrameRef = None, relative_to: FrameRef = None) -> Array:
        """Angular velocity [rad/s] (N, 3) of the body of `target` (a marker stands for its body), in
        ground or `frame` axes; with `relative_to=f`, w - w_f."""
        if relative_to is None:
            w = self.frames.w[:, ms.locate(self.system, target)[0]]
        else:
            w = kin.relative_angular_motion(self.system, self.frames, target, relative_to)[0]
        return self._express(w, frame)

    def angular_acceleration(self, target: Target, frame: FrameRef = None, relative_to: FrameRef = None) -> Array:
        """Angular acceleration [rad/s^2] (N, 3), in ground or `frame` axes; with `relative_to=f` the
        derivative, taken in f, of w - w_f: alpha - alpha_f - w_f x (w - w_f)."""
        self._need_acc("angular_acceleration")
        if relative_to is None:
            al = self.frames.alpha[:, ms.locate(self.system, target)[0]]
        else:
            al = kin.relative_angular_motion(self.system, self.frames, target, relative_to)[1]
        return self._express(al, frame)

    def _express(self, vec, frame):
        return ms.express(self.system, self.frames, vec, frame)

    def _need_acc(self, what):
        if self.vd is None:
            raise ValueError(f"{what} is not available: this result holds no accelerations")

    # ------------------------------------------------------------ joints (see mbdsim.results.joints)
    def _joint(self, joint) -> Joint:
        return jm.joint_of(self, joint)

    def joint_coordinate(self, joint: JointRef, kind: str | None = None) -> Array:
        """Joint coordinate, zero in the built configuration, continuous in time (N,) or (N, k):
        revolute angle [rad], translational slide [m], cylindrical [angle, slide], planar [u, v, angle]
        (u, v [m] along the plane axes of `add_planar`, angle [rad] about the normal); spherical,
        universal, fixed: rotation vector [rad] (N, 3) of body_j relative to its initial attitude, body_i
        axes.  `kind="angles"` (universal joints): the yoke angles (angle1, angle2) [rad] (angle1 of the
        cross about axis_i relative to body_i, angle2 of body_j about axis_j relative to the cross)."""
        return jm.coordinate(self, joint, kind)

    def joint_velocity(self, joint: JointRef, kind: str | None = None) -> Array:
        """Rate of the joint coordinate [rad/s or m/s]; for spherical, universal and fixed joints the
        angular velocity of j relative to i [rad/s] in body_i axes; `kind="angles"`: yoke angle rates."""
        return jm.velocity(self, joint, kind)

    def joint_acceleration(self, joint: JointRef, kind: str | None = None) -> Array:
        """Second derivative of the joint coordinate [rad/s^2 or m/s^2] (planar: [u'', v'', angle''];
        spherical, universal, fixed: the derivative, in body_i axes, of the relative angular velocity;
        `kind="angles"`: yoke angle accelerations)."""
        self._need_acc("joint_acceleration")
        return jm.acceleration(self, joint, kind)

    def reaction_force(self, joint: JointRef, on: BodyRef | None = None, frame: FrameRef = None) -> Array:
        """Force [N] (N, 3) the joint exerts on body `on` (a body, marker or name; default body_j), in
        ground or `frame` axes. With redundant constraints, components the rigid model cannot determine
        (Wojtyra-Fraczek, mbdsim.system.determinacy) are flagged: the array's `.indeterminate` (N, 3)
        booleans, and an IndeterminateReactionWarning naming them (their values are the minimum-norm split,
        one of infinitely many)."""
        return self._flagged(joint, on, frame, 0)

    def reaction_torque(self, joint: JointRef, on: BodyRef | None = None, frame: FrameRef = None) -> Array:
        """Torque [N m] (N, 3) the joint exerts on body `on`, reduced to the joint point, in ground or
        `frame` axes; indeterminate components flagged as in reaction_force."""
        return self._flagged(joint, on, frame, 1)

    def reaction_determinacy(self, joint: JointRef, on: BodyRef | None = None, frame: FrameRef = None) -> Array:
        """(N, 6) booleans, True where (Fx, Fy, Fz, Tx, Ty, Tz) of the joint's reaction (axes as
        reaction_force) is *indeterminate* at each sample; all False without redundant constraints."""
        from ..system.determinacy import indeterminate_components
        rep = self.stats.get("assembly") if self.stats else None
        if rep is not None and len(getattr(rep, "rows", ())) == self.system.nc:
            return np.zeros((len(self.time), 6), dtype=bool)
        jt = self._joint(joint) if not (isinstance(joint, str) and joint in self.system.owner_rows) else joint
        body = None if on is None else ms.resolve_body(self.system, on, "on")
        cache = self.__dict__.setdefault("_determinacy", {})   # an SVD per sample: once per joint, body, axes
        key = (getattr(jt, "name", jt), id(body), id(frame) if frame is not None and not isinstance(frame, str)
               else frame)
        if key not in cache:
            cache[key] = indeterminate_components(self.system, self.q, jt, body,
                                                  None if frame is None else (lambda x: self._express(x, frame)))
        return cache[key].copy()

    def _flagged(self, joint, on, frame, which):
        from .._userwarn import warn
        from ..system.determinacy import IndeterminateReactionWarning, ReactionArray
        value = self._reaction(joint, on, frame)[which]
        ind = self.reaction_determinacy(joint, on, frame)[:, 3 * which:3 * which + 3]
        out = ReactionArray(value, ind)
        if ind.any():
            name = getattr(joint, "name", joint)
            comps = [("F" if which == 0 else "T") + "xyz"[k] for k in range(3) if ind[:, k].any()]
            warn(f"joint '{name}': reaction components {', '.join(comps)} are indeterminate (redundant "
                 "constraints): the values are the minimum-norm split, not determined by the rigid model",
                 IndeterminateReactionWarning)
        return out

    def _reaction(self, joint, on, frame):
        if self.lambda_ is None:
            raise ValueError("reaction forces are not available: this result holds no multipliers")
        jt = self._joint(joint) if not (isinstance(joint, str) and joint in self.system.owner_rows) else joint
        body = None if on is None else ms.resolve_body(self.system, on, "on")
        lam = self.lambda_
        F, T = joint_reaction(self.system, self.q, lam, jt, body, J=jacobians_of(self.system, lam), fr=self.frames)
        return self._express(F, frame), self._express(T, frame)

    @property
    def sensor_events(self):
        """Sensors met during the run, in time order: [SensorEvent(name, time [s], value, action)], each
        time located on the dense output to 1e-13 s (empty without sensors)."""
        return list(self.__dict__.get("_sensor_events", []))

    @sensor_events.setter
    def sensor_events(self, events):
        self.__dict__["_sensor_events"] = sorted(events, key=lambda e: e.time)

    def coupler_load(self, coupler: str | Any) -> Array:
        """Load (N, k) a coupler, gear or user constraint transmits along each joint coordinate it couples
        (in the order given): torque [N m] about a rotation's axis, force [N] along a translation's,
        on that joint's body_j.  A gear's tooth force is the torque on a gear over its pitch radius."""
        from ..system.constraints.coupler import coupler_load
        return coupler_load(self, getattr(coupler, "name", coupler))

    def driver_effort(self, motion: str | Any) -> Array:
        """Effort [N m for a rotation, N for a translation] (N,) of a motion driver: the torque about /
        force along the driven joint axis that the driver applies to body_j."""
        if self.lambda_ is None:
            raise ValueError("driver efforts are not available: this result holds no multipliers")
        return jm.driver_effort(self, motion)

    def expression(self, text: str) -> np.ndarray:
        """Values (N,) of an expression of time and state written as for loads (mbdsim.model.loadexpr:
        DM(rod.tip, ground.anchor), VR, WZ(rod), AX, joint coordinates by name and <joint>_dot ...);
        here the accelerations `ACCX/ACCY/ACCZ(i[, j][, k])` [m/s^2] are available too. Units: those of
        the quantity written."""
        from ..model.loadexpr import parse_load
        from ..system.exprmeasures import evaluate
        le = parse_load(self.system.model, text, f"expression {text!r}", "text", allow_acc=True)
        if any(m.needs_acceleration for m in le.measures.values()):
            self._need_acc("ACCX/ACCY/ACCZ")

        def joint_value(joint, dof, rate):
            x = (self.joint_velocity if rate else self.joint_coordinate)(joint)
            jt = self._joint(joint)
            return x[:, 1] if jt.kind == "cylindrical" and dof == "translation" else x
        return evaluate(self.system, self.frames, le, self.time, joint_value)

    # ------------------------------------------------------------ springs and energy
    def _element(self, spring):
        forces = self.system.model.forces
        name = spring if isinstance(spring, str) else getattr(spring, "name", None)
        if name not in forces:
            raise ModelError(f"force element {name!r}", "spring", "is not part of the analysed model")
        if not isinstance(spring, str) and forces[name] is not spring:   # same name, another model's object
            raise ModelError(f"force element {name!r}", "spring", "is an element of another model (same name, "
                             "different object) than the analysed model")
        return forces[name]

    def spring_length(self, spring: str | Any) -> Array:
        """Spring length [m] (translational) or angle [rad] (torsional), (N,)."""
        el = self._element(spring)
        return evaluator(el).measure(self.system, self.frames, el)[0] if hasattr(evaluator(el), "measure") \
            else _spring(self, el)[0]

    def spring_velocity(self, spring: str | Any) -> Array:
        """Rate of spring length [m/s] or angle [rad/s], (N,)."""
        el = self._element(spring)
        return evaluator(el).measure(self.system, self.frames, el)[1] if hasattr(evaluator(el), "measure") \
            else _spring(self, el)[1]

    def spring_force(self, spring: str | Any) -> Array:
        """Spring force [N] (tension > 0) or torque [N m], (N,)."""
        el = self._element(spring)
        ev = evaluator(el)
        if not hasattr(ev, "tension"):
            raise ModelError(f"force element {el.name!r}", "spring", f"a {type(el).__name__} has no scalar "
                             "spring force (spring measures are for spring-dampers, torsion springs, stops, contacts)")
        L, Ld = self.spring_length(el), self.spring_velocity(el)
        return ev.tension(el, L, Ld)

    def kinetic_energy(self) -> Array:
        """Total kinetic energy [J], (N,)."""
        return ms.kinetic_energy(self.system, self.v)

    def potential_energy(self) -> Array:
        """Gravity plus every elastic element's potential energy [J], (N,)."""
        V = ms.gravity_potential(self.system, self.q)
        for el in self.system.model.forces.values():
            ev = evaluator(el)
            if hasattr(ev, "potential"):
                V = V + ev.potential(self.system, self.frames, el)
        return V

    def dissipated_energy(self) -> Array:
        """Energy dissipated by damping, friction and contact since the first sample [J], (N,): from the
        compiled run's own bookkeeping where it kept one (`energy`, stats["energy"] == "compiled"), else
        integrated on the dense output after the run (results.energy)."""
        from .energy import dissipated_energy
        return dissipated_energy(self)

    def contact_points(self, contact: str | Any) -> pd.DataFrame:
        """Shape contact per point (DataFrame: time, pair, shapes, point, normal, penetration, forces, slip)."""
        from .contacts import contact_points
        return contact_points(self, contact)

    def contact_force(self, contact: str | Any) -> Array:
        """Total shape-contact force [N] on the shape_j side, ground axes, (N, 3)."""
        from .contacts import contact_force
        return contact_force(self, contact)

    def friction_force(self, friction: str | Any) -> Array:
        """Joint friction force [N] (translational) or torque [N m] (revolute) on body_j along / about the
        joint axis, (N,); it opposes the joint's motion (or the impending motion while sticking)."""
        from ..system.force_elements.friction import friction_force
        return friction_force(self, friction)

    def friction_events(self, friction: str | Any) -> list[Any]:
        """Stick/slip history of a joint friction element: [(time [s], "stick" or "slip", direction)]."""
        from ..system.force_elements.friction import friction_events
        return friction_events(self, friction)

    # ------------------------------------------------------------ events and extrema
    def crossings(self, signal: Signal, value: float, direction: int = 0) -> Array:
        """Times [s] where signal(res) (N,) reaches `value`: direction +1 rising, -1 falling, 0 both.

        A sign change between two samples is refined on the dense output (brentq on `at()`); a sample
        exactly at the level counts when the signal arrives there (the first sample of a run at the
        level, the last sample of the result included), the direction being that of the values around
        the run.  Convention at the start: a signal that starts at the level has not crossed it, so
        t = res.time[0] is never a crossing (note that scipy's solve_ivp events do report t0 then)."""
        import scipy.optimize as so   # here, not at the top: only these refinements use scipy.optimize
        y = np.asarray(signal(self), dtype=float) - value
        out = []
        for k in range(len(y) - 1):
            a, b = y[k], y[k + 1]
            if a == 0.0 and k > 0 and y[k - 1] != 0.0 and _dir_ok(y, k, direction):
                out.append(self.time[k])
                continue
            if a * b < 0 and (direction == 0 or np.sign(b - a) == np.sign(direction)):
                f = lambda t: float(np.asarray(signal(self.at(t)))[0]) - value  # noqa: E731
                out.append(so.brentq(f, self.time[k], self.time[k + 1], xtol=1e-14, rtol=1e-15, maxiter=200))
        if len(y) > 1 and y[-1] == 0.0 and y[-2] != 0.0 and (direction == 0 or np.sign(-y[-2]) == np.sign(direction)):
            out.append(self.time[-1])
        return np.array(sorted(set(out)))

    def maximum(self, signal: Signal) -> tuple[float, float]:
        """(time [s], value) of the maximum of signal(res), refined on the dense output."""
        return self._extremum(signal, +1)

    def minimum(self, signal: Signal) -> tuple[float, float]:
        """(time [s], value) of the minimum of signal(res), refined on the dense output."""
        return self._extremum(signal, -1)

    def _extremum(self, signal, sign):
        # the first sample at the extreme value up to rounding (a plateau - a joint stopped by friction -
        # counts from its start), refined on the dense output a grid of times per call (results.refine)
        from .refine import extremum
        return extremum(self, signal, sign)

    # ------------------------------------------------------------ export
    def to_dataframe(self, markers: bool | Sequence[str] = False, euler: str | None = None) -> pd.DataFrame:
        """Wide pandas DataFrame, one row per output time, SI units in the column names
        ("crank.x [m]", "pin.angle [rad]", "pin.Fx [N]"): body positions, orientations (Euler parameters
        "<body>.qw [-]" ..., and Euler angles "<body>.ZYX_1 [rad]" ... when `euler` names a scipy
        sequence), velocities, accelerations; every joint's coordinates, rates and reactions; driver
        efforts; force-element forces; marker columns "<body>.<marker>.x [m]" ... when `markers=True` (every
        marker) or a list of names ("tip" or "<body>.<marker>").  The naming is listed in full in
        `mbdsim.results.export`."""
        from .export import to_dataframe
        return to_dataframe(self, markers=markers, euler=euler)

    def to_parquet(self, path: PathLike, markers: bool | Sequence[str] = False, euler: str | None = None) -> None:
        """Write `to_dataframe(markers, euler)` to a Parquet file (pyarrow); read back with pandas."""
        self.to_dataframe(markers=markers, euler=euler).to_parquet(path, index=False)

    def to_csv(self, path: PathLike, markers: bool | Sequence[str] = False, euler: str | None = None) -> None:
        """Write `to_dataframe(markers, euler)` to a CSV file (header = column names, no index)."""
        self.to_dataframe(markers=markers, euler=euler).to_csv(path, index=False)


def _dir_ok(y, k, direction):
    """Whether the run at the level starting at sample k (k > 0) goes in `direction`."""
    if direction == 0:
        return True
    nz = np.flatnonzero(y[k + 1:])
    nxt = y[k + 1 + nz[0]] if len(nz) else 0.0
    return np.sign(nxt - y[k - 1]) == np.sign(direction) or (nxt == 0.0 and np.sign(-y[k - 1]) == np.sign(direction))


def _spring(res, el):
    from ..system.force_elements.loads import spring_state
    L, Ld, *_ = spring_state(res.system, res.frames, el)
    return L, Ld


class _LazyFrames(Frames):
    """Body frames of a Result whose accelerations (rdd, alpha) and multipliers (lambda_, for friction
    measures: force_elements.friction) are computed on first use."""

    def __init__(self, fr: Frames, res: Result):
        self.r, self.A, self.rd, self.w = fr.r, fr.A, fr.rd, fr.w
        self._res = res

    def _full(self, key):
        d = self.__dict__
        if key not in d:
            res = self._res
            if key == "_lam":
                d["_lam"] = res.lambda_
            else:   # body_frames' acceleration terms, on the rotations already computed
                d["_rdd"], d["_alpha"] = acceleration_terms(res.system, self.A, res.vd)
        return d[key]

    rdd = property(lambda self: self._full("_rdd"), lambda self, x: self.__dict__.__setitem__("_rdd", x))
    alpha = property(lambda self: self._full("_alpha"), lambda self, x: self.__dict__.__setitem__("_alpha", x))
    lambda_ = property(lambda self: self._full("_lam"), lambda self, x: self.__dict__.__setitem__("_lam", x))
