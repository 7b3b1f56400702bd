"""Model files (YAML or JSON, one schema): load, save, and the dict forms they go through.

    model = mb.load_model("slider_crank.yaml")     # or .json
    mb.save_model(model, "copy.json")
    data = mbdsim.io.model_to_dict(model)          # plain data, SI numbers and expression strings
    model = mbdsim.io.model_from_dict(data)

Quantities may be strings with units ("500 mm", "60 deg/s", "3 kN/m"; converted to SI with pint and
dimension-checked); a bare number is SI.  Orientations: a 3x3 matrix (body -> ground),
{euler: [a, b, c], sequence: "ZXZ"} (scipy convention: upper case intrinsic, lower case extrinsic) or
{axis: [...], angle: ...}.  Expressions are strings for the whitelist parser `mbdsim.parse`; YAML is
read with the safe loader and tags are refused: a model file never runs code.  Errors are
`mbdsim.errors.ModelFileError` naming the file, the line, the entity and the field.
The JSON Schema: `mbdsim.io.json_schema()` or `mbdsim schema`.
"""
from __future__ import annotations

from pathlib import Path

from ..errors import ModelFileError
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..model.model import Model
    from .._types import PathLike

__all__ = ["load_model", "save_model", "model_from_dict", "model_to_dict", "json_schema", "ModelFileError"]


def model_from_dict(data: dict, source: str = "<dict>", marks: dict | None = None, base_dir: PathLike | None = None):
    """Build a Model from model-file data (the schema of `json_schema()`); SI unless units are given.

    `source` names the origin in error messages, `marks` maps key paths to line numbers (from a file),
    `base_dir` is the folder relative mesh paths start from (default: the working directory).
    Raises ModelFileError naming source, line, entity and field."""
    from pydantic import ValidationError

    from . import diagnose
    from .build import Builder, ItemError
    from .schema import ModelSpec
    if not isinstance(data, dict):
        raise ModelFileError("model", "(top level)", f"a model is a mapping of sections, got {type(data).__name__}",
                             source, 1 if marks is not None else None)
    try:
        spec = ModelSpec.model_validate(data)
    except ValidationError as exc:
        raise diagnose.from_validation(exc, data, source, marks) from None
    try:
        return Builder(spec, None if base_dir is None else str(base_dir)).build()
    except ItemError as exc:
        raise diagnose.from_item_error(exc, source, marks) from None


def model_to_dict(model, base_dir: PathLike | None = None) -> dict:
    """Plain data for `model` in the model-file schema (SI numbers, expression strings); mesh files by
    their path relative to `base_dir` (default: absolute paths).

    Raises ModelError naming the element when something cannot be stored (a Python callable)."""
    from .dump import model_to_dict as dump
    return dump(model, base_dir)


def load_model(path: PathLike) -> Model:
    """Read a model file (.yaml/.yml or .json) and build the Model; errors are ModelFileError."""
    from .files import read
    data, marks, source = read(path)
    return model_from_dict(data, source, marks, Path(path).parent)


def save_model(model: Model, path: PathLike) -> Path:
    """Write `model` to `path` as YAML or JSON (by extension) in SI units; returns the path.

    Raises ModelError naming the element when the model holds a Python callable."""
    from ..errors import ModelError
    from ..model.model import Model as _Model
    from .files import file_kind, write
    if not isinstance(model, _Model):
        raise ModelError("save_model", "model", f"expected an mbdsim.Model, got {type(model).__name__}")
    file_kind(Path(path), f"model '{model.name}'")
    return write(model_to_dict(model, Path(path).parent), path)


def json_schema() -> dict:
    """The JSON Schema of a model file."""
    from .schema import json_schema as schema
    return schema()
