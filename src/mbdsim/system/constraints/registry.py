"""Joint kind -> joint type class; the row kinds of screw and constant-velocity joints -> their Rows
functions (the group-by-group path of system.equations)."""
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
# Row kinds with their own Rows function (system.kernels.row_terms kinds 7 and 8, compiled like the others)
PAIR_ROW_KINDS = {"screw": screw_rows, "cvel": cvel_rows}
