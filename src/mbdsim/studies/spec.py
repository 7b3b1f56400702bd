"""Study files (YAML or JSON) and the analysis options, validated with the model-file schema machinery
(pydantic v2, unknown keys forbidden, quantities with units, errors naming file, line and field).

    name: slider_crank_study
    model: slider_crank.yaml               # relative to the study file
    analysis: {type: dynamics, end_time: 2 s, output_step: 10 ms, rtol: 1.0e-6}
    sampling: {method: sobol, samples: 128, seed: 1}
    parameters:
      crank: {range: [150 mm, 250 mm]}     # a name: used in `set` templates
      bodies.rod.mass: {range: [1 kg, 3 kg]}   # a path into the model file
    set:
      joints.crank_rod.point: ["{crank}", 0, 0]
    outputs:
      peak_rod_force: "max(norm(reaction_force('crank_rod')))"
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Literal, Optional, Union

from pydantic import Field, PositiveFloat, ValidationError, field_validator, model_validator

from ..errors import ModelFileError
from ..io.schema import Q, Spec

__all__ = ["AnalysisSpec", "SamplingSpec", "StudySpec", "validate_analysis", "load_study"]


class AnalysisSpec(Spec):
    """The analysis every variant runs: dynamics (mb.simulate), kinematics, statics (mb.equilibrium) or
    quasi_static; times in s (or strings with units). time_limit: wall time [s] a variant may take
    (None: no limit); a variant over it becomes a 'failed' row (mbdsim.studies.deadline)."""

    type: Literal["dynamics", "kinematics", "statics", "quasi_static"] = "dynamics"
    end_time: Optional[Q("s")] = None
    output_step: Optional[Q("s")] = None
    method: Optional[str] = None
    rtol: Optional[PositiveFloat] = None
    atol: Optional[PositiveFloat] = None
    max_step: Optional[Q("s")] = None
    time_limit: Optional[Q("s")] = None

    @model_validator(mode="after")
    def _times(self):
        if self.type != "statics" and (self.end_time is None or not self.end_time > 0):
            raise ValueError(f"a {self.type} analysis needs a positive end_time")
        return self

    @field_validator("time_limit")
    @classmethod
    def _positive_limit(cls, v):
        if v is not None and not v > 0:
            raise ValueError(f"the wall time a variant may take must be positive, got {v!r} s")
        return v


class SamplingSpec(Spec):
    """How the parameter space is sampled: grid (full factorial), lhs, sobol or random (Monte Carlo)."""

    method: Literal["grid", "lhs", "sobol", "random"] = "grid"
    samples: Optional[int] = Field(default=None, ge=1)
    seed: int = 0


class ParameterEntry(Spec):
    """A study parameter: values, a range (with num for a grid) or a distribution; unit for bare numbers."""

    values: Optional[list[Union[float, str]]] = Field(default=None, min_length=1)
    range: Optional[list[Union[float, str]]] = Field(default=None, min_length=2, max_length=2)
    num: Optional[int] = Field(default=None, ge=1)
    distribution: Optional[Literal["normal", "uniform", "lognormal"]] = None
    mean: Union[float, str, None] = None
    std: Union[float, str, None] = None
    low: Union[float, str, None] = None
    high: Union[float, str, None] = None
    median: Union[float, str, None] = None
    sigma: Union[float, str, None] = None
    unit: Optional[str] = None

    def as_dict(self) -> dict:
        return self.model_dump(exclude_none=True)


class StudySpec(Spec):
    """A study file: a model file, the parameters, the outputs and the analysis."""

    name: str = "study"
    model: str
    analysis: AnalysisSpec
    sampling: SamplingSpec = SamplingSpec()
    parameters: dict[str, Union[ParameterEntry, list[Union[float, str]], float, str]] = Field(min_length=1)
    set: dict[str, Any] = {}
    outputs: dict[str, str] = Field(min_length=1)
    chunk_size: Optional[int] = Field(default=None, ge=1)


def validate_analysis(analysis) -> dict:
    """The analysis options as a plain dict (SI floats); raises ModelError naming the field."""
    from ..errors import ModelError
    if isinstance(analysis, AnalysisSpec):
        return analysis.model_dump()
    if not isinstance(analysis, dict):
        raise ModelError("study", "analysis", f"expected a mapping such as {{'end_time': 2.0}}, got {analysis!r}")
    try:
        return AnalysisSpec.model_validate(analysis).model_dump()
    except ValidationError as exc:
        err = exc.errors()[0]
        field = ".".join(str(p) for p in err["loc"]) or "(options)"
        raise ModelError("study analysis", field, err["msg"].removeprefix("Value error, ")) from None


def _file_error(exc: ValidationError, source: str, marks: dict) -> ModelFileError:
    from ..io.diagnose import field_text, line_of
    err = exc.errors()[0]
    path = tuple(p for p in err["loc"] if not (isinstance(p, str) and p in (
        "ParameterEntry", "list[union[float,str]]", "float", "str", "union[float,str]")))
    msg = err["msg"].removeprefix("Value error, ")
    if err["type"] == "extra_forbidden":
        msg = f"unknown field {path[-1]!r}"
        if len(path) == 1:
            msg += f"; valid fields: {', '.join(StudySpec.model_fields)}"
    return ModelFileError("study", field_text(path), msg, source, line_of(marks, path))


def load_study(path):
    """A Study from a study file (.yaml/.yml/.json); the model path is relative to the file.

    Raises ModelFileError naming the file, line and field for a bad study file or model file."""
    from ..io.files import read
    from .study import Study
    path = Path(path)
    data, marks, source = read(path)
    if not isinstance(data, dict):
        raise ModelFileError("study", "(top level)", "a study is a mapping (model, parameters, outputs, analysis)",
                             source, 1)
    try:
        spec = StudySpec.model_validate(data)
    except ValidationError as exc:
        raise _file_error(exc, source, marks) from None
    model_path = (path.parent / spec.model) if not Path(spec.model).is_absolute() else Path(spec.model)
    if not model_path.is_file():
        raise ModelFileError("study", "model", f"model file {spec.model!r} not found (looked at {str(model_path)!r})",
                             source, line_of_key(marks, "model"))
    params = {k: (v.as_dict() if isinstance(v, ParameterEntry) else v) for k, v in spec.parameters.items()}
    try:
        return Study(model_path, params, spec.outputs, analysis=spec.analysis.model_dump(),
                     sampling=spec.sampling.method, samples=spec.sampling.samples, seed=spec.sampling.seed,
                     set=spec.set, chunk_size=spec.chunk_size, name=spec.name)
    except ModelFileError:
        raise
    except Exception as exc:  # a ModelError from the study's checks: name the file and line
        entity, field = getattr(exc, "entity", "study"), getattr(exc, "field", "(file)")
        key = entity.split("'")[1] if "'" in entity else None
        section = "outputs" if "output" in entity else ("set" if "set" in entity else "parameters")
        line = line_of_key(marks, section, key)
        message = getattr(exc, "args", [str(exc)])[0]
        raise ModelFileError(entity, field, str(message).split(": ", 1)[-1], source, line) from None


def line_of_key(marks: dict, *keys) -> int | None:
    """Line of the deepest of `keys` recorded in the YAML marks (None when unknown)."""
    from ..io.diagnose import line_of
    return line_of(marks, tuple(k for k in keys if k is not None))
