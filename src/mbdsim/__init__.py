"""mbdsim: 3D multibody dynamics in Python (SI units throughout).

Public API (a contract; everything else may change): Model, simulate, kinematics, assemble,
equilibrium, Result, the error types and the expression/function library.
"""
from .errors import AssemblyError, MbdsimError, ModelError, SolverError
from .model import Body, Force, Joint, Marker, Model, Motion, SpringDamper, Torque
from .results import Result
from .solvers.assembly import AssemblyReport, RedundantConstraintWarning, assemble
from .solvers.dynamic import simulate
from .solvers.kinematic import kinematics
from .solvers.static import equilibrium

__version__ = "0.1.0"

__all__ = [
    "Model", "Body", "Marker", "Joint", "Motion", "Force", "Torque", "SpringDamper", "Result",
    "simulate", "kinematics", "assemble", "equilibrium", "AssemblyReport",
    "MbdsimError", "ModelError", "AssemblyError", "SolverError", "RedundantConstraintWarning",
]

from .model.curves import Curve, Spline  # noqa: E402  (issue 3: path constraint curves)
__all__ += ["Curve", "Spline"]

from .model.shapes import Plane, Sphere  # noqa: E402  (issue 3: contact shapes)
__all__ += ["Sphere", "Plane"]
