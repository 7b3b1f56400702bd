"""mkdocs hooks: pages that embed live output of the installed mbdsim (works offline).

* `<!-- mbdsim-cli-help -->` becomes the `--help` text of every `mbdsim` command;
* `<!-- mbdsim-schema -->` becomes the `mbdsim schema` output (the model-file schema) when this
  install has that command (mbdsim.io), else a note saying it is not available in this build;
* `<!-- mbdsim-changelog -->` becomes CHANGELOG.md;
* in theory.md (plain-text equations such as `[M, phi_q^T] [vdot, lambda]`), square brackets outside
  code are escaped so Markdown does not read them as reference links.
"""
from __future__ import annotations

import os
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _run(args: list[str]) -> tuple[int, str]:
    from typer.testing import CliRunner

    from mbdsim.cli.app import app
    os.environ.setdefault("COLUMNS", "100")
    r = CliRunner().invoke(app, args, prog_name="mbdsim", env={"COLUMNS": "100", "NO_COLOR": "1", "TERM": "dumb"})
    return r.exit_code, r.output


def _cli_help() -> str:
    import typer.main

    from mbdsim.cli.app import app
    names = [c.name for c in typer.main.get_command(app).commands.values()] if hasattr(
        typer.main.get_command(app), "commands") else []
    out = []
    for args in [[]] + [[n] for n in sorted(names)]:
        code, text = _run(args + ["--help"])
        title = "mbdsim " + " ".join(args) if args else "mbdsim"
        out.append(f"### `{title.strip()}`\n\n```text\n{text.rstrip()}\n```\n")
    return "\n".join(out)


def _schema() -> str:
    code, text = _run(["schema"])
    if code != 0:
        return ("!!! note \"Schema not available in this build\"\n    This build of mbdsim has no `mbdsim schema` "
                "command (the model-file reader `mbdsim.io` is not installed), so the field reference could "
                "not be generated. Rebuild the docs with a version that has it.\n")
    lang = "json" if text.lstrip().startswith("{") else "text"
    return f"```{lang}\n{text.rstrip()}\n```\n"


def escape_brackets(markdown: str) -> str:
    """Escape [ and ] outside fenced/indented code blocks and inline code (text without links)."""
    out, fenced = [], False
    for line in markdown.split("\n"):
        if line.lstrip().startswith("```"):
            fenced = not fenced
        if fenced or line.startswith(("    ", "\t")) or line.lstrip().startswith("```"):
            out.append(line)
            continue
        parts = line.split("`")
        parts[::2] = [p.replace("[", "\\[").replace("]", "\\]") for p in parts[::2]]
        out.append("`".join(parts))
    return "\n".join(out)


def on_page_markdown(markdown: str, page, config, files, **kwargs) -> str:
    """Replace the markers above with generated text."""
    if page.file.src_uri == "theory.md" and "](" not in markdown:
        markdown = escape_brackets(markdown)
    if "<!-- mbdsim-cli-help -->" in markdown:
        markdown = markdown.replace("<!-- mbdsim-cli-help -->", _cli_help())
    if "<!-- mbdsim-schema -->" in markdown:
        markdown = markdown.replace("<!-- mbdsim-schema -->", _schema())
    if "<!-- mbdsim-changelog -->" in markdown:
        text = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
        markdown = markdown.replace("<!-- mbdsim-changelog -->", text.split("\n", 1)[1])
    return markdown
