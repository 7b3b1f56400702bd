"""Tier 1: what the user describes (bodies, markers, joints, drivers, loads): plain validated data."""
from .body import Body, Marker
from .joints import Joint, Motion
from .forces import Force, Torque, SpringDamper
from .model import Model

__all__ = ["Body", "Marker", "Joint", "Motion", "Force", "Torque", "SpringDamper", "Model"]
