"""Applied loads and force elements (plain data)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .body import Body, Marker


@dataclass(eq=False)
class Force:
    """A force applied at a point of a body.

    `force` is a constant 3-vector [N] or a callable (t, state) -> 3-vector; it is expressed in ground
    axes when `frame` is None, else in the axes of `frame` (a Body or Marker), following its rotation.
    """

    name: str
    body: Body
    s_B: np.ndarray      # application point, body axes, from the centre of mass [m]
    force: Any
    frame: Any = None


@dataclass(eq=False)
class Torque:
    """A pure torque [N m] on a body: constant 3-vector or callable (t, state); axes as for Force."""

    name: str
    body: Body
    torque: Any
    frame: Any = None


@dataclass(eq=False)
class SpringDamper:
    """Translational spring-damper between two points; tension > 0 pulls the points together.

    tension = stiffness (L - free_length) + damping dL/dt + preload  [N], with L the distance [m].
    """

    name: str
    marker_i: Marker
    marker_j: Marker
    stiffness: float
    damping: float
    free_length: float
    preload: float

    @property
    def point_i(self) -> np.ndarray:
        """Attachment point on body i in ground at t=0 [m]."""
        return self.marker_i.point

    @property
    def point_j(self) -> np.ndarray:
        """Attachment point on body j in ground at t=0 [m]."""
        return self.marker_j.point


@dataclass(eq=False)
class ExprForce(Force):
    """A Force whose components are numbers or load expressions (`force` is a loadexpr.ExprVector)."""


@dataclass(eq=False)
class ExprTorque(Torque):
    """A Torque whose components are numbers or load expressions (`torque` is a loadexpr.ExprVector)."""


@dataclass(eq=False)
class LineForce:
    """Action-reaction force along the line between two points (Adams SFORCE, translational).

    `magnitude` [N] (a number, a loadexpr.LoadExpr or a callable (t, state)); positive pulls the points
    together (the sign of a spring's tension): +magnitude u on marker_i's body, -magnitude u on
    marker_j's, u the unit vector from point i to point j."""

    name: str
    marker_i: Marker
    marker_j: Marker
    magnitude: Any

    @property
    def needs_state(self) -> bool:
        return callable(self.magnitude) and not isinstance(self.magnitude, str)


@dataclass(eq=False)
class JointForce:
    """Generalized force along (dof "translation" [N]) or torque about (dof "rotation" [N m]) a joint's
    axis, acting on body_j and, reacting, on body_i: positive drives the joint coordinate up (a motor's
    torque, an actuator's force). `value`: a number, a loadexpr.LoadExpr or a callable (t, state)."""

    name: str
    joint: Any
    dof: str
    value: Any

    @property
    def needs_state(self) -> bool:
        return callable(self.value)
