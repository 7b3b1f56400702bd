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


def _num(a) -> list:
    return [float(f"{x:.6g}") for x in np.asarray(a, float).ravel()]


def describe(geometry) -> dict:
    """The geometry's kind and dimensions [m] in its own axes, for the viewer's scene data: box size,
    sphere radius, ellipsoid radii, cylinder / capsule radius, length and axis, mesh vertex and face counts."""
    from ..model.shapes import Box, Cylinder, Sphere
    from .meshes import ConvexMesh, Mesh
    from .primitives import Capsule, Ellipsoid
    if isinstance(geometry, Box):
        return {"kind": "box", "size": _num(geometry.size)}
    if isinstance(geometry, Sphere):
        return {"kind": "sphere", "radius": float(geometry.radius)}
    if isinstance(geometry, Ellipsoid):
        return {"kind": "ellipsoid", "radii": _num(geometry.radii)}
    if isinstance(geometry, (Cylinder, Capsule)):
        axis = geometry.axis_vector if isinstance(geometry, Cylinder) else geometry.axis
        return {"kind": type(geometry).__name__.lower(), "radius": float(geometry.radius),
                "length": float(geometry.length), "axis": _num(axis)}
    kind = "convex_mesh" if isinstance(geometry, ConvexMesh) else "mesh"
    out = {"kind": kind, "vertices": len(geometry.vertices), "faces": len(geometry.mesh.faces)}
    if getattr(geometry, "path", None):
        out["path"] = geometry.path
    return out


def body_meshes(body) -> list[dict]:
    """The viewer's dicts of the shapes placed on `body`: kind "mesh" (drawn as triangles), "vertices"
    (flat x, y, z [m]) in body axes from the centre of mass, so the page moves them with the body's pose
    of each frame; "geometry" (`describe`) and "placement" in body axes, {"center" [m] from the CM,
    "quat" (geometry axes -> body axes, x, y, z, w as three.js)}, already applied to the vertices."""
    from scipy.spatial.transform import Rotation
    out = []
    for sh in body.shapes.values():
        v, f = tessellate(sh.geometry)
        vb = v @ sh.R_BG.T + sh.s_B
        out.append({"kind": "mesh", "name": sh.name, "local": [0.0, 0.0, 0.0], "geometry": describe(sh.geometry),
                    "placement": {"center": _num(sh.s_B), "quat": _num(Rotation.from_matrix(sh.R_BG).as_quat())},
                    "vertices": _num(vb), "faces": [int(i) for i in f.ravel()]})
    return out
