"""Model methods for joint primitives (Adams JPRIM), the screw joint and the constant-velocity joint.

Mixed into mbdsim.Model.  Like the other joint methods each takes two bodies (names or Body) with the
point [m] and axes (unit) in ground at t=0, or two markers (Body.add_marker) whose origins and axes
are the joint's I and J frames (then point and axes are omitted).  The equations live in
mbdsim.system.constraints (one class per kind).
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ._check import scalar, vec3
from .body import Body, Marker
from .joints import Joint
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .._types import BodyRef, Vector


class JointsExtraMixin:
    """add_inline, add_inplane, add_orientation, add_parallel_axes, add_perpendicular, add_atpoint,
    add_screw, add_constant_velocity."""

    # ------------------------------------------------------------- joint primitives
    def add_inline(self, name: str, body_i: BodyRef, body_j: BodyRef, point: Vector | None = None,
                   axis: Vector | None = None) -> Joint:
        """Inline primitive: the joint point of body_j stays on the line through `point` along `axis`
        fixed on body_i (2 equations; with markers: the J origin on the I marker's z line)."""
        return self._joint(name, "inline", body_i, body_j, point, axis)

    def add_inplane(self, name: str, body_i: BodyRef, body_j: BodyRef, point: Vector | None = None,
                    normal: Vector | None = None) -> Joint:
        """Inplane primitive: the joint point of body_j stays in the plane through `point` with `normal`
        fixed on body_i (1 equation; with markers: the J origin in the I marker's xy plane)."""
        return self._joint(name, "inplane", body_i, body_j, point, normal)

    def add_orientation(self, name: str, body_i: BodyRef, body_j: BodyRef) -> Joint:
        """Orientation primitive: body_j keeps its attitude relative to body_i, translations free
        (3 equations; with markers: the markers' axes coincide)."""
        return self._joint(name, "orientation", body_i, body_j, self._cm_point(body_i, body_j), _z())

    def add_parallel_axes(self, name: str, body_i: BodyRef, body_j: BodyRef, axis: Vector | None = None) -> Joint:
        """Parallel-axes primitive: `axis` (ground, t=0) fixed on each body stays parallel on both
        (2 equations; with markers: the z axes stay parallel)."""
        return self._joint(name, "parallel_axes", body_i, body_j, self._cm_point(body_i, body_j), axis)

    def add_perpendicular(self, name: str, body_i: BodyRef, body_j: BodyRef, axis_i: Vector | None = None,
                          axis_j: Vector | None = None) -> Joint:
        """Perpendicular primitive: `axis_i` fixed on body_i stays perpendicular to `axis_j` fixed on
        body_j (ground, t=0, perpendicular then within 1e-6 rad; 1 equation; with markers: the z axes)."""
        from .model import _universal_axis_j
        j = self._joint(name, "perpendicular", body_i, body_j, self._cm_point(body_i, body_j), axis_i)
        try:
            if j.marker_j is not None:
                if axis_j is not None:
                    raise ModelError(f"joint '{name}'", "axis_j", "omit the axes of a joint between two "
                                     "markers (their z axes are used)")
                j.axis_j = j.marker_j.orientation[:, 2].copy()
            else:
                j.axis_j = _universal_axis_j(j, axis_j)
        except ModelError:
            self._drop_joint(name)
            raise
        return j

    def add_atpoint(self, name: str, body_i: BodyRef, body_j: BodyRef, point: Vector | None = None) -> Joint:
        """Atpoint primitive: the points of body_i and body_j at `point` (ground, t=0) coincide; rotations
        free (3 equations, a spherical joint's; with markers: the origins coincide)."""
        return self._joint(name, "atpoint", body_i, body_j, point, _z())

    # ------------------------------------------------------------- screw, constant velocity
    def add_screw(self, name: str, body_i: BodyRef, body_j: BodyRef, point: Vector | None = None,
                  axis: Vector | None = None, lead: float | None = None,
                  initial_displacement: float | Vector | None = None,
                  initial_velocity: float | Vector | None = None) -> Joint:
        """Screw joint along `axis` through `point` (ground, t=0, or two markers: the I marker's z axis).

        `lead` [m per revolution]: body_j advances lead * angle / (2 pi) along the axis as it turns by
        `angle` [rad] about it (positive: right-handed).  Coordinate (joint_coordinate, motions): the
        angle [rad]; a motion may drive "rotation" (default) or "translation"."""
        entity = f"joint '{name}'"
        if lead is None:
            raise ModelError(entity, "lead", "is required (slide per revolution [m])")
        lead = scalar(entity, "lead", lead)
        if lead == 0.0:
            raise ModelError(entity, "lead", "must be non-zero (a zero lead is a revolute joint)")
        j = self._joint(name, "screw", body_i, body_j, point, axis, initial_displacement, initial_velocity)
        j.lead = lead
        return j

    def add_constant_velocity(self, name: str, body_i: BodyRef, body_j: BodyRef, point: Vector | None = None,
                              axis_i: Vector | None = None, axis_j: Vector | None = None) -> Joint:
        """Constant-velocity joint (Adams CVJOINT) at `point`: the shafts `axis_i` (fixed on body_i) and
        `axis_j` (on body_j), ground at t=0, turn by equal angles about their own axes; the two bending
        freedoms are left.  With two markers: their z axes are the shafts and the angles are counted
        from their x axes (which should both lie along the bend axis as drawn).  Coordinates: the relative
        rotation vector [rad] in body_i axes, as a universal joint's."""
        entity = f"joint '{name}'"
        j = self._joint(name, "constant_velocity", body_i, body_j, point, axis_i)
        try:
            if j.marker_j is not None:
                if axis_j is not None:
                    raise ModelError(entity, "axis_j", "omit the axes of a joint between two markers (their "
                                     "z axes are used)")
                return j
            if axis_j is None:
                raise ModelError(entity, "axis_j", "is required (or give two markers instead of the bodies)")
            j.axis_j = vec3(entity, "axis_j", axis_j, unit=True)
            if float(j.axis @ j.axis_j) < -1e-9:
                raise ModelError(entity, "axis_j", "bends the shafts by more than 90 deg; give the shaft "
                                 "directions pointing away from the joint on one side and on along the other")
        except ModelError:
            self._drop_joint(name)
            raise
        bend = np.cross(j.axis, j.axis_j)
        if np.linalg.norm(bend) < 1e-9:   # straight as built: any axis perpendicular to the shafts
            from ..math.rotation import perpendicular_frame
            bend = perpendicular_frame(j.axis)[0]
        j.u_axis = bend / np.linalg.norm(bend)
        return j

    def _cm_point(self, body_i, body_j):
        """Joint point of a primitive without one: body_j's CM (None for a marker pair)."""
        if isinstance(body_i, Marker) or isinstance(body_j, Marker):
            return None
        bj = self.bodies.get(body_j) if isinstance(body_j, str) else body_j
        return bj.position if isinstance(bj, Body) else np.zeros(3)


def _z():
    """The placeholder axis object of joints without one (Model._marker_joint accepts it with markers)."""
    from .model import _Z
    return _Z
