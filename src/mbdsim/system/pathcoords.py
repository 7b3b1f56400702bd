"""Point-on-curve (path) constraints packed for the compiled kernels (`solvers.pathcoord`, CompiledModel slot 49),
issue 29: curves written as expression strings in s (mbdsim.Curve of three expressions), mbdsim.Spline, and
Python-callable curves tabulated as splines to the run's tolerance (system.pathtable).

The curve parameter s of each constraint stays an auxiliary coordinate of the state (system.constraints.path),
but not a velocity variable of the KKT solve (the compiled velocity layout has six slots per frame): the
kernel takes s* = the foot point of P on the curve near the state's s (Newton on c'(s) . (c(s) - P) = 0),
and of the three rows d = P_j - C_i(s*) = 0 solves the two normal components n_a . d = 0 (phi_q = n_a^T J_d,
gamma = -n_a . quad_d with the parameter-rate terms of quad_d at s' = t . d'|_s / |t|^2, t = A_i c'(s*));
the tangential component t^ . d is a residual only. s, s' are set to s* and its rate by every projection and
integrated along (s'' = t . (J_d vd + quad_d) / |t|^2), so that s only picks the foot point's branch.

Layout `pc` (tuple): 0 the three rows of each constraint (n, 3), 1, 2 frames i (curve) and j (point) (n,),
3 the point s_j on body j (n, 3) [m, body axes], 4 A0^T (n, 3, 3) and 5 r0 (n, 3): the curve's ground axes at
t = 0 to body i's (c_B = A0^T (C - r0)), 6, 7 aux q / v index of s (n,), 8-12 code, consts, tables, start, end
(system.exprvm.pack): nine programs per constraint (x, y, z, x', y', z', x'', y'', z'' in s; constants for a
spline), 13 curve kind (n,) (0 expressions, 1 mbdsim.Spline), 14 first segment of each spline (n + 1,) (its
breakpoints start at segment + constraint index), 15 breakpoints [m] and 16 the segments' cubic coefficients
(nseg, 4, 3) (scipy's CubicSpline: c0 u^3 + c1 u^2 + c2 u + c3, u = s - breakpoint), 17 periodic flag (n,).
"""
from __future__ import annotations

import numpy as np


def empty() -> tuple:
    """`pack` of a model without path constraints (same types, n = 0)."""
    i, f = np.zeros(0, np.int64), np.zeros(0)
    return (np.zeros((0, 3), np.int64), i, i, np.zeros((0, 3)), np.zeros((0, 3, 3)), np.zeros((0, 3)), i, i,
            np.zeros((0, 2), np.int64), f, f, i, i, i, np.zeros(1, np.int64), f, np.zeros((0, 4, 3)), i)


def tangent_rows(sys) -> np.ndarray:
    """The third (tangential) row of every path constraint: a residual, never solved for."""
    return np.array([int(r0) + 2 for g in sys.groups if g.kind == "curve" for r0 in g.row_adr], dtype=np.int64)


def pack(sys, rtol=None, atol=None) -> tuple[tuple, int]:
    """(`pc`, stack size) of the System's path constraints; a Python-callable curve is tabulated as a spline
    to the run's rtol / atol (system.pathtable)."""
    from . import exprvm
    from .pathtable import tabulate
    groups = [g for g in sys.groups if g.kind == "curve"]
    if not groups:
        return empty(), 4
    from ..model.curves import Spline
    rows, bi, bj, sj, A0T, r0, aq, av, progs = [], [], [], [], [], [], [], [], []
    ckind, sptr, breaks, coef, periodic = [], [0], [], [], []
    for g in groups:
        for k, (cp, r) in enumerate(zip(g.fns, g.row_adr)):
            curve = cp.spec.curve
            exprs = getattr(curve, "expressions", None)
            tabulated = not isinstance(curve, Spline) and exprs is None
            if isinstance(curve, Spline) or tabulated:   # a Python callable: its table (system.pathtable)
                cs = curve._cs if not tabulated else tabulate(curve, rtol, atol, cp.spec.name)[0]
                ckind.append(1)
                breaks.extend(np.asarray(cs.x, float))
                coef.extend(np.moveaxis(np.asarray(cs.c, float), 1, 0))   # (nseg, 4, 3)
                sptr.append(sptr[-1] + len(cs.x) - 1)
                periodic.append(int(curve.closed))
                progs.extend(exprvm.constant_program(0.0) for _ in range(9))
            else:
                e1 = [e.derivative("s") for e in exprs]
                e2 = [e.derivative("s") for e in e1]
                progs.extend(exprvm.compile_expr(e, {"s": 0}) for e in (*exprs, *e1, *e2))
                ckind.append(0)
                sptr.append(sptr[-1])
                periodic.append(0)
            rows.append([int(r), int(r) + 1, int(r) + 2])
            bi.append(int(g.bi[k]))
            bj.append(int(g.bj[k]))
            sj.append(np.asarray(g.vecs[0][k], float))
            A0T.append(np.asarray(cp.A0, float).T)
            r0.append(np.asarray(cp.r0, float))
            aq.append(int(sys.aux_q_idx[cp.aux]))
            av.append(int(sys.aux_v_idx[cp.aux]))
    pk = exprvm.pack(progs)
    i64 = lambda x: np.array(x, np.int64)  # noqa: E731
    return (i64(rows).reshape(-1, 3), i64(bi), i64(bj), np.array(sj).reshape(-1, 3), np.array(A0T).reshape(-1, 3, 3),
            np.array(r0).reshape(-1, 3), i64(aq), i64(av), pk.code, pk.consts, pk.tables, pk.start, pk.end,
            i64(ckind), i64(sptr), np.array(breaks, float), np.array(coef, float).reshape(-1, 4, 3), i64(periodic)), \
        max(4, int(pk.stack_size))


def work(pc, stack) -> tuple:
    """Scratch of solvers.pathcoord (Work slot 51): x (1,), stack, s* (n), s' (n), the ground-axes frame
    (t^, n1, n2) (n, 3, 3), |t| (n), the three rows' Jacobian blocks (n, 3, 2, 6), quad_d (n, 3), the
    curve c, c', c'' in body-i axes (n, 3, 3)."""
    n = len(pc[1])
    z = np.zeros
    return (z(1), z(max(stack, 4)), z(n), z(n), z((n, 3, 3)), z(n), z((n, 3, 2, 6)), z((n, 3)), z((n, 3, 3)))
