"""Planar joint: j's plane stays on i's plane with normal h_i (3 rows; 1 for a particle j)."""
from .base import JointType, RowSpec


class Planar(JointType):
    kind = "planar"

    @staticmethod
    def rows(g):
        rows = [] if g.particle_j else [RowSpec("dot1", (g.h_i, g.f_j), g.name),
                                        RowSpec("dot1", (g.h_i, g.g_j), g.name)]
        return rows + [RowSpec("dot2", (g.h_i, g.s_i, g.s_j), g.name)]
