"""Collision geometry of imported files as contact (issue 31, `collision=True` of from_urdf / from_mjcf).

URDF: every <collision> geometry becomes a shape on its body (Body.add_shape; meshes as triangle meshes) and
every pair of shapes on two bodies not joined by a joint gets an IMPACT contact with the parameters of
`contact` (DEFAULT_CONTACT where not given).  MJCF: every geom whose contype/conaffinity let it collide
becomes a shape (a plane geom an mb.Plane, a mesh geom the convex hull of its vertices, as MuJoCo collides
it), and each pair MuJoCo would collide (its bitmask, parent-child and <exclude> filters, plus the explicit
<pair>s) gets an IMPACT contact mapped from the pair's solref / solimp (`mujoco_impact`).  A pair of kinds
the narrow phase does not take (mbdsim.model.contacts.supported) is a note, never a failure.  SI units.
"""
from __future__ import annotations

import math
import re

import numpy as np

# IMPACT parameters of URDF contacts (URDF has none): stiffness [N/m^e], exponent e, damping [N s/m]
# reached at penetration [m], Coulomb mu regularised below friction_velocity [m/s]
DEFAULT_CONTACT = {"stiffness": 1e6, "exponent": 1.5, "damping": 100.0, "penetration": 1e-4, "mu": 0.5,
                   "friction_velocity": 1e-3}


def contact_parameters(entity, contact) -> dict:
    """DEFAULT_CONTACT updated with the user's `contact` dict (keyword arguments of Model.add_contact)."""
    from ..errors import ModelError
    if contact is None:
        return dict(DEFAULT_CONTACT)
    if not isinstance(contact, dict):
        raise ModelError(entity, "contact", f"expected a dict of Model.add_contact arguments, got {contact!r}")
    return {**DEFAULT_CONTACT, **contact}


def place(model, v, name, notes, geometry=None):
    """The shape `name` of VisualShape `v` on its body (made with Body.add_shape unless already there);
    None (and a note) when it cannot be made."""
    from ._common import _geometry
    body = model.ground if v.body == model.ground.name else model.bodies.get(v.body)
    if body is None:
        return None
    if name in body.shapes:
        return body.shapes[name]
    try:
        geo = geometry if geometry is not None else _geometry(v)
        if geo is None:
            notes.append(f"collision shape {v.name!r} on {v.body!r}: not made (mesh scale {tuple(v.scale)})")
            return None
        return body.add_shape(name, geo, center=v.point, orientation=v.orientation)
    except Exception as exc:  # noqa: BLE001 - an import goes on without this shape (noted)
        notes.append(f"collision shape {v.name!r} on {v.body!r}: not made ({type(exc).__name__}: {exc})")
        return None


def _kind(s) -> str:
    from ..model.contacts import kind_of
    from ..model.shapes import Plane
    return "plane" if isinstance(s, Plane) else kind_of(s)


def add_contacts(model, pairs, names, notes) -> int:
    """Model.add_contact for each (label_a, shape_a, label_b, shape_b, parameters); pairs of kinds the
    narrow phase does not take are noted.  Returns the number of contacts made."""
    from ..model.contacts import supported
    made = 0
    for la, a, lb, b, params in pairs:
        ka, kb = _kind(a), _kind(b)
        if not supported(ka, kb):
            notes.append(f"no contact between {la!r} ({ka}) and {lb!r} ({kb}): that pair of shapes is not "
                         "supported by the contact model")
            continue
        name = re.sub(r"\W", "_", f"contact_{la}_{lb}")
        model.add_contact(names.take(name, "contact", expression=False), a, b, **params)
        made += 1
    return made


def urdf_contacts(model, robot, body_of, visuals, names, notes, contact) -> None:
    """Shapes of the <collision> geometries and an IMPACT contact between each pair of them on two bodies
    that no joint joins directly."""
    params = contact_parameters("from_urdf", contact)
    shapes = []
    for k, v in enumerate(visuals):
        if v.role == "collision":
            s = place(model, v, f"collision_{k}", notes)
            if s is not None:
                shapes.append((v.name or f"collision_{k}", s))
    adjacent = {frozenset((body_of[j.parent].name, body_of[j.child].name)) for j in robot.joints.values()
                if j.type != "floating"}
    pairs = [(la, a, lb, b, params) for i, (la, a) in enumerate(shapes) for lb, b in shapes[i + 1:]
             if a.body is not b.body and frozenset((a.body.name, b.body.name)) not in adjacent]
    add_contacts(model, pairs, names, notes)
    notes.append(f"collision geometry: {len(shapes)} shapes; URDF gives no contact law: IMPACT with "
                 + ", ".join(f"{k}={v!r}" for k, v in params.items()))


def impedance(r, solimp) -> float:
    """MuJoCo's constraint impedance d(r) at penetration r [m] (solimp = d0, dwidth, width, midpoint, power)."""
    d0, dw, width, mid, power = (float(x) for x in solimp[:5])
    if width <= 1e-15 or d0 == dw:
        d = 0.5 * (d0 + dw)
    else:
        x = min(max(r / width, 0.0), 1.0)
        if x in (0.0, 1.0) or power == 1:
            y = x
        elif x <= mid:
            y = x ** power / mid ** (power - 1)
        else:
            y = 1 - (1 - x) ** power / (1 - mid) ** (power - 1)
        d = d0 + y * (dw - d0)
    return min(max(d, 1e-4), 0.9999)


def resting_penetration(g, solref, solimp) -> float:
    """MuJoCo's penetration [m] of one contact holding a body against acceleration g [m/s^2]: at rest its
    constraint a1 + d (b v + k r) = (1 - d) a0 gives d(r) K d(r) r = (1 - d(r)) g."""
    from scipy.optimize import brentq
    K = _stiffness_ref(solref, solimp)
    f = lambda r: impedance(r, solimp) ** 2 * K * r - (1 - impedance(r, solimp)) * g  # noqa: E731
    d0 = impedance(0.0, solimp)
    hi = (1 - d0) * g / (d0 * d0 * K)       # d(r) >= d0 puts the root below the d0 answer
    return brentq(f, 0.0, hi, xtol=1e-18, rtol=1e-14) if hi > 0 else 0.0


def _stiffness_ref(solref, solimp) -> float:
    dmax = min(max(float(solimp[1]), 1e-4), 0.9999)
    if solref[0] > 0:
        return 1.0 / (dmax ** 2 * float(solref[0]) ** 2 * float(solref[1]) ** 2)
    return -float(solref[0]) / dmax ** 2


def _damping_ref(solref, solimp) -> float:
    dmax = min(max(float(solimp[1]), 1e-4), 0.9999)
    return 2.0 / (dmax * float(solref[0])) if solref[0] > 0 else -float(solref[1]) / dmax


def mujoco_impact(mass, g, solref, solimp, friction, condim) -> dict:
    """IMPACT parameters standing for MuJoCo's soft contact on a body of `mass` [kg] under gravity `g`
    [m/s^2] (see docs/import.md).

    MuJoCo's contact obeys a1 + d (B v + K d r) = (1 - d) a0 with impedance d(r) (solimp) and, for
    solref = (timeconst, dampratio) > 0, K = 1 / (dwidth^2 timeconst^2 dampratio^2), B = 2 / (dwidth
    timeconst) (dwidth = solimp[1]); for solref <= 0, K = -solref[0] / dwidth^2, B = -solref[1] / dwidth.
    The linear IMPACT spring keeps MuJoCo's resting penetration r* of one contact under the weight
    (`resting_penetration`): stiffness m g / r*; its damping keeps MuJoCo's damping ratio B / (2 sqrt K)
    (solref's dampratio) and is reached at a tenth of r*.  mu: the sliding friction (torsional and
    rolling friction dropped; condim 1: frictionless)."""
    r = resting_penetration(g, solref, solimp)
    if not (mass > 0 and r > 0):
        raise ValueError("no resting penetration")   # a massless body or no gravity: caller notes it
    stiffness = mass * g / r
    zeta = _damping_ref(solref, solimp) / (2.0 * math.sqrt(_stiffness_ref(solref, solimp)))
    return {"stiffness": stiffness, "exponent": 1.0, "damping": 2.0 * zeta * math.sqrt(stiffness * mass),
            "penetration": 0.1 * r, "mu": 0.0 if condim == 1 else float(friction[0]), "friction_velocity": 1e-3}


def _mix(mj, g1, g2):
    """MuJoCo's combination of two geoms' contact parameters (priority, else solmix and max friction)."""
    p1, p2 = int(mj.geom_priority[g1]), int(mj.geom_priority[g2])
    if p1 != p2:
        g = g1 if p1 > p2 else g2
        return mj.geom_solref[g], mj.geom_solimp[g], mj.geom_friction[g], int(mj.geom_condim[g])
    s1, s2 = float(mj.geom_solmix[g1]), float(mj.geom_solmix[g2])
    w = 0.5 if s1 + s2 < 1e-15 else s1 / (s1 + s2)
    solref = w * mj.geom_solref[g1] + (1 - w) * mj.geom_solref[g2]
    if mj.geom_solref[g1][0] <= 0 or mj.geom_solref[g2][0] <= 0:   # direct values are not mixed: the smaller
        solref = np.minimum(mj.geom_solref[g1], mj.geom_solref[g2])
    solimp = w * mj.geom_solimp[g1] + (1 - w) * mj.geom_solimp[g2]
    friction = np.maximum(mj.geom_friction[g1], mj.geom_friction[g2])
    return solref, solimp, friction, max(int(mj.geom_condim[g1]), int(mj.geom_condim[g2]))


def _mass(a, b) -> float:
    """The mass MuJoCo's contact acceleration acts on: the moving body's, the reduced mass of two."""
    ma = 0.0 if a.body.is_ground else float(a.body.mass)
    mb_ = 0.0 if b.body.is_ground else float(b.body.mass)
    if ma > 0 and mb_ > 0:
        return ma * mb_ / (ma + mb_)
    return max(ma, mb_)


def mjcf_contacts(builder, shape_of, contact) -> None:
    """Contacts of the collidable geom pairs of the compiled MjModel; `shape_of` {geom id: shape}."""
    mujoco, mj, notes = builder.mujoco, builder.mj, builder.notes
    label = {g: builder.name("mjOBJ_GEOM", g) or f"geom_{g}" for g in shape_of}
    filterparent = not (mj.opt.disableflags & int(mujoco.mjtDisableBit.mjDSBL_FILTERPARENT))
    excluded = {int(s) for s in mj.exclude_signature[:mj.nexclude]} if mj.nexclude else set()
    weld = [int(x) for x in mj.body_weldid]
    parent = [weld[int(mj.body_parentid[w])] for w in weld]
    pairs, seen = [], set()

    g = float(np.linalg.norm(builder.model.gravity)) or 9.81   # without gravity: rated for 1 g (noted)
    if not np.linalg.norm(builder.model.gravity):
        notes.append("no gravity: MuJoCo's contact stiffness is matched at 9.81 m/s^2")

    def add(g1, g2, solref, solimp, friction, condim):
        seen.add(frozenset((g1, g2)))
        a, b = shape_of[g1], shape_of[g2]
        m = _mass(a, b)
        if not m > 0:
            notes.append(f"no contact between {label[g1]!r} and {label[g2]!r}: neither body has mass")
            return
        params = mujoco_impact(m, g, solref, solimp, friction, condim)
        if contact:
            params.update(contact)
        pairs.append((label[g1], a, label[g2], b, params))

    for p in range(mj.npair):
        g1, g2 = int(mj.pair_geom1[p]), int(mj.pair_geom2[p])
        if g1 in shape_of and g2 in shape_of:
            add(g1, g2, mj.pair_solref[p], mj.pair_solimp[p], mj.pair_friction[p], int(mj.pair_dim[p]))
    geoms = sorted(shape_of)
    for i, g1 in enumerate(geoms):
        for g2 in geoms[i + 1:]:
            b1, b2 = weld[int(mj.geom_bodyid[g1])], weld[int(mj.geom_bodyid[g2])]
            if b1 == b2 or frozenset((g1, g2)) in seen:
                continue
            if not (mj.geom_contype[g1] & mj.geom_conaffinity[g2] or mj.geom_contype[g2] & mj.geom_conaffinity[g1]):
                continue
            if filterparent and b1 and b2 and (b1 == parent[b2] or b2 == parent[b1]):
                continue
            lo, hi = sorted((int(mj.geom_bodyid[g1]), int(mj.geom_bodyid[g2])))
            if (lo << 16) + hi in excluded or (hi << 16) + lo in excluded:
                continue
            if shape_of[g1].body is shape_of[g2].body:
                continue
            add(g1, g2, *_mix(mj, g1, g2))
    made = add_contacts(builder.model, pairs, builder.names, notes)
    if made:
        notes.append(f"{made} geom contact pair(s): MuJoCo's soft contact (solref/solimp) approximated by the "
                     "IMPACT law of docs/import.md (linear spring with MuJoCo's resting penetration, "
                     "its damping ratio); torsional and rolling friction dropped")
