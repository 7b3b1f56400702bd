"""Atpoint joint primitive (Adams JPRIM ATPOINT): the joint points of body_i and body_j coincide (3 rows,
a spherical joint's equations; the 3 relative rotations are left).

Vectors of `JointGeom` are in the axes of the body they are fixed on; lengths in m.
"""
from .base import JointType


class Atpoint(JointType):
    kind = "atpoint"

    @staticmethod
    def rows(g):
        return JointType.point(g)
