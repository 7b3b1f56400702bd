"""Revolute joint: common point and parallel axes (5 rows; 3 when body j is a particle)."""
from .base import JointType


class Revolute(JointType):
    kind = "revolute"

    @staticmethod
    def rows(g):
        return JointType.point(g) + JointType.parallel_axes(g)
