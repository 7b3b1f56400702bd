"""Constraints between joint coordinates (couplers, gears, user constraints): f(x, t) = 0.

Each angle coordinate taking part gets an auxiliary coordinate psi (massless; in q and v after the
bodies and the path parameters, see System.aux_q_idx) that counts whole turns, and one link row

    wrap(theta(q) - psi) = 0        theta: the joint angle [rad] (primitive `angle`, wrapped), so psi
                                    is the continuous angle; Jacobian J_theta - e_psi, gamma = -quad_theta

so that f sees continuous coordinates X (psi for angles, the slide h_i . (P_j - P_i) [m] for
translations) and every row is single-valued: no state, any number of turns.  The main row:

    phi = f(X, t),  phi_q = sum_k f_k J_Xk,  nu = -f_t,
    gamma = -(sum_k f_k quad_Xk + sum_kl f_kl X'_k X'_l + 2 sum_k f_kt X'_k + f_tt)

with exact symbolic derivatives f_k, f_kl (mbdsim.expressions).  Rows are evaluated here by numpy for the
reference path; the compiled core evaluates them on a joint-coordinate tree (solvers.treecoord) and in
closed loops (solvers.loopcoord, where psi only picks the angle's branch).  The load the constraint
transmits along joint coordinate k is -f_k lambda (lambda: the main row's multiplier).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..frames import Frames
from . import primitives as pr
from .base import RowSpec


@dataclass
class CoordRowSpec(RowSpec):
    """All rows of one coordinate constraint (link rows first, then the main row); fn: its CoordEval."""

    @property
    def nrow(self) -> int:
        return self.fn.nrow


class CoordEval:
    """Evaluator of one CoordConstraint: terms (geom, dof, aux q index, aux v index or -1)."""

    def __init__(self, spec, terms):
        self.spec, self.terms = spec, terms
        self.nlink = sum(1 for t in terms if t[1] == "rotation")
        self.nrow = self.nlink + 1

    def evaluate(self, sys, fr, q, v, t, r0, phi, J, nu, gamma):
        """Write the rows starting at r0 into phi, J (None: no Jacobian), nu, gamma."""
        c = self.spec
        X, Xd, JX, quad = [], [], [], []
        link = r0
        for g, dof, aq, av in self.terms:
            bi, bj = np.array([g.bi]), np.array([g.bj])
            if dof == "rotation":
                th, rows, thd = pr.angle(fr, bi, bj, g.f_i[None], g.g_i[None], g.f_j[None])
                Jr = _dense(sys, fr, rows)
                Jr[av] -= 1.0
                phi[link] = (th[0] - q[aq] + np.pi) % (2 * np.pi) - np.pi
                gamma[link] = -rows.quad[0]
                if J is not None:
                    J[link] = Jr
                link += 1
                e = np.zeros(sys.nv)
                e[av] = 1.0
                X.append(q[aq]); Xd.append(v[av]); JX.append(e); quad.append(0.0)
            else:
                rows = pr.dot2(fr, bi, bj, g.h_i[None], g.s_i[None], g.s_j[None])
                Js = _dense(sys, fr, rows)
                X.append(rows.phi[0]); Xd.append(float(Js @ v)); JX.append(Js); quad.append(rows.quad[0])
        env = dict(zip(c.variables, [t, *X]))
        val = lambda e: _const(e, env, c.variables)  # noqa: E731
        names = c.variables[1:]
        fk = np.array([val(c.derivs[n]) for n in names])
        row = link
        phi[row] = val(c.expr)
        if J is not None:
            J[row] = fk @ np.array(JX)
        nu[row] = -val(c.derivs["t"])
        g2 = float(fk @ np.array(quad)) + val(c.derivs[("t", "t")])
        for a, xa in zip(names, Xd):
            g2 += 2 * val(c.derivs[(a, "t")]) * xa
            for b, xb in zip(names, Xd):
                g2 += val(c.derivs[(a, b)]) * xa * xb
        gamma[row] = -g2

    def loads(self, X_env):
        """Coefficients f_k at the coordinates X_env (dict variable -> value): the load on coordinate k
        is -f_k lambda."""
        c = self.spec
        return np.array([_const(c.derivs[n], X_env, c.variables) for n in c.variables[1:]])


def _const(e, env, variables):
    """Value of Expr e at env (only the variables it depends on are passed)."""
    return float(e.evaluate(**{k: env[k] for k in variables if e.depends_on(k)}))


def _dense(sys, fr, rows):
    from ..equations import scatter_jacobian
    out = np.zeros((1, sys.nv))
    scatter_jacobian(sys, fr, np.array([0]), rows, out)
    return out[0]


def coord_specs(model, fid, geoms, aux_q0, aux_v0):
    """Row specs, initial psi and psi_dot, aux q / v indices of the model's coordinate constraints.

    psi starts at the joint angle of the bodies as drawn (zero for joints given by bodies)."""
    specs, psi0, aq, av = [], [], [], []
    fr = None
    for c in getattr(model, "coord_constraints", {}).values():
        terms = []
        for jt, dof in c.terms:
            g = geoms[jt.name]
            if dof == "rotation":
                if fr is None:
                    fr = _drawn_frames(model, fid)
                th = pr.angle(fr, np.array([g.bi]), np.array([g.bj]), g.f_i[None], g.g_i[None], g.f_j[None])[0]
                terms.append((g, dof, aux_q0 + len(psi0), aux_v0 + len(psi0)))
                aq.append(aux_q0 + len(psi0)); av.append(aux_v0 + len(psi0))
                psi0.append(float(th[0]))
            else:
                terms.append((g, dof, -1, -1))
        specs.append(CoordRowSpec("coord", (), c.name, CoordEval(c, terms)))
    return specs, psi0, [0.0] * len(psi0), np.array(aq, dtype=int), np.array(av, dtype=int)


def _drawn_frames(model, fid):
    nf = len(fid)
    r, A = np.zeros((nf, 3)), np.broadcast_to(np.eye(3), (nf, 3, 3)).copy()
    for b, k in fid.items():
        r[k], A[k] = b.position, b.orientation
    return Frames(r, A, np.zeros((nf, 3)), np.zeros((nf, 3)))


def coord_terms(sys, group, fr, q, v, t, phi, J, nu, gamma):
    """Evaluate a "coord" group into the global arrays (rows from each spec's first-row address)."""
    for ev, r0 in zip(group.fns, group.row_adr):
        ev.evaluate(sys, fr, q, v, t, r0, phi, J, nu, gamma)


def coupler_load(res, name):
    """Generalized load (N, k) the coordinate constraint `name` applies along each of its joint
    coordinates (order of its terms): a torque [N m] about the axis of a rotation, a force [N] along the
    axis of a translation, acting on the joint's body_j (the opposite on body_i): -f_k lambda."""
    from ...errors import ModelError
    from ..frames import body_frames
    sys = res.system
    spec = next((g.fns[k] for g in sys.groups if g.kind == "coord" for k in range(len(g.fns))
                 if g.fns[k].spec.name == name), None)
    if spec is None:
        raise ModelError(f"coupler {name!r}", "name", "is not a coupler, gear or user constraint of the "
                         "analysed model")
    if res.lambda_ is None:
        raise ValueError("coupler loads are not available: this result holds no multipliers")
    lam = np.asarray(res.lambda_)[:, sys.owner_rows[name][-1]]
    out = np.zeros((len(res.time), len(spec.terms)))
    for n, (q, t) in enumerate(zip(np.asarray(res.q), res.time)):
        fr = body_frames(sys, q)
        X = []
        for g, dof, aq, _ in spec.terms:
            if dof == "rotation":
                X.append(q[aq])
            else:
                X.append(pr.dot2(fr, np.array([g.bi]), np.array([g.bj]), g.h_i[None], g.s_i[None],
                                 g.s_j[None]).phi[0])
        out[n] = -spec.loads(dict(zip(spec.spec.variables, [t, *X]))) * lam[n]
    return out
