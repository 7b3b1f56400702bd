"""Joint kind -> joint type class; numpy-only row kinds -> their evaluators."""
from .atpoint import Atpoint
from .constant_velocity import ConstantVelocity, cvel_rows
from .cylindrical import Cylindrical
from .fixed import Fixed
from .inline import Inline
from .inplane import Inplane
from .orientation import Orientation
from .parallel_axes import ParallelAxes
from .perpendicular import Perpendicular
from .planar import Planar
from .revolute import Revolute
from .screw import Screw, screw_rows
from .spherical import Spherical
from .translational import Translational
from .universal import Universal

JOINT_TYPES = {c.kind: c for c in (Revolute, Spherical, Cylindrical, Translational, Universal, Planar, Fixed,
                                   Inline, Inplane, Orientation, ParallelAxes, Perpendicular, Atpoint,
                                   Screw, ConstantVelocity)}
# Row kinds evaluated by numpy only (the compiled kernels carry sph, dot1, dot2, angle, slide): a model
# with any of them runs the reference path (compile_system raises NotCompiled).
PAIR_ROW_KINDS = {"screw": screw_rows, "cvel": cvel_rows}
