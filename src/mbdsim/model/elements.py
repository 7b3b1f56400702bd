"""Model methods for the force-element library (torsion springs, bushings, contact, stops).

Mixed into mbdsim.Model; each method validates its input, builds a spec and registers it with
`self.add_element(spec)`.  Errors are ModelError naming the entity and the field.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ._check import scalar, vector
from .element_specs import Bushing, Contact, Stop, TorsionSpring
from .shapes import AttachedShape, attach
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
                    penetration: float, mu: float = 0.0, friction_velocity: float = 1e-3, *,
                    restitution: float | None = None, mu_static: float | None = None,
                    mu_dynamic: float | None = None, stiction_velocity: float | None = None,
                    transition_velocity: float | None = None) -> Any:
        """Compliant contact between shapes (Adams IMPACT law, or POISSON with `restitution`).

        shape_i, shape_j: a shape of Body.add_shape (box, cylinder, capsule, ellipsoid, sphere, convex or
        triangle mesh), an mb.Sphere(body, radius, center) or an mb.Plane(body, point, normal), or a list of
        them on either side (every pair between the lists on two different bodies; the broad phase prunes).
        stiffness k [N/m^e] >= 0, exponent e > 0, damping c_max [N s/m] >= 0 reached at `penetration`
        d [m] > 0, applied at each contact point; `restitution` (0..1): the POISSON law instead of the
        damping (a mass leaves a contact with restitution times its approach speed).  Friction: Coulomb
        `mu` >= 0 regularised below `friction_velocity` [m/s] > 0, or Adams' `mu_static`, `mu_dynamic`
        with `stiction_velocity` (default 1e-4 m/s) and `transition_velocity` [m/s] (default 10 times it).
        A sphere-sphere or sphere-plane pair without the new options stays the exact issue-3 Contact;
        anything else is a ShapeContact (model.contacts, solvers.fastcontact)."""
        from .contacts import ShapeContact, friction_options, make_pairs, shape_list
        entity = f"contact '{name}'"
        lists = isinstance(shape_i, (list, tuple)) or isinstance(shape_j, (list, tuple))
        si = [self._shape(entity, "shape_i", s) for s in shape_list(entity, "shape_i", shape_i)]
        sj = [self._shape(entity, "shape_j", s) for s in shape_list(entity, "shape_j", shape_j)]
        if not si or not sj:
            raise ModelError(entity, "shape_i" if not si else "shape_j", "the list of shapes is empty")
        law = (scalar(entity, "stiffness", stiffness, minimum=0.0),
               scalar(entity, "exponent", exponent, minimum=0.0, strict=True),
               scalar(entity, "damping", damping, minimum=0.0),
               scalar(entity, "penetration", penetration, minimum=0.0, strict=True),
               scalar(entity, "mu", mu, minimum=0.0),
               scalar(entity, "friction_velocity", friction_velocity, minimum=0.0, strict=True))
        eps = None if restitution is None else scalar(entity, "restitution", restitution, minimum=0.0)
        if eps is not None and eps > 1.0:
            raise ModelError(entity, "restitution", f"must be between 0 and 1, got {restitution!r}")
        fr = friction_options(entity, law[4], law[5], mu_static, mu_dynamic, stiction_velocity, transition_velocity)
        legacy = not lists and eps is None and fr[0] is None and all(isinstance(s, AttachedShape) for s in si + sj)
        if legacy:
            a, b = si[0], sj[0]
            if a.body is b.body:
                raise ModelError(entity, "shape_j", "the two shapes are on the same body")
            if a.kind == "plane" and b.kind == "plane":
                raise ModelError(entity, "shape_j", "plane-plane contact is not supported (use a sphere)")
            return self.add_element(Contact(name, a, b, *law))
        spec = ShapeContact(name, make_pairs(entity, si, sj), *law, eps, *fr, shapes_i=si, shapes_j=sj)
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
        from ..geometry.shape import Shape
        body = self._lookup(getattr(shape, "body", None), self.bodies, entity, field) \
            if getattr(shape, "body", None) is not None else None
        if body is None:
            raise ModelError(entity, field, "expected a shape of Body.add_shape, an mb.Sphere(body, radius) or "
                             f"an mb.Plane, got {shape!r}")
        if isinstance(shape, Shape):
            return shape
        return attach(entity, field, shape, body)

def _six(entity, field, values, minimum=None) -> np.ndarray:
    a = vector(entity, field, values, 6, " (x, y, z, rx, ry, rz)")
    return np.array([scalar(entity, f"{field}[{k}]", x, minimum=minimum) for k, x in enumerate(a)])