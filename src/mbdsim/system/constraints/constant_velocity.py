"""Constant-velocity joint (Adams CVJOINT): common point and equal spin of the two shafts.

Frames (body axes of each body): on body_i (f_i, g_i, h_i) with h_i the shaft axis of body_i, on body_j
(f_j, g_j, h_j) with h_j the shaft axis of body_j; f_i = f_j = the bend axis (axis_i x axis_j) as
built, g = h x f.  Rows: the spherical joint's 3 and one equal-angle row (kind "cvel", `system.kernels.row_terms` kind 8)

    phi = f_i . g_j - g_i . f_j  (= -2 sin(alpha) n . h_i for a relative rotation alpha about n)

which holds when the relative rotation of the frames is about an axis perpendicular to the shafts
(the homokinetic condition: both shafts turn by the same angle about their own axes).  It leaves the
two bending freedoms (4 rows, 2 relative DOF).
"""
from __future__ import annotations

import numpy as np

from . import primitives as pr
from .base import JointType, RowSpec


class ConstantVelocity(JointType):
    kind = "constant_velocity"
    needs_orientation = True

    @staticmethod
    def rows(g):
        return JointType.point(g) + [RowSpec("cvel", (g.f_i, g.g_i, g.f_j, g.g_j), g.name)]

    @staticmethod
    def frames(joint):
        """((f, g, h) on body_i, (f, g, h) on body_j), ground axes at t=0, of a joint given by bodies."""
        hi, hj = joint.axis, joint.axis_j
        f = joint.u_axis
        return (f, np.cross(hi, f), hi), (f, np.cross(hj, f), hj)


def cvel_rows(fr, group) -> pr.Rows:
    """Equal-angle rows of all constant-velocity joints of a group."""
    return pr.cvel(fr, group.bi, group.bj, *group.vecs)
