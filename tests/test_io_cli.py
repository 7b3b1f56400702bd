"""`mbdsim run / info / schema`: summaries, results files, exit codes (0 ok, 1 failed, 2 bad input, 130
interrupted), no bare tracebacks, a fast --help; and identical simulations after a file round trip."""
import json
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

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES, BAD = ROOT / "examples", ROOT / "tests" / "bad_models"
runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def test_run_writes_parquet_and_prints_the_summary(tmp_path):
    out = tmp_path / "res.parquet"
    r = invoke("run", EXAMPLES / "slider_crank.yaml", "--end", 0.5, "--step", 0.01, "--out", out)
    assert r.exit_code == 0, r.output
    for words in ("DOF (Gruebler)", "DOF (rank)", "redundant constraints", "steps", "wall time", "success"):
        assert words in r.output
    df = pd.read_parquet(out)
    assert len(df) == 51 and any(c.startswith("slide.") for c in df.columns)


def test_run_csv_with_method_and_rtol(tmp_path):
    out = tmp_path / "res.csv"
    r = invoke("run", EXAMPLES / "pendulum.yaml", "--end", 0.2, "--method", "dop853", "--rtol", 1e-6, "--out", out)
    assert r.exit_code == 0, r.output
    assert "dop853" in r.output.lower() and pd.read_csv(out).shape[0] > 2


def test_info_lists_bodies_joints_dof_drivers_and_elements():
    r = invoke("info", EXAMPLES / "four_bar.yaml")
    assert r.exit_code == 0, r.output
    for words in ("crank", "coupler", "rocker", "revolute", "drive", "DOF (Gruebler)", "DOF (rank)"):
        assert words in r.output
    lines = {ln.split("│")[1].strip(): ln.split("│")[2].strip() for ln in r.output.splitlines()
             if ln.count("│") == 3}
    # planar loop of 3D revolutes, flagged planar: 6*3 - 5*4 - 1 = -3 in space, 3*3 - 2*4 - 1 = 0 in the plane
    assert lines["DOF (Gruebler)"] == "-3 (planar count: 0)" and lines["DOF (rank)"] == "0"
    assert lines["redundant constraints"].startswith("0 (3 out-of-plane")
    r = invoke("info", EXAMPLES / "quarter_car.yaml")
    assert "suspension" in r.output and "SpringDamper" in r.output


def test_schema_is_json_schema():
    r = invoke("schema")
    assert r.exit_code == 0
    s = json.loads(r.output)
    assert s["title"] == "mbdsim model file" and "bodies" in s["properties"]


@pytest.mark.parametrize("args, code, words", [
    (["run", BAD / "unknown_body.yaml", "--end", 1], 2, "unknown_body.yaml, line 17: joint 'pin'.body_j"),
    (["info", BAD / "python_object_tag.yaml"], 2, "YAML tag"),
    (["run", "absent.yaml", "--end", 1], 2, "does not exist"),
    (["run", EXAMPLES / "pendulum.yaml", "--end", 1, "--out", "r.txt"], 2, "expected a .parquet or .csv"),
    (["run", EXAMPLES / "pendulum.yaml", "--end", 1, "--method", "euler"], 2, "unknown method 'euler'"),
    (["run", EXAMPLES / "pendulum.yaml", "--end", -1], 2, "--end must be > 0"),
])
def test_bad_input_exits_2_without_traceback(args, code, words):
    r = invoke(*args)
    assert r.exit_code == code, r.output
    assert words in " ".join(r.output.split()) and "Traceback" not in r.output


LOCKED = """name: locked
bodies:
  - {name: crank, mass: 1, inertia: [1.0e-4, 0.003, 0.003], position: [0.15, 0, 0]}
  - {name: rod, mass: 1, inertia: [1.0e-4, 0.003, 0.003], position: [0.4, 0, 0]}
  - {name: slider, mass: 1, inertia: [1.0e-3, 1.0e-3, 1.0e-3], position: [0.5, 0, 0]}
joints:
  - {name: crank_pin, type: revolute, body_i: ground, body_j: crank, point: [0, 0, 0], axis: [0, 0, 1]}
  - {name: crank_rod, type: revolute, body_i: crank, body_j: rod, point: [0.3, 0, 0], axis: [0, 0, 1]}
  - {name: rod_slider, type: spherical, body_i: rod, body_j: slider, point: [0.5, 0, 0]}
  - {name: slide, type: translational, body_i: ground, body_j: slider, point: [0.5, 0, 0], axis: [1, 0, 0]}
motions:
  - {name: drive, joint: crank_pin, displacement: 2*pi*t}
"""


def test_failed_analysis_exits_1_and_debug_shows_the_traceback(tmp_path):
    p = tmp_path / "locked.yaml"          # crank 0.3 m, rod 0.2 m: locks where sin(theta) = 2/3
    p.write_text(LOCKED)
    r = invoke("run", p, "--end", 0.5)
    assert r.exit_code == 1, r.output
    assert "Traceback" not in r.output and "success" in r.output and "False" in r.output
    t_lock = float(np.arcsin(2 / 3) / (2 * np.pi))
    res = mb.simulate(mb.load_model(p), end_time=0.5, output_step=0.001)
    assert not res.success and res.time[-1] == pytest.approx(t_lock, abs=2e-3)
    p.write_text(LOCKED.replace("point: [0.3, 0, 0]", "point: [0.3, 0, 0], axis: [0, 0, 0]"))
    r = invoke("run", p, "--end", 0.5, "--debug")
    assert r.exit_code != 0 and r.exception is not None          # --debug lets the error through


def test_interrupt_exits_130(monkeypatch):
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt
    monkeypatch.setattr(mb, "simulate", interrupted)
    r = invoke("run", EXAMPLES / "pendulum.yaml", "--end", 1)
    assert r.exit_code == 130 and "interrupted" in r.output


def test_help_is_fast_and_has_examples():
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-m", "mbdsim", "--help"], capture_output=True, text=True, check=True)
    assert time.perf_counter() - t0 < 3.0          # typically ~0.25 s; generous for a loaded 2-core machine
    assert "run" in out.stdout and "schema" in out.stdout
    for cmd in ("run", "info", "schema", "plot", "animate", "validate", "study", "version"):
        assert "Example: mbdsim " + cmd in " ".join(invoke(cmd, "--help").output.split())


def test_help_does_not_import_the_engine_or_pydantic():
    code = ("import sys; from mbdsim.cli.app import app; "
            "print(any(m in sys.modules for m in ('pydantic', 'pint', 'numba', 'scipy', 'mbdsim.io.schema')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


@pytest.mark.parametrize("name", ["slider_crank", "heavy_top"])
def test_round_trip_gives_identical_simulation(name, tmp_path):
    m1 = mb.load_model(EXAMPLES / f"{name}.yaml")
    mb.save_model(m1, tmp_path / "copy.json")
    m2 = mb.load_model(tmp_path / "copy.json")
    r1, r2 = (mb.simulate(m, end_time=0.2, output_step=0.02) for m in (m1, m2))
    body = list(m1.bodies)[1]
    assert np.array_equal(r1.position(body), r2.position(body))
    assert np.array_equal(r1.angular_velocity(body), r2.angular_velocity(body))


def test_warnings_are_one_line_each_without_source_paths(tmp_path):
    """A model whose given velocity the joint cannot hold: the command line says so once, as one line."""
    p = tmp_path / "ic.yaml"
    p.write_text("name: ic\ngravity: [0, -9.81, 0]\nbodies:\n"
                 "  - {name: rod, mass: 1, inertia: [0.01, 0.01, 0.01], position: [0.5, 0, 0], velocity: [1, 0, 0]}\n"
                 "joints:\n  - {name: pin, type: revolute, body_i: ground, body_j: rod, point: [0, 0, 0], "
                 "axis: [0, 0, 1]}\n")
    out = subprocess.run([sys.executable, "-m", "mbdsim", "run", str(p), "--end", "0.1"], capture_output=True,
                         text=True)
    assert out.returncode == 0, out.stderr
    lines = [ln for ln in out.stderr.splitlines() if "InitialConditionWarning" in ln]
    assert len(lines) == 1 and lines[0].startswith("warning: InitialConditionWarning: ")
    assert ".py:" not in out.stderr and "Traceback" not in out.stderr


def test_example_files_leave_free_velocities_free():
    """The slider-crank file gives no velocities: nothing to warn about (they are solved at assembly)."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error", mb.InitialConditionWarning)
        mb.assemble(mb.load_model(EXAMPLES / "slider_crank.yaml"))


def test_planar_models_are_counted_in_the_plane_and_not_called_redundant():
    """Four-bar flagged planar: Kutzbach 3 (n - 1) - 2 j1 = 3*3 - 2*4 = 1, less the driver: 0; the three
    dependent out-of-plane equations are said to be by design. Gears count one equation each."""
    from mbdsim.io.summary import summarize
    r = invoke("info", EXAMPLES / "four_bar.yaml")
    text = " ".join(r.output.split())
    assert r.exit_code == 0 and "(planar count: 0)" in text
    assert "redundant constraints │ 0 (3 out-of-plane equations dependent by design" in text
    m = mb.Model("gears")
    a = m.add_body("a", 1.0, inertia=(0.1, 0.1, 0.1))
    b = m.add_body("b", 1.0, inertia=(0.1, 0.1, 0.1), position=(1, 0, 0))
    m.add_revolute("ja", m.ground, a, (0, 0, 0), (0, 0, 1))
    m.add_revolute("jb", m.ground, b, (1, 0, 0), (0, 0, 1))
    m.add_gear("mesh", "ja", "jb", -2.0)
    s = summarize(m)
    assert s.gruebler_dof == 12 - 10 - 1 and s.planar_dof is None


def test_cold_kernel_cache_is_announced(tmp_path, monkeypatch):
    from mbdsim import _jitcache
    from mbdsim.cli.run_cmds import _kernels_cold
    monkeypatch.setattr(_jitcache, "CACHE_DIR", str(tmp_path))
    assert _kernels_cold()
    (tmp_path / "solvers_abc").mkdir()
    (tmp_path / "solvers_abc" / "fastdop.run-145.py311.nbi").write_bytes(b"")
    assert not _kernels_cold()


def test_the_issue_sequence_run_plot_animate(tmp_path):
    """issue 9, Must show: run a model file to Parquet, plot a column of it, animate the model and the
    results (a streamed run's .parquet is a dataset directory: plot and animate read it too)."""
    from mbdsim.cli.app import app as cli
    out, png, page, page2 = (tmp_path / n for n in ("r.parquet", "x.png", "a.html", "b.html"))
    r = runner.invoke(cli, ["run", str(EXAMPLES / "slider_crank.yaml"), "--end", "0.5", "--out", str(out)])
    assert r.exit_code == 0, r.output
    r = runner.invoke(cli, ["plot", str(out), "slider.x", "-o", str(png)])
    assert r.exit_code == 0, r.output
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    x = pd.read_parquet(out)["slider.x [m]"].to_numpy()
    t = pd.read_parquet(out)["time [s]"].to_numpy()
    th = 2 * np.pi * t                                   # x = r cos(th) + sqrt(l^2 - r^2 sin^2(th)), r 0.2, l 0.4
    assert np.allclose(x, 0.2 * np.cos(th) + np.sqrt(0.16 - 0.04 * np.sin(th) ** 2), atol=1e-6)
    for src, dst in ((EXAMPLES / "slider_crank.yaml", page), (out, page2)):
        r = runner.invoke(cli, ["animate", str(src), "-o", str(dst), "--end", "0.5"])
        assert r.exit_code == 0, r.output
        assert "<html" in dst.read_text()[:500].lower()
