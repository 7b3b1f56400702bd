"""Results written to disk while a run goes (`out=`): the final file is `to_dataframe()`, an interrupted or
killed run leaves a readable file holding what it computed (checked against the closed-form free fall)."""
import os
import signal
import subprocess
import sys
import textwrap

import numpy as np
import pandas as pd
import pytest

import mbdsim as mb

G = 9.81


def projectile():
    """A free particle thrown at (1, 2, 0) m/s under gravity -y: x = t, y = 2 t - g t^2 / 2."""
    model = mb.Model("throw", gravity=(0.0, -G, 0.0))
    model.add_particle("ball", 0.3, position=(0, 0, 0), velocity=(1.0, 2.0, 0.0))
    return model


def check_free_fall(df):
    t = df["time [s]"].to_numpy()
    assert np.allclose(df["ball.x [m]"], t, atol=1e-9)
    assert np.allclose(df["ball.y [m]"], 2 * t - G * t**2 / 2, atol=1e-9)


def oscillator():
    """A particle on a spring (k = 400 N/m, m = 1 kg, free length 1 m) released 0.1 m out, no gravity:
    x = 1 + 0.1 cos(20 t) [m]."""
    model = mb.Model("osc")
    p = model.add_particle("ball", 1.0, position=(1.1, 0, 0), velocity=(0, 0, 0))
    model.add_spring_damper("k", (model.ground, (0, 0, 0)), p, 400.0, free_length=1.0)
    return model


def check_oscillation(df, atol=1e-6):
    t = df["time [s]"].to_numpy()
    assert np.allclose(df["ball.x [m]"], 1 + 0.1 * np.cos(20 * t), atol=atol)
    assert np.allclose(df["ball.y [m]"], 0.0, atol=1e-12)


def pendulum_with_spring():
    """Torsion spring on a pin: runs on the Python (HHT) path."""
    model = mb.Model("pend", gravity=(0.0, -G, 0.0))
    rod = model.add_body("rod", 1.0, inertia=(0.01, 0.08, 0.08), position=(0.5, 0, 0))
    model.add_revolute("pin", model.ground, rod, (0, 0, 0), (0, 0, 1))
    model.add_torsion_spring("k", "pin", 5.0)
    return model


@pytest.mark.parametrize("suffix, method", [(".parquet", None), (".csv", "hht"), (".parquet", "rk45")])
def test_file_is_the_results_table(tmp_path, suffix, method):
    model = projectile() if method is None else pendulum_with_spring()
    out = tmp_path / f"r{suffix}"
    seen = []
    res = mb.simulate(model, 0.5, 0.01, method=method, out=out, progress=seen.append)
    df = pd.read_parquet(out) if suffix == ".parquet" else pd.read_csv(out)
    pd.testing.assert_frame_equal(df, res.to_dataframe(), check_exact=suffix == ".parquet", rtol=1e-12)
    assert seen and seen[-1] == pytest.approx(0.5) and all(np.diff(seen) >= 0)
    if method is None:
        check_free_fall(df)
    assert not list(tmp_path.glob(".*partial"))          # no temporary file left behind


@pytest.mark.parametrize("method", [None, "rk45", "hht"])
def test_ctrl_c_keeps_the_outputs_before_it(tmp_path, method):
    out = tmp_path / "r.parquet"

    def progress(t):
        if t > 0.6:
            raise KeyboardInterrupt
    res = mb.simulate(oscillator(), 2.0, 0.001, method=method, out=out, progress=progress)
    assert not res.success and "KeyboardInterrupt" in res.message
    df = pd.read_parquet(out)
    assert 0.5 <= df["time [s]"].iloc[-1] < 1.5 and len(df) == len(res.time)
    check_oscillation(df, 1e-3 if method == "hht" else 1e-6)      # HHT: second order, numerical damping


def test_kinematics_progress_and_out(tmp_path):
    model = mb.Model("crank")
    crank = model.add_body("crank", 1.0, inertia=(0.01, 0.01, 0.01), position=(0.1, 0, 0))
    model.add_revolute("pin", model.ground, crank, (0, 0, 0), (0, 0, 1))
    model.add_motion("drive", "pin", displacement="2*pi*t")
    seen = []
    res = mb.kinematics(model, 1.0, 0.01, progress=seen.append, out=tmp_path / "k.csv")
    df = pd.read_csv(tmp_path / "k.csv")
    assert len(seen) == 101 and seen[-1] == pytest.approx(1.0)
    assert np.allclose(df["pin.angle [rad]"], 2 * np.pi * df["time [s]"], atol=1e-9)   # continuous past pi
    assert len(df) == len(res.time) == 101


def test_a_killed_run_leaves_a_readable_file(tmp_path):
    """The process kills itself (SIGKILL: nothing is cleaned up) half-way through a run writing every chunk."""
    out = tmp_path / "r.parquet"
    code = textwrap.dedent(f"""
        import os, signal
        import mbdsim as mb
        from mbdsim.results import stream
        stream.WRITE_INTERVAL = 0.0
        model = mb.Model("osc")
        p = model.add_particle("ball", 1.0, position=(1.1, 0, 0), velocity=(0, 0, 0))
        model.add_spring_damper("k", (model.ground, (0, 0, 0)), p, 400.0, free_length=1.0)
        def progress(t):
            if t > 1.0:
                os.kill(os.getpid(), signal.SIGKILL)
        mb.simulate(model, 2.0, 0.001, out={str(out)!r}, progress=progress)
    """)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert r.returncode == -signal.SIGKILL, r.stderr
    df = pd.read_parquet(out)
    assert 0 < len(df) < 2001 and df["time [s]"].iloc[-1] <= 1.0 + 1e-12
    assert np.allclose(df["time [s]"], np.arange(len(df)) * 0.001, atol=1e-12)
    check_oscillation(df)


def test_bad_out_names_the_field(tmp_path):
    for bad in (tmp_path / "r.txt", tmp_path, 3.0):
        with pytest.raises(mb.ModelError) as err:
            mb.simulate(projectile(), 0.1, 0.01, out=bad)
        assert err.value.field == "out"
