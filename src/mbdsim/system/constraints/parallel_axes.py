"""Parallel-axes joint primitive (Adams JPRIM PARALLEL_AXES): h_j stays parallel to h_i (2 rows;
the 3 translations and the rotation about the axis are left).

Vectors of `JointGeom` are in the axes of the body they are fixed on; lengths in m.
"""
from .base import JointType


class ParallelAxes(JointType):
    kind = "parallel_axes"
    needs_orientation = True

    @staticmethod
    def rows(g):
        return JointType.parallel_axes(g)
