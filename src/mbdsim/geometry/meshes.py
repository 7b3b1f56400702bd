"""Polyhedral solids: the convex hull of points (ConvexMesh) and triangle meshes (Mesh, STL/OBJ/PLY read by
trimesh, convex or not).  Vertices in the geometry's axes [m]; mass properties of closed meshes by trimesh."""
from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..model._check import scalar


def _points(entity, field, values) -> np.ndarray:
    try:
        v = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(entity, field, f"expected an (n, 3) array of points [m], got {values!r:.80}") from None
    if v.ndim != 2 or v.shape[1] != 3 or len(v) < 4:
        raise ModelError(entity, field, f"expected an (n, 3) array of at least 4 points [m], got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ModelError(entity, field, "points must be finite")
    return v


def _hull(entity, field, v):
    import trimesh
    from scipy.spatial import ConvexHull, QhullError
    try:
        h = ConvexHull(v)
    except (QhullError, ValueError) as exc:
        raise ModelError(entity, field, f"the points span no volume (flat or repeated): {str(exc).splitlines()[0]}") \
            from None
    mesh = trimesh.Trimesh(v, h.simplices, process=True)
    trimesh.repair.fix_normals(mesh)
    return mesh


def _mass(entity, mesh, density):
    rho = scalar(entity, "density", density, minimum=0.0, strict=True)
    if not mesh.is_watertight or mesh.volume <= 0:
        raise ModelError(entity, "density", "mass properties need a closed (watertight) mesh with outward faces")
    return rho * float(mesh.volume), np.asarray(mesh.center_mass, float), rho * np.asarray(mesh.moment_inertia, float)


@dataclass(eq=False, init=False)
class ConvexMesh:
    """The convex hull of `vertices` ((n, 3) [m], the geometry's axes); `vertices` keeps the hull's corners."""

    vertices: np.ndarray

    def __init__(self, vertices):
        v = _points("convex mesh", "vertices", vertices)
        self.mesh = _hull("convex mesh", "vertices", v)
        self.vertices = np.asarray(self.mesh.vertices, float)

    def mass_properties(self, density: float) -> tuple[float, np.ndarray, np.ndarray]:
        """(mass [kg], centroid [m], inertia about the centroid 3x3 [kg m^2]) for `density` [kg/m^3]."""
        return _mass("convex mesh", self.mesh, density)

    def __repr__(self) -> str:
        return f"ConvexMesh({len(self.vertices)} vertices)"


@dataclass(eq=False, init=False)
class Mesh:
    """A triangle mesh: a file path (STL, OBJ, PLY, ... through trimesh; `scale` multiplies its coordinates
    into m) or (n, 3) vertices [m] with `faces` (m, 3) vertex indices.  It need not be convex; closed
    meshes also give mass properties."""

    vertices: np.ndarray
    faces: np.ndarray
    path: str | None

    def __init__(self, path_or_vertices, faces=None, scale: float = 1.0):
        import trimesh
        entity = "mesh"
        s = scalar(entity, "scale", scale, minimum=0.0, strict=True)
        if isinstance(path_or_vertices, (str, os.PathLike)):
            self.path = os.fspath(path_or_vertices)
            self.abspath = os.path.abspath(self.path)   # model files store it relative to their folder
            entity = f"mesh {self.path!r}"
            if faces is not None:
                raise ModelError(entity, "faces", "a mesh file carries its own faces")
            if not os.path.isfile(self.path):
                raise ModelError(entity, "path", "no such file")
            try:
                mesh = trimesh.load_mesh(self.path, process=True)
            except Exception as exc:   # trimesh raises many types on bad files
                raise ModelError(entity, "path", f"cannot read the mesh: {exc}") from None
            if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
                raise ModelError(entity, "path", "the file holds no triangle mesh")
            mesh.apply_scale(s)
        else:
            self.path = self.abspath = None
            v = _points(entity, "vertices", path_or_vertices) * s
            if faces is None:
                raise ModelError(entity, "faces", "give the triangles (m, 3) vertex indices with the vertices")
            try:
                f = np.asarray(faces, dtype=np.int64)
            except (TypeError, ValueError):
                raise ModelError(entity, "faces", f"expected (m, 3) vertex indices, got {faces!r:.80}") from None
            if f.ndim != 2 or f.shape[1] != 3 or len(f) == 0 or f.min() < 0 or f.max() >= len(v):
                raise ModelError(entity, "faces", f"expected (m, 3) indices into the {len(v)} vertices")
            mesh = trimesh.Trimesh(v, f, process=True)
        self.mesh, self.scale = mesh, s
        self.vertices = np.asarray(mesh.vertices, float)
        self.faces = np.asarray(mesh.faces, np.int64)

    def mass_properties(self, density: float) -> tuple[float, np.ndarray, np.ndarray]:
        """(mass [kg], centroid [m], inertia about the centroid 3x3 [kg m^2]) for `density` [kg/m^3]."""
        return _mass(f"mesh {self.path!r}" if self.path else "mesh", self.mesh, density)

    def __repr__(self) -> str:
        return f"Mesh({self.path + ', ' if self.path else ''}{len(self.vertices)} vertices, {len(self.faces)} faces)"
