"""Parameter studies on dask.distributed: a LocalCluster of 2 workers, a study killed and resumed, and a
separately started scheduler with two workers (one killed mid-study).  Few variants, short end times."""
import os
import signal
import socket
import subprocess
import sys
import threading
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import mbdsim as mb
from mbdsim.studies.models import slider_crank
from mbdsim.studies.runner import start_method

pytest.importorskip("distributed")

OUT = {"amax": "peak(x(acceleration('slider')))", "F": "max(norm(reaction_force('crank_rod')))"}
FAST = {"end_time": 0.5, "output_step": 0.01, "rtol": 1e-6}
SAME = ["run", "crank", "rod", "amax", "F", "status", "message"]
ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module", autouse=True)
def _kernels_on_disk():
    """Compile (or load) the kernels here first, so that worker processes load them from numba's disk cache."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mb.simulate(slider_crank(), 0.05, 0.01, rtol=1e-6)


def test_local_cluster_complete_and_identical_to_serial():
    outs = {**OUT, "x_end": lambda res: float(res.position("slider")[-1, 0])}    # a callable travels too
    study = mb.Study(slider_crank, {"crank": [0.1, 0.15, 0.2, 0.5], "rod": [0.3, 0.4]}, outs, analysis=FAST)
    df = study.run(workers=2, chunk_size=2, progress=False)
    assert list(df.run) == list(range(8)) and df.attrs["executed"] == 8
    here = f"{socket.gethostname()}:{os.getpid()}"
    if start_method() == "fork":                                       # the first run warms this process up
        assert df.worker[0] == here and df.attrs["executed"] == 8
    assert df.worker[df.worker != here].nunique() == 2                 # both workers ran chunks
    failing = df[df.crank == 0.5]
    assert (failing.status == "failed").all() and failing.message.str.contains("joints involved").all()
    assert (df[df.crank < 0.5].status == "ok").all()
    serial = study.run(workers=0)
    pd.testing.assert_frame_equal(df[SAME + ["x_end"]], serial[SAME + ["x_end"]])   # bit-identical outputs


def _stored(path, study_id=None):
    """Rows stored so far (the Parquet file and its journal), as a re-run would find them."""
    from mbdsim.studies.store import load_rows
    if study_id is None:
        from mbdsim.studies.store import _read_journal, journal_path
        frames = [pd.read_parquet(path)] if path.exists() else []
        frames += [j for j in [_read_journal(journal_path(path))] if j is not None]
        return pd.concat(frames).drop_duplicates("run") if frames else pd.DataFrame(columns=["run"])
    return load_rows(path, study_id)


def _rows(path):
    try:
        return len(_stored(path))
    except Exception:  # noqa: BLE001 - not written yet
        return 0


def test_killed_study_resumes_missing_runs_only(tmp_path):
    (tmp_path / "slider_crank.yaml").write_text((ROOT / "examples/slider_crank.yaml").read_text())
    study_file = tmp_path / "s.yaml"
    study_file.write_text("model: slider_crank.yaml\nanalysis: {end_time: 0.5, output_step: 0.01, rtol: 1.0e-6}\n"
                          "parameters:\n  bodies.rod.mass: {range: [1, 3], num: 40}\n"
                          "outputs: {F: \"max(norm(reaction_force('crank_rod')))\"}\n")
    out = tmp_path / "r.parquet"
    proc = subprocess.Popen([sys.executable, "-m", "mbdsim", "study", str(study_file), "--workers", "0",
                             "--chunk", "1", "--out", str(out)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.time() + 120
        while _rows(out) < 3 and time.time() < deadline and proc.poll() is None:
            time.sleep(0.05)
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.kill()
        proc.wait(10)
    study = mb.load_study(study_file)
    before = _stored(out, study.study_id)             # the Parquet file and the journal of the killed run
    assert 3 <= len(before) < 40, "the study was not killed mid-way"
    df = study.run(workers=0, out=out)
    assert df.attrs["executed"] == 40 - len(before) and len(df) == 40 and (df.status == "ok").all()
    kept = df.set_index("run").loc[before.run]
    assert kept.wall_time.tolist() == before.wall_time.tolist()      # finished rows were not re-run
    # heavier rod, larger pin force: the rows are those of their own parameters
    assert np.all(np.diff(df.sort_values("bodies.rod.mass").F) > 0)


def _spawn(args, log):
    return subprocess.Popen([sys.executable, "-m", *args], stdout=log, stderr=subprocess.STDOUT,
                            start_new_session=True)


def test_remote_scheduler_and_a_killed_worker(tmp_path):
    """`dask scheduler` and two `dask worker` processes on 127.0.0.1; the study goes through the address;
    one worker is killed once rows arrive: its tasks are retried on the other, nothing is lost."""
    from distributed import Client
    sched_file = tmp_path / "scheduler.json"
    log = open(tmp_path / "dask.log", "w")
    procs = [_spawn(["distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                     "--scheduler-file", str(sched_file)], log)]
    try:
        deadline = time.time() + 30
        while not sched_file.exists() and time.time() < deadline:
            time.sleep(0.1)
        for _ in range(2):
            procs.append(_spawn(["distributed.cli.dask_worker", "--scheduler-file", str(sched_file), "--nthreads", "1",
                                 "--no-dashboard", "--no-nanny", "--host", "127.0.0.1"], log))
        with Client(scheduler_file=str(sched_file), timeout="30s") as c:
            c.wait_for_workers(2, timeout=30)
            address = c.scheduler.address
        study = mb.Study(slider_crank, {"crank": list(np.linspace(0.1, 0.2, 16))}, OUT,
                         analysis={**FAST, "end_time": 1.0})
        out = tmp_path / "r.parquet"

        killed = []

        def kill_one():
            while _rows(out) < 2 and time.time() < deadline + 60:
                time.sleep(0.02)
            os.kill(procs[1].pid, signal.SIGKILL)
            killed.append(time.time())
        killer = threading.Thread(target=kill_one, daemon=True)
        killer.start()
        df = study.run(client=address, out=out, chunk_size=1)
        finished = time.time()
        killer.join(5)
        assert killed and killed[0] < finished, "the worker was not killed during the study"
        assert len(df) == 16 and (df.status == "ok").all()
        r, w = df.crank, 2 * np.pi
        assert np.allclose(df.amax, r * w**2 * (1 + r / 0.4), rtol=1e-8)
    finally:
        for p in reversed(procs):
            if p.poll() is None:
                p.terminate()
        for p in procs:
            try:
                p.wait(10)
            except subprocess.TimeoutExpired:
                p.kill()
        log.close()


KILLED_RUN = """
import sys, warnings
import numpy as np
import mbdsim as mb
from mbdsim.studies.models import slider_crank
warnings.simplefilter("ignore")
cranks = list(np.linspace(0.1, 0.2, 199)) + [0.5]
study = mb.Study(slider_crank, {"crank": cranks}, %r, analysis=%r)
study.run(workers=2, out=sys.argv[1], chunk_size=4, progress=False)
"""


def test_200_variants_two_workers_failing_row_killed_resumed_identical_to_serial(tmp_path):
    """The issue's demonstration: 200 slider-cranks on a LocalCluster of 2 workers, one of them (crank 0.5 m >
    rod 0.4 m) locking up; the study is killed mid-way (SIGKILL of the process and its workers) and re-run
    with the same file: only the missing runs execute, the table is complete, the failing variant is a
    row with its error, and every output equals a serial run of the same variants bit for bit."""
    analysis = {"end_time": 0.3, "output_step": 0.01, "rtol": 1e-6}
    out = tmp_path / "r.parquet"
    proc = subprocess.Popen([sys.executable, "-c", KILLED_RUN % (OUT, analysis), str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    cranks = list(np.linspace(0.1, 0.2, 199)) + [0.5]
    study = mb.Study(slider_crank, {"crank": cranks}, OUT, analysis=analysis)
    try:
        deadline = time.time() + 300
        while len(_stored(out)) < 30 and time.time() < deadline and proc.poll() is None:
            time.sleep(0.05)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)       # the study and its forked workers
        proc.wait(10)
    before = _stored(out, study.study_id)
    assert 30 <= len(before) < 200, "the study was not killed mid-way"
    df = study.run(workers=2, out=out, progress=False)
    assert df.attrs["executed"] == 200 - len(before) and list(df.run) == list(range(200))
    assert len(pd.read_parquet(out)) == 200
    kept = df.set_index("run").loc[before.run]
    assert kept.wall_time.tolist() == before.wall_time.tolist()          # not run again
    bad = df[df.crank == 0.5]
    assert len(bad) == 1 and bad.status.iloc[0] == "failed" and "joints involved" in bad.message.iloc[0]
    assert (df[df.crank < 0.5].status == "ok").all()
    serial = study.run(workers=0, progress=False)
    cols = [c for c in SAME if c != "rod"]
    pd.testing.assert_frame_equal(df[cols], serial[cols])
    r, w = df.crank[df.crank < 0.5], 2 * np.pi
    assert np.allclose(df.amax[df.crank < 0.5], r * w**2 * (1 + r / 0.4), rtol=1e-8)
