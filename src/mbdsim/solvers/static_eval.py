"""The evaluations of the static equilibrium solve (solvers.static): batches of configurations on the chart
q(z) = project(q0 (+) N z) at one time, each giving the reduced load f = N^T r and max |r| of the unbalanced
load r = Q - phi_q^T lambda_ (least-squares multipliers).

`evaluator(sys, rows, sf)` returns the compiled one (`Compiled`: solvers.faststatic, every configuration of a
batch in one call) when the model compiles in absolute coordinates without joint friction (point-on-curve
constraints and couplers included, gears and differentials: their curve parameters and continued angles
follow the configuration, so the tangent basis leaves them out), else the reference (`Reference`: numpy,
the force elements' own evaluators). Both give, for the first row of a batch, the configuration, the loads Q (nv,) [N, N m] and the
Jacobian of the rows solved for (for the tangent basis); velocity-like vectors: CM translations in ground
axes, rotations in body axes (the System's layout).
"""
from __future__ import annotations

import numpy as np

from ..errors import SolverError
from ..system.dynamics import applied_forces
from ..system.equations import constraint_terms
from ..system.frames import body_frames
from .reduced import Chart, null_basis, tangent_residual

PROJ_TOL = 1e-12   # Newton tolerance of the compiled chart's projection: max |phi| [m or rad]


class Batch:
    """One batch: F (m, d) reduced loads, R (m,) max |r|, X (m, nq) configurations; Q0 (nv,), J0 (rows, nv)
    and r0 (nv,) at the first row; `done` rows evaluated (< m: the projection of row `done` failed)."""

    def __init__(self, F, R, X, Q0, J0, r0, done):
        self.F, self.R, self.X, self.Q0, self.J0, self.r0, self.done = F, R, X, Q0, J0, r0, done


class Reference:
    """The numpy evaluations (force elements' evaluators, `reduced.Chart`)."""

    compiled = False

    def __init__(self, sys, rows, sf):
        self.sys, self.rows, self.sf = sys, np.asarray(rows, dtype=int), sf

    def batch(self, q0, N, Z, t, accept):
        from .static import _follow_angles
        sys, zero = self.sys, np.zeros(self.sys.nv)
        if len(Z):
            _follow_angles(sys, q0, zero if accept else N @ Z[-1], t)
        chart = Chart(sys, q0, t, self.rows, N)
        m = len(Z)
        F, R, X = np.zeros((m, N.shape[1])), np.zeros(m), np.zeros((m, sys.nq))
        Q0 = J0 = r0 = None
        for k, z in enumerate(Z):
            try:
                x = chart.q(z)
            except SolverError:
                return Batch(F, R, X, Q0, J0, r0, k)
            Q = applied_forces(sys, body_frames(sys, x, zero), t, self.sf(t, x, zero) if self.sf else None)
            r = tangent_residual(sys, x, t, self.rows, Q)[0]
            F[k], R[k], X[k] = N.T @ r, float(np.max(np.abs(r), initial=0.0)), x
            if k == 0:
                Q0, r0 = Q, r
                J0 = constraint_terms(sys, x, zero, t)[1][self.rows] if len(self.rows) else np.zeros((0, sys.nv))
        return Batch(F, R, X, Q0, J0, r0, m)

    def basis(self, J0, scale):
        """The tangent basis N (nv, d) at the first row of a batch (`reduced.null_basis`)."""
        return null_basis(J0, scale)

    def angle_refs(self):
        """None: the force elements keep their own references, by time (`static._follow_angles`)."""
        return None

    def set_angle_refs(self, refs):
        return None

    def record(self, t):
        """Nothing: `static._follow_angles` anchored the angles at every iteration."""
        return None


class Compiled:
    """The compiled evaluations (solvers.faststatic.reduced_forces) of a model compiled in absolute
    coordinates; Python-callable loads called back (solvers.pyloads), their errors raised as they are."""

    compiled = True

    def __init__(self, sys, rows, cm):
        from ..system.compiled import Work
        from . import pyloads
        self.sys, self.cm = sys, cm
        self.work = Work.for_model(cm)
        self.pyloads = pyloads.attach(sys, cm, self.work)
        w = self.work.arrays()
        self.nrows = len(cm.arrays()[32]) + len(w[46]) + len(cm.arrays()[50][17])
        self.anchors = _angle_measures(sys, cm)
        # point-on-curve and couplers: the kernels eliminate the curve parameters (foot points) and carry the
        # couplers' continued angles along, so the rows leave their columns empty; the tangent basis is that
        # of the other velocity variables
        aux = np.asarray(getattr(sys, "aux_v_idx", ()), dtype=int)   # (and the couplers' continued angles)
        self.free = None if not len(aux) else np.setdiff1d(np.arange(sys.nv), aux)

    def basis(self, J0, scale):
        """The tangent basis N (nv, d) at the first row of a batch (`reduced.null_basis`), without the
        auxiliary velocity variables (curve parameters, couplers' continued angles: zero rows of N)."""
        if self.free is None:
            return null_basis(J0, scale)
        Nf = null_basis(J0[:, self.free], np.asarray(scale)[self.free])
        N = np.zeros((self.sys.nv, Nf.shape[1]))
        N[self.free] = Nf
        return N

    def batch(self, q0, N, Z, t, accept):
        from . import faststatic
        sys = self.sys
        m, d = len(Z), N.shape[1]
        F, R, X = np.zeros((m, d)), np.zeros(m), np.zeros((m, sys.nq))
        Q0, J0 = np.zeros(sys.nv), np.zeros((self.nrows, sys.nv))
        w = self.work.arrays()
        r0 = np.zeros(sys.nv)
        done = faststatic.reduced_forces(self.cm.arrays(), w, float(t), np.ascontiguousarray(q0, dtype=float),
                                         np.ascontiguousarray(N, dtype=float), np.ascontiguousarray(Z, dtype=float),
                                         PROJ_TOL, bool(accept), F, R, X, Q0, J0, r0)
        self._raise_callback_error()
        return Batch(F, R, X, Q0, J0, r0, done)

    def record(self, t):
        """Anchor the continued joint angles of torsion springs and rotational stops at t [s] (the kernel's
        references at the last accepted state, the solution) on the System, for the Result's continued
        coordinates (force_elements._common.joint_coordinate), as the reference path records them."""
        from ..system.force_elements._common import element_state
        ref = self.work.arrays()[44][7]
        for name, m in self.anchors.items():   # (inserted in time order: Result.at solves between samples)
            st = element_state(self.sys, name)
            st["angle_ref"] = sorted([a for a in st.get("angle_ref", []) if a[0] != t] + [(float(t), float(ref[m]))])

    def _raise_callback_error(self):
        pyl = self.pyloads
        if pyl is not None and (pyl.error is not None or pyl.interrupted):
            if pyl.interrupted:
                raise KeyboardInterrupt
            err, pyl.error = pyl.error, None
            raise err

    def angle_refs(self):
        """A copy of the joint angles' references [rad] (work slot 44[7]) at the last accepted state."""
        return self.work.arrays()[44][7].copy()

    def set_angle_refs(self, refs):
        self.work.arrays()[44][7][:] = refs


def _angle_measures(sys, cm) -> dict:
    """{element name: index of its joint-angle measure in the compiled expression loads (cm.exprloads)} of
    the torsion springs and rotational stops (the measure rows built again and matched)."""
    from ..model.element_specs import Stop, TorsionSpring
    from ..system.exprloads_pack import _measure_row, stop_expression, torsion_expression
    ex, out = cm.exprloads, {}
    if not len(ex) or not len(ex[0]):
        return out
    for e in sys.model.forces.values():
        if not (isinstance(e, TorsionSpring) or (isinstance(e, Stop) and e.dof == "rotation")):
            continue
        expr = torsion_expression(e) if isinstance(e, TorsionSpring) else stop_expression(e)
        m = next(v for v in expr.measures.values() if v.name == "joint" and not v.rate)
        row = _measure_row(sys, m, 0, None, None)
        for k in range(len(ex[0])):
            if ex[0][k] == row[0] and np.array_equal(ex[1][k], row[1]) and np.allclose(ex[2][k], row[2]) \
                    and np.allclose(ex[3][k], row[3]) and np.allclose(ex[4][k], row[4]):
                out[e.name] = k
                break
    return out


def evaluator(sys, rows, sf):
    """The compiled evaluator when the model compiles in absolute coordinates without joint friction, else
    the reference."""
    from ..system.compiled import NotCompiled, compile_system
    if len(getattr(sys, "lock_rows", ())):
        return Reference(sys, rows, sf)
    try:
        cm = compile_system(sys, rows)
    except NotCompiled:
        return Reference(sys, rows, sf)
    a = cm.arrays()
    if int(cm.dims[5]) == 1 or len(a[48][0]):
        return Reference(sys, rows, sf)
    return Compiled(sys, rows, cm)
