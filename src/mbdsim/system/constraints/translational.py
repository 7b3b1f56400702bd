"""Translational joint: cylindrical plus no rotation about the axis (5 rows; 2 for a particle j)."""
from .base import JointType, RowSpec


class Translational(JointType):
    kind = "translational"

    @staticmethod
    def rows(g):
        rows = JointType.parallel_axes(g) + JointType.on_line(g)
        if not g.particle_j:
            rows.append(RowSpec("dot1", (g.f_i, g.g_j), g.name))
        return rows
