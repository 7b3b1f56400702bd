"""Issue 35, never corrupt or lose data, never hang: resuming a checkpoint of another model, overwriting
files mbdsim did not write, outputs further apart than the write interval, a raising progress callback,
and model files that are not regular files or are too large. (Unit strings with unbounded powers and
runs asking for unbounded work are in the bad-input catalogue, tests/bad_inputs.)"""
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

import mbdsim as mb
from mbdsim.cli.app import app
from mbdsim.errors import EvaluationError, ModelError, ModelFileError
from mbdsim.results import stream as results_stream

SRC = str(Path(mb.__file__).resolve().parents[1])


def oscillator(k=100.0, mass=1.0):
    m = mb.Model("osc", gravity=(0.0, 0.0, 0.0))
    b = m.add_body("b", mass, inertia=(0.01, 0.01, 0.01), position=(1.0, 0.0, 0.0))
    m.add_translational("s", m.ground, b, (0, 0, 0), (1, 0, 0))
    m.add_spring_damper("k", (b, (1, 0, 0)), (m.ground, (0, 0, 0)), stiffness=k, free_length=0.5)
    return m


# ----------------------------------------------------------------------------- 1. resume of another model
def test_resume_refuses_a_checkpoint_of_another_model(tmp_path):
    out = tmp_path / "run.parquet"
    assert mb.simulate(oscillator(100.0), 0.5, 0.01, out=out).success
    with pytest.raises(ModelError) as err:   # same names, sizes, initial state and settings: other stiffness
        mb.simulate(oscillator(400.0), 0.5, 0.01, out=out, resume=True)
    assert (err.value.entity, err.value.field) == ("simulate", "resume")
    assert "another model" in str(err.value) and "'k'" in str(err.value) and "body" not in str(err.value)
    with pytest.raises(ModelError, match="body 'b'"):
        mb.simulate(oscillator(100.0, mass=2.0), 0.5, 0.01, out=out, resume=True)
    res = mb.simulate(oscillator(100.0), 0.5, 0.01, out=out, resume=True)   # the same model resumes
    assert res.success


MODEL = """
import mbdsim as mb

def push(t, state):
    return (0.1 * t, 0.0, 0.0)

def model(gain):
    m = mb.Model("osc", gravity=(0.0, 0.0, 0.0))
    b = m.add_body("b", 1.0, inertia=(0.01, 0.01, 0.01), position=(1.0, 0.0, 0.0))
    m.add_translational("s", m.ground, b, (0, 0, 0), (1, 0, 0))
    m.add_force("f", (b, (0, 0, 0)), lambda t, s: (gain * t, 0.0, 0.0))
    m.add_force("g", (b, (0, 0, 0)), push)
    return m
"""


def test_model_digests_are_portable_and_see_python_functions(tmp_path):
    (tmp_path / "osc_model.py").write_text(MODEL)
    code = ("import sys, json; sys.path[:0] = [{src!r}, {here!r}]; import osc_model; "
            "from mbdsim.system.fingerprint import model_digests; "
            "print(json.dumps(model_digests(osc_model.model({gain}))))")

    def digests(gain):
        out = subprocess.run([sys.executable, "-c", code.format(src=SRC, here=str(tmp_path), gain=gain)],
                             capture_output=True, text=True, timeout=300, check=True).stdout
        import json
        return json.loads(out)
    a, b, c = digests(1.0), digests(1.0), digests(2.0)
    assert a == b   # two processes, the same model: the same digests (functions by value, not identity)
    assert [k for k in a if a[k] != c[k]] == ["force 'f'"]   # a closure value changed: that force only


# ----------------------------------------------------------------------------- 2. foreign files at out=
@pytest.mark.parametrize("name", ["foreign.parquet", "foreign.csv"])
def test_out_refuses_a_file_mbdsim_did_not_write(tmp_path, name):
    path = tmp_path / name
    df = pd.DataFrame({"a": [1.0, 2.0], "b": [3.0, 4.0]})
    df.to_parquet(path) if name.endswith(".parquet") else df.to_csv(path, index=False)
    before = path.read_bytes()
    for method in (None, "hht"):   # the streamed writer and the whole-file writer
        with pytest.raises(ModelError) as err:
            mb.simulate(oscillator(), 0.2, 0.01, method=method, out=path)
        assert err.value.field == "out" and "not written by mbdsim" in str(err.value)
        assert path.read_bytes() == before


def test_out_replaces_files_mbdsim_wrote(tmp_path):
    m = oscillator()
    for name in ("r.csv", "r.parquet"):
        path = tmp_path / name
        for _ in range(2):   # written, then replaced by the whole-file writer
            res = mb.simulate(m, 0.2, 0.01, method="hht", out=path)
            assert res.success
        df = pd.read_csv(path) if name.endswith(".csv") else pd.read_parquet(path)
        assert len(df) == 21 and list(df.columns) == list(res.to_dataframe().columns)
    res = mb.simulate(m, 0.2, 0.01, out=tmp_path / "r.parquet")   # the streamed writer replaces it too
    assert res.success and (tmp_path / "r.parquet").is_dir() and len(pd.read_parquet(tmp_path / "r.parquet")) == 21


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs")
def test_out_refuses_a_fifo(tmp_path):
    os.mkfifo(tmp_path / "r.csv")
    with pytest.raises(ModelError, match="not a regular file"):
        mb.simulate(oscillator(), 0.2, 0.01, out=tmp_path / "r.csv")


# ----------------------------------------------------------------------------- 3. sparse outputs, streamed
def test_streamed_outputs_further_apart_than_the_write_interval(tmp_path, monkeypatch):
    monkeypatch.setattr(results_stream, "WRITE_INTERVAL", 0.0)   # every return to Python is "past due"
    m = oscillator()
    # max_step: ~40000 steps, the step loop returns to Python every 12800 steps, between outputs
    res = mb.simulate(m, 4.0, 2.0, max_step=1e-4, out=tmp_path / "sp.parquet")
    assert res.success, res.message
    df = pd.read_parquet(tmp_path / "sp.parquet")
    assert np.array_equal(df["time [s]"].to_numpy(), [0.0, 2.0, 4.0])
    ref = mb.simulate(m, 4.0, 2.0, max_step=1e-4)
    assert np.allclose(df["b.x [m]"].to_numpy(), ref.q[:, 0], atol=1e-6)


# ----------------------------------------------------------------------------- 4. raising progress callback
class Raiser:
    def __init__(self, after):
        self.calls, self.after = 0, after

    def __call__(self, t):
        self.calls += 1
        if self.calls > self.after:
            raise RuntimeError("bar broke")


def _check_failed(res, path=None):
    assert not res.success and isinstance(res.error, EvaluationError)
    assert res.error.field == "progress" and "progress callback raised RuntimeError: bar broke" in str(res.error)
    assert len(res.time) >= 1 and res.time[0] == 0.0
    if path is not None:
        df = pd.read_parquet(path) if path.suffix == ".parquet" else pd.read_csv(path)
        assert len(df) >= 1 and df["time [s]"].iloc[0] == 0.0


@pytest.mark.parametrize("method", [None, "hht"])
def test_a_raising_progress_callback_ends_the_run_keeping_outputs(tmp_path, method):
    m = oscillator()
    _check_failed(mb.simulate(m, 30.0, 0.001, method=method, max_step=1e-3, progress=Raiser(1)))
    path = tmp_path / "r.csv"
    _check_failed(mb.simulate(m, 30.0, 0.001, method=method, max_step=1e-3, progress=Raiser(1), out=path), path)


def test_a_raising_progress_callback_ends_a_streamed_run(tmp_path, monkeypatch):
    from mbdsim.solvers import stream
    monkeypatch.setattr(stream, "CHUNK_ROWS", 100)
    path = tmp_path / "r.parquet"
    res = mb.simulate(oscillator(), 2.0, 0.001, max_step=1e-3, progress=Raiser(3), out=path)
    _check_failed(res, path)
    assert res.time[-1] < 2.0


def test_a_raising_progress_callback_ends_a_kinematic_run():
    m = mb.Model("crank", gravity=(0.0, 0.0, 0.0))
    b = m.add_body("b", 1.0, inertia=(0.1, 0.1, 0.1), position=(0.5, 0.0, 0.0))
    m.add_revolute("pin", m.ground, b, (0, 0, 0), (0, 0, 1))
    m.add_motion("d", "pin", displacement="t")
    res = mb.kinematics(m, 1.0, 0.1, progress=Raiser(2))
    _check_failed(res)


# ----------------------------------------------------------------------------- 5. unit strings in study values
def test_study_values_with_unbounded_unit_powers_are_refused_at_once():
    from mbdsim.studies.design import to_si_value
    t0 = time.monotonic()
    with pytest.raises(ModelError) as err:
        to_si_value("1 kg**9**9**9", "mass")
    assert (err.value.entity, err.value.field) == ("study parameter 'mass'", "values")
    assert "double precision" in str(err.value) and time.monotonic() - t0 < 5.0
    assert to_si_value("150 mm", "x") == pytest.approx(0.15)


# ----------------------------------------------------------------------------- 6. model files
def _load_within(path, seconds=20.0):
    """load_model(path) in a thread: (the exception it raised, elapsed s); fails if it has not returned."""
    box = {}

    def go():
        t0 = time.monotonic()
        try:
            mb.load_model(path)
        except Exception as exc:  # noqa: BLE001
            box["exc"] = exc
        box["dt"] = time.monotonic() - t0
    th = threading.Thread(target=go, daemon=True)
    th.start()
    th.join(seconds)
    assert not th.is_alive(), f"load_model({path}) hung"
    return box.get("exc"), box["dt"]


@pytest.mark.skipif(not hasattr(os, "mkfifo") or not os.path.exists("/dev/zero"), reason="POSIX only")
def test_model_files_that_are_not_regular_or_too_large_are_refused(tmp_path):
    os.mkfifo(tmp_path / "fifo.yaml")
    (tmp_path / "zero.yaml").symlink_to("/dev/zero")
    with open(tmp_path / "big.yaml", "wb") as fh:   # sparse: 100 MB without the disk space
        fh.truncate(100 * 2**20)
    (tmp_path / "dir.yaml").mkdir()
    for name, words in [("fifo.yaml", "FIFO"), ("zero.yaml", "device"), ("big.yaml", "20 MB"),
                        ("dir.yaml", "directory")]:
        exc, dt = _load_within(tmp_path / name)
        assert isinstance(exc, ModelFileError) and (exc.entity, exc.field) == ("file", "path"), exc
        assert name in str(exc) and words in str(exc) and dt < 5.0
    runner = CliRunner()
    for name in ("fifo.yaml", "zero.yaml"):
        r = runner.invoke(app, ["run", str(tmp_path / name), "--end", "1"])
        text = " ".join(r.output.split())   # (rich wraps lines)
        assert r.exit_code == 2 and "does not exist" not in text and "not a regular file" in text


# ----------------------------------------------------------------------------- 7. unbounded work
def test_python_methods_stop_after_the_step_budget(monkeypatch):
    from mbdsim.solvers import driver
    from mbdsim.solvers import dynamic
    monkeypatch.setattr(driver, "MAX_STEPS", 40)   # (1e7 by default, as the compiled integrator)
    monkeypatch.setattr(dynamic, "USE_COMPILED", False)   # the reference (Python) HHT
    res = mb.simulate(oscillator(), 1e12, method="hht")
    assert not res.success and "step budget exhausted (40 steps)" in res.message
    assert len(res.time) >= 1 and res.time[0] == 0.0


def test_budget_errors_give_the_numbers():
    with pytest.raises(ModelError, match=r"1e\+14 steps \(more than 1e\+09\)") as err:
        mb.simulate(oscillator(), 1e12, max_step=1e-2)
    assert (err.value.entity, err.value.field) == ("simulate", "max_step")
    with pytest.raises(ModelError, match=r"1e\+14 output times \(more than 1e\+08\)") as err:
        mb.simulate(oscillator(), 1e12, 1e-2, out="never-written.parquet")
    assert err.value.field == "output_step" and not os.path.exists("never-written.parquet")
