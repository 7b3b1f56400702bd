"""Cylindrical joint: parallel axes and point on the axis line (4 rows; 2 for a particle j)."""
from .base import JointType


class Cylindrical(JointType):
    kind = "cylindrical"

    @staticmethod
    def rows(g):
        return JointType.parallel_axes(g) + JointType.on_line(g)
