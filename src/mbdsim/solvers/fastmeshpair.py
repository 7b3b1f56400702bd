"""Two triangle meshes against each other (issue 30; a penalty approximation, fine for finely tessellated meshes).

The vertices of each mesh are the candidate points against the other's triangles (solvers.fastmesh:
`point_below` into the slots of sc[29]), counted only when less than SKIN times the smaller of the two
bounding radii below a triangle (a vertex outside a closed mesh is behind its far faces, but deeper than
that); `mesh_pair` keeps, per vertex, the direction of least depth (the nearest face).

`mesh_mesh_points` walks the two bounding-volume hierarchies (geometry.bvh) together: pairs of nodes whose
boxes overlap (x's node box, in x's axes, taken into msh's axes as the box around it, against msh's node box
swept by its triangles moved SKIN x its bounding radius along their inward normals, sc[34], so that a vertex
up to the depth cap below a triangle is met however thin the leaves), splitting the larger
node of a pair first, down to pairs of leaves, whose triangles' vertices (of x) are tested against the
triangles (of msh).  The cost grows with the size of the touching region, not with the product of the
meshes' sizes.

Coarse meshes touch edge across edge with no vertex inside the other (a prism's roof edge resting crosswise
on another's, a mesh box's edge landing on a mesh ridge): in the same walk (once, not for both sides) the
pairs of sharp ridges (geometry.ridges; faces bent by more than SHARP_COS, so that a finely tessellated
smooth surface keeps its vertex contacts only) of the two leaves' triangles that cross (fastridge.crossing:
the closest points of the two edges inside both), along their common normal L out of msh's ridge's normal
cone and into x's (fastridge.in_cone), less than the skin deep: one point midway between the two edges,
depth L . (X - Y), normal L.  The corners of a contact polygon where two edges cross (a mesh box resting
off-centre on another) are such points too.
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from .fastlaw import _apply
from .fastmesh import NSLOT, clear_slots, point_below, slot_means, triangle
from .fastnarrow import to_ground, to_local
from .fastridge import cone_crossing, in_cone

SKIN = 0.5        # a mesh's vertex counts below another mesh's triangle to SKIN x the smaller bounding radius
SHARP_COS = 0.94  # a ridge whose faces' normals are closer than this (cosine; about 20 degrees) has no edge contact


@kernel(_nrt=False)
def _relative(Pm, Px):
    """Rotation from x's local axes to msh's (Gm^T Gx, row-major 9-tuple)."""
    return (Pm[3] * Px[3] + Pm[6] * Px[6] + Pm[9] * Px[9], Pm[3] * Px[4] + Pm[6] * Px[7] + Pm[9] * Px[10],
            Pm[3] * Px[5] + Pm[6] * Px[8] + Pm[9] * Px[11],
            Pm[4] * Px[3] + Pm[7] * Px[6] + Pm[10] * Px[9], Pm[4] * Px[4] + Pm[7] * Px[7] + Pm[10] * Px[10],
            Pm[4] * Px[5] + Pm[7] * Px[8] + Pm[10] * Px[11],
            Pm[5] * Px[3] + Pm[8] * Px[6] + Pm[11] * Px[9], Pm[5] * Px[4] + Pm[8] * Px[7] + Pm[11] * Px[10],
            Pm[5] * Px[5] + Pm[8] * Px[8] + Pm[11] * Px[11])


@kernel(_nrt=False)
def _disjoint(swept, nodes, na, nb, R, o0, o1, o2):
    """Whether node na's swept box (msh's axes) and the box around node nb (x's axes; R, o: x's axes and
    origin in msh's) do not overlap."""
    c0, c1, c2 = 0.5 * (nodes[nb, 0] + nodes[nb, 3]), 0.5 * (nodes[nb, 1] + nodes[nb, 4]), \
        0.5 * (nodes[nb, 2] + nodes[nb, 5])
    h0, h1, h2 = 0.5 * (nodes[nb, 3] - nodes[nb, 0]), 0.5 * (nodes[nb, 4] - nodes[nb, 1]), \
        0.5 * (nodes[nb, 5] - nodes[nb, 2])
    l0 = o0 + R[0] * c0 + R[1] * c1 + R[2] * c2
    l1 = o1 + R[3] * c0 + R[4] * c1 + R[5] * c2
    l2 = o2 + R[6] * c0 + R[7] * c1 + R[8] * c2
    e0 = abs(R[0]) * h0 + abs(R[1]) * h1 + abs(R[2]) * h2
    e1 = abs(R[3]) * h0 + abs(R[4]) * h1 + abs(R[5]) * h2
    e2 = abs(R[6]) * h0 + abs(R[7]) * h1 + abs(R[8]) * h2
    return l0 + e0 < swept[na, 0] or l0 - e0 > swept[na, 3] or l1 + e1 < swept[na, 1] or \
        l1 - e1 > swept[na, 4] or l2 + e2 < swept[na, 2] or l2 - e2 > swept[na, 5]


@kernel(_nrt=False)
def _size(nodes, n):
    return nodes[n, 3] - nodes[n, 0] + nodes[n, 4] - nodes[n, 1] + nodes[n, 5] - nodes[n, 2]


@kernel(_nrt=False)
def _sharp(sc, t, j):
    """Whether the ridge from corner j of triangle t bends by more than SHARP_COS (its two faces' normals)."""
    verts, tri, nbr = sc[7], sc[22], sc[35]
    nb = nbr[t, j]
    if nb < 0:
        return False
    cs, n0, n1, n2 = 0.0, 0.0, 0.0, 1.0
    for k in range(2):
        f = t if k == 0 else nb
        a0, a1, a2 = verts[tri[f, 0], 0], verts[tri[f, 0], 1], verts[tri[f, 0], 2]
        b0, b1, b2 = verts[tri[f, 1], 0] - a0, verts[tri[f, 1], 1] - a1, verts[tri[f, 1], 2] - a2
        c0, c1, c2 = verts[tri[f, 2], 0] - a0, verts[tri[f, 2], 1] - a1, verts[tri[f, 2], 2] - a2
        m0, m1, m2 = b1 * c2 - b2 * c1, b2 * c0 - b0 * c2, b0 * c1 - b1 * c0
        L = np.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
        if not L > 0.0:
            return False
        if k == 0:
            n0, n1, n2 = m0 / L, m1 / L, m2 / L
        else:
            cs = (n0 * m0 + n1 * m1 + n2 * m2) / L
    return cs < SHARP_COS


@kernel(_nrt=False)
def _ridge_crossings(sc, x, Px, Pm, t, u, cap, S, s):
    """The sharp owned ridges of triangle t (mesh msh, pose Pm) crossing those of triangle u (mesh x, pose Px)
    (fastridge.crossing: the closest points X, Y inside both edges) with their common normal L out of msh's
    ridge cone and into x's (-L in x's ridge cone), less than cap [m] deep (D = L . (X - Y) > 0): rows from s of
    S (used, D, the midpoint, L from msh into x, weight 1) while it has room; returns the next row."""
    rm, verts, tri = sc[33], sc[7], sc[22]
    for j in range(3):
        if not rm[t] & (1 << j) or not _sharp(sc, t, j):
            continue
        a0, a1, a2 = to_ground(Pm, verts[tri[t, j], 0], verts[tri[t, j], 1], verts[tri[t, j], 2])
        v = tri[t, (j + 1) % 3]
        b0, b1, b2 = to_ground(Pm, verts[v, 0], verts[v, 1], verts[v, 2])
        for i in range(3):
            if not rm[u] & (1 << i) or s >= S.shape[0] or not _sharp(sc, u, i):
                continue
            c0, c1, c2 = to_ground(Px, verts[tri[u, i], 0], verts[tri[u, i], 1], verts[tri[u, i], 2])
            v = tri[u, (i + 1) % 3]
            e0, e1, e2 = to_ground(Px, verts[v, 0], verts[v, 1], verts[v, 2])
            ok, X0, X1, X2, Y0, Y1, Y2, L0, L1, L2 = cone_crossing(sc, Pm, t, j, a0, a1, a2, b0, b1, b2, c0, c1, c2,
                                                                   e0, e1, e2)
            if not ok:
                continue
            D = L0 * (X0 - Y0) + L1 * (X1 - Y1) + L2 * (X2 - Y2)
            if not (D > 0.0 and D < cap) or not in_cone(sc, Px, u, i, -L0, -L1, -L2):
                continue
            S[s, 0], S[s, 1], S[s, 2], S[s, 3], S[s, 4] = 1.0, D, 0.5 * (X0 + Y0), 0.5 * (X1 + Y1), 0.5 * (X2 + Y2)
            S[s, 5], S[s, 6], S[s, 7], S[s, 8] = L0, L1, L2, 1.0
            s += 1
    return s


@kernel(_nrt=False)
def _leaves(sc, x, Px, Pm, ta, na_, tb, nb_, S, cap, edges, s):
    """The vertices of x's triangles tb..tb + nb_ against msh's triangles ta..ta + na_ and, with edges, their
    ridges crossing (`_ridge_crossings`, rows from s); returns the next free edge row."""
    sv, verts, tri, rm = sc[6], sc[7], sc[22], sc[33]
    for t in range(ta, ta + na_):
        a0, a1, a2, b0, b1, b2, c0, c1, c2, m0, m1, m2, ok = triangle(sc, Pm, t)
        if not ok:
            continue
        for u in range(tb, tb + nb_):
            for j in range(3):
                v = tri[u, j]
                y0, y1, y2 = to_ground(Px, verts[v, 0], verts[v, 1], verts[v, 2])
                point_below(S, v - sv[x, 0], y0, y1, y2, a0, a1, a2, b0, b1, b2, c0, c1, c2, m0, m1, m2, cap)
            if edges and rm[t] & 7 and rm[u] & 7:
                s = _ridge_crossings(sc, x, Px, Pm, t, u, cap, S, s)
    return s


@kernel(_nrt=False)
def mesh_mesh_points(sc, x, msh, Px, Pm, edges):
    """The vertices of mesh x (pose Px) below the triangles of mesh msh (pose Pm) into the slot rows of
    sc[29], NSLOT per vertex of x, and with edges after them the two meshes' ridges crossing (module
    docstring); returns (nrow, nxt): the vertices' slot rows 0..nrow, the crossings' rows nrow..nxt."""
    sv, rad, meta, nodes, links, S, stack, swept = sc[6], sc[5], sc[21], sc[27], sc[28], sc[29], sc[30], sc[34]
    nrow = (sv[x, 1] - sv[x, 0]) * NSLOT
    if nrow > S.shape[0] or meta[msh, 3] <= meta[msh, 2] or meta[x, 3] <= meta[x, 2]:
        return 0, 0
    clear_slots(S, nrow)
    cap = SKIN * min(rad[x], rad[msh])
    R = _relative(Pm, Px)
    o0, o1, o2 = to_local(Pm, Px[0], Px[1], Px[2])
    stack[0], stack[1] = meta[msh, 2], meta[x, 2]
    top, nxt = 2, nrow
    while top > 0:
        top -= 2
        na, nb = stack[top], stack[top + 1]
        if _disjoint(swept, nodes, na, nb, R, o0, o1, o2):
            continue
        la, lb = links[na, 0] < 0, links[nb, 0] < 0
        if la and lb:
            nxt = _leaves(sc, x, Px, Pm, links[na, 2], links[na, 3], links[nb, 2], links[nb, 3], S, cap,
                          edges, nxt)
        elif top + 4 <= stack.shape[0]:
            if not la and (lb or _size(nodes, na) >= _size(nodes, nb)):
                stack[top], stack[top + 1], stack[top + 2], stack[top + 3] = links[na, 0], nb, links[na, 1], nb
            else:
                stack[top], stack[top + 1], stack[top + 2], stack[top + 3] = na, links[nb, 0], na, links[nb, 1]
            top += 4
    slot_means(S, nrow)
    return nrow, nxt


@kernel(_nrt=False)
def mesh_pair(sc, pair, a, b, Pa, Pb, r, A, rd, w, rigid, F, rec, nrec):
    """Two triangle meshes (a penalty approximation for finely tessellated meshes): the vertices of each
    below the other's triangles (`mesh_mesh_points`: the two hierarchies walked together, depth capped at a
    skin), per vertex the direction of least depth (the nearest face of a closed mesh), and (once) their
    sharp ridges crossing, each a point of the contact law (solvers.fastlaw)."""
    S = sc[29]
    for side in range(2):
        x, msh, Px, Pm, sign = (b, a, Pb, Pa, 1.0) if side == 0 else (a, b, Pa, Pb, -1.0)
        nrow, nxt = mesh_mesh_points(sc, x, msh, Px, Pm, side == 0)
        for k in range(nrow // NSLOT):
            best, bd = -1, np.inf
            for s in range(k * NSLOT, (k + 1) * NSLOT):
                if S[s, 0] > 0.0 and S[s, 1] < bd:
                    best, bd = s, S[s, 1]
            if best >= 0:
                _apply(sc, pair, r, A, rd, w, rigid, F, rec, nrec, S[best, 2], S[best, 3], S[best, 4],
                       sign * S[best, 5], sign * S[best, 6], sign * S[best, 7], S[best, 1])
        for s in range(nrow, nxt):
            _apply(sc, pair, r, A, rd, w, rigid, F, rec, nrec, S[s, 2], S[s, 3], S[s, 4], sign * S[s, 5],
                   sign * S[s, 6], sign * S[s, 7], S[s, 1])
