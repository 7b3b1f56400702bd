"""Model methods for the force-element library (torsion springs, bushings, contact, stops).

Mixed into mbdsim.Model; each method validates its input, builds a spec and registers it with
`self.add_element(spec)`.  Errors are ModelError naming the entity and the field.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ._check import scalar, vector
from .element_specs import Bushing, Contact, Stop, TorsionSpring
from .shapes import attach
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .._types import JointRef, Location
    from numpy.typing import ArrayLike
    from typing import Any


class ForceElementsMixin:
    """add_torsion_spring, add_bushing, add_contact, add_stop (see issue 3)."""

    def add_torsion_spring(self, name: str, joint: JointRef, stiffness: float, damping: float = 0.0,
                           free_angle: float = 0.0, preload: float = 0.0) -> TorsionSpring:
        """Rotational spring-damper on a revolute or cylindrical joint axis.

        Torque on body_j about the axis = -(stiffness (theta - free_angle) + damping theta_dot + preload),
        on body_i the opposite; theta [rad] is the joint angle (0 in the initial configuration).
        stiffness [N m/rad] >= 0, damping [N m s/rad] >= 0, free_angle [rad], preload [N m].
        `res.spring_length/velocity/force` give theta, theta_dot and that spring torque."""
        entity = f"torsion spring '{name}'"
        jt = self._element_joint(entity, joint)
        self._rotational_joint(entity, jt, "rotation")
        spec = TorsionSpring(name, jt, scalar(entity, "stiffness", stiffness, minimum=0.0),
                             scalar(entity, "damping", damping, minimum=0.0),
                             scalar(entity, "free_angle", free_angle), scalar(entity, "preload", preload))
        return self.add_element(spec)

    def add_bushing(self, name: str, marker_i: Location, marker_j: Location, stiffness: ArrayLike = (0.0,) * 6,
                    damping: ArrayLike = (0.0,) * 6, preload: ArrayLike = (0.0,) * 6) -> Bushing:
        """Bushing between two markers (a Marker or (body, point in ground at t=0)), Adams BUSHING semantics.

        stiffness (kx, ky, kz [N/m], ktx, kty, ktz [N m/rad]), damping (cx, cy, cz [N s/m], ctx, cty, ctz
        [N m s/rad]) and preload (Fx, Fy, Fz [N], Tx, Ty, Tz [N m]) in marker_i axes; see mbdsim Bushing.
        As in Adams, the torque is -K a - C w + T0 with `a` the rotation vector of marker_j relative to
        marker_i (small-angle semantics): with unequal rotational stiffnesses ktx, kty, ktz this torque is
        not the gradient of any potential once the rotation is finite, so such a bushing exchanges energy
        with the bodies (a few percent of its elastic energy over large rotations, whatever the
        tolerance): the run monitor then does not check the energy balance (res.diagnostics.notes)."""
        entity = f"bushing '{name}'"
        mi, mj = self._location(entity, "marker_i", marker_i), self._location(entity, "marker_j", marker_j)
        if mi.body is mj.body:
            raise ModelError(entity, "marker_j", "the markers must be on two different bodies")
        k = _six(entity, "stiffness", stiffness, minimum=0.0)
        c = _six(entity, "damping", damping, minimum=0.0)
        return self.add_element(Bushing(name, mi, mj, k, c, _six(entity, "preload", preload)))

    def add_contact(self, name: str, shape_i: Any, shape_j: Any, stiffness: float, exponent: float, damping: float,
                    penetration: float, mu: float = 0.0, friction_velocity: float = 1e-3) -> Contact:
        """Compliant contact between an mb.Sphere and an mb.Plane or two spheres (Adams IMPACT law).

        stiffness k [N/m^e] >= 0, exponent e > 0, damping c_max [N s/m] >= 0 reached at `penetration`
        d [m] > 0, Coulomb coefficient mu >= 0 regularised below `friction_velocity` [m/s] > 0."""
        entity = f"contact '{name}'"
        si = self._shape(entity, "shape_i", shape_i)
        sj = self._shape(entity, "shape_j", shape_j)
        if si.body is sj.body:
            raise ModelError(entity, "shape_j", "the two shapes are on the same body")
        if si.kind == "plane" and sj.kind == "plane":
            raise ModelError(entity, "shape_j", "plane-plane contact is not supported (use a sphere)")
        spec = Contact(name, si, sj, scalar(entity, "stiffness", stiffness, minimum=0.0),
                       scalar(entity, "exponent", exponent, minimum=0.0, strict=True),
                       scalar(entity, "damping", damping, minimum=0.0),
                       scalar(entity, "penetration", penetration, minimum=0.0, strict=True),
                       scalar(entity, "mu", mu, minimum=0.0),
                       scalar(entity, "friction_velocity", friction_velocity, minimum=0.0, strict=True))
        return self.add_element(spec)

    def add_stop(self, name: str, joint: JointRef, lower: float | None = None, upper: float | None = None,
                 stiffness: float | None = None, exponent: float = 1.5, damping: float = 0.0, penetration: float = 1e-3,
                 dof: str | None = None) -> Stop:
        """One- or two-sided stop on a translational, revolute or cylindrical joint coordinate.

        lower/upper [m or rad] (None: open), in the coordinates of Result.joint_coordinate (0 at the
        initial configuration); stiffness [N/m^e or N m/rad^e] > 0 (required), exponent e > 0,
        damping c_max [N s/m or N m s/rad] >= 0 reached at `penetration` [m or rad] > 0.
        `dof` picks "rotation" or "translation" on a cylindrical joint (default "rotation", as for every
        call that takes `dof=`, see Model.add_cylindrical)."""
        entity = f"stop '{name}'"
        jt = self._element_joint(entity, joint)
        dof = self._stop_dof(entity, jt, dof)
        if lower is None and upper is None:
            raise ModelError(entity, "lower", "give lower and/or upper")
        lo = None if lower is None else scalar(entity, "lower", lower)
        hi = None if upper is None else scalar(entity, "upper", upper)
        if lo is not None and hi is not None and not lo < hi:
            raise ModelError(entity, "upper", f"must be > lower ({lo!r}), got {hi!r}")
        if stiffness is None:
            raise ModelError(entity, "stiffness", "is required")
        spec = Stop(name, jt, dof, lo, hi, scalar(entity, "stiffness", stiffness, minimum=0.0, strict=True),
                    scalar(entity, "exponent", exponent, minimum=0.0, strict=True),
                    scalar(entity, "damping", damping, minimum=0.0),
                    scalar(entity, "penetration", penetration, minimum=0.0, strict=True))
        return self.add_element(spec)

    # ----------------------------------------------------------------- helpers
    def _element_joint(self, entity, joint):
        return self._lookup(joint, self.joints, entity, "joint")

    @staticmethod
    def _rotational_joint(entity, jt, what):
        from .joint_kinds import ROT, axis_dofs
        if ROT not in axis_dofs(jt.kind, loads=True):
            raise ModelError(entity, "joint", f"needs a revolute or cylindrical joint for a {what}, "
                             f"{jt.name!r} is {jt.kind}")
        if jt.body_j.is_particle:
            raise ModelError(entity, "joint", f"body_j of {jt.name!r} is a particle: it has no rotation")

    def _stop_dof(self, entity, jt, dof):
        from .joint_kinds import pick_axis_dof
        dof = pick_axis_dof(entity, jt, dof, True, f"needs a translational, revolute or cylindrical joint, "
                            f"{jt.name!r} is {jt.kind}")
        if dof == "rotation":
            self._rotational_joint(entity, jt, "rotational stop")
        return dof

    def _shape(self, entity, field, shape):
        body = self._lookup(getattr(shape, "body", None), self.bodies, entity, field) \
            if hasattr(shape, "body") else None
        if body is None:
            raise ModelError(entity, field, f"expected mb.Sphere or mb.Plane, got {shape!r}")
        return attach(entity, field, shape, body)


def _six(entity, field, values, minimum=None) -> np.ndarray:
    a = vector(entity, field, values, 6, " (x, y, z, rx, ry, rz)")
    return np.array([scalar(entity, f"{field}[{k}]", x, minimum=minimum) for k, x in enumerate(a)])