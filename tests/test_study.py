"""Parameter studies without Dask: design, units, paths, outputs against closed forms, failing variants,
resume from a partial file, sensitivity against an exact linear model, study files, plots, CLI."""
import math
import warnings

import numpy as np
import pandas as pd
import pytest

import mbdsim as mb
from mbdsim.errors import ModelError, ModelFileError
from mbdsim.studies.design import make_design, parse_parameter, to_si_value
from mbdsim.studies.measures import OutputError, fill_template
from mbdsim.studies.models import slider_crank
from mbdsim.studies.variant import apply_path

SC_OUT = {"amax": "peak(x(acceleration('slider')))",
          "t_idc": "crossing(x(velocity('slider')), 0, direction=1)",
          "F": "max(norm(reaction_force('crank_rod')))"}
FAST = {"end_time": 0.6, "output_step": 0.01, "rtol": 1e-6}


def test_units_and_expressions():
    assert to_si_value("200 mm", "p") == pytest.approx(0.2)
    assert to_si_value("60 rpm", "p") == pytest.approx(2 * math.pi)
    assert to_si_value(150, "p", "mm") == pytest.approx(0.15)
    assert to_si_value("3 kN/m", "p") == pytest.approx(3000.0)
    assert to_si_value("2*pi*t", "p") == "2*pi*t"          # an expression stays text
    assert fill_template(["{a + b/2}", 0, "2*{a}*t"], {"a": 1.5, "b": 1.0}, "x") == [2.0, 0, "2*1.5*t"]
    with pytest.raises(ModelError, match="study set 'x'"):
        fill_template("{a + nope}", {"a": 1.0}, "x")


def test_grid_and_samplers():
    grid = make_design([parse_parameter("a", [1, 2, 3]), parse_parameter("b", {"range": [0, 1], "num": 2})])
    assert len(grid) == 6 and list(grid.loc[1]) == [1.0, 1.0] and list(grid.loc[5]) == [3.0, 1.0]
    n = 16
    for method in ("lhs", "sobol"):
        d = make_design([parse_parameter("x", {"range": ["100 mm", "300 mm"]}),
                         parse_parameter("y", {"distribution": "uniform", "low": 2, "high": 4})], method, n, seed=3)
        assert len(d) == n and d["x"].between(0.1, 0.3).all() and d["y"].between(2, 4).all()
        # both designs put exactly one point in each of the n equal strata of every parameter
        for col, lo, hi in (("x", 0.1, 0.3), ("y", 2, 4)):
            strata = np.floor((d[col] - lo) / (hi - lo) * n).astype(int)
            assert sorted(strata) == list(range(n))
    mc = make_design([parse_parameter("m", {"distribution": "normal", "mean": "2 kg", "std": "100 g"}),
                      parse_parameter("k", [1, 2])], "random", 2000, seed=1)
    assert len(mc) == 4000 and abs(mc["m"].mean() - 2.0) < 4 * 0.1 / math.sqrt(2000)
    assert abs(mc["m"].std() - 0.1) < 0.01
    with pytest.raises(ModelError, match="study parameter 'm'"):
        parse_parameter("m", {"distribution": "cauchy", "mean": 1, "std": 1})
    with pytest.raises(ModelError, match="grid needs discrete values"):
        make_design([parse_parameter("x", {"range": [0, 1]})], "grid")


def test_paths_into_model_data():
    data = {"bodies": [{"name": "rod", "mass": 1.0}], "gravity": [0, -9.81, 0]}
    apply_path(data, "bodies.rod.mass", 2.5)
    apply_path(data, "gravity.1", -1.62)
    assert data == {"bodies": [{"name": "rod", "mass": 2.5}], "gravity": [0, -1.62, 0]}
    with pytest.raises(ModelError, match="no item named 'rod2'.*names are: rod"):
        apply_path(data, "bodies.rod2.mass", 1.0)
    with pytest.raises(ModelError, match="neither a path"):
        mb.Study("examples/slider_crank.yaml", {"crank": [0.1]}, {"a": SC_OUT["amax"]}, analysis=FAST)
    with pytest.raises(ModelError, match="not an argument"):
        mb.Study(slider_crank, {"crank_length": [0.1]}, {"a": SC_OUT["amax"]}, analysis=FAST)


@pytest.mark.parametrize("text", ["__import__('os')", "res.system", "lambda: 1", "open('x')", "max(t)[0]("])
def test_output_expressions_are_not_code(text):
    with pytest.raises(OutputError, match="study output 'o'"):
        mb.Study(slider_crank, {"crank": [0.1]}, {"o": text}, analysis=FAST)


def test_outputs_against_closed_form_and_failures():
    """Slider max acceleration r w^2 (1 + r/l) (outer dead centre), first inner dead centre at pi/w; a rod
    shorter than the crank locks up (status failed), a negative mass is refused (status error)."""
    study = mb.Study(slider_crank, {"crank": [0.1, 0.2, 0.5], "rod": [0.4], "speed": ["60 rpm", "90 rpm"],
                                    "rod_mass": [2.0]}, SC_OUT, analysis=FAST)
    bad = mb.Study(slider_crank, {"crank_mass": [-1.0]}, SC_OUT, analysis=FAST)
    df = study.run(workers=0)
    assert len(df) == 6 and df.attrs["executed"] == 6
    ok = df[df.crank < 0.4]
    assert (ok.status == "ok").all() and (df[df.crank == 0.5].status == "failed").all()
    assert df[df.crank == 0.5].message.str.contains("t = ").all()
    r, l, w = ok.crank, ok.rod, ok.speed
    assert np.allclose(ok.amax, r * w**2 * (1 + r / l), rtol=1e-8)
    assert np.allclose(ok.t_idc, math.pi / w, rtol=1e-8)
    more = {**SC_OUT, "t_min": "time_of_min(x(position('slider')))", "x_min": "min(x(position('slider')))",
            "travel": "final(x(position('slider'))) - initial(x(position('slider')))",
            "int_v": "integral(x(velocity('slider')))", "v_rms": "rms(x(velocity('slider')))"}
    kin = mb.Study(slider_crank, {"crank": [0.15]}, more, analysis={**FAST, "type": "kinematics"}).run(workers=0)
    assert kin.amax[0] == pytest.approx(0.15 * (2 * math.pi) ** 2 * (1 + 0.15 / 0.4), rel=1e-8)
    assert kin.t_min[0] == pytest.approx(0.5, abs=1e-6) and kin.x_min[0] == pytest.approx(0.4 - 0.15, abs=1e-9)
    assert kin.int_v[0] == pytest.approx(kin.travel[0], abs=2e-4)       # trapezoid rule, 10 ms samples
    assert 0 < kin.v_rms[0] < 0.15 * 2 * math.pi * (1 + 0.15 / 0.4)
    row = bad.run(workers=0).iloc[0]
    assert row.status == "error" and "mass" in row.message and math.isnan(row.amax)


def test_resume_runs_only_missing(tmp_path):
    out = tmp_path / "r.parquet"
    study = mb.Study(slider_crank, {"crank": [0.1, 0.15, 0.2], "rod": [0.3, 0.4]}, SC_OUT, analysis=FAST)
    full = study.run(workers=0, out=out)
    part = pd.read_parquet(out).iloc[[0, 2, 5]]          # as if killed after three rows
    part.to_parquet(out, index=False)
    again = study.run(workers=0, out=out)
    assert again.attrs["executed"] == 3 and len(pd.read_parquet(out)) == 6
    cols = ["run", "crank", "rod", *SC_OUT, "status"]
    pd.testing.assert_frame_equal(again[cols], full[cols])
    assert again.set_index("run").loc[[0, 2, 5], "wall_time"].tolist() == part.wall_time.tolist()
    assert study.run(workers=0, out=out).attrs["executed"] == 0
    other = mb.Study(slider_crank, {"crank": [0.1, 0.12]}, SC_OUT, analysis=FAST)
    with pytest.raises(ModelError, match="another study"):
        other.run(workers=0, out=out)


def test_sensitivity_exact_linear_model():
    """y = 2 x1 + x2 with x1, x2 ~ U(0, 1): SRC = (2, 1)/sqrt(5), first-order Sobol (4/5, 1/5)."""
    d = make_design([parse_parameter("x1", {"range": [0, 1]}), parse_parameter("x2", {"range": [0, 1]})],
                    "sobol", 1024, seed=2)
    d["y"], d["status"] = 2 * d.x1 + d.x2, "ok"
    src = mb.sensitivity(d, ["x1", "x2"], ["y"])
    assert src.loc[("y", "x1"), "src"] == pytest.approx(2 / math.sqrt(5), abs=1e-3)
    assert src.loc[("y", "x2"), "src"] == pytest.approx(1 / math.sqrt(5), abs=1e-3)
    assert src["r2"].iloc[0] == pytest.approx(1.0)
    s1 = mb.sensitivity(d, ["x1", "x2"], ["y"], method="sobol")["S1"]
    assert s1[("y", "x1")] == pytest.approx(0.8, abs=0.02) and s1[("y", "x2")] == pytest.approx(0.2, abs=0.02)


def test_study_file_and_errors(tmp_path):
    study = mb.load_study("examples/slider_crank_study.yaml")
    assert len(study) >= 100 and {"crank", "rod", "speed", "bodies.slider.mass"} <= set(study.design.columns)
    assert study.design["speed"].between(math.pi - 1e-12, 3 * math.pi + 1e-12).all()   # 30..90 rpm in rad/s
    text = (tmp_path / "x.yaml")
    (tmp_path / "slider_crank.yaml").write_text(open("examples/slider_crank.yaml").read())
    text.write_text("model: slider_crank.yaml\nanalysis: {end_time: 1}\nparameters:\n  bodies.rod.mass: [1, 2]\n"
                    "outputs: {f: 'final(t)'}\nsamples: 4\n")
    with pytest.raises(ModelFileError, match=r"x.yaml, line 6: study.samples: unknown field"):
        mb.load_study(text)
    text.write_text("model: slider_crank.yaml\nanalysis: {end_time: 1}\nparameters:\n  bodies.rod.mas: [1, 2]\n"
                    "outputs: {f: 'final(t)'}\n")
    with pytest.raises(ModelFileError, match=r"line 4: study parameter .bodies.rod.mas..path: .*unknown field .mas."):
        mb.load_study(text)
    text.write_text("model: slider_crank.yaml\nanalysis: {end_time: 1}\nparameters:\n  bodies.rod.mass: [1, 2]\n"
                    "outputs: {f: 'final(t'}\n")
    with pytest.raises(ModelFileError, match=r"line 5: study output 'f'"):
        mb.load_study(text)


def test_plots_and_cli(tmp_path):
    from typer.testing import CliRunner

    from mbdsim.cli.app import app
    (tmp_path / "slider_crank.yaml").write_text(open("examples/slider_crank.yaml").read())
    (tmp_path / "s.yaml").write_text(
        "model: slider_crank.yaml\nanalysis: {end_time: 0.5 s, output_step: 10 ms, rtol: 1.0e-6}\n"
        "sampling: {method: lhs, samples: 5}\nparameters:\n  bodies.rod.mass: {range: [1 kg, 3 kg]}\n"
        "  bodies.slider.mass: {range: [1000 g, 2000 g]}\noutputs: {F: \"max(norm(reaction_force('crank_rod')))\"}\n")
    out = tmp_path / "r.parquet"
    res = CliRunner().invoke(app, ["study", str(tmp_path / "s.yaml"), "--workers", "0", "--out", str(out),
                                   "--plots", str(tmp_path / "p")])
    assert res.exit_code == 0, res.output
    df = pd.read_parquet(out)
    assert len(df) == 5 and (df.status == "ok").all() and df["bodies.slider.mass"].between(1, 2).all()
    assert {p.name for p in (tmp_path / "p").iterdir()} == {"main_effects.png", "scatter_matrix.png", "surface.png"}
    fig = mb.plot_study(df, "main_effects", ["bodies.rod.mass", "bodies.slider.mass"], ["F"])
    assert len(fig.axes) == 2
    bad = CliRunner().invoke(app, ["study", str(tmp_path / "nope.yaml")])
    assert bad.exit_code == 2 and "does not exist" in bad.output


def test_readme_study_snippet_runs():
    import re
    from pathlib import Path
    text = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    code = re.findall(r"```python\n(.*?)```", text.split("## Parameter studies", 1)[1].split("\n## ", 1)[0], re.S)[0]
    code = code.replace('workers=2, out="runs.parquet"', "workers=0").replace("samples=50", "samples=4")
    ns = {"mb": mb}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        exec(compile(code, "README.md", "exec"), ns)   # noqa: S102 - our own docs
    assert len(ns["df"]) == 4 and (ns["df"].status == "ok").all()
    assert np.all(np.diff(ns["df"].sort_values("bodies.rod.mass").F) > 0)   # heavier rod, larger pin force


def _compiled_signatures():
    import sys

    from numba.core.registry import CPUDispatcher
    return sum(len(obj.signatures) for name, mod in list(sys.modules.items()) if name.startswith("mbdsim")
               for obj in vars(mod).values() if isinstance(obj, CPUDispatcher))


def test_variants_reuse_compiled_kernels():
    """After the first variant, other lengths, masses and speeds compile nothing new (same topology)."""
    study = mb.Study(slider_crank, {"crank": [0.1, 0.12, 0.14], "rod_mass": [1.0, 3.0], "speed": [3.0, 7.0]},
                     SC_OUT, analysis={**FAST, "end_time": 0.1})
    first = mb.Study(slider_crank, {"crank": [0.2]}, SC_OUT, analysis={**FAST, "end_time": 0.1}).run(workers=0)
    assert first.status[0] == "ok"
    before = _compiled_signatures()
    df = study.run(workers=0)
    assert (df.status == "ok").all() and before > 0 and _compiled_signatures() == before


def test_lost_tasks_are_reported_not_stored(tmp_path):
    """A chunk Dask gave up on (KilledWorker) is a 'lost' row in the DataFrame but not in the file, so a
    re-run with the same file runs it again."""
    from mbdsim.studies.runner import _lost_rows, _Sink, chunks_of
    from mbdsim.studies.variant import run_chunk
    study = mb.Study(slider_crank, {"crank": [0.1, 0.12, 0.14]}, SC_OUT, analysis={**FAST, "end_time": 0.1})
    out = tmp_path / "r.parquet"
    sink = _Sink(study, out, None)
    first, second = chunks_of(study.design, 2)
    sink.add(run_chunk(study.plan, first))
    sink.add(_lost_rows(study, second, RuntimeError("worker died three times")), keep=False)
    sink.close()
    df = sink.frame(study)
    assert list(df.status) == ["ok", "ok", "lost"] and "worker died" in df.message[2]
    assert "run 2 lost: the Dask worker running it died" in df.message[2] and "same out= file" in df.message[2]
    assert sorted(pd.read_parquet(out).run) == [0, 1]
    assert study.run(workers=0, out=out).attrs["executed"] == 1


def _brent_extremum(res, sig, sign):
    """Independent reference: Brent's scalar search on the dense output around the best sample."""
    from scipy.optimize import minimize_scalar
    y = sign * sig(res)
    k = int(np.argmax(y))
    if k in (0, len(y) - 1):   # at an end: the sample itself
        return float(res.time[k]), float(sign * y[k])
    f = lambda t: -sign * float(np.asarray(sig(res.at(t)))[0])  # noqa: E731
    try:
        r = minimize_scalar(f, bracket=(res.time[k - 1], res.time[k], res.time[k + 1]), method="brent", tol=1e-12)
    except ValueError:   # the samples do not bracket a peak (flat or a kink): a bounded search
        r = minimize_scalar(f, bounds=(res.time[k - 1], res.time[k + 1]), method="bounded", options={"xatol": 1e-12})
    return (float(r.x), -sign * float(r.fun)) if -sign * float(r.fun) * sign >= y[k] else (float(res.time[k]), sign * y[k])


def test_grid_refinement_matches_result_searches():
    """results.refine (a grid of times per dense-output call; Result.maximum/minimum use it) against a
    Brent search on the dense output, Result.crossings and
    closed forms: slider x = r cos(wt) + sqrt(l^2 - r^2 sin^2(wt)), min l - r at t = pi/w; a smooth peak
    takes at most 3 dense-output calls (2 for a resolved peak); a kink (min |x - 0.5|) is located to round-off."""
    from scipy.optimize import brentq

    from mbdsim.results import refine
    r, l, w = 0.2, 0.5, 7.3
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = mb.simulate(slider_crank(crank=r, rod=l, speed=w), 1.0, 0.01, rtol=1e-6)
    calls = []
    at = res.at
    res.at = lambda ts: calls.append(len(np.atleast_1d(ts))) or at(ts)
    x = lambda q: q.position("slider")[:, 0]  # noqa: E731
    signals = {"F": lambda q: np.linalg.norm(q.reaction_force("crank_rod"), axis=1),
               "tau": lambda q: q.driver_effort("drive"), "x": x}
    for name, sig in signals.items():
        for sign in (+1, -1):
            ref = _brent_extremum(res, sig, sign)
            assert (res.maximum if sign > 0 else res.minimum)(sig) == refine.extremum(res, sig, sign)
            calls.clear()
            got = refine.extremum(res, sig, sign)
            assert got[1] == pytest.approx(ref[1], rel=1e-12, abs=1e-12), (name, sign)
            assert got[0] == pytest.approx(ref[0], abs=1e-6), (name, sign)
            assert len(calls) <= 3, (name, sign, calls)
    t_min, x_min = refine.extremum(res, x, -1)
    assert x_min == pytest.approx(l - r, abs=1e-12) and t_min == pytest.approx(math.pi / w, abs=1e-7)
    v = lambda q: q.velocity("slider")[:, 0]  # noqa: E731
    assert refine.first_crossing(res, v, 0.0, +1) == pytest.approx(math.pi / w, abs=1e-12)
    assert refine.first_crossing(res, v, 0.0, -1) == pytest.approx(res.crossings(v, 0.0, -1)[0], abs=1e-12)
    assert refine.first_crossing(res, v, 0.0, -1) == pytest.approx(2 * math.pi / w, abs=1e-11)
    assert math.isnan(refine.first_crossing(res, x, 5.0))
    exact = lambda t: r * math.cos(w * t) + math.sqrt(l**2 - (r * math.sin(w * t))**2) - 0.5  # noqa: E731
    t_half = brentq(exact, 0.0, math.pi / w, xtol=1e-15)
    t_k, v_k = refine.extremum(res, lambda q: np.abs(x(q) - 0.5), -1)
    assert v_k < 1e-12 and t_k == pytest.approx(t_half, abs=1e-10)
    assert refine.first_crossing(res, x, 0.5, -1) == pytest.approx(t_half, abs=1e-12)
    # peak pin forces over a sample of geometries and speeds: Brent's value, three calls each
    design = make_design([parse_parameter("crank", {"range": [0.15, 0.25]}), parse_parameter("rod", {"range": [0.4, 0.6]}),
                          parse_parameter("speed", {"range": [3.0, 9.5]})], "lhs", 8, seed=4)
    for p in design.to_dict("records"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = mb.simulate(slider_crank(**p), 2.0, 0.01, rtol=1e-6)
        at = res.at
        res.at = lambda ts: calls.append(len(np.atleast_1d(ts))) or at(ts)
        calls.clear()
        got = refine.extremum(res, signals["F"], +1)
        n_calls = len(calls)
        ref = res.maximum(signals["F"])
        assert got[1] == pytest.approx(ref[1], rel=1e-13) and n_calls <= 2, (p, got, ref, n_calls)


def test_row_store_journal_keeps_every_finished_row(tmp_path):
    """Rows go to the journal at once and to the Parquet file every FLUSH_INTERVAL: a study killed between
    two Parquet writes (close never called) loses no row; a half-written journal line is skipped; close
    folds the journal into the Parquet file and removes it."""
    from mbdsim.studies.store import RowStore, journal_path, load_rows
    out = tmp_path / "r.parquet"
    row = lambda k: pd.DataFrame([{"run": k, "x": 0.1 * k, "y": math.nan if k == 2 else k**2,  # noqa: E731
                                   "status": "ok", "message": "ok", "study_id": "abc"}])
    store = RowStore(out, None, interval=3600.0)
    for k in range(4):
        store.append(row(k))
    assert not out.exists() and journal_path(out).exists()               # nothing rewritten yet
    with open(journal_path(out), "a") as fh:
        fh.write('{"run": 9, "x": 0.')                                    # killed mid-line
    got = load_rows(out, "abc")
    assert list(got.run) == [0, 1, 2, 3] and got.x.tolist() == [0.0, 0.1, 0.2, 0.1 * 3]
    assert math.isnan(got.y[2]) and got.y[3] == 9.0
    with pytest.raises(ModelError, match="another study"):
        load_rows(out, "other")
    store2 = RowStore(out, got, interval=3600.0)                           # the resumed run
    assert len(pd.read_parquet(out)) == 4 and journal_path(out).stat().st_size == 0   # journal folded in
    store2.append(row(4))
    assert list(load_rows(out, "abc").run) == [0, 1, 2, 3, 4]
    store2.close()
    assert not journal_path(out).exists() and list(load_rows(out, "abc").run) == [0, 1, 2, 3, 4]


def test_row_store_takes_dict_rows(tmp_path):
    """Rows given as dicts (a study in this process: one run at a time) are journaled at once and written
    to the Parquet file with the DataFrame rows of a resumed run, in the same columns."""
    from mbdsim.studies.store import RowStore, journal_path, load_rows
    out = tmp_path / "d.parquet"
    store = RowStore(out, None, interval=3600.0)
    store.append([{"run": 0, "x": 0.5, "status": "ok", "study_id": "s"}])
    store.append([{"run": 1, "x": math.nan, "status": "error", "study_id": "s"}])
    got = load_rows(out, "s")                                             # from the journal alone
    assert not out.exists() and list(got.run) == [0, 1] and math.isnan(got.x[1])
    store.close()
    assert not journal_path(out).exists()
    again = RowStore(out, load_rows(out, "s"), interval=3600.0)
    again.append([{"run": 2, "x": 2.0, "status": "ok", "study_id": "s"}])
    again.close()
    df = pd.read_parquet(out)
    assert list(df.run) == [0, 1, 2] and list(df.columns) == ["run", "x", "status", "study_id"] and df.x[2] == 2.0


def test_callable_outputs():
    """An output may be a callable of the Result: the same number as the expression; one that raises or
    returns an array makes that run an 'error' row naming the output."""
    outs = {"x_end": lambda res: float(res.position("slider")[-1, 0]), "x_end_expr": "final(x(position('slider')))",
            "bad": lambda res: res.position("slider")[:, 0]}
    df = mb.Study(slider_crank, {"crank": [0.1, 0.15]}, {k: outs[k] for k in ("x_end", "x_end_expr")},
                  analysis={**FAST, "end_time": 0.25}).run(workers=0)
    assert (df.status == "ok").all() and df.x_end.tolist() == df.x_end_expr.tolist()
    r, l = df.crank, 0.4       # theta = pi/2 at t = 0.25 s: x = sqrt(l^2 - r^2)
    assert np.allclose(df.x_end, np.sqrt(l**2 - r**2), atol=1e-9)
    bad = mb.Study(slider_crank, {"crank": [0.1]}, {"bad": outs["bad"]}, analysis={**FAST, "end_time": 0.1}).run(workers=0)
    assert bad.status[0] == "error" and "study output 'bad'" in bad.message[0] and "one number" in bad.message[0]


def test_reaction_measures_equal_result_values():
    """Study reaction measures skip Result's determinacy analysis (an SVD per sample at every call) but give
    its values: same numbers with on= and frame=; wrong arguments name the output."""
    from mbdsim.studies.measures import compile_output
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = mb.simulate(slider_crank(), 0.5, 0.01, rtol=1e-6)
        ref_f = res.reaction_force("crank_rod", on="crank", frame="rod")
        ref_t = res.reaction_torque("crank_rod")
    f = compile_output("f", "final(y(reaction_force('crank_rod', on='crank', frame='rod')))")
    t = compile_output("t", "max(z(reaction_torque('crank_rod')))")
    assert f(res) == ref_f[-1, 1]
    assert abs(t(res)) <= np.max(np.abs(ref_t)) + 1e-12 and np.max(np.abs(ref_t)) < 1e-9   # revolute: no torque about z
    df = mb.Study(slider_crank, {"crank": [0.1]}, {"bad": "max(norm(reaction_force('crank_rod', relative_to='rod')))"},
                  analysis={**FAST, "end_time": 0.1}).run(workers=0)
    assert df.status[0] == "error" and "study output 'bad'" in df.message[0]


def _three_parameter_runs():
    rng = np.random.default_rng(0)
    n = 60
    df = pd.DataFrame({"a": rng.uniform(0, 1, n), "b": rng.uniform(0, 1, n), "c": rng.uniform(0.1, 0.3, n)})
    df["F"] = 0.01 * df.a + 50 * df.c + 4 * df.b + rng.normal(0, 1e-3, n)   # c dominates, then b, a is noise
    df["status"] = "ok"
    df.attrs.update(parameters=["a", "b", "c"], outputs=["F"], units={"c": "m", "F": "N"})
    return df


def test_surface_defaults_to_the_dominant_parameters_and_labels_units():
    df = _three_parameter_runs()
    fig = mb.plot_study(df, "surface")
    ax = fig.axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("c [m]", "b")
    assert fig.axes[1].get_ylabel() == "F [N]"                        # the colour bar
    ax = mb.plot_study(df, "surface", x="a", y="b").axes[0]           # an explicit choice is kept
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("a", "b")
    ax = mb.plot_study(df, "surface", x="a", units={"a": "kg"}).axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("a [kg]", "c [m]")
    me = mb.plot_study(df, "main_effects")
    assert [a.get_xlabel() for a in me.axes] == ["a", "b", "c [m]"] and me.axes[0].get_ylabel() == "F [N]"


def test_one_parameter_main_effects_title_lies_inside_the_figure():
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    fig = mb.plot_study(_three_parameter_runs(), "main_effects", ["c"], ["F"])
    FigureCanvasAgg(fig).draw()
    box = fig._suptitle.get_window_extent(fig.canvas.get_renderer())
    assert fig.bbox.x0 <= box.x0 and box.x1 <= fig.bbox.x1 and fig.bbox.y0 <= box.y0 and box.y1 <= fig.bbox.y1


def test_study_units_of_parameters_and_outputs():
    from mbdsim.studies.units import output_unit, schema_unit
    study = mb.Study("examples/slider_crank.yaml",
                     {"bodies.rod.mass": [1, 2], "bodies.slider.mass": {"range": ["1000 g", "2 kg"], "num": 2},
                      "gravity.1": [-9.81, -1.62]}, SC_OUT, analysis=FAST)
    assert study.units == {"bodies.rod.mass": "kg", "bodies.slider.mass": "kg", "gravity.1": "m/s**2",
                           "amax": "m/s**2", "t_idc": "s", "F": "N"}
    assert schema_unit("forces.s.stiffness") == "N/m" and schema_unit("motions.drive.displacement") == ""
    assert output_unit("degrees(final(joint_coordinate('j')))") == "" and output_unit(len) == ""
    factory = mb.Study(slider_crank, {"crank": ["100 mm", "120 mm"], "rod_mass": [1.0, 3.0]}, SC_OUT, analysis=FAST)
    assert factory.units["crank"] == "m" and "rod_mass" not in factory.units


def test_designs_over_the_size_limit_are_refused_before_any_is_generated():
    import time
    from mbdsim.studies.design import MAX_VARIANTS, ParameterSpec, make_design
    from scipy import stats
    grid = [ParameterSpec(f"p{k}", values=tuple(range(10))) for k in range(10)]   # 1e10 variants
    t0 = time.monotonic()
    with pytest.raises(mb.ModelError) as err:
        make_design(grid)
    assert (err.value.entity, err.value.field) == ("study", "values") and "1e+10 variants" in str(err.value)
    with pytest.raises(mb.ModelError) as err:
        make_design([ParameterSpec("m", dist=stats.uniform(1, 2))], "lhs", samples=10**9)
    assert err.value.field == "samples" and f"{MAX_VARIANTS:,}" in str(err.value)
    assert time.monotonic() - t0 < 5.0
    assert len(make_design([ParameterSpec("a", values=(1.0, 2.0))])) == 2


def test_output_power_towers_are_double_precision_not_endless():
    """'9**9**9' was Python's exact integer power (it never ends); now double precision: inf at once."""
    import subprocess
    import sys
    code = ("from mbdsim.studies.measures import compile_output, evaluate_outputs, OutputError\n"
            "assert compile_output('o', '2**3')(None) == 8.0\n"
            "print(evaluate_outputs({'o': '9**9**9', 'p': '2**10000'}, None))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "{'o': inf, 'p': inf}"


def _stuck_or_slow(mode, c=0.0):
    """A damped pendulum; mode 1: the factory never returns (a Python loop); mode 2: its damping torque is a
    Python callable that takes 20 ms a call (the run would take minutes); mode 0: an ordinary variant."""
    import time
    if mode == 1:
        while True:
            pass
    m = mb.Model("pend", gravity=(0.0, -9.81, 0.0))
    rod = m.add_body("rod", 1.0, inertia=(0.01, 0.01, 0.01), position=(0.5, 0.0, 0.0))
    pin = m.add_revolute("pin", m.ground, rod, (0, 0, 0), (0, 0, 1))
    if mode == 2:
        def slow(t, state):
            time.sleep(0.02)
            return 0.0
        m.add_joint_force("damper", pin, slow)
    return m


def test_time_limit_turns_a_stuck_or_endless_variant_into_a_failed_row():
    """Issue 35: a variant that never returns (a factory in an endless loop) or that would run for minutes
    (a slow Python load called back from the compiled loop) is stopped at analysis.time_limit and becomes
    a 'failed' row naming the limit; the other variants run and the study returns."""
    import time
    mb.simulate(_stuck_or_slow(0), 0.1)   # kernels loaded before: the ordinary variants take milliseconds
    study = mb.Study(_stuck_or_slow, {"mode": [0, 1, 2, 0]}, {"angle": "final(joint_coordinate('pin'))"},
                     analysis={"end_time": 5.0, "output_step": 0.01, "time_limit": "1.5 s"})
    t0 = time.monotonic()
    df = study.run(workers=0)
    assert time.monotonic() - t0 < 30.0
    assert list(df["status"]) == ["ok", "failed", "failed", "ok"], df[["status", "message"]]
    for k in (1, 2):
        assert "time limit" in df["message"][k] and "1.5 s" in df["message"][k] and math.isnan(df["angle"][k])
        assert 1.4 < df["wall_time"][k] < 10.0
    # the pendulum released from horizontal swings between -pi and 0 (angle about +z): the ordinary rows
    assert -np.pi - 1e-6 <= df["angle"][0] <= 1e-6 and df["angle"][0] != 0.0 and df["angle"][0] == df["angle"][3]
    with pytest.raises(ModelError) as err:
        mb.Study(_stuck_or_slow, {"mode": [0]}, {"a": "final(joint_coordinate('pin'))"}, analysis={"end_time": 1.0, "time_limit": -1})
    assert err.value.field == "time_limit"


def test_path_parameter_units_are_checked_against_the_field():
    """Issue 35: '[1 m, 2 m]' for a mass was converted to SI numbers and accepted; the units written are
    now checked against the field the path sets, the parameter and 'values' named."""
    out = {"a": "final(joint_coordinate('pin'))"}
    for spec in (["1 m", "2 m"], {"values": [1, 2], "unit": "m"}, {"range": ["1 s", "2 s"], "num": 2}):
        with pytest.raises(ModelError) as err:
            mb.Study("examples/pendulum.yaml", {"bodies.rod.mass": spec}, out, analysis={"end_time": 0.1})
        assert (err.value.entity, err.value.field) == ("study parameter 'bodies.rod.mass'", "values")
        assert "is not a mass" in str(err.value)
    ok = mb.Study("examples/pendulum.yaml", {"bodies.rod.mass": ["1 kg", "2000 g"]}, out, analysis={"end_time": 0.1})
    assert ok.design["bodies.rod.mass"].tolist() == [1.0, 2.0]
