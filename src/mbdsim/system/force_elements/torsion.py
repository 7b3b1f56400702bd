"""Rotational spring-damper on a revolute or cylindrical joint axis (TorsionSpring)."""
from __future__ import annotations

from ...model.element_specs import TorsionSpring
from . import register
from ._common import angle_reanchor, angle_switch, joint_coordinate, load_from_rows


@register(TorsionSpring)
class TorsionEval:
    """theta [rad] = joint angle of body_j w.r.t. body_i (continued beyond +-pi), rate [rad/s]."""

    @staticmethod
    def measure(sys, fr, elem, t=None):
        """(theta [rad], theta_dot [rad/s]), each (N,)."""
        x, xd, _ = joint_coordinate(sys, fr, elem.joint, "rotation", elem.name, t)
        return x, xd

    @staticmethod
    def tension(elem, theta, theta_dot):
        """Spring torque [N m] k (theta - free) + c theta_dot + preload (the torque on body_j is minus this)."""
        return elem.stiffness * (theta - elem.free_angle) + elem.damping * theta_dot + elem.preload

    @staticmethod
    def generalized(sys, fr, elem, t, state):
        x, xd, rows = joint_coordinate(sys, fr, elem.joint, "rotation", elem.name, t)
        return load_from_rows(sys, fr, rows, -float(TorsionEval.tension(elem, x[0], xd[0])))

    @staticmethod
    def potential(sys, fr, elem):
        """1/2 k (theta - free)^2 + preload (theta - free) [J]."""
        x = TorsionEval.measure(sys, fr, elem)[0] - elem.free_angle
        return 0.5 * elem.stiffness * x**2 + elem.preload * x

    @staticmethod
    def dissipation(sys, fr, elem, t):
        """Damping power c theta_dot^2 [W]."""
        return elem.damping * TorsionEval.measure(sys, fr, elem, t)[1] ** 2

    @staticmethod
    def switch(sys, fr, elem, t):
        """Angle continuation: an event each time the angle moves WRAP_LIMIT from its anchor."""
        return angle_switch(sys, fr, elem.joint, elem.name, t)

    @staticmethod
    def on_event(sys, elem, t, q, v):
        from ..frames import body_frames
        angle_reanchor(sys, body_frames(sys, q, v), elem.joint, elem.name, t)
