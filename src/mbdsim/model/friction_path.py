"""Model methods for joint friction and path (point-on-curve) constraints (issue 3).

Mixed into mbdsim.Model.  The specs are plain data; the equations live in
mbdsim.system.force_elements.friction (stick/slip Coulomb friction) and
mbdsim.system.constraints.path (point on a curve, with the curve parameter as an extra coordinate).
"""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import ModelError
from ._check import scalar
from .body import Body, Marker
from .curves import Curve
from .joints import Joint
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .._types import BodyRef, JointRef, Location
    from typing import Any

# model parameters per joint kind: name -> (unit, meaning); all optional, None = term omitted
FRICTION_PARAMETERS = {
    "translational": {
        "preload": ("N", "normal load added to the reaction-based one"),
        "effective_length": ("m", "bending moment / effective_length adds to the normal load"),
        "reaction_arm": ("m", "torsional moment about the axis / reaction_arm adds to the normal load"),
    },
    "revolute": {
        "pin_radius": ("m", "radial reaction force times pin_radius is the friction load [N m] (required)"),
        "preload": ("N m", "friction load added to the reaction-based one"),
        "friction_arm": ("m", "axial (thrust) reaction force times friction_arm adds to the friction load"),
        "bending_arm": ("m", "bending moment / bending_arm acts as an extra radial force (times pin_radius)"),
    },
}


@dataclass(eq=False)
class JointFriction:
    """Coulomb friction in a translational or revolute joint (see force_elements.friction for the model).

    Parameters are in SI units; those of the other joint kind stay None."""

    name: str
    joint: Joint
    mu_static: float
    mu_dynamic: float
    preload: float = 0.0
    pin_radius: float | None = None
    friction_arm: float | None = None
    bending_arm: float | None = None
    effective_length: float | None = None
    reaction_arm: float | None = None


@dataclass(eq=False)
class PointOnCurve:
    """The origin of `marker` (on its body) stays on `curve`, which is fixed on `body`."""

    name: str
    marker: Marker
    body: Body
    curve: Curve


class FrictionPathMixin:
    """add_friction, add_point_on_curve (see issue 3)."""

    def add_friction(self, name: str, joint: JointRef, mu_static: float, mu_dynamic: float,
                     **model_parameters: float) -> JointFriction:
        """Coulomb friction in a translational or revolute joint with event-driven stick/slip.

        mu_static >= mu_dynamic >= 0.  Friction load = mu * N with N from the joint's reaction on
        body_j at the joint point (force F, moment T; h the joint axis):
          translational [N]:  N = preload + |F_perp| + |T_perp|/effective_length + |T.h|/reaction_arm
          revolute [N m]:     N = preload + pin_radius |F_perp| + friction_arm |F.h|
                                  + pin_radius |T_perp| / bending_arm
        model_parameters (all [m] except preload): translational: preload, effective_length,
        reaction_arm; revolute: pin_radius (required), preload, friction_arm, bending_arm.
        Terms whose parameter is not given are omitted.  `res.friction_force(name)` gives the friction
        force [N] / torque [N m] on body_j along / about the axis."""
        entity = f"friction '{name}'"
        self._claim(name, "friction")
        try:
            jt = self._lookup(joint, self.joints, entity, "joint")
            if jt.kind not in FRICTION_PARAMETERS:
                raise ModelError(entity, "joint", f"friction needs a translational or revolute joint, "
                                 f"{jt.name!r} is {jt.kind}")
            taken = [f.name for f in self.forces.values() if isinstance(f, JointFriction) and f.joint is jt]
            if taken:
                raise ModelError(entity, "joint", f"joint {jt.name!r} already has friction {taken[0]!r}")
            if jt.kind == "revolute" and (jt.body_j.is_particle or jt.body_i.is_particle):
                raise ModelError(entity, "joint", "revolute friction needs rigid bodies (a particle has no rotation)")
            ms = scalar(entity, "mu_static", mu_static, minimum=0.0)
            md = scalar(entity, "mu_dynamic", mu_dynamic, minimum=0.0)
            if md > ms:
                raise ModelError(entity, "mu_dynamic", f"must not exceed mu_static ({ms}), got {md}")
            params = self._friction_parameters(entity, jt.kind, model_parameters)
            spec = JointFriction(name, jt, ms, md, **params)
        except ModelError:
            self._names.discard(name)
            raise
        self.forces[name] = spec
        return spec

    @staticmethod
    def _friction_parameters(entity, kind, given):
        allowed = FRICTION_PARAMETERS[kind]
        out = {}
        for key, value in given.items():
            if key not in allowed:
                raise ModelError(entity, key, f"unknown parameter for {kind} friction; allowed: {sorted(allowed)}")
            if key == "preload":
                out[key] = scalar(entity, key, value, minimum=0.0)
            elif value is not None:
                out[key] = scalar(entity, key, value, minimum=0.0, strict=True)
        if kind == "revolute" and "pin_radius" not in out:
            raise ModelError(entity, "pin_radius", "revolute friction needs pin_radius [m] > 0")
        return out

    def add_point_on_curve(self, name: str, marker: Location, body: BodyRef, curve: Any) -> PointOnCurve:
        """Constrain the origin of `marker` (a Marker, or (body, point in ground at t=0)) to `curve`
        (mb.Curve or mb.Spline, given in ground at t=0) fixed on `body` (a rigid body or ground).

        Three constraint rows P_marker = C(s); the curve parameter s is an extra (massless)
        coordinate, found at t=0 as the curve point nearest to the marker (assembly then closes any
        gap).  `res.reaction_force(name)` is the force the curve exerts on the marker's body."""
        entity = f"point-on-curve '{name}'"
        self._claim(name, "point-on-curve")
        try:
            mk = self._location(entity, "marker", marker)
            b = self._lookup(body, self.bodies, entity, "body")
            if b is mk.body:
                raise ModelError(entity, "body", "the curve must be on another body than the marker")
            if b.is_particle:
                raise ModelError(entity, "body", "a curve cannot be fixed on a particle (it has no orientation)")
            if not isinstance(curve, Curve):
                raise ModelError(entity, "curve", f"expected mb.Curve or mb.Spline, got {curve!r}")
        except ModelError:
            self._names.discard(name)
            raise
        spec = PointOnCurve(name, mk, b, curve)
        self.__dict__.setdefault("path_constraints", {})[name] = spec
        return spec
