"""Compiled shape contact (issue 30): broad phase, narrow phase per pair and the contact law at each point.

`shape_contacts(sc, r, A, rd, w, rigid, F, rec, nrec)` adds the contact loads of every shape pair of the
packed tuple `sc` (geometry.pack.pack_contacts) into F (nf, 6): force [N] in ground axes, torque [N m]
about the CM in body axes, from the frames r, A, rd, w (w in ground axes).  With rec (m, NREC) of m > 0
rows it also records each contact point (see REC_FIELDS; nrec[0] counts them); the step loop passes an
empty rec.

Broad phase (solvers.fastbroad): sweep and prune on the shapes' ground bounding boxes, so that only
pairs whose boxes overlap reach the narrow phase (cost: shapes plus overlaps, not pairs).  Narrow phase
per pair (solvers.fastnarrow): against a plane, the candidate points of the shape; spheres and capsules by
the closest points of their segments; against a box or convex hull, the separating-axis test over the
polyhedra's face normals picks the reference face of least penetration, whose normal is the contact normal
of every point: the incident shape's candidate points below it and inside the reference (vertices, rim
points, ...) and, between two polyhedra, the reference's vertices inside the incident one, so face and
line contacts get several points and the right moments; a curved shape (sphere, capsule, cylinder,
ellipsoid) none of whose deepest candidates lies over that face presses on an edge or a vertex of the
polyhedron instead (`_curved_point`: one point, a sphere or capsule on a box by the distance of its core
from the box, the others by GJK/EPA; a capsule or cylinder lying along the edge, `_edge_line`, a point at
each end of the part of the edge beside its axis); a convex shape against a triangle mesh through
its bounding-volume hierarchy (solvers.fastmesh; with a box or hull also the mesh's ridges and peaks
inside it, solvers.fastridge; a mesh no larger than a box or hull it meets puts its vertices on the
polyhedron's faces instead); two triangle meshes by the vertices of each against the other's triangles
and their sharp ridges crossing (solvers.fastmeshpair.mesh_pair, the two hierarchies walked together; a
penalty approximation for finely tessellated meshes); two cylinders, or a
capsule and a cylinder, with axes within LINE_SIN of parallel along their line (`_line_pair`: a point at
each end of the overlap of the axes); the other convex pairs (cylinders and ellipsoids against
curved shapes) in solvers.fastgjk: a sphere or capsule against a cylinder or an ellipsoid by the distance
of its point or segment from the solid (closed forms and a monotone Newton iteration: smooth in the
state), the others (cylinders and ellipsoids among themselves) by GJK and EPA over support functions, one
point midway between the witness points.

The contact law at each point (IMPACT or POISSON normal force, Coulomb friction with Adams' stiction and
transition velocities) and its record: solvers.fastlaw._apply (its names re-exported here).
"""
from __future__ import annotations

import numpy as np
from .._jit import kernel

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from ..system.exprloads_kernel import _cross
from .fastcross import edge_crossings
from .fastedges import FACE_COS, hull_edges
from .fastbroad import boxes, partner, sort_order, sweep_axis
from .fastgjk import penetration, rounded_penetration
from .fastlaw import (NREC, PAR_FIELDS, REC_FIELDS, RESTITUTION_VELOCITY, _apply,  # noqa: F401  (re-exported)
                      friction_coefficient, normal_force)
from .fastmesh import NSLOT, mesh_points
from .fastmeshpair import mesh_pair
from .fastnarrow import (BOX, CAPSULE, CYLINDER, HULL, LINE_SIN, MESH, PLANE, SPHERE, candidate, deepest_on_face,
                         exit_depth, face, inside_except, n_candidates, pressed, segments_closest, support_depth,
                         to_ground)


@kernel(_nrt=False)
def _against(sc, pair, x, ref, g, P, Q, q0, q1, q2, m0, m1, m2, sign, r, A, rd, w, rigid, F, rec, nrec):
    """Candidate points of shape x (pose P) below the plane (q, outward normal m) of shape `ref` (pose Q;
    face g of a polyhedron, whose other faces then bound the points; g < 0: a plane); n = sign m."""
    kind, prm, sv, verts = sc[1], sc[4], sc[6], sc[7]
    spl, planes, rad = sc[8], sc[9], sc[5]
    tol = 1e-6 * rad[ref] + 1e-12 if g >= 0 else 0.0
    for k in range(n_candidates(kind[x], sv[x, 1] - sv[x, 0])):
        c0, c1, c2 = candidate(kind[x], P, prm[x], verts, sv[x, 0], m0, m1, m2, k)
        d = m0 * (q0 - c0) + m1 * (q1 - c1) + m2 * (q2 - c2)
        if not d > 0.0:
            continue
        if g >= 0 and not inside_except(Q, planes, spl[ref, 0], spl[ref, 1] - spl[ref, 0], g, c0, c1, c2, tol):
            continue
        h = 0.5 * d
        _apply(sc, pair, r, A, rd, w, rigid, F, rec, nrec, c0 + h * m0, c1 + h * m1, c2 + h * m2,
               sign * m0, sign * m1, sign * m2, d)


@kernel(_nrt=False)
def _polytope_pair(sc, pair, a, b, Pa, Pb, r, A, rd, w, rigid, F, rec, nrec):
    """Shape a against shape b, at least one of them a box or convex hull: separating axes over the face
    normals of the polyhedra, then the points of the least-penetration reference face (module docstring)."""
    kind, prm, sv, verts, spl, planes, rad = sc[1], sc[4], sc[6], sc[7], sc[8], sc[9], sc[5]
    best, ref, gbest = np.inf, -1, -1
    for side in range(2):
        rs, xs = (b, a) if side == 0 else (a, b)
        if kind[rs] != BOX and kind[rs] != HULL:
            continue
        Pr, Px = (Pb, Pa) if side == 0 else (Pa, Pb)
        for g in range(spl[rs, 1] - spl[rs, 0]):
            q0, q1, q2, m0, m1, m2 = face(Pr, planes, spl[rs, 0], g)
            D = support_depth(kind[xs], Px, prm[xs], verts, sv[xs, 0], sv[xs, 1] - sv[xs, 0], q0, q1, q2, m0, m1, m2)
            if D < best:
                best, ref, gbest = D, rs, g
            if not D > 0.0:
                return   # a separating face: no contact
    rs, xs = (b, a) if ref == b else (a, b)
    Pr, Px = (Pb, Pa) if ref == b else (Pa, Pb)
    sign = -1.0 if ref == b else 1.0   # n = sign * m runs from shape_i (a) to shape_j (b)
    q0, q1, q2, m0, m1, m2 = face(Pr, planes, spl[rs, 0], gbest)
    # edge-edge axes (an axis within FACE_COS of the reference face's normal is that face's contact)
    if kind[a] == BOX and kind[b] == BOX and _box_edges(sc, pair, a, b, Pa, Pb, best, m0, m1, m2, r, A, rd, w, rigid,
                                                        F, rec, nrec):
        return   # separated along an edge-edge axis, or an edge-edge contact
    if (kind[a] == HULL or kind[b] == HULL) and (kind[a] == BOX or kind[a] == HULL) and \
            (kind[b] == BOX or kind[b] == HULL):
        st, p0, p1, p2, L0, L1, L2, D = hull_edges(sc, a, b, Pa, Pb, best, m0, m1, m2)
        if st == 1:
            _apply(sc, pair, r, A, rd, w, rigid, F, rec, nrec, p0, p1, p2, L0, L1, L2, D)
        if st != 0:
            return   # separated along an edge-edge axis (fastedges), or an edge-edge contact
    if kind[xs] != BOX and kind[xs] != HULL and not deepest_on_face(sc, xs, rs, gbest, Px, Pr, q0, q1, q2, m0, m1,
                                                                     m2):
        _curved_point(sc, pair, a, b, Pa, Pb, r, A, rd, w, rigid, F, rec, nrec)
        return   # a curved shape on an edge or a vertex of the polyhedron: one point, the exact normal
    _against(sc, pair, xs, rs, gbest, Px, Pr, q0, q1, q2, m0, m1, m2, sign, r, A, rd, w, rigid, F, rec, nrec)
    if kind[xs] != BOX and kind[xs] != HULL:
        return
    # the reference's vertices inside the incident polyhedron, their depth the way out of it along -m
    # (those where an incident vertex already pressed, e.g. two equal faces flush, are not counted twice)
    tol = 1e-6 * rad[xs] + 1e-12
    for k in range(sv[rs, 1] - sv[rs, 0]):
        v0, v1, v2 = to_ground(Pr, verts[sv[rs, 0] + k, 0], verts[sv[rs, 0] + k, 1], verts[sv[rs, 0] + k, 2])
        if not inside_except(Px, planes, spl[xs, 0], spl[xs, 1] - spl[xs, 0], -1, v0, v1, v2, tol):
            continue
        d = exit_depth(Px, planes, spl[xs, 0], spl[xs, 1], v0, v1, v2, m0, m1, m2)
        if not d > 0.0 or pressed(Px, Pr, verts, sv[xs, 0], sv[xs, 1], planes, spl[rs, 0], spl[rs, 1], gbest,
                                   v0, v1, v2, m0, m1, m2, q0, q1, q2, tol):
            continue
        h = 0.5 * d
        _apply(sc, pair, r, A, rd, w, rigid, F, rec, nrec, v0 - h * m0, v1 - h * m1, v2 - h * m2,
               sign * m0, sign * m1, sign * m2, d)
    S = sc[29]   # the incident's edges leaving the reference through its side planes (solvers.fastcross)
    for s in range(edge_crossings(sc, xs, rs, gbest, Px, Pr, q0, q1, q2, m0, m1, m2, tol, S)):
        _apply(sc, pair, r, A, rd, w, rigid, F, rec, nrec, S[s, 2], S[s, 3], S[s, 4], sign * m0, sign * m1,
               sign * m2, S[s, 1])


@kernel(_nrt=False)
def _curved_point(sc, pair, a, b, Pa, Pb, r, A, rd, w, rigid, F, rec, nrec):
    """A curved shape against an edge or a vertex of a box or hull: one point, a sphere or capsule on a box
    by the distance of its core from the box (closed form, fastgjk.rounded_penetration), the others by
    GJK/EPA."""
    kind, prm, rad = sc[1], sc[4], sc[5]
    if kind[a] == BOX and (kind[b] == SPHERE or kind[b] == CAPSULE):
        depth, n0, n1, n2, p0, p1, p2 = rounded_penetration(kind[b], Pb, prm[b], BOX, Pa, prm[a])
    elif kind[b] == BOX and (kind[a] == SPHERE or kind[a] == CAPSULE):
        depth, n0, n1, n2, p0, p1, p2 = rounded_penetration(kind[a], Pa, prm[a], BOX, Pb, prm[b])
        n0, n1, n2 = -n0, -n1, -n2
    else:
        depth, n0, n1, n2, p0, p1, p2 = penetration(sc, a, b, Pa, Pb, 1e-10 * (rad[a] + rad[b]))
    if not depth > 0.0:
        return
    if kind[a] == CAPSULE or kind[a] == CYLINDER or kind[b] == CAPSULE or kind[b] == CYLINDER:
        cur, poly, Pc, Pp, sign = (a, b, Pa, Pb, -1.0) if kind[a] == CAPSULE or kind[a] == CYLINDER else \
            (b, a, Pb, Pa, 1.0)
        if _edge_line(sc, pair, poly, cur, Pp, Pc, sign * n0, sign * n1, sign * n2, sign, r, A, rd, w, rigid, F,
                      rec, nrec):
            return
    _apply(sc, pair, r, A, rd, w, rigid, F, rec, nrec, p0, p1, p2, n0, n1, n2, depth)


@kernel(_nrt=False)
def _edge_line(sc, pair, poly, cur, Pp, Pc, n0, n1, n2, sign, r, A, rd, w, rigid, F, rec, nrec):
    """A capsule or cylinder cur whose side lies along an edge of the polyhedron poly (the contact normal n,
    from poly towards cur, within LINE_SIN of perpendicular to cur's axis; poly's vertices that support it
    along n, within LINE_SIN of its size, spanning a segment within LINE_SIN of the axis): a line contact, a
    point at each end of the part of that edge beside the axis, each as deep as the radius less its distance
    from the axis (the capsule's core).  True when it is such a line (its points applied); sign: +1 when
    poly is the pair's shape_i."""
    prm, sv, verts, rad = sc[4], sc[6], sc[7], sc[5]
    u0, u1, u2 = Pc[5], Pc[8], Pc[11]
    if abs(u0 * n0 + u1 * n1 + u2 * n2) > LINE_SIN:
        return False
    p = prm[cur]
    top = -np.inf
    for k in range(sv[poly, 0], sv[poly, 1]):
        g0, g1, g2 = to_ground(Pp, verts[k, 0], verts[k, 1], verts[k, 2])
        top = max(top, g0 * n0 + g1 * n1 + g2 * n2)
    tol = LINE_SIN * 2.0 * rad[poly]
    lo, hi, klo, khi = np.inf, -np.inf, -1, -1
    for k in range(sv[poly, 0], sv[poly, 1]):
        g0, g1, g2 = to_ground(Pp, verts[k, 0], verts[k, 1], verts[k, 2])
        if g0 * n0 + g1 * n1 + g2 * n2 >= top - tol:
            z = (g0 - Pc[0]) * u0 + (g1 - Pc[1]) * u1 + (g2 - Pc[2]) * u2
            if z < lo:
                lo, klo = z, k
            if z > hi:
                hi, khi = z, k
    if khi < 0 or not hi - lo > 1e-9 * rad[cur]:
        return False
    a0, a1, a2 = to_ground(Pp, verts[klo, 0], verts[klo, 1], verts[klo, 2])
    b0, b1, b2 = to_ground(Pp, verts[khi, 0], verts[khi, 1], verts[khi, 2])
    e0, e1, e2 = b0 - a0, b1 - a1, b2 - a2
    x0, x1, x2 = _cross(u0, u1, u2, e0, e1, e2)
    if x0 * x0 + x1 * x1 + x2 * x2 > LINE_SIN * LINE_SIN * (e0 * e0 + e1 * e1 + e2 * e2):
        return False
    t0, t1 = max(lo, -p[1]), min(hi, p[1])
    if not t0 < t1:
        return False
    for end in range(2):
        z = t0 if end == 0 else t1
        f = (z - lo) / (hi - lo)
        q0, q1, q2 = a0 + f * e0, a1 + f * e1, a2 + f * e2
        zq = min(max((q0 - Pc[0]) * u0 + (q1 - Pc[1]) * u1 + (q2 - Pc[2]) * u2, -p[1]), p[1])
        d0, d1, d2 = q0 - Pc[0] - zq * u0, q1 - Pc[1] - zq * u1, q2 - Pc[2] - zq * u2
        L = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if not (L < p[0] and L > 0.0):
            continue
        d0, d1, d2 = d0 / L, d1 / L, d2 / L   # outward of cur, towards poly
        h = 0.5 * (p[0] - L)
        _apply(sc, pair, r, A, rd, w, rigid, F, rec, nrec, q0 + h * d0, q1 + h * d1, q2 + h * d2,
               -sign * d0, -sign * d1, -sign * d2, p[0] - L)
    return True


@kernel(_nrt=False)
def _box_edges(sc, pair, a, b, Pa, Pb, face_depth, m0, m1, m2, r, A, rd, w, rigid, F, rec, nrec):
    """Edge-edge axes of two boxes (the cross products of their edge directions): True when one separates
    them, or when one penetrates clearly less than the best face (below 0.95 of it; faces are preferred
    for resting contact) and the contact at the closest points of the two supporting edges is applied."""
    prm = sc[4]
    ha, hb = prm[a], prm[b]
    c0, c1, c2 = Pb[0] - Pa[0], Pb[1] - Pa[1], Pb[2] - Pa[2]
    best, bi, bj, L0, L1, L2 = 0.95 * face_depth, -1, -1, 0.0, 0.0, 0.0
    for i in range(3):
        for j in range(3):
            x0, x1, x2 = _cross(Pa[3 + i], Pa[6 + i], Pa[9 + i], Pb[3 + j], Pb[6 + j], Pb[9 + j])
            nrm = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
            if nrm < 1e-6:
                continue   # parallel edges: the face axes cover them
            x0, x1, x2 = x0 / nrm, x1 / nrm, x2 / nrm
            s = x0 * c0 + x1 * c1 + x2 * c2
            if s < 0.0:
                x0, x1, x2, s = -x0, -x1, -x2, -s
            ext = 0.0
            for k in range(3):
                ext += abs(x0 * Pa[3 + k] + x1 * Pa[6 + k] + x2 * Pa[9 + k]) * ha[k]
                ext += abs(x0 * Pb[3 + k] + x1 * Pb[6 + k] + x2 * Pb[9 + k]) * hb[k]
            D = ext - s
            if not D > 0.0:
                return True
            if D < best and abs(x0 * m0 + x1 * m1 + x2 * m2) <= FACE_COS:
                best, bi, bj, L0, L1, L2 = D, i, j, x0, x1, x2
    if bi < 0:
        return False
    # a's edge along axis bi farthest along L, b's edge along axis bj farthest along -L
    p0, p1, p2 = Pa[0], Pa[1], Pa[2]
    q0, q1, q2 = Pb[0], Pb[1], Pb[2]
    for k in range(3):
        if k != bi:
            s = ha[k] if L0 * Pa[3 + k] + L1 * Pa[6 + k] + L2 * Pa[9 + k] > 0.0 else -ha[k]
            p0, p1, p2 = p0 + s * Pa[3 + k], p1 + s * Pa[6 + k], p2 + s * Pa[9 + k]
        if k != bj:
            s = -hb[k] if L0 * Pb[3 + k] + L1 * Pb[6 + k] + L2 * Pb[9 + k] > 0.0 else hb[k]
            q0, q1, q2 = q0 + s * Pb[3 + k], q1 + s * Pb[6 + k], q2 + s * Pb[9 + k]
    ea0, ea1, ea2 = ha[bi] * Pa[3 + bi], ha[bi] * Pa[6 + bi], ha[bi] * Pa[9 + bi]
    eb0, eb1, eb2 = hb[bj] * Pb[3 + bj], hb[bj] * Pb[6 + bj], hb[bj] * Pb[9 + bj]
    X, Y = segments_closest(p0 - ea0, p1 - ea1, p2 - ea2, p0 + ea0, p1 + ea1, p2 + ea2,
                            q0 - eb0, q1 - eb1, q2 - eb2, q0 + eb0, q1 + eb1, q2 + eb2)
    _apply(sc, pair, r, A, rd, w, rigid, F, rec, nrec, 0.5 * (X[0] + Y[0]), 0.5 * (X[1] + Y[1]),
           0.5 * (X[2] + Y[2]), L0, L1, L2, best)
    return True


@kernel(_nrt=False)
def _round_pair(sc, pair, a, b, Pa, Pb, r, A, rd, w, rigid, F, rec, nrec):
    """Spheres and capsules: the closest points of their segments, then as two spheres."""
    kind, prm = sc[1], sc[4]
    ha = prm[a, 1] if kind[a] == CAPSULE else 0.0
    hb = prm[b, 1] if kind[b] == CAPSULE else 0.0
    a0, a1, a2 = to_ground(Pa, 0.0, 0.0, -ha)
    b0, b1, b2 = to_ground(Pa, 0.0, 0.0, ha)
    c0, c1, c2 = to_ground(Pb, 0.0, 0.0, -hb)
    e0, e1, e2 = to_ground(Pb, 0.0, 0.0, hb)
    X, Y = segments_closest(a0, a1, a2, b0, b1, b2, c0, c1, c2, e0, e1, e2)
    d0, d1, d2 = Y[0] - X[0], Y[1] - X[1], Y[2] - X[2]
    L = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    g = L - prm[a, 0] - prm[b, 0]
    if not g < 0.0:
        return
    inv = 1.0 / L if L > 0.0 else 0.0
    n0, n1, n2 = d0 * inv, d1 * inv, d2 * inv
    if L == 0.0:
        n2 = 1.0
    h = prm[a, 0] + 0.5 * g
    _apply(sc, pair, r, A, rd, w, rigid, F, rec, nrec, X[0] + h * n0, X[1] + h * n1, X[2] + h * n2,
           n0, n1, n2, -g)


@kernel(_nrt=False)
def _line_pair(sc, pair, a, b, Pa, Pb, r, A, rd, w, rigid, F, rec, nrec):
    """Two cylinders, or a capsule and a cylinder, whose axes are within LINE_SIN of parallel and whose
    projections overlap: a line contact, one point at each end of the overlap of the two axes (clipped on
    a's axis), each of depth r_a + r_b minus the distance of b's axis line from that point of a's axis, the
    normal along that distance, the point midway in the overlap of the two surfaces.  False (no points
    applied) when the axes are not parallel enough, the projections do not overlap or the axes cross
    (then the caller's single point, GJK/EPA or the closed form)."""
    prm = sc[4]
    u0, u1, u2 = Pa[5], Pa[8], Pa[11]
    v0, v1, v2 = Pb[5], Pb[8], Pb[11]
    c = u0 * v0 + u1 * v1 + u2 * v2
    x0, x1, x2 = u1 * v2 - u2 * v1, u2 * v0 - u0 * v2, u0 * v1 - u1 * v0
    if x0 * x0 + x1 * x1 + x2 * x2 > LINE_SIN * LINE_SIN:
        return False
    ra, ha, rb, hb = prm[a, 0], prm[a, 1], prm[b, 0], prm[b, 1]
    tb = (Pb[0] - Pa[0]) * u0 + (Pb[1] - Pa[1]) * u1 + (Pb[2] - Pa[2]) * u2
    lo, hi = max(-ha, tb - abs(c) * hb), min(ha, tb + abs(c) * hb)
    if not lo < hi:
        return False
    y0, y1, y2 = Pa[0] + lo * u0, Pa[1] + lo * u1, Pa[2] + lo * u2
    z0, z1, z2 = Pa[0] + hi * u0, Pa[1] + hi * u1, Pa[2] + hi * u2
    s = (y0 - Pb[0]) * v0 + (y1 - Pb[1]) * v1 + (y2 - Pb[2]) * v2
    d0, d1, d2 = Pb[0] + s * v0 - y0, Pb[1] + s * v1 - y1, Pb[2] + s * v2 - y2
    s = (z0 - Pb[0]) * v0 + (z1 - Pb[1]) * v1 + (z2 - Pb[2]) * v2
    e0, e1, e2 = Pb[0] + s * v0 - z0, Pb[1] + s * v1 - z1, Pb[2] + s * v2 - z2
    Ly, Lz = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2), np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    if not (Ly > 1e-6 * (ra + rb) and Lz > 1e-6 * (ra + rb)):
        return False   # the axes (nearly) cross: no line contact
    if ra + rb - Ly > 0.0:
        h = 0.5 * (ra - rb + Ly) / Ly
        _apply(sc, pair, r, A, rd, w, rigid, F, rec, nrec, y0 + h * d0, y1 + h * d1, y2 + h * d2,
               d0 / Ly, d1 / Ly, d2 / Ly, ra + rb - Ly)
    if ra + rb - Lz > 0.0:
        h = 0.5 * (ra - rb + Lz) / Lz
        _apply(sc, pair, r, A, rd, w, rigid, F, rec, nrec, z0 + h * e0, z1 + h * e1, z2 + h * e2,
               e0 / Lz, e1 / Lz, e2 / Lz, ra + rb - Lz)
    return True


@kernel(_nrt=False)
def _narrow(sc, pair, r, A, rd, w, rigid, F, rec, nrec):
    """The narrow phase of one pair whose bounding boxes overlap (module docstring)."""
    kind, rad, pr, PS = sc[1], sc[5], sc[10], sc[17]
    a, b = pr[pair, 0], pr[pair, 1]
    Pa, Pb = PS[a], PS[b]   # views of the poses' rows (a 12-tuple passed down is many times slower here)
    ka, kb = kind[a], kind[b]
    if ka == PLANE or kb == PLANE:
        pl, x, P, Q, sign = (a, b, Pb, Pa, 1.0) if ka == PLANE else (b, a, Pa, Pb, -1.0)
        m0, m1, m2 = Q[5], Q[8], Q[11]   # the plane's local z
        if m0 * (P[0] - Q[0]) + m1 * (P[1] - Q[1]) + m2 * (P[2] - Q[2]) > rad[x]:
            return   # the bounding sphere clears the plane
        _against(sc, pair, x, pl, -1, P, Q, Q[0], Q[1], Q[2], m0, m1, m2, sign, r, A, rd, w, rigid, F, rec, nrec)
        return
    if (ka == SPHERE or ka == CAPSULE) and (kb == SPHERE or kb == CAPSULE):
        _round_pair(sc, pair, a, b, Pa, Pb, r, A, rd, w, rigid, F, rec, nrec)
        return
    if ka == MESH and kb == MESH:
        mesh_pair(sc, pair, a, b, Pa, Pb, r, A, rd, w, rigid, F, rec, nrec)
        return
    if ka == MESH or kb == MESH:
        msh, x, Px, Pm, sign = (a, b, Pb, Pa, 1.0) if ka == MESH else (b, a, Pa, Pb, -1.0)
        if (kind[x] == BOX or kind[x] == HULL) and rad[msh] <= rad[x]:
            # a mesh no larger than the polyhedron: its vertices on the polyhedron's faces
            _polytope_pair(sc, pair, a, b, Pa, Pb, r, A, rd, w, rigid, F, rec, nrec)
            return
        S = sc[29]
        for s in range(mesh_points(sc, x, msh, Px, Pm)):
            if S[s, 0] > 0.0:
                _apply(sc, pair, r, A, rd, w, rigid, F, rec, nrec, S[s, 2], S[s, 3], S[s, 4],
                       sign * S[s, 5], sign * S[s, 6], sign * S[s, 7], S[s, 1])
        return
    if ka == BOX or ka == HULL or kb == BOX or kb == HULL:
        _polytope_pair(sc, pair, a, b, Pa, Pb, r, A, rd, w, rigid, F, rec, nrec)
        return
    if (ka == CYLINDER and (kb == CYLINDER or kb == CAPSULE)) or (kb == CYLINDER and ka == CAPSULE):
        if _line_pair(sc, pair, a, b, Pa, Pb, r, A, rd, w, rigid, F, rec, nrec):
            return
    prm = sc[4]
    if ka == SPHERE or ka == CAPSULE:   # a rounded shape on a cylinder or an ellipsoid: n from b to a
        depth, n0, n1, n2, p0, p1, p2 = rounded_penetration(ka, Pa, prm[a], kb, Pb, prm[b])
        n0, n1, n2 = -n0, -n1, -n2
    elif kb == SPHERE or kb == CAPSULE:
        depth, n0, n1, n2, p0, p1, p2 = rounded_penetration(kb, Pb, prm[b], ka, Pa, prm[a])
    else:
        depth, n0, n1, n2, p0, p1, p2 = penetration(sc, a, b, Pa, Pb, 1e-10 * (rad[a] + rad[b]))
    if depth > 0.0:
        _apply(sc, pair, r, A, rd, w, rigid, F, rec, nrec, p0, p1, p2, n0, n1, n2, depth)


@kernel(_nrt=False)
def shape_contacts(sc, r, A, rd, w, rigid, F, rec, nrec):
    """Contact loads of every packed shape pair into F (module docstring); records into rec while it has room."""
    kind, ptr, adj, BB, order, stats = sc[1], sc[15], sc[16], sc[18], sc[19], sc[20]
    if sc[10].shape[0] == 0:
        return
    boxes(sc, r, A)
    ax = sweep_axis(BB)
    sort_order(order, BB, ax)
    k1, k2 = (ax + 1) % 3, (ax + 2) % 3
    stats[0] = 0
    stats[2] += 1
    ns = kind.shape[0]
    for ii in range(ns):
        i = order[ax, ii]
        if ptr[i + 1] == ptr[i]:
            continue
        hi = BB[i, 3 + ax]
        for jj in range(ii + 1, ns):
            j = order[ax, jj]
            if BB[j, ax] > hi:
                break
            if BB[j, k1] > BB[i, 3 + k1] or BB[i, k1] > BB[j, 3 + k1] or BB[j, k2] > BB[i, 3 + k2] \
                    or BB[i, k2] > BB[j, 3 + k2]:
                continue
            row = partner(ptr, adj, i, j)
            if row < 0:
                continue
            while row < ptr[i + 1] and adj[row, 0] == j:
                stats[0] += 1
                stats[1] += 1
                _narrow(sc, adj[row, 1], r, A, rd, w, rigid, F, rec, nrec)
                row += 1
