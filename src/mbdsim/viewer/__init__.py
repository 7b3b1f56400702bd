"""3D browser viewer: `animate(res_or_model, path)` writes a self-contained HTML page playing a Result.

The page needs no network: three.js (npm `three`, MIT licence, see static/THREE_LICENSE) is inlined.
In the page, `window.mbdsimViewer.setTime(t)` poses the mechanism at time t [s] (and pauses),
`play()` / `pause()` control playback.
"""
from __future__ import annotations

from pathlib import Path

from ..errors import ModelError
from .page import THREE_VERSION, build_page
from ..plotting import TIME_COLUMN, match_column
from .scene import MAX_FRAMES, Scene, build_scene, scene_from_table
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..model.model import Model
    from .._types import PathLike
    from typing import Any
    import pandas as pd
    from ..results.result import Result

__all__ = ["animate", "build_page", "build_scene", "Scene", "MAX_FRAMES", "THREE_VERSION", "default_signal"]


def default_signal(columns) -> str | None:
    """The first joint coordinate column ("pin.angle [rad]", "slider.displacement [m]") among `columns`
    (those of `res.to_dataframe()`), or None."""
    for col in columns:
        if str(col).endswith((".angle [rad]", ".displacement [m]")):
            return str(col)
    return None


def _result(res_or_model, end_time):
    from ..model import Model
    if isinstance(res_or_model, Model):
        from ..solvers.dynamic import simulate
        end = 2.0 if end_time is None else _end_time(end_time)
        return simulate(res_or_model, end_time=end, output_step=end / 1000.0)
    if not hasattr(res_or_model, "system") or not hasattr(res_or_model, "time"):
        raise ModelError("animation", "result", f"expected an mbdsim Result or Model, got {type(res_or_model).__name__}")
    if end_time is None:
        return res_or_model
    end = _end_time(end_time)
    keep = [k for k, t in enumerate(res_or_model.time) if t <= end + 1e-12 * max(1.0, end)]
    if not keep:
        raise ModelError("animation", "end_time", f"{end!r} s is before the result's first sample")
    return res_or_model._subset(keep)  # noqa: SLF001 - same Result API, fewer rows


def _end_time(end_time) -> float:
    try:
        end = float(end_time)
    except (TypeError, ValueError):
        raise ModelError("animation", "end_time", f"must be a number of seconds, got {end_time!r}") from None
    if not end > 0 or end != end or end == float("inf"):
        raise ModelError("animation", "end_time", f"must be a positive finite time [s], got {end_time!r}")
    return end


def animate(res_or_model: Result | Model | pd.DataFrame, path: PathLike = "anim.html", signal: str | None = "auto",
            end_time: float | None = None, geometry: dict[str, Any] | None = None, max_frames: int = MAX_FRAMES,
            title: str | None = None, contact_forces: bool = False) -> Path:
    """Write a self-contained HTML page playing a Result (a Model is simulated first, over `end_time` [s],
    default 2 s, 1000 output steps; a DataFrame from `res.to_dataframe()` shows its bodies' centres of mass
    as spheres) and return its path.

    signal: shown as a value and a small chart beside the 3D view; a callable of the Result, a column of
    `res.to_dataframe()` or ("label [unit]", callable) as in `mbdsim.plot`; "auto" (default) picks the
    first joint coordinate, None shows none.  end_time: also cuts a Result at that time [s].
    geometry: {body or name: mb.Sphere} drawn instead of the body's equivalent-inertia box.
    Bodies move with positions and orientation quaternions sampled at <= `max_frames` frames.
    contact_forces: draw the force [N] on shape_j at each touching point of the contacts
    (Model.add_contact) as an arrow whose tip is at the point; a force of the run's 90th percentile is
    0.1 scene sizes long (docs/visualisation.md).
    """
    out = Path(path)
    if out.suffix.lower() not in (".html", ".htm"):
        raise ModelError("animation", "path", f"must end in .html, got {str(out)!r}")
    if hasattr(res_or_model, "columns") and hasattr(res_or_model, "iloc"):   # an exported results table
        df = res_or_model if end_time is None else \
            res_or_model[res_or_model[match_column(res_or_model.columns, TIME_COLUMN)] <= _end_time(end_time)]
        sig = default_signal(df.columns) if isinstance(signal, str) and signal == "auto" else signal
        if contact_forces:
            raise ModelError("animation", "contact_forces", "a results table holds no contact points: "
                             "animate the Result or the model")
        scene = scene_from_table(df, signal=sig, max_frames=max_frames, title=title or "results")
    else:
        res = _result(res_or_model, end_time)
        if isinstance(signal, str) and signal == "auto":
            signal = default_signal(res.to_dataframe().columns)
        scene = build_scene(res, signal=signal, geometry=geometry, max_frames=max_frames, title=title,
                            contact_forces=contact_forces)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(build_page(scene.to_json(), title), encoding="utf-8")
    return out
