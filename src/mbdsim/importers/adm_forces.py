"""Force statements of an .adm dataset -> mbdsim loads and force elements (SI).

SFORCE TRANSLATIONAL: a line force (positive repels, as in Adams); ACTIONONLY: a force on I along J's z.
SFORCE ROTATIONAL / SPRINGDAMPER ROTATIONAL: a torque on I about J's z and its reaction on J.
SPRINGDAMPER TRANSLATIONAL: a spring-damper (FORCE is the preload, repelling positive).  BUSHING:
mbdsim's bushing (Adams semantics; rotations as a rotation vector, equal to Adams' small angles to
first order).  FIELD (matrices by columns): diagonal -> a bushing; coupled -> expression loads of the
same linear law (field_loads).  VFORCE/VTORQUE/GFORCE: expression components in the RM marker's axes on I, the
reaction on the JFLOAT marker's part at I's current position (as a force at the floating marker's
initial point plus the moment of the offset).  FRICTION: mbdsim's event-driven joint friction (the
stiction transition parameters are approximated by exact stick/slip).  CONTACT and GRAPHICS: adm_contact.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError


def _par(text):
    return f"({text})"


def _pair_loads(imp, st, name, mi, ref_j, frame, force, torque):
    """Force components `force` (3 texts or None) at marker `mi` and torque `torque` on its body, in the axes
    of `frame`; the reaction (when ref_j is on a moving body) on ref_j's body: -force at ref_j plus the
    moment -(r x F) of the offset r = I - ref_j, and -torque."""
    m = imp.model
    if force is not None:
        m.add_force(f"{name}_force" if torque is not None else name, mi, list(force), frame=frame)
    if torque is not None:
        m.add_torque(f"{name}_torque" if force is not None else name, mi.body, list(torque), frame=frame)
    if ref_j is None or ref_j.body.is_ground:
        return
    k = f"{frame.body.name}.{frame.name}" if frame is not None else "ground"
    i, j = f"{mi.body.name}.{mi.name}", f"{ref_j.body.name}.{ref_j.name}"
    if force is not None:
        m.add_force(f"{name}_reaction", ref_j, [f"-{_par(c)}" for c in force], frame=frame)
        r = [f"DX({i}, {j}, {k})", f"DY({i}, {j}, {k})", f"DZ({i}, {j}, {k})"]
        F = [_par(c) for c in force]
        moment = [f"-({r[1]}*{F[2]} - {r[2]}*{F[1]})", f"-({r[2]}*{F[0]} - {r[0]}*{F[2]})",
                  f"-({r[0]}*{F[1]} - {r[1]}*{F[0]})"]
        if torque is not None:
            moment = [f"{mm} - {_par(t)}" for mm, t in zip(moment, torque)]
        m.add_torque(f"{name}_reaction_torque", ref_j.body, moment, frame=frame)
    elif torque is not None:
        m.add_torque(f"{name}_reaction_torque", ref_j.body, [f"-{_par(t)}" for t in torque], frame=frame)


def sforce(imp, st) -> None:
    """SFORCE/id, I=, J=, TRANSLATIONAL|ROTATIONAL [, ACTIONONLY], FUNCTION=."""
    a, fl = imp.args(st, ("I", "J", "FUNCTION"), ("TRANSLATIONAL", "ROTATIONAL", "ACTIONONLY"))
    mi, mj = imp.marker(st, a, "I"), imp.marker(st, a, "J", fixed=False)
    rot = "ROTATIONAL" in fl
    f = imp.expression(st, a, "FUNCTION", "torque" if rot else "force")
    name = imp.name(st, f"SFORCE_{st.id}")
    try:
        if rot:
            _pair_loads(imp, st, name, mi, None if "ACTIONONLY" in fl else mj, mj, None, ["0", "0", f])
        elif "ACTIONONLY" in fl:
            imp.model.add_force(name, mi, ["0", "0", f], frame=mj)
        else:
            imp.model.add_line_force(name, mi, mj, f"-({f})")
    except ModelError as exc:
        imp.model_error(st, exc, a["FUNCTION"].line)


def springdamper(imp, st) -> None:
    """SPRINGDAMPER/id, I=, J=, TRANSLATIONAL (K, C, LENGTH, FORCE) | ROTATIONAL (KT, CT, ANGLE, TORQUE)."""
    a, fl = imp.args(st, ("I", "J", "K", "C", "LENGTH", "FORCE", "KT", "CT", "ANGLE", "TORQUE"),
                     ("TRANSLATIONAL", "ROTATIONAL"))
    mi, mj = imp.marker(st, a, "I"), imp.marker(st, a, "J")
    name = imp.name(st, f"SPRINGDAMPER_{st.id}")
    try:
        if "ROTATIONAL" in fl:
            kt = imp.num(st, a, "KT", 0.0, "rot_stiffness")
            ct = imp.num(st, a, "CT", 0.0, "rot_damping")
            a0 = imp.num(st, a, "ANGLE", 0.0, "angle")
            t0 = imp.num(st, a, "TORQUE", 0.0, "torque")
            i, j = f"{mi.body.name}.{mi.name}", f"{mj.body.name}.{mj.name}"
            t = f"-({kt!r})*(AZ({i}, {j}) - ({a0!r})) - ({ct!r})*WZ({i}, {j}, {j}) + ({t0!r})"
            _pair_loads(imp, st, name, mi, mj, mj, None, ["0", "0", t])
            imp.note(st, "rotational spring-damper read as torques in AZ(I, J) (within +-180 deg, no turn count) "
                     "and WZ(I, J, J)")
        else:
            k = imp.num(st, a, "K", 0.0, "stiffness")
            c = imp.num(st, a, "C", 0.0, "damping")
            L0 = imp.num(st, a, "LENGTH", None, "length")
            f0 = imp.num(st, a, "FORCE", 0.0, "force")
            imp.model.add_spring_damper(name, mi, mj, k, c, free_length=L0, preload=-f0)
    except ModelError as exc:
        imp.model_error(st, exc)


def bushing(imp, st) -> None:
    """BUSHING/id, I=, J=, STIFFNESS, DAMPING, TSTIFFNESS, TDAMPING, FORCE, TORQUE (on I, in J's axes)."""
    a, _ = imp.args(st, ("I", "J", "STIFFNESS", "DAMPING", "TSTIFFNESS", "TDAMPING", "FORCE", "TORQUE"))
    mi, mj = imp.marker(st, a, "I"), imp.marker(st, a, "J")
    k = imp.nums(st, a, "STIFFNESS", 3, [0.0] * 3, "stiffness") + imp.nums(st, a, "TSTIFFNESS", 3, [0.0] * 3,
                                                                           "rot_stiffness")
    c = imp.nums(st, a, "DAMPING", 3, [0.0] * 3, "damping") + imp.nums(st, a, "TDAMPING", 3, [0.0] * 3, "rot_damping")
    p = imp.nums(st, a, "FORCE", 3, [0.0] * 3, "force") + imp.nums(st, a, "TORQUE", 3, [0.0] * 3, "torque")
    try:
        imp.model.add_bushing(imp.name(st, f"BUSHING_{st.id}"), mj, mi, k, c, p)
    except ModelError as exc:
        imp.model_error(st, exc)
    if any(k[3:]) or any(c[3:]):
        imp.note(st, "rotations as a rotation vector (Adams: small angles; equal to first order)")


def field(imp, st) -> None:
    """FIELD/id, I=, J=, KMATRIX (36), CMATRIX (36) or CRATIO, LENGTH (6), FORCE (6); the matrices are given
    by columns, as Adams reads them.  Diagonal: a bushing; coupled (off-diagonal terms): the same linear
    law written as expression loads on I in J's axes (field_loads)."""
    if "FUNCTION" in [x.key for x in st.args]:
        imp.fail(st, "FUNCTION", "a FIELD written by a user subroutine (FIESUB) is not supported")
    a, _ = imp.args(st, ("I", "J", "KMATRIX", "CMATRIX", "CRATIO", "LENGTH", "FORCE"), ignored=("ROUTINE",))
    mi, mj = imp.marker(st, a, "I"), imp.marker(st, a, "J")
    K = np.array(imp.nums(st, a, "KMATRIX", 36, [0.0] * 36)).reshape(6, 6).T     # by columns
    C = np.array(imp.nums(st, a, "CMATRIX", 36, [0.0] * 36)).reshape(6, 6).T
    if "CRATIO" in a:
        C = imp.num(st, a, "CRATIO") * K
    L = np.array(imp.nums(st, a, "LENGTH", 6, [0.0] * 6))
    # SI: translational rows in force, rotational in torque; columns in length or rad (and per time for C)
    su = np.array([imp.units.scale("force")] * 3 + [imp.units.scale("torque")] * 3)
    du = np.array([imp.units.length] * 3 + [1.0] * 3)
    K, C = K * su[:, None] / du[None, :], C * su[:, None] / du[None, :] * imp.units.time
    L = L * du
    f0 = np.array(imp.nums(st, a, "FORCE", 6, [0.0] * 6)) * su
    name = imp.name(st, f"FIELD_{st.id}")
    off = lambda M: M - np.diag(np.diag(M))   # noqa: E731
    try:
        if np.any(off(K)) or np.any(off(C)):
            field_loads(imp, st, name, mi, mj, K, C, L, f0)
            imp.note(st, "coupled FIELD read as expression loads: rotations as AX/AY/AZ(I, J) (Adams' small "
                     "angles), translational velocity as seen in J's frame")
            return
        k, c = np.diag(K), np.diag(C)
        imp.model.add_bushing(name, mj, mi, k, c, f0 + k * L)    # -K (x - L) + F0 = -K x + (F0 + K L)
    except ModelError as exc:
        imp.model_error(st, exc)
    imp.note(st, "diagonal FIELD read as a bushing (rotations as a rotation vector)")


def field_loads(imp, st, name, mi, mj, K, C, L, f0) -> None:
    """F = -K (x - L) - C xdot + F0 on I (SI, J's axes): x = (DX DY DZ)(I, J, J), AX AY AZ(I, J); xdot =
    the velocity of I relative to J as seen in J's frame (VX(I, J, J) - (w_J x r)) and WX WY WZ(I, J, J).
    The reaction on J's part, with the moment of the offset, by _pair_loads (exact action-reaction)."""
    i, j = f"{mi.body.name}.{mi.name}", f"{mj.body.name}.{mj.name}"
    r = [f"D{c}({i}, {j}, {j})" for c in "XYZ"]
    wj = [f"W{c}({j}, ground, {j})" for c in "XYZ"]
    x = r + [f"A{c}({i}, {j})" for c in "XYZ"]
    v = [f"(V{c}({i}, {j}, {j}) - ({wj[(n + 1) % 3]}*{r[(n + 2) % 3]} - {wj[(n + 2) % 3]}*{r[(n + 1) % 3]}))"
         for n, c in enumerate("XYZ")] + [f"W{c}({i}, {j}, {j})" for c in "XYZ"]
    rows = []
    for n in range(6):
        terms = [repr(float(f0[n] + K[n] @ L))]
        terms += [f"({float(-K[n, m])!r})*{x[m]}" for m in range(6) if K[n, m] != 0.0]
        terms += [f"({float(-C[n, m])!r})*{v[m]}" for m in range(6) if C[n, m] != 0.0]
        rows.append(" + ".join(terms))
    _pair_loads(imp, st, name, mi, mj, mj, rows[:3], rows[3:])


def vector_force(imp, st) -> None:
    """VFORCE (FX FY FZ), VTORQUE (TX TY TZ), GFORCE (both): on I in RM's axes, reaction on JFLOAT's part."""
    keys = {"VFORCE": ("FX", "FY", "FZ"), "VTORQUE": ("TX", "TY", "TZ"),
            "GFORCE": ("FX", "FY", "FZ", "TX", "TY", "TZ")}[st.name]
    a, _ = imp.args(st, ("I", "JFLOAT", "RM") + keys)
    mi, rm = imp.marker(st, a, "I"), imp.marker(st, a, "RM", required=False, fixed=False)
    jf = imp.marker(st, a, "JFLOAT", fixed=False)
    for kk in keys:
        if kk not in a:
            imp.fail(st, kk, f"is required for {st.name}")
    force = [imp.expression(st, a, kk, "force") for kk in keys if kk.startswith("F")] or None
    torque = [imp.expression(st, a, kk, "torque") for kk in keys if kk.startswith("T")] or None
    try:
        _pair_loads(imp, st, imp.name(st, f"{st.name}_{st.id}"), mi, jf, rm, force, torque)
    except ModelError as exc:
        imp.model_error(st, exc)


def friction(imp, st) -> None:
    """FRICTION/id, JOINT=, MU_STATIC, MU_DYNAMIC and the joint's friction arms -> Model.add_friction."""
    a, _ = imp.args(st, ("JOINT", "MU_STATIC", "MU_DYNAMIC", "PIN_RADIUS", "FRICTION_ARM", "BENDING_REACTION_ARM",
                         "FRICTION_FORCE_PRELOAD", "FRICTION_TORQUE_PRELOAD", "REACTION_ARM", "INITIAL_OVERLAP"),
                    ignored=("STICTION_TRANSITION_VELOCITY", "TRANSITION_VELOCITY_COEFFICIENT",
                             "MAX_STICTION_DEFORMATION", "MAX_FRICTION_FORCE", "MAX_FRICTION_TORQUE", "EFFECT",
                             "INPUTS", "BALL_RADIUS", "OVERLAP_DELTA", "FRICTION_MODEL"))
    jid = imp.ident(st, a, "JOINT")
    jt = imp.joints.get(jid)
    if jt is None:
        imp.fail(st, "JOINT", f"no JOINT/{jid} in the dataset")
    params = {}
    if jt.kind == "revolute":
        for key, p, q in (("PIN_RADIUS", "pin_radius", "length"), ("FRICTION_ARM", "friction_arm", "length"),
                          ("BENDING_REACTION_ARM", "bending_arm", "length"),
                          ("FRICTION_TORQUE_PRELOAD", "preload", "torque")):
            if key in a:
                params[p] = imp.num(st, a, key, None, q)
    else:
        for key, p, q in (("FRICTION_FORCE_PRELOAD", "preload", "force"), ("INITIAL_OVERLAP", "effective_length",
                                                                            "length"),
                          ("REACTION_ARM", "reaction_arm", "length")):
            if key in a:
                params[p] = imp.num(st, a, key, None, q)
    try:
        imp.model.add_friction(imp.name(st, f"FRICTION_{st.id}"), jt, imp.num(st, a, "MU_STATIC", 0.0),
                               imp.num(st, a, "MU_DYNAMIC", 0.0), **params)
    except ModelError as exc:
        imp.model_error(st, exc)
    imp.note(st, "stick/slip by events (exact Coulomb); Adams' stiction transition parameters are not used")
