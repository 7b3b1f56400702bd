"""Step-by-step simulation and co-simulation (issue 33): `Simulator` (control loops in Python), FMUs in
its loop (`Model.add_fmu`, mbdsim.cosim.fmu_import) and FMI 2.0 co-simulation export (`export_fmu`)."""
from __future__ import annotations

__all__ = ["Simulator", "SimulatorState", "export_fmu"]


def __getattr__(name):
    if name in ("Simulator", "SimulatorState"):
        from . import simulator
        return getattr(simulator, name)
    if name == "export_fmu":
        from .fmu_export import export_fmu
        return export_fmu
    raise AttributeError(f"module 'mbdsim.cosim' has no attribute {name!r}")
