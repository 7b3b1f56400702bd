"""Joint and motion-driver specifications (plain data; equations live in mbdsim.system)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ModelError
from ._check import scalar, vector
from .body import Body, Marker
from .joint_kinds import JOINT_KINDS

# Derived from the joint-kind registry (model/joint_kinds.py): relative degrees of freedom between two
# rigid bodies, values of Result.joint_coordinate, and how the multi-valued coordinates read.
JOINT_DOF = {n: k.dof for n, k in JOINT_KINDS.items()}
JOINT_NCOORD = {n: k.ncoord for n, k in JOINT_KINDS.items()}
COORD_NAMES = {n: k.coord_names for n, k in JOINT_KINDS.items() if k.ncoord > 1}


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
    lead: float | None = None   # screw joint: slide per revolution [m/rev]
    initial_displacement: np.ndarray | None = None   # held at assembly (joint coordinates, from as drawn)
    initial_velocity: np.ndarray | None = None       # held at assembly (joint_velocity)
    marker_i: Marker | None = None   # marker-pair joint: point and axes from the I marker (on body_i) ...
    marker_j: Marker | None = None   # ... and the J marker (on body_j), which assembly brings together
    notes: list = field(default_factory=list)   # e.g. axes orthogonalised (shown in the AssemblyReport)

    @property
    def dof(self) -> int:
        """Relative degrees of freedom the joint leaves between two rigid bodies."""
        return JOINT_DOF[self.kind]

    @property
    def ncoord(self) -> int:
        """Number of joint coordinates (values of `initial_displacement` / `initial_velocity`)."""
        return JOINT_NCOORD[self.kind]

    def __repr__(self) -> str:
        return f"Joint({self.kind} {self.name!r}: {self.body_i.name} -> {self.body_j.name})"


@dataclass(eq=False)
class Motion:
    """A driver imposing a joint coordinate as a function of time.

    `function` is an mbdsim.expressions.TimeFunction of t [s] giving the coordinate [rad or m];
    `dof` is "rotation" or "translation" (which coordinate of the joint is driven). A velocity or
    acceleration driver keeps the function as given in `given` and its initial values in `initial`;
    `function` is then its integral (closed form when the expression has one).
    """

    name: str
    joint: Joint
    kind: str            # "displacement", "velocity" or "acceleration" (as given by the user)
    function: Any        # TimeFunction with value/d1/d2 of the driven displacement
    dof: str = "rotation"
    given: Any = None    # velocity / acceleration kinds: the TimeFunction as given [unit/s or unit/s^2]
    initial: tuple = (0.0, 0.0)   # and its initial displacement [m or rad] and velocity [m/s or rad/s]

    def __repr__(self) -> str:
        return f"Motion({self.name!r} on {self.joint.name}, {self.kind})"


def joint_initial(entity: str, kind: str, field_name: str, value) -> np.ndarray | None:
    """Validate a joint's `initial_displacement` / `initial_velocity`: None, a number for a one-coordinate
    joint, else a sequence in the order of Result.joint_coordinate (see COORD_NAMES); SI units."""
    if value is None:
        return None
    n = JOINT_NCOORD[kind]
    if n == 0:
        raise ModelError(entity, field_name, f"a {kind} joint has no coordinates to start from")
    if n == 1:
        if np.ndim(value) == 1 and np.size(value) == 1:
            value = np.asarray(value).reshape(-1)[0]
        return np.array([scalar(entity, field_name, value)])
    return vector(entity, field_name, value, n, f" {COORD_NAMES[kind]}")
