"""Analytic solids for contact and mass properties: capsule and ellipsoid (box, cylinder and sphere live in
model.shapes).  Each is given in its own axes, centred on its origin; SI units (m, kg/m^3)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..model._check import scalar, vec3


def axis_vector(entity: str, axis) -> np.ndarray:
    """Unit axis of "x", "y", "z" or a 3-vector (ModelError naming entity.axis otherwise)."""
    if isinstance(axis, str):
        if axis not in ("x", "y", "z"):
            raise ModelError(entity, "axis", f"must be 'x', 'y', 'z' or a 3-vector, got {axis!r}")
        return np.eye(3)["xyz".index(axis)]
    return vec3(entity, "axis", axis, unit=True)


def axis_frame(a: np.ndarray) -> np.ndarray:
    """Rotation whose third column is the unit vector a (geometry's local z = its axis)."""
    h = a / np.linalg.norm(a)
    f = np.cross(h, (1.0, 0.0, 0.0) if abs(h[0]) < 0.9 else (0.0, 1.0, 0.0))
    f /= np.linalg.norm(f)
    return np.column_stack([f, np.cross(h, f), h])


def _density(name, density) -> float:
    return scalar(name, "density", density, minimum=0.0, strict=True)


@dataclass(eq=False, init=False)
class Capsule:
    """A capsule: the points within `radius` [m] of a segment of `length` [m] (between the two hemisphere
    centres) along `axis` ("x", "y", "z" or a 3-vector in the geometry's axes), centred on the origin."""

    radius: float
    length: float
    axis: np.ndarray

    def __init__(self, radius, length, axis="z"):
        self.radius = scalar("capsule", "radius", radius, minimum=0.0, strict=True)
        self.length = scalar("capsule", "length", length, minimum=0.0)
        self.axis = axis_vector("capsule", axis)

    def mass_properties(self, density: float) -> tuple[float, np.ndarray]:
        """(mass [kg], inertia about the centre in the geometry's axes 3x3 [kg m^2]) for `density` [kg/m^3]:
        a cylinder plus two hemispheres (each hemisphere's CM 3r/8 from the cap centre)."""
        rho, r, L = _density("capsule", density), self.radius, self.length
        mc, mh = rho * np.pi * r * r * L, rho * 2.0 / 3.0 * np.pi * r ** 3
        i_ax = 0.5 * mc * r * r + 2 * 0.4 * mh * r * r
        i_tr = mc * (3 * r * r + L * L) / 12.0 + 2 * mh * (0.4 * r * r + 0.25 * L * L + 0.375 * L * r)
        R = axis_frame(self.axis)
        return float(mc + 2 * mh), R @ np.diag([i_tr, i_tr, i_ax]) @ R.T

    def __repr__(self) -> str:
        return f"Capsule(radius={self.radius:g}, length={self.length:g}, axis={tuple(self.axis)})"


@dataclass(eq=False, init=False)
class Ellipsoid:
    """A solid ellipsoid with semi-axes `radii` = (a, b, c) [m] along the geometry's x, y, z axes."""

    radii: np.ndarray

    def __init__(self, radii):
        self.radii = vec3("ellipsoid", "radii", radii)
        if np.any(self.radii <= 0):
            raise ModelError("ellipsoid", "radii", f"semi-axes must be > 0, got {tuple(self.radii)}")

    def mass_properties(self, density: float) -> tuple[float, np.ndarray]:
        """(mass [kg], inertia about the centre in the geometry's axes 3x3 [kg m^2]) for `density` [kg/m^3]."""
        a, b, c = self.radii
        m = _density("ellipsoid", density) * 4.0 / 3.0 * np.pi * a * b * c
        return float(m), np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) * (m / 5.0)

    def __repr__(self) -> str:
        return f"Ellipsoid(radii={tuple(float(x) for x in self.radii)})"
