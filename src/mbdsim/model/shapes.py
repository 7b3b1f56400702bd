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
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .._types import Array


@dataclass(eq=False, init=False)
class Sphere:
    """A sphere of `radius` [m] fixed on `body` (a Body, particle or body name), centre `center` [m]
    in ground at t=0 (default: the body's centre of mass).  `mb.Sphere(radius=r)` (no body) is a geometry
    centred on its origin, placed with `Body.add_shape`."""

    body: Any
    radius: float
    center: np.ndarray | None

    def __init__(self, body=None, radius=None, center=None):
        if radius is None and body is not None and not isinstance(body, (str,)) and not hasattr(body, "name"):
            body, radius = None, body   # mb.Sphere(0.1): the geometry of radius 0.1
        entity = "sphere" if body is None else f"sphere on {getattr(body, 'name', body)!r}"
        if radius is None:
            raise ModelError(entity, "radius", "is required")
        if body is None and center is not None:
            raise ModelError(entity, "center", "a sphere geometry is centred on its origin: place it with "
                             "Body.add_shape(name, mb.Sphere(radius=r), center=...)")
        self.body = body
        self.radius = scalar(entity, "radius", radius, minimum=0.0, strict=True)
        self.center = None if center is None else vec3(entity, "center", center)

    def mass_properties(self, density: float) -> tuple[float, Array]:
        """(mass [kg], inertia about the centre 3x3 [kg m^2]) of a solid sphere of `density` [kg/m^3]."""
        m = _density(self, density) * 4.0 / 3.0 * np.pi * self.radius ** 3
        return float(m), np.eye(3) * (0.4 * m * self.radius ** 2)

    def __repr__(self) -> str:
        if self.body is None:
            return f"Sphere(radius={self.radius:g})"
        return f"Sphere({getattr(self.body, 'name', self.body)!r}, r={self.radius:g})"


@dataclass(eq=False, init=False)
class Box:
    """A solid box with edge lengths `size` = (a, b, c) [m] along the body x, y, z axes (for mass properties)."""

    size: np.ndarray

    def __init__(self, size):
        self.size = vec3("box", "size", size)
        if np.any(self.size <= 0):
            raise ModelError("box", "size", f"edge lengths must be > 0, got {tuple(self.size)}")

    def mass_properties(self, density: float) -> tuple[float, Array]:
        """(mass [kg], inertia about the centre in body axes 3x3 [kg m^2]) for `density` [kg/m^3]."""
        a, b, c = self.size
        m = _density(self, density) * a * b * c
        return float(m), np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) * (m / 12.0)

    def __repr__(self) -> str:
        return f"Box(size={tuple(float(x) for x in self.size)})"


@dataclass(eq=False, init=False)
class Cylinder:
    """A solid cylinder of `radius` and `length` [m] along the body `axis` ("x", "y" or "z")."""

    radius: float
    length: float
    axis: str

    def __init__(self, radius, length, axis="z"):
        from ..geometry.primitives import axis_vector
        self.radius = scalar("cylinder", "radius", radius, minimum=0.0, strict=True)
        self.length = scalar("cylinder", "length", length, minimum=0.0, strict=True)
        axis_vector("cylinder", axis)   # "x", "y", "z" or a 3-vector
        self.axis = axis if isinstance(axis, str) else tuple(float(x) for x in np.asarray(axis, float) /
                                                              np.linalg.norm(np.asarray(axis, float)))

    @property
    def axis_vector(self) -> np.ndarray:
        """The unit axis in the geometry's (body's) axes."""
        from ..geometry.primitives import axis_vector
        return axis_vector("cylinder", self.axis)

    def mass_properties(self, density: float) -> tuple[float, Array]:
        """(mass [kg], inertia about the centre in body axes 3x3 [kg m^2]) for `density` [kg/m^3]."""
        from ..geometry.primitives import axis_frame
        r, L = self.radius, self.length
        m = _density(self, density) * np.pi * r * r * L
        i_tr = m * (3 * r * r + L * L) / 12.0
        R = axis_frame(self.axis_vector)
        return float(m), R @ np.diag([i_tr, i_tr, 0.5 * m * r * r]) @ R.T

    def __repr__(self) -> str:
        return f"Cylinder(radius={self.radius:g}, length={self.length:g}, axis={self.axis!r})"


def _density(shape, density) -> float:
    return scalar(type(shape).__name__.lower(), "density", density, minimum=0.0, strict=True)


MASS_SHAPES = (Box, Cylinder, Sphere)


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
