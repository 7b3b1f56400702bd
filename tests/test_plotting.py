"""mb.plot (signals, units, x-signal, events), lenient column matching, `mbdsim plot` command."""
import subprocess
import sys

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.plotting import match_column, resolve, split_unit


def pendulum():
    """Uniform rod of 1 m, 2 kg, pinned at one end, released horizontal (y up)."""
    model = mb.Model("pendulum", gravity=(0.0, -9.81, 0.0))
    rod = model.add_body("rod", mass=2.0, inertia=(1e-3, 2.0 / 12, 2.0 / 12), position=(0.5, 0, 0))
    rod.add_marker("tip", point=(1.0, 0, 0))
    model.add_revolute("pin", model.ground, rod, point=(0, 0, 0), axis=(0, 0, 1))
    return model


@pytest.fixture(scope="module")
def res():
    return mb.simulate(pendulum(), end_time=1.0, output_step=0.01)


COLS = ["time [s]", "rod.x [m]", "rod.vx [m/s]", "rod.vy [m/s]", "pin.angle [rad]", "pin.angle_rate [rad/s]"]


def test_match_column_exact_case_unit_prefix():
    assert match_column(COLS, "rod.x [m]") == "rod.x [m]"
    assert match_column(COLS, "ROD.X") == "rod.x [m]"                  # case-insensitive, unit ignored
    assert match_column(COLS, "pin.angle") == "pin.angle [rad]"        # exact base beats the prefix of _rate
    assert match_column(COLS, "pin.angle_r") == "pin.angle_rate [rad/s]"   # unique prefix
    assert split_unit("pin.angle_rate [rad/s]") == ("pin.angle_rate", "rad/s")


def test_match_column_errors_list_columns():
    with pytest.raises(mb.ModelError, match="ambiguous.*'rod.vx \\[m/s\\]', 'rod.vy \\[m/s\\]'"):
        match_column(COLS, "rod.v")
    with pytest.raises(mb.ModelError, match="matches no column; valid columns: 'time \\[s\\]'") as e:
        match_column(COLS, "crank.angle")
    assert e.value.field == "signal"


def test_plot_callable_label_unit_and_data(res):
    ax = mb.plot(res, lambda r: r.joint_coordinate("pin"))
    assert ax.get_xlabel() == "time [s]"
    assert ax.get_ylabel() == "pin angle [rad]"
    (line,) = ax.lines
    np.testing.assert_array_equal(line.get_xdata(), res.time)
    np.testing.assert_array_equal(line.get_ydata(), res.joint_coordinate("pin"))


def test_transformed_measure_gets_no_borrowed_unit(res):
    ax = mb.plot(res, lambda r: np.degrees(r.joint_coordinate("pin")))
    assert "rad" not in ax.get_ylabel()
    ax = mb.plot(res, ("pin angle [deg]", lambda r: np.degrees(r.joint_coordinate("pin"))))
    assert ax.get_ylabel() == "pin angle [deg]"


def test_vector_signal_against_other_signal(res):
    ax = mb.plot(res, lambda r: r.reaction_force("pin"), x="pin.angle")
    assert ax.get_xlabel() == "pin.angle [rad]" and ax.get_ylabel() == "pin reaction force [N]"
    assert [ln.get_label() for ln in ax.lines] == [f"pin reaction force {c}" for c in "xyz"]
    np.testing.assert_allclose(ax.lines[0].get_xdata(), res.joint_coordinate("pin"))


def test_several_signals_same_unit_and_existing_axes(res):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    out = mb.plot(res, ["rod.x", lambda r: r.position("rod")[:, 1]], ax=ax, lw=2)
    assert out is ax and len(ax.lines) == 2 and ax.lines[0].get_linewidth() == 2
    s = resolve(res, lambda r: r.velocity(r.system.model.bodies["rod"].markers["tip"]))
    assert s.unit == "m/s" and s.values.shape == (len(res.time), 3)
    plt.close(fig)


def test_events_marked_as_vertical_lines(res):
    res.events = [0.25, (0.5, "contact"), 7.0]     # 7 s is outside the run: not drawn
    try:
        ax = mb.plot(res, "pin.angle")
        xs = sorted(ln.get_xdata()[0] for ln in ax.lines[1:])
        assert xs == [0.25, 0.5]
        assert len(mb.plot(res, "pin.angle", events=False).lines) == 1
    finally:
        del res.events


def test_different_units_get_separate_labelled_axes(res):
    import matplotlib.pyplot as plt

    ax = mb.plot(res, ["pin.angle", "rod.x", "rod.y", "pin.angle_rate"])
    axes = ax.figure.axes
    assert ax is axes[0] and len(axes) == 3                        # rad, m, rad/s
    assert [a.get_ylabel() for a in axes] == ["pin.angle [rad]", "[m]", "pin.angle_rate [rad/s]"]
    assert [len(a.lines) for a in axes] == [1, 2, 1] and axes[-1].get_xlabel() == "time [s]"
    plt.close(ax.figure)
    fig, ax = plt.subplots()
    out = mb.plot(res, ["pin.angle", "rod.x"], ax=ax)               # given axes: a twin on the right
    assert out is ax and len(fig.axes) == 2
    assert ax.get_ylabel() == "pin.angle [rad]" and fig.axes[1].get_ylabel() == "rod.x [m]"
    assert len(mb.plot(res, ["rod.x", "rod.y"]).figure.axes) == 1    # one unit, one axis
    plt.close("all")


def test_unknown_column_names_at_most_ten_closest(res):
    df = res.to_dataframe()
    assert len(df.columns) > 20
    with pytest.raises(mb.ModelError) as e:
        match_column(df.columns, "rod.vel")
    msg = str(e.value)
    listed = [c for c in df.columns if repr(c) in msg]
    assert f"the closest of the {len(df.columns)} columns" in msg and 1 <= len(listed) <= 10
    assert "'rod.vx [m/s]'" in msg and "'pin.Tz [N m]'" not in msg


def test_bad_signal_errors(res):
    with pytest.raises(mb.ModelError, match="matches no column; the closest"):
        mb.plot(res, "crank")
    with pytest.raises(mb.ModelError, match="one value .* per output time"):
        mb.plot(res, lambda r: 1.0)
    with pytest.raises(mb.ModelError, match="expected a callable"):
        mb.plot(res, 3)
    with pytest.raises(mb.ModelError, match="x: must be a scalar signal"):
        mb.plot(res, "pin.angle", x=lambda r: r.position("rod"))


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "mbdsim", *args], capture_output=True, text=True, timeout=120)


def test_cli_plot_csv_parquet(res, tmp_path):
    df = res.to_dataframe()
    df.to_csv(tmp_path / "r.csv", index=False)
    df.to_parquet(tmp_path / "r.parquet")
    p = _cli("plot", str(tmp_path / "r.parquet"), "PIN.ANGLE", "rod.x", "-o", str(tmp_path / "f.png"))
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "f.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    from typer.testing import CliRunner

    from mbdsim.cli.app import app
    cli = lambda *a: CliRunner().invoke(app, list(a))  # noqa: E731 - in-process for the other cases
    r = cli("plot", str(tmp_path / "r.csv"), "rod.y", "--x", "rod.x", "-o", str(tmp_path / "f.svg"))
    assert r.exit_code == 0, r.output
    assert "<svg" in (tmp_path / "f.svg").read_text()
    r = cli("plot", str(tmp_path / "r.csv"), "pin.angel", "-o", str(tmp_path / "g.png"))
    assert r.exit_code == 2 and "closest" in r.output and "'pin.angle [rad]'" in r.output
    assert "--list" in r.output and r.output.count("'") <= 2 * 10 + 2   # ten names at most, and the signal
    r = cli("plot", str(tmp_path / "r.csv"), "--list")
    assert r.exit_code == 0 and r.output.split("\n")[0] == "time [s]" and "pin.angle [rad]" in r.output
    assert r.exception is None or isinstance(r.exception, SystemExit)
    assert not (tmp_path / "g.png").exists()
    r = cli("plot", str(tmp_path / "missing.csv"), "rod.x")
    assert r.exit_code == 2 and "does not exist" in r.output
    r = cli("plot", str(tmp_path / "r.csv"), "rod.x", "-o", str(tmp_path / "f.jpg"))
    assert r.exit_code == 2 and "expected a .png, .svg or .pdf" in r.output


def test_cli_imports_stay_lazy():
    code = ("import sys, mbdsim; before = set(sys.modules); import mbdsim.cli.app; "
            "print(sorted(m for m in set(sys.modules) - before if m.split('.')[0] in "
            "('matplotlib', 'pandas', 'pyarrow', 'selenium')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.stdout.strip() == "[]", out.stdout + out.stderr


def test_friction_stop_marked_at_closed_form_time():
    """A car sliding on a rail with Coulomb friction stops at t = v0 / (mu g): the stick event is marked."""
    g, mu, v0 = 9.81, 0.3, 1.5
    m = mb.Model("rail", gravity=(0, -g, 0))
    car = m.add_particle("car", 2.0, velocity=(v0, 0, 0))
    rail = m.add_translational("rail", m.ground, car, (0, 0, 0), (1, 0, 0))
    m.add_friction("friction", rail, mu, mu)
    res = mb.simulate(m, end_time=1.0, output_step=0.01)
    ax = mb.plot(res, lambda r: r.joint_coordinate(rail))
    assert ax.get_ylabel() == "rail displacement [m]"
    marks = [ln.get_xdata()[0] for ln in ax.lines[1:]]
    assert marks == [pytest.approx(v0 / (mu * g), rel=1e-6)]
