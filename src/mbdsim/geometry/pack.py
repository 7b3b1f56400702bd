"""Shapes as the arrays of the compiled narrow phase (solvers.fastcontact, solvers.fastnarrow).

Each shape gets its frame, a local frame (origin c [m] and axes R, body axes, from the body's CM), three
parameters [m], its bounding radius [m] about c, and for polyhedra its local vertices [m] and face planes
(unit n, d [m]: n . x <= d inside).  A shape's local z is a cylinder's or capsule's axis and a plane's
outward normal.
"""
from __future__ import annotations

import numpy as np

from ..solvers.fastnarrow import BOX, CAPSULE, CYLINDER, ELLIPSOID, HULL, KIND_NAMES, MESH, PLANE, SPHERE, _BOX_SIGNS


def kind_name(shape) -> str:
    return KIND_NAMES[_local(shape)[0]]


def _geometry_kind(g):
    from ..model.shapes import Box, Cylinder, Sphere
    from .meshes import ConvexMesh, Mesh
    from .primitives import Capsule, Ellipsoid, axis_frame
    if isinstance(g, Sphere):
        return SPHERE, np.eye(3), (g.radius, 0.0, 0.0), None, None, g.radius
    if isinstance(g, Box):
        h = 0.5 * g.size
        pl = np.array([[*(s * e), h[k]] for k, e in enumerate(np.eye(3)) for s in (1.0, -1.0)])
        return BOX, np.eye(3), tuple(h), _BOX_SIGNS * h, pl, float(np.linalg.norm(h))
    if isinstance(g, (Cylinder, Capsule)):
        a = g.axis_vector if isinstance(g, Cylinder) else g.axis
        r, h = g.radius, 0.5 * g.length
        kind = CYLINDER if isinstance(g, Cylinder) else CAPSULE
        return kind, axis_frame(a), (r, h, 0.0), None, None, float(np.hypot(r, h) if kind == CYLINDER else r + h)
    if isinstance(g, Ellipsoid):
        return ELLIPSOID, np.eye(3), tuple(g.radii), None, None, float(max(g.radii))
    if isinstance(g, ConvexMesh):
        v = g.vertices
        return HULL, np.eye(3), (0.0, 0.0, 0.0), v, hull_planes(g.mesh), float(np.linalg.norm(v, axis=1).max())
    if isinstance(g, Mesh):
        v = g.vertices
        return MESH, np.eye(3), (0.0, 0.0, 0.0), v, None, float(np.linalg.norm(v, axis=1).max())
    raise TypeError(f"not a contact geometry: {g!r}")


def hull_planes(mesh) -> np.ndarray:
    """Distinct outward face planes (n, d) of a convex trimesh (coplanar triangles merged)."""
    n = np.asarray(mesh.face_normals, float)
    d = np.einsum("ij,ij->i", n, np.asarray(mesh.vertices)[mesh.faces[:, 0]])
    scale = max(float(np.abs(mesh.vertices).max()), 1e-300)
    key = np.round(np.column_stack([n, d / scale]), 9)
    _, idx = np.unique(key, axis=0, return_index=True)
    return np.column_stack([n, d])[np.sort(idx)]


def _local(shape):
    """(kind, c [m], R, params, verts, planes, bounding radius) of a resolved shape in body axes."""
    from .shape import Shape
    if isinstance(shape, Shape):
        kind, R0, p, v, pl, rad = _geometry_kind(shape.geometry)
        return kind, shape.s_B, shape.R_BG @ R0, p, v, pl, rad
    # a legacy model.shapes.AttachedShape (mb.Sphere(body, r, center) or mb.Plane(body, point, normal))
    if shape.kind == "sphere":
        return SPHERE, shape.s_B, np.eye(3), (shape.radius, 0.0, 0.0), None, None, shape.radius
    from .primitives import axis_frame
    return PLANE, shape.s_B, axis_frame(shape.n_B), (0.0, 0.0, 0.0), None, None, np.inf


def pack_contacts(sys, elems) -> tuple:
    """The packed tuple `sc` of fastcontact.shape_contacts for the ShapeContact elements `elems`:
    (frame (ns,), kind (ns,), c (ns, 3), R (ns, 3, 3), params (ns, 3), bounding radius (ns,),
    vertex ranges (ns, 2), vertices (nv, 3), plane ranges (ns, 2), planes (npl, 4), pairs (np, 2),
    pair parameters (np, 11: fastcontact.PAR_FIELDS))."""
    index, rows, verts, planes, pairs, par = {}, [], [], [], [], []
    nv = npl = 0
    for ei, e in enumerate(elems):
        for a, b in e.pairs:
            ids = []
            for s in (a, b):
                if id(s) not in index:
                    kind, c, R, p, v, pl, rad = _local(s)
                    v = np.zeros((0, 3)) if v is None else np.asarray(v, float)
                    pl = np.zeros((0, 4)) if pl is None else np.asarray(pl, float)
                    index[id(s)] = len(rows)
                    rows.append((sys.fid[s.body], kind, c, R, p, rad, (nv, nv + len(v)), (npl, npl + len(pl))))
                    verts.append(v)
                    planes.append(pl)
                    nv, npl = nv + len(v), npl + len(pl)
                ids.append(index[id(s)])
            pairs.append(ids)
            par.append(e.parameters() + (float(ei),))
    ns, n = len(rows), len(pairs)
    col = lambda k, dt=float: np.array([r[k] for r in rows], dtype=dt)  # noqa: E731
    return (col(0, np.int64).reshape(ns), col(1, np.int64).reshape(ns), col(2).reshape(ns, 3),
            col(3).reshape(ns, 3, 3), col(4).reshape(ns, 3), col(5).reshape(ns), col(6, np.int64).reshape(ns, 2),
            np.concatenate(verts).reshape(-1, 3) if verts else np.zeros((0, 3)),
            col(7, np.int64).reshape(ns, 2), np.concatenate(planes).reshape(-1, 4) if planes else np.zeros((0, 4)),
            np.array(pairs, np.int64).reshape(n, 2), np.array(par, float).reshape(n, 11))


def empty_contacts() -> tuple:
    """The packed tuple of a model without shape contact."""
    z = np.zeros
    return (z(0, np.int64), z(0, np.int64), z((0, 3)), z((0, 3, 3)), z((0, 3)), z(0), z((0, 2), np.int64),
            z((0, 3)), z((0, 2), np.int64), z((0, 4)), z((0, 2), np.int64), z((0, 11)))
