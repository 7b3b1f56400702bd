"""One variant of a study: its model (model-file data with parameter paths applied, or a factory called
with the parameters), its analysis and its outputs, as one row of results.  `run_chunk` is the Dask task:
many variants per task, so imports, kernel loading and the task overhead are paid once per chunk."""
from __future__ import annotations

import copy
import math
import os
import socket
import time
import warnings
from dataclasses import dataclass, field
from typing import Callable

from ..errors import ModelError
from .measures import evaluate_outputs, fill_template

__all__ = ["Plan", "apply_path", "build_model", "run_analysis", "run_variant", "run_chunk"]

ANALYSES = ("dynamics", "kinematics", "statics", "quasi_static")


@dataclass
class Plan:
    """Everything a worker needs to run variants (pickled once per study and shared by its tasks).

    base: model-file data (SI or unit strings) when the model is a file, dict or Model; factory: a
    callable of keyword parameters returning a Model otherwise.  settings: `set` templates (path ->
    value with {expr} fields over the parameters).  analysis: the validated analysis options."""

    base: dict | None
    factory: Callable | None
    source: str
    analysis: dict
    outputs: dict
    settings: dict = field(default_factory=dict)


def is_path(name: str) -> bool:
    """Parameter names with a dot are paths into the model data ('bodies.rod.mass')."""
    return "." in name


def _step(node, key: str, path: str, source: str):
    """The child of `node` at `key`: a dict key, an item named `key` of a list of named items, or an index."""
    entity = f"study parameter '{path}'"
    if isinstance(node, list):
        named = [item for item in node if isinstance(item, dict) and item.get("name") == key]
        if named:
            return named[0]
        if key.lstrip("-").isdigit() and -len(node) <= int(key) < len(node):
            return int(key)
        names = [str(item.get("name")) for item in node if isinstance(item, dict)]
        raise ModelError(entity, "path", f"no item named {key!r} in {source}; names are: {', '.join(names) or '(none)'}")
    if isinstance(node, dict):
        if key not in node:
            raise ModelError(entity, "path", f"{key!r} not found in {source}; keys are: {', '.join(map(str, node))}")
        return node[key]
    raise ModelError(entity, "path", f"cannot go into {key!r}: the value there is {node!r}")


def apply_path(data: dict, path: str, value, source: str = "the model") -> None:
    """Set `value` at `path` ('bodies.rod.mass', 'gravity.1', 'motions.drive.displacement') in place.

    Sections that are lists of named items are indexed by name; the last key may be a new field (the
    model schema then checks it).  Raises ModelError naming the parameter and the missing step."""
    keys = path.split(".")
    node = data
    for key in keys[:-1]:
        nxt = _step(node, key, path, source)
        node = node[nxt] if isinstance(nxt, int) else nxt
    last = keys[-1]
    if isinstance(node, list):
        idx = _step(node, last, path, source)
        if not isinstance(idx, int):
            raise ModelError(f"study parameter '{path}'", "path", f"{last!r} is an item, not a value")
        node[idx] = value
    elif isinstance(node, dict):
        node[last] = value
    else:
        raise ModelError(f"study parameter '{path}'", "path", f"cannot set {last!r} inside {node!r}")


def build_model(plan: Plan, params: dict):
    """The Model of one variant (params: name -> SI value)."""
    if plan.factory is not None:
        return plan.factory(**params)
    from ..io import model_from_dict
    data = copy.deepcopy(plan.base)
    for name, value in params.items():
        if is_path(name):
            apply_path(data, name, value, plan.source)
    for path, template in plan.settings.items():
        apply_path(data, path, fill_template(template, params, path), plan.source)
    return model_from_dict(data, source=plan.source)


def run_analysis(model, analysis: dict, monitor: bool = True):
    """The Result of the study's analysis on `model` (analysis: type, end_time [s], output_step [s],
    and for dynamics method, rtol, atol, max_step).  monitor=False skips simulate's run monitors (their
    warnings are silenced in a study and no output expression reads Result.diagnostics)."""
    import mbdsim as mb
    kind = analysis.get("type", "dynamics")
    if kind == "statics":
        return mb.equilibrium(model)
    end, step = analysis["end_time"], analysis.get("output_step")
    if kind == "kinematics":
        return mb.kinematics(model, end, step)
    if kind == "quasi_static":
        return mb.quasi_static(model, end, step)
    opts = {k: analysis[k] for k in ("method", "rtol", "atol", "max_step") if analysis.get(k) is not None}
    return mb.simulate(model, end, step, monitor=monitor, **opts)


def needs_diagnostics(plan: Plan) -> bool:
    """Whether the runs need simulate's monitors: only a callable output can read Result.diagnostics."""
    return any(callable(spec) for spec in plan.outputs.values())


def run_variant(plan: Plan, params: dict) -> dict:
    """One row: the outputs, status ('ok', 'failed': the analysis stopped early, 'error': it raised),
    message and wall time [s].  Never raises for a problem of the variant itself."""
    t0 = time.perf_counter()
    from ..system.assemble import single_use
    from .deadline import _VariantTimeout, time_limit
    row = {name: math.nan for name in plan.outputs}
    limit = plan.analysis.get("time_limit")
    try:
        with time_limit(limit) as watch:
            try:
                with warnings.catch_warnings(), single_use():   # each variant's model is built and run once
                    warnings.simplefilter("ignore")      # assembly notes and redundancy reports, once per variant
                    res = run_analysis(build_model(plan, params), plan.analysis, needs_diagnostics(plan))
                    if getattr(res, "success", True):
                        row.update(evaluate_outputs(plan.outputs, res))
                        status, message = "ok", "ok"
                    else:
                        status, message = "failed", str(getattr(res, "message", "analysis failed"))
            except Exception as exc:  # noqa: BLE001 - a failing variant is a row with its error, never a crash
                status, message = "error", f"{type(exc).__name__}: {exc}"
    except _VariantTimeout:
        status, message = "failed", ""
    if watch.fired:   # the run stopped on the limit (its outputs so far discarded: the row is not 'ok')
        row = {name: math.nan for name in plan.outputs}
        status, message = "failed", (f"stopped by the study's time limit (analysis.time_limit = {limit:g} s of "
                                     f"wall time per variant)")
    row.update(status=status, message=message, wall_time=time.perf_counter() - t0)
    return row


def run_chunk(plan: Plan, runs: list) -> list[dict]:
    """The Dask task: rows for `runs`, a list of (run number, {parameter: value}).  The whole chunk (the
    outputs' linear algebra included, not only the analyses) runs with one BLAS thread: the workers
    already share the cores."""
    from .._blas import _limit
    worker = f"{socket.gethostname()}:{os.getpid()}"
    with _limit():
        return [{"run": run, **params, **run_variant(plan, params), "worker": worker} for run, params in runs]
