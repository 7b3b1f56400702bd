"""The model-file reference, generated from the schema (mbdsim.io.schema): for every section and element
type a table of its fields (type, SI unit, default, required) and a short example, plus the raw JSON
Schema as a separate file.

    python3 -m mbdsim.io.reference [DOCS_DIR]     # writes DOCS_DIR/model-file-reference.md and
                                                  # DOCS_DIR/model-file-schema.json (default: docs)

Units are those of a bare number (SI); any quantity may also be a string with units ("500 mm").
"""
from __future__ import annotations

import json
import sys
import types
import typing
from pathlib import Path

from pydantic import BaseModel

from .schema import ModelSpec, UnitMark, json_schema

__all__ = ["reference_markdown", "schema_text", "write_reference", "REFERENCE", "SCHEMA_FILE"]

REFERENCE, SCHEMA_FILE = "model-file-reference.md", "model-file-schema.json"
_BASIC = {str: "string", float: "number", int: "integer", bool: "boolean", type(None): "null", typing.Any: "any"}
# units of fields whose unit depends on the joint or element (converted by mbdsim.io.build)
_RAW_NOTE = "raw"


def _lengths(metadata) -> str:
    lo = next((m.min_length for m in metadata if getattr(m, "min_length", None) is not None), None)
    hi = next((m.max_length for m in metadata if getattr(m, "max_length", None) is not None), None)
    if lo is not None and lo == hi:
        return f"{lo} "
    if lo is not None and hi is not None:
        return f"{lo}..{hi} "
    return f"{lo} or more " if lo else ""


def _flat(metadata) -> list:
    """Annotated metadata with pydantic's Field(...) expanded into its constraints (MinLen, MaxLen)."""
    from pydantic.fields import FieldInfo
    return [x for m in metadata for x in (m.metadata if isinstance(m, FieldInfo) else [m])]


def _anchor(cls) -> str:
    return cls.__name__.lower()


def _describe(ann, metadata=(), units=None, classes=None) -> str:
    """Markdown text of a type; collects units (SI strings, "" pure number) and nested Spec classes."""
    units = units if units is not None else []
    origin, args = typing.get_origin(ann), typing.get_args(ann)
    if origin is typing.Annotated:
        meta = _flat(ann.__metadata__)
        marks = [m for m in meta if isinstance(m, UnitMark)]
        if marks:
            units.append(str(marks[0]))
            return "quantity"
        if args[0] == typing.Union[float, str] and any("BeforeValidator" in type(m).__name__ for m in meta):
            units.append(_RAW_NOTE)
            return "quantity"
        return _describe(args[0], meta, units, classes)
    marks = [m for m in metadata if isinstance(m, UnitMark)]
    if marks:
        units.append(str(marks[0]))
        return "quantity"
    if origin is typing.Union or origin is types.UnionType:
        parts = [_describe(a, (), units, classes) for a in args if a is not type(None)]
        return " or ".join(dict.fromkeys(parts))
    if origin is list:
        return f"list of {_lengths(metadata)}{_describe(args[0], (), units, classes)}"
    if origin is dict:
        return f"mapping of {_describe(args[0], (), units, classes)} to {_describe(args[1], (), units, classes)}"
    if origin is typing.Literal:
        return " or ".join(f'`"{a}"`' if isinstance(a, str) else f"`{a}`" for a in args)
    if isinstance(ann, type) and issubclass(ann, BaseModel):
        if classes is not None and ann not in classes:
            classes.append(ann)
        return f"[{ann.__name__}](#{_anchor(ann)})"
    return _BASIC.get(ann, getattr(ann, "__name__", str(ann)))


def _unit_text(units) -> str:
    found = [u for u in dict.fromkeys(units)]
    if not found:
        return ""
    return ", ".join("1" if u == "" else u for u in found)


def _default(field) -> str:
    if field.is_required():
        return ""
    value = field.get_default(call_default_factory=True)
    if isinstance(value, BaseModel):
        value = value.model_dump(exclude_defaults=True)
    return f"`{json.dumps(value)}`" if value is not None else "none"


def _doc(cls) -> str:
    doc = cls.__dict__.get("__doc__") or ""
    return " ".join(doc.split("\n\n")[0].split())


def _table(cls, classes) -> list[str]:
    rows = ["| field | type | unit | default | required |", "|---|---|---|---|---|"]
    for name, field in sorted(cls.model_fields.items(), key=lambda kv: kv[0] != "type"):
        units = []
        text = _describe(field.annotation, field.metadata, units, classes)
        rows.append(f"| `{name}` | {text} | {_unit_text(units)} | {_default(field)} | "
                    f"{'yes' if field.is_required() else ''} |")
    return rows


def _members(ann) -> list:
    """The Spec classes of a section's item type (a class or a discriminated union of classes)."""
    origin, args = typing.get_origin(ann), typing.get_args(ann)
    if origin is typing.Annotated:
        return _members(args[0])
    if origin is typing.Union or origin is types.UnionType:
        return [c for a in args for c in _members(a)]
    return [ann] if isinstance(ann, type) and issubclass(ann, BaseModel) else []


def _types_of(cls) -> list[str]:
    field = cls.model_fields.get("type")
    return list(typing.get_args(field.annotation)) if field is not None else []


def _sample(name, ann, metadata=()):
    """A valid-looking value for a required field (examples)."""
    origin, args = typing.get_origin(ann), typing.get_args(ann)
    marks = [m for m in (*metadata, *(ann.__metadata__ if origin is typing.Annotated else ())) if isinstance(m, UnitMark)]
    if marks:
        return f"1 {marks[0]}".replace("**", "^") if str(marks[0]) else 1.0
    if origin is typing.Annotated:
        return _sample(name, args[0], _flat(ann.__metadata__))
    if origin is typing.Literal:
        return args[0]
    if origin is typing.Union or origin is types.UnionType:
        return _sample(name, next(a for a in args if a is not type(None)), metadata)
    if origin is list:
        n = _lengths(metadata).strip()
        item = _sample(name, args[0])
        if n == "3" and not isinstance(item, str):
            return [0.0, 0.0, 1.0]
        return [item] * int(n.split(".")[0].split(" ")[0] or 1)
    if origin is dict:
        return {}
    if isinstance(ann, type) and issubclass(ann, BaseModel):
        return _example(ann)
    if ann is str:
        return {"body_i": "ground", "body_j": "arm", "joint": "pin", "body": "arm", "joint_1": "pin",
                "joint_2": "slide", "expression": "pin - 2*slide"}.get(name, "arm")
    return {float: 1.0, int: 1, bool: True}.get(ann, "1")


def _example(cls, kind=None) -> dict:
    out = {"type": kind} if kind is not None else {}
    if "name" in cls.model_fields:
        out["name"] = f"{kind or cls.__name__.removesuffix('Spec').lower()}_1"
    for name, field in cls.model_fields.items():
        if field.is_required() and name not in out:
            out[name] = _sample(name, field.annotation, field.metadata)
    return out


# hand-written examples where the generated one (required fields, placeholder values) is not valid
_EXAMPLES: dict[str, dict] = {
    "BodySpec": {"name": "arm", "mass": "2 kg", "inertia": [0.01, 0.02, 0.02], "position": ["100 mm", 0, 0],
                 "shapes": [{"name": "geo", "geometry": {"type": "box", "size": ["200 mm", "20 mm", "20 mm"]}},
                            {"name": "tip", "geometry": {"type": "mesh", "path": "meshes/tip.stl", "scale": 0.001},
                             "center": ["200 mm", 0, 0], "density": "2700 kg/m**3"}]},
    "ContactSpec": {"type": "contact", "name": "floor", "shape_i": "ground.floor", "shape_j": ["arm.geo", "arm.tip"],
                    "stiffness": "100 kN/m", "exponent": 1.0, "damping": "20 N*s/m", "penetration": "0.1 mm",
                    "mu_static": 0.3, "mu_dynamic": 0.2, "stiction_velocity": "1 mm/s"},
    "PointOnCurveSpec": {"type": "point_on_curve", "name": "follower", "marker": "arm.tip", "body": "ground",
                         "curve": {"type": "spline", "points": [[0, 0, 0], ["100 mm", "50 mm", 0], ["200 mm", 0, 0]]}},
}


def _example_block(section: str, example: dict) -> list[str]:
    import yaml
    text = yaml.safe_dump({section: [example]}, default_flow_style=None, sort_keys=False, width=100)
    return ["```yaml", text.rstrip(), "```"]


def reference_markdown() -> str:
    """The Markdown reference of every model-file section and element type (deterministic)."""
    classes: list = []
    lines = ["# Model-file reference", "",
             "Generated from the schema (`mbdsim.io.schema`) by `python3 -m mbdsim.io.reference`; do not edit "
             "by hand. A quantity is a number in the SI unit shown or a string with units (`\"500 mm\"`, "
             "`\"60 deg/s\"`); unit `1`: a pure number; `raw`: a number, a string with units or an expression "
             "whose unit depends on the joint or element (rad or m by the joint's coordinate, N for a force), "
             "converted once the joint is known. Points and axes are in ground at t = 0. The raw "
             f"JSON Schema is [{SCHEMA_FILE}]({SCHEMA_FILE}) (also printed by `mbdsim schema`).", "",
             "## Top level", "", _doc(ModelSpec), "", *_table(ModelSpec, classes), ""]
    for section, field in ModelSpec.model_fields.items():
        if typing.get_origin(field.annotation) is not list:
            continue
        members = _members(typing.get_args(field.annotation)[0])
        if not members:
            continue
        lines += [f"## {section}", ""]
        for cls in members:
            kinds = _types_of(cls)
            title = ", ".join(kinds) if kinds else cls.__name__.removesuffix("Spec").lower()
            lines += [f"### {title} {{#{_anchor(cls)}}}", ""]
            if _doc(cls):
                lines += [_doc(cls), ""]
            lines += _table(cls, classes) + [""]
            example = _EXAMPLES.get(cls.__name__) or _example(cls, kinds[0] if kinds else None)
            cls.model_validate(example)        # the example is a valid item (an error here is a bug)
            lines += _example_block(section, example) + [""]
    lines += ["## Nested objects", ""]
    done = {cls for f in ModelSpec.model_fields.values() if typing.get_origin(f.annotation) is list
            for cls in _members(typing.get_args(f.annotation)[0])}
    classes[:] = [c for c in classes if c not in done] + [c for c in classes if c in done]
    while not set(classes) <= done:
        for cls in list(classes):
            if cls in done:
                continue
            done.add(cls)
            lines += [f"### {cls.__name__} {{#{_anchor(cls)}}}", ""]
            if _doc(cls):
                lines += [_doc(cls), ""]
            lines += _table(cls, classes) + [""]
    return "\n".join(lines).rstrip() + "\n"


def schema_text() -> str:
    """The JSON Schema of a model file as written to docs (indented, sorted keys)."""
    return json.dumps(json_schema(), indent=1, sort_keys=True) + "\n"


def write_reference(docs_dir="docs") -> list[Path]:
    """Write the reference page and the JSON Schema into `docs_dir`; returns their paths."""
    docs = Path(docs_dir)
    paths = [docs / REFERENCE, docs / SCHEMA_FILE]
    paths[0].write_text(reference_markdown(), encoding="utf-8")
    paths[1].write_text(schema_text(), encoding="utf-8")
    return paths


if __name__ == "__main__":
    for p in write_reference(sys.argv[1] if len(sys.argv) > 1 else "docs"):
        print(p)
