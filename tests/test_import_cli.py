"""The CLI reads imported formats by extension (issue 31): run writes results, bad files one clear line."""
from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from typer.testing import CliRunner

from mbdsim.cli.app import app

ROOT = Path(__file__).resolve().parents[1]
FILES = Path(__file__).parent / "import_files"
runner = CliRunner()


def cli(*args):
    return runner.invoke(app, [str(a) for a in args])


@pytest.mark.parametrize("model", [ROOT / "examples" / "arm_urdf.urdf", FILES / "fourbar.xml"])
def test_run_writes_results_of_an_imported_file(tmp_path, model):
    pytest.importorskip("mujoco") if model.suffix == ".xml" else None
    out = tmp_path / "res.csv"
    r = cli("run", model, "--end", "0.1", "--step", "0.01", "--out", out)
    assert r.exit_code == 0, r.output
    df = pd.read_csv(out)
    assert len(df) == 11 and any(c.endswith(".angle [rad]") for c in df.columns)


def test_info_of_a_urdf_lists_the_file_names():
    r = cli("info", ROOT / "examples" / "arm_urdf.urdf")
    assert r.exit_code == 0, r.output
    assert "upper_arm" in r.output and "finger_right_joint_mimic" in r.output


@pytest.mark.parametrize("name, text, line", [
    ("bad.urdf", '<robot name="r">\n<link name="a"/>\n<joint name="j" type="continuous"><parent link="a"/>'
                 '<child link="zz"/></joint>\n</robot>', 3),
    ("bad.xml", '<?xml version="1.0"?>\n<!DOCTYPE m [<!ENTITY e SYSTEM "http://example.com/x">]>\n<mujoco>&e;</mujoco>',
     2),
])
def test_bad_imported_file_is_one_clear_error(tmp_path, name, text, line):
    path = tmp_path / name
    path.write_text(text)
    r = cli("run", path, "--end", "0.1")
    assert r.exit_code != 0
    assert f"{path}, line {line}" in r.output and "Traceback" not in r.output


# `mbdsim animate` and `mbdsim study` on each imported format, as subprocesses (the installed entry point's
# code path: `python -m mbdsim` with this checkout on PYTHONPATH), all six started at once to keep the wall
# time down; each checks what the command wrote.
STUDY = """name: {name}
model: {model}
analysis: {{type: dynamics, end_time: 0.1 s, output_step: 10 ms}}
sampling: {{method: grid}}
parameters:
  bodies.{body}.mass: {{values: [{m1} kg, {m2} kg]}}
outputs:
  reach: "rms({coord}(velocity('{body}')))"
"""
CASES = [("urdf", FILES / "two_link.urdf", "lower", 0.5, 2.0, "z"),
         ("mjcf", FILES / "fourbar.xml", "rocker", 0.05, 0.5, "x"),
         ("adm", ROOT / "examples" / "slider_crank.adm", "follower", 0.8, 3.0, "x")]


def test_animate_and_study_on_imported_files_from_the_command_line(tmp_path):
    import os
    import subprocess
    import sys
    pytest.importorskip("mujoco")
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""))
    jobs = {}
    for kind, model, body, m1, m2, coord in CASES:
        study = tmp_path / f"{kind}_study.yaml"
        study.write_text(STUDY.format(name=kind, model=model.as_posix(), body=body, m1=m1, m2=m2, coord=coord))
        for cmd, args in (("animate", [model, "--end", "0.1", "-o", tmp_path / f"{kind}.html"]),
                          ("study", [study, "--workers", "0", "--out", tmp_path / f"{kind}.parquet"])):
            jobs[(kind, cmd)] = subprocess.Popen([sys.executable, "-m", "mbdsim", cmd, *map(str, args)], env=env,
                                                 stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    outs = {key: p.communicate(timeout=600)[0] for key, p in jobs.items()}
    for (kind, cmd), p in jobs.items():
        assert p.returncode == 0, (kind, cmd, outs[(kind, cmd)][-2000:])
    for kind, model, body, *_ in CASES:
        html = (tmp_path / f"{kind}.html").read_text()
        assert len(html) > 100_000 and body in html and "<script" in html      # the page names the bodies
        df = pd.read_parquet(tmp_path / f"{kind}.parquet")
        assert len(df) == 2 and df["reach"].notna().all(), df
        assert df[f"bodies.{body}.mass"].tolist() == pytest.approx(sorted(df[f"bodies.{body}.mass"]))
        assert abs(df["reach"].iloc[0] - df["reach"].iloc[1]) > 1e-6, (kind, df["reach"])   # the mass reached it
