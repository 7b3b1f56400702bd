"""The model-file schema (pydantic v2, unknown keys forbidden): one schema for YAML and JSON files.

It mirrors the Python API field by field (``Model.add_*``).  Quantities are a number in SI units or a
string with units ("500 mm", "60 deg/s", "3 kN/m"), converted to SI here with the field's dimension
checked.  Points and axes are in ground at t = 0, as in the API.  Fields whose unit depends on the
joint (a stop's limits, a motion's values, friction preload) stay raw here and are converted by
mbdsim.io.build once the joint is known.  Expressions are strings for ``mbdsim.parse`` (whitelist,
never evaluated as code).
"""
from __future__ import annotations

from typing import Annotated, Literal, Optional, Union

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, WithJsonSchema

from .units import dimension_name, to_si


class Spec(BaseModel):
    """Base of every schema class: unknown keys are errors."""

    model_config = ConfigDict(extra="forbid")


class UnitMark(str):
    """Metadata on a quantity field: its SI unit ("m", "N*m/rad"; "" for a pure number)."""


def _quantity_validator(unit: str):
    def convert(value):
        return to_si(value, unit)
    return convert


def Q(unit: str):  # noqa: N802 - a type factory
    """A float field in SI `unit`, given as a number (SI) or a string with units."""
    return Annotated[float, BeforeValidator(_quantity_validator(unit)), WithJsonSchema(
        {"anyOf": [{"type": "number"}, {"type": "string"}],
         "description": f"{dimension_name(unit)}: a number in SI units or a string with units"}), UnitMark(unit)]


def V(unit: str, n: int = 3):  # noqa: N802
    """n quantities in SI `unit` (each a number or a string with units)."""
    return Annotated[list[Q(unit)], Field(min_length=n, max_length=n)]


def _raw(value):
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise ValueError(f"expected a number or a string, got {value!r}")
    return value


# a number or string whose unit depends on the joint (converted by mbdsim.io.build)
Raw = Annotated[Union[float, str], BeforeValidator(_raw)]
Name = Annotated[str, Field(min_length=1)]
Length, Mass, Angle, Force_, Torque_ = Q("m"), Q("kg"), Q("rad"), Q("N"), Q("N*m")
Number = Q("")
Matrix3 = Annotated[list[Annotated[list[Number], Field(min_length=3, max_length=3)]],
                    Field(min_length=3, max_length=3)]


# ----------------------------------------------------------------------------- orientation, shapes
class EulerSpec(Spec):
    """Euler angles [rad or with units] in a scipy sequence: "ZXZ" intrinsic (upper case), "zxz" extrinsic."""

    euler: V("rad")
    sequence: Annotated[str, Field(pattern=r"^([XYZ]{3}|[xyz]{3})$")] = "ZXZ"


class AxisAngleSpec(Spec):
    """Rotation by `angle` about `axis` (ground)."""

    axis: V("")
    angle: Angle


Orientation = Union[Matrix3, EulerSpec, AxisAngleSpec]


class BoxSpec(Spec):
    type: Literal["box"]
    size: V("m")


Axis = Union[Literal["x", "y", "z"], V("")]   # a geometry's axis: "x", "y", "z" or a vector in its own axes


class CylinderSpec(Spec):
    type: Literal["cylinder"]
    radius: Length
    length: Length
    axis: Axis = "z"


class SphereShapeSpec(Spec):
    type: Literal["sphere"]
    radius: Length


MassShape = Annotated[Union[BoxSpec, CylinderSpec, SphereShapeSpec], Field(discriminator="type")]


class CapsuleSpec(Spec):
    """Points within `radius` of a segment of `length` (between the cap centres) along `axis`."""

    type: Literal["capsule"]
    radius: Length
    length: Length
    axis: Axis = "z"


class EllipsoidSpec(Spec):
    type: Literal["ellipsoid"]
    radii: V("m")


Points = Annotated[list[V("m")], Field(min_length=4)]


class ConvexMeshSpec(Spec):
    """The convex hull of `vertices` [m] (the geometry's axes)."""

    type: Literal["convex_mesh"]
    vertices: Points


class MeshSpec(Spec):
    """A triangle mesh: a file (STL, OBJ, PLY; a path relative to the model file's folder, or absolute)
    whose coordinates times `scale` are metres, or `vertices` [m] with `faces` (vertex index triples)."""

    type: Literal["mesh"]
    path: Optional[Name] = None
    scale: Number = 1.0
    vertices: Optional[Points] = None
    faces: Optional[Annotated[list[Annotated[list[int], Field(min_length=3, max_length=3)]],
                              Field(min_length=1)]] = None


Geometry = Annotated[Union[BoxSpec, CylinderSpec, CapsuleSpec, EllipsoidSpec, SphereShapeSpec, ConvexMeshSpec,
                           MeshSpec], Field(discriminator="type")]


class ShapeSpec(Spec):
    """A geometry placed on the body (Body.add_shape): for contact, the viewer and, with `density`, mass
    properties (added to the body's `mass` and `inertia`).  `center` [m] and `orientation` (geometry ->
    ground) in ground at t = 0; defaults the body's centre of mass and axes."""

    name: Name
    geometry: Geometry
    center: Optional[V("m")] = None
    orientation: Optional[Orientation] = None
    density: Optional[Q("kg/m**3")] = None


class LocationSpec(Spec):
    """A point fixed on `body`, given in ground at t = 0 [m]."""

    body: Name
    point: V("m")


# "body.marker", "body" (its centre of mass) or {body, point}
Location = Union[str, LocationSpec]


# ----------------------------------------------------------------------------- bodies
class MarkerSpec(Spec):
    name: Name
    point: Optional[V("m")] = None
    orientation: Optional[Orientation] = None


class BodySpec(Spec):
    """A rigid body: mass and inertia, or a shape and a density (mass properties from geometry)."""

    name: Name
    mass: Optional[Mass] = None
    inertia: Optional[Union[V("kg*m**2"), Annotated[list[V("kg*m**2")], Field(min_length=3, max_length=3)]]] = None
    shape: Optional[MassShape] = None
    density: Optional[Q("kg/m**3")] = None
    position: V("m") = [0.0, 0.0, 0.0]
    orientation: Optional[Orientation] = None
    velocity: Optional[V("m/s")] = None            # None: free, solved at assembly (as in the API)
    angular_velocity: Optional[V("rad/s")] = None
    markers: list[MarkerSpec] = []
    shapes: list[ShapeSpec] = []


class GroundSpec(Spec):
    """The ground body, fixed: its markers (`model.ground.add_marker` in the API), named "ground.<name>", and
    its shapes (without density), named "ground.<name>" in contacts."""

    markers: list[MarkerSpec] = []
    shapes: list[ShapeSpec] = []


class ParticleSpec(Spec):
    name: Name
    mass: Mass
    position: V("m") = [0.0, 0.0, 0.0]
    velocity: Optional[V("m/s")] = None
    markers: list[MarkerSpec] = []
    shapes: list[ShapeSpec] = []     # spheres only (a particle has no orientation)


# ----------------------------------------------------------------------------- joints
class JointPair(Spec):
    """A joint between two bodies (names; point and axes in ground at t = 0) or between two markers
    ("body.marker" as body_i and body_j: the joint's I and J frames, then point and axes are omitted)."""

    name: Name
    body_i: Name
    body_j: Name


# a joint coordinate's start value or rate: a number for a one-coordinate joint, else a list in the order of
# Result.joint_coordinate; units [rad or m (per s)] by coordinate, converted by mbdsim.io.build
JointValues = Optional[Union[Raw, Annotated[list[Raw], Field(min_length=1, max_length=3)]]]


class Initial(Spec):
    """initial_displacement [rad or m, from as drawn] and initial_velocity [rad/s or m/s] of the joint
    coordinates, held at assembly (as the joint methods of the API)."""

    initial_displacement: JointValues = None
    initial_velocity: JointValues = None


class AxisJointSpec(JointPair, Initial):
    type: Literal["revolute", "translational", "cylindrical"]
    point: Optional[V("m")] = None
    axis: Optional[V("")] = None


class InlineSpec(JointPair):
    type: Literal["inline"]
    point: Optional[V("m")] = None
    axis: Optional[V("")] = None


class SphericalSpec(JointPair, Initial):
    type: Literal["spherical"]
    point: Optional[V("m")] = None


class AtPointSpec(JointPair):
    type: Literal["atpoint"]
    point: Optional[V("m")] = None


class UniversalSpec(JointPair, Initial):
    type: Literal["universal"]
    point: Optional[V("m")] = None
    axis_i: Optional[V("")] = None
    axis_j: Optional[V("")] = None


class PlanarSpec(JointPair, Initial):
    type: Literal["planar"]
    point: Optional[V("m")] = None
    normal: Optional[V("")] = None
    u_axis: Optional[V("")] = None


class FixedSpec(JointPair):
    type: Literal["fixed"]
    point: Optional[V("m")] = None


class SplineSpec(Spec):
    """C2 cubic spline through points [m] (ground, t = 0)."""

    type: Literal["spline"]
    points: Annotated[list[V("m")], Field(min_length=3)]
    closed: bool = False


class ParametricCurveSpec(Spec):
    """C(s) = (x(s), y(s), z(s)) [m]: expression strings of the parameter s (whitelist parser)."""

    type: Literal["curve"]
    x: Union[str, float]
    y: Union[str, float]
    z: Union[str, float]
    s_range: Annotated[list[Number], Field(min_length=2, max_length=2)]
    closed: bool = False


CurveSpec = Annotated[Union[SplineSpec, ParametricCurveSpec], Field(discriminator="type")]


class PointOnCurveSpec(Spec):
    """The origin of `marker` stays on `curve`, fixed on `body`."""

    type: Literal["point_on_curve"]
    name: Name
    marker: Location
    body: Name
    curve: CurveSpec


from .schema_extra import (EXTRA_JOINTS, ConstraintSpec, InputSpec, JointForceSpec, LineForceSpec,  # noqa: E402
                           OutputSpec, SensorSpec, TableSpec)

JointSpec = Annotated[Union[(AxisJointSpec, InlineSpec, SphericalSpec, AtPointSpec, UniversalSpec, PlanarSpec,
                             FixedSpec, PointOnCurveSpec,
                             *EXTRA_JOINTS)], Field(discriminator="type")]


# ----------------------------------------------------------------------------- motions
class MotionSpec(Spec):
    """Exactly one of displacement / velocity / acceleration: a number [rad or m (per s, s^2)] or an
    expression string in t [s], e.g. "pi/6*(1-cos(pi*t/2))"; a constant may carry units ("60 deg/s").
    The expression may read the model's inputs by name ("w_cmd"): a Simulator holds them over each step
    (a velocity or acceleration driver stays continuous when they change, a displacement driver jumps)."""

    name: Name
    joint: Name
    displacement: Optional[Raw] = None
    velocity: Optional[Raw] = None
    acceleration: Optional[Raw] = None
    initial_displacement: Raw = 0.0
    initial_velocity: Raw = 0.0
    dof: Optional[Literal["rotation", "translation"]] = None


# ----------------------------------------------------------------------------- loads and elements
# a load component: a number [SI], a constant with units ("3 kN") or an expression string of time and state
# ("-k*DZ(ball)", mbdsim.model.loadexpr), told apart by mbdsim.io.build
LoadVector = Annotated[list[Raw], Field(min_length=3, max_length=3)]


class ForceSpec(Spec):
    """Force [N] at a point, each component a number, a constant with units or an expression of time and
    state; in ground axes, or in the axes of `frame` ("body" or "body.marker")."""

    type: Literal["force"]
    name: Name
    at: Location
    force: LoadVector
    frame: Optional[str] = None


class TorqueSpec(Spec):
    """Torque [N m] on a body, components as ForceSpec."""

    type: Literal["torque"]
    name: Name
    body: Name
    torque: LoadVector
    frame: Optional[str] = None


class SpringDamperSpec(Spec):
    type: Literal["spring_damper"]
    name: Name
    at_i: Location
    at_j: Location
    stiffness: Q("N/m")
    damping: Q("N*s/m") = 0.0
    free_length: Optional[Length] = None
    preload: Force_ = 0.0


class TorsionSpringSpec(Spec):
    type: Literal["torsion_spring"]
    name: Name
    joint: Name
    stiffness: Q("N*m/rad")
    damping: Q("N*m*s/rad") = 0.0
    free_angle: Angle = 0.0
    preload: Torque_ = 0.0


class BushingSpec(Spec):
    """stiffness (kx, ky, kz [N/m], ktx, kty, ktz [N m/rad]), damping and preload likewise, marker_i axes."""

    type: Literal["bushing"]
    name: Name
    marker_i: Location
    marker_j: Location
    stiffness: Annotated[list[Raw], Field(min_length=6, max_length=6)] = [0.0] * 6
    damping: Annotated[list[Raw], Field(min_length=6, max_length=6)] = [0.0] * 6
    preload: Annotated[list[Raw], Field(min_length=6, max_length=6)] = [0.0] * 6


class ContactSphereSpec(Spec):
    type: Literal["sphere"]
    body: Name
    radius: Length
    center: Optional[V("m")] = None


class ContactPlaneSpec(Spec):
    type: Literal["plane"]
    body: Name
    point: V("m")
    normal: V("")


ContactShape = Annotated[Union[ContactSphereSpec, ContactPlaneSpec], Field(discriminator="type")]
# a body's shape by "body.shape" (BodySpec.shapes), or an inline sphere / plane
ShapeRef = Union[Name, ContactShape]
ShapeSide = Union[ShapeRef, Annotated[list[ShapeRef], Field(min_length=1)]]


class ContactSpec(Spec):
    """Contact between shapes (one or a list on each side: every pair between the lists): the Adams IMPACT
    law, stiffness [N/m^exponent] (a number in SI, or with units), damping [N s/m] reached at `penetration`
    [m], or POISSON with `restitution` (0..1).  Friction: `mu` regularised below `friction_velocity`, or
    Adams' `mu_static`, `mu_dynamic`, `stiction_velocity` and `transition_velocity`."""

    type: Literal["contact"]
    name: Name
    shape_i: ShapeSide
    shape_j: ShapeSide
    stiffness: Raw
    exponent: Number
    damping: Q("N*s/m")
    penetration: Length
    mu: Number = 0.0
    friction_velocity: Q("m/s") = 1e-3
    restitution: Optional[Number] = None
    mu_static: Optional[Number] = None
    mu_dynamic: Optional[Number] = None
    stiction_velocity: Optional[Q("m/s")] = None
    transition_velocity: Optional[Q("m/s")] = None


class StopSpec(Spec):
    """Joint stop: limits [m or rad], stiffness [N/m^e or N m/rad^e], damping, penetration by the joint's dof."""

    type: Literal["stop"]
    name: Name
    joint: Name
    lower: Optional[Raw] = None
    upper: Optional[Raw] = None
    stiffness: Raw
    exponent: Number = 1.5
    damping: Raw = 0.0
    penetration: Raw = 1e-3
    dof: Optional[Literal["rotation", "translation"]] = None


class FrictionSpec(Spec):
    """Coulomb joint friction; preload [N] on a translational joint, [N m] on a revolute joint."""

    type: Literal["friction"]
    name: Name
    joint: Name
    mu_static: Number
    mu_dynamic: Number
    preload: Optional[Raw] = None
    pin_radius: Optional[Length] = None
    friction_arm: Optional[Length] = None
    bending_arm: Optional[Length] = None
    effective_length: Optional[Length] = None
    reaction_arm: Optional[Length] = None


ElementSpec = Annotated[Union[ForceSpec, TorqueSpec, SpringDamperSpec, TorsionSpringSpec, BushingSpec, ContactSpec,
                              StopSpec, FrictionSpec, LineForceSpec, JointForceSpec], Field(discriminator="type")]


class ModelSpec(Spec):
    """An mbdsim model file: SI units unless a value is a string with units; ground axes at t = 0."""

    name: str = "model"
    gravity: V("m/s**2") = [0.0, 0.0, 0.0]
    planar: Union[bool, V("")] = False     # True: a 2D mechanism in the xy plane (or its plane normal)
    ground: GroundSpec = GroundSpec()
    tables: list[TableSpec] = []       # interpolated tables that load expressions call (Adams SPLINE)
    inputs: list[InputSpec] = []       # scalars that expressions read by name (a Simulator sets them)
    bodies: list[BodySpec] = []
    particles: list[ParticleSpec] = []
    joints: list[JointSpec] = []
    motions: list[MotionSpec] = []
    forces: list[ElementSpec] = []
    constraints: list[ConstraintSpec] = []   # couplers, gears, user constraints
    sensors: list[SensorSpec] = []
    outputs: list[OutputSpec] = []     # measured signals (expressions of the state)


SECTIONS = {"tables": "table",
            "bodies": "body", "particles": "particle", "joints": "joint", "motions": "motion", "forces": "element",
            "constraints": "constraint", "sensors": "sensor", "inputs": "input", "outputs": "output"}


def json_schema() -> dict:
    """The JSON Schema of a model file (draft 2020-12, as pydantic writes it)."""
    schema = ModelSpec.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "mbdsim model file"
    return schema
