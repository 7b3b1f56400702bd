"""Turn schema and build errors into one ModelFileError naming the file, line, entity and field."""
from __future__ import annotations

import difflib
import typing

from ..errors import ModelFileError

SECTION_ENTITY = {"bodies": "body", "particles": "particle", "joints": "joint", "motions": "motion"}
# errors from the wrong branch of an undiscriminated union (orientation: matrix / euler / axis-angle)
BRANCH_NOISE = {"list_type", "model_type", "dict_type", "model_attributes_type", "float_type", "string_type",
                "float_parsing"}


def line_of(marks: dict | None, path) -> int | None:
    """Line (1-based) of the longest prefix of `path` recorded in `marks`."""
    if not marks:
        return None
    path = tuple(path)
    for n in range(len(path), -1, -1):
        if path[:n] in marks:
            return marks[path[:n]]
    return None


def entity_of(data, path) -> str:
    """"joint 'pin'" for path ('joints', 3, ...), "model" for top-level fields."""
    if len(path) >= 2 and isinstance(data, dict) and isinstance(path[1], int):
        items = data.get(path[0])
        item = items[path[1]] if isinstance(items, list) and path[1] < len(items) else None
        name = item.get("name") if isinstance(item, dict) else None
        kind = SECTION_ENTITY.get(path[0])
        if kind is None:
            from .build import element_word
            kind = element_word(str(item.get("type", "element"))) if isinstance(item, dict) else "element"
        return f"{kind} {name!r}" if isinstance(name, str) else f"{kind} #{path[1] + 1} of {path[0]}"
    return "model"


def field_text(path) -> str:
    """('markers', 1, 'point', 0) -> 'markers[1].point[0]'."""
    out = ""
    for p in path:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out or "(file)"


def _data_path(data, loc, kind):
    """Drop the union-branch and tag elements pydantic puts in `loc`, keeping the path through `data`."""
    path, cur = [], data
    for k, p in enumerate(loc):
        last = k == len(loc) - 1
        if isinstance(p, int) and isinstance(cur, list) and p < len(cur):
            path.append(p)
            cur = cur[p]
        elif isinstance(cur, dict) and p in cur:
            path.append(p)
            cur = cur[p]
        elif last and kind == "missing":
            path.append(p)
    return tuple(path)


def _pick(errors):
    """The error to report: the first item at fault, preferring a message that is not a union branch's."""
    first = errors[0]
    prefix = tuple(first["loc"][:2])
    same = [e for e in errors if tuple(e["loc"][:2]) == prefix]
    better = [e for e in same if e["type"] not in BRANCH_NOISE] or same
    extra = [e for e in better if e["type"] == "extra_forbidden"]   # a misspelt key also makes one "missing"
    return (extra or better)[0]


def _spec_class(data, path):
    """The schema class of the item at path[:2] (or ModelSpec at top level), for listing valid fields."""
    from . import schema
    if len(path) <= 1:
        return schema.ModelSpec
    section = path[0]
    simple = {"bodies": schema.BodySpec, "particles": schema.ParticleSpec, "motions": schema.MotionSpec}
    if section in simple:
        return simple[section]
    union = {"joints": schema.JointSpec, "forces": schema.ElementSpec}.get(section)
    item = data[section][path[1]]
    for cls in typing.get_args(typing.get_args(union)[0]):
        if item.get("type") in typing.get_args(cls.model_fields["type"].annotation):
            return cls
    return None


def _message(err, data, path, missing=()) -> str:
    kind, msg = err["type"], err["msg"]
    if kind == "extra_forbidden":
        key = path[-1]
        cls = _spec_class(data, path) if len(path) in (1, 3) else None
        valid = list(missing) if cls is None else [f for f in cls.model_fields if f != "type"]
        close = difflib.get_close_matches(str(key), valid, n=1)
        if cls is None:
            return f"unknown field {key!r}" + (f" (did you mean {close[0]!r}?)" if close else "")
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        return f"unknown field {key!r}{hint}; valid fields: {', '.join(valid)}"
    if kind == "missing":
        return "is required"
    if kind in ("too_short", "too_long"):
        ctx = err.get("ctx", {})
        n = ctx.get("min_length") if kind == "too_short" else ctx.get("max_length")
        return f"expected {n} values, got {ctx.get('actual_length')}: {err.get('input')!r}"
    if kind == "union_tag_not_found":
        return "needs a 'type' (see `mbdsim schema` for the kinds of each section)"
    if kind == "union_tag_invalid":
        tag, tags = err["ctx"]["tag"], err["ctx"]["expected_tags"]
        return f"type {tag!r} is not known; types are: {tags.replace(chr(39), '')}"
    return msg.removeprefix("Value error, ")


def from_validation(exc, data, source: str, marks: dict | None) -> ModelFileError:
    """ModelFileError for the first problem of a pydantic ValidationError on model data."""
    errors = exc.errors()
    err = _pick(errors)
    path = _data_path(data, err["loc"], err["type"])
    missing = [e["loc"][-1] for e in errors if e["type"] == "missing" and tuple(e["loc"][:-1]) == tuple(err["loc"][:-1])]
    entity = entity_of(data, path)
    field = field_text(path[2:] if entity != "model" else path)
    if err["type"] in ("union_tag_invalid", "union_tag_not_found"):
        field = "type"
        path = path + ("type",)
    return ModelFileError(entity, field, _message(err, data, path, missing), source, line_of(marks, path))


def from_item_error(exc, source: str, marks: dict | None) -> ModelFileError:
    """ModelFileError for a build error (mbdsim.io.build.ItemError) at its item's path."""
    return ModelFileError(exc.entity, exc.field, exc.message, source, line_of(marks, exc.path))
