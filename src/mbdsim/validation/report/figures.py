"""Figures of the validation report: the mechanism at t = 0 (x-y projection) and the manual's plots (matplotlib, lazily)."""
from __future__ import annotations

import io
from dataclasses import dataclass
from typing import Any

from mbdsim.validation.framework import CaseOutcome, Plot
from .format import _safe


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
