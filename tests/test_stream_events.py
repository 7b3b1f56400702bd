"""Streamed runs with events on the compiled core (issue 29): joint friction (stick/slip decided between
kernel calls) and expression sensors stream in parts like any other model, each part continuing the
carried state exactly: the table is the in-memory run's (1e-10), the events the same, and a run stopped
mid-way resumes bit-identical to an uninterrupted one (the modes, held groups, switching and sensor
values carried in the checkpoint)."""
import numpy as np
import pandas as pd
import pytest

import mbdsim as mb
from mbdsim.solvers import stream
from test_compiled_friction import closed_form, spring_pulled_block

ROWS, MARGIN = 25, 3


@pytest.fixture
def small_chunks(monkeypatch):
    from mbdsim.results import stream as results_stream
    monkeypatch.setattr(results_stream, "WRITE_INTERVAL", 1e9)   # parts by output count only: same boundaries
    monkeypatch.setattr(stream, "CHUNK_ROWS", ROWS)
    monkeypatch.setattr(stream, "MARGIN", MARGIN)


def _same_table(out, ref):
    df, d0 = pd.read_parquet(out), ref.to_dataframe()
    assert list(df.columns) == list(d0.columns) and len(df) == len(d0)
    assert np.array_equal(df["time [s]"].to_numpy(), ref.time)
    return float(np.max(np.abs(df.to_numpy() - d0.to_numpy())))


def test_stick_slip_streams_compiled_in_parts_equal_to_the_in_memory_run(tmp_path, small_chunks):
    tb, ts, _ = closed_form()
    model, _ = spring_pulled_block()
    end = ts + 0.3   # breakaway, stop, a second breakaway: events inside parts, several parts
    ref = mb.simulate(spring_pulled_block()[0], end, 0.005)
    res = mb.simulate(model, end, 0.005, out=tmp_path / "run.parquet")
    assert res.success, res.message
    assert res.stats["method"] == "DOP853 (compiled, streamed)" and res.stats["chunks"] >= 5
    assert res.friction_events("friction") == ref.friction_events("friction")
    ev = res.friction_events("friction")
    assert [m for _, m, _ in ev[:3]] == ["stick", "slip", "stick"]
    assert ev[1][0] == pytest.approx(tb, rel=1e-8) and ev[2][0] == pytest.approx(ts, rel=1e-7)
    assert np.array_equal(res.q[-1], ref.q[-1]) and np.array_equal(res.v[-1], ref.v[-1])
    assert _same_table(tmp_path / "run.parquet", ref) < 1e-10


def test_stick_slip_stream_resumes_bit_identical(tmp_path, small_chunks):
    _, ts, _ = closed_form()
    end = ts + 0.3
    full = mb.simulate(spring_pulled_block()[0], end, 0.005, out=tmp_path / "full.parquet")
    out = tmp_path / "cut.parquet"

    def stop_late(t):
        if t > 0.6 * end:
            raise RuntimeError("stopped by the test")
    cut = mb.simulate(spring_pulled_block()[0], end, 0.005, out=out, progress=stop_late)
    assert not cut.success and 0 < len(pd.read_parquet(out)) < len(full.time)
    res = mb.simulate(spring_pulled_block()[0], end, 0.005, out=out, resume=True)
    assert res.success, res.message
    assert res.friction_events("friction") == full.friction_events("friction")
    assert np.array_equal(res.q[-1], full.q[-1]) and np.array_equal(res.v[-1], full.v[-1])
    assert pd.read_parquet(out).equals(pd.read_parquet(tmp_path / "full.parquet"))


def pendulum(theta0=np.radians(60), l=1.0):
    m = mb.Model("pendulum", gravity=(0, -9.81, 0))
    m.add_body("bob", 1.0, inertia=(1e-4, 1e-4, 1e-4), position=(l * np.sin(theta0), -l * np.cos(theta0), 0))
    m.add_revolute("pin", "ground", "bob", (0, 0, 0), (0, 0, 1))
    m.add_sensor("bottom", "pin", value=-theta0, action="record")   # each passage through the bottom
    m.add_sensor("back", "pin_dot", value=0.0, direction=+1, action="stop")   # the second far turning point
    return m


def test_sensors_stream_compiled_with_the_stop_in_the_last_part(tmp_path, small_chunks):
    ref = mb.simulate(pendulum(), 10.0, 0.01)
    res = mb.simulate(pendulum(), 10.0, 0.01, out=tmp_path / "run.parquet")
    assert res.success and res.message == ref.message and res.message.startswith("stopped by sensor 'back'")
    assert res.stats["method"] == "DOP853 (compiled, streamed)" and res.stats["chunks"] >= 3
    assert [(e.name, e.time) for e in res.sensor_events] == [(e.name, e.time) for e in ref.sensor_events]
    assert [e.name for e in res.sensor_events] == ["bottom", "back"]
    assert res.stats["samples"] == len(ref.time) and res.time[-1] == ref.time[-1]
    assert np.array_equal(res.q[-1], ref.q[-1]) and np.array_equal(res.v[-1], ref.v[-1])
    assert _same_table(tmp_path / "run.parquet", ref) < 1e-10


def test_held_group_streams_and_resumes_between_its_stop_and_breakaway(tmp_path, small_chunks):
    """The five-bar held by five pins (tests/test_friction_held_loop.py) streamed in parts and stopped while
    held: the resumed run carries the held group (its shares of the capacity) and breaks away as the
    in-memory run does, bit-identical to an uninterrupted stream."""
    from test_friction_held_loop import PINS, coasting_five_bar
    end, step = 1.3, 0.005
    ref = mb.simulate(coasting_five_bar(), end, step)
    full = mb.simulate(coasting_five_bar(), end, step, out=tmp_path / "full.parquet")
    assert full.success and full.stats["method"] == "DOP853 (compiled, streamed)"
    assert _same_table(tmp_path / "full.parquet", ref) < 1e-10
    out = tmp_path / "cut.parquet"

    def stop_held(t):
        if t > 0.95:   # stopped at 0.38 s, breaks away at 1.12 s
            raise RuntimeError("stopped by the test")
    cut = mb.simulate(coasting_five_bar(), end, step, out=out, progress=stop_held)
    assert not cut.success
    with np.load(out / stream.CHECKPOINT) as z:   # the run resumes from a part that ended while held
        assert 0.4 < float(z["st"][0]) < 1.1
    res = mb.simulate(coasting_five_bar(), end, step, out=out, resume=True)
    assert res.success, res.message
    for n in PINS:
        e = res.friction_events("f_" + n)
        assert e == full.friction_events("f_" + n) == ref.friction_events("f_" + n)
        assert e[-1][1] == ("stick" if n == "C" else "slip")   # broken away, C left at rest
    assert pd.read_parquet(out).equals(pd.read_parquet(tmp_path / "full.parquet"))


def test_stiff_friction_model_streamed_hands_over_to_radau_in_memory(tmp_path):
    """Stiffness found in the first part: nothing is streamed, the whole-file writer runs "auto" with its
    hand-over to the compiled Radau (the friction modes going on): the in-memory run's table exactly."""
    from test_friction_implicit import stiff_pulled_block
    _, ts, _ = closed_form(m=2.01)
    ref = mb.simulate(stiff_pulled_block()[0], ts + 0.05, 0.01)
    res = mb.simulate(stiff_pulled_block()[0], ts + 0.05, 0.01, out=tmp_path / "run.parquet")
    assert res.success and "then Radau IIA (compiled)" in res.stats["method"], res.stats["method"]
    assert res.friction_events("friction") == ref.friction_events("friction")
    assert _same_table(tmp_path / "run.parquet", ref) == 0.0
