"""mbdsim: 3D multibody dynamics in Python (SI units throughout).

Public API (a contract; everything else may change): Model and its add_* methods, the analyses
(simulate, kinematics, assemble, equilibrium), Result, the importers (from_urdf, from_mjcf), contact shapes and path curves, the error
types, and the Adams-style function library (STEP, STEP5, HAVSIN, IMPACT, BISTOP, POLY, SHF, AKISPL)
with the safe expression parser `parse`.
"""
import gc
import os
import sys
from importlib import import_module

from .errors import (AnalysisInterrupted, AssemblyError, EvaluationError, MbdsimError, ModelError, ModelFileError,
                     SolverError)

# Public names load their module on first use (PEP 562), so `import mbdsim` stays fast and the solvers,
# scipy and numba load with the first analysis. One line per name: where it lives.
_LAZY = {
    "expressions": ".expressions", "functions": ".functions",
    "ExpressionError": ".expressions", "parse": ".expressions",
    "AKISPL": ".functions", "BISTOP": ".functions", "HAVSIN": ".functions", "IMPACT": ".functions",
    "POLY": ".functions", "SHF": ".functions", "STEP": ".functions", "STEP5": ".functions",
    "Akima": ".functions", "CubicSplineTable": ".functions",
    "Body": ".model", "Force": ".model", "Joint": ".model", "Marker": ".model", "Model": ".model",
    "Motion": ".model", "SpringDamper": ".model", "Torque": ".model",
    "Curve": ".model.curves", "Spline": ".model.curves", "Plane": ".model.shapes", "Sphere": ".model.shapes",
    "Box": ".model.shapes", "Cylinder": ".model.shapes", "Capsule": ".geometry", "Ellipsoid": ".geometry",
    "ConvexMesh": ".geometry", "Mesh": ".geometry", "load_model": ".io", "save_model": ".io",
    "Result": ".results",
    "AssemblyReport": ".solvers.assembly", "RedundantConstraintWarning": ".solvers.assembly",
    "InitialConditionWarning": ".solvers.assembly", "SingularConfigurationWarning": ".solvers.kinematic",
    "assemble": ".solvers.assembly", "simulate": ".solvers.dynamic", "kinematics": ".solvers.kinematic",
    "equilibrium": ".solvers.static", "quasi_static": ".solvers.static",
    "UnstableEquilibriumWarning": ".solvers.static", "linearize": ".solvers.linear",
    "Linearization": ".solvers.linear", "plot": ".plotting", "animate": ".viewer",
    "Study": ".studies", "load_study": ".studies", "plot_study": ".studies", "sensitivity": ".studies",
    "OutputError": ".studies.measures", "InertiaWarning": ".model._check",
    "InitialPenetrationWarning": ".solvers.checks", "MonitorWarning": ".results.diagnostics",
    "IndeterminateReactionWarning": ".system.determinacy", "ProgressError": ".results.stream",
    "AccuracyWarning": ".solvers.autoswitch",
    "Simulator": ".cosim.simulator", "SimulatorState": ".cosim.simulator", "export_fmu": ".cosim.fmu_export",
    "from_urdf": ".importers", "from_mjcf": ".importers", "from_adm": ".importers.adm", "ImportApproximationWarning": ".importers",
}


def _load(path):
    """Import the lazy module `path` (relative to mbdsim) with the cyclic garbage collector paused, and
    then move what exists (the modules, classes and functions the import built, numba's type tables:
    all of them kept for the process's life) to the collector's permanent generation (`gc.freeze`).
    numba's import alone builds some 10^5 tracked objects that every later full collection and the
    interpreter's exit would traverse again: 0.07 s of a fresh process's 0.45 s first simulate
    (bench/startup.py). Frozen objects are still freed by reference counting as always; only cyclic
    garbage left from before the import is never collected. MBDSIM_GC_FREEZE=0 turns this off."""
    full = __name__ + path if path.startswith(".") else path
    if full in sys.modules or os.environ.get("MBDSIM_GC_FREEZE", "1") == "0":
        return import_module(full)
    enabled = gc.isenabled()
    gc.disable()
    try:
        return import_module(full)
    finally:
        if enabled:
            gc.freeze()
            gc.enable()


def __getattr__(name):
    if name in _LAZY:
        mod = _load(_LAZY[name])
        value = mod if name in ("expressions", "functions") else getattr(mod, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'mbdsim' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_LAZY))


__version__ = "0.1.0"

__all__ = [
    "Model", "Body", "Marker", "Joint", "Motion", "Force", "Torque", "SpringDamper", "Result",
    "Curve", "Spline", "Sphere", "Plane", "Box", "Cylinder", "Capsule", "Ellipsoid", "ConvexMesh", "Mesh",
    "load_model", "save_model", "from_adm",
    "simulate", "kinematics", "assemble", "equilibrium", "AssemblyReport",
    "quasi_static", "linearize", "Linearization", "UnstableEquilibriumWarning",
    "MbdsimError", "ModelError", "ModelFileError", "AssemblyError", "SolverError", "EvaluationError",
    "AnalysisInterrupted", "ProgressError", "ExpressionError", "OutputError",
    "RedundantConstraintWarning", "InitialConditionWarning", "SingularConfigurationWarning", "InertiaWarning",
    "InitialPenetrationWarning", "MonitorWarning", "IndeterminateReactionWarning", "AccuracyWarning",
    "expressions", "functions", "parse",
    "plot", "animate",
    "Study", "load_study", "plot_study", "sensitivity",
    "Simulator", "SimulatorState", "export_fmu",
    "from_urdf", "from_mjcf", "ImportApproximationWarning",
    "STEP", "STEP5", "HAVSIN", "IMPACT", "BISTOP", "POLY", "SHF", "AKISPL", "Akima", "CubicSplineTable",
]
