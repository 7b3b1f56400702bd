"""Contact and mass geometry fixed on bodies (issue 30).

Geometry classes describe a solid in its own axes, centred on its own origin: mb.Box, mb.Cylinder,
mb.Sphere(radius=...) (model.shapes), mb.Capsule, mb.Ellipsoid (`primitives`), mb.ConvexMesh and mb.Mesh
(`meshes`, through trimesh).  `Body.add_shape` places one on a body (`shape.Shape`); `pack` turns the
shapes into the arrays of the compiled narrow phase (solvers.fastcontact).  SI units: m, kg/m^3.
"""
from __future__ import annotations

from .meshes import ConvexMesh, Mesh
from .primitives import Capsule, Ellipsoid
from .shape import Shape

__all__ = ["Capsule", "ConvexMesh", "Ellipsoid", "Mesh", "Shape"]
