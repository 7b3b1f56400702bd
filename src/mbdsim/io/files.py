"""Reading and writing model files: YAML (safe loader only, no tags) and JSON, chosen by extension.

YAML is composed into a node tree first: every key's line is recorded (for error messages), any tag
other than the plain YAML types (``!!python/object``, ``!custom``...), duplicate keys, nesting deeper
than MAX_DEPTH levels and integers of more than MAX_DIGITS digits are refused, and only then is the
tree turned into plain data by the safe constructor.  Nothing in a model file can run code.  JSON is
held to the same rules: duplicate keys, deep nesting and huge integers are refused (naming the file,
and the line where it can be found), never taken silently (last key wins) or left to a bare
RecursionError or ValueError.

Only a regular file of at most MAX_BYTES (20 MB; model files are kilobytes) is read: a FIFO, a device
(a link to /dev/zero), a directory or a larger file is refused before reading, naming the file (opened
non-blocking and checked on the open descriptor, so a FIFO never blocks and a file swapped after the
check is still caught; at most MAX_BYTES + 1 bytes are ever read).
"""
from __future__ import annotations

import json
import os
import stat
from pathlib import Path

from ..errors import ModelFileError

MAX_BYTES = 20 * 2**20   # largest model or study file read
PLAIN_TAGS = {f"tag:yaml.org,2002:{t}" for t in ("str", "int", "float", "bool", "null", "map", "seq")}
YAML_SUFFIXES, JSON_SUFFIXES = (".yaml", ".yml"), (".json",)


def file_kind(path: Path, entity: str = "file") -> str:
    """'yaml' or 'json' from the extension, else ModelFileError."""
    suffix = path.suffix.lower()
    if suffix in YAML_SUFFIXES:
        return "yaml"
    if suffix in JSON_SUFFIXES:
        return "json"
    raise ModelFileError(entity, "path", f"unknown model file extension {suffix!r}; use .yaml, .yml or .json "
                         "(or import .urdf, .xml/.mjcf, .adm: mb.from_urdf, mb.from_mjcf, mb.from_adm)", str(path))


def _item_name(node) -> str | None:
    """The `name: ...` of a mapping node, if it has a plain one."""
    import yaml
    for key, value in node.value if isinstance(node, yaml.MappingNode) else ():
        if getattr(key, "value", None) == "name" and isinstance(getattr(value, "value", None), str):
            return value.value
    return None


MAX_NODES = 200_000   # YAML aliases re-use nodes: a "billion laughs" file expands past any budget
MAX_DEPTH = 64        # nesting levels of lists and mappings (a model file has about 6)
MAX_DIGITS = 400      # digits of an integer (a float holds at most 309): Python refuses past 4300
INT_TAG = "tag:yaml.org,2002:int"


def _walk(node, path, marks, source, entity="model", budget=None):
    """Record the line of every key/item under `node` and refuse tags, duplicate keys and alias bombs."""
    import yaml

    from .diagnose import SECTION_ENTITY, field_text
    budget = [MAX_NODES] if budget is None else budget
    budget[0] -= 1
    if budget[0] < 0:
        raise ModelFileError("file", "(size)", f"more than {MAX_NODES} values once aliases are expanded",
                             source, node.start_mark.line + 1)
    if len(path) == 2 and isinstance(path[1], int):
        name = _item_name(node)
        entity = f"{SECTION_ENTITY.get(path[0], 'element')} " + (repr(name) if name else f"#{path[1] + 1}")
    field = (lambda: field_text(path[2:] if len(path) > 2 else path) if entity != "model" or path
             else "(top level)")
    if len(path) > MAX_DEPTH:
        raise ModelFileError(entity, field(), f"data nested deeper than {MAX_DEPTH} levels", source,
                             node.start_mark.line + 1)
    if node.tag == INT_TAG and len(node.value.lstrip("+-")) > MAX_DIGITS:
        raise ModelFileError(entity, field(), f"an integer of {len(node.value.lstrip('+-'))} digits, larger than any number a "
                             "model holds", source, node.start_mark.line + 1)
    if node.tag not in PLAIN_TAGS:
        raise ModelFileError(entity, field(), f"YAML tag {node.tag!r} is not allowed in a model file "
                             "(plain data only, nothing is constructed or run)", source, node.start_mark.line + 1)
    if isinstance(node, yaml.MappingNode):
        seen = set()
        for key, value in node.value:
            if not isinstance(key, yaml.ScalarNode):
                raise ModelFileError("file", "/".join(map(str, path)) or "(top level)", "keys must be plain names",
                                     source, key.start_mark.line + 1)
            if key.value in seen:
                raise ModelFileError("file", key.value, f"duplicate key {key.value!r}", source,
                                     key.start_mark.line + 1)
            seen.add(key.value)
            sub = path + (key.value,)
            marks[sub] = key.start_mark.line + 1
            _walk(key, sub, {}, source, entity, budget)
            _walk(value, sub, marks, source, entity, budget)
    elif isinstance(node, yaml.SequenceNode):
        for k, item in enumerate(node.value):
            marks[path + (k,)] = item.start_mark.line + 1
            _walk(item, path + (k,), marks, source, entity, budget)


def parse_yaml(text: str, source: str):
    """(data, marks) from YAML text: marks maps a key path ('joints', 2, 'body_i') to its line."""
    import yaml
    loader = yaml.SafeLoader(text)
    try:
        node = loader.get_single_node()
        marks: dict = {}
        if node is None:
            raise ModelFileError("file", "(top level)", "the file is empty", source)
        _walk(node, (), marks, source)
        data = loader.construct_document(node)
    except RecursionError:
        raise ModelFileError("file", "(nesting)", f"data nested deeper than {MAX_DEPTH} levels", source) from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        problem = getattr(exc, "problem", None) or str(exc)
        raise ModelFileError("file", "(syntax)", f"YAML syntax error: {problem}", source,
                             None if mark is None else mark.line + 1) from None
    finally:
        loader.dispose()
    return data, marks


class _Refused(Exception):
    """A JSON document breaks a rule of _walk (duplicate key, huge integer): args = (field, message)."""


def _json_object(pairs):
    out = {}
    for key, value in pairs:
        if key in out:
            raise _Refused(key, f"duplicate key {key!r}")
        out[key] = value
    return out


def _json_int(text):
    if len(text.lstrip("-")) > MAX_DIGITS:
        raise _Refused("(number)", f"an integer of {len(text.lstrip('-'))} digits, larger than any number a "
                       "model holds")
    return int(text)


def _depth(data) -> int:
    """Nesting depth of lists and dicts in `data` (iterative: no recursion limit)."""
    deepest, stack = 0, [(data, 0)]
    while stack:
        node, d = stack.pop()
        deepest = max(deepest, d)
        if isinstance(node, (list, dict)) and d <= MAX_DEPTH:
            stack.extend((x, d + 1) for x in (node.values() if isinstance(node, dict) else node))
    return deepest


def parse_json(text: str, source: str):
    """(data, marks) from JSON text; line marks come from reading the same text as YAML where it can (and
    so do the line, entity and field of a duplicate key or a huge integer)."""
    try:
        data = json.loads(text, object_pairs_hook=_json_object, parse_int=_json_int)
    except json.JSONDecodeError as exc:
        raise ModelFileError("file", "(syntax)", f"JSON syntax error: {exc.msg}", source, exc.lineno) from None
    except RecursionError:
        raise ModelFileError("file", "(nesting)", f"data nested deeper than {MAX_DEPTH} levels", source) from None
    except _Refused as exc:
        try:
            parse_yaml(text, source)
        except ModelFileError as precise:
            if exc.args[1] in str(precise) or exc.args[0] == "(number)" and "digits" in str(precise):
                raise precise from None
        raise ModelFileError("file", *exc.args, source) from None
    if _depth(data) > MAX_DEPTH:
        raise ModelFileError("file", "(nesting)", f"data nested deeper than {MAX_DEPTH} levels", source)
    try:
        _, marks = parse_yaml(text, source)
    except ModelFileError:
        marks = {}
    return data, marks


def read(path) -> tuple:
    """(data, marks, source) of a model file; source is the file name used in messages."""
    path = Path(path)
    kind = file_kind(path)
    source = path.name
    try:
        text = read_bytes(path).decode("utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ModelFileError("file", "path", f"cannot read {str(path)!r}: {exc}", source) from None
    data, marks = (parse_yaml if kind == "yaml" else parse_json)(text, source)
    return data, marks, source


def read_bytes(path: Path, limit: int | None = None) -> bytes:
    """The bytes of the regular file `path` (at most `limit`, default MAX_BYTES), else ModelFileError
    naming it: missing, not a regular file (FIFO, device, directory) or larger than the limit. OSError
    for other failures to read."""
    limit = MAX_BYTES if limit is None else limit
    source = path.name
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))   # a FIFO opens without a writer
    except FileNotFoundError:
        raise ModelFileError("file", "path", f"cannot read {str(path)!r}: it does not exist", source) from None
    except IsADirectoryError:
        raise ModelFileError("file", "path", f"cannot read {str(path)!r}: it is a directory, not a regular file",
                             source) from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            what = "a directory" if stat.S_ISDIR(st.st_mode) else "a FIFO" if stat.S_ISFIFO(st.st_mode) else \
                "a device" if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode) else "a special file"
            raise ModelFileError("file", "path", f"cannot read {str(path)!r}: it is {what}, not a regular file",
                                 source)
        if st.st_size > limit:
            raise ModelFileError("file", "path", f"cannot read {str(path)!r}: it has {st.st_size / 2**20:.1f} MB, "
                                 f"more than the {limit / 2**20:g} MB a model file may have", source)
    except BaseException:
        os.close(fd)
        raise
    with os.fdopen(fd, "rb") as fh:
        data = fh.read(limit + 1)
    if len(data) > limit:   # (grown since the check)
        raise ModelFileError("file", "path", f"cannot read {str(path)!r}: it is larger than the "
                             f"{limit / 2**20:g} MB a model file may have", source)
    return data


def write(data: dict, path) -> Path:
    """Write model data as YAML or JSON (by extension); returns the path."""
    path = Path(path)
    if _depth(data) > MAX_DEPTH:   # (what load_model would refuse; the dumpers would hit RecursionError)
        raise ModelFileError("file", "(nesting)", f"data nested deeper than {MAX_DEPTH} levels", path.name)
    if file_kind(path) == "json":
        text = json.dumps(data, indent=2, allow_nan=False) + "\n"
    else:
        import yaml
        text = yaml.safe_dump(data, sort_keys=False, default_flow_style=None, width=110, allow_unicode=True)
    path.write_text(text, encoding="utf-8")
    return path
