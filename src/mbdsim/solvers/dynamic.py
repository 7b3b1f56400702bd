"""Dynamic analysis: `simulate` (checks, method choice, tolerances) over the compiled DOP853 and Radau IIA
(mbdsim.solvers.compiled_run, radau_run), the index-1 scipy methods and HHT (those two through the one
driver of mbdsim.solvers.driver).

Index-1 methods ("dop853" - the high-accuracy default for smooth problems -, "rk45", "radau", "bdf"):
the equations of motion are solved for accelerations at every stage (augmented KKT system), the
state y = [q, v] is integrated with a scipy OdeSolver, and after every accepted step the positions
and velocities are projected back onto phi = 0 and phi_q v = nu (coordinate projection), which keeps
the drift at the Newton tolerance (~1e-12).  "hht" is the implicit HHT-alpha method (mbdsim.solvers.hht).
"""
from __future__ import annotations

import os

import numpy as np

from .._blas import blas_single_thread, lazy_import
from ..errors import ModelError
from ..results.result import Result
from ..system.assemble import assemble_system
from ..system.compiled import NotCompiled
from ..system.force_elements import evaluator
from .assembly import assemble_state
from .autoswitch import warn_reached
from .compiled_run import Stiff, integrate_compiled
from .common import _weak_joints, consistent_state  # noqa: F401  (names other modules import from here)
from .checks import check_initial_contacts
from .kinematic import check_model, time_grid
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from typing import Sequence
    from .._types import PathLike, Progress
    from ..model.model import Model

SCIPY_METHODS = {"dop853": "DOP853", "high-accuracy": "DOP853", "rk45": "RK45", "radau": "Radau", "bdf": "BDF"}
# scipy.integrate's OdeSolver class of each method, by name: imported when a run uses the reference path
# (~17 MB of scipy that the compiled runs do not load)
COMPILED_METHODS = ("dop853", "high-accuracy")   # run by the compiled step loop when the model allows
USE_COMPILED = True   # False: always the reference scipy path (tests compare the two)
DEFAULT_TOL = {"auto": (1e-7, 1e-9), "dop853": (1e-10, 1e-12), "high-accuracy": (1e-10, 1e-12), "rk45": (1e-7, 1e-9),
               "radau": (1e-8, 1e-10), "bdf": (1e-8, 1e-10), "hht": (1e-5, 1e-7)}
AUTO_LOCAL = 0.05   # "auto": rtol targets the global error of the outputs; the step control uses rtol / 20
TIGHT = 1e-6        # "auto" on a model the compiled core does not carry: below this rtol DOP853, not HHT


@blas_single_thread
def simulate(model: Model, end_time: float, output_step: float | None = None, method: str | None = None,
             rtol: float | None = None, atol: float | None = None, max_step: float | None = None,
             start_time: float = 0.0, progress: Progress = None, out: PathLike | None = None,
             resume: bool = False, monitor: bool = True, markers: bool | Sequence[str] = False) -> Result:
    """Dynamic analysis from start_time to end_time [s]; output every output_step [s] (default 1/500 span).

    method: "auto" (default): the compiled DOP853 (8th order, O(N) equations of motion) when every
    element of the model is compiled, handing over to the compiled Radau IIA (5th order, implicit) when
    it detects stiffness (Radau continues from the detection time at the same target tolerance;
    res.stats["switch_time"]; mbdsim.solvers.radau_run); otherwise the reference
    DOP853 (index-1 with projection; "hht" only when a given rtol is 1e-6 or looser; expression sensors are
    watched inside the compiled DOP853's step loop). A model with zero degrees of freedom
    (fully driven: assembly's dof == 0) on the compiled core is solved by "auto" as a kinematic
    analysis instead, exact to the Newton tolerance at every output (mbdsim.solvers.kinsweep;
    res.stats["method"] "auto: kinematic (0 DOF)"; DOP853 when it meets a change point or has sensors). With "auto", rtol (default 1e-7) is
    the target relative error of the outputs: the step control uses rtol / 20 (local error) so that the
    accumulated (global) error stays near rtol. Named methods: "dop853" (high accuracy,
    index-1 with projection; compiled when the model allows), "hht" (implicit HHT-alpha with numerical
    damping; compiled when the model allows, sensors watched on its steps), "rk45", "radau" (implicit
    Radau IIA; compiled when the model allows, sensors watched on its steps), "bdf". rtol/atol: integrator tolerances (relative; absolute in SI units of
    the coordinates and velocities); atol follows a given rtol in the method's default ratio.
    `res.stats` reports the method used, steps, rejected steps, function and Jacobian evaluations
    (nfev, njev), factorisations, the order and "order_history": (t_start [s], method, order) segments.
    progress: True shows a progress bar of the simulated time on stderr (rich, redrawn at most 10 times a
    second, mbdsim._progress); a callable progress(t) receives the simulated time reached [s] now and then
    (an exception it raises ends the run like any failure below, res.error a ProgressError naming
    analysis.progress); False: nothing; None (default): the bar once the run has taken 2 s, in a terminal or
    notebook only; anything else is a ModelError before any work.
    Every failure during the run (solver, a user function raising or returning a non-number or a
    non-finite value, Ctrl-C) ends it with `res.success = False`, `res.message` and `res.error` naming the
    element, field and time (EvaluationError, SolverError, AnalysisInterrupted), the Result holding
    every output before it; bad arguments raise ModelError before any work, and so do runs asking for
    unbounded work: more than MAX_OUTPUTS (1e8) output times, or (end_time - start_time) / max_step over
    MAX_STEP_COUNT (1e9) steps (ModelError naming output_step or max_step, with the numbers). Every
    method stops after 1e7 steps (the compiled max_steps, driver.MAX_STEPS) with success=False.
    out: optional path of a .parquet or .csv file written while the run goes, so that an interrupted or
    killed run leaves what it computed. A ".parquet" path on the compiled DOP853 (method "auto" or
    "dop853" on a model the kernels carry) is a Parquet dataset directory streamed in parts as they are
    computed, with checkpoints: bounded memory whatever the length (the returned Result holds every
    output while they fit 8 MB (stream.STREAM_KEEP), else the last part; res.stats["out"], ["samples"]) and
    resume=True continues it from its last checkpoint, bit-identical to an uninterrupted run
    (mbdsim.solvers.stream); a ".csv" path there is one CSV file streamed the same way (rows appended
    part by part; no checkpoint, so no resume). Otherwise `res.to_dataframe()` of the outputs so far is
    rewritten every few seconds, atomically, and completely at the end (mbdsim.results.stream);
    `pandas.read_parquet(out)` or `pandas.read_csv(out)` reads either. markers: the marker columns of the out= table, as `res.to_dataframe(markers=...)`: True
    every marker's, or a list of names ("tip" or "<body>.<marker>"); ModelError for an unknown name.
    monitor=True (default): constraint violation, energy balance and contact penetration are checked on
    the output samples (after the run, or after every part of a streamed run); the first exceedance of
    each warns (MonitorWarning naming time, quantity and element) and `res.diagnostics` keeps the history
    (mbdsim.results.diagnostics)."""
    from .._progress import progress_of
    if not isinstance(resume, bool):
        raise ModelError("simulate", "resume", f"expected True or False, got {resume!r}")
    _check_markers(model, markers, "simulate")
    with progress_of(progress, "simulate", f"simulating {getattr(model, 'name', '')}", start_time, end_time) as p:
        return _simulate_out(model, end_time, output_step, method, rtol, atol, max_step, start_time, p, out, resume,
                             monitor, markers)


def _check_markers(model, markers, entity) -> None:
    """ModelError naming entity.markers unless `markers` selects markers of `model` (export.marker_targets)."""
    from ..results.export import marker_targets
    if markers is not None and markers is not False:
        marker_targets(getattr(model, "bodies", {}).values(), markers, entity)


def _simulate_out(model, end_time, output_step, method, rtol, atol, max_step, start_time, progress, out, resume,
                  monitor, markers=False) -> Result:
    """`simulate` once progress is None or a callable: the streamed or whole-file writer, then the monitors."""
    from ..results.diagnostics import monitor as run_monitors
    from ..results.stream import check_progress, run_writing
    check_progress(progress, "simulate")
    if resume and str(out).lower().endswith(".csv"):
        raise ModelError("simulate", "resume", "a .csv output has no checkpoint to resume from: stream to a "
                         ".parquet path to resume a run")
    res = None
    if out is not None and isinstance(out, (str, os.PathLike)) and str(out).lower().endswith((".parquet", ".csv")) and \
            (method is None or str(method).lower() in ("auto",) + COMPILED_METHODS) and USE_COMPILED:
        try:
            res = _simulate(model, end_time, output_step, method, rtol, atol, max_step, start_time, progress, out,
                            resume, monitor, markers)
        except NotStreamable:
            pass
    if res is None:
        if resume:
            raise ModelError("simulate", "resume", "resuming needs out= a .parquet path and the compiled DOP853 "
                             "(method 'auto' or 'dop853' on a model the compiled kernels carry)")
        res = run_writing(lambda p: _simulate(model, end_time, output_step, method, rtol, atol, max_step,
                                              start_time, p, None, False, monitor), progress, out, "simulate",
                          markers)
    if monitor and res.diagnostics is None:
        res.diagnostics = run_monitors(res)
    return res


class NotStreamable(Exception):
    """simulate(out=...parquet): the compiled core does not carry this model (the whole-file writer runs)."""


def _simulate(model, end_time, output_step=None, method=None, rtol=None, atol=None, max_step=None,
              start_time=0.0, progress=None, out=None, resume=False, monitor=True, markers=False) -> Result:
    """The analysis of `simulate` (its docstring has the arguments), without the monitors; with `out`, the
    streamed compiled run (NotStreamable when the model needs another path)."""
    check_model(model, "simulate")
    for name in getattr(model, "fmus", {}):   # FMUs are sampled in the Simulator's step loop only
        raise ModelError(f"fmu '{name}'", "path", "FMUs run in the step loop of mbdsim.Simulator, not in simulate")
    method = "auto" if method is None else method
    if not isinstance(method, str):
        raise ModelError("simulate", "method", f"expected a method name, got {method!r}")
    method = method.lower()
    if method not in SCIPY_METHODS and method not in ("hht", "auto"):
        raise ModelError("simulate", "method", f"unknown method {method!r}; choose from "
                         f"{sorted(list(SCIPY_METHODS) + ['hht', 'auto'])}")
    user_rtol = None if rtol is None else _positive("rtol", rtol)
    if user_rtol is not None and user_rtol < RTOL_FLOOR:
        raise ModelError("simulate", "rtol", f"{rtol!r} is below what double precision can deliver "
                         f"(at least {RTOL_FLOOR:g})")
    if method == "hht" and user_rtol is not None and user_rtol < HHT_RTOL_FLOOR:
        raise ModelError("simulate", "rtol", f"{rtol!r} is below what the HHT method resolves (its Newton "
                         f"tolerance; at least {HHT_RTOL_FLOOR:g}): use method='dop853' for tighter tolerances")
    user_atol = None if atol is None else _positive("atol", atol)
    max_step = None if max_step is None else _positive("max_step", max_step, finite=False)
    start_time = _number("start_time", start_time)
    _check_budget(model, start_time, end_time, output_step, max_step, in_memory=out is None)
    times = time_grid(start_time, end_time, output_step)
    sys = assemble_system(model)
    sys.track_energy = bool(monitor)   # compiled runs keep the energy bookkeeping for the monitor (energy_run)
    rep = assemble_state(sys, sys.q0, sys.v0, start_time)
    check_initial_contacts(sys, rep.q, rep.v)
    if out is not None:
        return _streamed(sys, rep, times, method, user_rtol, user_atol, max_step, progress, out, resume, monitor,
                         markers)
    if method == "auto":
        rt, at = _tolerances("auto", user_rtol, user_atol)
        try:
            if USE_COMPILED and rep.dof == 0 and sys.nv:   # fully driven: a kinematic sweep, no integration
                from .kinsweep import integrate_kinematic
                res = integrate_kinematic(sys, rep, times, progress)
                if res is not None:   # (None: a joint-coordinate tree, integrated below)
                    res = _with_history(res, times[0])
                    res.stats["method"] = "auto: " + res.stats["method"]
                    return res
            if USE_COMPILED:
                res = _with_history(integrate_compiled(sys, rep, times, AUTO_LOCAL * rt, AUTO_LOCAL * at,
                                                       max_step, progress, stiff_check=True), times[0])
                res.stats["method"] = "auto: " + res.stats["method"]
                return res
        except NotCompiled as exc:
            reason = str(exc)
        except Stiff as exc:
            reason = f"stiffness detected at t = {exc.time:.6g} s"
            if exc.prefix is not None:   # the compiled Radau IIA continues (sensors watched on its steps too)
                from .radau_run import continue_radau   # from there, at auto's tolerance (joint friction too: its
                #                                         events on Radau's steps, the same modes)
                res = continue_radau(sys, rep, times, exc, AUTO_LOCAL * rt, AUTO_LOCAL * at, max_step, progress,
                                     reason)
                res.stats["rtol_reached"] = rt
                return res
        else:
            reason = "compiled path disabled"
        method = _default_method(model)
        if method == "hht" and (user_rtol is None or user_rtol < TIGHT) and not reason.startswith("stiff"):
            # the outputs' target (auto's rtol, 1e-7 by default) is beyond a second-order method in
            # reasonable time: DOP853 (a gear train at the defaults: 3e-8 instead of HHT's 1.4e-3)
            method = "dop853"
            user_rtol, user_atol = AUTO_LOCAL * rt, AUTO_LOCAL * at
        elif method == "hht" and user_rtol is not None:
            user_rtol = max(user_rtol, HHT_RTOL_FLOOR)   # stiff hand-over: HHT's own floor
        res = _run(sys, rep, times, method, *_tolerances(method, user_rtol, user_atol), max_step, progress)
        res.stats["method"] = f"auto: {res.stats.get('method', method)} ({reason})"
        if method == "hht":
            warn_reached(res, _tolerances("hht", user_rtol, user_atol)[0], rt, reason)
        return res
    return _run(sys, rep, times, method, *_tolerances(method, user_rtol, user_atol), max_step, progress)


def _streamed(sys, rep, times, method, rtol, atol, max_step, progress, out, resume, monitor=True,
              markers=False) -> Result:
    """simulate(out=...parquet): the compiled DOP853 streamed to disk in parts (mbdsim.solvers.stream);
    NotStreamable when the model needs another path (nothing written yet)."""
    from . import stream
    if method not in ("auto",) + COMPILED_METHODS:
        raise NotStreamable(method)
    rt, at = _tolerances(method, rtol, atol)
    if method == "auto":   # as in memory: rtol targets the outputs' global error (local rtol / 20)
        rt, at = AUTO_LOCAL * rt, AUTO_LOCAL * at
    try:
        return _with_history(stream.stream_compiled(sys, rep, times, rt, at, max_step, progress, out, resume,
                                                    monitor, markers, stiff_check=method == "auto"), times[0])
    except NotCompiled as exc:
        raise NotStreamable(str(exc)) from None


def _tolerances(method, rtol, atol):
    """(rtol, atol) of a method: its defaults, or the user's rtol with atol following in the default ratio
    (so that rtol alone tightens or loosens a run; atol = 0 would divide by zero in the error norms)."""
    d_rtol, d_atol = DEFAULT_TOL[method]
    r = d_rtol if rtol is None else rtol
    return r, (d_atol * r / d_rtol if atol is None else atol)


def _run(sys, rep, times, method, rtol, atol, max_step, progress=None) -> Result:
    """One named method over the output grid from the assembled state (res.stats with its order history)."""
    return _with_history(_run_method(sys, rep, times, method, rtol, atol, max_step, progress), times[0])


def _with_history(res, t0) -> Result:
    """res with res.stats["order_history"] (one segment from t0 [s] when the run kept no history itself)."""
    from .autoswitch import single_history
    res.stats.setdefault("order_history", single_history(t0, res.stats.get("method"), res.stats.get("order")))
    return res


def _run_method(sys, rep, times, method, rtol, atol, max_step, progress=None) -> Result:
    if method == "hht":
        from .hht import integrate_hht
        names = [e.name for e in sys.model.forces.values() if getattr(evaluator(e), "needs_lambda", False)]
        reason = "the compiled core is off (USE_COMPILED)"
        if USE_COMPILED:   # the compiled HHT-alpha (mbdsim.solvers.hht_run; joint friction included)
            from .hht import ALPHA
            from .hht_run import integrate_hht_compiled
            try:
                return integrate_hht_compiled(sys, rep, times, rtol, atol, max_step, ALPHA, progress)
            except NotCompiled as exc:
                reason = str(exc)
        if getattr(sys.model, "sensors", None):   # (the compiled HHT watches them on its steps' polynomials)
            raise ModelError(f"sensor '{next(iter(sys.model.sensors))}'", "method", "sensors are located by the "
                             f"compiled HHT, which cannot run this model ({reason}), and the index-1 methods "
                             "(method='auto', 'dop853', 'rk45', 'radau' or 'bdf'), not the reference HHT")
        if names:   # the reference HHT has no stick/slip events
            raise ModelError(f"friction '{names[0]}'", "method", "joint friction with stick/slip runs on the "
                             f"compiled HHT, which cannot run this model ({reason}); use method='dop853', "
                             "'rk45', 'radau' or 'bdf'")
        res = integrate_hht(sys, rep, times, rtol, atol, max_step, progress=progress)
        res.stats.setdefault("method", "HHT")
        return res
    if method == "radau" and USE_COMPILED:   # the compiled Radau IIA (mbdsim.solvers.radau_run)
        from .radau_run import integrate_radau
        try:
            return integrate_radau(sys, rep, times, rtol, atol, max_step, progress)
        except NotCompiled:
            pass
    if method in COMPILED_METHODS and USE_COMPILED:
        try:
            return integrate_compiled(sys, rep, times, rtol, atol, max_step, progress)
        except NotCompiled:
            pass   # an element the compiled kernels do not carry yet: the reference (scipy) path
    from .index1 import integrate_index1
    integrate = lazy_import("scipy.integrate")
    return integrate_index1(sys, rep, times, getattr(integrate, SCIPY_METHODS[method]), rtol, atol, max_step,
                            progress)


HHT_RTOL_FLOOR = 1e-10     # HHT's Newton iterations converge to ~1e-12: its error estimate means nothing below
RTOL_FLOOR = 1e-14          # relative tolerances below this cannot be met in double precision
RESULT_BUDGET = 4 * 2**30   # bytes of output arrays an analysis may allocate
MAX_OUTPUTS = 1e8           # output times of one analysis, at most (streamed to disk too)
MAX_STEP_COUNT = 1e9        # steps that max_step may force on a run ((end - start) / max_step), at most


def _check_budget(model, t0, t1, step, max_step=None, in_memory=True):
    """ModelError before any work when the analysis asks for unbounded work: more than MAX_OUTPUTS output
    times (naming output_step), more than MAX_STEP_COUNT steps forced by max_step (naming max_step), or,
    in memory (in_memory), output arrays over RESULT_BUDGET (from the model's size: 7 coordinates, 12
    velocity variables and accelerations per body and 6 multipliers per joint or motion per sample)."""
    try:
        span = float(t1) - t0
    except (TypeError, ValueError):
        return   # time_grid names the bad argument
    if max_step is not None and np.isfinite(span) and span > 0 and span / max_step > MAX_STEP_COUNT:
        raise ModelError("simulate", "max_step", f"max_step = {max_step:g} s over {span:g} s would need at least "
                         f"{span / max_step:.3g} steps (more than {MAX_STEP_COUNT:.0e}); use a larger max_step "
                         "or a shorter run")
    try:
        n = span / float(step) + 1
    except (TypeError, ValueError, ZeroDivisionError):
        return   # time_grid names the bad argument
    per_sample = 8 * (19 * len(model.bodies) + 6 * (len(model.joints) + len(model.motions)) + 1)
    if in_memory and np.isfinite(n) and n * per_sample > RESULT_BUDGET:
        raise ModelError("simulate", "output_step", f"{n:.3g} output times would need {n * per_sample / 2**30:.3g} "
                         f"GiB of results (more than {RESULT_BUDGET / 2**30:g} GiB); use a larger output_step")
    if np.isfinite(n) and n > MAX_OUTPUTS:
        raise ModelError("simulate", "output_step", f"{span:g} s every {float(step):g} s would be {n:.3g} output "
                         f"times (more than {MAX_OUTPUTS:.0e}); use a larger output_step or a shorter run")


def _number(field, value) -> float:
    """A finite number for simulate.<field>, else ModelError (a boolean or text is not a number)."""
    from ..model._check import not_a_number
    try:
        if not_a_number(value):
            raise TypeError
        x = float(value)
    except (TypeError, ValueError):
        raise ModelError("simulate", field, f"expected a number, got {value!r}") from None
    if not np.isfinite(x):
        raise ModelError("simulate", field, f"must be finite, got {value!r}")
    return x


def _positive(field, value, strict=True, finite=True) -> float:
    """A solver setting > 0 (>= 0 when not strict), else ModelError naming simulate.<field>."""
    from ..model._check import not_a_number
    try:
        if not_a_number(value):
            raise TypeError
        x = float(value)
    except (TypeError, ValueError):
        raise ModelError("simulate", field, f"expected a number, got {value!r}") from None
    if np.isnan(x) or x < 0 or (strict and x == 0) or (finite and np.isinf(x)):
        raise ModelError("simulate", field, f"must be {'>' if strict else '>='} 0"
                         f"{' and finite' if finite else ''}, got {value!r}")
    return x


def _default_method(model) -> str:
    """'hht', or 'dop853' when a force element needs event-driven mode switching (joint friction) or the
    model has sensors (located on DOP853's dense output)."""
    if any(getattr(evaluator(e), "needs_lambda", False) for e in model.forces.values()) or \
            getattr(model, "sensors", None):
        return "dop853"
    return "hht"
