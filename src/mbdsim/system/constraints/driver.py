"""Motion drivers: the joint coordinate minus f(t) (1 row).

Rotation: theta of j about h_i (angle primitive); translation: h_i . (P_j - P_i) (slide primitive).
"""
from .base import RowSpec


def driver_rows(g, dof: str, fn, owner: str):
    """Row of a motion driver on joint geometry g for the coordinate `dof`."""
    if dof == "rotation":
        return [RowSpec("angle", (g.f_i, g.g_i, g.f_j), owner, fn)]
    return [RowSpec("slide", (g.h_i, g.s_i, g.s_j), owner, fn)]
