"""Coordinate constraints (couplers, gears, rack and pinion, user constraints) in absolute coordinates, packed
for the compiled kernels (`solvers.loopcoord`, CompiledModel slot 50), issue 29.

On the absolute-coordinate core (a closed loop: dims[5] == 0) each constraint f(X, t) = 0 is one row of the
step loop's KKT solve over the bodies' velocities: X_k is the joint coordinate of term k (an angle
continued from its auxiliary coordinate psi_k of system.constraints.coupler, X_k = psi_k + wrap(theta_k -
psi_k), or a slide), phi_q = sum_k f_k J_Xk on the bodies of the terms, nu = -f_t, gamma = -(sum_k f_k quad_Xk
+ sum_kl f_kl X'_k X'_l + 2 sum_k f_kt X'_k + f_tt). The link rows wrap(theta_k - psi_k) = 0 of the
reference path leave the solve: psi_k is carried along instead (psi' = theta', psi'' = theta'' from the
solved accelerations; set to the continued angle and its rate by each projection), so it only picks the
branch of the angle. A row whose terms move at most two bodies other than ground has the two Jacobian
blocks of every compiled row (written into Jc, solved with the other rows); a *wide* row (three or more
bodies: a differential, a planetary mesh through its carrier) keeps its Jacobian as the sum of its terms'
blocks f_k J_Xk and enters the solve bordered, through its Schur complement on top of the factorisation of
the other rows (solvers.loopcoord, docs/theory.md).

Layout `lc` (tuple): 0 main row (m,), 1 ptr (m + 1,) term ranges, 2 pbase (m,) program base of each row
[f, f_t, f_tt, f_k (n), f_kt (n), f_kl (n n)], 3-7 code, consts, tables, start, end (system.exprvm.pack),
8 term kind (nt,) (0 angle, 1 slide), 9, 10 the term joint's frames i, j (nt,), 11 its vectors (nt, 3, 3)
(f_i, g_i, f_j of an angle, h_i, s_i, s_j of a slide; body axes), 12, 13 aux q / v index of psi (nt,; -1
for a slide), 14 link row (nt,; -1), 15 the row side (0: the row's frame i, 1: its frame j, -1: ground) of
the term's frames i and j (nt, 2), 16 the constraint of each term (nt,), 17 the wide constraints (nw,)
(indices into 0; their main rows have frames 0, 0 and every side -1: nothing goes into Jc).
"""
from __future__ import annotations

import numpy as np


class _Unsupported(Exception):
    pass


def empty() -> tuple:
    """`pack` of a model without coordinate constraints in absolute coordinates (same types, m = 0)."""
    i, f = np.zeros(0, np.int64), np.zeros(0)
    return (i, np.zeros(1, np.int64), i, np.zeros((0, 2), np.int64), f, f, i, i, i, i, i, np.zeros((0, 3, 3)),
            i, i, i, np.zeros((0, 2), np.int64), i, i)


def programs(c) -> list:
    """The derivative expressions of coordinate constraint c in the order of the program block
    [f, f_t, f_tt, f_k (n), f_kt (n), f_kl (n n)] (shared with system.jointtree.coord_arrays)."""
    names = c.variables[1:]
    return [c.expr, c.derivs["t"], c.derivs[("t", "t")], *(c.derivs[n] for n in names),
            *(c.derivs[(n, "t")] for n in names), *(c.derivs[(a, b)] for a in names for b in names)]


def link_rows(sys) -> np.ndarray:
    """Row indices of the link rows wrap(theta - psi) = 0 of every coordinate constraint."""
    out = []
    for g in sys.groups:
        if g.kind == "coord":
            for ev, r0 in zip(g.fns, g.row_adr):
                out.extend(range(int(r0), int(r0) + ev.nlink))
    return np.array(out, dtype=np.int64)


def wide_rows(lc) -> np.ndarray:
    """Main rows (System row indices) of the wide constraints of `lc` (terms moving three or more bodies)."""
    return lc[0][lc[17]]


def only_wide(lc, rows) -> tuple:
    """`lc` with its wide constraints restricted to those whose main row is among `rows` (solved for)."""
    keep = lc[17][np.isin(lc[0][lc[17]], rows)]
    return (*lc[:17], keep.astype(np.int64))


def pack(sys, bi, bj) -> tuple[tuple, int]:
    """(`lc`, stack size) of the System's coordinate constraints; writes each main row's two frames into the
    packed frame arrays bi, bj (nc,) (ground, ground for a wide row: terms moving three or more bodies,
    whose Jacobian stays with its terms)."""
    from . import exprvm
    groups = [g for g in sys.groups if g.kind == "coord"]
    if not groups:
        return empty(), 4
    cols = {k: [] for k in ("kind", "bi", "bj", "V", "aq", "av", "link", "side", "con")}
    mrow, ptr, pbase, progs, wide = [], [0], [], [], []
    for g in groups:
        for ev, r0 in zip(g.fns, g.row_adr):
            c = ev.spec
            frames = sorted({f for geom, *_ in ev.terms for f in (geom.bi, geom.bj) if f != 0})
            is_wide = len(frames) > 2
            if is_wide:
                wide.append(len(mrow))
                fi, fj = 0, 0
            else:
                fi, fj = (0, frames[0]) if len(frames) == 1 else ((0, 0) if not frames else tuple(frames))
            row = int(r0) + ev.nlink
            bi[row], bj[row] = fi, fj
            link = int(r0)
            for geom, dof, aq, av in ev.terms:
                rot = dof == "rotation"
                cols["kind"].append(0 if rot else 1)
                cols["bi"].append(geom.bi)
                cols["bj"].append(geom.bj)
                cols["V"].append((geom.f_i, geom.g_i, geom.f_j) if rot else (geom.h_i, geom.s_i, geom.s_j))
                cols["aq"].append(aq if rot else -1)
                cols["av"].append(av if rot else -1)
                cols["link"].append(link if rot else -1)
                link += rot
                cols["side"].append([-1 if f == 0 or is_wide else (0 if f == fi else 1) for f in (geom.bi, geom.bj)])
                cols["con"].append(len(mrow))
            slots = {name: k for k, name in enumerate(c.variables)}
            pbase.append(len(progs))
            progs.extend(exprvm.compile_expr(e, slots) for e in programs(c))
            ptr.append(ptr[-1] + len(c.variables) - 1)
            mrow.append(row)
    pk = exprvm.pack(progs)
    i64 = lambda k: np.array(cols[k], np.int64)  # noqa: E731
    return (np.array(mrow, np.int64), np.array(ptr, np.int64), np.array(pbase, np.int64), pk.code, pk.consts,
            pk.tables, pk.start, pk.end, i64("kind"), i64("bi"), i64("bj"),
            np.array(cols["V"], float).reshape(-1, 3, 3), i64("aq"), i64("av"), i64("link"),
            np.array(cols["side"], np.int64).reshape(-1, 2), i64("con"), np.array(wide, np.int64)), \
        max(4, int(pk.stack_size))


def work(lc, stack, nf=1, nc=0) -> tuple:
    """Scratch of solvers.loopcoord (Work slot 52): x (1 + widest row), stack, X, X' (nt), the terms'
    Jacobian blocks (nt, 2, 6), quad (nt), f_k (nt); for the nw wide rows (frames nf, rows nc): 7 E
    (nw, nf, 6) and 8 EL (nw, nc) the solve of each row's load G_a^T with the other rows (accelerations,
    multipliers), 9 P = G E (nw, nw), 10 its pivoted Cholesky factor (1, nw, nw), 11 the pivot order (1 + nw)
    (rank first), 12 the right-hand side (1, nw), 13 a load (nf, 6), 14 zero row right-hand sides (nc)."""
    nt = len(lc[8])
    width = int(np.max(np.diff(lc[1]))) if len(lc[0]) else 0
    nw = len(lc[17])
    nfw, ncw = (nf, nc) if nw else (1, 0)
    z = np.zeros
    return (z(1 + width), z(max(stack, 4)), z(nt), z(nt), z((nt, 2, 6)), z(nt), z(nt),
            z((nw, nfw, 6)), z((nw, ncw)), z((nw, nw)), z((1, nw, nw)), np.zeros(1 + nw, np.int64), z((1, nw)),
            z((nfw, 6)), z(ncw))
