"""Orientation joint primitive (Adams JPRIM ORIENTATION): body_j keeps its attitude relative to body_i
(3 rows, those of a fixed joint's rotation; the 3 relative translations are left).

Vectors of `JointGeom` are in the axes of the body they are fixed on; lengths in m.
"""
from .base import JointType, RowSpec


class Orientation(JointType):
    kind = "orientation"
    needs_orientation = True

    @staticmethod
    def rows(g):
        return [RowSpec("dot1", (g.f_i, g.g_j), g.name), RowSpec("dot1", (g.g_i, g.h_j), g.name),
                RowSpec("dot1", (g.h_i, g.f_j), g.name)]
