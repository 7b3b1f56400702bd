"""The Model container: named bodies, joints, motions and loads, validated as they are added."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ModelError
from ._check import scalar, vec3
from .body import Body, Marker, make_body, shape_mass_properties
from .forces import Force, SpringDamper, Torque
from .elements import ForceElementsMixin
from .friction_path import FrictionPathMixin
from .joints import Joint, Motion


class Model(ForceElementsMixin, FrictionPathMixin):
    """A mechanism description in SI units; `gravity` [m/s^2] in ground axes."""

    def __init__(self, name: str = "model", gravity=(0.0, 0.0, 0.0)):
        self.name = str(name)
        self.gravity = vec3(f"model '{name}'", "gravity", gravity)
        self.ground = Body("ground", is_ground=True)
        self.bodies: dict[str, Body] = {"ground": self.ground}
        self.joints: dict[str, Joint] = {}
        self.motions: dict[str, Motion] = {}
        self.forces: dict[str, Any] = {}
        self._names: set[str] = {"ground"}

    # ----------------------------------------------------------------- bodies
    def add_body(self, name, mass=None, inertia=None, position=(0, 0, 0), orientation=None,
                 velocity=(0, 0, 0), angular_velocity=(0, 0, 0), shape=None, density=None) -> Body:
        """Add a rigid body: mass [kg], inertia about the CM in body axes [kg m^2] (3 values or 3x3, default 0),
        CM position [m], orientation (body->ground), CM velocity [m/s] and angular velocity [rad/s] in ground.

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

    def add_particle(self, name, mass, position=(0, 0, 0), velocity=(0, 0, 0)) -> Body:
        """Add a point mass [kg] at position [m] with velocity [m/s], both in ground; it has no rotation."""
        self._claim(name, "particle")
        try:
            b = make_body(name, mass, None, position, None, velocity, None, particle=True)
        except ModelError:
            self._names.discard(name)
            raise
        self.bodies[name] = b
        return b

    # ----------------------------------------------------------------- joints
    def add_revolute(self, name, body_i, body_j, point, axis) -> Joint:
        """Revolute joint at `point` [m] about `axis`, both in ground at t=0."""
        return self._joint(name, "revolute", body_i, body_j, point, axis)

    def add_translational(self, name, body_i, body_j, point, axis) -> Joint:
        """Translational (prismatic) joint sliding along `axis` through `point` (ground, t=0)."""
        return self._joint(name, "translational", body_i, body_j, point, axis)

    def add_cylindrical(self, name, body_i, body_j, point, axis) -> Joint:
        """Cylindrical joint: rotation about and sliding along `axis` through `point` (ground, t=0).

        Its coordinates are (angle [rad], slide [m]); every call that takes `dof=` on it (add_motion,
        add_stop, ...) picks "rotation" or "translation" and defaults to "rotation"."""
        return self._joint(name, "cylindrical", body_i, body_j, point, axis)

    def add_spherical(self, name, body_i, body_j, point) -> Joint:
        """Spherical (ball) joint at `point` [m] in ground at t=0."""
        return self._joint(name, "spherical", body_i, body_j, point, (0.0, 0.0, 1.0))

    def add_universal(self, name, body_i, body_j, point, axis_i, axis_j) -> Joint:
        """Universal joint at `point`; `axis_i` fixed on body_i, `axis_j` on body_j, perpendicular at t=0."""
        j = self._joint(name, "universal", body_i, body_j, point, axis_i)
        j.axis_j = vec3(f"joint '{name}'", "axis_j", axis_j, unit=True)
        if abs(float(j.axis @ j.axis_j)) > 1e-9:
            del self.joints[name]
            self._names.discard(name)
            raise ModelError(f"joint '{name}'", "axis_j", "must be perpendicular to axis_i at t=0")
        return j

    def add_planar(self, name, body_i, body_j, point, normal, u_axis=None) -> Joint:
        """Planar joint: body_j moves in the plane through `point` with `normal` fixed on body_i.

        Its coordinates (Result.joint_coordinate) are [u, v, angle]: the joint point of body_j along the
        in-plane axes u and v = normal x u [m] and the rotation about the normal [rad], all fixed on
        body_i and zero as built.  `u_axis` (ground, t=0) must be perpendicular to the normal; the
        default is the ground x axis projected onto the plane, or the ground y axis projected when the
        normal is within about 26 deg of x (|normal . x| > 0.9): normal +z gives u = +x, v = +y."""
        j = self._joint(name, "planar", body_i, body_j, point, normal)
        try:
            u = None if u_axis is None else vec3(f"joint '{name}'", "u_axis", u_axis, unit=True)
            if u is not None and abs(float(u @ j.axis)) > 1e-9:
                raise ModelError(f"joint '{name}'", "u_axis", "must be perpendicular to the normal")
        except ModelError:
            del self.joints[name]
            self._names.discard(name)
            raise
        j.u_axis = _default_u_axis(j.axis) if u is None else u
        return j

    def add_fixed(self, name, body_i, body_j, point=None) -> Joint:
        """Fixed joint welding body_j to body_i (at `point`, default body_j's CM)."""
        bj = self.bodies.get(body_j) if isinstance(body_j, str) else body_j   # a body may be given by name
        point = bj.position if point is None and isinstance(bj, Body) else point
        return self._joint(name, "fixed", body_i, body_j, point, (0.0, 0.0, 1.0))

    # ----------------------------------------------------------------- drivers
    def add_motion(self, name, joint, displacement=None, velocity=None, acceleration=None,
                   initial_displacement=0.0, initial_velocity=0.0, dof=None) -> Motion:
        """Drive a joint coordinate [rad or m] as a function of time t [s].

        Give exactly one of displacement, velocity (with initial_displacement) or acceleration (with
        initial_displacement and initial_velocity): a callable of t, a number or an expression string
        in t (safe whitelist parser, never eval'd).  `dof` picks "rotation" (the default) or "translation"
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
            try:
                tf = time_function(f)
                x0 = scalar(entity, "initial_displacement", initial_displacement)
                v0 = scalar(entity, "initial_velocity", initial_velocity)
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
        m = Motion(name, jt, kind, tf, dof)
        self.motions[name] = m
        return m

    # ----------------------------------------------------------------- loads
    def add_force(self, name, at, force, frame=None) -> Force:
        """Force [N] at a point: `at` is a Marker or (body, point in ground at t=0 [m]).

        `force` is a constant 3-vector or a callable (t, state) -> 3-vector, in ground axes when
        frame is None else in the axes of the given Body/Marker."""
        entity = f"force '{name}'"
        self._claim(name, "force")
        try:
            mk = self._location(entity, "at", at)
            val = force if callable(force) else vec3(entity, "force", force)
            self._check_frame(entity, frame)
        except ModelError:
            self._names.discard(name)
            raise
        f = Force(name, mk.body, mk.s_B, val, frame)
        self.forces[name] = f
        return f

    def add_torque(self, name, body, torque, frame=None) -> Torque:
        """Pure torque [N m] on a body; constant 3-vector or callable (t, state); axes as add_force."""
        entity = f"torque '{name}'"
        self._claim(name, "torque")
        try:
            b = self._lookup(body, self.bodies, entity, "body")
            if b.is_particle:
                raise ModelError(entity, "body", f"{b.name!r} is a particle: it has no rotation for a torque to act on")
            val = torque if callable(torque) else vec3(entity, "torque", torque)
            self._check_frame(entity, frame)
        except ModelError:
            self._names.discard(name)
            raise
        t = Torque(name, b, val, frame)
        self.forces[name] = t
        return t

    def add_spring_damper(self, name, at_i, at_j, stiffness, damping=0.0, free_length=None,
                          preload=0.0) -> SpringDamper:
        """Translational spring-damper between two points (Marker or (body, point in ground at t=0)).

        stiffness [N/m], damping [N s/m], free_length [m] (None = initial distance), preload [N]:
        tension = stiffness (L - free_length) + damping dL/dt + preload, positive pulling together."""
        entity = f"spring '{name}'"
        self._claim(name, "spring")
        try:
            mi, mj = self._location(entity, "at_i", at_i), self._location(entity, "at_j", at_j)
            k = scalar(entity, "stiffness", stiffness, minimum=0.0)
            c = scalar(entity, "damping", damping, minimum=0.0)
            L0 = float(np.linalg.norm(mj.point - mi.point)) if free_length is None else \
                scalar(entity, "free_length", free_length, minimum=0.0)
            s = SpringDamper(name, mi, mj, k, c, L0, scalar(entity, "preload", preload))
        except ModelError:
            self._names.discard(name)
            raise
        self.forces[name] = s
        return s

    # ----------------------------------------------------------------- helpers
    def add_element(self, element) -> Any:
        """Register a force element built elsewhere (must have a unique `name`)."""
        self._claim(element.name, type(element).__name__)
        self.forces[element.name] = element
        return element

    def _claim(self, name, what):
        if not isinstance(name, str) or not name:
            raise ModelError(f"{what} {name!r}", "name", "must be a non-empty string")
        if name in self._names:
            raise ModelError(f"{what} '{name}'", "name", "an entity of this name already exists in the model")
        self._names.add(name)

    def _lookup(self, item, table, entity, field):
        if isinstance(item, str):
            if item not in table:
                raise ModelError(entity, field, f"no {field} named {item!r} in the model")
            return table[item]
        if not any(item is v for v in table.values()):
            raise ModelError(entity, field, f"{item!r} is not part of this model")
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

    def _joint(self, name, kind, body_i, body_j, point, axis) -> Joint:
        entity = f"joint '{name}'"
        self._claim(name, "joint")
        try:
            bi = self._lookup(body_i, self.bodies, entity, "body_i")
            bj = self._lookup(body_j, self.bodies, entity, "body_j")
            if bi is bj:
                raise ModelError(entity, "body_j", "a joint needs two different bodies")
            jt = Joint(name, kind, bi, bj, vec3(entity, "point", point), vec3(entity, "axis", axis, unit=True))
        except ModelError:
            self._names.discard(name)
            raise
        self.joints[name] = jt
        return jt

    @staticmethod
    def _motion_dof(entity, joint, dof):
        allowed = {"revolute": ("rotation",), "translational": ("translation",),
                   "cylindrical": ("rotation", "translation")}
        if joint.kind not in allowed:
            raise ModelError(entity, "joint", f"cannot drive a {joint.kind} joint; use revolute, "
                             "translational or cylindrical")
        if dof is None:
            return allowed[joint.kind][0]
        if dof not in allowed[joint.kind]:
            raise ModelError(entity, "dof", f"{dof!r} is not a coordinate of {joint.kind} joint {joint.name!r}")
        return dof

    def _repr_html_(self) -> str:  # Jupyter summary
        from ..viewer.notebook import model_html; return model_html(self)  # noqa: E702

    def __repr__(self) -> str:
        return (f"Model({self.name!r}: {len(self.bodies) - 1} bodies, {len(self.joints)} joints, "
                f"{len(self.motions)} motions, {len(self.forces)} forces)")


def _default_u_axis(normal) -> np.ndarray:
    """In-plane u axis of a planar joint: ground x projected onto the plane (ground y when |n . x| > 0.9)."""
    e = np.eye(3)[1 if abs(normal[0]) > 0.9 else 0]
    u = e - (e @ normal) * normal
    return u / np.linalg.norm(u)
