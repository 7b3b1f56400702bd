"""One driver over the Python steppers: output grid, events, progress, failures and the Result.

The steppers (HHT-alpha: `solvers.hht.HHTStepper`; scipy's index-1 OdeSolvers: `solvers.index1.Index1Stepper`)
share one interface, after scipy's OdeSolver split of stepper and driver:

    first()                 the output tuple at the start state (t0)
    step() -> Step          the next accepted step from `t` (not taken yet): (t_old, t_new [s], dense(t) -> y =
                            [q, v] on the step, sample(t) -> output tuple, y_new)
    to_event(step, t_hit, locate)   (step, reached): the step ending at the event time t_hit (the dense
                            output cut there, or the step redone to end there, as often as locate(step),
                            the earliest root on a step's own dense output, still finds one before its end);
                            reached: it ends at the event
    take(step)              accept the step: `t` and `y` (consistent [q, v]) move to its end
    restart()               begin afresh from (t, y) after an event switched modes
    here()                  the output tuple at (t, y)
    result(times, out, **kw) -> Result,  stats() -> dict,  evaluate(ts),  step_states()

and `drive` does what every method needs: the switching functions of force elements and sensors (located
on the step's dense output by `solvers.events.EventTracker`, the step cut or redone to end at the root,
`on_event` after it, a sensor's "stop"), the output samples in each step (from the step's own dense
output), progress calls with a partial Result, and a failure that keeps every output before it. The
compiled DOP853 (`solvers.compiled_run`) has its own loop in numba: Python is re-entered only per chunk
of outputs, which a per-step interface would defeat.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..errors import SolverError
from ..results.stream import notify
from .common import analysis_error

MAX_STEPS = 10_000_000   # steps of one run, at most (as the compiled integrator's max_steps)


@dataclass
class Step:
    """An accepted step from t_old to t_new [s]: y_new = [q, v] at its end (before projection), dense(t) ->
    [q, v] on it, sample(t) -> the output tuple at t (projected, completed); `data`: the stepper's own."""

    t_old: float
    t_new: float
    y_new: np.ndarray
    dense: Callable
    sample: Callable
    data: Any = None


def drive(stepper, sys, rep, times, events, progress=None, max_steps=None):
    """Run `stepper` over the output grid `times` [s] from the assembled state `rep`, with the switching
    functions of `events` (an EventTracker already started at t0); returns the Result (success=False with
    every output before a failure, the failure in res.error; a SolverError after max_steps steps, default
    MAX_STEPS as the compiled integrator's budget, so that a run over an enormous span ends)."""
    t_end = float(times[-1])
    out = [stepper.first()]
    nxt, success, message, error = 1, True, "ok", None
    taken, max_steps = 0, MAX_STEPS if max_steps is None else max_steps
    try:
        while stepper.t < t_end - 1e-14 * max(1.0, abs(t_end)):
            taken += 1
            if taken > max_steps:
                raise SolverError(f"step budget exhausted ({max_steps} steps)", time=float(stepper.t))
            step = stepper.step()
            hit = events.check(step.t_old, step.t_new, step.dense)
            event = False
            if hit is not None:
                step, event = stepper.to_event(step, hit, lambda s: events.locate(s.t_old, s.t_new, s.dense)[0])
            while nxt < len(times) and times[nxt] <= step.t_new + stepper.out_tol * max(1.0, abs(step.t_new)):
                out.append(step.sample(min(times[nxt], step.t_new)))
                nxt += 1
            notify(progress, step.t_new, lambda n=len(out): stepper.result(
                times[:n], out[:n], stats={"assembly": rep}, message="partial (run in progress)"))
            stepper.take(step)
            if not event:
                continue
            events.after(stepper.t, stepper.y)
            if events.stop:   # a sensor with action "stop": the event is the last sample
                if stepper.t > times[len(out) - 1]:
                    out.append(stepper.here())
                    times = np.append(times[:len(out) - 1], stepper.t)
                message = f"stopped by sensor '{events.sensor_events[-1].name}' at t = {stepper.t:.12g} s"
                break
            stepper.restart()
    except (Exception, KeyboardInterrupt) as exc:   # noqa: BLE001 - every failure ends the run, named
        exc = analysis_error(exc, stepper.t)
        success, message, error = False, f"{exc}; last good output at t = {times[len(out) - 1]:.9g} s", exc
    n = len(out)
    stepped = stepper.has_steps()
    res = stepper.result(times[:n], out, evaluate=stepper.evaluate if stepped else None, success=success,
                         status=0 if success else -1, message=message, stats=stepper.stats())
    res.error = error
    res.sensor_events = list(events.sensor_events)
    res.steps = stepper.step_states if stepped else None
    return res
