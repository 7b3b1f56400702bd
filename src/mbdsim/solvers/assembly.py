"""Assembly analysis: make initial positions and velocities consistent with the constraints."""
from __future__ import annotations

import dataclasses

import warnings
from dataclasses import dataclass, field

import numpy as np

from .._userwarn import warn
from .._blas import blas_single_thread
from ..errors import AssemblyError
from ..system.assemble import System, assemble_system
from ..system.equations import constraint_terms
from .common import (DENSE_LIMIT, active_rows, dependent_owners, increment, independent_rows, min_norm_solve,
                     project_velocities)
from ..system.metrics import kinetic_metric, length_scale, position_metric
from .held import changed_items, joint_position_items, lexi_solve, velocity_items
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..model.model import Model


class RedundantConstraintWarning(UserWarning):
    """Some constraint equations are linearly dependent (e.g. a planar loop of 3D revolutes)."""


class InitialConditionWarning(UserWarning):
    """Given initial values (body velocities, joint initial displacements or velocities) that are not
    consistent with the joints, the drivers and each other: the values used are the closest fit in the
    kinetic-energy metric; the warning names each changed body or joint with the value given and used."""


@dataclass(repr=False)
class AssemblyReport:
    """Consistent initial state and what assembly changed (SI units, ground axes).

    Attributes:
        system: the assembled System.  t: assembly time [s].
        q, v: consistent coordinates and velocity variables (see mbdsim.system.assemble for the layout).
        rows: indices of an independent subset of the constraint rows.
        dof: degrees of freedom left by the joints and motions.
        redundant: joints/motions involved in redundant (dependent) constraint rows.
        moved: body name -> (distance its CM moved [m], angle it turned [rad]) from as drawn; nothing
            below the tolerance (1e-10 of the model size, 1e-10 rad) is listed.
        velocity_changed: body name -> |change| of its given velocity or angular velocity (SI).
        changed: (entity, field, given, used) of each given value that could not be held.
        joint_changed: joint name -> {field: used - given} of its initial_displacement [rad or m] or
            initial_velocity [rad/s or m/s] that could not be held (the fit moved them; also warned).
        notes: remarks on the model's geometry (e.g. universal-joint axes orthogonalised).
        residual: max |phi| after assembly [m or rad].
    `print(report)` gives a readable summary.
    """

    system: System
    t: float
    q: np.ndarray
    v: np.ndarray
    rows: np.ndarray
    dof: int
    redundant: list = field(default_factory=list)
    moved: dict = field(default_factory=dict)
    velocity_changed: dict = field(default_factory=dict)
    residual: float = 0.0
    changed: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    joint_changed: dict = field(default_factory=dict)

    def __repr__(self) -> str:
        return f"AssemblyReport(t={self.t:g} s, dof={self.dof}, residual={self.residual:.3g}, moved={list(self.moved)})"

    def __str__(self) -> str:
        lines = [f"assembly at t = {self.t:g} s: {self.dof} DOF, residual {self.residual:.3g}"]
        if self.redundant:
            lines.append("redundant constraints among: " + ", ".join(self.redundant))
        lines += [f"  note: {n}" for n in self.notes]
        if not self.moved:
            lines.append("  no body moved")
        for name, (dr, da) in self.moved.items():
            lines.append(f"  moved {name}: {_tiny(dr):.6g} m, {np.degrees(_tiny(da)):.6g} deg")
        for name, dv in self.velocity_changed.items():
            lines.append(f"  velocity of {name} changed by {_tiny(dv):.6g}")
        lines += [f"  {e} {f}: given {_fmt(g)}, used {_fmt(u)}" for e, f, g, u in self.changed]
        for name, fields in self.joint_changed.items():
            lines += [f"  joint '{name}' {f} changed by {_fmt(d)}" for f, d in fields.items()]
        return "\n".join(lines)


REPORT_ZERO = 1e-12   # moves below this [m, rad, m/s or rad/s] are rounding, printed as 0


def _tiny(x: float) -> float:
    """x [m, rad or per s], or 0.0 when |x| < REPORT_ZERO (a rounding residue such as 3.9e-43 deg)."""
    return 0.0 if abs(x) < REPORT_ZERO else float(x)


def _fmt(x):
    x = np.atleast_1d(x)
    return f"{x[0]:.9g}" if len(x) == 1 else "(" + ", ".join(f"{a:.9g}" for a in x) + ")"


@blas_single_thread
def assemble(model: Model, t: float = 0.0, tol: float = 1e-12) -> AssemblyReport:
    """Solve phi(q, t) = 0 and phi_q v = nu from the model's initial values.

    Given values (joint initial displacements and velocities, body velocities, drivers) are held exactly
    when consistent, else fitted in the kinetic-energy metric with an InitialConditionWarning; the rest
    is the least correction of the drawn positions (weighted by each body's mass and inertia) and the
    least kinetic energy.  Raises AssemblyError when the constraints cannot be met or a motion is
    dependent on the constraints and the other motions (over-driven)."""
    from .kinematic import check_model
    check_model(model)
    sys = assemble_system(model)
    return assemble_state(sys, sys.q0, sys.v0, t, tol)


def assemble_state(sys: System, q0, v0, t=0.0, tol=1e-12) -> AssemblyReport:
    """Assembly from a given state of an assembled System.

    The model's held values (joint initial values, given body velocities) apply when q0 / v0 are the
    System's own initial arrays (sys.q0 / sys.v0); other states are corrected by the least change.
    The System's own initial state is assembled once per time and tolerance (kept in sys.derived, its
    warnings issued again on each call) when the model calls no Python function: a System reused for
    an unchanged Model starts from it."""
    if q0 is not sys.q0 or v0 is not sys.v0 or len(sys.lock_rows) or sys.derived.get("calls_python", True):
        return _assemble_state(sys, q0, v0, t, tol)
    key = (float(t), float(tol))
    kept = sys.derived.get("assembly")
    if kept is None or kept[0] != key:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            report = _assemble_state(sys, q0, v0, t, tol)
        kept = sys.derived["assembly"] = (key, report, [(w.message, w.category) for w in caught])
    _, report, issued = kept
    for message, category in issued:
        warn(message, category)
    return dataclasses.replace(report, system=sys, q=report.q.copy(), v=report.v.copy())


DENSE_BYTES = 2 * 2**30   # bytes of one dense Jacobian (nc x nv) above which the general assembly refuses


def _assemble_state(sys: System, q0, v0, t=0.0, tol=1e-12) -> AssemblyReport:
    """assemble_state without the cache."""
    from .assembly_large import consistent_tree
    fast = consistent_tree(sys, q0, v0, t, tol)   # a large consistent tree: no dense matrix (issue 35)
    if fast is not None:
        rows, phi = fast
        notes = [f"joint '{j.name}': {n}" for j in sys.model.joints.values() for n in getattr(j, "notes", [])]
        return AssemblyReport(sys, t, q0.copy(), v0.copy(), rows, sys.nv - len(rows), [], {}, {},
                              float(np.max(np.abs(phi), initial=0.0)), [], notes, {})
    from . import assembly_sparse
    solved = None
    if sys.nv > assembly_sparse.SPARSE_NV:
        try:
            solved = assembly_sparse.assemble_sparse(sys, q0, v0, t, tol)
        except AssemblyError:
            if not sys.model.motions or 8.0 * sys.nv * max(sys.nc, 1) > DENSE_BYTES:
                raise
            solved = "its motions may be over-driven"   # the dense route names them (_check_overdriven)
    if isinstance(solved, tuple):
        q, v, rows, changed, vchanged, phi, dropped = solved
        return _report(sys, q0, v0, t, q, v, rows, changed, vchanged, phi, _sparse_redundancy(sys, dropped))
    if 8.0 * sys.nv * max(sys.nc, 1) > DENSE_BYTES:
        from .assembly_large import why_dense
        raise AssemblyError(f"assembly of {sys.nbody} bodies ({sys.nv} velocity variables, {sys.nc} constraint "
                            f"equations) needs dense matrices of {8.0 * sys.nv * sys.nc / 2**30:.1f} GB "
                            f"here because {solved or why_dense(sys)}; a large model assembles without "
                            "them when its tree joints are independent as drawn and its loops (couplers and "
                            "paths among them) close few rows", time=float(t))
    rows_all = sys.fixed_rows   # friction locks: run time
    own_q = q0 is sys.q0
    try:
        q, changed, terms = _positions(sys, q0, t, rows_all, tol, held=own_q)
    except AssemblyError:
        _overdriven_failure(sys, q0, t, rows_all, tol)
        raise
    if terms is None:   # phi, phi_q and nu do not depend on v
        terms = constraint_terms(sys, q, np.zeros(sys.nv), t)
    J = terms[1][rows_all]
    rows = independent_rows(J, sys=sys)
    _check_overdriven(sys, J, rows, t, q)
    redundant = dependent_owners(sys, J, rows)
    planar_note = None
    if redundant and getattr(sys.model, "planar", None) is not None:   # dependent by design (issue 11)
        from .planar import planar_redundancy
        redundant, planar_note = planar_redundancy(sys, q, J, rows)
    vchanged = None
    if v0 is sys.v0:
        v, vchanged = velocities(sys, q, t, rows, terms)
    else:
        v = project_velocities(sys, q, v0, t, rows)
    return _report(sys, q0, v0, t, q, v, rows, changed, vchanged, terms[0][rows_all], (redundant, planar_note))


def _sparse_redundancy(sys, dropped):
    """(redundant owners, planar note) of the rows the sparse selection dropped: the owners of those rows
    (the dense route also names the kept rows they depend on); a planar model's dropped rows are taken
    as its out-of-plane equations, dependent by design (the dense route checks them row by row)."""
    if not len(dropped):
        return [], None
    _check_motions(sys, dropped)
    owners = list(dict.fromkeys(sys.row_owner[r] for r in dropped))
    if getattr(sys.model, "planar", None) is not None:
        return [], (f"planar model: {len(dropped)} out-of-plane equations are dependent by design and dropped "
                    f"(rows of {', '.join(sorted(owners))}); in-plane reactions are determinate")
    return owners, None


def _check_motions(sys, dropped):
    """AssemblyError naming the motions whose rows the sparse selection dropped (over-driven)."""
    bad = [m for m in dict.fromkeys(sys.row_owner[r] for r in dropped) if m in sys.model.motions]
    if bad:
        raise AssemblyError("over-driven mechanism: motion(s) " + ", ".join(f"'{m}'" for m in bad) +
                            " are dependent on the constraints and the other motions (remove one)", joints=bad)


def _report(sys, q0, v0, t, q, v, rows, changed, vchanged, phi, redundancy) -> AssemblyReport:
    """The AssemblyReport of an assembled state, with the warnings of redundant rows and changed values
    (vchanged: the changed given velocities, None when v0 was not the System's own)."""
    redundant, planar_note = redundancy
    if redundant:
        warn(f"redundant constraints: {sys.nc - len(rows)} of {sys.nc} equations are dependent; "
             f"joints involved: {', '.join(redundant)}. The dynamics use an independent subset; "
             "indeterminate reaction components are returned as the minimum-norm solution.",
             RedundantConstraintWarning)
    if vchanged is not None:
        changed = changed + vchanged
        vmoved = {e.split("'")[1]: float(np.linalg.norm(u - g)) for e, f, g, u in vchanged if e.startswith("body")}
    else:
        vmoved = _vchanged(sys, v0, v)
    moves = [_change(sys, q, e, f, g, u) for e, f, g, u in changed]
    if changed:
        warn("initial values not consistent with the joints and drivers were changed (kinetic-"
             "energy fit): " + "; ".join(f"{e} {f} given {_fmt(g)}, used {_fmt(u)} (changed by {_fmt(d)}{unit})"
                                         for (e, f, g, u), (d, unit) in zip(changed, moves)),
             InitialConditionWarning)
    jmoved = {}
    for (e, f, _, _), (d, _) in zip(changed, moves):
        if e.startswith("joint"):
            jmoved.setdefault(e.split("'")[1], {})[f] = d
    notes = [f"joint '{j.name}': {n}" for j in sys.model.joints.values() for n in getattr(j, "notes", [])]
    notes += [planar_note] if planar_note else []
    return AssemblyReport(sys, t, q, v, rows, sys.nv - len(rows), redundant, _moved(sys, q0, q),
                          vmoved, float(np.max(np.abs(phi), initial=0.0)), changed, notes, jmoved)


def _change(sys, q, entity, fld, given, used):
    """(used - given, ' unit') of a changed item: angles wrapped to [-pi, pi) [rad], slides [m],
    their rates [rad/s, m/s]; body velocities [m/s], angular velocities [rad/s]."""
    d = np.atleast_1d(np.asarray(used, dtype=float) - np.asarray(given, dtype=float))
    if entity.startswith("body"):
        return d, " m/s" if fld == "velocity" else " rad/s"
    from .held import ROTVEC_JOINTS, coordinate_rows, joint_values
    jt = sys.model.joints[entity.split("'")[1]]
    rows = None if jt.kind in ROTVEC_JOINTS else coordinate_rows(sys, jt)
    angle = np.ones(len(d), dtype=bool) if jt.kind in ROTVEC_JOINTS else \
        np.array([a for _, _, a in rows])[:len(d)] if rows is not None else joint_values(sys, jt, q)[4][:len(d)]
    if fld == "initial_displacement":
        d = np.where(angle, (d + np.pi) % (2 * np.pi) - np.pi, d)
    units = [("rad" if a else "m") + ("/s" if fld == "initial_velocity" else "") for a in angle]
    return d, f" {units[0]}" if len(set(units)) == 1 else f" [{', '.join(units)}]"


# ------------------------------------------------------------------------------ positions
def positions(sys, q0, t, rows, tol, held=True):
    """Newton onto phi(q, t) = 0 with steps least in the position metric (system.metrics.position_metric); with
    `held`, the joints' initial displacements are reached by continuation from as drawn (so the branch
    is kept) and held exactly when consistent.  Returns (q, changed items)."""
    return _positions(sys, q0, t, rows, tol, held)[:2]


def _positions(sys, q0, t, rows, tol, held=True):
    """positions, and constraint_terms(sys, q, 0, t) of all rows at the q returned when Newton
    evaluated them there last (else None)."""
    D = position_metric(sys)
    items = joint_position_items(sys, q0) if held else []
    q = q0
    if not items:
        q, res, terms = _newton(sys, q0, t, rows, tol, D)
        _check_residual(sys, q, t, rows, res)
        return q, [], terms
    L = length_scale(sys)
    span = max(max(float(np.max(np.abs(np.where(it.angle, it.g, it.g / L)))) for it in items), 1e-300)
    n = int(min(400, max(1, np.ceil(span / 0.2))))
    M = np.diag(D)
    for k in range(1, n + 1):
        q, consistent, items = _held_newton(sys, q, t, rows, tol, M, k / n)
    _check_residual(sys, q, t, rows, _residual(sys, q, t, rows))
    return q, ([] if consistent else changed_items(items, None)), None


def _held_newton(sys, q, t, rows, tol, M, scale, maxit=50):
    consistent, items = True, []
    for _ in range(maxit):
        phi, J = (x[rows] for x in constraint_terms(sys, q, np.zeros(sys.nv), t)[:2])
        items = joint_position_items(sys, q, scale)
        for it in items:
            it.g = it.residual()          # the step's target: the (wrapped) residual
        dx, consistent = lexi_solve(J, -phi, items, M)
        q = increment(sys, q, dx)
        if np.max(np.abs(dx), initial=0.0) < 1e-14 * max(1.0, length_scale(sys)) and \
                np.max(np.abs(phi), initial=0.0) <= tol:
            break
    items = joint_position_items(sys, q, scale)
    L = length_scale(sys)
    consistent = all(np.max(np.abs(np.where(it.angle, 1.0, 1.0 / L) * it.residual())) <= 1e-9 for it in items)
    return q, consistent, items


def _newton(sys, q0, t, rows, tol, D, maxit=50):
    """Newton with steps least in the diagonal metric D: dx = D^-1/2 (J D^-1/2)^+ (-phi); when full steps
    do not converge (a body drawn far off), again with backtracking on |phi|.  Returns (q, max |phi|,
    the constraint terms at q when the last evaluation was there, else None)."""
    q, res, terms = _newton_run(sys, q0, t, rows, tol, D, maxit, False)
    return (q, res, terms) if res <= 1e-9 else _newton_run(sys, q0, t, rows, tol, D, 4 * maxit, True)


def _newton_run(sys, q, t, rows, tol, D, maxit, backtrack):
    rows = active_rows(sys, rows, t)
    s = 1.0 / np.sqrt(D)
    res = np.inf
    norm = lambda x: float(np.linalg.norm(constraint_terms(sys, x, np.zeros(sys.nv), t, False)[0][rows]))  # noqa: E731
    for _ in range(maxit):
        terms = constraint_terms(sys, q, np.zeros(sys.nv), t)
        phi, J = terms[0][rows], terms[1][rows]
        res = float(np.max(np.abs(phi), initial=0.0))
        if res <= tol:
            return q, res, terms
        dx = s * min_norm_solve(J * s, -phi)
        step, n0 = 1.0, float(np.linalg.norm(phi))
        while backtrack and step > 1e-3 and res > 1e-6 and norm(increment(sys, q, step * dx)) >= n0:
            step *= 0.5   # far from the solution: backtrack along the Gauss-Newton direction
        q = increment(sys, q, step * dx)
        if float(np.max(np.abs(dx))) < 1e-15 * max(1.0, float(np.max(np.abs(q)))):
            break
    return q, res, None


def _residual(sys, q, t, rows):
    return float(np.max(np.abs(constraint_terms(sys, q, np.zeros(sys.nv), t, jacobian=False)[0][rows]),
                        initial=0.0))


def _check_residual(sys, q, t, rows, res, phi=None):
    """AssemblyError naming the joints of the largest residuals when res > 1e-9 (phi: of all rows at q)."""
    if res > 1e-9:
        phi = (constraint_terms(sys, q, np.zeros(sys.nv), t, jacobian=False)[0] if phi is None else phi)[rows]
        worst = [sys.row_owner[rows[k]] for k in np.argsort(-np.abs(phi))[:4] if abs(phi[k]) > 1e-9]
        raise AssemblyError(f"assembly failed: constraint residual {res:.3g} cannot be removed",
                            time=t, joints=dict.fromkeys(worst), state=q)


def _overdriven_failure(sys, q0, t, rows, tol):
    """When assembly fails: AssemblyError naming the motions if they are dependent on the joints and
    each other at the configuration the joints alone assemble to (else nothing: the caller re-raises)."""
    motions = set(sys.model.motions)
    if not motions:
        return
    free = np.array([r for r in rows if sys.row_owner[r] not in motions], dtype=int)
    try:
        q, _ = positions(sys, q0, t, free, tol, held=False)
    except AssemblyError:
        return
    J = constraint_terms(sys, q, np.zeros(sys.nv), t)[1][rows]
    _check_overdriven(sys, J, independent_rows(J, sys=sys), t, q)


def _check_overdriven(sys, J, rows, t, q):
    """AssemblyError naming the motions that are dependent on the constraints and the other motions."""
    if len(rows) == J.shape[0]:
        return
    motions = [m for m in sys.model.motions if m in sys.owner_rows]
    bad = []
    for m in motions:
        keep = np.ones(J.shape[0], dtype=bool)
        keep[sys.owner_rows[m]] = False
        if len(independent_rows(J[keep])) == len(rows):   # m adds nothing: it is implied by the rest
            bad.append(m)
    if bad:
        raise AssemblyError("over-driven mechanism: motion(s) " + ", ".join(f"'{m}'" for m in bad) +
                            " are dependent on the constraints and the other motions (remove one)",
                            time=t, joints=bad, state=q)


# ------------------------------------------------------------------------------ velocities
def velocities(sys, q, t, rows, terms=None):
    """Velocities holding the given values (fitted in the kinetic-energy metric when inconsistent),
    the rest of least kinetic energy; `terms`: constraint_terms at (q, t) when already computed.
    Returns (v, changed items)."""
    _, J, nu, _ = constraint_terms(sys, q, np.zeros(sys.nv), t) if terms is None else terms
    rows = active_rows(sys, rows, t)
    items = velocity_items(sys, q)
    if sys.nv > DENSE_LIMIT:
        return _velocities_sparse(sys, q, t, rows, J, nu, items)
    v, consistent = lexi_solve(J[rows], nu[rows], items, kinetic_metric(sys))
    return v, ([] if consistent else changed_items(items, v))


def _velocities_sparse(sys, q, t, rows, J, nu, items):
    """Large systems: the given values stacked on the constraints, least kinetic energy (diagonal metric)
    when consistent; else the given values projected onto the constraints (least change)."""
    if not items:
        return project_velocities(sys, q, np.zeros(sys.nv), t, rows), []
    S = 1.0 / np.sqrt(np.diag(kinetic_metric(sys)))
    A = np.vstack([J[rows]] + [it.C for it in items])
    rhs = np.concatenate([nu[rows]] + [it.g for it in items])
    v = S * min_norm_solve(A * S, rhs)
    if np.max(np.abs(A @ v - rhs)) <= 1e-9 * max(1.0, float(np.max(np.abs(rhs)))):
        return v, []
    v0 = S * min_norm_solve(np.vstack([it.C for it in items]) * S, np.concatenate([it.g for it in items]))
    v = project_velocities(sys, q, v0, t, rows)
    return v, changed_items(items, v)


def _moved(sys, q0, q):
    """{body name: (CM shift [m], rotation angle [rad])} of the bodies assembly moved (beyond 1e-10)."""
    if q is q0:   # Newton took no step
        return {}
    L = length_scale(sys)
    dr = np.sqrt(((q[sys.r_idx] - q0[sys.r_idx]) ** 2).sum(-1))
    da = np.zeros(len(sys.bodies))
    if len(sys.rigid_fid):
        p0, p = q0[sys.p_idx], q[sys.p_idx]
        p0 = p0 / np.linalg.norm(p0, axis=-1, keepdims=True)
        p = p / np.linalg.norm(p, axis=-1, keepdims=True)
        vec = p0[:, :1] * p[:, 1:] - p[:, :1] * p0[:, 1:] - np.cross(p0[:, 1:], p[:, 1:])
        da[np.asarray(sys.rigid_fid) - 1] = 2 * np.arctan2(np.linalg.norm(vec, axis=-1), np.abs((p0 * p).sum(-1)))
    return {b.name: (float(dr[k]), float(da[k])) for k, b in enumerate(sys.bodies)
            if dr[k] > 1e-10 * L or da[k] > 1e-10}


def _vchanged(sys, v0, v):
    out = {}
    for k, b in enumerate(sys.bodies):
        a = sys.frame_v_adr[k + 1]
        n = 3 if b.is_particle else 6
        dv = float(np.linalg.norm(v[a:a + n] - v0[a:a + n]))
        if dv > 1e-12:
            out[b.name] = dv
    return out
