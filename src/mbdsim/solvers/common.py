"""Shared numerical kernels of the solvers: manifold increments, projections, accelerations."""
from __future__ import annotations

import numpy as np

from ..errors import SolverError
from ..system import kernels
from ..system.coordinates import normalize, qdot  # noqa: F401  (the solvers' names)
from ..system.dynamics import _worst_joints, accelerations, applied_forces, solve_kkt  # noqa: F401  (the solvers' names)
from ..system.equations import constraint_terms
from ..system.rows import (DENSE_LIMIT, active_rows, dependent_owners, independent_rows,  # noqa: F401
                           min_norm_solve)


def increment(sys, q, dx):
    """q (+) dx: translate CMs by dx [m], rotate bodies by the body-axes rotation vector dx [rad]."""
    q = kernels.increment_kernel(np.asarray(q, dtype=float), np.asarray(dx, dtype=float), sys.r_idx,
                                 sys.rd_idx, sys.p_idx, sys.w_idx)
    q[sys.aux_q_idx] += dx[sys.aux_v_idx]   # auxiliary coordinates (curve parameters): plain sums
    return q


def project_positions(sys, q, t, rows, tol=1e-12, maxit=25):
    """Newton (minimum-norm steps) onto phi(q, t) = 0 for the given rows; returns (q, residual, iterations)."""
    rows = active_rows(sys, rows, t)
    zero = np.zeros(sys.nv)
    res = np.inf
    for it in range(maxit):
        phi, J, _, _ = constraint_terms(sys, q, zero, t)
        phi, J = phi[rows], J[rows]
        res = float(np.max(np.abs(phi))) if len(phi) else 0.0
        if res <= tol:
            return q, res, it
        dx = -min_norm_solve(J, phi)
        q = increment(sys, q, dx)
        if it > 3 and float(np.max(np.abs(dx))) < 1e-15:
            break
    return q, res, maxit


def project_velocities(sys, q, v, t, rows):
    """Minimum-norm correction of v so that phi_q v = nu on the given rows."""
    rows = active_rows(sys, rows, t)
    _, J, nu, _ = constraint_terms(sys, q, v, t)
    J, nu = J[rows], nu[rows]
    if len(nu) == 0:
        return v
    return v - min_norm_solve(J, J @ v - nu)


def consistent_state(sys, y, t, rows, sf):
    """(q, v, vd, lambda_) at time t [s] from y = [q, v]: q projected onto phi(q, t) = 0, v onto
    phi_q v = nu (minimum-norm corrections), then the accelerations and multipliers of all rows."""
    q, v = y[:sys.nq], y[sys.nq:]
    q, _, _ = project_positions(sys, normalize(sys, q), t, rows)
    v = project_velocities(sys, q, v, t, rows)
    vd, lam = accelerations(sys, q, v, t, rows, sf)
    return q, v, vd, lam


def _weak_joints(sys, q, v, t, rows):
    """Joints whose constraint rows are closest to dependent at (q, t) (failure reports)."""
    _, J, _, _ = constraint_terms(sys, normalize(sys, q), v, t)
    return _worst_joints(sys, J, rows)


def analysis_error(exc: BaseException, t) -> Exception:
    """The mbdsim error that ends an analysis for exception `exc` caught at about time t [s]: mbdsim errors
    as they are, KeyboardInterrupt as AnalysisInterrupted, anything else (numpy/LAPACK failures, a bug
    in a user function not caught by system.guard) as a SolverError naming its type and the time."""
    from ..errors import AnalysisInterrupted, MbdsimError
    if isinstance(exc, MbdsimError):
        return exc
    t = None if t is None else float(t)
    if isinstance(exc, KeyboardInterrupt):
        return AnalysisInterrupted("interrupted (KeyboardInterrupt)", time=t)
    return SolverError(f"{type(exc).__name__}: {exc}", time=t)


def blame_load(sys, t, y):
    """The EvaluationError of the first load that is not finite at time t [s] in state y = [q, v] (the
    reference evaluators, which name the element and field), or None: the diagnosis of a compiled run
    that ended with a non-finite state or a collapsed step, whose kernels do not name elements."""
    from ..errors import EvaluationError, MbdsimError
    from ..results.state import state_factory
    from ..system.force_elements import evaluator
    from ..system.frames import body_frames
    q, v = y[:sys.nq], y[sys.nq:]
    if not (np.isfinite(q).all() and np.isfinite(v).all()):
        return None
    sf = state_factory(sys)
    fr = body_frames(sys, normalize(sys, q), v)
    for elem in sys.model.forces.values():
        try:
            Q = evaluator(elem).generalized(sys, fr, elem, t, sf(t, q, v) if sf else None)
        except EvaluationError as exc:
            return exc
        except (MbdsimError, ArithmeticError, ValueError, TypeError, np.linalg.LinAlgError):
            continue   # (not a clear verdict on this element)
        if not np.isfinite(Q).all():
            return EvaluationError(f"element '{elem.name}'", "load", "evaluates to a non-finite load", time=t)
    return None
