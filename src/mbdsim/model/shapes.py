"""Contact shapes fixed on a body: spheres and (infinite) planes.

Geometry is given in ground axes at t=0 (like joints and markers) and stored in body axes when the
shape is attached to a model by `Model.add_contact`.  SI units: m.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ModelError
from ._check import scalar, vec3


@dataclass(eq=False, init=False)
class Sphere:
    """A sphere of `radius` [m] fixed on `body` (a Body, particle or body name), centre `center` [m]
    in ground at t=0 (default: the body's centre of mass)."""

    body: Any
    radius: float
    center: np.ndarray | None

    def __init__(self, body, radius, center=None):
        entity = f"sphere on {getattr(body, 'name', body)!r}"
        self.body = body
        self.radius = scalar(entity, "radius", radius, minimum=0.0, strict=True)
        self.center = None if center is None else vec3(entity, "center", center)

    def __repr__(self) -> str:
        return f"Sphere({getattr(self.body, 'name', self.body)!r}, r={self.radius:g})"


@dataclass(eq=False, init=False)
class Plane:
    """An infinite plane fixed on `body` through `point` [m] with outward `normal` (solid side is -normal),
    both in ground at t=0."""

    body: Any
    point: np.ndarray
    normal: np.ndarray

    def __init__(self, body, point, normal):
        entity = f"plane on {getattr(body, 'name', body)!r}"
        self.body = body
        self.point = vec3(entity, "point", point)
        self.normal = vec3(entity, "normal", normal, unit=True)

    def __repr__(self) -> str:
        return f"Plane({getattr(self.body, 'name', self.body)!r}, n={self.normal})"


@dataclass(eq=False)
class AttachedShape:
    """A shape resolved on a model body: kind "sphere" or "plane", data in body axes from the CM."""

    kind: str
    body: Any
    s_B: np.ndarray            # sphere centre or plane point, body axes [m]
    n_B: np.ndarray | None     # plane normal, body axes (None for a sphere)
    radius: float = 0.0        # sphere radius [m]
    source: Any = None         # the user's Sphere/Plane


def attach(entity: str, field: str, shape, body) -> AttachedShape:
    """Resolve a user's Sphere/Plane on `body` (the model's Body object)."""
    A, r = body.orientation, body.position
    if isinstance(shape, Sphere):
        c = r if shape.center is None else shape.center
        return AttachedShape("sphere", body, A.T @ (c - r), None, shape.radius, shape)
    if isinstance(shape, Plane):
        if body.is_particle:
            raise ModelError(entity, field, "a plane needs a rigid body or ground (a particle has no orientation)")
        return AttachedShape("plane", body, A.T @ (shape.point - r), A.T @ shape.normal, 0.0, shape)
    raise ModelError(entity, field, f"expected mb.Sphere or mb.Plane, got {shape!r}")
