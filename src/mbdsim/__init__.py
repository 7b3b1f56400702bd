"""mbdsim: 3D multibody dynamics in Python (SI units throughout).

Public API (a contract; everything else may change): Model and its add_* methods, the analyses
(simulate, kinematics, assemble, equilibrium), Result, contact shapes and path curves, the error
types, and the Adams-style function library (STEP, STEP5, HAVSIN, IMPACT, BISTOP, POLY, SHF, AKISPL)
with the safe expression parser `parse`.
"""
from . import _jitcache  # noqa: F401  (first: numba's cache directory for this version of the kernels)
from . import expressions, functions
from .errors import AssemblyError, MbdsimError, ModelError, SolverError
from .expressions import ExpressionError, parse
from .functions import AKISPL, BISTOP, HAVSIN, IMPACT, POLY, SHF, STEP, STEP5, Akima, CubicSplineTable
from .model import Body, Force, Joint, Marker, Model, Motion, SpringDamper, Torque
from .model.curves import Curve, Spline
from .model.shapes import Plane, Sphere
from .results import Result
from .solvers.assembly import AssemblyReport, RedundantConstraintWarning, assemble
from .solvers.dynamic import simulate
from .solvers.kinematic import kinematics
from .solvers.static import equilibrium
from .plotting import plot
from .viewer import animate

__version__ = "0.1.0"

__all__ = [
    "Model", "Body", "Marker", "Joint", "Motion", "Force", "Torque", "SpringDamper", "Result",
    "Curve", "Spline", "Sphere", "Plane",
    "simulate", "kinematics", "assemble", "equilibrium", "AssemblyReport",
    "MbdsimError", "ModelError", "AssemblyError", "SolverError", "ExpressionError", "RedundantConstraintWarning",
    "expressions", "functions", "parse",
    "plot", "animate",
    "STEP", "STEP5", "HAVSIN", "IMPACT", "BISTOP", "POLY", "SHF", "AKISPL", "Akima", "CubicSplineTable",
]
