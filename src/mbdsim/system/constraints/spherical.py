"""Spherical joint: common point (3 rows)."""
from .base import JointType


class Spherical(JointType):
    kind = "spherical"

    @staticmethod
    def rows(g):
        return JointType.point(g)
