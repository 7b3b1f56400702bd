"""One- or two-sided compliant stop on a joint coordinate (Adams IMPACT / BISTOP on the coordinate)."""
from __future__ import annotations

import numpy as np

from ...model.element_specs import Stop
from . import register
from ._common import angle_reanchor, angle_switch, element_state, joint_coordinate, load_from_rows


def _walls(elem, x, xd):
    """Per active wall: (penetration p >= 0, rate dp/dt, outward sign s): the load along x is s * f."""
    out = []
    if elem.lower is not None:
        out.append((np.maximum(elem.lower - x, 0.0), -xd, 1.0))
    if elem.upper is not None:
        out.append((np.maximum(x - elem.upper, 0.0), xd, -1.0))
    return out


def _wall_force(elem, p, pd):
    """max(0, k p^e + STEP(p, 0, 0, d, c) dp/dt) where p > 0, else 0."""
    u = np.clip(p / elem.penetration, 0.0, 1.0)
    c = elem.damping * u * u * (3.0 - 2.0 * u)
    f = elem.stiffness * p**elem.exponent + c * pd
    return np.where(p > 0.0, np.maximum(f, 0.0), 0.0)


@register(Stop)
class StopEval:
    """Stop element; spring_length/velocity/force give the joint coordinate, its rate and the stop load."""

    @staticmethod
    def measure(sys, fr, elem, t=None):
        x, xd, _ = joint_coordinate(sys, fr, elem.joint, elem.dof, elem.name, t)
        return x, xd

    @staticmethod
    def tension(elem, x, xd):
        """Load along the coordinate [N or N m] on body_j (> 0 pushes x up, from the lower wall)."""
        x, xd = np.asarray(x, float), np.asarray(xd, float)
        return sum((s * _wall_force(elem, p, pd) for p, pd, s in _walls(elem, x, xd)), np.zeros_like(x))

    @staticmethod
    def generalized(sys, fr, elem, t, state):
        x, xd, rows = joint_coordinate(sys, fr, elem.joint, elem.dof, elem.name, t)
        F = float(StopEval.tension(elem, x, xd)[0])
        return load_from_rows(sys, fr, rows, F) if F != 0.0 else np.zeros(sys.nv)

    @staticmethod
    def potential(sys, fr, elem):
        """k p^(e+1) / (e+1) [J] per penetrated wall."""
        x, xd = StopEval.measure(sys, fr, elem)
        e = elem.exponent
        return sum((elem.stiffness * p ** (e + 1) / (e + 1) for p, _, _ in _walls(elem, x, xd)), np.zeros_like(x))

    @staticmethod
    def dissipation(sys, fr, elem, t):
        """Damping power (f - k p^e) dp/dt per penetrated wall [W]."""
        x, xd = StopEval.measure(sys, fr, elem, t)
        return sum(((_wall_force(elem, p, pd) - np.where(p > 0, elem.stiffness * p**elem.exponent, 0.0)) * pd
                    for p, pd, _ in _walls(elem, x, xd)), np.zeros_like(x))

    @staticmethod
    def switch(sys, fr, elem, t):
        """Signed clearances x - lower, upper - x [m or rad] (wall contacts located as events), plus the
        angle continuation switch for a rotation."""
        x = joint_coordinate(sys, fr, elem.joint, elem.dof, elem.name, t)[0]
        out = [x - elem.lower] if elem.lower is not None else []
        out += [elem.upper - x] if elem.upper is not None else []
        if elem.dof == "rotation":
            out.append(angle_switch(sys, fr, elem.joint, elem.name, t))
        return np.concatenate(out)

    @staticmethod
    def on_event(sys, elem, t, q, v):
        from ..frames import body_frames
        fr = body_frames(sys, q, v)
        if elem.dof == "rotation":
            angle_reanchor(sys, fr, elem.joint, elem.name, t)
        x = joint_coordinate(sys, fr, elem.joint, elem.dof, elem.name, t)[0][0]
        if any(w is not None and abs(x - w) < 1e-9 for w in (elem.lower, elem.upper)):
            element_state(sys, elem.name).setdefault("events", []).append(float(t))
