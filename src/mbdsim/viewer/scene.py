"""The data a viewer page plays: bodies (shape, pose per frame), joints, springs, contact shapes, signal.

Everything is in SI units and ground axes, as plain lists ready for JSON.  Body-fixed items (joint
markers, spring ends, contact shapes) are given in body axes relative to the body's centre of mass, so
the page moves them with their body; items on ground have body index -1.
"""
from __future__ import annotations

from dataclasses import dataclass, field
import numpy as np

from ..errors import ModelError
from ..model.shapes import Sphere

MAX_FRAMES = 2000
PALETTE = ("#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#76b7b2", "#edc948", "#b07aa1", "#ff9da7",
           "#9c755f", "#bab0ac")


@dataclass
class Scene:
    """Plain-data scene of a Result; `to_json()` gives what the page's `mbdsimViewer` plays."""

    title: str
    up: list
    scale: float
    time: list
    bodies: list = field(default_factory=list)
    joints: list = field(default_factory=list)
    springs: list = field(default_factory=list)
    shapes: list = field(default_factory=list)
    signal: dict | None = None
    trails: bool = False      # draw each body's centre-of-mass path
    # shape-contact forces drawn as arrows: {"scale": arrow length per force [m/N], "frames": per frame a flat
    # list x, y, z [m], Fx, Fy, Fz [N] of each touching point (force on shape_j, ground axes)}; None: not drawn
    contact_forces: dict | None = None

    def to_json(self) -> dict:
        """The scene as a JSON-ready dict."""
        return {"title": self.title, "up": self.up, "scale": self.scale, "time": self.time,
                "bodies": self.bodies, "joints": self.joints, "springs": self.springs,
                "shapes": self.shapes, "signal": self.signal, "trails": self.trails,
                "contact_forces": self.contact_forces}


def frame_indices(n: int, max_frames: int = MAX_FRAMES) -> np.ndarray:
    """At most `max_frames` sample indices out of n, evenly spread, first and last included."""
    if max_frames < 2:
        raise ModelError("animation", "max_frames", f"must be >= 2, got {max_frames!r}")
    if n <= max_frames:
        return np.arange(n)
    return np.unique(np.round(np.linspace(0, n - 1, max_frames)).astype(int))


def equivalent_box(mass: float, inertia: np.ndarray, minimum: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Sides [m] (3,) and principal axes (3x3, columns, body axes) of the uniform box with the body's mass
    and inertia about its CM (I1 = m (b^2 + c^2) / 12 ...); sides below `minimum` are raised to it.
    None when the body has no mass or no inertia."""
    J = 0.5 * (np.asarray(inertia, float) + np.asarray(inertia, float).T)
    if mass <= 0 or not np.any(J):
        return None
    moments, axes = np.linalg.eigh(J)
    total = moments.sum()
    sq = 6.0 / mass * (total - 2.0 * moments)          # a^2 = 6/m (I2 + I3 - I1), cyclic
    sides = np.sqrt(np.clip(sq, 0.0, None))
    if np.linalg.det(axes) < 0:
        axes[:, 2] *= -1
    return np.maximum(sides, minimum), axes


def quaternions(R: np.ndarray) -> np.ndarray:
    """Rotation matrices (N, 3, 3) -> unit quaternions (N, 4) as (x, y, z, w) (three.js order)."""
    from scipy.spatial.transform import Rotation
    return Rotation.from_matrix(R).as_quat()


def _r(a, digits=6) -> list:
    """Round for a compact JSON (6 significant digits is well below a pixel)."""
    a = np.asarray(a, dtype=float)
    return [float(f"{x:.{digits}g}") if np.isfinite(x) else None for x in a.ravel()]


def _local(body, point_ground) -> list:
    """A point given in ground at t=0 -> body axes from the body's CM (as markers are stored)."""
    return _r(body.orientation.T @ (np.asarray(point_ground, float) - body.position))


def build_scene(res, signal=None, geometry: dict | None = None, max_frames: int = MAX_FRAMES,
                title: str | None = None, contact_forces: bool = False) -> Scene:
    """Extract the scene of a Result: at most `max_frames` frames; `signal` as in `mbdsim.plot` (or None);
    `geometry` maps a body (or its name) to an mb.Sphere drawn instead of its equivalent box (its centre
    in ground at t=0, default the body's CM); `contact_forces`: the force at each touching point of the
    shape contacts, per frame (Scene.contact_forces, drawn as arrows)."""
    system, model = res.system, res.system.model
    if len(res.time) == 0:
        raise ModelError("animation", "result", "the result holds no samples")
    idx = frame_indices(len(res.time), max_frames)
    sub = res._subset(idx) if len(idx) < len(res.time) else res  # noqa: SLF001 - same Result API, fewer rows
    bodies = [b for b in system.bodies if not b.is_ground]
    index = {b.name: k for k, b in enumerate(bodies)}
    pos = {b.name: np.asarray(sub.position(b)) for b in bodies}
    scale = _scale(model, pos)
    g = np.asarray(model.gravity, float)
    up = _r(-g / np.linalg.norm(g)) if np.linalg.norm(g) > 0 else [0.0, 1.0, 0.0]
    scene = Scene(title or model.name, up, float(f"{scale:.6g}"), _r(sub.time, 9))
    given = _given_geometry(geometry or {}, model)
    for k, b in enumerate(bodies):
        quat = np.tile([0.0, 0.0, 0.0, 1.0], (len(idx), 1)) if b.is_particle else quaternions(sub.orientation(b))
        scene.bodies.append({"name": b.name, "color": PALETTE[k % len(PALETTE)],
                             "shape": _body_shape(b, given.get(b.name), scale, model),
                             "pos": _r(pos[b.name]), "quat": _r(quat)})
    scene.joints = [_joint(j, index) for j in model.joints.values()]
    scene.springs, scene.shapes = _elements(model, index)
    from ..geometry.visual import body_meshes   # shapes placed with Body.add_shape (issue 30)
    for b in [model.ground] + [b for b in system.bodies if not b.is_ground]:   # ground's shapes too
        for d in body_meshes(b):
            color = "#9aa5b1" if b.is_ground else scene.bodies[index[b.name]]["color"]
            scene.shapes.append({**d, "body": _on(b, index), "color": color})
    if signal is not None:
        scene.signal = _signal(sub, signal)
    if contact_forces:
        scene.contact_forces = _contact_forces(sub, model, scale)
    return scene


def _contact_forces(res, model, scale: float) -> dict:
    """Scene.contact_forces: every contact's touching points and forces (on shape_j) per frame; a
    force of the 90th percentile of all point forces of the run is drawn 0.1 scene sizes long (so that
    impact peaks do not shrink resting forces out of sight; the page caps arrows at 0.3 scene sizes)."""
    from ..model.contacts import ShapeContact
    from ..model.element_specs import Contact
    from ..results.contacts import _records
    frames = [[] for _ in res.time]
    for el in model.forces.values():
        if isinstance(el, Contact):   # the exact sphere-plane / sphere-sphere contact: its own evaluator
            from ..system.force_elements.contact import _forces, contact_state
            g, n, cp, v_rel = contact_state(res.system, res.frames, el)
            Fn, _, _, Ft = _forces(el, g, n, v_rel)
            F = Fn[:, None] * n + Ft
            for k in np.nonzero(Fn > 0)[0]:
                frames[k].extend(np.concatenate([cp[k], F[k]]))
        elif isinstance(el, ShapeContact):
            for k, rc in enumerate(_records(res, el)):
                if len(rc):
                    F = rc[:, 8:9] * rc[:, 4:7] + rc[:, 9:12]
                    frames[k].extend(np.column_stack([rc[:, 1:4], F]).ravel())
    mags = np.concatenate([np.linalg.norm(np.reshape(f, (-1, 6))[:, 3:], axis=1) for f in frames if f] or
                          [np.zeros(0)])
    ref = float(np.percentile(mags, 90)) if len(mags) else 0.0
    return {"scale": float(f"{0.1 * scale / ref:.6g}") if ref > 0 else 0.0, "frames": [_r(f) for f in frames]}


def _scale(model, pos: dict) -> float:
    """Size of the scene [m]: the diagonal of the box holding every body's path and every joint."""
    pts = [p for p in pos.values()] + [np.atleast_2d(j.point) for j in model.joints.values()]
    pts = np.concatenate(pts) if pts else np.zeros((1, 3))
    ext = float(np.linalg.norm(pts.max(0) - pts.min(0)))
    return ext if ext > 1e-9 else 1.0


def _given_geometry(geometry: dict, model) -> dict:
    out = {}
    for key, shape in geometry.items():
        name = getattr(key, "name", key)
        if name not in model.bodies or name == "ground":
            raise ModelError(f"geometry for {name!r}", "geometry", "is not a (moving) body of the model")
        if not isinstance(shape, Sphere):
            raise ModelError(f"geometry for {name!r}", "geometry", f"expected an mb.Sphere, got {shape!r}")
        out[name] = shape
    return out


def _body_shape(body, given, scale: float, model) -> dict:
    """Shape of a body in body axes: given geometry, else {"kind": "shapes"} for a body with shapes placed
    by Body.add_shape (drawn by them, in Scene.shapes), else its own contact sphere, else the equivalent box."""
    if given is None and body.shapes:
        return {"kind": "shapes"}
    shape = given if given is not None else _contact_sphere(body, model)
    if shape is not None:
        return _shape_dict(body, shape)
    minimum = 0.02 * scale
    box = None if body.is_particle else equivalent_box(body.mass, body.inertia, minimum)
    if box is None:
        return {"kind": "sphere", "radius": float(f"{0.03 * scale:.6g}"), "center": [0.0, 0.0, 0.0]}
    sides, axes = box
    return {"kind": "box", "size": _r(sides), "quat": _r(quaternions(axes[None])[0])}


def _contact_sphere(body, model):
    for el in model.forces.values():
        for sh in (getattr(el, "shape_i", None), getattr(el, "shape_j", None)):
            if sh is not None and sh.kind == "sphere" and sh.body is body:
                return sh.source
    return None


def _shape_dict(body, shape) -> dict:
    """An mb.Sphere in body axes (its centre from the body's CM)."""
    c = [0.0, 0.0, 0.0] if shape.center is None else _local(body, shape.center)
    return {"kind": "sphere", "radius": float(shape.radius), "center": c}


def _on(body, index) -> int:
    return -1 if body.is_ground else index[body.name]


def _joint(j, index) -> dict:
    """A joint marker, drawn on body_j (on body_i when body_j is ground)."""
    body = j.body_i if j.body_j.is_ground else j.body_j
    axis = body.orientation.T @ np.asarray(j.axis, float)
    return {"name": j.name, "kind": j.kind, "body": _on(body, index), "local": _local(body, j.point),
            "axis": _r(axis)}


def _end(marker, index) -> dict:
    return {"body": _on(marker.body, index), "local": _r(marker.s_B)}


def _elements(model, index) -> tuple[list, list]:
    springs, shapes = [], []
    for el in model.forces.values():
        kind = type(el).__name__
        if kind in ("SpringDamper", "Bushing"):
            springs.append({"name": el.name, "kind": "coil" if kind == "SpringDamper" else "line",
                            "i": _end(el.marker_i, index), "j": _end(el.marker_j, index)})
        elif kind == "Contact":
            for sh in (el.shape_i, el.shape_j):
                d = {"contact": el.name, "kind": sh.kind, "body": _on(sh.body, index), "local": _r(sh.s_B)}
                if sh.kind == "sphere":
                    d["radius"] = float(sh.radius)
                else:
                    d["normal"] = _r(sh.n_B)
                if d not in shapes:
                    shapes.append(d)
    return springs, shapes


def _signal(res, spec) -> dict:
    from ..plotting import resolve
    s = resolve(res, spec)
    vals = s.values.reshape(len(s.values), -1)
    comps = s.components or (("",) if vals.shape[1] == 1 else tuple(str(k) for k in range(vals.shape[1])))
    return {"label": s.label, "unit": s.unit,
            "series": [{"name": (f"{s.label} {c}".strip()), "values": _r(vals[:, k])} for k, c in enumerate(comps)]}



def scene_from_table(df, signal=None, max_frames: int = MAX_FRAMES, title: str = "results") -> Scene:
    """A scene from an exported results table (`res.to_dataframe()` read back from .csv/.parquet).

    Such a table holds centre-of-mass positions only ("<body>.x [m]", ".y", ".z"): every body is drawn
    as a sphere at its centre of mass without rotation, with its path; no joints or force elements (a shape
    contact's centre of pressure, "<contact>.x [m]" beside "<contact>.nx [-]", is not a body).  `signal` is a
    column name (matched leniently) or None."""
    from ..plotting import TIME_COLUMN, match_column
    time_col = match_column(df.columns, TIME_COLUMN)
    names = [c[:-len(".x [m]")] for c in df.columns if str(c).endswith(".x [m]")]
    names = [n for n in names if f"{n}.nx [-]" not in df.columns]   # a shape contact's centre of pressure
    if not names:
        raise ModelError(f"results table {title!r}", "columns", "has no body position columns "
                         "('<body>.x [m]', '.y [m]', '.z [m]'); was it written from res.to_dataframe()?")
    idx = frame_indices(len(df), max_frames)
    sub = df.iloc[idx].reset_index(drop=True)
    pos = {n: sub[[f"{n}.{a} [m]" for a in "xyz"]].to_numpy(dtype=float) for n in names}
    pts = np.concatenate(list(pos.values()))
    ext = float(np.linalg.norm(pts.max(0) - pts.min(0)))
    scale = ext if ext > 1e-9 else 1.0
    scene = Scene(title, [0.0, 1.0, 0.0], float(f"{scale:.6g}"), _r(sub[time_col], 9), trails=True)
    sphere = {"kind": "sphere", "radius": float(f"{0.03 * scale:.6g}"), "center": [0.0, 0.0, 0.0]}
    for k, n in enumerate(names):
        scene.bodies.append({"name": n, "color": PALETTE[k % len(PALETTE)], "shape": sphere,
                             "pos": _r(pos[n]), "quat": _r(np.tile([0.0, 0.0, 0.0, 1.0], (len(sub), 1)))})
    if signal is not None:
        scene.signal = _signal(sub, signal)
    return scene
