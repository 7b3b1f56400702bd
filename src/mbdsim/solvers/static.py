"""Static equilibrium and quasi-static analysis: Q(q, t) - phi_q^T lambda_ = 0 with phi(q, t) = 0, v = 0.

The equilibrium is sought in independent coordinates z of the constraint manifold (`reduced.Chart`,
translations scaled by the model's length L so that z is dimensionless). The unbalanced load is the
reduced force f(z) = N^T (Q - phi_q^T lambda_) (least-squares multipliers), which equals -dV/dz when the
loads have a potential V; K = -df/dz is the reduced tangent stiffness (central differences, step 1e-6).

Globalisation: a trust-region Newton method on V. Each step minimises the quadratic model
-f.dz + dz.K_s.dz/2 (K_s: symmetric part of K) within |dz| <= Delta (Levenberg-Marquardt shift
mu >= max(0, -lambda_min(K_s)), Moré-Sorensen hard case along the most negative curvature), so it moves
downhill even where K is singular (a pendulum started horizontal) or indefinite (near the top).
The decrease of V is measured without V itself, as the work of the loads along the step (Simpson's rule
on f at dz/2 and dz), so follower loads and constant torques are handled too; the ratio of actual to
predicted decrease sets Delta (0.25 / 0.75 rule, Delta <= 1). Should the radius collapse (loads without a
potential that fool the work measure) the iteration continues as pseudo-transient continuation, the
implicit Euler steps (K + I / tau) dz = f of the overdamped flow dz/dtau = f with tau growing as the
residual falls (switched evolution relaxation).

Evaluations (solvers.static_eval): each iteration evaluates one batch of configurations (the chart's
centre, the 2 d central differences of K, the trust step's dz/2 and dz) in one compiled call
(solvers.faststatic: projection, loads, unbalanced load) where the model compiles in absolute coordinates,
res.stats["method"] then ending in "(compiled)"; else by the force elements' numpy evaluators.

Stability: at the solution the eigenvalues of K_s classify it: all positive, stable; a negative one,
unstable; zeros, neutral (indeterminate along those directions). A start that is already an unstable
equilibrium (the pendulum exactly upright) is returned as it is, flagged unstable, with an
`UnstableEquilibriumWarning` naming the directions; any other start descends to a stable one.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._userwarn import warn
from .._blas import blas_single_thread
from ..errors import SolverError
from ..results.result import Result
from ..system.assemble import assemble_system
from ..system.equations import constraint_terms
from ..system.frames import body_frames
from .assembly import assemble_state
from .common import project_positions
from .reduced import describe_direction, length_scale, velocity_scale
from .static_eval import evaluator
from ..results.state import state_factory
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..model.model import Model
    from .._types import Progress

DELTA_MAX = 1.0     # largest trust radius: 1 rad of rotation or L of translation per step
FD_STEP = 1e-6      # central-difference step of the reduced stiffness (dimensionless z)


class UnstableEquilibriumWarning(UserWarning):
    """The equilibrium found is unstable (a direction of negative stiffness)."""


@dataclass
class StaticSolution:
    """One equilibrium: coordinates, multipliers (all nc rows), iterations and stability."""

    t: float
    q: np.ndarray
    lam: np.ndarray
    iterations: int
    method: str
    stiffness: np.ndarray               # eigenvalues of K_s [N m per unit z^2], ascending
    unstable: list = field(default_factory=list)   # descriptions of the negative-stiffness directions
    neutral: list = field(default_factory=list)    # descriptions of the zero-stiffness directions

    @property
    def stable(self) -> bool:
        return not self.unstable


@blas_single_thread
def equilibrium(model: Model, t: float = 0.0, tol: float = 1e-10, maxit: int = 100) -> Result:
    """Static equilibrium at time t [s] (motions at their value at t, velocities zero).

    Starts from the assembled initial configuration and descends to a stable equilibrium (see the module
    docstring). Returns a single-sample Result with zero velocities and accelerations and the multipliers,
    so reactions are as in dynamics; `res.stats` has "iterations", "method", "stable",
    "unstable_directions", "neutral_directions" and "stiffness_eigenvalues". Raises `SolverError` naming
    the unbalanced directions when no equilibrium is found within maxit iterations."""
    from .kinematic import check_model
    check_model(model)
    sys = assemble_system(model)
    rep = assemble_state(sys, sys.q0, np.zeros(sys.nv), t)
    sol = solve_static(sys, rep.q, t, rep.rows, state_factory(sys), tol, maxit)
    _warn_unstable([sol])
    return _result(sys, [sol], None, True, _summary(sol))


@blas_single_thread
def quasi_static(model: Model, end_time: float, output_step: float | None = None, start_time: float = 0.0,
                 tol: float = 1e-10, maxit: int = 100, progress: Progress = None) -> Result:
    """Quasi-static analysis: the static equilibrium at each output time from start_time to end_time [s]
    (every output_step [s]) of a mechanism whose motions move it; each solve starts from the previous one.
    progress: True shows a progress bar on stderr, a callable progress(t) receives each solved time [s]
    (an exception it raises ends the run as a failure does, res.error a ProgressError), False nothing,
    None (default) the bar after 2 s in a terminal or notebook (as `simulate`).

    Inertia and velocity-dependent forces are neglected: velocities and accelerations are reported zero,
    reactions and driver efforts are those that hold the mechanism in equilibrium at each time.
    `res.stats["stable"]` is a bool array per sample. A failure stops the run: the Result keeps every
    sample before it (`success` False, `message`, `error`: the mbdsim error, e.g. an EvaluationError
    naming a load callable that raised, AnalysisInterrupted for Ctrl-C, other exceptions as a
    SolverError naming their type and the time [s])."""
    from .._progress import progress_of
    from ..results.stream import ProgressError, notify
    from .kinematic import check_model, time_grid
    with progress_of(progress, "quasi_static", f"quasi-static {getattr(model, 'name', '')}", start_time,
                     end_time) as bar:     # a bad progress value: ModelError before any work
        check_model(model)
        sys = assemble_system(model)
        rep = assemble_state(sys, sys.q0, np.zeros(sys.nv), start_time)
        times, sf = time_grid(start_time, end_time, output_step), state_factory(sys)
        ev = evaluator(sys, rep.rows, sf)
        sols, refs, q, error = [], [], rep.q, None
        for t in times:
            try:
                sols.append(solve_static(sys, q, t, rep.rows, sf, tol, maxit, ev=ev))
                refs.append(ev.angle_refs())
                notify(bar, t)
            except (Exception, KeyboardInterrupt) as exc:   # noqa: BLE001 - every failure ends the run, named
                from .common import analysis_error
                error = exc if isinstance(exc, ProgressError) else analysis_error(exc, t)
                break
            q = sols[-1].q
    _warn_unstable(sols)

    def evaluate(ts):
        out = []
        for x in ts:   # from the nearest sample, its joint-angle references restored
            k = int(np.argmin([abs(s.t - x) for s in sols]))
            ev.set_angle_refs(refs[k])
            out.append(solve_static(sys, sols[k].q, x, rep.rows, sf, tol, maxit, ev=ev))
        return _arrays(sys, out)[1:]
    ok = error is None
    msg = f"quasi-static equilibrium at {len(sols)} times" if ok else \
        f"{error}; last equilibrium at t = {sols[-1].t if sols else start_time:.9g} s"
    res = _result(sys, sols, evaluate if sols else None, ok, msg)
    res.error = error
    return res


def solve_static(sys, q, t, rows, sf=None, tol=1e-10, maxit=100, relax=False, ev=None) -> StaticSolution:
    """Equilibrium of an assembled System from configuration q (projected onto the constraints first) at
    time t [s]; relax=True starts with the pseudo-transient continuation (the fallback) instead of the trust
    region. ev: the evaluator of the loads (solvers.static_eval; default: compiled where the model compiles)."""
    ev = ev if ev is not None else evaluator(sys, rows, sf)
    L = length_scale(sys, q)
    scale = velocity_scale(sys, L)
    cur = _at(ev, sys, q, t, rows)
    q = cur.X[0]
    force_scale = max(1.0, float(np.max(np.abs(cur.Q0), initial=0.0)), 10 * float(np.max(np.abs(sys.M), initial=0.0)))
    delta, tau, mode = 0.5, None, "trust-region Newton"
    if relax:
        mode = "pseudo-transient continuation"
    for it in range(maxit + 1):
        if it:
            cur = _at(ev, sys, q, t, rows)
        N = ev.basis(cur.J0, scale)
        f, r = N.T @ cur.r0, cur.r0
        converged = np.max(np.abs(r), initial=0.0) <= tol * force_scale
        if it == maxit and not converged:
            break
        K = _stiffness(ev, q, N, t)
        if converged:
            ev.record(t)
            return _classify(sys, q, t, N, K, cur.Q0, it, mode + (" (compiled)" if ev.compiled else ""),
                             force_scale * L, L)
        if mode.startswith("pseudo") and tau is None:
            tau = 1.0 / max(float(np.max(np.abs(K), initial=0.0)), 1e-12 * force_scale)
        if mode.startswith("trust"):
            dz, pred = _trust_step(K, f, delta)
            pair = ev.batch(q, N, np.vstack([dz / 2, dz]), t, False)
            if pair.done < 2:
                delta *= 0.25
                continue
            f_half, f_new = pair.F
            actual = float((f + 4 * f_half + f_new) @ dz) / 6   # work of the loads = decrease of V
            rho = actual / pred if pred > 0 else -np.inf
            n = float(np.linalg.norm(dz))
            if rho < 0.25:
                delta = 0.25 * n
            elif rho > 0.75 and n > 0.99 * delta:
                delta = min(2 * delta, DELTA_MAX)
            if rho > 0.1:
                q = pair.X[1]
            elif delta < 1e-9:                       # the work measure cannot guide: relax instead
                mode = "pseudo-transient continuation"
        else:   # implicit Euler on dz/dtau = f, kept downhill: K_s + I / tau positive definite
            neg = max(0.0, -float(np.linalg.eigvalsh(0.5 * (K + K.T))[0])) if len(f) else 0.0
            dz = np.linalg.lstsq(K + np.eye(len(f)) * max(1.0 / tau, 1.5 * neg), f, rcond=None)[0]
            dz *= min(1.0, DELTA_MAX / max(float(np.linalg.norm(dz)), 1e-300))
            one = ev.batch(q, N, dz[None], t, False)
            if one.done < 1:
                tau *= 0.25
                continue
            q = one.X[0]
            f_new = float(np.linalg.norm(one.F[0]))
            tau *= min(10.0, float(np.linalg.norm(f)) / max(f_new, 1e-300))   # switched evolution relaxation
    where = describe_direction(sys, q, N @ f, L, t)
    raise SolverError(f"no static equilibrium: the loads along [{where}] are not balanced by any stiffness "
                      f"(indeterminate or unbounded direction); static equilibrium not found in {maxit} "
                      f"iterations (residual {np.max(np.abs(r)):.3g})", time=t, state=q)


def _at(ev, sys, q, t, rows):
    """The evaluation at q projected onto the constraints at t (the joint angles' references accepted
    there); a compiled projection that fails is retried from the reference projection's configuration;
    SolverError when the motions cannot be satisfied."""
    cur = ev.batch(q, np.zeros((sys.nv, 0)), np.zeros((1, 0)), t, True)
    if cur.done == 0 and ev.compiled:
        cur = ev.batch(_onto(sys, q, t, rows), np.zeros((sys.nv, 0)), np.zeros((1, 0)), t, True)
    if cur.done == 0:
        raise SolverError("the motions cannot be satisfied (no configuration on the constraints)", time=t, state=q)
    return cur


def _trust_step(K, f, delta):
    """dz minimising -f.dz + dz.K_s.dz/2 within |dz| <= delta (Newton with the full K when it is
    inside and K_s is positive definite); returns (dz, predicted decrease)."""
    Ks = 0.5 * (K + K.T)
    lam, V = np.linalg.eigh(Ks)
    g = V.T @ f
    top = max(float(np.max(np.abs(lam), initial=0.0)), 1e-300)
    if lam[0] > 1e-10 * top:
        dz = np.linalg.solve(K, f)
        if np.linalg.norm(dz) <= delta:
            return dz, float(f @ dz - 0.5 * dz @ Ks @ dz)
    lo = max(0.0, -lam[0]) + 1e-12 * top

    def step(mu):
        with np.errstate(all="ignore"):
            return V @ (g / (lam + mu))
    if _norm(step(lo)) <= delta:     # hard case: go to the boundary along the least curvature
        dz = step(lo) if lam[0] > 0 else V[:, 1:] @ (g[1:] / (lam[1:] + lo))
        if lam[0] <= 0:
            s = 1.0 if g[0] >= 0 else -1.0
            dz = dz + s * np.sqrt(max(delta ** 2 - dz @ dz, 0.0)) * V[:, 0]
    else:
        hi = lo + np.linalg.norm(g) / delta + top
        for _ in range(100):                  # |step(mu)| decreases with mu: bisection in log space
            mid = np.sqrt(lo * hi) if lo > 0 else 0.5 * hi
            lo, hi = (mid, hi) if _norm(step(mid)) > delta else (lo, mid)
            if hi - lo <= 1e-12 * hi:
                break
        dz = step(hi)
    return dz, float(f @ dz - 0.5 * dz @ Ks @ dz)


def _norm(x) -> float:
    """Euclidean norm without overflow (inf stays inf)."""
    m = float(np.max(np.abs(x), initial=0.0))
    return m * float(np.linalg.norm(x / m)) if 0.0 < m < np.inf else m


def _stiffness(ev, q, N, t, h=FD_STEP):
    """K = -d f / d z (d, d) by central differences along the chart at q (one batch of 2 d configurations);
    SolverError when one of them cannot be projected."""
    d = N.shape[1]
    if not d:
        return np.zeros((0, 0))
    E = np.eye(d) * h
    b = ev.batch(q, N, np.vstack([E, -E]), t, False)
    if b.done < 2 * d:
        raise SolverError("the constraints cannot be satisfied near this configuration", time=t, state=q)
    return -(b.F[:d] - b.F[d:]).T / (2 * h)


def _classify(sys, q, t, N, K, Q, it, method, energy_scale, L):
    """StaticSolution at the converged configuration q (loads Q there) with the stiffness eigenvalues and
    directions and the minimum-norm multipliers of every row in force."""
    lam, V = np.linalg.eigh(0.5 * (K + K.T)) if N.shape[1] else (np.zeros(0), np.zeros((0, 0)))
    thr = 1e-7 * max(float(np.max(np.abs(lam), initial=0.0)), energy_scale)
    unstable = [describe_direction(sys, q, N @ V[:, k], L, t) for k in range(len(lam)) if lam[k] < -thr]
    neutral = [describe_direction(sys, q, N @ V[:, k], L, t) for k in range(len(lam)) if abs(lam[k]) <= thr]
    zero = np.zeros(sys.nv)
    J = constraint_terms(sys, q, zero, t)[1][sys.fixed_rows]
    lam_all = np.zeros(sys.nc)
    if J.shape[0]:
        lam_all[sys.fixed_rows] = np.linalg.lstsq(J.T, Q, rcond=None)[0]   # minimum norm, as in dynamics
    return StaticSolution(t, q, lam_all, it, method, lam, unstable, neutral)


def _onto(sys, q, t, rows):
    """q projected onto the constraints at time t (motions moved on); SolverError when impossible."""
    q, res, _ = project_positions(sys, q, t, rows, tol=1e-13, maxit=50)
    if res > 1e-9:
        raise SolverError(f"the motions cannot be satisfied (constraint residual {res:.3g})", time=t, state=q)
    return q


def _summary(sol) -> str:
    text = f"equilibrium in {sol.iterations} iterations ({sol.method}): "
    if sol.unstable:
        text += "UNSTABLE along " + " | ".join(sol.unstable)
    else:
        text += "stable"
    if sol.neutral:
        text += "; neutral (indeterminate) along " + " | ".join(sol.neutral)
    return text


def _warn_unstable(sols):
    bad = [s for s in sols if s.unstable]
    if bad:
        warn(f"unstable static equilibrium at t = {bad[0].t:.9g} s"
             f"{f' (and {len(bad) - 1} more times)' if len(bad) > 1 else ''}: negative stiffness along "
             + " | ".join(bad[0].unstable) + ". Start from a perturbed configuration to reach a stable one.",
             UnstableEquilibriumWarning)


def _arrays(sys, sols):
    n = len(sols)
    zeros = np.zeros((n, sys.nv))
    return (np.array([s.t for s in sols]), np.array([s.q for s in sols]).reshape(n, sys.nq), zeros, zeros.copy(),
            np.array([s.lam for s in sols]).reshape(n, sys.nc))


def _result(sys, sols, evaluate, success, message):
    stats = {"iterations": [s.iterations for s in sols], "method": sols[0].method if sols else "",
             "stable": np.array([s.stable for s in sols]), "unstable_directions": [s.unstable for s in sols],
             "neutral_directions": [s.neutral for s in sols],
             "stiffness_eigenvalues": [s.stiffness for s in sols]}
    if len(sols) == 1:
        stats = {k: (v[0] if isinstance(v, (list, np.ndarray)) else v) for k, v in stats.items()}
        stats["stable"] = bool(stats["stable"])
    return Result(sys, *_arrays(sys, sols), evaluate=evaluate, success=success, status=0 if success else -1,
                  message=message, stats=stats)


def _follow_angles(sys, q, dx, t):
    """Anchor the continued joint angles of torsion springs and rotational stops at their linear prediction
    for the update q (+) dx, so that equilibria beyond +-pi (a wound-up spring) are found."""
    from ..model.element_specs import Stop, TorsionSpring
    from ..system.force_elements._common import element_state, joint_coordinate, load_from_rows
    fr = None
    for e in sys.model.forces.values():
        if isinstance(e, TorsionSpring) or (isinstance(e, Stop) and e.dof == "rotation"):
            fr = body_frames(sys, q, np.zeros(sys.nv)) if fr is None else fr
            x, _, rws = joint_coordinate(sys, fr, e.joint, "rotation", e.name, t)
            pred = float(x[0] + load_from_rows(sys, fr, rws, 1.0) @ dx)
            st = element_state(sys, e.name)   # anchors of earlier times stay (quasi-static histories)
            st["angle_ref"] = [a for a in st.get("angle_ref", []) if a[0] < t] + [(float(t), pred)]
