"""Importers of foreign model files: URDF (`from_urdf`), MJCF (`from_mjcf`); each returns an ordinary Model.

`load_any(path)` opens any model file the CLI accepts, by extension: mbdsim's own YAML/JSON
(mbdsim.load_model) and the formats of IMPORTERS.  Files are read with a hardened XML parser (no
entities, no external references; mbdsim.importers._xml): a file never runs code, and a defect is a
ModelFileError naming the file, the line and the element.  What an importer approximates is listed in
`model.import_notes` (and warned about once, ImportApproximationWarning); drawn shapes are in
`model.visuals` (mbdsim.importers._common.VisualShape).  See docs/import.md.
"""
from __future__ import annotations

from importlib import import_module
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .._types import PathLike, Vector
    from ..model.model import Model

from ..errors import ModelFileError
from ._common import ImportApproximationWarning, VisualShape

__all__ = ["from_urdf", "from_mjcf", "from_adm", "load_any", "IMPORTERS", "ImportApproximationWarning", "VisualShape"]

# extension -> "module:function" of the importer (called with the path alone)
IMPORTERS = {
    ".urdf": "mbdsim.importers.urdf:from_urdf",
    ".xml": "mbdsim.importers.mjcf:from_mjcf",
    ".mjcf": "mbdsim.importers.mjcf:from_mjcf",
    ".adm": "mbdsim.importers.adm:from_adm",
}


def from_urdf(path: PathLike, floating_base: bool = False, gravity: Vector = (0.0, 0.0, -9.81),
              initial_displacement: dict[str, Any] | None = None, initial_velocity: dict[str, Any] | None = None,
              **options: Any) -> Model:
    """A Model from a URDF file; see mbdsim.importers.urdf.from_urdf."""
    from .urdf import from_urdf as load
    return load(path, floating_base, gravity, initial_displacement, initial_velocity, **options)


def from_mjcf(path: PathLike, initial_displacement: dict[str, Any] | None = None,
              initial_velocity: dict[str, Any] | None = None, **options: Any) -> Model:
    """A Model from a MuJoCo MJCF file; see mbdsim.importers.mjcf.from_mjcf."""
    from .mjcf import from_mjcf as load
    return load(path, initial_displacement, initial_velocity, **options)


def from_adm(path: PathLike) -> Model:
    """A Model from an Adams dataset (.adm), in SI units (mbdsim.importers.adm.from_adm)."""
    from .adm import from_adm as _from_adm
    return _from_adm(path)


def importer_for(path: PathLike) -> Any:
    """The importer function of `path`'s extension, None for mbdsim's own model files."""
    suffix = Path(path).suffix.lower()
    target = IMPORTERS.get(suffix)
    if target is None:
        return None
    module, _, func = target.partition(":")
    return getattr(import_module(module), func)


def load_any(path: PathLike) -> Model:
    """A Model from any model file by extension: .yaml/.yml/.json (mbdsim.load_model) or an imported
    format of IMPORTERS (.urdf, .xml/.mjcf, ...); ModelFileError naming the file otherwise."""
    load = importer_for(path)
    if load is not None:
        return load(path)
    suffix = Path(path).suffix.lower()
    if suffix in (".yaml", ".yml", ".json"):
        from ..io import load_model
        return load_model(path)
    known = ", ".join([".yaml", ".yml", ".json", *IMPORTERS])
    raise ModelFileError("file", "path", f"unknown model file extension {suffix or '(none)'!r}; use {known}", str(path))
