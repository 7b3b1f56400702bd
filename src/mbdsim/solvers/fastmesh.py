"""Compiled narrow phase of a convex shape against a triangle mesh (issue 30; meshes need not be convex).

A mesh shape (geometry.pack) has its triangles (sc[22]: vertex rows of sc[7], in the order of its
bounding-volume hierarchy) and that hierarchy (sc[27]: each node's box in the mesh's local axes [m];
sc[28]: left and right child, or -1 and the node's first triangle and count), both built at pack time
(geometry.bvh).  `mesh_points` walks the hierarchy with the convex shape's bounding box (in the mesh's
axes) and its bounding sphere (a node's box must meet both; an explicit stack, sc[30]) and, per triangle
met (its outward normal m by the right-hand rule):

* a sphere, and each end sphere of a capsule: the closest point of the triangle (face, edge or vertex),
  touching when nearer than the radius, with the normal from that point to the centre;
* any other shape: its candidate points against the triangle's plane (solvers.fastnarrow.candidate:
  vertices, cylinder rim points, the ellipsoid's deepest point) that lie below it (by less than the
  shape's bounding radius) and whose foot lies on the triangle, with normal m; none when the shape's
  centre (`interior_point`) lies behind the triangle's plane (the far side of a closed mesh thinner than
  the shape, whose vertices lie behind it by less than the bounding radius: not a contact).

The points of one candidate met through several triangles are merged per normal direction (normals within
COS_SAME of the slot's mean count as one: a point over a shared edge of a flat or gently curved mesh is
not counted twice), up to NSLOT directions per candidate (a sphere in a groove touches both walls): the
largest depth, and the point and normal averaged with the weights depth^2, so that the contact moves
continuously from one triangle to the next (a ball rolling over the facets of a bowl feels no jumps of
the normal).  They are left in the slot rows of sc[29] (used, depth [m], point [m], normal m, weight),
which solvers.fastcontact applies.

For a box or hull the walk also collects the mesh's ridges and peaks inside it (solvers.fastridge), in
the RIDGE_ROWS rows after the candidates' slots; for a capsule, a cylinder or an ellipsoid likewise the
ridges and peaks that press into its curved surface (fastridge.curved_ridge_points: a cylinder lying along
a ridge, a capsule across one, an ellipsoid on a peak).  Two triangle meshes: solvers.fastmeshpair.
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from .fastnarrow import (BOX, CAPSULE, CYLINDER, ELLIPSOID, HULL, SPHERE, candidate, dir_local, n_candidates, to_ground,
                         to_local)
from .fastridge import curved_ridge_points, ridge_points

NSLOT = 4          # contact directions kept per candidate point
COS_SAME = 0.95    # normals closer than this (cosine) are one direction
RIDGE_ROWS = 64    # slot rows after the candidates' for a polyhedron's ridge and peak points (solvers.fastridge)


@kernel(_nrt=False)
def closest_on_triangle(p0, p1, p2, a0, a1, a2, b0, b1, b2, c0, c1, c2):
    """Closest point to p on the triangle a, b, c (Ericson, Real-Time Collision Detection, 5.1.5)."""
    ab0, ab1, ab2 = b0 - a0, b1 - a1, b2 - a2
    ac0, ac1, ac2 = c0 - a0, c1 - a1, c2 - a2
    ap0, ap1, ap2 = p0 - a0, p1 - a1, p2 - a2
    d1 = ab0 * ap0 + ab1 * ap1 + ab2 * ap2
    d2 = ac0 * ap0 + ac1 * ap1 + ac2 * ap2
    if d1 <= 0.0 and d2 <= 0.0:
        return a0, a1, a2
    bp0, bp1, bp2 = p0 - b0, p1 - b1, p2 - b2
    d3 = ab0 * bp0 + ab1 * bp1 + ab2 * bp2
    d4 = ac0 * bp0 + ac1 * bp1 + ac2 * bp2
    if d3 >= 0.0 and d4 <= d3:
        return b0, b1, b2
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        v = d1 / (d1 - d3)
        return a0 + v * ab0, a1 + v * ab1, a2 + v * ab2
    cp0, cp1, cp2 = p0 - c0, p1 - c1, p2 - c2
    d5 = ab0 * cp0 + ab1 * cp1 + ab2 * cp2
    d6 = ac0 * cp0 + ac1 * cp1 + ac2 * cp2
    if d6 >= 0.0 and d5 <= d6:
        return c0, c1, c2
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        w = d2 / (d2 - d6)
        return a0 + w * ac0, a1 + w * ac1, a2 + w * ac2
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return b0 + w * (c0 - b0), b1 + w * (c1 - b1), b2 + w * (c2 - b2)
    den = 1.0 / (va + vb + vc)
    v, w = vb * den, vc * den
    return a0 + ab0 * v + ac0 * w, a1 + ab1 * v + ac1 * w, a2 + ab2 * v + ac2 * w


@kernel(_nrt=False)
def _on_triangle(y0, y1, y2, a0, a1, a2, b0, b1, b2, c0, c1, c2, tol):
    """Whether the point y of the triangle's plane lies on the triangle (barycentric, within tol)."""
    ab0, ab1, ab2 = b0 - a0, b1 - a1, b2 - a2
    ac0, ac1, ac2 = c0 - a0, c1 - a1, c2 - a2
    ap0, ap1, ap2 = y0 - a0, y1 - a1, y2 - a2
    d00 = ab0 * ab0 + ab1 * ab1 + ab2 * ab2
    d01 = ab0 * ac0 + ab1 * ac1 + ab2 * ac2
    d11 = ac0 * ac0 + ac1 * ac1 + ac2 * ac2
    d20 = ap0 * ab0 + ap1 * ab1 + ap2 * ab2
    d21 = ap0 * ac0 + ap1 * ac1 + ap2 * ac2
    den = d00 * d11 - d01 * d01
    if not den > 0.0:
        return False
    v = (d11 * d20 - d01 * d21) / den
    w = (d00 * d21 - d01 * d20) / den
    return v >= -tol and w >= -tol and v + w <= 1.0 + tol


@kernel(_nrt=False)
def _keep(S, k, depth, x0, x1, x2, n0, n1, n2):
    """Add the point to candidate k's slots: to the slot whose mean normal is within COS_SAME of n, else
    to a free slot (else over the shallowest, if deeper).  A slot keeps the largest depth and the depth^2
    weighted sums of points and normals (module docstring)."""
    free, low, lowd = -1, -1, np.inf
    wgt = depth * depth
    for s in range(k * NSLOT, (k + 1) * NSLOT):
        if S[s, 0] > 0.0:
            L = np.sqrt(S[s, 5] * S[s, 5] + S[s, 6] * S[s, 6] + S[s, 7] * S[s, 7])
            if n0 * S[s, 5] + n1 * S[s, 6] + n2 * S[s, 7] > COS_SAME * L:
                S[s, 1] = max(S[s, 1], depth)
                S[s, 2], S[s, 3], S[s, 4] = S[s, 2] + wgt * x0, S[s, 3] + wgt * x1, S[s, 4] + wgt * x2
                S[s, 5], S[s, 6], S[s, 7] = S[s, 5] + wgt * n0, S[s, 6] + wgt * n1, S[s, 7] + wgt * n2
                S[s, 8] += wgt
                return
            if S[s, 1] < lowd:
                low, lowd = s, S[s, 1]
        elif free < 0:
            free = s
    s = free if free >= 0 else (low if depth > lowd else -1)
    if s >= 0:
        S[s, 0], S[s, 1], S[s, 2], S[s, 3], S[s, 4] = 1.0, depth, wgt * x0, wgt * x1, wgt * x2
        S[s, 5], S[s, 6], S[s, 7], S[s, 8] = wgt * n0, wgt * n1, wgt * n2, wgt


@kernel(_nrt=False)
def triangle(sc, Pm, t):
    """Triangle t of a mesh (pose Pm) in ground: its corners a, b, c [m], outward unit normal m (the right-hand
    rule) and whether it has an area."""
    verts, tri = sc[7], sc[22]
    a0, a1, a2 = to_ground(Pm, verts[tri[t, 0], 0], verts[tri[t, 0], 1], verts[tri[t, 0], 2])
    b0, b1, b2 = to_ground(Pm, verts[tri[t, 1], 0], verts[tri[t, 1], 1], verts[tri[t, 1], 2])
    c0, c1, c2 = to_ground(Pm, verts[tri[t, 2], 0], verts[tri[t, 2], 1], verts[tri[t, 2], 2])
    m0 = (b1 - a1) * (c2 - a2) - (b2 - a2) * (c1 - a1)
    m1 = (b2 - a2) * (c0 - a0) - (b0 - a0) * (c2 - a2)
    m2 = (b0 - a0) * (c1 - a1) - (b1 - a1) * (c0 - a0)
    L = np.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
    if not L > 0.0:
        return a0, a1, a2, b0, b1, b2, c0, c1, c2, 0.0, 0.0, 1.0, False
    return a0, a1, a2, b0, b1, b2, c0, c1, c2, m0 / L, m1 / L, m2 / L, True


@kernel(_nrt=False)
def point_below(S, k, y0, y1, y2, a0, a1, a2, b0, b1, b2, c0, c1, c2, m0, m1, m2, cap):
    """Candidate k at the ground point y into its slots when it lies below the triangle a, b, c (outward
    normal m) by less than cap [m] and its foot lies on the triangle."""
    d = m0 * (a0 - y0) + m1 * (a1 - y1) + m2 * (a2 - y2)
    if not (d > 0.0 and d < cap):
        return
    if not _on_triangle(y0 + d * m0, y1 + d * m1, y2 + d * m2, a0, a1, a2, b0, b1, b2, c0, c1, c2, 1e-9):
        return
    h = 0.5 * d
    _keep(S, k, d, y0 + h * m0, y1 + h * m1, y2 + h * m2, m0, m1, m2)


@kernel(_nrt=False)
def interior_point(kind, Px, verts, v0, v1):
    """A ground point inside a convex shape (pose Px): the mean of a convex hull's vertices rows v0..v1, else
    the origin of its local frame (the centre of a box, cylinder, ellipsoid)."""
    if kind != HULL or v1 <= v0:
        return Px[0], Px[1], Px[2]
    s0 = s1 = s2 = 0.0
    for k in range(v0, v1):
        s0, s1, s2 = s0 + verts[k, 0], s1 + verts[k, 1], s2 + verts[k, 2]
    return to_ground(Px, s0 / (v1 - v0), s1 / (v1 - v0), s2 / (v1 - v0))


@kernel(_nrt=False)
def _triangle(sc, x, Px, Pm, t, S, cap):
    """Shape x (pose Px) against triangle t of the mesh (pose Pm): its points no deeper than cap [m] into
    the slots S."""
    kind, prm, sv, verts = sc[1], sc[4], sc[6], sc[7]
    a0, a1, a2, b0, b1, b2, c0, c1, c2, m0, m1, m2, ok = triangle(sc, Pm, t)
    if not ok:
        return
    kd, p = kind[x], prm[x]
    if kd == SPHERE or kd == CAPSULE:
        for k in range(2 if kd == CAPSULE else 1):
            z = 0.0 if kd == SPHERE else (p[1] if k == 0 else -p[1])
            e0, e1, e2 = to_ground(Px, 0.0, 0.0, z)
            hgt = m0 * (e0 - a0) + m1 * (e1 - a1) + m2 * (e2 - a2)
            if hgt <= 0.0 or hgt >= p[0]:
                continue   # the centre behind the triangle, or clear of its plane
            q0, q1, q2 = closest_on_triangle(e0, e1, e2, a0, a1, a2, b0, b1, b2, c0, c1, c2)
            d0, d1, d2 = e0 - q0, e1 - q1, e2 - q2
            dist = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            if not (dist < p[0] and dist > 0.0):
                continue
            n0, n1, n2 = d0 / dist, d1 / dist, d2 / dist
            h = 0.5 * (p[0] - dist)
            _keep(S, k, p[0] - dist, q0 - h * n0, q1 - h * n1, q2 - h * n2, n0, n1, n2)
        return
    o0, o1, o2 = interior_point(kd, Px, verts, sv[x, 0], sv[x, 1])
    if not m0 * (o0 - a0) + m1 * (o1 - a1) + m2 * (o2 - a2) > 0.0:
        return   # the shape's centre behind the triangle: a far face of a closed mesh, not a contact
    for k in range(n_candidates(kd, sv[x, 1] - sv[x, 0])):
        y0, y1, y2 = candidate(kd, Px, p, verts, sv[x, 0], m0, m1, m2, k)
        point_below(S, k, y0, y1, y2, a0, a1, a2, b0, b1, b2, c0, c1, c2, m0, m1, m2, cap)


@kernel(_nrt=False)
def clear_slots(S, nrow):
    for s in range(nrow):
        S[s, 0] = 0.0


@kernel(_nrt=False)
def slot_means(S, nrow):
    """The depth^2 weighted means of the slots: a contact that moves continuously over the triangles."""
    for s in range(nrow):
        if S[s, 0] > 0.0 and S[s, 8] > 0.0:
            L = np.sqrt(S[s, 5] * S[s, 5] + S[s, 6] * S[s, 6] + S[s, 7] * S[s, 7])
            S[s, 2], S[s, 3], S[s, 4] = S[s, 2] / S[s, 8], S[s, 3] / S[s, 8], S[s, 4] / S[s, 8]
            S[s, 5], S[s, 6], S[s, 7] = S[s, 5] / L, S[s, 6] / L, S[s, 7] / L
        else:
            S[s, 0] = 0.0


@kernel(_nrt=False)
def box_distance2(nodes, nd, c0, c1, c2):
    """Squared distance [m^2] from the point c to node nd's box (zero inside it); nodes' rows as sc[27]."""
    d0 = max(nodes[nd, 0] - c0, 0.0, c0 - nodes[nd, 3])
    d1 = max(nodes[nd, 1] - c1, 0.0, c1 - nodes[nd, 4])
    d2 = max(nodes[nd, 2] - c2, 0.0, c2 - nodes[nd, 5])
    return d0 * d0 + d1 * d1 + d2 * d2


@kernel(_nrt=False)
def mesh_points(sc, x, msh, Px, Pm):
    """Points of convex shape x (pose Px) on mesh msh (pose Pm) into the slot rows of sc[29] (module
    docstring), and after them, for a box or hull, the mesh's ridges and peaks inside it (solvers.fastridge);
    returns how many slot rows to read."""
    kind, sv, BB, meta, nodes, links, S, stack = sc[1], sc[6], sc[18], sc[21], sc[27], sc[28], sc[29], sc[30]
    kd = kind[x]
    cap = sc[5][x]
    nc = 2 if kd == CAPSULE else (1 if kd == SPHERE else n_candidates(kd, sv[x, 1] - sv[x, 0]))
    nrow = min(nc * NSLOT, S.shape[0])
    clear_slots(S, nrow)
    ridges = kd == BOX or kd == HULL
    curved = kd == CAPSULE or kd == CYLINDER or kd == ELLIPSOID
    nxt = nrow
    # x's ground box, as a box in the mesh's axes
    g0, g1, g2 = 0.5 * (BB[x, 0] + BB[x, 3]) - Pm[0], 0.5 * (BB[x, 1] + BB[x, 4]) - Pm[1], \
        0.5 * (BB[x, 2] + BB[x, 5]) - Pm[2]
    h0, h1, h2 = 0.5 * (BB[x, 3] - BB[x, 0]), 0.5 * (BB[x, 4] - BB[x, 1]), 0.5 * (BB[x, 5] - BB[x, 2])
    l0, l1, l2 = dir_local(Pm, g0, g1, g2)
    e0 = abs(Pm[3]) * h0 + abs(Pm[6]) * h1 + abs(Pm[9]) * h2
    e1 = abs(Pm[4]) * h0 + abs(Pm[7]) * h1 + abs(Pm[10]) * h2
    e2 = abs(Pm[5]) * h0 + abs(Pm[8]) * h1 + abs(Pm[11]) * h2
    # and its bounding sphere (about its frame's origin, radius sc[5]) in the mesh's axes: a node's box must
    # meet both (the sphere prunes the box's corners: most of the triangles under a ball)
    c0, c1, c2 = to_local(Pm, Px[0], Px[1], Px[2])
    rr = sc[5][x] * sc[5][x]
    if meta[msh, 3] <= meta[msh, 2]:
        return 0
    stack[0] = meta[msh, 2]
    top = 1
    while top > 0:
        top -= 1
        nd = stack[top]
        if l0 + e0 < nodes[nd, 0] or l0 - e0 > nodes[nd, 3] or l1 + e1 < nodes[nd, 1] or \
                l1 - e1 > nodes[nd, 4] or l2 + e2 < nodes[nd, 2] or l2 - e2 > nodes[nd, 5]:
            continue
        if box_distance2(nodes, nd, c0, c1, c2) > rr:
            continue
        if links[nd, 0] < 0:
            for t in range(links[nd, 2], links[nd, 2] + links[nd, 3]):
                if nc * NSLOT <= S.shape[0]:
                    _triangle(sc, x, Px, Pm, t, S, cap)
                    if ridges:
                        nxt = ridge_points(sc, x, Px, Pm, t, S, nxt)
                    elif curved:
                        nxt = curved_ridge_points(sc, x, Px, Pm, t, S, nxt)
        elif top + 2 <= stack.shape[0]:
            stack[top] = links[nd, 0]
            stack[top + 1] = links[nd, 1]
            top += 2
    slot_means(S, nrow)
    return nxt
