"""Universal joint: common point, axis on i perpendicular to axis on j (4 rows)."""
from .base import JointType, RowSpec


class Universal(JointType):
    kind = "universal"

    @staticmethod
    def rows(g):
        rows = JointType.point(g)
        if not g.particle_j:
            rows.append(RowSpec("dot1", (g.h_i, g.extra), g.name))
        return rows
