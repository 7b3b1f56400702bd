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


def _edges(kind, shape) -> tuple:
    """(edges (ne, 2: local vertex rows), normals (ne, 6): the outward unit normals of the two faces that
    meet at each edge, shape axes) of a box or hull (coplanar-face diagonals left out), else none."""
    if kind == BOX:
        ed = [(i, j) for i in range(8) for j in range(i + 1, 8)
              if np.count_nonzero(_BOX_SIGNS[i] != _BOX_SIGNS[j]) == 1]
        nrm = []
        for i, j in ed:
            a, b = [k for k in range(3) if _BOX_SIGNS[i][k] == _BOX_SIGNS[j][k]]   # the faces' axes
            nrm.append(np.concatenate([np.eye(3)[a] * _BOX_SIGNS[i][a], np.eye(3)[b] * _BOX_SIGNS[i][b]]))
        return np.array(ed, np.int64), np.array(nrm, float)
    if kind == HULL:
        m = shape.geometry.mesh
        sharp = np.asarray(m.face_adjacency_angles) > 1e-6
        fn = np.asarray(m.face_normals, float)[np.asarray(m.face_adjacency, np.int64)[sharp]]
        return np.asarray(m.face_adjacency_edges, np.int64)[sharp].reshape(-1, 2), fn.reshape(-1, 6)
    return np.zeros((0, 2), np.int64), np.zeros((0, 6))


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


# sizes of the narrow phase's scratch arrays (solvers.fastgjk, solvers.fastmesh)
_EPA_FACES, _EPA_EDGES, _STACK = 3000, 128, 256


def pack_contacts(sys, elems) -> tuple:
    """The packed tuple `sc` of fastcontact.shape_contacts for the ShapeContact elements `elems`:
    (0) frame (ns,), (1) kind (ns,), (2) c (ns, 3), (3) R (ns, 3, 3), (4) params (ns, 3), (5) bounding
    radius (ns,), (6) vertex ranges (ns, 2), (7) vertices (nv, 3), (8) plane ranges (ns, 2), (9) planes
    (npl, 4), (10) pairs (np, 2), (11) pair parameters (np, 11: fastcontact.PAR_FIELDS), (12) an empty
    record buffer (0, NREC) and (13) its counter (1,) (the step loop's), (14) local bounding boxes of hulls
    and meshes (ns, 6: centre, half extents [m]), (15, 16) each shape's partners: row ranges (ns + 1,) into
    (other shape, pair) rows sorted by the other shape, (17) poses (ns, 12), (18) ground bounding boxes
    (ns, 6), (19) sweep order per axis (3, ns), (20) broad-phase counters (4,) (solvers.fastbroad),
    (21) per shape: triangle range and node range of its mesh (ns, 4), (22) triangles (nt, 3: rows of (7)),
    (23-26) EPA scratch (solvers.fastgjk), (27) hierarchy node boxes (nn, 6), (28) node links (nn, 4)
    (geometry.bvh), (29) mesh contact slots (solvers.fastmesh), (30) the hierarchy walk's stack, (31) edge
    ranges (ns, 2) into (32) the edges of boxes and hulls (ne, 2: rows of (7); solvers.fastedges), (33) per
    triangle of (22) its ridge and peak bits (nt,: geometry.ridges, solvers.fastridge), (34) the node boxes of
    (27) swept along their triangles' inward normals (nn, 6: geometry.bvh.swept, solvers.fastmeshpair), (35) per
    triangle of (22) and corner e the triangle across its edge e, e + 1, or -1 (nt, 3: geometry.ridges.
    ridge_neighbours, the normal-cone test of solvers.fastridge.curved_ridge_points), (36) per edge of (32) the
    outward unit normals of its two faces (ne, 6: shape axes; the Gauss-map test of solvers.fastedges)."""
    from ..solvers.fastcontact import NREC
    from ..solvers.fastgjk import MAX_ITER
    from ..solvers.fastmesh import NSLOT, RIDGE_ROWS
    from ..solvers.fastmeshpair import SKIN
    from .bvh import build, swept
    from .ridges import ridge_masks, ridge_neighbours
    index, rows, verts, planes, pairs, par = {}, [], [], [], [], []
    lbox, meta, tris, nodes, links, eran, edges, rmask, sweep, nbr = [], [], [], [], [], [], [], [], [], []
    enrm = []
    nv = npl = nt = nn = ne = 0
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
                    lo, hi = (v.min(axis=0), v.max(axis=0)) if len(v) else (np.zeros(3), np.zeros(3))
                    lbox.append(np.concatenate([0.5 * (lo + hi), 0.5 * (hi - lo)]))
                    m = (nt, nt, nn, nn)
                    if kind == MESH:
                        f = np.asarray(s.geometry.faces, np.int64)
                        order, nb, nl = build(v, f)
                        tris.append(f[order] + nv)
                        rmask.append(ridge_masks(v, f[order]))
                        nb_t = ridge_neighbours(f[order])
                        nbr.append(np.where(nb_t >= 0, nb_t + nt, -1))
                        nodes.append(nb)
                        sweep.append(swept(v, f[order], nb, nl, SKIN * rad))
                        nl = nl.copy()
                        inner = nl[:, 0] >= 0
                        nl[inner, :2] += nn
                        nl[~inner, 2] += nt
                        links.append(nl)
                        m = (nt, nt + len(f), nn, nn + len(nb))
                        nt, nn = nt + len(f), nn + len(nb)
                    meta.append(m)
                    ed, en = _edges(kind, s)
                    ed = ed + nv
                    edges.append(ed)
                    enrm.append(en)
                    eran.append((ne, ne + len(ed)))
                    ne += len(ed)
                    verts.append(v)
                    planes.append(pl)
                    nv, npl = nv + len(v), npl + len(pl)
                ids.append(index[id(s)])
            pairs.append(ids)
            par.append(e.parameters() + (float(ei),))
    ns, n = len(rows), len(pairs)
    col = lambda k, dt=float: np.array([r[k] for r in rows], dtype=dt)  # noqa: E731
    adj = sorted([(i, j, p) for p, (i, j) in enumerate(pairs)] + [(j, i, p) for p, (i, j) in enumerate(pairs)])
    ptr = np.searchsorted(np.array([x[0] for x in adj], np.int64), np.arange(ns + 1)).astype(np.int64)
    mm = {i for i, j in pairs if rows[i][1] == MESH and rows[j][1] == MESH} | \
        {j for i, j in pairs if rows[i][1] == MESH and rows[j][1] == MESH}   # meshes whose vertices push
    ncand = max([8] + [r[6][1] - r[6][0] for k, r in enumerate(rows) if r[1] == HULL or k in mm])
    return (col(0, np.int64).reshape(ns), col(1, np.int64).reshape(ns), col(2).reshape(ns, 3),
            col(3).reshape(ns, 3, 3), col(4).reshape(ns, 3), col(5).reshape(ns), col(6, np.int64).reshape(ns, 2),
            np.concatenate(verts).reshape(-1, 3) if verts else np.zeros((0, 3)),
            col(7, np.int64).reshape(ns, 2), np.concatenate(planes).reshape(-1, 4) if planes else np.zeros((0, 4)),
            np.array(pairs, np.int64).reshape(n, 2), np.array(par, float).reshape(n, 11),
            np.zeros((0, NREC)), np.zeros(1, np.int64), np.array(lbox, float).reshape(ns, 6), ptr,
            np.array([x[1:] for x in adj], np.int64).reshape(-1, 2), np.zeros((ns, 12)), np.zeros((ns, 6)),
            np.tile(np.arange(ns, dtype=np.int64), (3, 1)), np.zeros(4, np.int64),
            np.array(meta, np.int64).reshape(ns, 4),
            np.concatenate(tris).reshape(-1, 3) if tris else np.zeros((0, 3), np.int64),
            np.zeros((MAX_ITER + 8, 6)), np.zeros((_EPA_FACES, 3), np.int64), np.zeros((_EPA_FACES, 5)),
            np.zeros((_EPA_EDGES, 2), np.int64),
            np.concatenate(nodes).reshape(-1, 6) if nodes else np.zeros((0, 6)),
            np.concatenate(links).reshape(-1, 4) if links else np.zeros((0, 4), np.int64),
            np.zeros((ncand * NSLOT + RIDGE_ROWS, 9)), np.zeros(_STACK, np.int64),
            np.array(eran, np.int64).reshape(ns, 2),
            np.concatenate(edges).reshape(-1, 2) if edges else np.zeros((0, 2), np.int64),
            np.concatenate(rmask) if rmask else np.zeros(0, np.int64),
            np.concatenate(sweep).reshape(-1, 6) if sweep else np.zeros((0, 6)),
            np.concatenate(nbr).reshape(-1, 3) if nbr else np.zeros((0, 3), np.int64),
            np.concatenate(enrm).reshape(-1, 6) if enrm else np.zeros((0, 6)))


def empty_contacts() -> tuple:
    """The packed tuple of a model without shape contact (the same types, no shapes)."""
    from ..solvers.fastcontact import NREC
    z, i = np.zeros, np.int64
    return (z(0, i), z(0, i), z((0, 3)), z((0, 3, 3)), z((0, 3)), z(0), z((0, 2), i), z((0, 3)), z((0, 2), i),
            z((0, 4)), z((0, 2), i), z((0, 11)), z((0, NREC)), z(1, i), z((0, 6)), z(1, i), z((0, 2), i),
            z((0, 12)), z((0, 6)), z((3, 0), i), z(4, i), z((0, 4), i), z((0, 3), i), z((0, 6)), z((0, 3), i),
            z((0, 5)), z((0, 2), i), z((0, 6)), z((0, 4), i), z((0, 9)), z(0, i), z((0, 2), i), z((0, 2), i),
            z(0, i), z((0, 6)), z((0, 3), i), z((0, 6)))
