"""The documentation site builds offline in strict mode, and the getting-started examples run."""
import importlib.util
import os
import re
import subprocess
import sys
import warnings
from pathlib import Path

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
