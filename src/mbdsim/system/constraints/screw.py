"""Screw joint: a cylindrical joint whose slide follows the rotation, s = lead * theta / (2 pi).

Rows: the cylindrical joint's 4 (h_j parallel to h_i, the point of body_j on the axis line of body_i)
and one screw row (kind "screw", `system.kernels.row_terms` kind 7), with
c = lead / (2 pi) [m/rad], s = h_i . (P_j - P_i) [m] the slide and theta [rad] the rotation of body_j
about h_i (both zero as built):

    phi = c * wrap(s / c - theta)          (wrap to (-pi, pi]; = s - c theta near the solution)

The wrap makes the row single-valued for any number of turns (s carries the winding), so it needs no
state.  Jacobian: J_s - c J_theta; quadratic velocity term: quad_s - c quad_theta.  Positive lead:
right-handed (positive rotation about the axis advances body_j along +axis).  Vectors in body axes.
"""
from __future__ import annotations

import numpy as np

from . import primitives as pr
from .base import JointType, RowSpec


class Screw(JointType):
    kind = "screw"
    needs_orientation = True

    @staticmethod
    def rows(g):
        rows = JointType.parallel_axes(g) + JointType.on_line(g)
        return rows + [RowSpec("screw", (g.f_i, g.g_i, g.f_j, g.h_i, g.s_i, g.s_j), g.name, g.extra)]


def lead_per_radian(group) -> np.ndarray:
    """c = lead / 2 pi [m/rad] of each screw of a group (`group.fns` holds each joint's lead [m/rev])."""
    return np.asarray(group.fns, dtype=float) / (2 * np.pi)


def screw_rows(fr, group) -> pr.Rows:
    """Rows of all screw constraints of a group."""
    return pr.screw(fr, group.bi, group.bj, *group.vecs, lead_per_radian(group))
