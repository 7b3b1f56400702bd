"""Triangle meshes of placed shapes for the viewer (trimesh's primitives), in body axes [m]."""
from __future__ import annotations

import numpy as np


def tessellate(geometry) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (n, 3) [m], faces (m, 3)) of a geometry in its own axes."""
    import trimesh
    from ..model.shapes import Box, Cylinder, Sphere
    from .meshes import ConvexMesh, Mesh
    from .primitives import Capsule, Ellipsoid, axis_frame
    if isinstance(geometry, Box):
        m = trimesh.creation.box(extents=geometry.size)
    elif isinstance(geometry, Sphere):
        m = trimesh.creation.icosphere(subdivisions=2, radius=geometry.radius)
    elif isinstance(geometry, Ellipsoid):
        m = trimesh.creation.icosphere(subdivisions=2, radius=1.0)
        m.vertices = m.vertices * geometry.radii
    elif isinstance(geometry, (Cylinder, Capsule)):
        if isinstance(geometry, Cylinder):
            m = trimesh.creation.cylinder(radius=geometry.radius, height=geometry.length, sections=32)
            a = geometry.axis_vector
        else:
            m = trimesh.creation.capsule(height=geometry.length, radius=geometry.radius, count=[16, 16])
            a = geometry.axis
        m.vertices = m.vertices @ axis_frame(a).T
    elif isinstance(geometry, (ConvexMesh, Mesh)):
        m = geometry.mesh
    else:   # pragma: no cover - add_shape accepts only the types above
        raise TypeError(f"no mesh for {geometry!r}")
    return np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)


def body_meshes(body) -> list[dict]:
    """The viewer's dicts of the shapes placed on `body`: kind "mesh", vertices in body axes (from the CM)."""
    out = []
    for sh in body.shapes.values():
        v, f = tessellate(sh.geometry)
        vb = v @ sh.R_BG.T + sh.s_B
        out.append({"kind": "mesh", "name": sh.name, "local": [0.0, 0.0, 0.0],
                    "vertices": [float(f"{x:.6g}") for x in vb.ravel()], "faces": [int(i) for i in f.ravel()]})
    return out
