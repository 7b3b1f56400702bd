"""mb.Study: a parameter study of a model, run on dask.distributed (see mbdsim.studies)."""
from __future__ import annotations

import copy
import hashlib
import inspect
import json
import re
from pathlib import Path

import pandas as pd

from ..errors import ModelError
from .design import make_design, parse_parameter
from .measures import compile_output, fill_template
from .spec import validate_analysis
from .variant import Plan, apply_path, is_path

__all__ = ["Study"]

RESERVED = ("run", "status", "message", "wall_time", "worker", "study_id")


def _model_source(model):
    """(base data, factory, source name) of the model argument."""
    if isinstance(model, (str, Path)):
        from ..importers import importer_for
        load = importer_for(model)
        if load is not None:   # an imported format (URDF, MJCF, ...): its model data
            from ..io import model_to_dict
            return model_to_dict(load(model)), None, str(model)
        from ..io.files import read
        data, _, source = read(model)
        return data, None, source
    if isinstance(model, dict):
        return copy.deepcopy(model), None, str(model.get("name", "<dict>"))
    if hasattr(model, "add_body") and hasattr(model, "bodies"):
        from ..io import model_to_dict
        return model_to_dict(model), None, f"model '{model.name}'"
    if callable(model):
        return None, model, getattr(model, "__qualname__", "factory")
    raise ModelError("study", "model", f"expected a model file, a model dict, an mb.Model or a factory callable, "
                     f"got {type(model).__name__}")


def _identity(obj):
    """Text identifying a callable (module and qualified name) or a value, for the study fingerprint."""
    if callable(obj):
        return f"{getattr(obj, '__module__', '?')}.{getattr(obj, '__qualname__', repr(obj))}"
    return obj


def _check_schema(data: dict, source: str, entity: str) -> None:
    """The first variant's model data against the model-file schema: a misspelt field in a parameter path
    or a `set` entry is an error of the study, not of each run."""
    from pydantic import ValidationError

    from ..io import diagnose
    from ..io.schema import ModelSpec
    try:
        ModelSpec.model_validate(data)
    except ValidationError as exc:
        err = diagnose.from_validation(exc, data, source, None)
        raise ModelError(entity, "path", f"makes the model data invalid: {err}") from None


def _check_units(base: dict, name: str, spec, source: str) -> None:
    """The units a path parameter is written in against the field it sets ("1 m" for a mass is refused,
    ModelError naming the parameter and 'values'): each value with a unit is put into the model data
    as written and checked by the model-file schema (the design itself holds SI numbers)."""
    from .design import quantity_texts
    for text in quantity_texts(spec):
        probe = copy.deepcopy(base)
        apply_path(probe, name, text, source)
        try:
            _check_schema(probe, source, f"study parameter '{name}'")
        except ModelError as exc:
            why = str(exc).split("makes the model data invalid: ")[-1]
            raise ModelError(f"study parameter '{name}'", "values", f"{text!r} does not fit the field it sets "
                             f"({why})") from None


class Study:
    """A parameter study: variants of `model`, each run through `analysis`, measured by `outputs`.

    model: a model file path (.yaml/.json), model-file data (dict), an mb.Model, or a factory callable
    taking the parameters as keyword arguments and returning an mb.Model.
    parameters: name -> spec (see mbdsim.studies.design: values, ranges, distributions, units).  With a
    file/dict/Model, names with dots are paths into the model data ("bodies.rod.mass",
    "motions.drive.displacement", "gravity.1"); plain names are symbols for the `set` templates.  With a
    factory, names are its keyword arguments.
    outputs: name -> expression over the Result's measures (mbdsim.studies.measures) or callable(result).
    analysis: {"type": "dynamics"|"kinematics"|"statics"|"quasi_static", "end_time": s,
    "output_step": s, "rtol", "atol", "method", "max_step", "time_limit": s of wall time per variant (a
    variant over it becomes a 'failed' row; default none)}.
    sampling: "grid", "lhs", "sobol" or "random" with `samples` points and `seed`.
    set: path -> value with {expr} fields over the parameters, applied after the parameter paths
    (derived quantities: {"joints.crank_rod.point": ["{crank}", 0, 0]}).
    chunk_size: variants per Dask task (default: about four tasks per worker, at most 32 variants)."""

    def __init__(self, model, parameters: dict, outputs: dict, analysis: dict | None = None, *,
                 sampling: str | None = None, samples: int | None = None, seed: int = 0, set: dict | None = None,
                 chunk_size: int | None = None, name: str | None = None):
        base, factory, source = _model_source(model)
        if not isinstance(parameters, dict) or not parameters:
            raise ModelError("study", "parameters", "give a mapping of parameter names to values or ranges")
        if not isinstance(outputs, dict) or not outputs:
            raise ModelError("study", "outputs", "give a mapping of output names to expressions or callables")
        self.parameters = [parse_parameter(k, v) for k, v in parameters.items()]
        self.design = make_design(self.parameters, sampling, samples, seed)
        for out_name, spec in outputs.items():
            if out_name in RESERVED or out_name in parameters:
                raise ModelError(f"study output '{out_name}'", "name", "is a parameter or a reserved column name "
                                 f"({', '.join(RESERVED)})")
            compile_output(out_name, spec)
        settings = dict(set or {})
        self.plan = Plan(base, factory, source, validate_analysis(analysis if analysis is not None else {}),
                         dict(outputs), settings)
        self.name = name or (source if factory is None else "study")
        from .units import study_units
        self.units = study_units(parameters, outputs, model_file=factory is None)   # column -> SI unit
        self.chunk_size = chunk_size
        self._check_names(parameters, settings)

    def _check_names(self, parameters, settings):
        if self.plan.factory is not None:
            if settings:
                raise ModelError("study", "set", "a factory model takes its parameters as arguments; 'set' is for "
                                 "model files")
            try:
                sig = inspect.signature(self.plan.factory)
            except (TypeError, ValueError):
                return
            for name in parameters:
                try:
                    sig.bind_partial(**{name: None})
                except TypeError:
                    raise ModelError(f"study parameter '{name}'", "name",
                                     f"is not an argument of {self.plan.source}{sig}") from None
            return
        text = json.dumps(settings)
        first = self.design.iloc[0].to_dict()
        probe = copy.deepcopy(self.plan.base)
        for name in parameters:
            if is_path(name):
                apply_path(probe, name, first[name], self.plan.source)
                _check_schema(probe, self.plan.source, f"study parameter '{name}'")
                _check_units(self.plan.base, name, parameters[name], self.plan.source)
            elif not re.search(r"\{[^{}]*\b" + re.escape(name) + r"\b[^{}]*\}", text):
                raise ModelError(f"study parameter '{name}'", "name", "is neither a path into the model "
                                 "(section.item.field) nor used in a 'set' template ({" + name + "})")
        for path, template in settings.items():
            apply_path(probe, path, fill_template(template, first, path), self.plan.source)
            _check_schema(probe, self.plan.source, f"study set '{path}'")

    def __repr__(self):
        names = ", ".join(p.name for p in self.parameters)
        return f"Study({self.name!r}, {len(self.design)} variants; parameters: {names}; outputs: {', '.join(self.plan.outputs)})"

    def __len__(self):
        return len(self.design)

    def variants(self) -> pd.DataFrame:
        """The design: one row per run (index 'run'), one column per parameter, SI values."""
        return self.design.copy()

    @property
    def study_id(self) -> str:
        """A fingerprint of the model, analysis, outputs and design: rows in an output file must match it."""
        blob = json.dumps({"model": self.plan.base if self.plan.factory is None else _identity(self.plan.factory),
                           "set": self.plan.settings, "analysis": self.plan.analysis,
                           "outputs": {k: _identity(v) for k, v in self.plan.outputs.items()},
                           "design": self.design.to_json(orient="split", double_precision=15)},
                          sort_keys=True, default=str)
        return hashlib.sha1(blob.encode()).hexdigest()[:16]

    def run(self, client=None, workers: int | None = None, out=None, *, chunk_size: int | None = None,
            progress: bool | None = None) -> pd.DataFrame:
        """Run every variant; returns a DataFrame, one row per run: parameters (SI), outputs, status ('ok',
        'failed' when the analysis stopped early, 'error' when it raised, 'lost' when Dask gave up on its
        task), message, wall_time [s] and worker.

        client: a dask.distributed Client or a scheduler address ('tcp://host:8786'); None starts a
        LocalCluster of `workers` processes (default 2) for this run.  workers=0 runs in this process
        without Dask.  out: a Parquet file for the rows: each row is appended to its journal
        ('.NAME.journal' beside it) as it arrives, the file is rewritten every few seconds and at the end;
        when the file (or a journal left by a killed run) already holds rows of this study, those runs are
        skipped (a killed study resumes, losing no finished run).  progress: a progress bar
        on stderr (default: when stderr is a terminal).  df.attrs['executed'] counts the runs done now."""
        from .runner import execute
        return execute(self, client=client, workers=workers, out=out,
                       chunk_size=chunk_size or self.chunk_size, progress=progress)

    def sensitivity(self, df: pd.DataFrame, method: str = "src") -> pd.DataFrame:
        """Sensitivity table of this study's outputs to its numeric parameters (see mbdsim.studies.sensitivity)."""
        from .sensitivity import sensitivity
        return sensitivity(df, [p.name for p in self.parameters], list(self.plan.outputs), method=method)
