"""Bodies, particles and markers (frames fixed on a body)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError
from ..math.rotation import as_matrix
from ._check import inertia_matrix, scalar, vec3
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from typing import Any

    from .._types import Orientation, Vector
    from ..geometry.shape import Shape


@dataclass(eq=False)
class Marker:
    """A frame fixed on a body. `point` [m] and `orientation` (marker->ground) are given in ground at t=0."""

    name: str
    body: "Body"
    point: np.ndarray
    orientation: np.ndarray

    @property
    def s_B(self) -> np.ndarray:
        """Marker origin in body axes, relative to the body's centre of mass [m]."""
        return self.body.orientation.T @ (self.point - self.body.position)

    @property
    def R_BM(self) -> np.ndarray:
        """Marker axes relative to the body axes (3x3)."""
        return self.body.orientation.T @ self.orientation

    def __repr__(self) -> str:
        return f"Marker({self.body.name}.{self.name})"


@dataclass(eq=False)
class Body:
    """A rigid body or particle; all initial values in ground at t=0 (SI units).

    position: centre of mass [m]; orientation: body->ground 3x3; velocity: of the centre of mass [m/s];
    angular_velocity: in ground axes [rad/s]; inertia: about the centre of mass in body axes [kg m^2].
    `velocity_given` / `angular_velocity_given`: whether the user gave them (then assembly holds them;
    otherwise they are zero placeholders that assembly solves for).
    """

    name: str
    mass: float = 0.0
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    orientation: np.ndarray = field(default_factory=lambda: np.eye(3))
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    angular_velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    is_particle: bool = False
    is_ground: bool = False
    markers: dict = field(default_factory=dict)
    velocity_given: bool = False
    angular_velocity_given: bool = False
    shapes: dict = field(default_factory=dict)

    def add_shape(self, name: str, geometry: Any, center: Vector | None = None, orientation: Orientation = None,
                  density: float | None = None) -> Shape:
        """Place `geometry` (mb.Box, mb.Cylinder, mb.Capsule, mb.Ellipsoid, mb.Sphere(radius=...),
        mb.ConvexMesh, mb.Mesh) on this body: its origin at `center` [m] and its axes `orientation`
        (geometry -> ground), both in ground at t=0 (defaults: the body's centre of mass and axes).
        Returns the mbdsim.geometry.Shape, usable by Model.add_contact and drawn by the viewer.  With
        `density` [kg/m^3] the solid's mass [kg] and inertia about the body's centre of mass [kg m^2]
        (parallel-axis term included) are added to the body's (the body's position stays its centre of
        mass: place shapes with a density so that their centroid is there)."""
        from ..geometry.shape import add_shape
        return add_shape(self, name, geometry, center, orientation, density)

    def add_marker(self, name: str, point: Vector | None = None, orientation: Orientation = None) -> Marker:
        """Add a frame fixed on this body; point [m] and orientation (marker->ground) in ground at t=0."""
        from .loadexpr import check_name
        entity = f"marker '{self.name}.{name}'"
        check_name(entity, name, True)
        if name in self.markers:
            raise ModelError(entity, "name", "a marker of this name already exists on the body")
        pt = self.position.copy() if point is None else vec3(entity, "point", point)
        try:
            R = as_matrix(orientation)
        except ValueError as exc:
            raise ModelError(entity, "orientation", str(exc)) from None
        m = Marker(name, self, pt, R)
        self.markers[name] = m
        return m

    def __repr__(self) -> str:
        kind = "Ground" if self.is_ground else ("Particle" if self.is_particle else "Body")
        return f"{kind}({self.name!r})"


def shape_mass_properties(entity: str, shape, density, mass, inertia):
    """(mass, inertia) from a mb.Box / mb.Cylinder / mb.Sphere and a density [kg/m^3] (then mass and
    inertia must not be given), else the given mass and inertia unchanged."""
    from .shapes import MASS_SHAPES
    if shape is None:
        if density is not None:
            raise ModelError(entity, "density", "needs a shape (mb.Box, mb.Cylinder or mb.Sphere)")
        return mass, inertia
    if not isinstance(shape, MASS_SHAPES):
        raise ModelError(entity, "shape", f"expected mb.Box, mb.Cylinder or mb.Sphere, got {shape!r}")
    if density is None:
        raise ModelError(entity, "density", "a shape needs a density [kg/m^3]")
    if mass is not None or inertia is not None:
        raise ModelError(entity, "mass" if mass is not None else "inertia",
                         "give either mass and inertia, or a shape and a density")
    try:
        return shape.mass_properties(density)
    except ModelError as exc:
        raise ModelError(entity, exc.field, str(exc).split(": ", 1)[-1]) from None


MASS_RANGE = (1e-150, 1e150)   # kg, kg m^2: beyond, products of masses, lengths and accelerations over/underflow


def _in_range(entity, field, x, unit) -> None:
    """ModelError unless x is 0 or within MASS_RANGE: a mass of 1e300 kg ran and then could not be tabled
    (its reactions overflow double precision); inside the range every threshold of the solvers is relative."""
    lo, hi = MASS_RANGE
    if x != 0.0 and not lo <= x <= hi:
        raise ModelError(entity, field, f"{x:g} {unit} is outside what double-precision dynamics can carry "
                         f"({lo:g} .. {hi:g} {unit})")


def make_body(name, mass, inertia, position, orientation, velocity, angular_velocity, particle=False) -> Body:
    """Validate user input and build a Body (or a particle when particle=True).

    mass [kg] must be finite and >= 0 (> 0 for a particle; 0 is a massless link); booleans are refused.
    velocity / angular_velocity None: not given (free, solved at assembly), stored as zero."""
    entity = f"{'particle' if particle else 'body'} '{name}'"
    if mass is None:
        raise ModelError(entity, "mass", "is required (or give a shape and a density)")
    inertia = (0.0, 0.0, 0.0) if inertia is None else inertia
    m = scalar(entity, "mass", mass, minimum=0.0, strict=particle)
    J = np.zeros((3, 3)) if particle else inertia_matrix(entity, inertia)
    _in_range(entity, "mass", m, "kg")
    _in_range(entity, "inertia", float(np.max(np.abs(J))), "kg m^2")
    try:
        R = np.eye(3) if particle else as_matrix(orientation)
    except ValueError as exc:
        raise ModelError(entity, "orientation", str(exc)) from None
    given_w = angular_velocity is not None and not particle
    vel = np.zeros(3) if velocity is None else vec3(entity, "velocity", velocity)
    w = vec3(entity, "angular_velocity", angular_velocity) if given_w else np.zeros(3)
    return Body(name, m, J, vec3(entity, "position", position), R, vel, w, is_particle=particle,
                velocity_given=velocity is not None, angular_velocity_given=given_w)
