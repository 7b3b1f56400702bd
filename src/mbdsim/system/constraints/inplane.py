"""Inplane joint primitive (Adams JPRIM INPLANE): the point of body_j stays in the plane through the joint
point with normal h_i fixed on body_i (1 row; 5 relative DOF left).

Vectors of `JointGeom` are in the axes of the body they are fixed on; lengths in m.
"""
from .base import JointType, RowSpec


class Inplane(JointType):
    kind = "inplane"

    @staticmethod
    def rows(g):
        return [RowSpec("dot2", (g.h_i, g.s_i, g.s_j), g.name)]
