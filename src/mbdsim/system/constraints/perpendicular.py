"""Perpendicular joint primitive (Adams JPRIM PERPENDICULAR): axis_j fixed on body_j (`JointGeom.extra`,
body-j axes) stays perpendicular to h_i fixed on body_i (1 row; 5 relative DOF left).

Vectors of `JointGeom` are in the axes of the body they are fixed on; lengths in m.
"""
from .base import JointType, RowSpec


class Perpendicular(JointType):
    kind = "perpendicular"
    needs_orientation = True

    @staticmethod
    def rows(g):
        return [RowSpec("dot1", (g.h_i, g.extra), g.name)]
