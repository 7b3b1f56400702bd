"""HTML summaries of a Model and a Result for Jupyter (`_repr_html_`): tables of bodies, joints,
drivers and force elements; time span, samples, outcome and solver statistics.  SI units."""
from __future__ import annotations

from html import escape

import numpy as np

_STYLE = ("<style>.mbdsim-t{border-collapse:collapse;font-size:12px;margin:2px 0 8px}"
          ".mbdsim-t th,.mbdsim-t td{border:1px solid #ccd;padding:2px 6px;text-align:left}"
          ".mbdsim-t th{background:#eef}</style>")


def _fmt(x) -> str:
    if isinstance(x, (float, np.floating)):
        return f"{x:.6g}"
    if isinstance(x, np.ndarray):
        return "(" + ", ".join(f"{v:.4g}" for v in x.ravel()) + ")"
    return str(x)


def table(caption: str, header: list[str], rows: list[list]) -> str:
    """An HTML table (cells escaped) with a bold caption line; empty string when there are no rows."""
    if not rows:
        return ""
    head = "".join(f"<th>{escape(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{escape(_fmt(c))}</td>" for c in r) + "</tr>" for r in rows)
    return f"<b>{escape(caption)}</b><table class='mbdsim-t'><tr>{head}</tr>{body}</table>"


def _name(x) -> str:
    return str(getattr(x, "name", x))


def _connects(el) -> str:
    for a, b in (("marker_i", "marker_j"), ("shape_i", "shape_j")):
        if hasattr(el, a):
            return f"{_name(getattr(el, a).body)} - {_name(getattr(el, b).body)}"
    if hasattr(el, "joint"):
        return f"joint {_name(el.joint)}"
    if hasattr(el, "body"):
        return _name(el.body)
    return ""


def model_html(model) -> str:
    """Summary of a Model: gravity, then bodies, joints, drivers and force elements as tables."""
    bodies = [[b.name, "particle" if b.is_particle else "body", b.mass, np.diag(b.inertia), b.position]
              for b in model.bodies.values() if not b.is_ground]
    joints = [[j.name, j.kind, j.body_i.name, j.body_j.name, j.point, j.axis] for j in model.joints.values()]
    motions = [[m.name, _name(m.joint), m.kind, getattr(m, "dof", "")] for m in model.motions.values()]
    forces = [[e.name, type(e).__name__, _connects(e)] for e in model.forces.values()]
    return (_STYLE + f"<div><b>mbdsim Model {escape(model.name)!s}</b>: {len(bodies)} bodies, {len(joints)} "
            f"joints, {len(motions)} drivers, {len(forces)} force elements; gravity {_fmt(model.gravity)} m/s<sup>2"
            "</sup><br>"
            + table("bodies", ["name", "kind", "mass [kg]", "inertia diag [kg m^2]", "position [m]"], bodies)
            + table("joints", ["name", "kind", "body_i", "body_j", "point [m]", "axis"], joints)
            + table("drivers", ["name", "joint", "given", "dof"], motions)
            + table("force elements", ["name", "type", "acts on"], forces) + "</div>")


def result_html(res) -> str:
    """Summary of a Result: model, time span, samples, success, message and solver statistics."""
    t = np.asarray(res.time, dtype=float)
    span = f"{t[0]:.6g} .. {t[-1]:.6g} s" if len(t) else "(empty)"
    stats = {k: v for k, v in (res.stats or {}).items() if isinstance(v, (int, float, str, np.number))}
    rows = [["model", res.system.model.name], ["time span", span], ["samples", len(t)],
            ["success", bool(res.success)], ["message", res.message]] + [[k, v] for k, v in stats.items()]
    colour = "#1a7f37" if res.success else "#b00020"
    return (_STYLE + f"<div><b>mbdsim Result</b> <span style='color:{colour}'>"
            f"{'success' if res.success else 'failed'}</span>"
            + table("run", ["", "value"], rows) + "</div>")
