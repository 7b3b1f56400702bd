"""progress=True (a rich bar on stderr) for simulate, kinematics and quasi_static: the same results as
progress=None, a cheap callback (at most ~10 bar updates a second), bad values still a clear ModelError."""
import io
import time
from pathlib import Path

import numpy as np
import pytest

import mbdsim as mb
from mbdsim._progress import REFRESH_HZ, ProgressBar

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def same(a, b):
    assert np.array_equal(a.time, b.time) and np.array_equal(a.q, b.q) and np.array_equal(a.v, b.v)
    assert a.success and b.success


def test_simulate_with_a_bar_gives_the_same_result(capsys):
    m = mb.load_model(EXAMPLES / "pendulum.yaml")
    plain = mb.simulate(m, end_time=0.5, output_step=0.01)
    capsys.readouterr()
    for p in (True, False):
        same(mb.simulate(m, end_time=0.5, output_step=0.01, progress=p), plain)
    assert "Traceback" not in capsys.readouterr().err          # not a terminal here: the bar draws nothing


def test_kinematics_and_quasi_static_with_a_bar_give_the_same_results(capsys):
    m = mb.load_model(EXAMPLES / "slider_crank.yaml")
    same(mb.kinematics(m, end_time=0.3, output_step=0.05, progress=True),
         mb.kinematics(m, end_time=0.3, output_step=0.05))
    seen = []
    qs = mb.quasi_static(m, end_time=0.3, output_step=0.05, progress=seen.append)
    same(mb.quasi_static(m, end_time=0.3, output_step=0.05, progress=True), qs)
    assert seen == pytest.approx(list(qs.time))                 # the callback form: each solved time [s]


def test_a_raising_callback_ends_the_quasi_static_run_keeping_its_samples():
    m = mb.load_model(EXAMPLES / "slider_crank.yaml")

    def stop(t):
        if t > 0.12:
            raise RuntimeError("enough")
    res = mb.quasi_static(m, end_time=0.3, output_step=0.05, progress=stop)
    assert not res.success and "enough" in res.message and len(res.time) == 4 and res.time[-1] == pytest.approx(0.15)


@pytest.mark.parametrize("analysis, kwargs", [
    (mb.simulate, {}), (mb.kinematics, {}), (mb.quasi_static, {}),
])
@pytest.mark.parametrize("bad", ["yes", 1, 0.5])
def test_bad_progress_values_are_model_errors(analysis, kwargs, bad):
    m = mb.load_model(EXAMPLES / "slider_crank.yaml")
    with pytest.raises(mb.ModelError, match=r"progress: expected True, False, None or a callable progress\(t\)") as e:
        analysis(m, end_time=0.1, progress=bad, **kwargs)
    assert e.value.field == "progress" and analysis.__name__ in str(e.value)


def test_the_bar_in_a_terminal_shows_the_time_and_updates_at_most_ten_times_a_second():
    from rich.console import Console
    buf = io.StringIO()
    console = Console(file=buf, force_terminal=True, width=100)
    t0 = time.monotonic()
    with ProgressBar("simulating demo", 0.0, 2.0, console=console) as bar:
        for t in np.linspace(0.0, 2.0, 20000):
            bar(t)
        elapsed, during = time.monotonic() - t0, bar.updates
    text = buf.getvalue()
    assert "simulating demo" in text and "t = " in text
    assert during <= 1 + elapsed * REFRESH_HZ + 1                  # 20000 calls, a handful of bar updates
    assert bar.updates == during + 1 and bar.t == 2.0             # the last time is shown at the end


def test_default_progress_shows_a_bar_only_in_a_terminal_and_after_the_delay(monkeypatch):
    """progress=None: in a terminal (or notebook) a bar appears once the run has taken DELAY s of wall time;
    outside a terminal, or before the delay, nothing is drawn."""
    import mbdsim._progress as pr
    made = []

    class Recorder:
        def __init__(self, *args):
            made.append(args)
            self.ts = []

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            made.append("closed")

        def __call__(self, t):
            self.ts.append(t)
    monkeypatch.setattr(pr, "ProgressBar", Recorder)
    with pr.progress_of(None, "simulate", "sim", 0.0, 2.0) as p:   # not a terminal here: nothing
        assert p is None
    monkeypatch.setattr(pr, "interactive", lambda: True)
    with pr.progress_of(None, "simulate", "sim", 0.0, 2.0) as p:   # a terminal, before the delay: no bar
        p(0.5)
    assert made == []
    monkeypatch.setattr(pr, "DELAY", 0.0)
    with pr.progress_of(None, "simulate", "sim", 0.0, 2.0) as p:   # past the delay: the bar, closed at the end
        p(0.5)
        p(1.0)
    assert made == [("sim", 0.0, 2.0), "closed"]
