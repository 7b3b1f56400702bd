"""Model-file specs of issue 11: joint primitives, screw and constant-velocity joints, coordinate
constraints (couplers, gears, user constraints) and sensors; of issue 14: line and joint forces.  Units as in mbdsim.io.schema."""
from __future__ import annotations

from typing import Annotated, Literal, Optional, Union

from pydantic import Field

from .schema import Location, Name, Number, Q, Raw, Spec, V   # imported by schema.py once these exist


class _Pair(Spec):
    name: Name
    body_i: Name
    body_j: Name


class InplaneSpec(_Pair):
    type: Literal["inplane"]
    point: V("m")
    normal: V("")


class OrientationSpec(_Pair):
    type: Literal["orientation"]


class ParallelAxesSpec(_Pair):
    type: Literal["parallel_axes"]
    axis: V("")


class PerpendicularSpec(_Pair):
    type: Literal["perpendicular"]
    axis_i: V("")
    axis_j: V("")


class ScrewSpec(_Pair):
    """Screw joint: lead [m per revolution], positive right-handed."""

    type: Literal["screw"]
    point: V("m")
    axis: V("")
    lead: Q("m")


class ConstantVelocitySpec(_Pair):
    type: Literal["constant_velocity"]
    point: V("m")
    axis_i: V("")
    axis_j: V("")


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
