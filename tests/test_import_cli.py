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
