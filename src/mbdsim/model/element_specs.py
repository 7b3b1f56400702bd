"""Force-element specifications of issue 3 (plain data; evaluators live in mbdsim.system.force_elements).

Joint coordinates (torsion springs, stops) are those of `Result.joint_coordinate`: the angle [rad] of
body_j relative to body_i about the joint axis (right-hand rule) or the slide [m] of body_j's joint
point along the axis, both zero in the model's initial configuration.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .body import Marker
from .joints import Joint
from .shapes import AttachedShape


@dataclass(eq=False)
class TorsionSpring:
    """Rotational spring-damper on the axis of a revolute or cylindrical joint.

    spring torque M = stiffness (theta - free_angle) + damping theta_dot + preload  [N m], positive
    when it resists positive rotation: the torque on body_j about the joint axis is -M, on body_i +M.
    stiffness [N m/rad], damping [N m s/rad], free_angle [rad], preload [N m].
    """

    name: str
    joint: Joint
    stiffness: float
    damping: float = 0.0
    free_angle: float = 0.0
    preload: float = 0.0


@dataclass(eq=False)
class Bushing:
    """Linear 6-component bushing between marker_i and marker_j (Adams BUSHING semantics).

    x: translation of marker_j's origin relative to marker_i's, in marker_i axes [m]; xd its rate
    seen from marker_i's frame [m/s]; a: small-angle rotation of marker_j relative to marker_i (the
    rotation vector, in marker_i axes) [rad]; w: relative angular velocity in marker_i axes [rad/s].
    Force on body_j (at marker_j) F = -K_t x - C_t xd + F0 [N], torque T = -K_r a - C_r w + T0 [N m],
    both in marker_i axes; body_i receives -F at the same point (hence the offset moment) and -T.
    stiffness/damping/preload: 6 values (x, y, z, rx, ry, rz).
    """

    name: str
    marker_i: Marker
    marker_j: Marker
    stiffness: np.ndarray
    damping: np.ndarray
    preload: np.ndarray


@dataclass(eq=False)
class Contact:
    """Unilateral compliant contact between two shapes with the Adams IMPACT law.

    gap g [m] (signed, < 0 when penetrating), penetration delta = max(-g, 0):
    normal force  Fn = max(0, stiffness delta^exponent + STEP(delta, 0, 0, penetration, damping) d(delta)/dt)
    friction      Ft = -mu Fn v_t / sqrt(|v_t|^2 + friction_velocity^2)   (regularised Coulomb)
    with v_t the tangential slip velocity at the contact point.  stiffness [N/m^e], damping [N s/m]
    (reached at penetration [m]), friction_velocity [m/s].
    """

    name: str
    shape_i: AttachedShape
    shape_j: AttachedShape
    stiffness: float
    exponent: float
    damping: float
    penetration: float
    mu: float = 0.0
    friction_velocity: float = 1e-3


@dataclass(eq=False)
class Stop:
    """One- or two-sided compliant stop on a joint coordinate x (Adams IMPACT / BISTOP).

    Free for lower <= x <= upper (None: no wall on that side).  Past a wall the penetration p >= 0
    gives a load along the coordinate of magnitude max(0, k p^e + STEP(p, 0, 0, penetration, damping) dp/dt),
    pushing x back inside: a force [N] on a translational coordinate, a torque [N m] on a rotational one,
    on body_j (body_i receives the reaction).  `dof` is "rotation" or "translation".
    """

    name: str
    joint: Joint
    dof: str
    lower: float | None
    upper: float | None
    stiffness: float
    exponent: float
    damping: float
    penetration: float


ELEMENT_SPECS: tuple[Any, ...] = (TorsionSpring, Bushing, Contact, Stop)
