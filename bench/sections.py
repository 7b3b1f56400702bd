"""One `## ` section of a markdown results file (bench/RESULTS.md) written in place: each bench script owns
its section and keeps the others'."""
from __future__ import annotations

from pathlib import Path


def replace_section(path, text):
    """Write the section `text` (its first line the `## ` heading) into the markdown file `path`: in place
    of the section of that heading (up to the next `## `), or appended at the end."""
    path = Path(path)
    heading = text.splitlines()[0]
    old = path.read_text() if path.exists() else ""
    start = old.find(heading + "\n")
    if start >= 0:
        end = old.find("\n## ", start + len(heading))
        new = old[:start] + text.rstrip("\n") + "\n" + ("\n" + old[end + 1:] if end >= 0 else "")
    else:
        new = old.rstrip("\n") + "\n\n" + text.rstrip("\n") + "\n"
    path.write_text(new)
