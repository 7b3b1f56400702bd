"""`mbdsim kinematics / statics / modes` and `run --markers`: numbers against closed forms, results files,
exit codes (0 ok, 1 failed, 2 bad input) and one-line errors without tracebacks."""
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from mbdsim.cli.app import app

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
runner = CliRunner()
G = 9.81


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def flat(r) -> str:
    return " ".join(r.output.split())


def test_modes_of_the_pendulum_match_the_small_oscillation_frequency(tmp_path):
    """Rod 1 kg, 1 m on a pin at its end: f = sqrt(m g c / I_pin) / (2 pi), c = 0.5 m, I_pin = 1/12 + 1/4."""
    out = tmp_path / "modes.csv"
    r = invoke("modes", EXAMPLES / "pendulum.yaml", "--out", out)
    assert r.exit_code == 0, r.output
    f = np.sqrt(1.0 * G * 0.5 / (1 / 12 + 0.25)) / (2 * np.pi)        # 0.610521 Hz
    df = pd.read_csv(out)
    assert list(df.columns)[:4] == ["mode", "frequency [Hz]", "damped frequency [Hz]", "damping ratio [-]"]
    assert len(df) == 1 and df["frequency [Hz]"][0] == pytest.approx(f, rel=1e-6)
    assert df["damping ratio [-]"][0] == pytest.approx(0.0, abs=1e-9)
    assert f"{f:.6g}" in r.output and "frequency [Hz]" in r.output
    r = invoke("modes", EXAMPLES / "pendulum.yaml", "--at", "initial", "--out", out)   # replaces its own table
    assert r.exit_code == 0, r.output
    assert pd.read_csv(out)["frequency [Hz]"][0] == pytest.approx(f, rel=1e-5)


def test_modes_of_the_spring_mass_chain_match_the_matrix_eigenproblem(tmp_path):
    """Vertical modes of three masses (1, 2, 0.5 kg) on 500 N/m springs with 2 N s/m dampers: eigenvalues of
    [[0, I], [-M^-1 K, -M^-1 C]] (independent of gravity: linear springs along the chain)."""
    out = tmp_path / "modes.parquet"
    r = invoke("modes", EXAMPLES / "spring_mass_chain.yaml", "--out", out)
    assert r.exit_code == 0, r.output
    k, c = 500.0, 2.0
    S = np.array([[2, -1, 0], [-1, 2, -1], [0, -1, 1]], float)
    Mi = np.diag(1 / np.array([1.0, 2.0, 0.5]))
    A = np.block([[np.zeros((3, 3)), np.eye(3)], [-Mi @ (k * S), -Mi @ (c * S)]])
    lam = np.linalg.eigvals(A)
    lam = lam[lam.imag > 0]
    want = np.sort(np.abs(lam)) / (2 * np.pi)
    zeta = -lam.real / np.abs(lam)
    df = pd.read_parquet(out)
    damped = df[df["damping ratio [-]"] > 1e-6]          # the lateral modes are undamped (dampers act along)
    assert np.allclose(np.sort(damped["frequency [Hz]"]), want, rtol=1e-5)
    assert np.allclose(np.sort(damped["damping ratio [-]"]), np.sort(zeta), rtol=1e-4)


def test_statics_of_the_spring_mass_chain_sags_by_the_hanging_weights(tmp_path):
    out = tmp_path / "eq.csv"
    r = invoke("statics", EXAMPLES / "spring_mass_chain.yaml", "--out", out)
    assert r.exit_code == 0, r.output
    assert "stable" in r.output and "yes" in r.output
    df = pd.read_csv(out)
    k = 500.0
    assert len(df) == 1
    assert df["m1.y [m]"][0] == pytest.approx(-0.25 - 3.5 * G / k, abs=1e-8)
    assert df["m2.y [m]"][0] == pytest.approx(-0.50 - 6.0 * G / k, abs=1e-8)
    assert df["m3.y [m]"][0] == pytest.approx(-0.75 - 6.5 * G / k, abs=1e-8)   # 0.12753 m below its start
    assert "-0.87753" in r.output and "y [m]" in r.output                      # the printed configuration


def _slider_x(t):
    th = 2 * np.pi * t          # x = r cos(th) + sqrt(l^2 - r^2 sin^2(th)), r 0.2, l 0.4
    return 0.2 * np.cos(th) + np.sqrt(0.16 - 0.04 * np.sin(th) ** 2)


def test_statics_end_is_the_quasi_static_analysis(tmp_path):
    out = tmp_path / "qs.parquet"
    r = invoke("statics", EXAMPLES / "slider_crank.yaml", "--end", 0.5, "--step", 0.05, "--out", out)
    assert r.exit_code == 0, r.output
    df = pd.read_parquet(out)
    assert len(df) == 11 and "quasi-static" in r.output
    assert np.allclose(df["slider.x [m]"], _slider_x(df["time [s]"].to_numpy()), atol=1e-8)
    assert "drive.effort [N m]" in df.columns


def test_kinematics_with_a_marker_then_plot_it(tmp_path):
    """Four-bar: the coupler's point B stays sqrt(0.18) m from the crank pin A and sqrt(0.17) m from the rocker
    pivot O4 (0.4, 0); --marker puts coupler.B in the table, and `mbdsim plot` draws it."""
    out, png = tmp_path / "kin.csv", tmp_path / "b.png"
    r = invoke("kinematics", EXAMPLES / "four_bar.yaml", "--end", 1, "--step", 0.01, "--out", out, "--marker", "B")
    assert r.exit_code == 0, r.output
    assert "success" in r.output and "True" in r.output
    df = pd.read_csv(out)
    t, bx, by = df["time [s]"].to_numpy(), df["coupler.B.x [m]"].to_numpy(), df["coupler.B.y [m]"].to_numpy()
    th = np.pi / 2 + 2 * np.pi * t
    ax, ay = 0.1 * np.cos(th), 0.1 * np.sin(th)
    assert len(df) == 101
    assert np.allclose(np.hypot(bx - ax, by - ay), np.sqrt(0.18), atol=1e-8)
    assert np.allclose(np.hypot(bx - 0.4, by), np.sqrt(0.17), atol=1e-8)
    r = invoke("plot", out, "coupler.B.y", "-o", png)
    assert r.exit_code == 0, r.output
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_run_markers_adds_every_marker_and_plot_reads_it(tmp_path):
    out, png = tmp_path / "run.parquet", tmp_path / "tip.png"
    r = invoke("run", EXAMPLES / "pendulum.yaml", "--end", 0.5, "--step", 0.01, "--out", out, "--markers")
    assert r.exit_code == 0, r.output
    df = pd.read_parquet(out)
    tip = df[["rod.tip.x [m]", "rod.tip.y [m]"]].to_numpy()
    cm = df[["rod.x [m]", "rod.y [m]"]].to_numpy()
    assert np.allclose(tip, 2 * cm, atol=1e-9)          # the tip is twice as far from the pin as the centre
    r = invoke("plot", out, "rod.tip.y", "-o", png)
    assert r.exit_code == 0, r.output
    r = invoke("kinematics", EXAMPLES / "slider_crank.yaml", "--end", 0.1, "--out", tmp_path / "k.csv", "--markers")
    assert r.exit_code == 0 and "has no markers" in flat(r)


@pytest.mark.parametrize("args, words", [
    (["kinematics", EXAMPLES / "pendulum.yaml", "--end", 1], "1 DOF remain free"),
    (["kinematics", "absent.yaml", "--end", 1], "does not exist"),
    (["kinematics", EXAMPLES / "four_bar.yaml", "--end", 1, "--out", "k.txt"], "expected a .parquet or .csv"),
    (["kinematics", EXAMPLES / "four_bar.yaml", "--end", 0], "--end must be > 0"),
    (["kinematics", EXAMPLES / "four_bar.yaml", "--end", 1, "--marker", "B"], "give --out FILE"),
    (["statics", EXAMPLES / "four_bar.yaml", "--step", 0.1], "--step needs --end"),
    (["statics", EXAMPLES / "four_bar.yaml", "--out", "s.json"], "expected a .parquet or .csv"),
    (["modes", EXAMPLES / "pendulum.yaml", "--at", "top"], "--at: expected 'equilibrium' or 'initial'"),
    (["modes", ROOT / "tests" / "bad_models" / "unknown_body.yaml"], "joint 'pin'.body_j"),
])
def test_bad_input_exits_2_with_one_clear_line(args, words):
    r = invoke(*args)
    assert r.exit_code == 2, r.output
    assert words in flat(r) and "Traceback" not in r.output


def test_unknown_marker_names_the_field_and_the_markers(tmp_path):
    r = invoke("run", EXAMPLES / "four_bar.yaml", "--end", 0.1, "--out", tmp_path / "r.csv", "--marker", "C")
    assert r.exit_code == 2, r.output
    assert "simulate.markers: 'C' names no marker; markers: coupler.B" in flat(r)
    assert not (tmp_path / "r.csv").exists()


def test_foreign_out_files_are_not_replaced(tmp_path):
    mine = tmp_path / "notes.csv"
    mine.write_text("my,own\n1,2\n")
    for cmd in (["modes", EXAMPLES / "pendulum.yaml"], ["statics", EXAMPLES / "spring_mass_chain.yaml"]):
        r = invoke(*cmd, "--out", mine)
        assert r.exit_code == 2, r.output
        assert "notes.csv" in flat(r) and mine.read_text() == "my,own\n1,2\n"


def test_modes_of_a_fully_driven_model_say_there_are_none(tmp_path):
    r = invoke("modes", EXAMPLES / "four_bar.yaml", "--out", tmp_path / "m.csv")
    assert r.exit_code == 0, r.output
    assert "no free coordinates" in flat(r) and len(pd.read_csv(tmp_path / "m.csv")) == 0


def test_help_of_the_analyses_has_examples_and_units():
    for cmd in ("kinematics", "statics", "modes"):
        text = flat(invoke(cmd, "--help"))
        assert "Example: mbdsim " + cmd in text and "Exit status" in text
    assert "[Hz]" in flat(invoke("modes", "--help"))
    assert "--marker" in flat(invoke("run", "--help"))


def test_marker_columns_by_name_in_python():
    """to_dataframe(markers=...): True every marker, or names ("B" or "coupler.B"); unknown names and
    other values are ModelErrors naming the field."""
    import mbdsim as mb
    m = mb.load_model(EXAMPLES / "four_bar.yaml")
    res = mb.kinematics(m, end_time=0.1, output_step=0.05)
    for sel in (True, ["B"], "coupler.B"):
        cols = [c for c in res.to_dataframe(markers=sel).columns if c.startswith("coupler.B.")]
        assert cols[:3] == ["coupler.B.x [m]", "coupler.B.y [m]", "coupler.B.z [m]"]
    assert not any(c.startswith("coupler.B.") for c in res.to_dataframe().columns)
    with pytest.raises(mb.ModelError, match="'Q' names no marker; markers: coupler.B"):
        res.to_dataframe(markers=["Q"])
    with pytest.raises(mb.ModelError, match="markers: expected True, False or a list"):
        res.to_dataframe(markers=3)
    with pytest.raises(mb.ModelError, match="kinematics.markers"):
        mb.kinematics(m, end_time=0.1, out="never.csv", markers=["Q"])
    assert not Path("never.csv").exists()


LOCKED = (ROOT / "tests" / "test_io_cli.py").read_text().split('LOCKED = """')[1].split('"""')[0]


def test_a_kinematic_lock_up_exits_1_keeping_the_samples_before_it(tmp_path):
    """Crank 0.3 m, rod 0.2 m: the slider-crank locks where sin(theta) = 2/3, t = asin(2/3) / (2 pi)."""
    p, out = tmp_path / "locked.yaml", tmp_path / "k.csv"
    p.write_text(LOCKED)
    r = invoke("kinematics", p, "--end", 0.5, "--step", 0.001, "--out", out)
    assert r.exit_code == 1, r.output
    assert "Traceback" not in r.output and "False" in r.output
    t = pd.read_csv(out)["time [s]"].to_numpy()
    assert t[-1] == pytest.approx(np.arcsin(2 / 3) / (2 * np.pi), abs=2e-3)


@pytest.mark.parametrize("cmd, api", [(["kinematics", "four_bar.yaml", "--end", 1], "kinematics"),
                                      (["statics", "spring_mass_chain.yaml"], "equilibrium"),
                                      (["statics", "slider_crank.yaml", "--end", 1], "quasi_static"),
                                      (["modes", "pendulum.yaml"], "linearize")])
def test_interrupt_exits_130(monkeypatch, cmd, api):
    import mbdsim as mb

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt
    monkeypatch.setattr(mb, api, interrupted)
    r = invoke(cmd[0], EXAMPLES / cmd[1], *cmd[2:])
    assert r.exit_code == 130 and "interrupted" in r.output


def test_resuming_a_streamed_run_keeps_its_marker_columns(tmp_path):
    """The checkpoint's fingerprint covers the marker columns: the same selection resumes, another is refused."""
    import mbdsim as mb
    m, out = mb.load_model(EXAMPLES / "pendulum.yaml"), tmp_path / "r.parquet"
    mb.simulate(m, end_time=0.5, output_step=0.01, out=out, markers=["tip"])
    again = mb.simulate(m, end_time=0.5, output_step=0.01, out=out, markers=["rod.tip"], resume=True)
    assert again.success and "rod.tip.y [m]" in pd.read_parquet(out).columns
    with pytest.raises(mb.ModelError, match="marker columns differ"):
        mb.simulate(m, end_time=0.5, output_step=0.01, out=out, resume=True)
