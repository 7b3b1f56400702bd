"""The validation report: Markdown + one self-contained HTML page + figure PNGs.

:func:`write_report` takes the :class:`~mbdsim.validation.framework.CaseOutcome` list
produced by the validation runner and writes, into ``out_dir``::

    report.md            Markdown (figures referenced as figures/*.png)
    report.html          one self-contained page: inline CSS, figures as base64 data URIs
    figures/*.png        the mechanism at t=0 of every case and the manual's plots

The mechanism figure is drawn from the model itself (x-y projection of the bodies,
markers, joints and spring-dampers at t=0).  Figure drawing is defensive: if anything
is missing or fails, the report carries a note instead of the figure and goes on.

matplotlib is imported lazily (Agg canvas, no pyplot state), so importing this module
is cheap; :func:`quantity_records` and the formatting helpers need neither matplotlib
nor the engine.
"""
from __future__ import annotations

import base64
import datetime as _dt
import html
import io
import math
import platform
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable, Sequence

from mbdsim import __version__ as _mbdsim_version
from mbdsim.validation.framework import FLOOR, REL_TOL, CaseOutcome, Plot, Quantity
from mbdsim.validation.registry import is_finite, outcome_error

__all__ = [
    "write_report",
    "quantity_records",
    "fmt_value",
    "fmt_pct",
    "case_status",
    "COLUMNS",
]

MANUAL = "J. L. Meriam and L. G. Kraige, *Engineering Mechanics: Dynamics*, 7th ed."

#: comparison table columns (shared with the CLI's table)
COLUMNS = (
    "case",
    "quantity",
    "unit",
    "recomputed theory",
    "manual theory",
    "manual commercial",
    "mbdsim",
    "mbdsim error %",
    "commercial error % (recomputed)",
    "pass",
)

# --------------------------------------------------------------------------- formatting


def fmt_value(x: Any) -> str:
    """Nine significant digits: enough to show 1e-7 relative differences."""
    if x is None:
        return "—"
    try:
        v = float(x)
    except (TypeError, ValueError):
        return str(x)
    if not math.isfinite(v):
        return str(v)
    return f"{v:.9g}"


def fmt_pct(p: Any) -> str:
    """An error in percent: scientific notation with 3 significant digits when small."""
    if p is None:
        return "—"
    try:
        v = float(p)
    except (TypeError, ValueError):
        return str(p)
    if not math.isfinite(v):
        return str(v)
    if v == 0.0:
        return "0"
    if abs(v) < 0.01:
        return f"{v:.2e}"
    return f"{v:.3g}"


def _safe(fn, default=None):
    try:
        return fn()
    except Exception:  # noqa: BLE001
        return default


def case_status(outcome: CaseOutcome) -> str:
    """``"PASS"``, ``"FAIL"`` (some quantity fails) or ``"ERROR"`` (the case did not run)."""
    if outcome_error(outcome) is not None:
        return "ERROR"
    ok = _safe(lambda: all(q.passed for q in outcome.quantities), False)
    return "PASS" if ok else "FAIL"


def _json_num(x: Any) -> float | None:
    if x is None:
        return None
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def quantity_records(outcomes: Iterable[CaseOutcome]) -> list[dict[str, Any]]:
    """One JSON-ready record per compared quantity.

    Keys: ``case`` (int), ``quantity``, ``unit``, ``theory``, ``manual_theory``,
    ``manual_commercial``, ``mbdsim``, ``error_pct``, ``commercial_error_pct``, ``pass``.
    A case that raised contributes one record with ``quantity`` ``"<case error>"``,
    null values, ``pass`` false and an extra ``error`` key holding the message.
    Non-finite numbers are written as null.
    """
    records: list[dict[str, Any]] = []
    for o in outcomes:
        number = int(getattr(o.info, "number", 0))
        err = getattr(o, "error", None)
        if err or not o.quantities:
            records.append({
                "case": number, "quantity": "<case error>", "unit": "",
                "theory": None, "manual_theory": None, "manual_commercial": None,
                "mbdsim": None, "error_pct": None, "commercial_error_pct": None,
                "pass": False, "error": str(err or "the case produced no compared quantities"),
            })
            continue
        for q in o.quantities:
            records.append({
                "case": number,
                "quantity": str(q.name),
                "unit": str(q.unit),
                "theory": _json_num(q.theory),
                "manual_theory": _json_num(q.manual_theory),
                "manual_commercial": _json_num(q.manual_commercial),
                "mbdsim": _json_num(q.mbdsim),
                "error_pct": _json_num(_safe(lambda q=q: q.error_pct)),
                "commercial_error_pct": _json_num(_safe(lambda q=q: q.commercial_error_pct)),
                "pass": bool(_safe(lambda q=q: q.passed, False)),
            })
    return records


def _row_cells(number: int, q: Quantity) -> list[str]:
    passed = bool(_safe(lambda: q.passed, False))
    return [
        f"{number:02d}",
        str(q.name),
        str(q.unit),
        fmt_value(q.theory),
        fmt_value(q.manual_theory),
        fmt_value(q.manual_commercial),
        fmt_value(q.mbdsim),
        fmt_pct(_safe(lambda: q.error_pct)),
        fmt_pct(_safe(lambda: q.commercial_error_pct)),
        "PASS" if passed else "FAIL",
    ]


# --------------------------------------------------------------------------- figures


@dataclass
class _Figure:
    """A rendered figure (PNG bytes) or the note explaining why there is none."""

    kind: str                 # "mechanism" or "plot"
    title: str
    filename: str | None = None
    png: bytes | None = None
    note: str | None = None


def _new_figure(width: float = 6.4, height: float = 4.4):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), dpi=110)
    FigureCanvasAgg(fig)
    return fig


def _to_png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", bbox_inches="tight", metadata={"Software": None})
    return buf.getvalue()


def _items(container: Any) -> list[tuple[str, Any]]:
    """``(name, object)`` pairs from a dict, a list or any iterable of named objects."""
    if container is None:
        return []
    if callable(container) and not hasattr(container, "__iter__"):
        container = _safe(container, None)
        if container is None:
            return []
    if isinstance(container, dict):
        return [(str(k), v) for k, v in container.items()]
    try:
        seq = list(container)
    except TypeError:
        return []
    return [(str(getattr(v, "name", i)), v) for i, v in enumerate(seq)]


def _name_of(obj: Any) -> str | None:
    if obj is None:
        return None
    if isinstance(obj, str):
        return obj
    name = getattr(obj, "name", None)
    return None if name is None else str(name)


def _point(v: Any):
    """A 3-vector (numpy) from a 2- or 3-sequence, or None when unusable."""
    import numpy as np

    if v is None:
        return None
    try:
        a = np.asarray(v, dtype=float).ravel()
    except (TypeError, ValueError):
        return None
    if a.size == 2:
        a = np.array([a[0], a[1], 0.0])
    if a.size != 3 or not np.all(np.isfinite(a)):
        return None
    return a


def _is_ground(name: str | None, body: Any, ground_name: str | None) -> bool:
    if body is not None and bool(getattr(body, "is_ground", False)):
        return True
    if name is None:
        return False
    if ground_name is not None and name == ground_name:
        return True
    return name.lower() in ("ground", "gnd", "world")


def _zigzag(p, q, coils: int = 6, amp: float = 0.05):
    import numpy as np

    d = q - p
    length = float(np.hypot(d[0], d[1]))
    if length <= 0:
        return np.array([p[0], q[0]]), np.array([p[1], q[1]])
    u = d / length
    n = np.array([-u[1], u[0]])
    s = [0.0, 0.15]
    off = [0.0, 0.0]
    k = 2 * coils
    for i in range(k):
        s.append(0.15 + 0.7 * (i + 0.5) / k)
        off.append(amp * length * (1 if i % 2 == 0 else -1))
    s += [0.85, 1.0]
    off += [0.0, 0.0]
    s = np.array(s)
    off = np.array(off)
    xy = p[None, :] + s[:, None] * d[None, :] + off[:, None] * n[None, :]
    return xy[:, 0], xy[:, 1]


def _draw_mechanism(outcome: CaseOutcome) -> bytes:
    """Draw the model at t=0 (projection on the x-y plane). Raises if nothing can be drawn."""
    import numpy as np
    from matplotlib.patches import Rectangle

    model = outcome.model
    if model is None:
        raise ValueError("the case provides no model")
    bodies = _items(getattr(model, "bodies", None))
    joints = _items(getattr(model, "joints", None))
    forces = _items(getattr(model, "forces", None))
    ground_name = _name_of(getattr(model, "ground", None))

    body_by_name = {n: b for n, b in bodies}
    # ------------------------------------------------------------ collect geometry (3-D)
    body_geo: dict[str, dict[str, Any]] = {}
    ground_pts: list[tuple[str, Any]] = []
    for name, b in bodies:
        bname = _name_of(b) or name
        markers = []
        for mname, m in _items(getattr(b, "markers", None)):
            p = _point(getattr(m, "point", None))
            if p is None:
                p = _point(getattr(m, "position", None))
            if p is not None:
                markers.append((mname, p))
        if _is_ground(bname, b, ground_name):
            ground_name = ground_name or bname
            ground_pts.extend(markers)
            continue
        com = _point(getattr(b, "position", None))
        R = _safe(lambda b=b: np.asarray(getattr(b, "orientation"), dtype=float), None)
        if R is not None and (R.shape != (3, 3) or not np.all(np.isfinite(R))):
            R = None
        body_geo[bname] = {
            "com": com,
            "R": R,
            "markers": markers,
            "joints": [],
            "particle": bool(getattr(b, "is_particle", False)),
        }

    driven = set()
    for _, mo in _items(getattr(model, "motions", None)):
        jn = _name_of(getattr(mo, "joint", None))
        if jn is not None:
            driven.add(jn)
    joint_geo = []
    for jname, j in joints:
        p = _point(getattr(j, "point", None))
        if p is None:
            continue
        kind = str(getattr(j, "kind", "") or type(j).__name__)
        if (_name_of(j) or jname) in driven or jname in driven:
            kind += ", driven"
        axis = _point(getattr(j, "axis", None)) if kind.split(",")[0] in (
            "translational", "cylindrical") else None
        ends = [_name_of(getattr(j, "body_i", None)), _name_of(getattr(j, "body_j", None))]
        joint_geo.append((jname, kind, p, axis))
        for e in ends:
            if e is None:
                continue
            if e in body_geo:
                body_geo[e]["joints"].append(p)
            elif _is_ground(e, body_by_name.get(e), ground_name):
                ground_pts.append((None, p))

    spring_geo = []
    load_geo = []
    for fname, f in forces:
        pi = _safe(lambda f=f: _point(getattr(f, "point_i", None)))
        pj = _safe(lambda f=f: _point(getattr(f, "point_j", None)))
        if pi is None or pj is None:
            # an applied force: arrow at its point when it is a constant vector
            fb, sB, fv = getattr(f, "body", None), _point(getattr(f, "s_B", None)), getattr(f, "force", None)
            if fb is not None and sB is not None and not callable(fv) and fv is not None:
                pos = _point(getattr(fb, "position", None))
                R = _safe(lambda fb=fb: np.asarray(getattr(fb, "orientation"), dtype=float).reshape(3, 3))
                vec = _point(fv)
                frame = getattr(f, "frame", None)
                if frame is not None:  # expressed in the axes of a body or marker
                    Rf = _safe(lambda: np.asarray(getattr(frame, "orientation"), dtype=float).reshape(3, 3))
                    vec = None if Rf is None or vec is None else Rf @ vec
                if pos is not None and R is not None and vec is not None and np.any(vec != 0):
                    load_geo.append((fname, pos + R @ sB, vec))
            continue
        spring_geo.append((fname, pi, pj))
        for attr, mattr, p in (("body_i", "marker_i", pi), ("body_j", "marker_j", pj)):
            owner = getattr(f, attr, None)
            if owner is None:
                owner = getattr(getattr(f, mattr, None), "body", None)
            e = _name_of(owner)
            if e is not None and e not in body_geo and _is_ground(e, body_by_name.get(e), ground_name):
                ground_pts.append((None, p))
            elif e in body_geo:
                body_geo[e]["joints"].append(p)

    allpts = [g["com"] for g in body_geo.values() if g["com"] is not None]
    for g in body_geo.values():
        allpts += [p for _, p in g["markers"]]
    allpts += [p for _, _, p, _ in joint_geo]
    allpts += [p for _, p, _ in load_geo]
    allpts += [p for _, p in ground_pts]
    for _, a, b in spring_geo:
        allpts += [a, b]
    curve_geo, shape_geo = _curves_and_shapes(model, forces)
    for _, pts in curve_geo:
        allpts += list(pts)
    for _, kind, c, _ in shape_geo:
        allpts.append(c)
    if not allpts:
        raise ValueError("the model has no drawable points (bodies, markers or joints)")
    P = np.array(allpts)

    # ------------------------------------------------------------ projection plane
    ix, iy = 0, 1
    spans = P.max(axis=0) - P.min(axis=0)
    if spans[0] <= 1e-12 * max(spans.max(), 1e-300) and spans[1] <= 1e-12 * max(spans.max(), 1e-300) \
            and spans.max() > 0:
        # the x-y projection is degenerate (a mechanism along z): use the widest pair
        order = np.argsort(spans)[::-1]
        ix, iy = sorted(int(i) for i in order[:2])
    axis_names = "xyz"

    def xy(p):
        return float(p[ix]), float(p[iy])

    span2 = max(float(spans[ix]), float(spans[iy]))
    scale = span2 if span2 > 0 else max(float(np.abs(P).max()), 1.0)

    fig = _new_figure(6.4, 5.0)
    ax = fig.add_subplot(1, 1, 1)
    colors = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2",
              "#17becf", "#bcbd22", "#7f7f7f"]

    # ground: hatched blocks under every ground attachment
    seen = set()
    gw, gh = 0.08 * scale, 0.035 * scale
    for label, p in ground_pts:
        x, y = xy(p)
        key = (round(x / scale, 9), round(y / scale, 9))
        if key in seen:
            continue
        seen.add(key)
        ax.add_patch(Rectangle((x - gw / 2, y - gh), gw, gh, facecolor="none", edgecolor="0.35",
                               hatch="////", linewidth=0.0, zorder=1))
        ax.plot([x - gw / 2, x + gw / 2], [y, y], color="0.2", lw=1.5, zorder=2)
        if label:
            ax.annotate(label, (x, y), xytext=(3, -12), textcoords="offset points", fontsize=7,
                        color="0.3")

    # springs / dampers
    for fname, pi, pj in spring_geo:
        zx, zy = _zigzag(np.array(xy(pi)), np.array(xy(pj)))
        ax.plot(zx, zy, color="0.25", lw=1.0, zorder=3)
        mx, my = (zx[0] + zx[-1]) / 2, (zy[0] + zy[-1]) / 2
        ax.annotate(fname, (mx, my), xytext=(4, 4), textcoords="offset points", fontsize=7,
                    color="0.25")

    # bodies
    joint_names_at = {(round(xy(p)[0] / scale, 6), round(xy(p)[1] / scale, 6), jn)
                      for jn, _, p, _ in joint_geo}
    for k, (bname, g) in enumerate(body_geo.items()):
        c = colors[k % len(colors)]
        com = g["com"]
        if com is not None:
            cx, cy = xy(com)
            for p in [p for _, p in g["markers"]] + g["joints"]:
                px, py = xy(p)
                ax.plot([cx, px], [cy, py], color=c, lw=2.2, alpha=0.55, solid_capstyle="round",
                        zorder=3)
            if g["particle"]:
                ax.plot(cx, cy, "o", ms=11, color=c, mec="black", zorder=6)
            else:
                ax.plot(cx, cy, "o", ms=8, color=c, mec="black", zorder=6)
                ax.plot(cx, cy, "+", ms=8, color="white", mew=1.2, zorder=7)
                R = g["R"]
                if R is not None:
                    for col, ac in ((0, "#c0392b"), (1, "#27ae60")):
                        d = R[:, col] * 0.07 * scale
                        dx, dy = float(d[ix]), float(d[iy])
                        if abs(dx) + abs(dy) > 1e-3 * 0.07 * scale:
                            ax.annotate("", xy=(cx + dx, cy + dy), xytext=(cx, cy),
                                        arrowprops=dict(arrowstyle="->", color=ac, lw=0.9),
                                        zorder=5)
            ax.annotate(bname, (cx, cy), xytext=(6, 6), textcoords="offset points", fontsize=8,
                        color=c, fontweight="bold")
        for mname, p in g["markers"]:
            px, py = xy(p)
            ax.plot(px, py, "s", ms=3.5, color=c, zorder=5)
            if (round(px / scale, 6), round(py / scale, 6), mname) in joint_names_at:
                continue  # a marker named after the joint at the same point: the joint is labelled
            ax.annotate(mname, (px, py), xytext=(4, 5), textcoords="offset points", fontsize=6.5,
                        color=c)

    # applied constant forces
    for fname, p, vec in load_geo:
        x, y = xy(p)
        d = np.array([vec[ix], vec[iy]])
        nd = float(np.hypot(*d))
        if nd <= 0:
            continue
        d = d / nd * 0.15 * scale
        ax.annotate("", xy=(x + d[0], y + d[1]), xytext=(x, y),
                    arrowprops=dict(arrowstyle="-|>", color="#e67e22", lw=1.6), zorder=6)
        ax.annotate(fname, (x + d[0], y + d[1]), xytext=(3, 3), textcoords="offset points",
                    fontsize=7, color="#e67e22")

    # joints
    joint_labels: dict[tuple, tuple] = {}
    joint_legend: list[str] = []
    for jname, kind, p, axis in joint_geo:
        x, y = xy(p)
        if axis is not None:
            a = np.array([axis[ix], axis[iy]])
            na = float(np.hypot(*a))
            if na > 1e-9:
                a = a / na * 0.2 * scale
                ax.plot([x - a[0], x + a[0]], [y - a[1], y + a[1]], color="black", ls="--", lw=1.0,
                        zorder=4)
        ax.plot(x, y, "o", ms=10, mfc="white", mec="black", mew=1.4, zorder=8)
        ax.plot(x, y, ".", ms=3, color="black", zorder=9)
        key = (round(x / scale, 6), round(y / scale, 6))
        joint_labels.setdefault(key, ((x, y), []))[1].append(jname)
        joint_legend.append(f"{jname}: {kind}" if kind and kind != jname else jname)
    for (x, y), labels in joint_labels.values():  # joints sharing a point share one label
        ax.annotate(", ".join(labels), (x, y), xytext=(5, -7), textcoords="offset points",
                    fontsize=7, color="black", va="top")
    for cname, pts in curve_geo:   # path constraints: the curve at t = 0
        ax.plot(pts[:, ix], pts[:, iy], color="0.35", lw=1.2, ls="-", zorder=2)
        ax.annotate(cname, xy(pts[len(pts) // 2]), xytext=(4, 4), textcoords="offset points", fontsize=7,
                    color="0.3")
    for sname, kind, c, extra in shape_geo:   # contact shapes
        x, y = xy(c)
        if kind == "sphere":
            from matplotlib.patches import Circle
            ax.add_patch(Circle((x, y), extra, facecolor="none", edgecolor="#8c564b", lw=1.2, zorder=4))
        else:   # plane: its trace, perpendicular to the projected normal
            n2 = np.array([extra[ix], extra[iy]])
            t2 = np.array([-n2[1], n2[0]]) / max(np.linalg.norm(n2), 1e-12) * 0.6 * scale
            ax.plot([x - t2[0], x + t2[0]], [y - t2[1], y + t2[1]], color="#8c564b", lw=1.6, zorder=2)
        ax.annotate(sname, (x, y), xytext=(4, -10), textcoords="offset points", fontsize=7, color="#8c564b")
    legend = []
    if joint_legend:
        legend.append("joints: " + "; ".join(joint_legend))
    if spring_geo:
        legend.append("spring-dampers: " + ", ".join(n for n, _, _ in spring_geo))
    if load_geo:
        legend.append("constant forces: " + ", ".join(n for n, _, _ in load_geo))
    if legend:
        import textwrap

        text = "\n".join(textwrap.fill(line, 110) for line in legend)
        ax.annotate(text, xy=(0.0, 0.0), xycoords="axes fraction", xytext=(0, -36),
                    textcoords="offset points", fontsize=7, va="top", ha="left", color="0.25")

    ax.set_aspect("equal", adjustable="box")
    pad = 0.12 * scale
    xs, ys = P[:, ix], P[:, iy]
    ax.set_xlim(float(xs.min()) - pad, float(xs.max()) + pad)
    ax.set_ylim(float(ys.min()) - pad - gh, float(ys.max()) + pad)
    ax.set_xlabel(axis_names[ix])
    ax.set_ylabel(axis_names[iy])
    ax.grid(True, lw=0.4, alpha=0.5)
    plane = axis_names[ix] + "-" + axis_names[iy]
    ax.set_title(f"Case {outcome.info.number:02d}: model at t = 0 ({plane} projection)", fontsize=10)
    return _to_png(fig)


def _curves_and_shapes(model, forces):
    """Path curves [(name, (K, 3) points)] and contact shapes [(name, kind, centre, radius | normal)] at t = 0,
    all in ground; anything missing or malformed is skipped."""
    import numpy as np
    curves, shapes = [], []
    for name, pc in _items(getattr(model, "path_constraints", None)):
        try:
            a, b = pc.curve.s_range
            pts = np.array([pc.curve.point(x) for x in np.linspace(a, b, 200)], dtype=float)
            if pts.shape[1:] == (3,) and np.all(np.isfinite(pts)):
                curves.append((getattr(pc, "name", name), pts))
        except Exception:  # noqa: BLE001 - a figure never stops the report
            continue
    for name, f in forces:
        for side in ("shape_i", "shape_j"):
            sh = getattr(f, side, None)
            body = getattr(sh, "body", None)
            try:
                c = np.asarray(body.position, float) + np.asarray(body.orientation, float) @ np.asarray(sh.s_B, float)
                extra = sh.radius if sh.kind == "sphere" else np.asarray(body.orientation, float) @ sh.n_B
                shapes.append((f"{name}.{side[-1]}", sh.kind, c, extra))
            except Exception:  # noqa: BLE001
                continue
    return curves, shapes


def _draw_plot(plot: Plot) -> bytes:
    import numpy as np

    x = np.asarray(plot.x, dtype=float).ravel()
    series = plot.y.items() if isinstance(plot.y, dict) else [(None, plot.y)]
    fig = _new_figure(6.4, 4.0)
    ax = fig.add_subplot(1, 1, 1)
    n = 0
    for label, yy in series:
        y = np.asarray(yy, dtype=float).ravel()
        if y.shape != x.shape:
            raise ValueError(f"x has {x.size} points but series {label or 'y'!s} has {y.size}")
        ax.plot(x, y, lw=1.4, label=None if label is None else str(label))
        n += 1
    if n == 0:
        raise ValueError("the plot has no data series")
    if plot.mark is not None:
        mx, my = float(plot.mark[0]), float(plot.mark[1])
        ax.axvline(mx, color="0.6", ls=":", lw=0.9)
        ax.axhline(my, color="0.6", ls=":", lw=0.9)
        coords = f"({mx:.6g}, {my:.6g})"
        label = f"{plot.mark_label} {coords}" if plot.mark_label else coords
        ax.plot(mx, my, "o", ms=7, color="#d62728", mec="black", zorder=5, label=label)
        ax.annotate(label, (mx, my), xytext=(8, 8), textcoords="offset points", fontsize=8,
                    color="#a01010",
                    bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="#d62728", alpha=0.85))
    ax.set_xlabel(plot.xlabel)
    ax.set_ylabel(plot.ylabel)
    ax.set_title(plot.title, fontsize=10)
    ax.grid(True, lw=0.4, alpha=0.5)
    if isinstance(plot.y, dict) and len(plot.y) > 1:
        ax.legend(fontsize=8)
    return _to_png(fig)


def _render_figures(outcome: CaseOutcome) -> list[_Figure]:
    n = int(outcome.info.number)
    figs: list[_Figure] = []
    title = "Mechanism at t = 0 (drawn from the model)"
    if outcome.model is None:
        figs.append(_Figure("mechanism", title,
                            note="No mechanism figure: the case did not return a model."))
    else:
        try:
            figs.append(_Figure("mechanism", title, f"case{n:02d}_mechanism.png",
                                _draw_mechanism(outcome)))
        except Exception as exc:  # noqa: BLE001 - a figure must never break the report
            figs.append(_Figure("mechanism", title,
                                note=f"Mechanism figure could not be drawn: {type(exc).__name__}: {exc}"))
    for k, plot in enumerate(outcome.plots or [], start=1):
        ptitle = str(getattr(plot, "title", f"plot {k}"))
        try:
            figs.append(_Figure("plot", ptitle, f"case{n:02d}_plot{k}.png", _draw_plot(plot)))
        except Exception as exc:  # noqa: BLE001
            figs.append(_Figure("plot", ptitle,
                                note=f"Plot '{ptitle}' could not be drawn: {type(exc).__name__}: {exc}"))
    return figs


# --------------------------------------------------------------------------- markdown -> html

_MATH_RE = re.compile(r"\$\$(.+?)\$\$|(?<![\\$])\$(?!\s)([^$\n]+?)(?<!\s)\$", re.S)


def _md_renderer():
    try:
        from markdown_it import MarkdownIt
    except ImportError:  # pragma: no cover - markdown-it-py ships with rich
        return None
    return MarkdownIt("commonmark", {"html": False}).enable("table")


_MD = None


def _md_html(text: str, inline: bool = False) -> str:
    """Markdown to HTML (raw HTML escaped); TeX math kept verbatim in .math spans."""
    global _MD
    if not text:
        return ""
    maths: list[tuple[str, bool]] = []

    def stash(m: re.Match) -> str:
        if m.group(1) is not None:
            maths.append((m.group(1).strip(), True))
        else:
            maths.append((m.group(2), False))
        return f"MBDSIMMATHTOKEN{len(maths) - 1}X"

    protected = _MATH_RE.sub(stash, text)
    if _MD is None:
        _MD = _md_renderer() or False
    if _MD:
        out = _MD.renderInline(protected) if inline else _MD.render(protected)
    else:  # pragma: no cover
        out = html.escape(protected).replace("\n\n", "</p><p>")
        out = out if inline else f"<p>{out}</p>"

    def unstash(m: re.Match) -> str:
        expr, display = maths[int(m.group(1))]
        cls = "math display" if display else "math"
        return f'<span class="{cls}">{html.escape(expr)}</span>'

    return re.sub(r"MBDSIMMATHTOKEN(\d+)X", unstash, out)


# --------------------------------------------------------------------------- document model


@dataclass
class _CaseDoc:
    outcome: CaseOutcome
    status: str
    figures: list[_Figure] = field(default_factory=list)

    @property
    def number(self) -> int:
        return int(self.outcome.info.number)

    @property
    def anchor(self) -> str:
        return f"case-{self.number:02d}"


def _counts(docs: Sequence[_CaseDoc]) -> dict[str, int]:
    nq = sum(len(d.outcome.quantities) for d in docs)
    nq_pass = sum(1 for d in docs for q in d.outcome.quantities if _safe(lambda q=q: q.passed, False))
    return {
        "cases": len(docs),
        "cases_passed": sum(1 for d in docs if d.status == "PASS"),
        "cases_error": sum(1 for d in docs if d.status == "ERROR"),
        "quantities": nq,
        "quantities_passed": nq_pass,
    }


def _max_or_none(values: Iterable[Any]) -> float | None:
    vals = [float(v) for v in values if v is not None and is_finite(v)]
    return max(vals) if vals else None


def _environment() -> str:
    import numpy

    parts = [f"mbdsim {_mbdsim_version}", f"Python {platform.python_version()}",
             f"NumPy {numpy.__version__}"]
    scipy = sys.modules.get("scipy")
    if scipy is not None:
        parts.append(f"SciPy {getattr(scipy, '__version__', '?')}")
    parts.append(platform.platform(terse=True))
    return ", ".join(parts)


CRITERION = (
    "For every compared quantity, e = |mbdsim − theory| / |theory| (theory recomputed from the "
    "manual's formulas in full precision) and e_c is the commercial code's error against the same "
    f"recomputed theory. A quantity passes when e ≤ {REL_TOL:g} ({REL_TOL * 100:g} %) and "
    f"(e ≤ e_c or e ≤ {FLOOR:g}): never worse than the commercial code, except below one part per "
    "million."
)


# --------------------------------------------------------------------------- markdown


def _md_cell(s: str) -> str:
    return str(s).replace("|", "\\|").replace("\n", " ")


def _md_table(header: Sequence[str], rows: Sequence[Sequence[str]], right: Sequence[int] = ()) -> str:
    lines = ["| " + " | ".join(_md_cell(h) for h in header) + " |"]
    lines.append("|" + "|".join("---:" if i in right else "---" for i in range(len(header))) + "|")
    for r in rows:
        lines.append("| " + " | ".join(_md_cell(c) for c in r) + " |")
    return "\n".join(lines)


_NUM_COLS = (3, 4, 5, 6, 7, 8)


def _summary_rows(docs: Sequence[_CaseDoc], link) -> list[list[str]]:
    rows = []
    for d in docs:
        o = d.outcome
        qs = o.quantities
        npass = sum(1 for q in qs if _safe(lambda q=q: q.passed, False))
        elapsed = getattr(o, "elapsed_s", None)
        rows.append([
            link(d),
            str(o.info.title),
            str(o.info.reference),
            f"{npass}/{len(qs)}",
            fmt_pct(_max_or_none(_safe(lambda q=q: q.error_pct) for q in qs)),
            fmt_pct(_max_or_none(_safe(lambda q=q: q.commercial_error_pct) for q in qs)),
            str(len(o.info.discrepancies or [])),
            d.status,
            "—" if elapsed is None else f"{float(elapsed):.2f}",
        ])
    return rows


_SUMMARY_HEADER = ("case", "title", "reference", "quantities passed", "max mbdsim error %",
                   "max commercial error %", "discrepancies", "status", "time [s]")


def _markdown(docs: Sequence[_CaseDoc], generated: str) -> str:
    c = _counts(docs)
    out: list[str] = []
    out.append("# mbdsim validation report\n")
    out.append(f"Generated {generated} with {_environment()}.\n")
    out.append(f"Reference problems: {MANUAL} (the 30 problems of the validation manual).\n")
    verdict = "ALL PASS" if c["cases_passed"] == c["cases"] and c["cases"] else "FAILURES"
    out.append(f"**{verdict}: {c['cases_passed']}/{c['cases']} cases passed, "
               f"{c['quantities_passed']}/{c['quantities']} quantities passed"
               + (f", {c['cases_error']} case(s) raised an error" if c["cases_error"] else "")
               + ".**\n")
    out.append(f"Pass criterion: {CRITERION}\n")

    out.append("## Summary\n")
    out.append(_md_table(_SUMMARY_HEADER,
                         _summary_rows(docs, lambda d: f"[{d.number:02d}](#{d.anchor})"),
                         right=(4, 5, 6, 8)) + "\n")

    out.append("## Manual discrepancies found\n")
    any_disc = False
    for d in docs:
        disc = list(d.outcome.info.discrepancies or [])
        if not disc:
            continue
        any_disc = True
        out.append(f"### Case {d.number:02d}: {d.outcome.info.title}\n")
        out.extend(f"- {_one_line(s)}" for s in disc)
        out.append("")
    if not any_disc:
        out.append("None found in the cases run.\n")

    out.append("## All compared quantities\n")
    rows = [_row_cells(d.number, q) for d in docs for q in d.outcome.quantities]
    out.append(_md_table(COLUMNS, rows, right=_NUM_COLS) + "\n" if rows else "No quantities.\n")

    out.append("## Cases\n")
    for d in docs:
        out.append(_md_case(d))
    return "\n".join(out).rstrip() + "\n"


def _one_line(s: str) -> str:
    return str(s).strip().replace("\n", "\n  ")


def _md_case(d: _CaseDoc) -> str:
    o, info = d.outcome, d.outcome.info
    out: list[str] = []
    out.append(f'<a id="{d.anchor}"></a>\n')
    out.append(f"### Case {d.number:02d}: {info.title} [{d.status}]\n")
    meta = [f"**Reference:** {info.reference}" if info.reference else "",
            f"**Analysis:** {info.analysis}" if info.analysis else "",
            f"**Module:** `{info.slug}`" if info.slug else ""]
    elapsed = getattr(o, "elapsed_s", None)
    if elapsed is not None:
        meta.append(f"**Run time:** {float(elapsed):.2f} s")
    out.append(" · ".join(m for m in meta if m) + "\n")
    err = outcome_error(o)
    if err:
        out.append(f"> **ERROR:** {_md_cell(err)}\n")
        tb = getattr(o, "traceback", "")
        if tb:
            out.append("<details><summary>Traceback</summary>\n\n```text\n" + tb.rstrip()
                       + "\n```\n\n</details>\n")
    if info.statement:
        out.append("#### Problem statement\n")
        out.append(str(info.statement).strip() + "\n")
    if info.reconstruction:
        out.append("#### Reconstruction\n")
        out.append(str(info.reconstruction).strip() + "\n")
    for f in d.figures:
        if f.kind == "mechanism":
            out.append(_md_figure(f))
    plots = [f for f in d.figures if f.kind == "plot"]
    if plots:
        out.append("#### Plots\n")
        out.extend(_md_figure(f) for f in plots)
    if o.quantities:
        out.append("#### Comparison\n")
        out.append(_md_table(COLUMNS, [_row_cells(d.number, q) for q in o.quantities],
                             right=_NUM_COLS) + "\n")
        qnotes = [(q.name, q.note) for q in o.quantities if q.note]
        if qnotes:
            out.extend(f"- **{n}:** {_one_line(t)}" for n, t in qnotes)
            out.append("")
    for heading, items in (("Notes", info.notes), ("Full-physics variants", o.variants),
                           ("Manual discrepancies", info.discrepancies)):
        items = list(items or [])
        if items:
            out.append(f"#### {heading}\n")
            out.extend(f"- {_one_line(s)}" for s in items)
            out.append("")
    return "\n".join(out) + "\n"


def _md_figure(f: _Figure) -> str:
    if f.png is not None and f.filename:
        return f"![{_md_cell(f.title)}](figures/{f.filename})\n\n*{f.title}*\n"
    return f"> *{f.note}*\n"


# --------------------------------------------------------------------------- html

_CSS = """
:root { --ok:#1e7d32; --okbg:#e8f5e9; --bad:#b71c1c; --badbg:#ffebee; --err:#8a4b00; --errbg:#fff3e0;
        --line:#d0d7de; --muted:#57606a; }
* { box-sizing: border-box; }
body { font-family: -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; margin: 0; color:#1f2328;
       line-height: 1.5; background:#fff; }
main { max-width: 1280px; margin: 0 auto; padding: 24px 32px 64px; }
h1 { font-size: 1.9em; border-bottom: 2px solid var(--line); padding-bottom: .3em; }
h2 { font-size: 1.45em; border-bottom: 1px solid var(--line); padding-bottom: .25em; margin-top: 2em; }
h3 { font-size: 1.2em; margin-top: 1.6em; }
h4 { font-size: 1.02em; margin: 1.3em 0 .4em; color:#24292f; }
section.case { border: 1px solid var(--line); border-radius: 8px; padding: 8px 22px 18px; margin: 26px 0;
               background: #fff; }
section.case > h3 { margin-top: .6em; }
.meta { color: var(--muted); font-size: .92em; }
.verdict { font-size: 1.15em; font-weight: 600; padding: 10px 14px; border-radius: 6px; display: inline-block; }
.verdict.ok { background: var(--okbg); color: var(--ok); }
.verdict.bad { background: var(--badbg); color: var(--bad); }
.criterion { color: var(--muted); font-size: .92em; max-width: 960px; }
.tablewrap { overflow-x: auto; margin: 8px 0 12px; }
table { border-collapse: collapse; font-size: .88em; }
th, td { border: 1px solid var(--line); padding: 4px 8px; vertical-align: top; }
th { background: #f6f8fa; text-align: left; white-space: nowrap; }
td.num { text-align: right; font-family: ui-monospace, SFMono-Regular, Menlo, Consolas, monospace;
         white-space: nowrap; }
tr.fail td { background: var(--badbg); }
tr.error td { background: var(--errbg); }
.badge { display: inline-block; padding: 1px 8px; border-radius: 10px; font-size: .8em; font-weight: 700;
         letter-spacing: .03em; }
.badge.PASS { background: var(--okbg); color: var(--ok); }
.badge.FAIL { background: var(--badbg); color: var(--bad); }
.badge.ERROR { background: var(--errbg); color: var(--err); }
figure { margin: 10px 0 14px; display: inline-block; vertical-align: top; max-width: 100%; }
figure img { max-width: 100%; height: auto; border: 1px solid #eaeef2; border-radius: 4px; }
figcaption { color: var(--muted); font-size: .85em; text-align: center; }
.note { color: var(--muted); font-style: italic; border-left: 3px solid var(--line); padding-left: 10px; }
.error { background: var(--errbg); border-left: 4px solid var(--err); padding: 8px 12px; border-radius: 4px; }
pre { background: #f6f8fa; padding: 10px; overflow-x: auto; font-size: .85em; border-radius: 4px; }
code { font-family: ui-monospace, SFMono-Regular, Menlo, Consolas, monospace; font-size: .92em; }
.math { font-family: "Cambria Math", "STIX Two Math", "Latin Modern Math", Georgia, serif; color:#0a3069;
        background: #f3f6fb; padding: 0 3px; border-radius: 3px; white-space: pre-wrap; }
.math.display { display: block; margin: 6px 0; padding: 6px 10px; overflow-x: auto; }
.disc-case { margin: .6em 0 .2em; font-weight: 600; }
nav.toc { font-size: .9em; color: var(--muted); }
nav.toc a { margin-right: .6em; }
a { color: #0969da; text-decoration: none; }
a:hover { text-decoration: underline; }
"""


def _e(s: Any) -> str:
    return html.escape(str(s), quote=True)


def _html_table(header: Sequence[str], rows: Sequence[Sequence[str]], num_cols: Sequence[int] = (),
                row_classes: Sequence[str] | None = None, raw_cols: Sequence[int] = ()) -> str:
    h = "".join(f"<th>{_e(c)}</th>" for c in header)
    body = []
    for i, r in enumerate(rows):
        cls = f' class="{row_classes[i]}"' if row_classes and row_classes[i] else ""
        cells = []
        for j, c in enumerate(r):
            content = c if j in raw_cols else _e(c)
            cells.append(f'<td class="num">{content}</td>' if j in num_cols else f"<td>{content}</td>")
        body.append(f"<tr{cls}>" + "".join(cells) + "</tr>")
    return (f'<div class="tablewrap"><table><thead><tr>{h}</tr></thead><tbody>'
            + "\n".join(body) + "</tbody></table></div>")


def _badge(status: str) -> str:
    return f'<span class="badge {_e(status)}">{_e(status)}</span>'


def _html_quantity_table(rows_src: Sequence[tuple[int, Quantity]]) -> str:
    rows, classes = [], []
    for number, q in rows_src:
        cells = _row_cells(number, q)
        cells = [_e(c) for c in cells]
        cells[-1] = _badge("PASS" if cells[-1] == "PASS" else "FAIL")
        rows.append(cells)
        classes.append("" if _safe(lambda q=q: q.passed, False) else "fail")
    return _html_table(COLUMNS, rows, num_cols=_NUM_COLS, row_classes=classes,
                       raw_cols=tuple(range(len(COLUMNS))))


def _html_figure(f: _Figure) -> str:
    if f.png is not None:
        data = base64.b64encode(f.png).decode("ascii")
        return (f'<figure><img alt="{_e(f.title)}" src="data:image/png;base64,{data}">'
                f"<figcaption>{_e(f.title)}</figcaption></figure>")
    return f'<p class="note">{_e(f.note)}</p>'


def _html_list(items: Iterable[str]) -> str:
    return "<ul>" + "".join(f"<li>{_md_html(str(s).strip(), inline=True)}</li>" for s in items) + "</ul>"


def _html(docs: Sequence[_CaseDoc], generated: str) -> str:
    c = _counts(docs)
    ok = c["cases_passed"] == c["cases"] and c["cases"] > 0
    parts: list[str] = []
    parts.append("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
                 "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
                 "<title>mbdsim validation report</title>\n"
                 f"<style>{_CSS}</style>\n</head>\n<body>\n<main>\n")
    parts.append("<h1>mbdsim validation report</h1>")
    parts.append(f'<p class="meta">Generated {_e(generated)} with {_e(_environment())}.<br>'
                 f"Reference problems: {_md_html(MANUAL, inline=True)} "
                 "(the 30 problems of the validation manual).</p>")
    verdict = (f"{'ALL PASS' if ok else 'FAILURES'}: {c['cases_passed']}/{c['cases']} cases passed, "
               f"{c['quantities_passed']}/{c['quantities']} quantities passed")
    if c["cases_error"]:
        verdict += f", {c['cases_error']} case(s) raised an error"
    parts.append(f'<p><span class="verdict {"ok" if ok else "bad"}">{_e(verdict)}</span></p>')
    parts.append(f'<p class="criterion">{_e(CRITERION)}</p>')
    parts.append('<nav class="toc">Jump to: <a href="#summary">summary</a> '
                 '<a href="#discrepancies">manual discrepancies</a> '
                 '<a href="#quantities">all quantities</a> <a href="#cases">cases</a></nav>')

    # summary
    parts.append('<h2 id="summary">Summary</h2>')
    rows = _summary_rows(docs, lambda d: f'<a href="#{d.anchor}">{d.number:02d}</a>')
    esc_rows, classes = [], []
    for d, r in zip(docs, rows):
        cells = [r[0]] + [_e(x) for x in r[1:]]
        cells[7] = _badge(d.status)
        esc_rows.append(cells)
        classes.append({"PASS": "", "FAIL": "fail", "ERROR": "error"}[d.status])
    parts.append(_html_table(_SUMMARY_HEADER, esc_rows, num_cols=(3, 4, 5, 6, 8), row_classes=classes,
                             raw_cols=tuple(range(len(_SUMMARY_HEADER)))))

    # discrepancies
    parts.append('<h2 id="discrepancies">Manual discrepancies found</h2>')
    any_disc = False
    for d in docs:
        disc = list(d.outcome.info.discrepancies or [])
        if not disc:
            continue
        any_disc = True
        parts.append(f'<p class="disc-case"><a href="#{d.anchor}">Case {d.number:02d}</a>: '
                     f"{_e(d.outcome.info.title)}</p>")
        parts.append(_html_list(disc))
    if not any_disc:
        parts.append("<p>None found in the cases run.</p>")

    # all quantities
    parts.append('<h2 id="quantities">All compared quantities</h2>')
    allq = [(d.number, q) for d in docs for q in d.outcome.quantities]
    parts.append(_html_quantity_table(allq) if allq else "<p>No quantities.</p>")

    # cases
    parts.append('<h2 id="cases">Cases</h2>')
    for d in docs:
        parts.append(_html_case(d))
    parts.append("</main>\n</body>\n</html>\n")
    return "\n".join(parts)


def _html_case(d: _CaseDoc) -> str:
    o, info = d.outcome, d.outcome.info
    p: list[str] = [f'<section class="case" id="{d.anchor}">']
    p.append(f"<h3>Case {d.number:02d}: {_e(info.title)} {_badge(d.status)}</h3>")
    meta = []
    if info.reference:
        meta.append(f"<b>Reference:</b> {_e(info.reference)}")
    if info.analysis:
        meta.append(f"<b>Analysis:</b> {_e(info.analysis)}")
    if info.slug:
        meta.append(f"<b>Module:</b> <code>{_e(info.slug)}</code>")
    elapsed = getattr(o, "elapsed_s", None)
    if elapsed is not None:
        meta.append(f"<b>Run time:</b> {float(elapsed):.2f} s")
    if meta:
        p.append(f'<p class="meta">{" · ".join(meta)}</p>')
    err = outcome_error(o)
    if err:
        p.append(f'<div class="error"><b>ERROR:</b> {_e(err)}</div>')
        tb = getattr(o, "traceback", "")
        if tb:
            p.append(f"<details><summary>Traceback</summary><pre>{_e(tb)}</pre></details>")
    if info.statement:
        p.append("<h4>Problem statement</h4>")
        p.append(_md_html(str(info.statement)))
    if info.reconstruction:
        p.append("<h4>Reconstruction</h4>")
        p.append(_md_html(str(info.reconstruction)))
    for f in d.figures:
        if f.kind == "mechanism":
            p.append(_html_figure(f))
    plots = [f for f in d.figures if f.kind == "plot"]
    if plots:
        p.append("<h4>Plots</h4>")
        p.append("<div>" + "".join(_html_figure(f) for f in plots) + "</div>")
    if o.quantities:
        p.append("<h4>Comparison</h4>")
        p.append(_html_quantity_table([(d.number, q) for q in o.quantities]))
        qnotes = [(q.name, q.note) for q in o.quantities if q.note]
        if qnotes:
            p.append("<ul>" + "".join(f"<li><b>{_e(n)}:</b> {_md_html(str(t).strip(), inline=True)}</li>"
                                      for n, t in qnotes) + "</ul>")
    for heading, items in (("Notes", info.notes), ("Full-physics variants", o.variants),
                           ("Manual discrepancies", info.discrepancies)):
        items = list(items or [])
        if items:
            p.append(f"<h4>{_e(heading)}</h4>")
            p.append(_html_list(items))
    p.append("</section>")
    return "\n".join(p)


# --------------------------------------------------------------------------- entry point


def write_report(outcomes: Sequence[CaseOutcome], out_dir: str | Path) -> tuple[Path, Path]:
    """Write ``report.md``, ``report.html`` and ``figures/*.png`` into ``out_dir``.

    Returns ``(markdown_path, html_path)``.  Cases are ordered by number.  A figure that
    cannot be drawn is replaced by a note; the report itself is always written.
    """
    out = Path(out_dir)
    figdir = out / "figures"
    figdir.mkdir(parents=True, exist_ok=True)
    for stale in figdir.glob("case*.png"):  # figures of a previous run
        try:
            stale.unlink()
        except OSError:
            pass

    docs: list[_CaseDoc] = []
    for o in sorted(outcomes, key=lambda o: int(getattr(o.info, "number", 0))):
        d = _CaseDoc(o, case_status(o))
        d.figures = _render_figures(o)
        for f in d.figures:
            if f.png is not None and f.filename:
                (figdir / f.filename).write_bytes(f.png)
        docs.append(d)

    generated = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")
    md_path = out / "report.md"
    html_path = out / "report.html"
    md_path.write_text(_markdown(docs, generated), encoding="utf-8")
    html_path.write_text(_html(docs, generated), encoding="utf-8")
    return md_path, html_path
