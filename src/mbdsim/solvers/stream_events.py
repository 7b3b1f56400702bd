"""What a streamed run (solvers.stream) carries between kernel calls and parts besides the integrator's
state, for joint friction and sensors (issue 29): the kernel's carried values, saved for a window's redo,
and the checkpoint's event state (JSON), restored when a run resumes."""
from __future__ import annotations

import json

import numpy as np


def sensor_stop(run, t_stop, y, Y, iout, g0, times):
    """(outputs, Y, whether a row was added) after a sensor's stop at t_stop [s] with the integrator's
    state y there: that state (absolute coordinates) as the part's last row unless an output is at t_stop
    (as in memory, compiled_run.integrate_compiled); Y grown by a row when full."""
    from . import fastdyn
    ya = np.zeros(Y.shape[1])
    if run.joint_space:
        fastdyn.write_state(run.cm.arrays(), run.work.arrays(), y.copy(), ya, Y[iout - 1] if iout else ya[:0])
    else:
        ya[:] = y
    if iout and t_stop <= times[g0 + iout - 1] + 1e-14 * max(1.0, abs(t_stop)):
        return iout, Y, False
    if iout >= len(Y):
        Y = np.concatenate([Y, np.zeros((1, Y.shape[1]))])
    Y[iout] = ya
    return iout + 1, Y, True


def event_state(run):
    """What the kernel carries from one accepted step to the next besides the state: the friction switching
    values (wk[50][2]), the sensors' values and event count (wk[44][2], [5]) and the loop rows in use with
    their re-selection threshold (wk[46], [47]; solvers.fastsolve._reselect), copied."""
    w = run.work.arrays()
    return w[50][2].copy(), w[44][2].copy(), w[44][5].copy(), w[46].copy(), w[47].copy()


def set_event_state(run, saved):
    """The values of `event_state` back into the run's work arrays."""
    w = run.work.arrays()
    w[50][2][:], w[44][2][:], w[44][5][:], w[46][:], w[47][:] = saved


def events(run) -> str:
    """What a resumed run continues from besides the state, as JSON: the kernel's carried values
    (`event_state`), the sensor events met, the friction elements' mode histories and held groups
    (solvers.friction_run)."""
    gp, gs, _, sel, lim = event_state(run)
    out = {"friction_g": gp.tolist(), "sensor_g": gs.tolist(), "loop_rows": sel.tolist(),
           "loop_limits": lim.tolist(), "sensor_events": [[e.name, e.time, e.value, e.action] for e in run.sensor_events]}
    if run.friction is not None:
        sw = run.sys.switched
        out["modes"] = {n: [sw[n].times, [list(m) for m in sw[n].modes]] for n in run.friction.names}
        out["groups"] = [[t, g.tolist(), c.tolist()] for t, g, c in run.friction.groups_at]
        base = run.sys.derived.get("friction_base_rows")   # the decisions' independent rows, chosen at their
        out["base_rows"] = None if base is None else np.asarray(base).tolist()   # first use: kept as chosen
    return json.dumps(out)


def restore(run, text, t_now) -> None:
    """The event state of `events` back into the run at the carried time t_now [s] (its System's
    histories, the kernel's arrays)."""
    from .sensors import SensorEvent
    if text is None:   # a checkpoint of an older mbdsim (a run without events)
        return
    ev = json.loads(text)
    w = run.work.arrays()
    run.sensor_events = [SensorEvent(n, float(t), float(v), a) for n, t, v, a in ev.get("sensor_events", ())]
    if run.friction is not None and "modes" in ev:
        for n, (ts, modes) in ev["modes"].items():
            st = run.sys.switched[n]
            st.times[:] = [float(t) for t in ts]
            st.modes[:] = [(m, float(d), float(x)) for m, d, x in modes]
        run.friction.groups_at = [(float(t), np.array(g, np.int64), np.array(c, float).reshape(len(g), len(g)))
                                  for t, g, c in ev["groups"]]
        run.friction.set_modes(float(t_now))   # the modes in force at the carried time, into wk[50]
        if ev.get("base_rows") is not None:
            run.sys.derived["friction_base_rows"] = np.array(ev["base_rows"], dtype=np.int64)
    for (i, j), key in (((50, 2), "friction_g"), ((44, 2), "sensor_g")):
        if key in ev:
            w[i][j][:] = ev[key]
    if "loop_rows" in ev:
        w[46][:], w[47][:] = ev["loop_rows"], ev["loop_limits"]
