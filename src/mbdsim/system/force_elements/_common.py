"""Shared kinematics of the issue-3 force elements: batching, scalar coordinates and their loads.

Evaluators receive single-state Frames (nframes, ...) in `generalized` and time-axis Frames
(N, nframes, ...) in `measure`/`potential`/`dissipation`; `batched` gives both a time axis.
A scalar coordinate x(q) with Jacobian rows (Rows of the constraint primitives, ground-axes virtual
rotations) turns a generalized load F along x into Q = F * dx/dv, which is exactly the virtual work of
F dx: conservative loads derived from a potential V(x) then conserve energy to integrator accuracy.
"""
from __future__ import annotations

import bisect

import numpy as np

from ..constraints import primitives as pr
from ..equations import scatter_jacobian
from ..frames import Frames
from ..measures import flat


def batched(fr: Frames) -> tuple[Frames, bool]:
    """Frames with a leading time axis and whether the input was a single state."""
    if fr.r.ndim == 3:
        return fr, False
    out = Frames(fr.r[None], fr.A[None], fr.rd[None], fr.w[None], angle=fr.angle)   # (angle: continuation)
    if hasattr(fr, "t"):
        out.t = np.atleast_1d(fr.t)
    return out, True


def times_of(fr: Frames, t=None, n=1) -> np.ndarray:
    """Sample times (n,) from t or the frames' `t` attribute (NaN when unknown)."""
    t = getattr(fr, "t", None) if t is None else t
    return np.full(n, np.nan) if t is None else np.broadcast_to(np.asarray(t, dtype=float), (n,))


def element_state(sys, name) -> dict:
    """Per-simulation mutable state of a force element (kept on the System, so every analysis starts fresh)."""
    store = sys.run_state.setdefault("elements", {})
    return store.setdefault(name, {})


def load_from_rows(sys, fr: Frames, rows: pr.Rows, F: float) -> np.ndarray:
    """Q (nv,) of a generalized load F along the coordinate whose single-sample Jacobian is `rows`."""
    out = np.zeros((1, sys.nv))
    scatter_jacobian(sys, fr, np.array([0]), rows, out)
    return F * out[0]


# ----------------------------------------------------------------------------- joint coordinates
WRAP_LIMIT = 0.75 * np.pi   # re-anchor the angle reference when |theta - ref| exceeds this [rad]


def _ref(sys, name, ts):
    """Angle reference [rad] in force at times ts: the last anchor at or before each time (0 before any)."""
    hist = element_state(sys, name).get("angle_ref", [])
    if not hist:
        return np.zeros(len(ts))
    tk = [h[0] for h in hist]
    out = np.zeros(len(ts))
    for n, t in enumerate(ts):
        k = bisect.bisect_right(tk, t) - 1 if np.isfinite(t) else len(hist) - 1
        out[n] = hist[k][1] if k >= 0 else 0.0
    return out


def joint_coordinate(sys, fr: Frames, joint, dof, owner, t=None):
    """Coordinate x (N,), rate xd (N,) and Jacobian Rows of a joint's rotation [rad] or slide [m].

    The angle is continued beyond +-pi: theta = ref(t) + wrap(theta_raw - ref(t)), exact as long as the
    true angle stays within pi of ref(t).  The anchors (t, theta) of element `owner` are recorded on
    the System from accepted states only, at the events of `angle_switch` (|theta - ref| = WRAP_LIMIT):
    trial states of rejected steps never move them.  Without event support (solvers that do not
    call switch/on_event) ref stays 0, i.e. theta is wrapped to (-pi, pi].  Frames of a Result carry
    `angle` (the angle continued by the Result along its run's steps, whichever solver ran): it is the
    reference then."""
    fb, _ = batched(fr)
    g = sys.geoms[joint.name]
    N = fb.r.shape[0]
    ff, bi, bj = flat(fb, g.bi, g.bj)
    rep = lambda x: np.broadcast_to(x, (N, 3))  # noqa: E731
    if dof == "rotation":
        raw, rows, rate = pr.angle(ff, bi, bj, rep(g.f_i), rep(g.g_i), rep(g.f_j))
        angle = getattr(fr, "angle", None)   # a Result's frames: its own continuation (any solver)
        ref = np.asarray(angle(joint), dtype=float).reshape(N) if angle is not None else \
            _ref(sys, owner, times_of(fb, t, N))
        x = ref + (raw - ref + np.pi) % (2 * np.pi) - np.pi
        return x, rate, rows
    rows = pr.dot2(ff, bi, bj, rep(g.h_i), rep(g.s_i), rep(g.s_j))
    return rows.phi, rows.rate, rows


def angle_switch(sys, fr, joint, owner, t) -> np.ndarray:
    """Switching function > 0 while the continued angle stays within WRAP_LIMIT of its reference."""
    x = joint_coordinate(sys, fr, joint, "rotation", owner, t)[0]
    ref = _ref(sys, owner, times_of(batched(fr)[0], t, len(x)))
    return np.cos(x - ref) - np.cos(WRAP_LIMIT)


def angle_reanchor(sys, fr, joint, owner, t):
    """After an (accepted) event at t: anchor the reference at the current angle if it has moved away."""
    x = float(joint_coordinate(sys, fr, joint, "rotation", owner, t)[0][0])
    if abs(x - _ref(sys, owner, [t])[0]) > 0.5 * WRAP_LIMIT:
        bisect.insort(element_state(sys, owner).setdefault("angle_ref", []), (float(t), x))
