"""The documentation site builds offline in strict mode, and the getting-started examples run."""
import importlib.util
import os
import re
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.skipif(importlib.util.find_spec("mkdocs") is None and not os.environ.get("CI"),
                    reason="mkdocs not installed (pip install -e '.[test]')")
def test_mkdocs_build_strict(tmp_path):
    p = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(ROOT / "mkdocs.yml"),
                        "-d", str(tmp_path / "site")], capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert p.returncode == 0, p.stdout + p.stderr
    api = (tmp_path / "site" / "api" / "index.html").read_text()
    for name in ("add_revolute", "add_contact", "joint_coordinate", "simulate", "animate", "plot", "STEP5"):
        assert name in api, name
    cli = (tmp_path / "site" / "cli" / "index.html").read_text()
    assert "mbdsim plot" in cli and "--end" in cli            # generated --help text
    assert (tmp_path / "site" / "theory" / "index.html").exists()


def test_getting_started_examples_run(tmp_path, monkeypatch):
    text = (ROOT / "docs" / "getting-started.md").read_text()
    code = "\n".join(re.findall(r"```python\n(.*?)```", text, re.S))
    monkeypatch.chdir(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ns = {}
        exec(compile(code, "getting-started.md", "exec"), ns)   # noqa: S102 - our own documentation
    x = ns["x"]
    assert x.max() - x.min() == pytest.approx(0.2, abs=1e-6)   # stroke = 2 x crank radius
    assert (tmp_path / "stroke.png").exists() and (tmp_path / "slider_crank.html").exists()
    # the text says what the default method is, and what the minimum it prints is (issue 34)
    assert ns["dyn"].stats["method"].startswith("auto") and '(`method="auto"` by default' in text
    assert ns["angle"] == pytest.approx(-np.pi, abs=1e-3) and "lowest" not in text   # the far turning point


def _readme_python_blocks():
    return re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S)


def test_readme_python_blocks_import_what_they_use():
    for block in _readme_python_blocks():
        if "mb." in block:
            assert "import mbdsim as mb" in block, block[:80]
        if "np." in block:
            assert "import numpy as np" in block, block[:80]


def test_readme_slider_crank_is_not_redundant_and_its_report_prints_no_rounding_residue():
    """The README's redundancy text matches the behaviour: its initial-conditions slider-crank is not
    redundant (no warning), and the assembly report prints moves below 1e-12 as 0."""
    import mbdsim as mb
    text = (ROOT / "README.md").read_text()
    assert "reported once" not in text
    block = next(b for b in _readme_python_blocks() if "slider_crank" in b and "add_translational" in b)
    ns = {}
    with warnings.catch_warnings():
        warnings.simplefilter("error", mb.RedundantConstraintWarning)
        exec(compile(block.replace("print(", "str("), "README.md", "exec"), ns)   # noqa: S102 - our own docs
    report = str(mb.assemble(ns["model"]))
    assert re.search(r"moved slider: [0-9.]+ m, 0 deg", report), report
    assert not re.search(r"e-\d\d deg", report), report


def test_run_help_states_the_default_tolerance():
    from typer.testing import CliRunner

    from mbdsim.cli.app import app
    from mbdsim.solvers.dynamic import DEFAULT_TOL
    out = " ".join(CliRunner().invoke(app, ["run", "--help"]).output.replace("\u2502", " ").split())
    rtol = f"{DEFAULT_TOL['auto'][0]:.0e}".replace("e-0", "e-")   # 1e-7
    assert f"default {rtol} with --method auto" in out, out


def _hooks():
    spec = importlib.util.spec_from_file_location("mbdsim_docs_hooks", ROOT / "docs" / "hooks.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_hooks_escape_brackets_outside_code_only():
    hooks = _hooks()
    md = "[K, J] x = [Q, g] and `a[0]`\n\n    code[1]\n```\nb[2]\n```\n"
    assert hooks.escape_brackets(md) == "\\[K, J\\] x = \\[Q, g\\] and `a[0]`\n\n    code[1]\n```\nb[2]\n```\n"


def test_hooks_schema_page_says_when_there_is_no_schema_command():
    hooks = _hooks()
    code, _ = hooks._run(["schema", "--help"])
    text = hooks._schema()
    if code == 0:      # mbdsim.io is installed: its schema is embedded
        assert text.startswith("```")
    else:
        assert "Schema not available in this build" in text


def test_model_file_reference_is_generated_and_current():
    """docs/model-file-reference.md and docs/model-file-schema.json are what `python3 -m mbdsim.io.reference`
    writes from the schema now (regenerate them after a schema change); every element type has a table."""
    from mbdsim.io.reference import REFERENCE, SCHEMA_FILE, reference_markdown, schema_text
    text = reference_markdown()
    assert (ROOT / "docs" / REFERENCE).read_text(encoding="utf-8") == text, \
        f"docs/{REFERENCE} is stale: run python3 -m mbdsim.io.reference docs"
    assert (ROOT / "docs" / SCHEMA_FILE).read_text(encoding="utf-8") == schema_text(), \
        f"docs/{SCHEMA_FILE} is stale: run python3 -m mbdsim.io.reference docs"
    for kind in ("revolute", "spring_damper", "contact", "coupler", "point_on_curve", "joint_force"):
        assert re.search(rf"^### .*\b{kind}\b", text, re.M), kind
    assert "| `mass` | quantity | kg |" in text and "| `stiffness` | quantity | N/m |" in text
    assert text.count("```yaml") >= 25
    page = (ROOT / "docs" / "model-files.md").read_text()
    assert "(model-file-reference.md)" in page and "(model-file-schema.json)" in page and len(page) < 20000
    assert "model-file-reference.md" in (ROOT / "mkdocs.yml").read_text()
