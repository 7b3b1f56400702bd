"""Adams function expressions -> mbdsim expression text (`mbdsim.model.loadexpr`, `mbdsim.expressions`).

The Adams text is tokenized and rewritten, never evaluated: marker ids in measures become
`body.marker` references, measures and TIME are converted from the dataset's units to SI (so that a
function written in mm, N and s reads the same numbers in mbdsim's SI model), VARVAL(id) is replaced by
the VARIABLE's function, and Fortran names map onto the whitelist (SIN -> sin, MIN/MAX/SIGN/DIM by
abs).  The result is still parsed by mbdsim's whitelist parser.  An unknown name or function is a
ModelFileError naming the statement, the file and the line.

Supported: + - * / ** and parentheses; numbers (1.5E3, 1.5D3, 90D = 90 degrees in rad); PI, DTOR,
RTOD, TIME; ABS ACOS ASIN ATAN ATAN2 COS COSH EXP LOG LOG10 SIN SINH SQRT TAN TANH SIGN MIN MAX DIM;
STEP STEP5 HAVSIN POLY SHF IMPACT BISTOP; DX DY DZ DM VX VY VZ VM VR WX WY WZ WM AX AY AZ ACCX ACCY
ACCZ (markers by id, 0 = ground; reference frames other than ground are refused); VARVAL; IF and MOD
(lowered to sign/abs/atan2/STEP: no new operation); AKISPL and CUBSPL of a SPLINE (mbdsim tables, in
load functions; adm_spline).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from math import pi
from typing import Callable

from ..errors import ModelFileError

_TOKEN = re.compile(r"\s*(?:(?P<num>(?:\d+\.?\d*|\.\d+)(?:[EeDd][+-]?\d+)?[Dd]?)|(?P<id>[A-Za-z_][A-Za-z0-9_]*)"
                    r"|(?P<op>\*\*|[-+*/(),:]))")
MATH = {n: n.lower() for n in ("ABS", "ACOS", "ASIN", "ATAN", "ATAN2", "COS", "COSH", "EXP", "LOG", "SIN", "SINH",
                               "SQRT", "TAN", "TANH")}
LIBRARY = ("STEP", "STEP5", "HAVSIN", "POLY", "SHF", "IMPACT", "BISTOP")
# measure -> (kind of quantity: its unit in the dataset, the most arguments Adams takes, the most mbdsim reads)
MEASURES = {**{n: ("length", 3, 3) for n in ("DX", "DY", "DZ")}, "DM": ("length", 2, 2),
            **{n: ("velocity", 4, 3) for n in ("VX", "VY", "VZ")}, "VM": ("velocity", 3, 2),
            "VR": ("velocity", 3, 2), **{n: ("angular", 3, 3) for n in ("WX", "WY", "WZ")},
            "WM": ("angular", 2, 2), **{n: ("angle", 2, 2) for n in ("AX", "AY", "AZ")},
            **{n: ("acceleration", 4, 3) for n in ("ACCX", "ACCY", "ACCZ")}}


@dataclass
class Context:
    """What a translation needs: where the text comes from (statement label, file, line), the marker
    references (id -> "body.marker", 0 -> "ground"), the VARIABLE texts (id -> (Adams text, line)),
    the dataset's units (SI per dataset unit: length, time) and the name of time in the target
    language ("TIME" for loads, "t" for motions)."""

    label: str
    source: str
    line: int
    marker: Callable[[int], str]
    variables: dict
    length: float = 1.0
    time: float = 1.0
    time_name: str = "TIME"
    spline: Callable[[int, str], str] | None = None   # (SPLINE id, "AKISPL"/"CUBSPL") -> table name
    _active: set = field(default_factory=set)

    def fail(self, message: str, fld: str = "FUNCTION"):
        raise ModelFileError(self.label, fld, message, self.source, self.line)


def number(text: str) -> float:
    """An Adams number: 1.5D3 is 1500 (Fortran exponent), a trailing D is degrees (90D -> pi/2)."""
    t = text.strip().upper()
    deg = t.endswith("D") and not re.search(r"D[+-]?\d+$", t)
    t = t[:-1] if deg else t
    v = float(t.replace("D", "E"))
    return v * pi / 180.0 if deg else v


def _tokens(text: str, ctx: Context) -> list:
    out, pos = [], 0
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if not m or m.end() == pos:
            if not text[pos:].strip():
                break
            ctx.fail(f"unexpected character {text[pos:].strip()[:1]!r} at {text.strip()[:60]!r}")
        kind = m.lastgroup
        out.append((kind, m.group(kind)))
        pos = m.end()
    return out


def translate(text: str, ctx: Context) -> str:
    """The mbdsim expression text of the Adams function `text` (SI measures, dataset-unit result)."""
    toks = _tokens(text, ctx)
    if not toks:
        ctx.fail("empty function expression")
    out, k = _expr(toks, 0, ctx)
    if k != len(toks):
        ctx.fail(f"unbalanced parentheses in {text.strip()[:80]!r}")
    return out


def _expr(toks, k, ctx, stop=()):
    """Translate tokens from k up to a token in `stop` at depth 0; returns (text, index)."""
    parts = []
    while k < len(toks):
        kind, val = toks[k]
        if kind == "op" and val in stop:
            break
        if kind == "num":
            x = number(val)
            parts.append(repr(x))
            k += 1
        elif kind == "id":
            name = val.upper()
            if name == "IF" and k + 1 < len(toks) and toks[k + 1] == ("op", "("):
                text, k = _if(toks, k + 2, ctx)
                parts.append(text)
            elif k + 1 < len(toks) and toks[k + 1] == ("op", "("):
                args, k = _args(toks, k + 2, ctx)
                parts.append(_call(name, args, ctx))
            else:
                parts.append(_name(name, ctx))
                k += 1
        elif val == "(":
            inner, k = _expr(toks, k + 1, ctx, (")",))
            if k >= len(toks):
                ctx.fail("unbalanced parentheses: a '(' is not closed")
            parts.append(f"({inner})")
            k += 1
        elif val in (")", ",", ":"):
            ctx.fail(f"unexpected {val!r} in the function expression")
        else:
            parts.append(val)
            k += 1
    return " ".join(parts), k


def _args(toks, k, ctx):
    """Arguments of a call whose '(' is before k: (list of (translated text, raw tokens)), index after ')'."""
    args = []
    while True:
        start = k
        text, k = _expr(toks, k, ctx, (",", ")"))
        if k >= len(toks):
            ctx.fail("unbalanced parentheses: a function call is not closed")
        args.append((text, toks[start:k]))
        if toks[k][1] == ")":
            return args, k + 1
        k += 1


def _name(name, ctx):
    if name == "TIME":
        return f"({ctx.time_name}/{ctx.time!r})" if ctx.time != 1.0 else ctx.time_name
    if name == "PI":
        return "pi"
    if name == "DTOR":
        return "(pi/180)"
    if name == "RTOD":
        return "(180/pi)"
    ctx.fail(f"unknown name {name!r} in the function expression (known: TIME, PI, DTOR, RTOD)")


def _call(name, args, ctx):
    a = [t for t, _ in args]
    if name in MATH:
        return f"{MATH[name]}({', '.join(a)})"
    if name == "LOG10":
        _arity(name, a, 1, ctx)
        return f"(log({a[0]})/log(10.0))"
    if name in ("MIN", "MAX", "SIGN", "DIM"):
        _arity(name, a, 2, ctx)
        x, y = a
        return {"MIN": f"(0.5*(({x}) + ({y}) - abs(({x}) - ({y}))))",
                "MAX": f"(0.5*(({x}) + ({y}) + abs(({x}) - ({y}))))",
                "SIGN": f"(abs({x})*sign({y}))",
                "DIM": f"(0.5*(({x}) - ({y}) + abs(({x}) - ({y}))))"}[name]
    if name in LIBRARY:
        return f"{name}({', '.join(a)})"
    if name == "MOD":
        _arity(name, a, 2, ctx)
        return _mod(*a)
    if name in ("AKISPL", "CUBSPL"):
        return _spline(name, args, ctx)
    if name in MEASURES:
        return _measure(name, args, ctx)
    if name == "VARVAL":
        return _varval(args, ctx)
    known = sorted([*MATH, "LOG10", "MIN", "MAX", "SIGN", "DIM", *LIBRARY, *MEASURES, "VARVAL", "IF", "MOD",
                    "AKISPL", "CUBSPL"])
    ctx.fail(f"unknown or unsupported function {name!r} in the function expression (mbdsim reads: "
             f"{', '.join(known)})")


def _if(toks, k, ctx):
    """IF(e1: e2, e3, e4) (tokens from k, after its '('): e2 where e1 < 0, e3 where e1 = 0, e4 where
    e1 > 0, written with the indicators 0.5(|s| - s), 1 - |s|, 0.5(|s| + s) of s = sign(e1), which are
    exactly 0 or 1: the chosen branch's value is returned to the last bit (the others must be finite)."""
    cond, k = _expr(toks, k, ctx, (":", ")", ","))
    if k >= len(toks) or toks[k][1] != ":":
        ctx.fail("IF is written IF(expression1: expression2, expression3, expression4)")
    args, k = _args(toks, k + 1, ctx)
    if len(args) != 3:
        ctx.fail(f"IF takes three expressions after the ':', got {len(args)}")
    e2, e3, e4 = (t for t, _ in args)
    s = f"sign({cond})"
    return (f"(0.5*(abs({s}) - {s})*({e2}) + (1 - abs({s}))*({e3}) + 0.5*(abs({s}) + {s})*({e4}))", k)


MOD_BLEND = 1e-9    # MOD's jump at a multiple of b is blended over this fraction of |b| (see _mod)


def _mod(a, b):
    """Fortran MOD(a, b) = a - b*int(a/b) (the sign of a, magnitude below |b|) without a floor operation:
    c = |b|/(2 pi) atan2(sin psi, cos psi), psi = 2 pi |a|/|b|, is |a| modulo |b| centred in
    (-|b|/2, |b|/2]; adding |b| where c < 0 (a STEP5 of width MOD_BLEND*|b|, whose cubic onset keeps the
    rounding residue ~1e-16 |a| of an exact multiple at 0) gives |a| mod |b| in [0, |b|); times sign(a).
    Exact to about 1e-16 |a| (while |a/b| < 1e4) except within MOD_BLEND*|b| below a multiple of b,
    where the jump is blended."""
    P = f"abs({b})"
    c = f"({P}/(2*pi)*atan2(sin(2*pi*abs({a})/{P}), cos(2*pi*abs({a})/{P})))"
    return f"(sign({a})*({c} + {P}*STEP5(-{c}, 0, 0, {MOD_BLEND!r}*{P}, 1)))"


def _spline(name, args, ctx):
    """AKISPL / CUBSPL(x, z, id[, iord]) -> a call of the SPLINE's table (z: one curve, ignored as Adams does)."""
    if ctx.spline is None:
        ctx.fail(f"{name} is not supported in a MOTION function (a spline of time): mbdsim reads splines in "
                 "force and VARIABLE functions")
    if len(args) not in (3, 4):
        ctx.fail(f"{name} takes (x, z, id[, iord]), got {len(args)} argument(s)")
    raw = args[2][1]
    if len(raw) != 1 or not raw[0][1].isdigit():
        ctx.fail(f"{name}: the third argument is a SPLINE id (an integer), got {' '.join(v for _, v in raw)!r}")
    sid = int(raw[0][1])
    order = 0
    if len(args) == 4:
        raw = args[3][1]
        if len(raw) != 1 or raw[0][1] not in ("0", "1", "2"):
            ctx.fail(f"{name}: iord must be 0, 1 or 2, got {' '.join(v for _, v in raw)!r}")
        order = int(raw[0][1])
    table = ctx.spline(sid, name)
    return f"{table}({args[0][0]}, order={order})" if order else f"{table}({args[0][0]})"


def _arity(name, a, n, ctx):
    if len(a) != n:
        ctx.fail(f"{name} takes {n} argument(s), got {len(a)}")


def _marker_id(name, raw, ctx) -> int:
    if len(raw) != 1 or raw[0][0] != "num" or not raw[0][1].isdigit():
        ctx.fail(f"the arguments of {name} are marker ids (integers), got "
                 f"{' '.join(v for _, v in raw)!r}")
    return int(raw[0][1])


def _measure(name, args, ctx):
    kind, most, keep = MEASURES[name]
    if not 1 <= len(args) <= most:
        ctx.fail(f"{name} takes 1 to {most} marker ids, got {len(args)}")
    ids = [_marker_id(name, raw, ctx) for _, raw in args]
    if len(ids) > keep:   # a derivative frame (VX's l, VM's l ...): only ground is supported
        if any(i != 0 for i in ids[keep:]):
            ctx.fail(f"{name}: a time derivative taken in a moving reference frame (marker {ids[keep]}) is not "
                     "supported; only ground (0 or omitted)")
        ids = ids[:keep]
    while len(ids) > 1 and ids[-1] == 0:
        ids.pop()
    refs = ", ".join(ctx.marker(i) for i in ids)
    scale = {"length": ctx.length, "velocity": ctx.length / ctx.time, "angular": 1.0 / ctx.time, "angle": 1.0,
             "acceleration": ctx.length / ctx.time ** 2}[kind]
    return f"{name}({refs})" if scale == 1.0 else f"({name}({refs})/{scale!r})"


def _varval(args, ctx):
    if len(args) != 1:
        ctx.fail(f"VARVAL takes one VARIABLE id, got {len(args)}")
    vid = _marker_id("VARVAL", args[0][1], ctx)
    if vid not in ctx.variables:
        ctx.fail(f"VARVAL({vid}): no VARIABLE/{vid} in the dataset")
    if vid in ctx._active:
        ctx.fail(f"VARVAL({vid}): the VARIABLEs refer to each other in a loop")
    text, line = ctx.variables[vid]
    sub = Context(f"VARIABLE/{vid}", ctx.source, line, ctx.marker, ctx.variables, ctx.length, ctx.time,
                  ctx.time_name, ctx.spline, ctx._active | {vid})
    return f"({translate(text, sub)})"
