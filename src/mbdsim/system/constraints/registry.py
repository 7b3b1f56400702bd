"""Joint kind -> joint type class."""
from .cylindrical import Cylindrical
from .fixed import Fixed
from .planar import Planar
from .revolute import Revolute
from .spherical import Spherical
from .translational import Translational
from .universal import Universal

JOINT_TYPES = {c.kind: c for c in (Revolute, Spherical, Cylindrical, Translational, Universal, Planar, Fixed)}
