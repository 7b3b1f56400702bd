"""Type aliases of the public API, for annotations only (units and frames are in each docstring).

Modules import them under `typing.TYPE_CHECKING` (with `from __future__ import annotations`), so they
cost nothing at run time.
"""
from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any, Callable, Sequence, Union

from numpy.typing import ArrayLike, NDArray

if TYPE_CHECKING:
    from scipy.spatial.transform import Rotation

    from .model.body import Body, Marker
    from .model.joints import Joint
    from .model.model import Model
    from .model.shapes import Box, Cylinder, Sphere
    from .results.result import Result

Vector = ArrayLike                                   # 3 numbers [SI units]: list, tuple or numpy array
Array = NDArray[Any]                                 # a numpy array returned by a measure
BodyRef = Union[str, "Body"]                         # a body (or ground) or its name
JointRef = Union[str, "Joint"]                       # a joint or its name
Target = Union[str, "Body", "Marker"]                # a body, a marker, or a name ("body" / "body.marker")
FrameRef = Union["Body", "Marker", None]             # axes to express a vector in (None: ground)
Location = Union[str, "Marker", "Body", Sequence[Any]]   # a marker, a body (its CM) or (body, point)
Orientation = Union[ArrayLike, "Rotation", None]     # 3x3 matrix (body -> ground) or a scipy Rotation
Inertia = Union[ArrayLike, None]                     # 3 principal moments or a 3x3 matrix [kg m^2]
MassShape = Union["Box", "Cylinder", "Sphere"]       # geometry giving mass properties from a density
TimeFunction = Union[float, str, Callable[[float], float]]   # a number, an expression in t, or f(t)
Load = Union[ArrayLike, str, Callable[..., ArrayLike]]       # constant, expression or f(t, state)
Signal = Union[str, Callable[["Result"], ArrayLike]]         # a column name or a measure of a Result
Progress = Union[Callable[[float], Any], bool, None]         # progress(t [s]), True: a progress bar
PathLike = Union[str, "os.PathLike[str]"]
ModelOrName = Union["Model", PathLike]

__all__ = ["Vector", "Array", "BodyRef", "JointRef", "Target", "FrameRef", "MassShape", "Location", "Orientation", "Inertia",
           "TimeFunction", "Load", "Signal", "Progress", "PathLike", "ModelOrName"]
