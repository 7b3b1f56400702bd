"""A geometry placed on a body (`Body.add_shape`): for contact, the viewer and mass properties.

The placement is given like every point of the API: `center` [m] (where the geometry's origin goes) and
`orientation` (geometry axes -> ground) in ground at t = 0, defaults the body's centre of mass and axes;
stored in body axes relative to the centre of mass (s_B [m], R_BG)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ModelError
from ..math.rotation import as_matrix
from ..model._check import vec3

GEOMETRY_NAMES = "mb.Box, mb.Cylinder, mb.Capsule, mb.Ellipsoid, mb.Sphere(radius=...), mb.ConvexMesh or mb.Mesh"


def geometry_types() -> tuple:
    from ..model.shapes import Box, Cylinder, Sphere
    from .meshes import ConvexMesh, Mesh
    from .primitives import Capsule, Ellipsoid
    return (Box, Cylinder, Capsule, Ellipsoid, Sphere, ConvexMesh, Mesh)


@dataclass(eq=False)
class Shape:
    """`geometry` fixed on `body`: origin at s_B [m] from the CM and axes R_BG (geometry -> body), body axes."""

    name: str
    body: Any
    geometry: Any
    s_B: np.ndarray
    R_BG: np.ndarray
    # as given to add_shape (for model files): centre [m] and axes in ground at t = 0 (None: the defaults),
    # density [kg/m^3] (None: no mass) and the mass [kg] / inertia [kg m^2] it added to the body
    given_center: np.ndarray | None = None
    given_orientation: np.ndarray | None = None
    density: float | None = None
    added_mass: tuple | None = None

    @property
    def center(self) -> np.ndarray:
        """The geometry's origin in ground at t = 0 [m]."""
        return self.body.position + self.body.orientation @ self.s_B

    @property
    def orientation(self) -> np.ndarray:
        """The geometry's axes in ground at t = 0 (geometry -> ground)."""
        return self.body.orientation @ self.R_BG

    def __repr__(self) -> str:
        return f"Shape({self.body.name}.{self.name}: {self.geometry!r})"


def add_shape(body, name: str, geometry, center=None, orientation=None, density=None) -> Shape:
    """Place `geometry` on `body` (see Body.add_shape); with `density` [kg/m^3] its mass and inertia (about
    the body's centre of mass, parallel-axis term included) are added to the body's."""
    from ..model.loadexpr import check_name
    entity = f"shape '{body.name}.{name}'"
    check_name(entity, name, False)
    if name in body.shapes:
        raise ModelError(entity, "name", "a shape of this name already exists on the body")
    if not isinstance(geometry, geometry_types()) or getattr(geometry, "body", None) is not None:
        raise ModelError(entity, "geometry", f"expected {GEOMETRY_NAMES}, got {geometry!r}")
    if body.is_particle and not _is_sphere(geometry):
        raise ModelError(entity, "geometry", "a particle has no orientation: only a sphere can be placed on it")
    c = body.position.copy() if center is None else vec3(entity, "center", center)
    try:
        R = body.orientation.copy() if orientation is None else as_matrix(orientation)
    except ValueError as exc:
        raise ModelError(entity, "orientation", str(exc)) from None
    A = body.orientation
    shape = Shape(name, body, geometry, A.T @ (c - body.position), A.T @ R,
                  None if center is None else c.copy(), None if orientation is None else R.copy())
    if density is not None:
        if body.is_ground:
            raise ModelError(entity, "density", "ground has no mass properties")
        m, I_B = _body_mass_properties(entity, shape, density)
        shape.density = float(density)
        shape.added_mass = (float(body.mass), np.array(body.inertia, float), m, I_B)
        body.mass = float(body.mass + m)
        body.inertia = np.asarray(body.inertia, float) + (0.0 if body.is_particle else I_B)
    body.shapes[name] = shape
    return shape


def _is_sphere(g) -> bool:
    from ..model.shapes import Sphere
    return isinstance(g, Sphere)


def _body_mass_properties(entity, shape, density):
    """(mass [kg], inertia about the body's CM in body axes [kg m^2]) of the shape's solid."""
    try:
        mp = shape.geometry.mass_properties(density)
    except ModelError as exc:
        raise ModelError(entity, exc.field, str(exc).split(": ", 1)[-1]) from None
    m, c_G, I_G = (mp[0], np.zeros(3), mp[1]) if len(mp) == 2 else mp
    d = shape.s_B + shape.R_BG @ c_G
    I_B = shape.R_BG @ I_G @ shape.R_BG.T
    return m, I_B + m * (d @ d * np.eye(3) - np.outer(d, d))
