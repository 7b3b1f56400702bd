"""MJCF <equality> -> exact mbdsim constraints (MuJoCo's are soft: solref/solimp are not imported).

  joint   y - y0 = a0 + a1 (x - x0) + ... + a4 (x - x0)^4  (y0, x0 = qpos0; mbdsim coordinates are
          q - qpos0): a coupler when only a1 is non-zero, else a user constraint; without joint2
          the coordinate is held at a0 (a motion)
  connect the anchor points of body1 and body2 coincide: a spherical joint at the anchor; by sites:
          a spherical joint between markers at site1 and site2 (their origins coincide)
  weld    body2 keeps its pose relative to body1 (as at qpos0): a fixed joint; by sites: a fixed joint
          between markers at the two sites (their frames coincide)
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError, ModelFileError
from ._common import is_identifier

CONNECT, WELD, JOINT = 0, 1, 2
SITE = 6


def add_equality(b, e) -> None:
    """Add equality e of builder b's MjModel to its Model (ModelFileError naming the element)."""
    mj, model = b.mj, b.model
    typ = int(mj.eq_type[e])
    tag = {CONNECT: "connect", WELD: "weld", JOINT: "joint"}.get(typ, "equality")
    fname = b.name("mjOBJ_EQUALITY", e)
    name = b.names.take(fname or f"{tag}_{e}", "equality")
    if not mj.eq_active0[e]:
        b.notes.append(f"equality {name!r} is inactive in the file: not imported")
        return
    try:
        if typ == JOINT:
            _joint(b, e, name)
        elif typ in (CONNECT, WELD):
            _connect_weld(b, e, name, typ)
        else:
            raise ModelError(f"equality '{name}'", "type", "only joint, connect and weld equalities are supported")
    except ModelFileError:
        raise
    except ModelError as exc:
        raise b.error(tag, fname, exc.field, str(exc)) from None
    b.notes.append(f"equality {name!r} is an exact constraint (MuJoCo's soft solref/solimp are not imported)")


def _joint(b, e, name) -> None:
    mj, model = b.mj, b.model
    j1, j2 = int(mj.eq_obj1id[e]), int(mj.eq_obj2id[e])
    a = [float(x) for x in mj.eq_data[e, :5]]
    y = b.joint_of.get(j1)
    x = b.joint_of.get(j2) if j2 >= 0 else None
    if y is None or y.kind not in ("revolute", "translational") or (j2 >= 0 and (x is None or x.kind not in
                                                                                    ("revolute", "translational"))):
        raise ModelError(f"equality '{name}'", "joint1", "a joint equality couples hinge and slide joints")
    if x is None:
        model.add_motion(name, y, displacement=a[0])
        return
    if a[0] == 0.0 and not any(a[2:]):
        model.add_coupler(name, x, y, a[1])
        return
    if not (is_identifier(x.name) and is_identifier(y.name)):
        raise ModelError(f"equality '{name}'", "polycoef", "a polynomial coupling is a constraint expression, "
                         "which needs joint names that are identifiers")
    poly = " + ".join(f"({c!r})*{x.name}**{k}" if k > 1 else (f"({c!r})*{x.name}" if k else f"({c!r})")
                      for k, c in enumerate(a) if c != 0.0) or "0"
    model.add_user_constraint(name, f"{y.name} - ({poly})")


def _connect_weld(b, e, name, typ) -> None:
    mj, d, model = b.mj, b.data, b.model
    o1, o2 = int(mj.eq_obj1id[e]), int(mj.eq_obj2id[e])
    if int(mj.eq_objtype[e]) == SITE:
        _site_pair(b, name, typ, o1, o2)
        return
    b1, b2 = o1, o2
    point = d.xpos[b1] + d.xmat[b1].reshape(3, 3) @ mj.eq_data[e, :3]
    body1, body2 = b.body_of[b1], b.body_of[b2]
    if body1 is body2:
        b.notes.append(f"equality {name!r} joins parts of one rigid body: nothing to constrain")
        return
    if typ == CONNECT:
        model.add_spherical(name, body1, body2, point)
        return
    _check_relpose(b, e, b1, b2, name)
    model.add_fixed(name, body1, body2, point)


def _site_pair(b, name, typ, s1, s2) -> None:
    """connect / weld given by sites: MuJoCo makes site1's origin (connect) or frame (weld) coincide with
    site2's; a spherical (fixed) joint between markers at the two sites does so exactly, and assembly
    closes the loop when the file draws the sites apart."""
    body1, body2 = b.body_of[int(b.mj.site_bodyid[s1])], b.body_of[int(b.mj.site_bodyid[s2])]
    if body1 is body2:
        b.notes.append(f"equality {name!r} joins parts of one rigid body: nothing to constrain")
        return
    m1, m2 = _site_marker(b, s1, body1), _site_marker(b, s2, body2)
    (b.model.add_spherical if typ == CONNECT else b.model.add_fixed)(name, m1, m2)


def _site_marker(b, s, body):
    """The marker of site s on `body` (the site's name when it can be one; add_sites then keeps it)."""
    d = b.data
    name = b.name("mjOBJ_SITE", s)
    for cand in (name, f"site_{s}"):
        if cand and cand in body.markers:
            return body.markers[cand]
        if cand and is_identifier(cand):
            try:
                return body.add_marker(cand, d.site_xpos[s].copy(), d.site_xmat[s].reshape(3, 3).copy())
            except ModelError:
                continue
    raise ModelError(f"site '{name}'", "name", "cannot be a marker name")


def _check_relpose(b, e, b1, b2, name) -> None:
    """A weld's relpose must be the pose as drawn (at qpos0), which the fixed joint holds."""
    from scipy.spatial.transform import Rotation
    mj = b.mj
    dd = b.mujoco.MjData(mj)
    dd.qpos[:] = mj.qpos0
    b.mujoco.mj_kinematics(mj, dd)
    R1 = dd.xmat[b1].reshape(3, 3)
    rel_p = R1.T @ (dd.xpos[b2] - dd.xpos[b1])
    rel_R = R1.T @ dd.xmat[b2].reshape(3, 3)
    qw = mj.eq_data[e, 6:10]
    given = Rotation.from_quat([qw[1], qw[2], qw[3], qw[0]]).as_matrix() if np.linalg.norm(qw) > 0 else rel_R
    if np.linalg.norm(rel_p - mj.eq_data[e, 3:6]) > 1e-9 or np.abs(given - rel_R).max() > 1e-9:
        raise ModelError(f"equality '{name}'", "relpose", "a weld is imported as the relative pose at qpos0; "
                         "an explicit relpose different from it is not supported")
