"""The validation runner, report and ``mbdsim validate`` CLI, with fake cases (no engine)."""
from __future__ import annotations

import json
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from mbdsim.validation import registry
from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

typer_testing = pytest.importorskip("typer.testing")
from mbdsim.cli.app import app  # noqa: E402
from mbdsim.validation.report import (  # noqa: E402
    fmt_pct,
    fmt_value,
    quantity_records,
    write_report,
)

RECORD_KEYS = {"case", "quantity", "unit", "theory", "manual_theory", "manual_commercial",
               "mbdsim", "error_pct", "commercial_error_pct", "pass"}


# --------------------------------------------------------------------------- fakes

def _info(n: int, slug: str, **kw) -> CaseInfo:
    return CaseInfo(
        number=n, slug=slug, title=f"Fake case {n}", reference=f"M&K 7th ed., P{n}",
        analysis="dynamics",
        statement=kw.get("statement", "A ball is launched upward with $v_0 = 25$ m/s.\n\n"
                                      "$$s = v_0 t - \\tfrac12 g t^2$$"),
        reconstruction=kw.get("reconstruction", "| dim | value |\n|---|---|\n| L | 0.3 m |"),
        discrepancies=kw.get("discrepancies", []),
        notes=kw.get("notes", []),
    )


def _fake_model() -> SimpleNamespace:
    """Duck-typed stand-in for mbdsim.Model: a pendulum on ground with a spring."""
    ground = SimpleNamespace(name="ground", position=np.zeros(3), orientation=np.eye(3),
                             markers={"O": SimpleNamespace(point=np.zeros(3))}, is_particle=False)
    c, s = np.cos(0.3), np.sin(0.3)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    link = SimpleNamespace(name="link", position=np.array([0.5 * c, 0.5 * s, 0.0]), orientation=R,
                           markers={"A": SimpleNamespace(point=np.zeros(3)),
                                    "B": SimpleNamespace(point=np.array([c, s, 0.0]))},
                           is_particle=False)
    ball = SimpleNamespace(name="ball", position=np.array([c, s - 0.5, 0.0]), markers={},
                           is_particle=True)  # no orientation: must not matter
    joints = {"rev_O": SimpleNamespace(body_i=ground, body_j="link", point=np.zeros(3),
                                       kind="revolute"),
              "broken": SimpleNamespace(body_i="link", body_j="ball")}  # no point: skipped
    forces = {"spring": SimpleNamespace(point_i=np.array([0.6, -0.4, 0.0]),
                                        point_j=np.array([c, s, 0.0]), body_i="ground",
                                        body_j="link")}
    return SimpleNamespace(bodies={"ground": ground, "link": link, "ball": ball}, joints=joints,
                           forces=forces)


def _outcome_pass() -> CaseOutcome:
    t = np.linspace(0.0, 5.0, 101)
    y = 25.0 * t - 0.5 * 9.807 * t ** 2
    return CaseOutcome(
        info=_info(1, "launch", notes=["derivation uses g = 9.807 m/s^2"]),
        quantities=[
            # e = 1e-8 < 1e-6: passes even though the commercial code was exact
            Quantity("t_B", "s", 4.404, 4.404, 4.404, 4.404 * (1 + 1e-8)),
            # e = 5e-6 < e_c = 6e-5
            Quantity("h", "m", 16.865, 16.865, 16.866, 16.865 * (1 + 5e-6), note="read at t_B"),
        ],
        model=_fake_model(),
        plots=[Plot("height", t, y, "t [s]", "s [m]", mark=(4.404, 15.0), mark_label="t_B"),
               Plot("two series", t, {"a": y, "b": 2 * y}, "t [s]", "x"),
               Plot("bad", t, y[:3], "t", "y")],  # inconsistent lengths: a note, not a crash
        variants=["full physics: identical (no approximation)"],
    )


def _outcome_fail() -> CaseOutcome:
    return CaseOutcome(
        info=_info(2, "slider", discrepancies=["manual prints 3.21 m/s; the derivation gives 3.12 m/s"]),
        quantities=[
            Quantity("v_B", "m/s", 3.12, 3.21, 3.1201, 3.12),        # exact: passes
            Quantity("a_B", "m/s^2", 10.0, 10.0, 10.00001, 10.00005),  # e = 5e-6 > e_c = 1e-6: fails
        ],
        model=None,
    )


def _module(outcome_factory, number: int, slug: str):
    info = outcome_factory().info if callable(outcome_factory) else None
    return SimpleNamespace(__name__=f"fake.case{number:02d}_{slug}",
                           CASE=info or _info(number, slug), run=outcome_factory)


def _boom():
    raise RuntimeError("engine exploded")


def _fake_modules():
    return [
        _module(_outcome_pass, 1, "launch"),
        SimpleNamespace(__name__="fake.case03_boom", CASE=_info(3, "boom"), run=_boom),
        _module(_outcome_fail, 2, "slider"),
    ]


@pytest.fixture
def runner():
    return typer_testing.CliRunner()


# --------------------------------------------------------------------------- pass criterion

def test_pass_criterion():
    # within 1e-4 and better than the commercial code
    assert Quantity("q", "m", 1.0, None, 1.0 + 1e-4, 1.0 + 5e-5).passed
    # within 1e-4 but worse than the commercial code and above 1e-6
    assert not Quantity("q", "m", 1.0, None, 1.0 + 1e-6, 1.0 + 5e-6).passed
    # worse than the commercial code but below one part per million
    assert Quantity("q", "m", 1.0, None, 1.0, 1.0 + 9e-7).passed
    # above 1e-4 fails even when the commercial code was worse
    assert not Quantity("q", "m", 1.0, None, 1.1, 1.0 + 2e-4).passed
    # no commercial value: only the 1e-4 bound
    assert Quantity("q", "m", 1.0, None, None, 1.0 + 9e-5).passed
    # zero theory: absolute error
    assert Quantity("q", "m", 0.0, 0.0, 0.0, 1e-9).passed
    # NaN never passes
    assert not Quantity("q", "m", 1.0, None, None, float("nan")).passed
    q = Quantity("h", "m", 16.865, 16.865, 16.866, 16.865)
    assert q.error_pct == 0.0
    assert q.commercial_error_pct == pytest.approx(100 * 0.001 / 16.865)
    assert _outcome_pass().passed and not _outcome_fail().passed


def test_formatting():
    assert fmt_value(16.865) == "16.865"
    assert fmt_value(1.0 + 1e-7) == "1.0000001"  # 1e-7 relative differences are visible
    assert fmt_value(None) == "—"
    assert fmt_pct(0.0) == "0"
    assert fmt_pct(5.93e-3) == "5.93e-03"
    assert fmt_pct(None) == "—"
    assert fmt_pct(1.5) == "1.5"


# --------------------------------------------------------------------------- runner

def test_run_case_turns_exceptions_into_failed_outcomes():
    bad = SimpleNamespace(__name__="fake.case03_boom", CASE=_info(3, "boom"), run=_boom)
    o = registry.run_case(bad)
    assert isinstance(o, CaseOutcome) and not o.passed
    assert "engine exploded" in o.error and "RuntimeError" in o.error
    assert "Traceback" in o.traceback
    assert o.info.number == 3 and o.elapsed_s >= 0.0
    assert not registry.outcome_ok(o)

    wrong = SimpleNamespace(__name__="fake.case04_wrong", CASE=_info(4, "wrong"), run=lambda: 42)
    o = registry.run_case(wrong)
    assert not o.passed and "CaseOutcome" in o.error

    good = registry.run_case(SimpleNamespace(CASE=_info(1, "launch"), run=_outcome_pass))
    assert registry.outcome_ok(good) and registry.outcome_error(good) is None

    empty = registry.run_case(SimpleNamespace(CASE=_info(5, "empty"),
                                              run=lambda: CaseOutcome(_info(5, "empty"), [])))
    assert not registry.outcome_ok(empty)  # a case that compares nothing is not a pass


def test_case_modules_unknown_number_and_import_failure(monkeypatch):
    monkeypatch.setattr(registry, "discover", lambda: [
        (1, "mbdsim.validation.cases.case01_does_not_exist_xyz"),
    ])
    with pytest.raises(registry.UnknownCaseError, match="31"):
        registry.case_modules([31])
    (mod,) = registry.case_modules([1])  # import fails: a stand-in, not an exception
    o = registry.run_case(mod)
    assert not o.passed and "failed to import" in o.error
    assert o.info.number == 1


def test_discover_is_sorted_by_number():
    found = registry.discover()  # the real package (may still be empty)
    assert [n for n, _ in found] == sorted(n for n, _ in found)


# --------------------------------------------------------------------------- report

def test_the_report_knows_the_cases_not_the_other_way_round():
    """validation/report imports the framework and registry; the cases, framework and registry never
    import the report (issue 29: one path in the code)."""
    import ast

    import mbdsim.validation as validation
    root = Path(validation.__file__).parent
    sources = [root / "framework.py", root / "registry.py", *sorted((root / "cases").rglob("*.py"))]
    assert len(sources) > 30
    for path in sources:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [node.module or ""] + [a.name for a in node.names] if isinstance(node, ast.ImportFrom)
                     else [])
            assert not any("report" in n for n in names), (path, ast.dump(node))
    assert not list((root.parent / "reports").glob("*.py"))   # the old mbdsim.reports is gone (a leftover
                                                              # __pycache__ of an older checkout may remain)


def test_write_report(tmp_path: Path):
    outcomes = [registry.run_case(m) for m in _fake_modules()]
    md, html = write_report(outcomes, tmp_path / "rep")
    assert md == tmp_path / "rep" / "report.md" and md.exists()
    assert html == tmp_path / "rep" / "report.html" and html.exists()

    text = md.read_text(encoding="utf-8")
    assert "## Manual discrepancies found" in text
    assert "manual prints 3.21 m/s" in text
    assert "figures/case01_mechanism.png" in text and "figures/case01_plot1.png" in text
    assert "engine exploded" in text
    assert "could not be drawn" in text  # the inconsistent plot
    assert "16.8650843" in text  # full precision of mbdsim's value
    assert (tmp_path / "rep" / "figures" / "case01_mechanism.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

    page = html.read_text(encoding="utf-8")
    assert page.lstrip().startswith("<!DOCTYPE html>")
    assert 'src="http' not in page and "href=\"http" not in page
    assert '<link' not in page and '<script' not in page
    imgs = re.findall(r'<img [^>]*src="([^"]*)"', page)
    assert len(imgs) >= 3 and all(s.startswith("data:image/png;base64,") for s in imgs)
    assert "Manual discrepancies found" in page
    assert 'class="math' in page  # TeX kept readable, not mangled by Markdown
    assert "<table>" in page  # the Markdown table of the reconstruction
    for case in ("case-01", "case-02", "case-03"):
        assert f'id="{case}"' in page


def test_report_survives_a_broken_model(tmp_path: Path):
    o = _outcome_pass()
    o.model = SimpleNamespace(bodies=42)  # nothing drawable
    o.plots = []
    md, html = write_report([o], tmp_path)
    assert "Mechanism figure could not be drawn" in md.read_text(encoding="utf-8")
    assert html.exists()


def test_quantity_records():
    recs = quantity_records([_outcome_pass(), _outcome_fail()])
    assert len(recs) == 4
    assert all(set(r) == RECORD_KEYS for r in recs)
    assert [r["pass"] for r in recs] == [True, True, True, False]
    assert recs[0]["case"] == 1 and isinstance(recs[0]["case"], int)


# --------------------------------------------------------------------------- CLI

def test_cli_json_report_and_exit_status(runner, tmp_path: Path, monkeypatch):
    calls = []

    def fake_case_modules(numbers=None):
        calls.append(numbers)
        mods = _fake_modules()
        if numbers is not None:
            mods = [m for m in mods if m.CASE.number in set(numbers)]
        return mods

    monkeypatch.setattr(registry, "case_modules", fake_case_modules)
    out = tmp_path / "report"
    js = tmp_path / "res.json"
    res = runner.invoke(app, ["validate", "--out", str(out), "--json", str(js)])
    assert res.exit_code == 1, res.output  # case 2 fails and case 3 raises
    assert calls == [None]
    assert "engine exploded" in res.output
    recs = json.loads(js.read_text())
    cases = sorted({r["case"] for r in recs})
    assert cases == [1, 2, 3]  # the raising case did not stop the others
    normal = [r for r in recs if r["case"] != 3]
    assert len(normal) == 4 and all(set(r) == RECORD_KEYS for r in normal)
    assert [r["quantity"] for r in normal] == ["t_B", "h", "v_B", "a_B"]
    by = {r["quantity"]: r for r in normal}
    assert by["h"]["theory"] == 16.865 and by["h"]["manual_commercial"] == 16.866
    assert by["h"]["pass"] is True and by["a_B"]["pass"] is False
    assert by["h"]["error_pct"] == pytest.approx(5e-4)
    err = [r for r in recs if r["case"] == 3]
    assert len(err) == 1 and err[0]["pass"] is False and "engine exploded" in err[0]["error"]
    assert (out / "report.md").exists() and (out / "report.html").exists()


def test_cli_all_pass_exit_zero_and_case_selection(runner, tmp_path: Path, monkeypatch):
    monkeypatch.setattr(registry, "case_modules",
                        lambda numbers=None: [m for m in _fake_modules()
                                              if numbers is None or m.CASE.number in numbers])
    js = tmp_path / "one.json"
    res = runner.invoke(app, ["validate", "--case", "1", "--out", str(tmp_path / "r"),
                              "--json", str(js)])
    assert res.exit_code == 0, res.output
    assert {r["case"] for r in json.loads(js.read_text())} == {1}
    assert "PASS" in res.output

    res = runner.invoke(app, ["validate", "--case", "1,2", "3", "--no-report"])
    assert res.exit_code == 1
    assert "Traceback" not in res.output


def test_cli_bad_arguments(runner, monkeypatch):
    monkeypatch.setattr(registry, "discover", lambda: [(1, "x.case01_a"), (2, "x.case02_b")])
    res = runner.invoke(app, ["validate", "--case", "31", "--no-report"])
    assert res.exit_code == 2
    assert "unknown case number" in res.output and "31" in res.output
    assert "Traceback" not in res.output
    res = runner.invoke(app, ["validate", "--case", "abc"])
    assert res.exit_code == 2 and "Traceback" not in res.output


def test_cli_version(runner):
    res = runner.invoke(app, ["version"])
    assert res.exit_code == 0 and res.output.startswith("mbdsim ")
    res = runner.invoke(app, ["--version"])
    assert res.exit_code == 0 and res.output.startswith("mbdsim ")
