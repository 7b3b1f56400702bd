"""Importers of foreign model files, each returning an ordinary mbdsim.Model (SI units).

`IMPORTERS` maps a file extension to "module:function"; `load_any(path)` picks by extension and falls
back to mbdsim's own model files (.yaml/.yml/.json).  Every importer only reads its file (never runs
code) and raises ModelFileError naming the file, the line and what it cannot represent.
"""
from __future__ import annotations

from importlib import import_module
from pathlib import Path

IMPORTERS = {".adm": "mbdsim.importers.adm:from_adm"}


def importer_for(path):
    """The import function for `path`'s extension, or None for mbdsim's own model files."""
    target = IMPORTERS.get(Path(path).suffix.lower())
    if target is None:
        return None
    module, _, func = target.partition(":")
    return getattr(import_module(module), func)


def load_any(path):
    """A Model from `path`: a foreign file by its extension (IMPORTERS), else mbdsim.load_model."""
    fn = importer_for(path)
    if fn is None:
        from ..io import load_model
        return load_model(path)
    return fn(path)
