"""Model-file specs of issue 11: joint primitives, screw and constant-velocity joints, coordinate
constraints (couplers, gears, user constraints) and sensors; of issue 14: line and joint forces.  Units as in mbdsim.io.schema."""
from __future__ import annotations

from typing import Annotated, Literal, Optional, Union

from pydantic import Field

# imported by schema.py once these exist
from .schema import Initial, JointPair, Location, Name, Number, Q, Raw, Spec, V


class InplaneSpec(JointPair):
    type: Literal["inplane"]
    point: Optional[V("m")] = None
    normal: Optional[V("")] = None


class OrientationSpec(JointPair):
    type: Literal["orientation"]


class ParallelAxesSpec(JointPair):
    type: Literal["parallel_axes"]
    axis: Optional[V("")] = None


class PerpendicularSpec(JointPair):
    type: Literal["perpendicular"]
    axis_i: Optional[V("")] = None
    axis_j: Optional[V("")] = None


class ScrewSpec(JointPair, Initial):
    """Screw joint: lead [m per revolution], positive right-handed; its coordinate is the angle [rad]."""

    type: Literal["screw"]
    point: Optional[V("m")] = None
    axis: Optional[V("")] = None
    lead: Q("m")


class ConstantVelocitySpec(JointPair):
    type: Literal["constant_velocity"]
    point: Optional[V("m")] = None
    axis_i: Optional[V("")] = None
    axis_j: Optional[V("")] = None


EXTRA_JOINTS = (InplaneSpec, OrientationSpec, ParallelAxesSpec, PerpendicularSpec, ScrewSpec, ConstantVelocitySpec)


class CouplerSpec(Spec):
    """x_2 = ratio x_1 between two joints' coordinates (gear: two revolutes, ratio = -r_1 / r_2)."""

    type: Literal["coupler", "gear"]
    name: Name
    joint_1: Name
    joint_2: Name
    ratio: Number
    dof_1: Optional[Literal["rotation", "translation"]] = None
    dof_2: Optional[Literal["rotation", "translation"]] = None


class UserConstraintSpec(Spec):
    """expression(joint coordinates by name, t) = 0 (whitelist parser)."""

    type: Literal["user_constraint"]
    name: Name
    expression: str


ConstraintSpec = Annotated[Union[CouplerSpec, UserConstraintSpec], Field(discriminator="type")]


class SensorSpec(Spec):
    """A sensor on an expression `signal` in t and joint coordinates (rates: <joint>_dot)."""

    name: Name
    signal: str
    value: Number = 0.0
    direction: Literal[-1, 0, 1] = 0
    action: Literal["stop", "record"] = "stop"


class LineForceSpec(Spec):
    """Force [N] along the line between two points, positive pulling them together: a number, a constant
    with units or an expression of time and state ("k*(DM(a.p, b.q) - L0) + c*VR(a.p, b.q)")."""

    type: Literal["line_force"]
    name: Name
    at_i: Location
    at_j: Location
    magnitude: Raw


class JointForceSpec(Spec):
    """Generalized force [N] or torque [N m] along / about a joint's axis (unit by the joint's dof)."""

    type: Literal["joint_force"]
    name: Name
    joint: Name
    value: Raw
    dof: Optional[Literal["rotation", "translation"]] = None


class InputSpec(Spec):
    """A scalar input (issue 33) that load, sensor and output expressions read by name; `value`: its value
    in simulate and at the start of a Simulator (SI units of whatever reads it)."""

    name: Name
    value: Number = 0.0


class OutputSpec(Spec):
    """A measured signal (issue 33): an expression of the state and inputs, as load expressions use."""

    name: Name
    expression: str


class TableSpec(Spec):
    """An interpolated table that load expressions call as `name(x)` (or `name(x, order=1)`): an Adams
    SPLINE read through AKISPL (Akima) or CUBSPL (cubic, not-a-knot), extrapolated beyond the data by the
    parabola through the end three points, or the line through the end two with linear_extrapolate.  The
    numbers are in the units of the expression that reads it (not converted)."""

    name: Name
    kind: Literal["AKISPL", "CUBSPL"] = "AKISPL"
    x: list[float]
    y: list[float]
    linear_extrapolate: bool = False

