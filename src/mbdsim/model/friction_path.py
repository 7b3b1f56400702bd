"""Model methods for joint friction and path (point-on-curve) constraints.

Mixed into mbdsim.Model.
"""
from __future__ import annotations


class FrictionPathMixin:
    """add_friction, add_point_on_curve (see issue 3)."""
