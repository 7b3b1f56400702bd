"""Joint-coordinate model of a tree of one-degree-of-freedom joints (the articulated-body fast path).

A model whose joints form a tree rooted at ground, every joint a revolute, translational or fixed
joint between rigid bodies, is integrated in joint coordinates (one angle [rad] or slide [m] per joint,
and its rate) by the articulated-body algorithm (`solvers.fasttree`): the joints hold by construction and
a step costs O(N) with a small constant. Coordinates are measured from the assembled configuration (0
there). Couplers, gears, rack and pinion, user coordinate constraints and motion drivers of the tree's
joints are carried as rows f(X, t) = 0 over the joint coordinates (`coord_arrays`, solved and projected
on by solvers.treecoord), unless the drivers leave no free coordinate (the kinematic analysis then).
Anything else keeps the absolute-coordinate core (couplers in closed loops: the reference path).

`tree_arrays(sys, rows, q, v)` returns (mode, arrays): mode 1 and the arrays of the joint tree when the
model qualifies, else mode 0 and empty arrays of the same types (one compiled signature for all):

    parent (nf,)    parent frame of each frame (-1 for ground)
    jtype (nf,)     0 fixed, 1 revolute, 2 translational (ground: -1)
    axis (nf, 3)    joint axis in the parent's body axes (unit)
    spt (nf, 3)     joint point in the parent's body axes, from its CM [m]
    c0 (nf, 3)      child CM in the parent's body axes at assembly [m]
    R0 (nf, 3, 3)   child axes in the parent's axes at assembly
    order (nb,)     frames parents first
    qadr (nf,)      index of the frame's joint coordinate (-1: fixed joint or ground)
"""
from __future__ import annotations

import numpy as np

ONE_DOF = {"revolute": 1, "translational": 2, "fixed": 0}
TREE_DRIVERS = True   # motion drivers of tree joints as rows theta_k - f(t) = 0 (solvers.treecoord)
KERNEL_KINDS = ("sph", "dot1", "dot2", "angle", "slide", "screw", "cvel")   # (system.assemble's)


def empty_arrays(nf: int) -> tuple:
    """The arrays of a model that does not take the joint-coordinate path (same types, zero rows)."""
    return (np.full(0, -1, np.int64), np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros((0, 3)),
            np.zeros((0, 3)), np.zeros((0, 3, 3)), np.zeros(0, np.int64), np.zeros(0, np.int64))


def _why_not(sys, rows) -> str | None:
    """Reason the model cannot take the joint-coordinate path, or None."""
    model = sys.model
    if model.motions:
        if not TREE_DRIVERS:
            return "motion drivers"
        if any(getattr(mo.function, "symbolic", None) is not None for mo in model.motions.values()):
            return "motion drivers reading model inputs (re-projected when an input changes)"
        moving = sum(jt.kind in ("revolute", "translational") for jt in model.joints.values())
        if len(model.motions) + len(getattr(model, "coord_constraints", {})) >= moving:
            return "no free coordinate (the kinematic analysis)"
    if len(sys.lock_rows) or any(g.kind == "curve" for g in sys.groups):
        return "path or friction constraints"
    if any(g.kind not in KERNEL_KINDS + ("coord",) for g in sys.groups):
        return "rows the compiled core does not carry"
    if len(rows) != sys.nc:
        return "redundant constraints"
    if any(b.is_particle for b in sys.bodies):
        return "particles"
    if any(jt.kind not in ONE_DOF for jt in model.joints.values()):
        return "joints other than revolute, translational and fixed"
    if len(model.joints) != len(sys.bodies):
        return "not a tree of joints (loops or free bodies)"
    if sys.bodies:
        J = np.array([b.inertia for b in sys.bodies], float)
        ev = np.linalg.eigvalsh(J)
        if min(b.mass for b in sys.bodies) <= 0 or np.any(ev.min(axis=1) < -1e-12 * np.abs(ev).max(axis=1)):
            return "a body without positive mass and positive semi-definite inertia"
    return None


def _pivots_positive(sys, parent, jtype, axis, spt, c0, R0) -> bool:
    """True when every revolute's child body has a positive moment of inertia about the joint axis
    through the joint point (a lower bound of the articulated-body pivot D = S^T I^A S, which only grows
    with the subtree): slender rods and bodies with zero axial inertia qualify; a particle-like body
    turning about an axis through its own centre does not."""
    for c in np.flatnonzero(jtype == 1):
        b = sys.bodies[c - 1]
        a = axis[c]
        d = spt[c] - c0[c]
        d_perp = d - (d @ a) * a
        I_p = R0[c] @ np.asarray(b.inertia, float) @ R0[c].T
        moment = a @ I_p @ a + b.mass * (d_perp @ d_perp)
        if not moment > 1e-12 * max(np.trace(I_p) + b.mass * (d @ d), 1e-300):
            return False
    return True


def tree_arrays(sys, rows, q, v) -> tuple[int, tuple]:
    """(mode, arrays) of System `sys` at its assembled state (q, v); see the module docstring."""
    nf = sys.nbody + 1
    if _why_not(sys, rows) is not None:
        return 0, empty_arrays(nf)
    from .frames import body_frames
    fr = body_frames(sys, q, v)
    adj: dict[int, list] = {}
    for jt in sys.model.joints.values():
        g = sys.geoms[jt.name]
        adj.setdefault(g.bi, []).append((g.bj, jt, g))
        adj.setdefault(g.bj, []).append((g.bi, jt, g))
    parent = np.full(nf, -1, np.int64)
    jtype = np.full(nf, -1, np.int64)
    axis, spt, c0 = np.zeros((nf, 3)), np.zeros((nf, 3)), np.zeros((nf, 3))
    R0 = np.zeros((nf, 3, 3))
    qadr = np.full(nf, -1, np.int64)
    seen, order, queue = {0}, [], [0]
    while queue:
        p = queue.pop(0)
        for c, jt, g in adj.get(p, []):
            if c in seen:
                if parent[p] != c:    # an edge back to a frame already in the tree: a loop
                    return 0, empty_arrays(nf)
                continue
            seen.add(c)
            order.append(c)
            queue.append(c)
            parent[c] = p
            jtype[c] = ONE_DOF[jt.kind]
            on_i = g.bi == p
            axis[c] = (g.h_i if on_i else g.h_j) / np.linalg.norm(g.h_i if on_i else g.h_j)
            spt[c] = g.s_i if on_i else g.s_j
            Ap = fr.A[p]
            c0[c] = Ap.T @ (fr.r[c] - fr.r[p])
            R0[c] = Ap.T @ fr.A[c]
    if len(order) != nf - 1 or not np.any(jtype[1:] > 0):   # (all welded: nothing to integrate)
        return 0, empty_arrays(nf)
    if not _pivots_positive(sys, parent, jtype, axis, spt, c0, R0):
        return 0, empty_arrays(nf)
    n = 0
    for c in order:
        if jtype[c] > 0:
            qadr[c] = n
            n += 1
    return 1, (parent, jtype, axis, spt, c0, R0, np.array(order, np.int64), qadr)


def joint_state(sys, arrays, q, v) -> np.ndarray:
    """Joint-coordinate state [theta (nj), theta_dot (nj)] at the assembled state (q, v): coordinates 0,
    rates the relative angular velocity about / CM velocity along each joint axis."""
    from .frames import body_frames
    parent, jtype, axis, spt, c0, R0, order, qadr = arrays
    nj = int(np.count_nonzero(qadr >= 0))
    y = np.zeros(2 * nj)
    fr = body_frames(sys, q, v)
    for c in order:
        if qadr[c] < 0:
            continue
        p = parent[c]
        a = fr.A[p] @ axis[c]
        if jtype[c] == 1:
            y[nj + qadr[c]] = a @ (fr.w[c] - fr.w[p])
        else:
            rel = fr.rd[c] - fr.rd[p] - np.cross(fr.w[p], fr.r[c] - fr.r[p])
            y[nj + qadr[c]] = a @ rel
    return y


def coord_rows(sys) -> np.ndarray:
    """Rows of the model's coordinate constraints (link and main rows of couplers, gears, user constraints)
    and of its motion drivers: the rows the tree solves in joint coordinates (`coord_arrays`)."""
    out = [np.arange(r0, r0 + ev.nrow) for g in sys.groups if g.kind == "coord" for ev, r0 in zip(g.fns, g.row_adr)]
    out += [np.asarray(sys.owner_rows[name], np.int64) for name in sys.model.motions]
    return np.concatenate(out).astype(np.int64) if out else np.zeros(0, np.int64)


def empty_coords() -> tuple:
    """`coord_arrays` of a model without coordinate constraints (same types, m = 0)."""
    i, f = np.zeros(0, np.int64), np.zeros(0)
    return (i, f, f, np.zeros(1, np.int64), i, np.zeros((0, 2), np.int64), f, f, i, i, i, i, i, i, i,
            np.zeros((0, 3)), i, i, i)


def coord_arrays(sys, arrays, q, v) -> tuple[tuple, int]:
    """The coordinate constraints of a joint-coordinate tree for solvers.treecoord (layout in its docstring)
    at the assembled state (q, v): each term's tree coordinate, X_k = x0_k + s_k theta_k (x0: the assembled
    value: the auxiliary angle of coupler.py for a rotation, the slide for a translation), and the programs
    f, f_t, f_tt, f_k, f_kt, f_kl of each row (system.exprvm); then one row X - g(t) per motion driver (g
    evaluated by the compiled drivers); and the programs' stack size."""
    from . import exprvm
    from .frames import body_frames
    from .loopcoords import programs
    groups = [g for g in sys.groups if g.kind == "coord"]
    motions = list(sys.model.motions.values())
    if not groups and not motions:
        return empty_coords(), 4
    fr = body_frames(sys, q, v)
    cols = {k: [] for k in ("q", "s", "x0", "link", "aq", "av", "ff", "pt", "frame")}
    ptr, pbase, mrow, progs, drv, wrap = [0], [], [], [], [], []
    for g in groups:
        for ev, r0 in zip(g.fns, g.row_adr):
            c = ev.spec
            link = r0
            for (geom, dof, aq, av) in ev.terms:
                x0 = float(q[aq]) if dof == "rotation" else None
                _term(cols, arrays, fr, geom, dof, x0, aq, av, link if dof == "rotation" else -1)
                link += dof == "rotation"
            names = c.variables[1:]
            slots = {name: k for k, name in enumerate(c.variables)}
            pbase.append(len(progs))
            progs.extend(exprvm.compile_expr(e, slots) for e in programs(c))
            ptr.append(ptr[-1] + len(names))
            mrow.append(link)
            drv.append(-1)
            wrap.append(0)
    from .packing import pack_rows
    packed_drv = (sys.derived.get("packed") or pack_rows(sys))[5]   # each row's driver index
    for mo in motions:   # motion drivers: wrap(X - g(t)) (rotation) or X - g(t) (translation) = 0, g from
        geom = sys.geoms[mo.joint.name]   # the compiled drivers (fastdyn.drivers_at), callables included
        row = int(sys.owner_rows[mo.name][0])
        _term(cols, arrays, fr, geom, mo.dof, None, -1, -1, -1)
        pbase.append(len(progs))
        ptr.append(ptr[-1] + 1)
        mrow.append(row)
        drv.append(int(packed_drv[row]))
        wrap.append(int(mo.dof == "rotation"))
    pk = exprvm.pack(progs)
    i64 = lambda k: np.array(cols[k], np.int64)  # noqa: E731
    return (i64("q"), np.array(cols["s"], float), np.array(cols["x0"], float), np.array(ptr, np.int64),
            np.array(pbase, np.int64), pk.code, pk.consts, pk.tables, pk.start, pk.end, np.array(mrow, np.int64),
            i64("link"), i64("aq"), i64("av"), i64("ff"), np.array(cols["pt"], float).reshape(-1, 3),
            i64("frame"), np.array(drv, np.int64), np.array(wrap, np.int64)), max(4, int(pk.stack_size))


def _term(cols, arrays, fr, geom, dof, x0, aq, av, link):
    """Append one term (a joint coordinate X = x0 + s theta of the tree) to the columns of `coord_arrays`;
    x0 None: the joint's coordinate at the frames fr (a rotation's angle in (-pi, pi], a slide)."""
    from .constraints import primitives as pr
    parent, axis, qadr = arrays[0], arrays[2], arrays[7]
    child = geom.bj if parent[geom.bj] == geom.bi else geom.bi
    a = fr.A[parent[child]] @ axis[child]
    sense = 1.0 if child == geom.bj else -1.0
    bi, bj = np.array([geom.bi]), np.array([geom.bj])
    if dof == "rotation":
        s_ = float(np.sign(a @ (fr.A[geom.bi] @ np.cross(geom.f_i, geom.g_i)))) * sense
        if x0 is None:
            x0 = float(pr.angle(fr, bi, bj, geom.f_i[None], geom.g_i[None], geom.f_j[None])[0][0])
    else:
        s_ = float(a @ (fr.A[geom.bi] @ geom.h_i)) * sense
        x0 = float(pr.dot2(fr, bi, bj, geom.h_i[None], geom.s_i[None], geom.s_j[None]).phi[0])
    for k, val in (("q", qadr[child]), ("s", s_), ("x0", x0), ("aq", aq), ("av", av), ("ff", geom.bj),
                   ("pt", geom.s_j), ("frame", child), ("link", link)):
        cols[k].append(val)

