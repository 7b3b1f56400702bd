"""Issue 10, long runs on disk: simulate(out=...) streams Parquet parts as computed, equal to the in-memory run;
a SIGKILL at a random moment leaves every completed part readable; resume=True then ends bit-identical to an
uninterrupted run (a chaotic double pendulum: any difference in the carried state would grow visibly)."""
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

import mbdsim as mb
from mbdsim.cli.app import app
from mbdsim.solvers import stream

ROWS, MARGIN = 1000, 7


def double_pendulum():
    m = mb.Model("dp", gravity=(0.0, -9.81, 0.0))
    a = m.add_body("a", 1.0, inertia=(0.01, 0.01, 0.01), position=(0.5, 0.0, 0.0))
    b = m.add_body("b", 1.0, inertia=(0.01, 0.01, 0.01), position=(1.5, 0.0, 0.0))
    m.add_revolute("j1", m.ground, a, (0, 0, 0), (0, 0, 1))
    m.add_revolute("j2", a, b, (1.0, 0, 0), (0, 0, 1))
    return m


@pytest.fixture
def small_chunks(monkeypatch):
    from mbdsim.results import stream as results_stream
    monkeypatch.setattr(results_stream, "WRITE_INTERVAL", 1e9)   # parts by output count only: same boundaries
    monkeypatch.setattr(stream, "CHUNK_ROWS", ROWS)
    monkeypatch.setattr(stream, "MARGIN", MARGIN)   # small: the window-growing path is exercised too


def test_streamed_run_equals_the_in_memory_run(tmp_path, small_chunks):
    m = double_pendulum()
    ref = mb.simulate(m, 5.0, 0.001)
    res = mb.simulate(m, 5.0, 0.001, out=tmp_path / "run.parquet")
    assert res.success and res.stats["samples"] == 5001 and res.stats["chunks"] >= 5
    parts = sorted(p.name for p in (tmp_path / "run.parquet").glob("part-*.parquet"))
    assert len(parts) == res.stats["chunks"]
    df, d0 = pd.read_parquet(tmp_path / "run.parquet"), ref.to_dataframe()
    assert list(df.columns) == list(d0.columns) and len(df) == len(d0)
    assert np.array_equal(df["time [s]"].to_numpy(), ref.time)
    # every chunk ends at a step end: the states are the in-memory run's exactly; derived columns to round-off
    assert np.array_equal(res.q[-1], ref.q[-1]) and np.array_equal(res.v[-1], ref.v[-1])
    assert np.max(np.abs(df.to_numpy() - d0.to_numpy())) < 1e-10
    # angles are continuous across the part boundaries (no 2 pi jumps), Euler parameters keep their sign
    assert np.max(np.abs(np.diff(df["j2.angle [rad]"].to_numpy()))) < 0.1
    assert np.max(np.abs(np.diff(df["b.qw [-]"].to_numpy()))) < 0.1


def test_bad_stream_arguments(tmp_path):
    m = double_pendulum()
    with pytest.raises(mb.ModelError) as err:
        mb.simulate(m, 1.0, resume=True)
    assert err.value.field == "resume"
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "thesis.tex").write_text("precious")
    with pytest.raises(mb.ModelError) as err:
        mb.simulate(m, 1.0, out=tmp_path / "mine")
    assert err.value.field == "out" and (tmp_path / "mine" / "thesis.tex").exists()
    mb.simulate(m, 0.5, 0.01, out=tmp_path / "r.parquet")
    with pytest.raises(mb.ModelError, match="another run") as err:   # other settings than the checkpoint's
        mb.simulate(m, 0.5, 0.01, rtol=1e-6, out=tmp_path / "r.parquet", resume=True)


CHILD = """
import sys
sys.path[:0] = {path!r}
import mbdsim as mb
from mbdsim.solvers import stream
stream.CHUNK_ROWS, stream.MARGIN = {rows}, {margin}
from mbdsim.results import stream as results_stream
results_stream.WRITE_INTERVAL = 1e9
sys.path.insert(0, {here!r})
from test_stream_resume import double_pendulum
mb.simulate(double_pendulum(), {end}, 0.001, out={out!r})
"""


def _kill_at_a_random_moment(code, out, attempts=3):
    """Start the child run and SIGKILL it at a random moment inside the run: after a random number (1-5)
    of its parts exist, a further random 0-50 ms (between or inside part / checkpoint writes).  A child
    that finishes first (a fast machine) is started again."""
    import shutil
    for _ in range(attempts):
        shutil.rmtree(out, ignore_errors=True)
        proc = subprocess.Popen([sys.executable, "-c", code], stderr=subprocess.PIPE)
        k, deadline = random.randint(1, 5), time.time() + 240
        while proc.poll() is None and time.time() < deadline and \
                (not (out / stream.CHECKPOINT).exists() or len(list(out.glob("part-*.parquet"))) < k):
            time.sleep(0.002)
        time.sleep(random.uniform(0.0, 0.05))
        if proc.poll() is None:
            os.kill(proc.pid, signal.SIGKILL)
            proc.wait()
            return
        assert proc.returncode == 0, proc.stderr.read().decode()[-3000:]
    raise AssertionError(f"the child run finished before the kill {attempts} times")


def test_sigkill_at_a_random_moment_then_resume_is_bit_identical(tmp_path, small_chunks):
    end = 30.0
    out = tmp_path / "killed.parquet"
    code = CHILD.format(path=sys.path, rows=ROWS, margin=MARGIN, here=str(Path(__file__).parent), end=end,
                        out=str(out))
    _kill_at_a_random_moment(code, out)
    killed_rows = len(pd.read_parquet(out))   # every completed part is readable by pandas
    assert 0 < killed_rows < int(end / 0.001) + 1
    assert not any(p.name.startswith("part-") and p.suffix != ".parquet" for p in out.iterdir())

    m = double_pendulum()
    resumed = mb.simulate(m, end, 0.001, out=out, resume=True)
    full = mb.simulate(m, end, 0.001, out=tmp_path / "full.parquet")
    assert resumed.success and full.success
    assert np.array_equal(resumed.q[-1], full.q[-1]) and np.array_equal(resumed.v[-1], full.v[-1])
    a, b = pd.read_parquet(out), pd.read_parquet(tmp_path / "full.parquet")
    assert len(a) == len(b) == int(end / 0.001) + 1
    assert a.equals(b)   # every row, bit for bit


def test_cli_streams_and_resumes(tmp_path, small_chunks):
    model = tmp_path / "p.yaml"
    mb.save_model(double_pendulum(), model)
    out = tmp_path / "cli.parquet"
    r = CliRunner().invoke(app, ["run", str(model), "--end", "2", "--step", "0.001", "--out", str(out)])
    assert r.exit_code == 0, r.output
    df = pd.read_parquet(out)
    assert len(df) == 2001 and len(list(out.glob("part-*.parquet"))) >= 2
    r = CliRunner().invoke(app, ["run", str(model), "--end", "2", "--step", "0.001", "--out", str(out), "--resume"])
    assert r.exit_code == 0, r.output   # a finished run resumes to its end at once
    assert pd.read_parquet(out).equals(df)
    r = CliRunner().invoke(app, ["run", str(model), "--end", "2", "--resume"])
    assert r.exit_code == 2


def test_resume_after_a_kill_inside_an_atomic_write(tmp_path, small_chunks):
    """A run killed while writing its checkpoint or run file leaves their temporary files behind
    (`_atomic`'s names): a resume accepts them as the run's own and finishes as an uninterrupted run."""
    m = double_pendulum()
    out = tmp_path / "run.parquet"
    full = mb.simulate(m, 0.5, 0.001, out=tmp_path / "full.parquet")
    mb.simulate(m, 0.5, 0.001, out=out)
    for name in (stream.CHECKPOINT, stream.META):
        (out / stream._tmp_name(name)).write_bytes(b"partial write")
    resumed = mb.simulate(m, 0.5, 0.001, out=out, resume=True)
    assert resumed.success and np.array_equal(resumed.q[-1], full.q[-1])
    (out / "notes.txt").write_text("a user's file")
    with pytest.raises(mb.ModelError, match="not written by mbdsim"):
        mb.simulate(m, 0.5, 0.001, out=out, resume=True)


def test_csv_is_streamed_in_parts_equal_to_the_in_memory_table(tmp_path, small_chunks, monkeypatch):
    """Issue 35: out=.csv on the compiled path is one file appended part by part (bounded memory, as the
    Parquet dataset), not a whole table rewritten from a pandas frame; its rows are the in-memory
    run's to_dataframe() exactly (floats written as round-trip text)."""
    appended = []
    original = stream.CsvFile.part
    monkeypatch.setattr(stream.CsvFile, "part", lambda self, cols: (appended.append(len(cols["time [s]"])),
                                                                     original(self, cols))[1])
    m = double_pendulum()
    ref = mb.simulate(m, 3.0, 0.001)
    res = mb.simulate(m, 3.0, 0.001, out=tmp_path / "run.csv")
    assert res.success and res.stats["method"] == "DOP853 (compiled, streamed)" and res.stats["samples"] == 3001
    assert len(appended) >= 3 and sum(appended) == 3001   # appended in parts, every row once
    df, d0 = pd.read_csv(tmp_path / "run.csv"), ref.to_dataframe()
    assert list(df.columns) == list(d0.columns) and len(df) == len(d0)
    assert np.max(np.abs(df.to_numpy() - d0.to_numpy())) < 1e-10
    assert np.max(np.abs(np.diff(df["j2.angle [rad]"].to_numpy()))) < 0.1   # continuous across parts
    # a rerun replaces the file mbdsim wrote; a foreign .csv and resume are refused before any work
    mb.simulate(m, 0.2, 0.01, out=tmp_path / "run.csv")
    assert len(pd.read_csv(tmp_path / "run.csv")) == 21
    (tmp_path / "theirs.csv").write_text("a,b\n1,2\n")
    with pytest.raises(mb.ModelError) as err:
        mb.simulate(m, 0.2, 0.01, out=tmp_path / "theirs.csv")
    assert err.value.field == "out" and (tmp_path / "theirs.csv").read_text() == "a,b\n1,2\n"
    with pytest.raises(mb.ModelError) as err:
        mb.simulate(m, 0.2, 0.01, out=tmp_path / "run.csv", resume=True)
    assert err.value.field == "resume"
