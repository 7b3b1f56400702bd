"""Joint and motion-driver specifications (plain data; equations live in mbdsim.system)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .body import Body

# Joint kinds and their relative degrees of freedom (rotation, translation) between two rigid bodies.
JOINT_DOF = {
    "revolute": 1, "translational": 1, "cylindrical": 2, "spherical": 3,
    "universal": 2, "planar": 3, "fixed": 0,
}


@dataclass(eq=False)
class Joint:
    """A joint between body_i and body_j; `point` [m] and `axis` (unit) in ground at t=0.

    body_j moves relative to body_i.  For a universal joint `axis` is the axis fixed on body_i and
    `axis_j` the one fixed on body_j; for a planar joint `axis` is the plane normal and `u_axis` the
    in-plane u axis (v = normal x u), fixed on body_i.
    """

    name: str
    kind: str
    body_i: Body
    body_j: Body
    point: np.ndarray
    axis: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    axis_j: np.ndarray | None = None
    u_axis: np.ndarray | None = None

    @property
    def dof(self) -> int:
        """Relative degrees of freedom the joint leaves between two rigid bodies."""
        return JOINT_DOF[self.kind]

    def __repr__(self) -> str:
        return f"Joint({self.kind} {self.name!r}: {self.body_i.name} -> {self.body_j.name})"


@dataclass(eq=False)
class Motion:
    """A driver imposing a joint coordinate as a function of time.

    `function` is an mbdsim.expressions.TimeFunction of t [s] giving the coordinate [rad or m];
    `dof` is "rotation" or "translation" (which coordinate of the joint is driven).
    """

    name: str
    joint: Joint
    kind: str            # "displacement", "velocity" or "acceleration" (as given by the user)
    function: Any        # TimeFunction with value/d1/d2 of the driven displacement
    dof: str = "rotation"

    def __repr__(self) -> str:
        return f"Motion({self.name!r} on {self.joint.name}, {self.kind})"
