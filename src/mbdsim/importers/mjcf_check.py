"""MJCF pre-checks: the file (and every <include>) read with the hardened parser, then what mbdsim cannot
represent refused with the file, line and element before MuJoCo's compiler sees the file.

MuJoCo's own parser (tinyxml2) reads no DTD and expands no entity; the hardened pass additionally refuses
them outright, bounds the size and gives mbdsim's errors (ModelFileError with the line).
"""
from __future__ import annotations

from pathlib import Path

from ..errors import ModelFileError
from ._xml import XmlDoc, read_xml

# elements refused wherever they appear: no rigid-body equivalent in mbdsim
REFUSED = {"tendon": "tendons", "flex": "deformable flexes", "flexcomp": "deformable flexes",
           "composite": "composite bodies", "plugin": "engine plugins", "extension": "engine plugins",
           "replicate": "replicated bodies", "attach": "attached sub-models"}
ACTUATORS_OK = {"motor"}
EQUALITY_OK = {"joint", "connect", "weld"}
NOTED = {"sensor": "sensors are not imported (use Result measures)",
         "contact": "<contact> pairs and exclusions are not imported (geoms are drawn, not in contact)",
         "keyframe": None, "visual": None, "statistic": None, "asset": None, "default": None,
         "option": "<option> (timestep, integrator, solver settings) is not imported: mbdsim chooses its own",
         "size": None, "compiler": None, "custom": None, "worldbody": None, "actuator": None,
         "equality": None, "include": None, "deformable": "deformables are not imported"}


def check_file(path, max_depth: int = 8) -> tuple[XmlDoc, dict, list]:
    """(main document, {(tag, name): (file, line)} over the file and its includes, notes); refuses what
    mbdsim cannot represent (ModelFileError naming file, line and element)."""
    notes: list = []
    index: dict = {}
    doc = read_xml(path, "MJCF file")
    if doc.root.tag != "mujoco":
        raise doc.error(doc.root, "file", "(root)", f"an MJCF file's root element is <mujoco>, got <{doc.root.tag}>")
    _walk(doc, doc.root, index, notes, Path(doc.source).resolve().parent, max_depth, set())
    return doc, index, notes


def _walk(doc, el, index, notes, base, depth, seen_notes) -> None:
    for child in el:
        tag = child.tag
        if not isinstance(tag, str):
            continue
        name = child.get("name")
        if name is not None:
            index.setdefault((tag, name), (doc.source, doc.line(child)))
        if tag in REFUSED:
            raise doc.error(child, f"<{tag}> {name or ''}".strip(), "(element)",
                            f"{REFUSED[tag]} are not supported by mbdsim's import")
        if el.tag == "actuator" and tag not in ACTUATORS_OK and tag != "default":
            raise doc.error(child, f"actuator {name or tag!r}", "type", f"<{tag}> actuators are not supported "
                            f"(only {', '.join(sorted(ACTUATORS_OK))}: a joint force of gear * ctrl)")
        if el.tag == "equality" and tag not in EQUALITY_OK:
            raise doc.error(child, f"equality {name or tag!r}", "type", f"<{tag}> equalities are not supported "
                            f"(only {', '.join(sorted(EQUALITY_OK))})")
        if tag == "include":
            _include(doc, child, index, notes, base, depth, seen_notes)
            continue
        note = NOTED.get(tag)
        if note and el.tag == "mujoco" and tag not in seen_notes:
            seen_notes.add(tag)
            notes.append(f"{note} (line {doc.line(child)})")
        _walk(doc, child, index, notes, base, depth, seen_notes)


def _include(doc, el, index, notes, base, depth, seen_notes) -> None:
    ref = el.get("file")
    if not ref:
        raise doc.error(el, "include", "file", "<include> needs a file attribute")
    if depth <= 0:
        raise doc.error(el, "include", "file", "includes nested too deep")
    p = Path(ref) if Path(ref).is_absolute() else base / ref
    if not p.is_file():
        raise doc.error(el, "include", "file", f"included file {ref!r} not found")
    sub = read_xml(p, "MJCF include")
    _walk(sub, sub.root, index, notes, p.resolve().parent, depth - 1, seen_notes)


def compile_error(exc: Exception, source: str, index: dict) -> ModelFileError:
    """MuJoCo's compiler message as a ModelFileError with the file and line it names."""
    import re
    text = str(exc).strip()
    m = re.search(r"line (\d+)", text)
    line = int(m.group(1)) if m else None
    first = text.replace("\n", " ").replace("XML Error: ", "").replace("Error: ", "")
    return ModelFileError("MJCF file", "(compile)", f"MuJoCo's compiler refused it: {first}", source, line)
