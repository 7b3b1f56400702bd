"""The Model container: named bodies, joints, motions and loads, validated as they are added."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ModelError
from ._check import scalar, vec3
from .body import Body, Marker, make_body, shape_mass_properties
from .forces import ExprForce, ExprTorque, Force, SpringDamper, Torque
from .loadexpr import ExprLoadsMixin, ExprVector, load_vector
from .elements import ForceElementsMixin
from .friction_path import FrictionPathMixin
from .joints import Joint, Motion, joint_initial
from .couplers import CouplersMixin
from .joints_extra import JointsExtraMixin
from .sensors import SensorsMixin
from .signals import FmuMixin, SignalsMixin
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .._types import (BodyRef, FrameRef, Inertia, JointRef, Load, Location, MassShape, Orientation,
                          TimeFunction, Vector)


class Model(ExprLoadsMixin, ForceElementsMixin, FrictionPathMixin, JointsExtraMixin, CouplersMixin, SensorsMixin,
            SignalsMixin, FmuMixin):
    """A mechanism description in SI units; `gravity` [m/s^2] in ground axes."""

    def __getstate__(self):
        """Pickled and copied without the assembled System kept by mbdsim.system.assemble_system."""
        state = self.__dict__.copy()
        state.pop("_assembled", None)
        return state

    def __init__(self, name: str = "model", gravity=(0.0, 0.0, 0.0), planar=False):
        """planar: True (plane normal +z) or a normal vector marks a 2D mechanism built of 3D joints: its
        out-of-plane equations are dependent by design, dropped without a RedundantConstraintWarning and
        noted in the AssemblyReport (see mbdsim.solvers.planar)."""
        self.name = str(name)
        self.gravity = vec3(f"model '{name}'", "gravity", gravity)
        if isinstance(planar, (bool, np.bool_)) or planar is None:
            self.planar = np.array([0.0, 0.0, 1.0]) if planar else None
        else:
            self.planar = vec3(f"model '{name}'", "planar", planar, unit=True)
        self.ground = Body("ground", is_ground=True)
        self.bodies: dict[str, Body] = {"ground": self.ground}
        self.joints: dict[str, Joint] = {}
        self.motions: dict[str, Motion] = {}
        self.forces: dict[str, Any] = {}
        self._names: set[str] = {"ground"}

    # ----------------------------------------------------------------- bodies
    def add_body(self, name: str, mass: float | None = None, inertia: Inertia = None, position: Vector = (0, 0, 0),
                 orientation: Orientation = None, velocity: Vector | None = None,
                 angular_velocity: Vector | None = None, shape: MassShape | None = None,
                 density: float | None = None) -> Body:
        """Add a rigid body: mass [kg], inertia about the CM in body axes [kg m^2] (3 values or 3x3, default 0),
        CM position [m], orientation (body->ground), CM velocity [m/s] and angular velocity [rad/s] in ground.

        velocity / angular_velocity default to None: free, solved at assembly (the least kinetic energy
        that the joints, drivers and given values allow); what is given is held exactly when consistent.

        Instead of mass and inertia: `shape` (mb.Box, mb.Cylinder or mb.Sphere, centred on the CM, in body
        axes) and `density` [kg/m^3]."""
        self._claim(name, "body")
        try:
            mass, inertia = shape_mass_properties(f"body '{name}'", shape, density, mass, inertia)
            b = make_body(name, mass, inertia, position, orientation, velocity, angular_velocity)
        except ModelError:
            self._names.discard(name)   # a failed add must not claim the name
            raise
        self.bodies[name] = b
        return b

    def add_particle(self, name: str, mass: float, position: Vector = (0, 0, 0),
                     velocity: Vector | None = None) -> Body:
        """Add a point mass [kg] at position [m] with velocity [m/s] (None: free, solved at assembly), both
        in ground; it has no rotation."""
        self._claim(name, "particle")
        try:
            b = make_body(name, mass, None, position, None, velocity, None, particle=True)
        except ModelError:
            self._names.discard(name)
            raise
        self.bodies[name] = b
        return b

    # ----------------------------------------------------------------- joints
    # Every joint-adding method takes either two bodies (names or Body) with the point and axes in ground
    # at t=0, or two markers (Body.add_marker, on any body or on ground) whose origins and z axes (x axes
    # for in-plane references) are the joint's I and J frames, Adams style; then the point and axis
    # arguments are omitted and the bodies may be drawn anywhere (assembly closes the gaps); the joint's
    # angles and slides (motions, joint_coordinate) are then zero where the markers' axes coincide.
    # initial_displacement / initial_velocity: joint coordinates (from as drawn) and rates held at
    # assembly, a number for a one-coordinate joint, else in the order of Result.joint_coordinate.
    def add_revolute(self, name: str, body_i: BodyRef, body_j: BodyRef, point: Vector | None = None,
                     axis: Vector | None = None, initial_displacement: float | Vector | None = None,
                     initial_velocity: float | Vector | None = None) -> Joint:
        """Revolute joint at `point` [m] about `axis`, both in ground at t=0 (or two markers); coordinate:
        the angle [rad] of body_j about the axis."""
        return self._joint(name, "revolute", body_i, body_j, point, axis, initial_displacement, initial_velocity)

    def add_translational(self, name: str, body_i: BodyRef, body_j: BodyRef, point: Vector | None = None,
                          axis: Vector | None = None, initial_displacement: float | Vector | None = None,
                          initial_velocity: float | Vector | None = None) -> Joint:
        """Translational (prismatic) joint sliding along `axis` through `point` (ground, t=0, or two
        markers); coordinate: the slide [m]."""
        return self._joint(name, "translational", body_i, body_j, point, axis, initial_displacement,
                           initial_velocity)

    def add_cylindrical(self, name: str, body_i: BodyRef, body_j: BodyRef, point: Vector | None = None,
                        axis: Vector | None = None, initial_displacement: float | Vector | None = None,
                        initial_velocity: float | Vector | None = None) -> Joint:
        """Cylindrical joint: rotation about and sliding along `axis` through `point` (ground, t=0).

        Its coordinates are (angle [rad], slide [m]); every call that takes `dof=` on it (add_motion,
        add_stop, ...) picks "rotation" or "translation" and defaults to "rotation"."""
        return self._joint(name, "cylindrical", body_i, body_j, point, axis, initial_displacement,
                           initial_velocity)

    def add_spherical(self, name: str, body_i: BodyRef, body_j: BodyRef, point: Vector | None = None,
                      initial_displacement: float | Vector | None = None,
                      initial_velocity: float | Vector | None = None) -> Joint:
        """Spherical (ball) joint at `point` [m] in ground at t=0 (or two markers); coordinates: the
        relative rotation vector [rad] and relative angular velocity [rad/s] in body_i axes."""
        return self._joint(name, "spherical", body_i, body_j, point, _Z, initial_displacement, initial_velocity)

    def add_universal(self, name: str, body_i: BodyRef, body_j: BodyRef, point: Vector | None = None,
                      axis_i: Vector | None = None, axis_j: Vector | None = None,
                      initial_displacement: float | Vector | None = None,
                      initial_velocity: float | Vector | None = None) -> Joint:
        """Universal joint at `point`; `axis_i` fixed on body_i, `axis_j` on body_j, perpendicular at t=0
        (within 1e-6 rad: then axis_j is orthogonalised and the AssemblyReport notes it).  With two
        markers the axes are their z axes.  Coordinates as a spherical joint's (rotation vector)."""
        j = self._joint(name, "universal", body_i, body_j, point, axis_i, initial_displacement, initial_velocity)
        try:
            if j.marker_j is not None:
                if axis_j is not None:
                    raise ModelError(f"joint '{name}'", "axis_j", "omit the axes of a joint between two "
                                     "markers (their z axes are used)")
                j.axis_j = j.marker_j.orientation[:, 2].copy()
            else:
                j.axis_j = _universal_axis_j(j, axis_j)
        except ModelError:
            self._drop_joint(name)
            raise
        return j

    def add_planar(self, name: str, body_i: BodyRef, body_j: BodyRef, point: Vector | None = None,
                   normal: Vector | None = None, u_axis: Vector | None = None,
                   initial_displacement: float | Vector | None = None,
                   initial_velocity: float | Vector | None = None) -> Joint:
        """Planar joint: body_j moves in the plane through `point` with `normal` fixed on body_i.

        Its coordinates (Result.joint_coordinate) are [u, v, angle]: the joint point of body_j along the
        in-plane axes u and v = normal x u [m] and the rotation about the normal [rad], all fixed on
        body_i and zero as built.  `u_axis` (ground, t=0) must be perpendicular to the normal; the
        default is the ground x axis projected onto the plane, or the ground y axis projected when the
        normal is within about 26 deg of x (|normal . x| > 0.9): normal +z gives u = +x, v = +y.
        With two markers: normal = the I marker's z axis, u = its x axis."""
        j = self._joint(name, "planar", body_i, body_j, point, normal, initial_displacement, initial_velocity)
        try:
            if j.marker_i is not None and u_axis is not None:
                raise ModelError(f"joint '{name}'", "u_axis", "omit it for a joint between two markers "
                                 "(the I marker's x axis is used)")
            u = None if u_axis is None else vec3(f"joint '{name}'", "u_axis", u_axis, unit=True)
            if u is not None and abs(float(u @ j.axis)) > 1e-9:
                raise ModelError(f"joint '{name}'", "u_axis", "must be perpendicular to the normal")
        except ModelError:
            self._drop_joint(name)
            raise
        j.u_axis = j.marker_i.orientation[:, 0].copy() if j.marker_i is not None else \
            (_default_u_axis(j.axis) if u is None else u)
        return j

    def add_fixed(self, name: str, body_i: BodyRef, body_j: BodyRef, point: Vector | None = None) -> Joint:
        """Fixed joint welding body_j to body_i (at `point`, default body_j's CM; or two markers, which
        assembly makes coincide, axes included)."""
        bj = self.bodies.get(body_j) if isinstance(body_j, str) else body_j   # a body may be given by name
        point = bj.position if point is None and isinstance(bj, Body) else point
        return self._joint(name, "fixed", body_i, body_j, point, _Z)

    def _drop_joint(self, name):
        del self.joints[name]
        self._names.discard(name)

    # ----------------------------------------------------------------- drivers
    def add_motion(self, name: str, joint: JointRef, displacement: TimeFunction | None = None,
                   velocity: TimeFunction | None = None, acceleration: TimeFunction | None = None,
                   initial_displacement: float = 0.0, initial_velocity: float = 0.0, dof: str | None = None) -> Motion:
        """Drive a joint coordinate [rad or m] as a function of time t [s].

        Give exactly one of displacement, velocity (with initial_displacement) or acceleration (with
        initial_displacement and initial_velocity): a callable of t, a number or an expression string
        in t (safe whitelist parser, never eval'd). An expression may also read the model's inputs
        (Model.add_input, declared before): held constant over each step of mbdsim.Simulator, a velocity
        or acceleration driver then keeps its displacement continuous when an input changes, a
        displacement driver jumps (the state is re-projected at the step's start); see
        mbdsim.model.input_drivers.  `dof` picks "rotation" (the default) or "translation"
        on a cylindrical joint; other one-DOF joints drive their only coordinate.
        """
        from ..expressions import double_integrated, integrated, time_function

        entity = f"motion '{name}'"
        self._claim(name, "motion")
        try:
            jt = self._lookup(joint, self.joints, entity, "joint")
            given = [(k, v) for k, v in (("displacement", displacement), ("velocity", velocity),
                                          ("acceleration", acceleration)) if v is not None]
            if len(given) != 1:
                raise ModelError(entity, "displacement", "give exactly one of displacement, velocity, acceleration")
            kind, f = given[0]
            dof = self._motion_dof(entity, jt, dof)
            for other in self.motions.values():
                if other.joint is jt and other.dof == dof:
                    raise ModelError(entity, "joint", f"the {dof} of joint '{jt.name}' is already driven by "
                                     f"motion '{other.name}'; a coordinate takes one motion")
            from .input_drivers import input_driver, reads_inputs
            inputs = {n: i.value for n, i in getattr(self, "inputs", {}).items()}
            try:
                x0 = scalar(entity, "initial_displacement", initial_displacement)
                v0 = scalar(entity, "initial_velocity", initial_velocity)
                if reads_inputs(f, inputs):   # an expression of t and model inputs (Simulator.set_input)
                    given = tf = input_driver(kind, f, inputs, x0, v0)[0]
                else:
                    if callable(f) and not hasattr(f, "d1"):
                        from ._check import check_time_callable
                        check_time_callable(entity, kind, f)
                    given = tf = time_function(f)
                    if kind == "velocity":
                        tf = integrated(tf, x0)
                    elif kind == "acceleration":
                        tf = double_integrated(tf, x0, v0)
                float(tf.value(0.0))
            except ModelError:
                raise
            except Exception as exc:  # parse errors, bad callables
                raise ModelError(entity, kind, str(exc)) from None
        except ModelError:
            self._names.discard(name)
            raise
        m = Motion(name, jt, kind, tf, dof, None if kind == "displacement" else given, (x0, v0))
        self.motions[name] = m
        return m

    # ----------------------------------------------------------------- loads
    def add_force(self, name: str, at: Location, force: Load, frame: FrameRef = None) -> Force:
        """Force [N] at a point: `at` is a Marker or (body, point in ground at t=0 [m]).

        `force` is a constant 3-vector, three components each a number or an expression string of time
        and state (mbdsim.model.loadexpr: "-k*DZ(ball)", "STEP(TIME, 0, 0, 1, 10)"), or a callable
        (t, state) -> 3-vector, in ground axes when frame is None else in the axes of the given Body/Marker."""
        entity = f"force '{name}'"
        self._claim(name, "force")
        try:
            mk = self._location(entity, "at", at)
            val = _load_callable(entity, "force", force) if callable(force) else load_vector(self, entity, "force", force)
            self._check_frame(entity, frame)
        except ModelError:
            self._names.discard(name)
            raise
        f = (ExprForce if isinstance(val, ExprVector) else Force)(name, mk.body, mk.s_B, val, frame)
        self.forces[name] = f
        return f

    def add_torque(self, name: str, body: BodyRef, torque: Load, frame: FrameRef = None) -> Torque:
        """Pure torque [N m] on a body; constant 3-vector, components that are numbers or expression strings,
        or a callable (t, state); axes as add_force."""
        entity = f"torque '{name}'"
        self._claim(name, "torque")
        try:
            b = self._lookup(body, self.bodies, entity, "body")
            if b.is_particle:
                raise ModelError(entity, "body", f"{b.name!r} is a particle: it has no rotation for a torque to act on")
            val = _load_callable(entity, "torque", torque) if callable(torque) else load_vector(self, entity, "torque", torque)
            self._check_frame(entity, frame)
        except ModelError:
            self._names.discard(name)
            raise
        t = (ExprTorque if isinstance(val, ExprVector) else Torque)(name, b, val, frame)
        self.forces[name] = t
        return t

    def add_spring_damper(self, name: str, at_i: Location, at_j: Location, stiffness: float, damping: float = 0.0,
                          free_length: float | None = None, preload: float = 0.0) -> SpringDamper:
        """Translational spring-damper between two points (Marker or (body, point in ground at t=0)).

        stiffness [N/m], damping [N s/m], free_length [m] (None = initial distance), preload [N]:
        tension = stiffness (L - free_length) + damping dL/dt + preload, positive pulling together.

        The tension acts along the line between the points, which has no direction where they coincide:
        at zero length the element applies no force. Points that coincide at t=0 are therefore refused
        (ModelError naming at_j) unless free_length and preload are zero (a zero-length spring, whose
        force stiffness * (p_j - p_i) is continuous there)."""
        entity = f"spring '{name}'"
        self._claim(name, "spring")
        try:
            mi, mj = self._location(entity, "at_i", at_i), self._location(entity, "at_j", at_j)
            k = scalar(entity, "stiffness", stiffness, minimum=0.0)
            c = scalar(entity, "damping", damping, minimum=0.0)
            L0 = float(np.linalg.norm(mj.point - mi.point)) if free_length is None else \
                scalar(entity, "free_length", free_length, minimum=0.0)
            P = scalar(entity, "preload", preload)
            gap = float(np.linalg.norm(mj.point - mi.point))
            if gap <= 1e-12 * (1.0 + float(np.abs(mi.point).max())) and (L0 > 0.0 or P != 0.0):
                raise ModelError(entity, "at_j", f"the points coincide at t=0 (length {gap:.3g} m): the "
                                 f"direction of a tension of free_length {L0:g} m, preload {P:g} N is undefined")
            s = SpringDamper(name, mi, mj, k, c, L0, P)
        except ModelError:
            self._names.discard(name)
            raise
        self.forces[name] = s
        return s

    # ----------------------------------------------------------------- helpers
    def add_element(self, element: Any) -> Any:
        """Register a force element built elsewhere: a spec of mbdsim.model (Bushing, SpringDamper, ...) or
        an object with its own generalized(sys, frames, elem, t, state) method; it must have a unique
        `name`.  Anything else is refused here (ModelError naming the element), not at simulate."""
        from ..system.force_elements import EVALUATORS, friction, loads  # noqa: F401  (all registered)
        name = getattr(element, "name", None)
        what = type(element).__name__
        if not isinstance(name, str):
            raise ModelError(f"element {element!r:.60}", "name", f"a force element needs a string `name`; "
                             f"got a {what} without one")
        if not any(cls in EVALUATORS for cls in type(element).__mro__) and \
                not callable(getattr(element, "generalized", None)):
            raise ModelError(f"element '{name}'", "type", f"a {what} is not a force element (build elements "
                             "with the Model.add_* methods, or give the object a method "
                             "generalized(sys, frames, elem, t, state))")
        self._claim(name, what)
        self.forces[element.name] = element
        return element

    def _claim(self, name, what):
        """Reserve `name` for a new entity (ModelError naming it when taken or not a valid name, see
        loadexpr.check_name: bodies, particles and joints are read by expressions)."""
        from .loadexpr import check_name
        check_name(f"{what} {name!r}", name, what in ("body", "particle", "joint"))
        if what == "joint" and (name.endswith("_dot") and name[:-4] in self.joints or f"{name}_dot" in self.joints):
            raise ModelError(f"{what} {name!r}", "name", "expressions read a joint's rate as <joint>_dot: a joint "
                             f"{name!r} and a joint {name[:-4] if name.endswith('_dot') else name + '_dot'!r} "
                             "cannot both be in the model")
        if name in self._names:
            raise ModelError(f"{what} '{name}'", "name", "an entity of this name already exists in the model")
        self._names.add(name)

    def _lookup(self, item, table, entity, field):
        if isinstance(item, str):
            if item not in table:
                raise ModelError(entity, field, f"no {field} named {item!r} in the model")
            return table[item]
        name = getattr(item, "name", None)
        if not (isinstance(name, str) and table.get(name) is item) and not any(item is v for v in table.values()):
            raise ModelError(entity, field, f"{item!r} is not part of this model")   # (O(1) when it is)
        return item

    def _location(self, entity, field, at) -> Marker:
        if isinstance(at, Marker):
            self._lookup(at.body, self.bodies, entity, field)
            return at
        if isinstance(at, Body):   # a body alone means its centre of mass
            body = self._lookup(at, self.bodies, entity, field)
            return Marker(f"{entity}.{field}", body, body.position.copy(), np.eye(3))
        if isinstance(at, (tuple, list)) and len(at) == 2:
            body = self._lookup(at[0], self.bodies, entity, field)
            pt = vec3(entity, field, at[1])
            return Marker(f"{entity}.{field}", body, pt, np.eye(3))
        raise ModelError(entity, field, f"expected a Marker, a body (its centre of mass) or (body, point), "
                         f"got {at!r}")

    def _check_frame(self, entity, frame):
        if frame is None:
            return
        body = frame.body if isinstance(frame, Marker) else frame
        self._lookup(body, self.bodies, entity, "frame")

    def _joint(self, name, kind, body_i, body_j, point, axis, x0=None, v0=None) -> Joint:
        entity = f"joint '{name}'"
        self._claim(name, "joint")
        try:
            if isinstance(body_i, Marker) or isinstance(body_j, Marker):
                jt = self._marker_joint(entity, name, kind, body_i, body_j, point, axis)
            else:
                bi = self._lookup(body_i, self.bodies, entity, "body_i")
                bj = self._lookup(body_j, self.bodies, entity, "body_j")
                if bi is bj:
                    raise ModelError(entity, "body_j", "a joint needs two different bodies")
                for fld, val in (("point", point), ("axis", axis)):
                    if val is None:
                        raise ModelError(entity, fld, "is required (or give two markers instead of the bodies)")
                jt = Joint(name, kind, bi, bj, vec3(entity, "point", point), vec3(entity, "axis", axis, unit=True))
            jt.initial_displacement = joint_initial(entity, kind, "initial_displacement", x0)
            jt.initial_velocity = joint_initial(entity, kind, "initial_velocity", v0)
        except ModelError:
            self._names.discard(name)
            raise
        self.joints[name] = jt
        return jt

    def _marker_joint(self, entity, name, kind, mi, mj, point, axis) -> Joint:
        """A joint between two markers: I on body_i, J on body_j (point = I's origin, axis = I's z)."""
        for fld, m in (("body_i", mi), ("body_j", mj)):
            if not isinstance(m, Marker):
                raise ModelError(entity, fld, f"give two markers or two bodies, not a mix (got {m!r})")
            self._lookup(m.body, self.bodies, entity, fld)
        if mi.body is mj.body:
            raise ModelError(entity, "body_j", "the two markers are on the same body")
        if point is not None:
            raise ModelError(entity, "point", "omit it for a joint between two markers (their origins are used)")
        if axis is not None and axis is not _Z:
            raise ModelError(entity, "axis", "omit it for a joint between two markers (their z axes are used)")
        return Joint(name, kind, mi.body, mj.body, mi.point.copy(), mi.orientation[:, 2].copy(),
                     marker_i=mi, marker_j=mj)

    @staticmethod
    def _motion_dof(entity, joint, dof):
        from .joint_kinds import kinds_with_axis, pick_axis_dof
        return pick_axis_dof(entity, joint, dof, False,
                             lambda: f"cannot drive a {joint.kind} joint; use {', '.join(kinds_with_axis())}")

    def _repr_html_(self) -> str:  # Jupyter summary
        from ..viewer.notebook import model_html; return model_html(self)  # noqa: E702

    def __repr__(self) -> str:
        return (f"Model({self.name!r}: {len(self.bodies) - 1} bodies, {len(self.joints)} joints, "
                f"{len(self.motions)} motions, {len(self.forces)} forces)")


_Z = np.array([0.0, 0.0, 1.0])   # placeholder axis of joints without one (spherical, fixed)


def _universal_axis_j(j, axis_j) -> np.ndarray:
    """axis_j of a universal joint: perpendicular to axis_i within 1e-6 rad (then orthogonalised, noted)."""
    entity = f"joint '{j.name}'"
    if axis_j is None:
        raise ModelError(entity, "axis_j", "is required (or give two markers instead of the bodies)")
    aj = vec3(entity, "axis_j", axis_j, unit=True)
    dev = abs(float(np.arcsin(np.clip(j.axis @ aj, -1.0, 1.0))))
    if dev > 1e-6:
        raise ModelError(entity, "axis_j", f"must be perpendicular to axis_i at t=0; they are "
                         f"{np.degrees(dev):.6g} deg ({dev:.3g} rad) off (1e-6 rad is accepted)")
    if dev > 0.0:
        aj = aj - (aj @ j.axis) * j.axis
        aj = aj / np.linalg.norm(aj)
        j.notes.append(f"axis_j orthogonalised to axis_i (was {dev:.3g} rad off perpendicular)")
    return aj


def _default_u_axis(normal) -> np.ndarray:
    """In-plane u axis of a planar joint: ground x projected onto the plane (ground y when |n . x| > 0.9)."""
    e = np.eye(3)[1 if abs(normal[0]) > 0.9 else 0]
    u = e - (e @ normal) * normal
    return u / np.linalg.norm(u)


def _load_callable(entity, field, fn):
    """A load callable f(t, state) -> 3-vector, its signature checked now (values at run time)."""
    from ._check import check_load_callable
    check_load_callable(entity, field, fn)
    return fn
