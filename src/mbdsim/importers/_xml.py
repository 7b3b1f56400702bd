"""Hardened XML reading for the importers: no DTD entities, no external references, line numbers kept.

`read_xml(path)` parses a file with defusedxml's expat parser (entity declarations, external entities
and external DTDs are refused: nothing in a file can make the reader fetch or expand anything) and
returns an `XmlDoc` whose `line(element)` gives the line an element starts on.  Every failure is a
mbdsim.errors.ModelFileError naming the file and the line.  Only a regular file of at most
MAX_BYTES is read (the checks of mbdsim.io.files: no FIFO, device or directory).
"""
from __future__ import annotations

import os
import stat
from dataclasses import dataclass, field
from pathlib import Path
from xml.etree import ElementTree as ET

from ..errors import ModelFileError

MAX_BYTES = 50 * 2**20   # robot descriptions are kilobytes to a few megabytes
MAX_ELEMENTS = 500_000


@dataclass
class XmlDoc:
    """A parsed XML file: `root` element, `source` (the path as text) and each element's start line."""

    root: ET.Element
    source: str
    lines: dict = field(default_factory=dict)

    def line(self, element) -> int | None:
        """The line [1-based] where `element` starts, None when unknown."""
        return self.lines.get(element)

    def error(self, element, entity: str, fld: str, message: str) -> ModelFileError:
        """A ModelFileError naming this file and the element's line."""
        return ModelFileError(entity, fld, message, self.source, None if element is None else self.line(element))


def read_bytes(path, what: str = "file") -> tuple[bytes, str]:
    """(content, source) of a regular file of at most MAX_BYTES; ModelFileError otherwise."""
    source = str(path)
    try:
        fd = os.open(source, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise ModelFileError(what, "path", f"cannot open: {exc.strerror or exc}", source) from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise ModelFileError(what, "path", "is not a regular file", source)
        if st.st_size > MAX_BYTES:
            raise ModelFileError(what, "path", f"is {st.st_size} bytes, more than the {MAX_BYTES} read", source)
        with os.fdopen(fd, "rb", closefd=False) as fh:
            data = fh.read(MAX_BYTES + 1)
    finally:
        os.close(fd)
    if len(data) > MAX_BYTES:
        raise ModelFileError(what, "path", f"is larger than the {MAX_BYTES} bytes read", source)
    return data, source


def read_xml(path, what: str = "file") -> XmlDoc:
    """Parse an XML file (hardened, see the module docstring); ModelFileError naming file and line."""
    data, source = read_bytes(path, what)
    return parse_xml(data, source)


def parse_xml(data: bytes, source: str) -> XmlDoc:
    """Parse XML bytes with the hardened parser, recording each element's line."""
    try:
        from defusedxml import DefusedXmlException
        from defusedxml.ElementTree import DefusedXMLParser
    except ImportError:   # pragma: no cover - a dependency of mbdsim
        raise ModelFileError("file", "(reader)", "reading XML needs the package defusedxml "
                             "(pip install defusedxml)", source) from None
    lines: dict = {}

    class _Builder(ET.TreeBuilder):
        def start(self, tag, attrs):
            el = super().start(tag, attrs)
            lines[el] = parser.parser.CurrentLineNumber
            if len(lines) > MAX_ELEMENTS:
                raise ModelFileError("file", "(size)", f"more than {MAX_ELEMENTS} XML elements", source,
                                     parser.parser.CurrentLineNumber)
            return el

    parser = DefusedXMLParser(target=_Builder(), forbid_dtd=False, forbid_entities=True, forbid_external=True)
    try:
        parser.feed(data)
        root = parser.close()
    except ModelFileError:
        raise
    except DefusedXmlException as exc:
        line = _line(parser)
        raise ModelFileError("file", "(xml)", f"refused: {_defused_text(exc)} (entity declarations and "
                             "external references are not read)", source, line) from None
    except ET.ParseError as exc:
        line = getattr(exc, "position", (None,))[0]
        msg = str(exc).split(": line", 1)[0]
        raise ModelFileError("file", "(xml)", f"not well-formed XML: {msg}", source, line) from None
    except (ValueError, RecursionError) as exc:
        raise ModelFileError("file", "(xml)", f"cannot be read: {exc}", source, _line(parser)) from None
    return XmlDoc(root, source, lines)


def _line(parser) -> int | None:
    try:
        return int(parser.parser.CurrentLineNumber)
    except Exception:   # noqa: BLE001 - the expat parser may be gone after a failure
        return None


def _defused_text(exc) -> str:
    kind = type(exc).__name__
    if kind == "EntitiesForbidden":
        return f"an entity declaration ({getattr(exc, 'name', '?')!r})"
    if kind == "ExternalReferenceForbidden":
        return f"an external reference ({getattr(exc, 'sysid', None) or getattr(exc, 'pubid', '?')!r})"
    if kind == "DTDForbidden":
        return "a document type definition"
    return str(exc)


def floats(doc: XmlDoc, el, attr: str, n: int | None, default=None, entity: str = "element"):
    """The whitespace-separated numbers of attribute `attr` of `el` (n of them when n is given) as a
    list of floats; `default` when absent; ModelFileError naming the element's line otherwise."""
    import math
    text = el.get(attr)
    if text is None:
        return default
    try:
        vals = [float(x) for x in text.split()]
    except ValueError:
        raise doc.error(el, entity, attr, f"expected numbers, got {text!r}") from None
    if n is not None and len(vals) != n:
        raise doc.error(el, entity, attr, f"expected {n} numbers, got {len(vals)} ({text!r})")
    if not all(math.isfinite(v) for v in vals):
        raise doc.error(el, entity, attr, f"numbers must be finite, got {text!r}")
    return vals


def resolve_file(ref: str, base: Path, package_dirs=()) -> Path | None:
    """A file named by `ref` (package://pkg/rel, file:///abs, an absolute or a relative path, relative to
    `base`), looked up in `package_dirs`, $ROS_PACKAGE_PATH and the folders above `base` for
    package://; None when it is not found."""
    if ref.startswith("file://"):
        p = Path(ref[len("file://"):])
        return p if p.is_file() else None
    if ref.startswith("package://"):
        rest = ref[len("package://"):]
        pkg, _, rel = rest.partition("/")
        roots = [Path(d) for d in package_dirs]
        roots += [Path(d) for d in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if d]
        roots += [base, *base.parents]
        for root in roots:
            for cand in (root / pkg / rel, root / rel if root.name == pkg else None):
                if cand is not None and cand.is_file():
                    return cand
        return None
    p = Path(ref)
    p = p if p.is_absolute() else base / p
    return p if p.is_file() else None
