"""Inline joint primitive (Adams JPRIM INLINE): the point of body_j stays on the line through the joint
point along h_i fixed on body_i (2 rows; 4 relative DOF left).

Vectors of `JointGeom` are in the axes of the body they are fixed on; lengths in m.
"""
from .base import JointType


class Inline(JointType):
    kind = "inline"

    @staticmethod
    def rows(g):
        return JointType.on_line(g)
