"""Fixed joint: common point and locked relative orientation (6 rows; 3 for a particle j)."""
from .base import JointType, RowSpec


class Fixed(JointType):
    kind = "fixed"

    @staticmethod
    def rows(g):
        rows = JointType.point(g)
        if not g.particle_j:
            rows += [RowSpec("dot1", (g.f_i, g.g_j), g.name), RowSpec("dot1", (g.g_i, g.h_j), g.name),
                     RowSpec("dot1", (g.h_i, g.f_j), g.name)]
        return rows
