"""Build an mbdsim Model from a validated model-file spec (mbdsim.io.schema) through the public API.

Every reference (body, joint, marker, frame) is checked here first, so that a misspelt name gives a
message listing the valid choices; the API's own checks (ModelError) are reported against the item
being built.  Values whose unit depends on the joint (motions, stops, friction preload) are converted
to SI here.  Expression strings go to the whitelist parser `mbdsim.parse`: nothing is evaluated as code.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..model.joint_kinds import JOINT_KINDS
from .build_shapes import add_shapes, contact_side
from .schema import AxisAngleSpec, EulerSpec, ModelSpec
from .units import UnitError, to_si

JOINT_METHODS = {n: k.method for n, k in JOINT_KINDS.items()}     # the joint-kind registry
JOINT_FIELDS = {n: k.fields for n, k in JOINT_KINDS.items()}
PER = {"displacement": "", "velocity": "/s", "acceleration": "/s**2"}


def element_word(kind: str) -> str:
    """How errors name an element of a kind ("spring_damper" -> "spring", as Model.add_spring_damper does)."""
    return {"spring_damper": "spring"}.get(kind, kind.replace("_", " "))


class ItemError(ModelError):
    """A ModelError attributed to the item at `path` in the model data (section, index[, field...])."""

    def __init__(self, entity, field, message, path):
        super().__init__(entity, field, message)
        self.path, self.message = tuple(path), message


def rotation_matrix(entity: str, field: str, spec) -> np.ndarray | None:
    """3x3 body->ground matrix from a matrix, {euler, sequence} or {axis, angle} spec (None stays None)."""
    from scipy.spatial.transform import Rotation
    if spec is None:
        return None
    if isinstance(spec, EulerSpec):
        try:
            return Rotation.from_euler(spec.sequence, spec.euler).as_matrix()
        except ValueError as exc:   # e.g. "ZZX": consecutive axes must differ
            raise ModelError(entity, field, f"Euler sequence {spec.sequence!r}: {exc}") from None
    if isinstance(spec, AxisAngleSpec):
        axis = np.asarray(spec.axis, dtype=float)
        n = np.linalg.norm(axis)
        if n < 1e-12:
            raise ModelError(entity, field, "axis-angle axis must be non-zero")
        return Rotation.from_rotvec(axis / n * spec.angle).as_matrix()
    return np.asarray(spec, dtype=float)


class Builder:
    """Turns a ModelSpec into a Model; `path` is the item being built (for error locations)."""

    def __init__(self, spec: ModelSpec, base_dir: str | None = None):
        import mbdsim as mb
        self.spec, self.mb, self.base_dir = spec, mb, base_dir   # base_dir: where relative mesh paths start
        self.model = mb.Model(spec.name, gravity=spec.gravity, planar=spec.planar)
        self.path: tuple = ()

    # ------------------------------------------------------------------ references
    def fail(self, entity, field, message):
        raise ItemError(entity, field, message, self.path + (field,))

    def fail_at(self, entity, field, message, path):
        raise ItemError(entity, field, message, path)

    def body(self, entity, field, name):
        bodies = self.model.bodies
        if name not in bodies:
            self.fail(entity, field, f"body {name!r} not found; bodies are: {', '.join(bodies)}")
        return bodies[name]

    def joint(self, entity, field, name):
        joints = self.model.joints
        if name not in joints:
            listed = ", ".join(joints) or "(none)"
            self.fail(entity, field, f"joint {name!r} not found; joints are: {listed}")
        return joints[name]

    def frame(self, entity, field, ref):
        """A Body ("body") or Marker ("body.marker") by name."""
        if ref is None:
            return None
        body_name, _, marker = ref.partition(".")
        b = self.body(entity, field, body_name)
        if not marker:
            return b
        if marker not in b.markers:
            listed = ", ".join(f"{body_name}.{m}" for m in b.markers) or "(none)"
            self.fail(entity, field, f"marker {ref!r} not found; markers of {body_name!r} are: {listed}")
        return b.markers[marker]

    def location(self, entity, field, loc):
        """'body.marker' -> Marker, 'body' -> Body (its CM), {body, point} -> (Body, point)."""
        if isinstance(loc, str):
            return self.frame(entity, field, loc)
        return self.body(entity, field, loc.body), loc.point

    def si(self, entity, field, value, unit):
        if value is None:
            return None
        try:
            return to_si(value, unit)
        except UnitError as exc:
            self.fail(entity, field, str(exc))

    # ------------------------------------------------------------------ items
    def build(self):
        s = self.spec
        self.path = ("ground",)
        self.add_markers(self.model.ground, s.ground.markers)
        add_shapes(self, self.model.ground, s.ground.shapes, ("ground",))
        for section, items, fn in (("tables", s.tables, self.add_table),
                                   ("inputs", s.inputs, lambda i: self.model.add_input(i.name, i.value)),
                                   ("bodies", s.bodies, self.add_body), ("particles", s.particles, self.add_particle),
                                   ("joints", s.joints, self.add_joint), ("motions", s.motions, self.add_motion),
                                   ("forces", s.forces, self.add_element),
                                   ("constraints", s.constraints, self.add_constraint),
                                   ("sensors", s.sensors, self.add_sensor),
                                   ("outputs", s.outputs, lambda o: self.model.add_output(o.name, o.expression))):
            for k, item in enumerate(items):
                self.path = (section, k)
                try:
                    fn(item)
                except ItemError:
                    raise
                except ModelError as exc:
                    msg = str(exc)[len(f"{exc.entity}.{exc.field}: "):]
                    raise ItemError(exc.entity, exc.field, msg, self.path + (exc.field.split("[")[0],)) from None
        return self.model

    def add_markers(self, body, markers):
        for k, m in enumerate(markers):
            entity = f"marker '{body.name}.{m.name}'"
            self.path = self.path[:2] + ("markers", k)
            body.add_marker(m.name, m.point, rotation_matrix(entity, "orientation", m.orientation))
        self.path = self.path[:2]

    def add_body(self, b):
        entity = f"body '{b.name}'"
        if b.inertia is not None:   # model files refuse impossible inertias (the API only warns)
            from ..model._check import inertia_matrix
            inertia_matrix(entity, b.inertia, strict=True)
        shape = None
        if b.shape is not None:
            mb = self.mb
            shape = {"box": lambda x: mb.Box(x.size), "cylinder": lambda x: mb.Cylinder(x.radius, x.length, x.axis),
                     "sphere": lambda x: mb.Sphere(None, x.radius)}[b.shape.type](b.shape)
        body = self.model.add_body(b.name, b.mass, b.inertia, b.position,
                                   rotation_matrix(entity, "orientation", b.orientation), b.velocity,
                                   b.angular_velocity, shape=shape, density=b.density)
        self.add_markers(body, b.markers)
        add_shapes(self, body, b.shapes, self.path[:2])

    def add_particle(self, p):
        body = self.model.add_particle(p.name, p.mass, p.position, p.velocity)
        self.add_markers(body, p.markers)
        add_shapes(self, body, p.shapes, self.path[:2])

    def add_joint(self, j):
        entity = f"joint '{j.name}'"
        if j.type == "point_on_curve":
            return self.add_point_on_curve(entity, j)
        # a body, or "body.marker" on both sides for a joint between two markers (as the API takes them)
        bi, bj = self.frame(entity, "body_i", j.body_i), self.frame(entity, "body_j", j.body_j)
        args = [getattr(j, f) for f in JOINT_FIELDS[j.type]]
        initial = {f: self.joint_values(entity, f, j.type, getattr(j, f), per)
                   for f, per in (("initial_displacement", ""), ("initial_velocity", "/s"))
                   if getattr(j, f, None) is not None}
        getattr(self.model, JOINT_METHODS[j.type])(j.name, bi, bj, *args, **initial)

    def joint_values(self, entity, field, kind, value, per):
        """Joint coordinates [rad or m, per `per`] from a number or a list (each may carry units); a
        wrong count is left to the API's message."""
        units = JOINT_KINDS[kind].units or ("",)
        if not isinstance(value, list):
            return self.si(entity, field, value, units[0] + per)
        return [self.si(entity, field, v, units[min(k, len(units) - 1)] + per) for k, v in enumerate(value)]

    def add_constraint(self, c):
        """Coupler, gear or user constraint (issue 11)."""
        if c.type == "user_constraint":
            return self.model.add_user_constraint(c.name, c.expression)
        if c.type == "gear":
            return self.model.add_gear(c.name, c.joint_1, c.joint_2, c.ratio)
        return self.model.add_coupler(c.name, c.joint_1, c.joint_2, c.ratio, c.dof_1, c.dof_2)

    def add_table(self, t):
        """An interpolated table (model.tables) that load expressions call by name (an Adams SPLINE)."""
        from ..importers.adm_spline import AdamsSpline
        entity = f"table '{t.name}'"
        if len(t.x) != len(t.y) or len(t.x) < 3:
            self.fail(entity, "y", f"needs as many y as x values, at least 3 (got {len(t.x)} x, {len(t.y)} y)")
        if any(b <= a for a, b in zip(t.x, t.x[1:])):
            self.fail(entity, "x", "values must be strictly increasing")
        tables = self.model.__dict__.setdefault("tables", {})
        if t.name in tables:
            self.fail(entity, "name", "a second table of this name")
        tables[t.name] = AdamsSpline(t.x, t.y, t.kind, t.linear_extrapolate)

    def add_sensor(self, s):
        self.model.add_sensor(s.name, s.signal, s.value, s.direction, s.action)

    def add_point_on_curve(self, entity, j):
        mb, c = self.mb, j.curve
        if c.type == "spline":
            curve = mb.Spline(c.points, closed=c.closed)
        else:
            try:   # three expression strings of s: exact symbolic derivatives (model.curves)
                curve = mb.Curve((str(c.x), str(c.y), str(c.z)), c.s_range, closed=c.closed)
            except ModelError as exc:
                self.fail(entity, "curve", str(exc))
        self.model.add_point_on_curve(j.name, self.location(entity, "marker", j.marker),
                                      self.body(entity, "body", j.body), curve)

    def coordinate_unit(self, entity, joint, dof):
        """'rad' or 'm' for the driven/stopped coordinate of `joint` (API errors for other kinds)."""
        if joint.kind == "translational" or (joint.kind == "cylindrical" and dof == "translation"):
            return "m"
        return "rad"

    def motion_value(self, entity, field, value, unit):
        if value is None or not isinstance(value, str):
            return value
        from ..expressions import ExpressionError, parse
        try:
            parse(value, ("t",) + tuple(getattr(self.model, "inputs", {})))   # t and the model's inputs
            return value
        except ExpressionError as exc:
            try:
                return to_si(value, unit)   # a constant with units, e.g. "60 deg/s"
            except UnitError:
                self.fail(entity, field, str(exc))

    def add_motion(self, m):
        entity = f"motion '{m.name}'"
        jt = self.joint(entity, "joint", m.joint)
        unit = self.coordinate_unit(entity, jt, m.dof)
        values = {k: self.motion_value(entity, k, getattr(m, k), unit + PER[k])
                  for k in ("displacement", "velocity", "acceleration")}
        self.model.add_motion(m.name, jt, **values,
                              initial_displacement=self.si(entity, "initial_displacement", m.initial_displacement, unit),
                              initial_velocity=self.si(entity, "initial_velocity", m.initial_velocity, unit + "/s"),
                              dof=m.dof)

    def add_element(self, e):
        entity = f"{element_word(e.type)} '{e.name}'"
        getattr(self, "add_" + e.type)(entity, e)

    def load_value(self, value, unit):
        """A load component: a number, a constant with units ("3 kN") or else an expression string (parsed,
        never run, by the model's add_* method, which names the entity and field when it does not parse)."""
        if not isinstance(value, str):
            return float(value)
        try:
            return to_si(value, unit)
        except UnitError:
            return value

    def add_force(self, entity, e):
        self.model.add_force(e.name, self.location(entity, "at", e.at), [self.load_value(c, "N") for c in e.force],
                             self.frame(entity, "frame", e.frame))

    def add_torque(self, entity, e):
        self.model.add_torque(e.name, self.body(entity, "body", e.body), [self.load_value(c, "N*m") for c in e.torque],
                              self.frame(entity, "frame", e.frame))

    def add_line_force(self, entity, e):
        self.model.add_line_force(e.name, self.location(entity, "at_i", e.at_i), self.location(entity, "at_j", e.at_j),
                                  self.load_value(e.magnitude, "N"))

    def add_joint_force(self, entity, e):
        jt = self.joint(entity, "joint", e.joint)
        unit = "N*m" if self.coordinate_unit(entity, jt, e.dof or ("rotation" if jt.kind != "translational"
                                                                     else "translation")) == "rad" else "N"
        self.model.add_joint_force(e.name, jt, self.load_value(e.value, unit), e.dof)

    def add_spring_damper(self, entity, e):
        self.model.add_spring_damper(e.name, self.location(entity, "at_i", e.at_i), self.location(entity, "at_j", e.at_j),
                                     e.stiffness, e.damping, e.free_length, e.preload)

    def add_torsion_spring(self, entity, e):
        self.model.add_torsion_spring(e.name, self.joint(entity, "joint", e.joint), e.stiffness, e.damping,
                                      e.free_angle, e.preload)

    def six(self, entity, field, values, units):
        return [self.si(entity, field, v, u) for v, u in zip(values, units)]

    def add_bushing(self, entity, e):
        k = self.six(entity, "stiffness", e.stiffness, ["N/m"] * 3 + ["N*m/rad"] * 3)
        c = self.six(entity, "damping", e.damping, ["N*s/m"] * 3 + ["N*m*s/rad"] * 3)
        f0 = self.six(entity, "preload", e.preload, ["N"] * 3 + ["N*m"] * 3)
        self.model.add_bushing(e.name, self.location(entity, "marker_i", e.marker_i),
                               self.location(entity, "marker_j", e.marker_j), k, c, f0)

    def contact_shape(self, entity, field, s):
        body = self.body(entity, field, s.body)
        if s.type == "sphere":
            return self.mb.Sphere(body, s.radius, s.center)
        return self.mb.Plane(body, s.point, s.normal)

    def add_contact(self, entity, e):
        k = self.si(entity, "stiffness", e.stiffness, f"N/m**{e.exponent!r}")
        self.model.add_contact(e.name, contact_side(self, entity, "shape_i", e.shape_i),
                               contact_side(self, entity, "shape_j", e.shape_j), k, e.exponent, e.damping,
                               e.penetration, e.mu, e.friction_velocity, restitution=e.restitution,
                               mu_static=e.mu_static, mu_dynamic=e.mu_dynamic,
                               stiction_velocity=e.stiction_velocity, transition_velocity=e.transition_velocity)

    def add_stop(self, entity, e):
        jt = self.joint(entity, "joint", e.joint)
        u = self.coordinate_unit(entity, jt, e.dof)
        load = "N*m" if u == "rad" else "N"
        self.model.add_stop(e.name, jt, self.si(entity, "lower", e.lower, u), self.si(entity, "upper", e.upper, u),
                            self.si(entity, "stiffness", e.stiffness, f"{load}/{u}**{e.exponent!r}"), e.exponent,
                            self.si(entity, "damping", e.damping, f"{load}*s/{u}"),
                            self.si(entity, "penetration", e.penetration, u), dof=e.dof)

    def add_friction(self, entity, e):
        jt = self.joint(entity, "joint", e.joint)
        params = {k: getattr(e, k) for k in ("pin_radius", "friction_arm", "bending_arm", "effective_length",
                                             "reaction_arm") if getattr(e, k) is not None}
        if e.preload is not None:
            params["preload"] = self.si(entity, "preload", e.preload, "N*m" if jt.kind == "revolute" else "N")
        self.model.add_friction(e.name, jt, e.mu_static, e.mu_dynamic, **params)
