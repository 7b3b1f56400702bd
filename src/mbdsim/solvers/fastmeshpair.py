"""Two triangle meshes against each other (issue 30; a penalty approximation, fine for finely tessellated meshes).

The vertices of each mesh are the candidate points against the other's triangles (solvers.fastmesh:
`point_below` into the slots of sc[29]), counted only when less than SKIN times the smaller of the two
bounding radii below a triangle (a vertex outside a closed mesh is behind its far faces, but deeper than
that); solvers.fastcontact keeps, per vertex, the direction of least depth (the nearest face).

`mesh_mesh_points` walks the two bounding-volume hierarchies (geometry.bvh) together: pairs of nodes whose
boxes overlap (x's node box, in x's axes, taken into msh's axes as the box around it, against msh's node box
swept by its triangles moved SKIN x its bounding radius along their inward normals, sc[34], so that a vertex
up to the depth cap below a triangle is met however thin the leaves), splitting the larger
node of a pair first, down to pairs of leaves, whose triangles' vertices (of x) are tested against the
triangles (of msh).  The cost grows with the size of the touching region, not with the product of the
meshes' sizes.  Edge-edge crossings of two coarse meshes are not seen: only vertices push.
"""
from __future__ import annotations

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from .fastmesh import NSLOT, clear_slots, point_below, slot_means, triangle
from .fastnarrow import to_ground, to_local

SKIN = 0.5   # a mesh's vertex counts below another mesh's triangle to SKIN x the smaller bounding radius


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
def _leaves(sc, x, Px, Pm, ta, na_, tb, nb_, S, cap):
    """The vertices of x's triangles tb..tb + nb_ against msh's triangles ta..ta + na_."""
    sv, verts, tri = sc[6], sc[7], sc[22]
    for t in range(ta, ta + na_):
        a0, a1, a2, b0, b1, b2, c0, c1, c2, m0, m1, m2, ok = triangle(sc, Pm, t)
        if not ok:
            continue
        for u in range(tb, tb + nb_):
            for j in range(3):
                v = tri[u, j]
                y0, y1, y2 = to_ground(Px, verts[v, 0], verts[v, 1], verts[v, 2])
                point_below(S, v - sv[x, 0], y0, y1, y2, a0, a1, a2, b0, b1, b2, c0, c1, c2, m0, m1, m2, cap)


@kernel(_nrt=False)
def mesh_mesh_points(sc, x, msh, Px, Pm):
    """The vertices of mesh x (pose Px) below the triangles of mesh msh (pose Pm) into the slot rows of
    sc[29], NSLOT per vertex of x (module docstring); returns how many slot rows to read."""
    sv, rad, meta, nodes, links, S, stack, swept = sc[6], sc[5], sc[21], sc[27], sc[28], sc[29], sc[30], sc[34]
    nrow = (sv[x, 1] - sv[x, 0]) * NSLOT
    if nrow > S.shape[0] or meta[msh, 3] <= meta[msh, 2] or meta[x, 3] <= meta[x, 2]:
        return 0
    clear_slots(S, nrow)
    cap = SKIN * min(rad[x], rad[msh])
    R = _relative(Pm, Px)
    o0, o1, o2 = to_local(Pm, Px[0], Px[1], Px[2])
    stack[0], stack[1] = meta[msh, 2], meta[x, 2]
    top = 2
    while top > 0:
        top -= 2
        na, nb = stack[top], stack[top + 1]
        if _disjoint(swept, nodes, na, nb, R, o0, o1, o2):
            continue
        la, lb = links[na, 0] < 0, links[nb, 0] < 0
        if la and lb:
            _leaves(sc, x, Px, Pm, links[na, 2], links[na, 3], links[nb, 2], links[nb, 3], S, cap)
        elif top + 4 <= stack.shape[0]:
            if not la and (lb or _size(nodes, na) >= _size(nodes, nb)):
                stack[top], stack[top + 1], stack[top + 2], stack[top + 3] = links[na, 0], nb, links[na, 1], nb
            else:
                stack[top], stack[top + 1], stack[top + 2], stack[top + 3] = na, links[nb, 0], na, links[nb, 1]
            top += 4
    slot_means(S, nrow)
    return nrow
