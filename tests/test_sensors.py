"""Sensors (Adams SENSOR, issue 11): stop or record when a signal reaches a value, located on the dense
output to solver precision.  Closed forms: a body falling from rest through a height h takes
sqrt(2 h / g); a pendulum released from theta_0 reaches the bottom after K(sin^2(theta_0 / 2)) /
sqrt(g / l) (a quarter period, complete elliptic integral K); a driven joint passes given angles at
known times.
"""
import numpy as np
import pytest
from scipy.special import ellipk

import mbdsim as mb
from mbdsim.errors import ModelError

G = 9.81


def falling(h=2.0):
    m = mb.Model("drop", gravity=(0, 0, -G))
    m.add_body("ball", 0.5, inertia=(0.01, 0.01, 0.01), position=(0, 0, h))
    return m


@pytest.mark.parametrize("method", ["auto", "dop853", "rk45"])
def test_falling_body_stops_at_the_floor(method):
    m = falling()
    m.add_sensor("floor", lambda t, s: s.position("ball")[2], value=0.0, direction=-1, action="stop")
    res = mb.simulate(m, 5.0, 0.01, method=method)
    t_hit = np.sqrt(2 * 2.0 / G)
    assert res.success and "stopped by sensor 'floor'" in res.message
    (ev,) = res.sensor_events
    assert ev.name == "floor" and ev.action == "stop"
    assert ev.time == pytest.approx(t_hit, abs=1e-9)
    assert res.time[-1] == pytest.approx(t_hit, abs=1e-9)        # the last sample is the event
    assert abs(res.position("ball")[-1, 2]) < 1e-8
    assert np.all(np.diff(res.time) > 0)


def test_record_keeps_running_and_threshold_alias():
    m = falling(h=10.0)
    m.add_sensor("half", lambda t, s: s.position("ball")[2], threshold=5.0, action="record")
    m.add_sensor("late", "t", value=0.75, direction=+1, action="record")
    res = mb.simulate(m, 1.2, 0.1)
    assert res.time[-1] == pytest.approx(1.2)
    names = [e.name for e in res.sensor_events]
    assert names == ["late", "half"]
    assert res.sensor_events[1].time == pytest.approx(np.sqrt(2 * 5.0 / G), abs=1e-9)
    assert res.sensor_events[0].time == pytest.approx(0.75, abs=1e-12)


def pendulum(theta0):
    """A point-like bob (particle, 1 kg) on a massless-rod-free revolute: a rigid body with its mass at
    distance l from the pin and no moment of inertia about its CM (simple pendulum), released at theta0."""
    l = 0.8
    m = mb.Model("pendulum", gravity=(0, -G, 0))
    m.add_body("bob", 1.0, inertia=(1e-12, 1e-12, 1e-12), position=(l * np.sin(theta0), -l * np.cos(theta0), 0))
    m.add_revolute("pin", "ground", "bob", (0, 0, 0), (0, 0, 1))
    return m, l


def test_pendulum_passes_the_bottom_at_the_elliptic_quarter_period():
    theta0 = np.radians(60)
    m, l = pendulum(theta0)
    # the joint angle is zero as built (theta0): the bottom is at -theta0
    m.add_sensor("bottom", "pin", value=-theta0, direction=-1, action="record")
    m.add_sensor("back", "pin_dot", value=0.0, direction=+1, action="stop")   # far turning point
    res = mb.simulate(m, 10.0, 0.01, rtol=1e-12)
    quarter = ellipk(np.sin(theta0 / 2) ** 2) / np.sqrt(G / l)
    ev = {e.name: e.time for e in res.sensor_events}
    assert ev["bottom"] == pytest.approx(quarter, rel=1e-9)
    assert ev["back"] == pytest.approx(2 * quarter, rel=1e-9)
    assert res.time[-1] == pytest.approx(2 * quarter, rel=1e-9)
    assert res.joint_coordinate("pin")[-1] == pytest.approx(-2 * theta0, abs=1e-7)   # symmetric swing
    assert "(compiled)" in res.stats["method"]   # expression sensors: watched inside the compiled step loop


def test_driven_angle_past_several_turns():
    """A motion at 3 rad/s: the (continuous) angle reaches 20 rad at 20/3 s, after three turns."""
    m = mb.Model("spin")
    m.add_body("disc", 1.0, inertia=(0.1, 0.1, 0.2))
    m.add_revolute("axle", "ground", "disc", (0, 0, 0), (0, 0, 1))
    m.add_motion("drive", "axle", velocity=3.0)
    m.add_sensor("twenty", "axle - 20", action="stop")
    res = mb.simulate(m, 30.0, 0.05)
    assert res.time[-1] == pytest.approx(20 / 3, abs=1e-9)
    assert "the kinematic sweep does not watch sensors" in res.stats["method"]   # integrated instead


def test_sensor_errors_name_the_field():
    m = falling()
    m.add_revolute("pin", "ground", "ball", (0, 0, 0), (0, 1, 0))
    for kw, field in [({"signal": "pin + nope"}, "signal"), ({"signal": 3.0}, "signal"),
                      ({"signal": "pin", "action": "halt"}, "action"),
                      ({"signal": "pin", "direction": 2}, "direction"),
                      ({"signal": "pin", "value": "x"}, "value"),
                      ({"signal": "pin", "value": 1.0, "threshold": 2.0}, "threshold")]:
        with pytest.raises(ModelError, match=f"sensor 's'.*{field}"):
            m.add_sensor("s", **kw)
        assert "s" not in m.__dict__.get("sensors", {})
    m.add_sensor("s", "pin")
    from mbdsim.solvers import dynamic
    compiled = dynamic.USE_COMPILED
    try:   # the compiled HHT watches sensors; the reference HHT does not
        dynamic.USE_COMPILED = False
        with pytest.raises(ModelError, match="sensor 's'.*method"):
            mb.simulate(m, 1.0, method="hht")
    finally:
        dynamic.USE_COMPILED = compiled


def test_compiled_expression_sensors_stop_and_record_at_the_closed_form_times():
    """Expression sensors run in the compiled DOP853's step loop: a crossing found at the end of an
    accepted step is located on that step's dense output (to 1e-13 s); a "stop" makes its state the last
    sample, "record" goes on, a direction filters. Free fall from 2 m: z = 1 at sqrt(2 / g), the floor at
    sqrt(4 / g); the rising crossing of z = 1.5 never happens."""
    m = falling()
    m.add_sensor("floor", "DZ(ball)", value=0.0, direction=-1, action="stop")
    m.add_sensor("half", "DZ(ball) - 1", action="record")
    m.add_sensor("rising", "DZ(ball)", value=1.5, direction=+1, action="record")
    m.add_sensor("late", "t", value=0.3, direction=+1, action="record")
    res = mb.simulate(m, 5.0, 0.01)
    assert "(compiled)" in res.stats["method"] and res.success
    assert "stopped by sensor 'floor'" in res.message
    ev = [(e.name, e.time, e.action) for e in res.sensor_events]
    assert [e[0] for e in ev] == ["late", "half", "floor"]
    assert ev[0][1] == pytest.approx(0.3, abs=1e-12)
    assert ev[1][1] == pytest.approx(np.sqrt(2 / G), abs=1e-12)
    assert ev[2][1] == pytest.approx(np.sqrt(4 / G), abs=1e-12) and ev[2][2] == "stop"
    assert res.time[-1] == ev[2][1] and np.all(np.diff(res.time) > 0)
    assert abs(res.position("ball")[-1, 2]) < 1e-12
    assert res.velocity("ball")[-1, 2] == pytest.approx(-np.sqrt(4 * G), rel=1e-10)


def test_compiled_sensor_events_beyond_the_buffer_and_the_reference_path_agree(monkeypatch):
    """More events than the kernel's buffer holds (handed over to Python when full): sin(40 t) crosses
    zero at k pi / 40, 127 times in 10 s (rising at the even k > 0; max_step keeps a step from holding two
    crossings of this signal, which a free fall does not resolve); and a pendulum's joint-angle sensor
    gives the same times on the compiled path and on the reference (scipy) path."""
    from mbdsim.solvers import dynamic
    from mbdsim.system import exprloads_pack
    m = falling(h=1e3)
    m.add_sensor("wave", "sin(40*t)", action="record")
    m.add_sensor("up", "sin(40*t)", direction=+1, action="record")
    res = mb.simulate(m, 10.0, 0.1, rtol=1e-10, max_step=0.01)
    assert "(compiled)" in res.stats["method"]
    times = {n: np.array([e.time for e in res.sensor_events if e.name == n]) for n in ("wave", "up")}
    assert len(times["wave"]) == 127 > exprloads_pack.EVENT_CAPACITY
    assert np.max(np.abs(times["wave"] - np.arange(1, 128) * np.pi / 40)) < 1e-10
    assert np.max(np.abs(times["up"] - np.arange(2, 128, 2) * np.pi / 40)) < 1e-10

    theta0 = np.radians(100)
    runs = {}
    for compiled in (True, False):
        pm, _ = pendulum(theta0)
        pm.add_sensor("bottom", "pin + 1.7453292519943295", action="record")   # theta = 0: every pass
        pm.add_sensor("turn", "pin_dot", direction=+1, action="record")
        monkeypatch.setattr(dynamic, "USE_COMPILED", compiled)
        r = mb.simulate(pm, 4.0, 0.01, rtol=1e-11)
        assert ("(compiled)" in r.stats["method"]) == compiled
        runs[compiled] = [(e.name, e.time) for e in r.sensor_events]
    assert [n for n, _ in runs[True]] == [n for n, _ in runs[False]] and len(runs[True]) >= 4
    assert np.max(np.abs(np.array([t for _, t in runs[True]]) - [t for _, t in runs[False]])) < 1e-8


def test_more_sensors_than_the_event_buffer_holds():
    """70 time sensors crossing within a few steps (more than the 64-event buffer's default size): the
    buffer grows with the number of sensors, every event is reported at its own time, none twice."""
    m = falling()
    levels = np.linspace(0.05, 0.6, 70)
    for i, c in enumerate(levels):
        m.add_sensor(f"s{i}", f"t - {float(c)!r}", action="record")
    res = mb.simulate(m, 0.62, 0.31)
    assert "(compiled)" in res.stats["method"]
    got = sorted((e.time, e.name) for e in res.sensor_events)
    assert [n for _, n in got] == [f"s{i}" for i in range(70)]
    assert np.max(np.abs(np.array([t for t, _ in got]) - levels)) < 1e-12


def test_callable_sensor_runs_compiled_like_the_expression_sensor():
    """A Python-callable sensor is called back from the compiled step loop (solvers.pyloads) and its
    crossing located on the dense output like the expression sensor's: the falling ball reaches z = 0.5
    at sqrt(2 (h - 0.5) / g), both to 1e-9 of the closed form and to 1e-8 of each other."""
    res = {}
    for kind, signal in (("callable", lambda t, s: s.position("ball")[2]), ("expression", "DZ(ball)")):
        m = falling()
        m.add_sensor("floor", signal, value=0.5, direction=-1, action="stop")
        res[kind] = mb.simulate(m, 5.0, 0.01)
        assert res[kind].success and "(compiled)" in res[kind].stats["method"], res[kind].stats["method"]
        assert res[kind].sensor_events[0].time == pytest.approx(np.sqrt(2 * 1.5 / G), abs=1e-9)
    assert abs(res["callable"].sensor_events[0].time - res["expression"].sensor_events[0].time) < 1e-8
    assert abs(res["callable"].time[-1] - res["expression"].time[-1]) < 1e-8


def test_failing_callable_sensor_ends_the_run_naming_it():
    from mbdsim.errors import EvaluationError

    def signal(t, s):
        if t > 0.2:
            raise RuntimeError("probe lost")
        return s.position("ball")[2]
    m = falling()
    m.add_sensor("probe", signal, value=-1.0, action="stop")
    res = mb.simulate(m, 1.0, 0.01, max_step=0.02)
    assert not res.success and isinstance(res.error, EvaluationError)
    assert "sensor 'probe'" in str(res.error) and "probe lost" in str(res.error)
    # at once: the run ends at the start of the step the failure was met in, the outputs before it kept
    assert 0.2 < res.error.time <= 0.22 + 1e-12 and "at t = 0.2" in str(res.error)
    assert 0.17 <= res.time[-1] <= 0.2 + 1e-12
