"""Evaluators of loads written as expressions (issue 14), numpy reference path: ExprForce, ExprTorque,
LineForce, JointForce. The compiled kernels (system.exprloads_kernel) evaluate the same expressions.

A joint angle read by an expression is continued beyond +-pi by the anchors of `_common` (events at
|theta - ref| = WRAP_LIMIT on accepted states), one anchor history per (load, joint).
"""
from __future__ import annotations

import numpy as np

from ...errors import EvaluationError
from ...model.forces import ExprForce, ExprTorque, JointForce, LineForce
from ...model.loadexpr import LoadExpr
from .. import exprmeasures
from ..frames import point_state
from . import register
from ._common import angle_reanchor, angle_switch, batched, joint_coordinate, load_from_rows
from .loads import add_point_force, add_torque


def _exprs(elem):
    if isinstance(elem, (ExprForce, ExprTorque)):
        return (elem.force if isinstance(elem, ExprForce) else elem.torque).exprs
    v = elem.magnitude if isinstance(elem, LineForce) else elem.value
    return [v] if isinstance(v, LoadExpr) else []


def _angles(elem):
    return sorted({j for e in _exprs(elem) for j in e.joint_angles})


def value(sys, fr, elem, v, t, state) -> float:
    """A number, LoadExpr or callable (t, state) at one state (single-state Frames)."""
    if isinstance(v, LoadExpr):
        fb, _ = batched(fr)

        def joint_value(jn, dof, rate):
            x, xd, _ = joint_coordinate(sys, fb, sys.model.joints[jn], dof, f"{elem.name}:{jn}", t)
            return xd if rate else x
        out = float(exprmeasures.evaluate(sys, fb, v, t, joint_value)[0])
    elif callable(v):
        from ..guard import as_numbers
        what, field = _ENTITY.get(type(elem), ("load", "value"))
        got = v(t, state)
        try:
            out = float(as_numbers(got).reshape(-1)[0])
        except (TypeError, ValueError, IndexError):
            raise EvaluationError(f"{what} '{elem.name}'", field, f"callable returned {got!r}, not a number",
                                  time=float(t)) from None
    else:
        return float(v)
    if not np.isfinite(out):
        what, field = _ENTITY.get(type(elem), ("load", "value"))
        raise EvaluationError(f"{what} '{elem.name}'", field, f"evaluates to {out}", time=float(t))
    return out


# the entity and field of each expression load as named when it was added (Model.add_force ...)
_ENTITY = {ExprForce: ("force", "force"), ExprTorque: ("torque", "torque"), LineForce: ("line force", "magnitude"),
           JointForce: ("joint force", "value")}


class _Angles:
    """Switch/on_event of the angle continuation (no switching functions when no angle is read)."""

    @staticmethod
    def switch(sys, fr, elem, t):
        gs = [angle_switch(sys, fr, sys.model.joints[j], f"{elem.name}:{j}", t) for j in _angles(elem)]
        return np.concatenate(gs) if gs else np.zeros(0)

    @staticmethod
    def on_event(sys, elem, t, q, v):
        from ..frames import body_frames
        for j in _angles(elem):
            angle_reanchor(sys, body_frames(sys, q, v), sys.model.joints[j], f"{elem.name}:{j}", t)


def _vector(sys, fr, elem, vec, t, state):
    v = np.array([value(sys, fr, elem, c, t, state) for c in vec.components])
    if elem.frame is not None:
        from ..measures import locate
        fid, _, R_BM = locate(sys, elem.frame)
        v = fr.A[fid] @ (R_BM @ v)
    return v


@register(ExprForce)
class ExprForceEval(_Angles):
    @staticmethod
    def generalized(sys, fr, elem, t, state):
        Q = np.zeros(sys.nv)
        fid = sys.fid[elem.body]
        add_point_force(sys, fr, Q, fid, fr.A[fid] @ elem.s_B, _vector(sys, fr, elem, elem.force, t, state))
        return Q


@register(ExprTorque)
class ExprTorqueEval(_Angles):
    @staticmethod
    def generalized(sys, fr, elem, t, state):
        Q = np.zeros(sys.nv)
        add_torque(sys, fr, Q, sys.fid[elem.body], _vector(sys, fr, elem, elem.torque, t, state))
        return Q


@register(LineForce)
class LineForceEval(_Angles):
    @staticmethod
    def generalized(sys, fr, elem, t, state):
        """+T u on point i, -T u on point j (u from i to j): T > 0 pulls the points together."""
        Q = np.zeros(sys.nv)
        fi, fj = sys.fid[elem.marker_i.body], sys.fid[elem.marker_j.body]
        pi, _, _ = point_state(fr, fi, elem.marker_i.s_B, False)
        pj, _, _ = point_state(fr, fj, elem.marker_j.s_B, False)
        d = pj - pi
        L = float(np.linalg.norm(d))
        u = d / L if L > 0 else np.zeros(3)
        T = value(sys, fr, elem, elem.magnitude, t, state)
        add_point_force(sys, fr, Q, fi, pi - fr.r[fi], T * u)
        add_point_force(sys, fr, Q, fj, pj - fr.r[fj], -T * u)
        return Q


@register(JointForce)
class JointForceEval(_Angles):
    @staticmethod
    def generalized(sys, fr, elem, t, state):
        """F dx/dv: the virtual work of F along the joint coordinate x (rows of the constraint primitives)."""
        _, _, rows = joint_coordinate(sys, fr, elem.joint, elem.dof, f"{elem.name}:{elem.joint.name}", t)
        return load_from_rows(sys, fr, rows, value(sys, fr, elem, elem.value, t, state))
