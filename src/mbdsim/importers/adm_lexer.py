"""Statements of an Adams/Solver dataset (.adm): the lexical layer of `mbdsim.importers.adm`.

A dataset is a title line, then statements `NAME/id, ARG=values, FLAG, ...` up to `END`.  A line that
starts with ',' continues the statement above; '!' starts a comment (an Adams View
`adams_view_name='...'` comment names the statement that follows it).  Values of an argument are
separated by commas (`QP = 0, 10, 0`); a number may end in `D` (degrees: `90D`).  Function
expressions (`FUNCTION =`, and `FX =` ... `TZ =` of VFORCE/VTORQUE/GFORCE) run to the end of the
statement or to a backslash, continuation lines included.  Keywords are case-insensitive and may be
abbreviated to any unique prefix, as Adams allows.  Nothing here evaluates anything: the text is only
split.  Errors are ModelFileError naming the file and line.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

from ..errors import ModelFileError

EXPRESSION_KEYS = ("FUNCTION", "FX", "FY", "FZ", "TX", "TY", "TZ")
_VIEW_NAME = re.compile(r"adams_view_name\s*=\s*'([^']*)'", re.IGNORECASE)
_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([ED][+-]?\d+)?D?$", re.IGNORECASE)
_HEAD = re.compile(r"\s*([A-Za-z_]+)\s*(?:/\s*(\d+)?)?\s*(?=,|$|[A-Za-z])")


@dataclass
class Arg:
    """One argument: upper-case `key` (None for a bare flag), its value texts, the source line."""

    key: str | None
    values: list
    line: int


@dataclass
class Statement:
    """One statement: upper-case `name`, integer `id` (None for UNITS, ACCGRAV, END ...), its arguments,
    the line it starts on and the Adams View name of the comment above it (or None)."""

    name: str
    id: int | None
    args: list
    line: int
    view_name: str | None = None
    used: set = field(default_factory=set)

    @property
    def label(self) -> str:
        """'JOINT/3' (how messages name the statement)."""
        return self.name if self.id is None else f"{self.name}/{self.id}"

    def flags(self) -> set:
        """The bare flags of the statement (REVOLUTE, GROUND, ...), upper case."""
        return {a.values[0].upper() for a in self.args if a.key is None}


def split_top(text: str, sep: str = ",") -> list:
    """`text` split at `sep` outside parentheses."""
    out, depth, start = [], 0, 0
    for k, ch in enumerate(text):
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth -= 1
        elif ch == sep and depth == 0:
            out.append(text[start:k])
            start = k + 1
    out.append(text[start:])
    return out


def is_number(text: str) -> bool:
    """True for an Adams number: 1, -2.5, 1E3, 1.0D-3 (Fortran exponent), 90D (degrees)."""
    return bool(_NUMBER.match(text.strip()))


def read_statements(text: str, source: str) -> list:
    """The statements of dataset `text` (title line skipped, stops at END); ModelFileError(source, line)
    for text that is not a statement."""
    lines = text.splitlines()
    groups, view_name, pending = [], None, None
    for n, raw in enumerate(lines[1:], start=2):   # line 1 is the title
        code, bang, comment = raw.partition("!")
        if bang:
            m = _VIEW_NAME.search(comment)
            if m:
                view_name = m.group(1)
        if not code.strip():
            continue
        if code.lstrip().startswith(","):
            if pending is None:
                raise ModelFileError("dataset", "(syntax)", "a continuation line (starting with ',') without "
                                     "a statement above it", source, n)
            pending[1].append((n, code.lstrip()[1:]))
            continue
        if pending is not None and pending[2]:   # the line above ended in '&': this one continues it
            pending[1].append((n, code))
            pending[2] = code.rstrip().endswith("&")
            continue
        pending = [n, [(n, code)], code.rstrip().endswith("&"), view_name]
        groups.append(pending)
        view_name = None
        if code.strip().upper().startswith("END") and code.strip().upper() in ("END", "END/"):
            break
    out = []
    for n, parts, _, vname in groups:
        st = _statement(parts, source, vname)
        if st.name == "END":
            break
        out.append(st)
    return out


def _statement(parts, source, view_name) -> Statement:
    """One Statement from its (line, text) pieces (the first holds NAME/id and maybe arguments)."""
    line0, first = parts[0]
    m = _HEAD.match(first)
    if not m or ("/" not in first[:m.end()] and first[m.end():].strip()):
        raise ModelFileError("dataset", "(syntax)", f"expected a statement NAME/id, got {first.strip()[:60]!r}",
                             source, line0)
    rest = first[m.end():].lstrip()
    rest = rest[1:] if rest.startswith(",") else rest
    st = Statement(m.group(1).upper(), None if m.group(2) is None else int(m.group(2)), [], line0, view_name)
    expr = None   # the expression argument being read: it runs over commas and continuation lines
    for ln, txt in [(line0, rest)] + list(parts[1:]):
        txt = txt.rstrip()
        txt = txt[:-1] if txt.endswith("&") else txt
        pos = 0
        while pos < len(txt):
            if expr is not None:
                body, bs, _ = txt[pos:].partition("\\")
                expr.values[0] = f"{expr.values[0]} {body.strip()}".strip()
                if not bs:
                    break
                expr, pos = None, pos + len(body) + 1
                continue
            end = _next_comma(txt, pos)
            tok = txt[pos:end]
            key, eq, _ = tok.partition("=")
            if eq and key.strip().upper() in EXPRESSION_KEYS:
                expr = Arg(key.strip().upper(), [""], ln)
                st.args.append(expr)
                pos += tok.index("=") + 1
                continue
            if tok.strip():
                _plain(st, tok.strip(), ln, source)
            pos = end + 1
    for a in st.args:
        if a.key in EXPRESSION_KEYS and not a.values[0].strip():
            raise ModelFileError(st.label, a.key, "empty function expression", source, a.line)
    return st


def _next_comma(text, pos):
    """Index of the next top-level comma from `pos` (len(text) when none)."""
    depth = 0
    for k in range(pos, len(text)):
        ch = text[k]
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth -= 1
        elif ch == "," and depth <= 0:
            return k
    return len(text)


def _plain(st, tok, ln, source):
    """A bare token: a further value of the argument before it (a number) or a flag (a word)."""
    key, eq, val = tok.partition("=")
    if eq:
        st.args.append(Arg(key.strip().upper(), [val.strip()], ln))
        return
    if is_number(tok) and st.args and st.args[-1].key is not None and st.args[-1].key not in EXPRESSION_KEYS:
        st.args[-1].values.append(tok)
    elif re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", tok):
        st.args.append(Arg(None, [tok.upper()], ln))
    else:
        raise ModelFileError(st.label, "(syntax)", f"unexpected text {tok[:60]!r}", source, ln)
