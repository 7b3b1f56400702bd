"""Run monitors (issue 10): constraint violation, energy balance and contact penetration of a run's samples.

Checked by `simulate` from the stored output samples: after the run for results in memory, after every
chunk for runs streamed to disk (`simulate(out=...)`), i.e. not inside the compiled step loop. The first
time a quantity exceeds its tolerance a `MonitorWarning` names the time [s], the quantity, the element and
the value; `Result.diagnostics` keeps the history.

- constraint_violation: max |phi(q, t)| over the position constraint rows [m or rad] (the owning joint or
  motion named), at most MAX_SAMPLES evenly spaced samples per run or chunk (the first and the last
  included); tolerance CONSTRAINT_TOL. A compiled run's outputs are on the constraints by construction
  (joint coordinates, or projected to 1e-12 with a failure status otherwise): its first and last sample
  are checked, both in one compiled call (Result.residual_check).
- energy_error: (T + V + D - W) - (T + V + D - W)(t0) [J]: kinetic T, potential V (gravity and elastic
  elements), dissipated D (damping, friction, sphere and shape contacts: `Result.dissipated_energy`, the
  dissipation power integrated on the run's dense output step by step, so that impacts and modes ringing
  faster than the output step are counted) and the work W of applied forces and torques (trapezoidal
  rule of their power); a compiled run of simulate(monitor=True) accumulates D and W in its step loop
  (solvers.energy_run: its own stage powers, so exact to the run's accuracy and nearly free), and those are
  used where it kept them (joint friction's balance then too); tolerance ENERGY_TOL times the energy scale
  (the largest of T, |V - V(t0)|, D, |W| over the run, 1e-6 |V| and 1e-12 J) plus a trapezoid allowance when
  D or W are present (ENERGY_TOL_QUADRATURE). Not checked for driven models (motions do work through
  their multipliers) or unknown element types: `energy_error` is then None with the reason in `notes`.
- penetration: max(0, -gap) per contact [m]; tolerance PENETRATION_FRACTION of the (smaller) sphere radius,
  beyond which a point contact no longer describes the geometry.
"""
from __future__ import annotations

from .._userwarn import warn
from dataclasses import dataclass, field

import numpy as np

CONSTRAINT_TOL = 1e-6
ENERGY_TOL = 1e-4
ENERGY_TOL_QUADRATURE = 0.1   # D (integrator error) and W (trapezoidal on the samples): gross imbalances
PENETRATION_FRACTION = 0.5   # half the sphere inside its partner: the point-contact model no longer holds
MAX_SAMPLES = 32   # constraint residuals are evaluated one sample at a time: a coarse, cheap check


class MonitorWarning(UserWarning):
    """A monitored quantity (constraint violation, energy balance, contact penetration) exceeded its
    tolerance during a run."""


@dataclass
class Diagnostics:
    """History of the run monitors; arrays are per stored sample (per checked sample for
    constraint_violation: `constraint_time`). `exceedances`: first exceedance of each quantity and element,
    dicts with time [s], quantity, element, value, tolerance."""

    time: np.ndarray = field(default_factory=lambda: np.zeros(0))
    constraint_time: np.ndarray = field(default_factory=lambda: np.zeros(0))
    constraint_violation: np.ndarray = field(default_factory=lambda: np.zeros(0))
    energy_error: np.ndarray | None = None
    energy_scale: float = 0.0
    penetration: dict = field(default_factory=dict)
    tolerances: dict = field(default_factory=dict)
    exceedances: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    _carry: dict = field(default_factory=dict, repr=False)

    def summary(self) -> dict:
        """Largest value of each monitored quantity [m or rad, J, m]."""
        out = {"constraint_violation": float(np.max(self.constraint_violation, initial=0.0))}
        if self.energy_error is not None and len(self.energy_error):
            out["energy_error"] = float(np.max(np.abs(self.energy_error)))
        for k, v in self.penetration.items():
            out[f"penetration {k}"] = float(np.max(v, initial=0.0))
        return out


def _constraint(res, diag, stride_limit=MAX_SAMPLES):
    from ..system.equations import constraint_terms
    sys = res.system
    if not sys.nc or not len(res.time):
        return np.zeros(0), np.zeros(0), []
    n = len(res.time)
    method = str(res.stats.get("method", ""))
    if "(compiled)" in method or "kinematic (0 DOF)" in method:
        # compiled outputs are on the constraints by construction (joint coordinates) or projected to
        # 1e-12 with a failure status otherwise (the kinematic sweep of a zero-DOF model: solved to 1e-12):
        # a consistency check at the first and last sample suffices
        stride_limit = 2
    # evenly spaced samples, the first and the last included (linspace's end point is n - 1)
    idx = np.unique(np.linspace(0, n - 1, min(n, stride_limit)).astype(np.int64))
    rows = np.asarray(getattr(sys, "fixed_rows", np.arange(sys.nc)))   # not friction stick locks (switched)
    if not len(rows):
        return np.zeros(0), np.zeros(0), []
    if res.residual_check is not None:   # a compiled run: every checked sample in one compiled call
        val, arg = res.residual_check(idx, rows)
        return res.time[idx], val, [sys.row_owner[j] for j in arg.tolist()]
    zero = np.zeros(sys.nv)
    val, owner = np.zeros(len(idx)), []
    for k, i in enumerate(idx):
        phi = constraint_terms(sys, res.q[i], zero, res.time[i], jacobian=False)[0][rows]
        j = int(np.argmax(np.abs(phi))) if len(phi) else 0
        val[k] = abs(phi[j]) if len(phi) else 0.0
        owner.append(sys.row_owner[rows[j]] if len(phi) else "")
    return res.time[idx], val, owner


def _energy_terms(res):
    """(T, V, D, P_applied, W) at the samples (W: the compiled run's accumulated work, P_applied None then),
    or (None, reason)."""
    from ..model.element_specs import Bushing
    from ..model.forces import Force, Torque
    from ..system.force_elements import evaluator
    from .energy import run_energy
    sys = res.system
    if "HHT" in str(res.stats.get("method", "")):
        return None, "energy balance not checked: HHT dissipates high frequencies numerically by design"
    if sys.model.motions:
        return None, "energy balance not checked: driven model (motions do work through their multipliers)"
    applied = [e for e in sys.model.forces.values() if isinstance(e, (Force, Torque))]
    for e in sys.model.forces.values():
        ev = evaluator(e)
        if e not in applied and not (hasattr(ev, "potential") or hasattr(ev, "dissipation")):
            return None, f"energy balance not checked: element '{e.name}' has no energy bookkeeping"
        if getattr(ev, "needs_lambda", False) and run_energy(res, "D") is None:
            return None, f"energy balance not checked: friction '{e.name}' needs the multipliers"
        kt = np.asarray(e.stiffness, float)[3:] if isinstance(e, Bushing) else None
        if kt is not None and np.ptp(kt) > 1e-12 * np.max(kt):
            return None, (f"energy balance not checked: bushing '{e.name}' has unequal rotational stiffnesses "
                          "(Adams' small-angle BUSHING torque -K a is not conservative for finite rotations)")
    T, V = res.kinetic_energy(), res.potential_energy()
    # the dissipated energy the Result reports: the dissipation power integrated on the run's own dense
    # output (step-wise, to 1e-10), not the trapezoidal rule on the output samples, which misses the
    # power of contact impacts and of modes ringing faster than the output step
    D = res.dissipated_energy() if any(_can_dissipate(e) for e in sys.model.forces.values()) else None
    P_w, W = None, (run_energy(res, "W") if applied else None)
    if applied and W is None:
        from .state import state_factory
        sf = state_factory(sys)
        P_w = np.zeros(len(res.time))
        from ..system.frames import body_frames
        try:
            for i, t in enumerate(res.time):
                f1 = body_frames(sys, res.q[i], res.v[i])
                st = sf(t, res.q[i], res.v[i]) if sf else None
                for e in applied:
                    P_w[i] += float(evaluator(e).generalized(sys, f1, e, t, st) @ res.v[i])
        except Exception as exc:  # noqa: BLE001 - a user load failing here: monitor skipped, run unaffected
            return None, f"energy balance not checked: applied load failed ({type(exc).__name__})"
    return (T, V, D, P_w, W), None


def _can_dissipate(e) -> bool:
    """Whether force element `e` can dissipate energy: an element with a dissipation power, except the
    linear ones (spring-dampers, torsion springs, bushings) whose damping is zero, for which that power is
    identically zero (the dissipated energy's quadrature then costs more than the run)."""
    from ..model.element_specs import Bushing, TorsionSpring
    from ..model.forces import SpringDamper
    from ..system.force_elements import evaluator
    if not hasattr(evaluator(e), "dissipation"):
        return False
    if type(e) in (SpringDamper, TorsionSpring, Bushing):
        try:
            return bool(np.any(np.asarray(e.damping, float)))
        except (TypeError, ValueError):   # a damping that is not a number (an expression): it may dissipate
            return True
    return True


def _trapz_cum(P, t, start=0.0):
    if P is None:
        return None
    return start + np.concatenate([[0.0], np.cumsum(0.5 * (P[1:] + P[:-1]) * np.diff(t))])


def update(diag: Diagnostics, res, first: bool = True) -> Diagnostics:
    """Check the samples of `res` (a whole run, or the next chunk of a streamed run whose first sample
    repeats the previous chunk's last) and append to `diag`; warns at first exceedances."""
    sys = res.system
    t = res.time
    skip = 0 if first else 1
    ct, cv, owners = _constraint(res, diag)
    keep = ct > (diag.constraint_time[-1] if len(diag.constraint_time) else -np.inf)
    diag.constraint_time = np.concatenate([diag.constraint_time, ct[keep]])
    diag.constraint_violation = np.concatenate([diag.constraint_violation, cv[keep]])
    diag.tolerances.setdefault("constraint_violation", CONSTRAINT_TOL)
    for k in np.flatnonzero(cv > CONSTRAINT_TOL):
        _exceed(diag, float(ct[k]), "constraint_violation", f"joint '{owners[k]}'", float(cv[k]), CONSTRAINT_TOL)
    terms, note = _energy_terms(res) if "energy_off" not in diag._carry else (None, None)
    if terms is None:
        if note and note not in diag.notes:
            diag.notes.append(note)
        diag._carry["energy_off"] = True
        diag.energy_error = None
    else:
        T, V, D_run, P_w, W_run = terms
        c = diag._carry
        D = None if D_run is None else c.get("D", 0.0) + D_run   # D_run starts at 0 at the chunk's first sample
        W = _trapz_cum(P_w, t, c.get("W", 0.0)) if W_run is None else c.get("W", 0.0) + W_run
        bal = T + V + (0.0 if D is None else D) - (0.0 if W is None else W)
        c.setdefault("E0", float(bal[0]))
        c.setdefault("V0", float(V[0]))
        err = bal - c["E0"]
        c["D"], c["W"] = (float(D[-1]) if D is not None else 0.0), (float(W[-1]) if W is not None else 0.0)
        scale = max(diag.energy_scale, float(np.max(T)), float(np.max(np.abs(V - c["V0"]))), abs(c["D"]),
                    abs(c["W"]), 1e-6 * float(np.max(np.abs(V))), 1e-12)   # round-off floor: 1e-10 |V|
        diag.energy_scale = scale
        tol = (ENERGY_TOL_QUADRATURE if (D is not None or W is not None) else ENERGY_TOL) * scale
        diag.tolerances["energy_error"] = tol
        prev = diag.energy_error if diag.energy_error is not None else np.zeros(0)
        diag.energy_error = np.concatenate([prev, err[skip:]])
        bad = np.flatnonzero(np.abs(err) > tol)
        if len(bad):
            _exceed(diag, float(t[bad[0]]), "energy_error", f"model '{sys.model.name}'", float(err[bad[0]]), tol)
    from ..model.element_specs import Contact
    for e in sys.model.forces.values():
        if isinstance(e, Contact):
            gap = res.spring_length(e)
            pen = np.maximum(-gap, 0.0)
            prev = diag.penetration.get(e.name, np.zeros(0))
            diag.penetration[e.name] = np.concatenate([prev, pen[skip:]])
            tol = PENETRATION_FRACTION * min(sh.radius for sh in (e.shape_i, e.shape_j) if sh.kind == "sphere")
            diag.tolerances[f"penetration {e.name}"] = tol
            bad = np.flatnonzero(pen > tol)
            if len(bad):
                _exceed(diag, float(t[bad[0]]), "penetration", f"contact '{e.name}'", float(pen[bad[0]]), tol)
    diag.time = np.concatenate([diag.time, t[skip:]])
    return diag


def compact_tail(diag: Diagnostics, n_time: int, n_constraint: int) -> None:
    """Replace the history entries appended after the first n_time samples (n_constraint checked samples)
    by one entry at the chunk's last time holding the chunk's extreme values: bounded history for streamed
    runs (one entry per chunk)."""
    if len(diag.time) <= n_time + 1:
        return
    t_last = diag.time[-1:]

    def extreme(a, n):
        tail = a[n:]
        return np.concatenate([a[:n], tail[[int(np.argmax(np.abs(tail)))]]]) if len(tail) else a
    if diag.energy_error is not None and len(diag.energy_error) == len(diag.time):
        diag.energy_error = extreme(diag.energy_error, n_time)
    for k, v in diag.penetration.items():
        if len(v) == len(diag.time):
            diag.penetration[k] = extreme(v, n_time)
    if len(diag.constraint_violation) > n_constraint + 1:
        diag.constraint_violation = extreme(diag.constraint_violation, n_constraint)
        diag.constraint_time = np.concatenate([diag.constraint_time[:n_constraint], t_last])
    diag.time = np.concatenate([diag.time[:n_time], t_last])


def _exceed(diag, t, quantity, element, value, tol):
    if any(x["quantity"] == quantity and x["element"] == element for x in diag.exceedances):
        return
    diag.exceedances.append({"time": t, "quantity": quantity, "element": element, "value": value, "tolerance": tol})
    warn(f"{element}: {quantity.replace('_', ' ')} {value:.3g} exceeds the tolerance {tol:.3g} first at "
         f"t = {t:.9g} s", MonitorWarning)


def monitor(res, diag: Diagnostics | None = None, first: bool = True) -> Diagnostics:
    """Run the monitors over `res` (see module doc); never fails the run: an error inside a monitor is
    recorded in `notes`."""
    diag = Diagnostics() if diag is None else diag
    if not len(res.time):
        return diag
    try:
        return update(diag, res, first)
    except (ValueError, np.linalg.LinAlgError, FloatingPointError) as exc:
        diag.notes.append(f"monitors stopped: {type(exc).__name__}: {exc}")
        return diag
