"""The joint-type contract: a joint type maps a joint's geometry to primitive constraint rows.

Evaluation is vectorised per primitive over all joints of the model (see `primitives` and
`mbdsim.system.equations`), so a compiled kernel can later replace a primitive without touching
the joint types.  Vectors in `JointGeom` are in the body axes of the body they are fixed on.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass
class JointGeom:
    """Geometry of one joint: frames bi, bj (ground = 0), joint point and axes (f, g, h) on each body."""

    name: str
    bi: int
    bj: int
    particle_i: bool
    particle_j: bool
    s_i: np.ndarray   # joint point on body i, body-i axes, from its CM [m]
    s_j: np.ndarray   # joint point on body j, body-j axes [m]
    f_i: np.ndarray
    g_i: np.ndarray
    h_i: np.ndarray
    f_j: np.ndarray
    g_j: np.ndarray
    h_j: np.ndarray
    extra: Any = None  # e.g. universal joint's axis_j in body-j axes


@dataclass
class RowSpec:
    """One primitive constraint of a joint: kind in {sph, dot1, dot2, angle, slide} and its vectors."""

    kind: str
    vecs: tuple
    owner: str
    fn: Any = None     # TimeFunction for driver rows (angle/slide targets)
    frames: tuple = (0, 0)  # (bi, bj) frame indices, set when the system is assembled

    @property
    def nrow(self) -> int:
        return 3 if self.kind == "sph" else 1


class JointType:
    """Base class: subclasses set `kind` and implement rows(g) -> list[RowSpec]."""

    kind = ""

    @staticmethod
    def rows(g: JointGeom) -> list[RowSpec]:  # pragma: no cover - abstract
        raise NotImplementedError

    # shared building blocks --------------------------------------------------
    @staticmethod
    def point(g: JointGeom) -> list[RowSpec]:
        return [RowSpec("sph", (g.s_i, g.s_j), g.name)]

    @staticmethod
    def parallel_axes(g: JointGeom) -> list[RowSpec]:
        """h_j stays parallel to h_i (2 rows), dropped when body j is a particle (no orientation)."""
        if g.particle_j:
            return []
        return [RowSpec("dot1", (g.f_i, g.h_j), g.name), RowSpec("dot1", (g.g_i, g.h_j), g.name)]

    @staticmethod
    def on_line(g: JointGeom) -> list[RowSpec]:
        """Point of j stays on the line (point, h_i) of i (2 rows)."""
        return [RowSpec("dot2", (g.f_i, g.s_i, g.s_j), g.name), RowSpec("dot2", (g.g_i, g.s_i, g.s_j), g.name)]
