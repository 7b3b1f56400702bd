"""Shape contact (model.contacts.ShapeContact): the evaluator of the reference path and of the results.

Every quantity comes from the one compiled kernel, solvers.fastcontact.shape_contacts (called here on one
state at a time): generalized loads, and the per-point records (contact point [m], normal, penetration
[m], normal force [N], friction force [N], slip speed [m/s], gap rate [m/s]) from which the potential
k delta^(e+1)/(e+1) [J] and the dissipated power [W] follow.
"""
from __future__ import annotations

import numpy as np

from ...model.contacts import ShapeContact
from . import register
from ._common import batched

MAX_POINTS = 4096   # recorded points per state and element (results)


def packed(sys, elem):
    """fastcontact's packed tuple of one element (kept on the System)."""
    store = sys.derived.setdefault("shape_contact", {})
    sc = store.get(elem.name)
    if sc is None:
        from ...geometry.pack import pack_contacts
        sc = store[elem.name] = pack_contacts(sys, [elem])
    return sc


def _frames(fr, n):
    return (np.ascontiguousarray(fr.r[n]), np.ascontiguousarray(fr.A[n]), np.ascontiguousarray(fr.rd[n]),
            np.ascontiguousarray(fr.w[n]))


def loads(sys, fr1, elem, rec=None):
    """(F (nf, 6): force [N] ground axes, torque [N m] body axes; records (k, NREC)) at one state."""
    from ...solvers.fastcontact import NREC, shape_contacts
    F = np.zeros((sys.nbody + 1, 6))
    rec = np.zeros((0, NREC)) if rec is None else rec
    nrec = np.zeros(1, np.int64)
    shape_contacts(packed(sys, elem), *fr1, np.asarray(sys.frame_rigid, np.bool_), F, rec, nrec)
    return F, rec[:nrec[0]]


def records(sys, fr, elem) -> list:
    """Per sample of time-axis frames fr: the (k, NREC) array of the touching points (fastcontact.REC_FIELDS)."""
    from ...solvers.fastcontact import NREC
    fb, _ = batched(fr)
    buf = np.zeros((MAX_POINTS, NREC))
    return [loads(sys, _frames(fb, n), elem, buf)[1].copy() for n in range(fb.r.shape[0])]


def _pair_law(elem):
    return elem.stiffness, elem.exponent


@register(ShapeContact)
class ShapeContactEval:
    """Shape contact force element: onset is resolved by the step-size control (no switching function)."""

    @staticmethod
    def generalized(sys, fr, elem, t, state):
        fb, _ = batched(fr)
        F, _ = loads(sys, _frames(fb, 0), elem)
        Q = np.zeros(sys.nv)
        for f in range(1, F.shape[0]):
            a = sys.frame_v_adr[f]
            Q[a:a + 3] += F[f, :3]
            if sys.frame_rigid[f]:
                Q[a + 3:a + 6] += F[f, 3:]
        return Q

    @staticmethod
    def potential(sys, fr, elem):
        """Sum over the touching points of k delta^(e+1) / (e+1) [J] (the elastic part of the law)."""
        k, e = _pair_law(elem)
        return np.array([float(np.sum(k * rc[:, 7] ** (e + 1.0) / (e + 1.0))) for rc in records(sys, fr, elem)])

    @staticmethod
    def dissipation(sys, fr, elem, t):
        """Power [W] taken by the damping (or the POISSON unloading) and by friction: (Fn - k delta^e)
        d(delta)/dt + friction force . slip velocity, summed over the touching points."""
        k, e = _pair_law(elem)
        out = []
        for rc in records(sys, fr, elem):
            delta, Fn, gd, s = rc[:, 7], rc[:, 8], rc[:, 13], rc[:, 12]
            Ft = np.linalg.norm(rc[:, 9:12], axis=1)
            out.append(float(np.sum((Fn - k * delta ** e) * (-gd) + Ft * s)))
        return np.array(out)
