"""Assembly analysis: make initial positions and velocities consistent with the constraints."""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from ..errors import AssemblyError
from ..system.assemble import System, assemble_system
from ..system.equations import constraint_terms
from .common import dependent_owners, independent_rows, project_positions, project_velocities


class RedundantConstraintWarning(UserWarning):
    """Some constraint equations are linearly dependent (e.g. a planar loop of 3D revolutes)."""


@dataclass(repr=False)
class AssemblyReport:
    """Consistent initial state and what assembly changed (SI units, ground axes)."""

    system: System
    t: float
    q: np.ndarray
    v: np.ndarray
    rows: np.ndarray                 # independent constraint rows
    dof: int                         # degrees of freedom left by joints and motions
    redundant: list = field(default_factory=list)   # joints/motions involved in redundant rows
    moved: dict = field(default_factory=dict)       # body -> (|dr| [m], rotation angle [rad])
    velocity_changed: dict = field(default_factory=dict)  # body -> |dv| (velocity variables)
    residual: float = 0.0            # max |phi| after assembly [m or rad]

    def __repr__(self) -> str:
        return f"AssemblyReport(t={self.t:g} s, dof={self.dof}, residual={self.residual:.3g}, moved={list(self.moved)})"

    def __str__(self) -> str:
        lines = [f"assembly at t = {self.t:g} s: {self.dof} DOF, residual {self.residual:.3g}"]
        if self.redundant:
            lines.append("redundant constraints among: " + ", ".join(self.redundant))
        for name, (dr, da) in self.moved.items():
            lines.append(f"  moved {name}: {dr:.6g} m, {np.degrees(da):.6g} deg")
        for name, dv in self.velocity_changed.items():
            lines.append(f"  velocity of {name} changed by {dv:.6g}")
        return "\n".join(lines)


def assemble(model, t: float = 0.0, tol: float = 1e-12) -> AssemblyReport:
    """Solve phi(q, t) = 0 and phi_q v = nu from the model's initial values (minimum-norm corrections)."""
    from .kinematic import check_model
    check_model(model)
    sys = assemble_system(model)
    return assemble_state(sys, sys.q0, sys.v0, t, tol)


def assemble_state(sys: System, q0, v0, t=0.0, tol=1e-12) -> AssemblyReport:
    """Assembly from a given state of an assembled System."""
    _, J0, _, _ = constraint_terms(sys, q0, v0, t)
    q, res, _ = project_positions(sys, q0, t, sys.fixed_rows, tol=tol, maxit=50)  # friction locks: run time
    if res > 1e-9:
        phi = constraint_terms(sys, q, v0, t, jacobian=False)[0][sys.fixed_rows]
        worst = [sys.row_owner[k] for k in np.argsort(-np.abs(phi))[:4] if abs(phi[k]) > 1e-9]
        raise AssemblyError(f"assembly failed: constraint residual {res:.3g} cannot be removed",
                            time=t, joints=dict.fromkeys(worst), state=q)
    J = constraint_terms(sys, q, v0, t)[1][sys.fixed_rows]
    rows = independent_rows(J, sys=sys)
    redundant = dependent_owners(sys, J, rows)
    if redundant:
        warnings.warn(f"redundant constraints: {sys.nc - len(rows)} of {sys.nc} equations are dependent; "
                      f"joints involved: {', '.join(redundant)}. The dynamics use an independent subset; "
                      "indeterminate reaction components are returned as the minimum-norm solution.",
                      RedundantConstraintWarning, stacklevel=3)
    v = project_velocities(sys, q, v0, t, rows)
    return AssemblyReport(sys, t, q, v, rows, sys.nv - len(rows), redundant, _moved(sys, q0, q),
                          _vchanged(sys, v0, v), float(np.max(np.abs(constraint_terms(sys, q, v, t, False)[0][sys.fixed_rows]),
                                                              initial=0.0)))


def _moved(sys, q0, q):
    out = {}
    for k, b in enumerate(sys.bodies):
        dr = float(np.linalg.norm(q[sys.r_idx[k]] - q0[sys.r_idx[k]]))
        da = 0.0
        if not b.is_particle:
            pi = list(sys.rigid_fid).index(k + 1)
            c = abs(float(q[sys.p_idx[pi]] @ q0[sys.p_idx[pi]]) / np.linalg.norm(q0[sys.p_idx[pi]]))
            da = 2 * float(np.arccos(min(1.0, c)))
        if dr > 1e-12 or da > 1e-12:
            out[b.name] = (dr, da)
    return out


def _vchanged(sys, v0, v):
    out = {}
    for k, b in enumerate(sys.bodies):
        a = sys.frame_v_adr[k + 1]
        n = 3 if b.is_particle else 6
        dv = float(np.linalg.norm(v[a:a + n] - v0[a:a + n]))
        if dv > 1e-12:
            out[b.name] = dv
    return out
