"""Arrays of the expression loads (issue 14) and sensors (issue 11) for `system.exprloads_kernel`.

`pack(sys, elems, mode, tree, state, sensors)` turns ExprForce/ExprTorque/LineForce/JointForce elements,
torsion springs and stops (as joint loads, `torsion_expression`, `stop_expression`) and expression
sensors into the tuple `ex` (measures, loads, packed postfix programs of `system.exprvm`,
then the sensors: program, direction, stop flag and value, slots 18-21); `work(ex)` gives its scratch
(slots 2-6: the sensors' values at the last accepted step and at the new one, the events found, their
count and scratch; `solvers.fastdop.run` watches them).
A Python-callable sensor is a program calling its ctypes callback (solvers.pyloads.sensor_callback) with t.
A Python-callable load raises NotCompiled with the reason. On the joint-coordinate path a joint
measure reads the tree's own coordinate: angle = angle at assembly + sign theta (sign -1 when the
joint's body_i is the child in the tree). In absolute coordinates (closed loops) a joint angle is read
from the frames and continued beyond +-pi from the angle at the last accepted step (work slot 7; the step
loops move it, `exprloads_kernel.accept_angles`).
"""
from __future__ import annotations

import numpy as np

from ..model.element_specs import Stop, TorsionSpring
from ..model.forces import ExprForce, ExprTorque, JointForce, LineForce
from ..model.loadexpr import JOINT_ANGLE, JOINT_SLIDE, TIME_NAMES, LoadExpr, Measure, parse_load
from .measures import locate

# packed here: loads written as expressions, and torsion springs and stops as the joint torque or force
# expressions of `torsion_expression` and `stop_expression`
EXPR_TYPES = (ExprForce, ExprTorque, LineForce, JointForce, TorsionSpring, Stop)
LOAD_TYPES = (ExprForce, ExprTorque, LineForce, JointForce)   # the ones whose values may be Python callables


def _coordinate_expression(text, joint, dof) -> LoadExpr:
    """A load expression `text` of a joint's coordinate x [rad or m] and its rate x_dot (dof "rotation"
    or "translation"), for the elements packed as joint loads."""
    from ..expressions import parse
    return LoadExpr(parse(text, (*TIME_NAMES, "x", "x_dot")),
                    {"x": Measure("joint", joint=joint.name, dof=dof),
                     "x_dot": Measure("joint", joint=joint.name, dof=dof, rate=True)})


def torsion_expression(elem) -> LoadExpr:
    """The joint torque [N m] of a TorsionSpring as a load expression of its joint's angle [rad] and rate
    [rad/s]: -(stiffness (theta - free_angle) + damping theta_dot + preload), the torque on body_j about
    the joint axis (system.force_elements.torsion)."""
    text = (f"-({float(elem.stiffness)!r}*(x - {float(elem.free_angle)!r}) + {float(elem.damping)!r}*x_dot"
            f" + {float(elem.preload)!r})")
    return _coordinate_expression(text, elem.joint, "rotation")


def _stop_text(elem, xd) -> str:
    """The Stop's load law as text in x and the rate written `xd` (an expression text)."""
    f = lambda v: repr(float(v))  # noqa: E731
    law = f"{f(elem.stiffness)}, {f(elem.exponent)}, {f(elem.damping)}, {f(elem.penetration)}"
    if elem.lower is not None and elem.upper is not None:
        return f"BISTOP(x, {xd}, {f(elem.lower)}, {f(elem.upper)}, {law})"
    if elem.lower is not None:
        return f"IMPACT(x, {xd}, {f(elem.lower)}, {law})"
    return f"-IMPACT(-x, -({xd}), {f(-elem.upper)}, {law})"


def stop_expression(elem) -> LoadExpr:
    """The load [N or N m] of a Stop along its joint coordinate x (> 0 pushes x up) as a load expression of
    x and its rate: Adams IMPACT at the lower wall, its mirror image at the upper one, BISTOP for both
    (mbdsim.functions; the law of system.force_elements.stop)."""
    return _coordinate_expression(_stop_text(elem, "x_dot"), elem.joint, elem.dof)


def dissipation_expression(elem) -> LoadExpr | None:
    """The damping power [W] of a TorsionSpring or Stop as a load expression of its joint coordinate x and
    rate x_dot: -(L(x, x_dot) - L(x, 0)) x_dot of its load law L (c theta_dot^2 for a torsion spring; for a
    stop (f - k p^e) dp/dt at the penetrated wall, as force_elements.stop.dissipation), read by the compiled
    energy bookkeeping (solvers.fastenergy); None without damping."""
    if not float(elem.damping):
        return None
    if isinstance(elem, TorsionSpring):
        return _coordinate_expression(f"{float(elem.damping)!r}*x_dot*x_dot", elem.joint, "rotation")
    text = f"-(({_stop_text(elem, 'x_dot')}) - ({_stop_text(elem, '0.0')}))*x_dot"
    return _coordinate_expression(text, elem.joint, elem.dof)


class _NotCompiled(Exception):
    pass


def empty() -> tuple:
    """`ex` of a model without expression loads (same types as `pack`'s)."""
    i, f = np.int64, float
    return (np.zeros(0, i), np.zeros((0, 3), i), np.zeros((0, 2, 3)), np.zeros((0, 3, 3, 3)), np.zeros((0, 3, 3)),
            np.zeros(0, i), np.zeros((0, 2)), np.zeros(0, i), np.zeros((0, 3), i), np.zeros((0, 2, 3)),
            np.zeros((0, 3, 3)), np.zeros((0, 3, 3)), np.zeros((0, 3), i), np.zeros((0, 2), i), np.zeros(0, f),
            np.zeros(0, f), np.zeros(0, i), np.zeros(0, i), np.zeros(0, i), np.zeros(0, i), np.zeros(0, i),
            np.zeros(0, f))


EVENT_CAPACITY = 64   # sensor events a run holds (at least two steps' worth) before handing them to Python


def work(ex, stack_size) -> tuple:
    """Scratch of `expr_loads`: the variable vector x (1 + measures) and the interpreter's stack; of the
    sensors: their values (minus the threshold) at the last accepted step and at the new one, the events
    found (time [s], sensor index), their count, and the values at a probed time; of the joint angles read
    from the frames (absolute coordinates): their references [rad] (slot 7: the continued angle at the last
    accepted state, 0 at the start: the first angle in (-pi, pi], as on the reference path)."""
    ns = len(ex[18])
    return (np.zeros(1 + len(ex[0])), np.zeros(max(int(stack_size), 4)), np.zeros(ns), np.zeros(ns),
            np.zeros((max(EVENT_CAPACITY, 2 * ns) if ns else 0, 2)), np.zeros(1, np.int64), np.zeros(ns),
            np.zeros(len(ex[0])))


def _target(sys, name):
    if name is None:
        return 0, np.zeros(3), np.eye(3)
    return locate(sys, name)


def _joint_measure(sys, m, mode, tree, fr):
    """(kind, frames, vectors, tree coordinate index, (offset, sign)) of a joint measure."""
    from .measures import joint_coordinate
    jt = sys.model.joints[m.joint]
    g = sys.geoms[jt.name]
    rot = m.dof == "rotation"
    v = np.stack([g.f_i, g.g_i, g.f_j]) if rot else np.stack([g.h_i, g.s_i, g.s_j])
    kind = (JOINT_ANGLE if rot else JOINT_SLIDE) + int(m.rate)
    jq, jc = -1, (0.0, 1.0)
    if mode == 1:
        parent, qadr = tree[0], tree[7]
        child, sign = (g.bj, 1.0) if parent[g.bj] == g.bi else (g.bi, -1.0)
        jq = int(qadr[child])
        ang, _, sl, _ = joint_coordinate(sys, fr, jt)
        jc = (float((ang if rot else sl)[0]), sign)
    elif rot and not m.rate and g.particle_j:
        raise _NotCompiled(f"the angle of joint '{jt.name}' (its body_j is a particle)")
    # absolute coordinates: the angle from the frames, continued from the angle at the last accepted step
    # (system.exprloads_kernel.continued, accept_angles)
    return kind, (g.bi, g.bj, 0), v, jq, jc


def _compile(expr, slots, inputs, found):
    """`exprvm.compile_expr` of `expr` with the model inputs it reads (variable name -> input name in
    `inputs`) as constants holding their current values; appends (program-local constant index, input
    name) to `found`, so that `mbdsim.Simulator.set_input` can write the constants between steps."""
    from . import exprvm
    from .._exprtree import Var
    if not inputs:
        return exprvm.compile_expr(expr, slots)
    values = {v: float(sys_value) for v, sys_value in inputs.items()}

    class _Emitter(exprvm._Emitter):
        def emit(self, n):
            if isinstance(n, Var) and n.name in values:
                self.consts.append(values[n.name])
                found.append((len(self.consts) - 1, n.name))
                self.push(exprvm.CONST, len(self.consts) - 1)
                return
            super().emit(n)

    em = _Emitter(dict(slots))
    em.emit(getattr(expr, "node", expr))
    return exprvm.Program(np.array(em.code, dtype=np.int64).reshape(-1, 2), np.array(em.consts, dtype=float),
                          np.array(em.tables, dtype=float), max(em.max_depth, 1))


def pack(sys, elems, mode, tree, state, sensors=(), input_slots=None, switches=False):
    """(ex, stack size) of the expression loads `elems` and the Sensors `sensors` (expression signals);
    NotCompiled (from system.compiled) when one cannot be compiled. Model inputs read by the expressions are
    constants of the packed programs: with `input_slots` (a list), (input name, index into ex[14], the
    packed constants) is appended for each place an input is read. With `switches`, the switching
    functions of the stops in `elems` (clearances x - lower, upper - x) and of the model's sphere/plane
    contacts (signed gaps, `_contact_gap`) follow the sensors as entries with action 2 ("cut": the
    compiled implicit steppers end their step at a zero and restart there, as the reference path cuts its
    steps at these events; DOP853 ignores them)."""
    from . import exprvm
    from .compiled import NotCompiled
    from .frames import body_frames
    fr = None
    if mode == 1:
        f1 = body_frames(sys, *state)
        from .frames import Frames
        fr = Frames(f1.r[None], f1.A[None], f1.rd[None], f1.w[None])
    measures, ms, loads, progs = {}, [], [], []

    model_inputs = getattr(sys.model, "inputs", {})
    local_inputs = []   # (program index, local constant index, input name)

    def program(elem, v, what="load"):
        if isinstance(v, LoadExpr):
            slots = {n: 0 for n in TIME_NAMES}
            inputs = {}
            for var, m in v.measures.items():
                if m.name == "input":
                    inputs[var] = model_inputs[m.i].value
                    continue
                if m not in measures:
                    measures[m] = len(measures)
                    try:
                        ms.append(_measure_row(sys, m, mode, tree, fr))
                    except _NotCompiled as exc:
                        raise NotCompiled(f"{what} '{elem.name}' reads {exc}") from None
                slots[var] = 1 + measures[m]
            found = []
            progs.append(_compile(v.expr, slots, inputs, found))
            local_inputs.extend((len(progs) - 1, k, name) for k, name in found)
        elif callable(v):
            raise NotCompiled(f"{what} '{elem.name}' is a Python callable")
        else:
            progs.append(exprvm.constant_program(float(v)))
        return len(progs) - 1

    for e in elems:
        z3, eye = np.zeros(3), np.eye(3)
        if isinstance(e, (ExprForce, ExprTorque)):
            vec = e.force if isinstance(e, ExprForce) else e.torque
            p = [program(e, c) for c in vec.components]
            ff, _, R = (0, None, eye) if e.frame is None else locate(sys, e.frame)
            s = e.s_B if isinstance(e, ExprForce) else z3
            loads.append((0 if isinstance(e, ExprForce) else 1, (sys.fid[e.body], 0, ff), (s, z3), R,
                          np.zeros((3, 3)), p))
        elif isinstance(e, LineForce):
            p = [program(e, e.magnitude), -1, -1]
            loads.append((2, (sys.fid[e.marker_i.body], sys.fid[e.marker_j.body], 0),
                          (e.marker_i.s_B, e.marker_j.s_B), eye, np.zeros((3, 3)), p))
        else:   # a joint force or torque, a torsion spring (a joint torque) or a stop
            g = sys.geoms[e.joint.name]
            rot = isinstance(e, TorsionSpring) or e.dof == "rotation"
            value = torsion_expression(e) if isinstance(e, TorsionSpring) else \
                stop_expression(e) if isinstance(e, Stop) else e.value
            v = np.stack([g.f_i, g.g_i, g.f_j]) if rot else np.stack([g.h_i, g.s_i, g.s_j])
            diss = dissipation_expression(e) if isinstance(e, (TorsionSpring, Stop)) else None
            p = [program(e, value), -1 if diss is None else program(e, diss), -1]   # 2nd: its damping power
            loads.append((3 if rot else 4, (g.bi, g.bj, 0), (z3, z3), eye, v, p))
    sn = []
    for sensor in sensors:
        if sensor.text is None:   # a Python callable: called back through a ctypes callback (solvers.pyloads)
            from ..solvers.pyloads import sensor_callback
            from .._exprtree import Var
            em = exprvm._Emitter({"t": 0})
            em.user_call(sensor_callback(sensor).address, (Var("t"),))   # signal(t, state) at the kernel's frames
            progs.append(exprvm.Program(np.array(em.code, np.int64).reshape(-1, 2), np.array(em.consts, float),
                                        np.zeros(0), max(em.max_depth, 1)))
            p = len(progs) - 1
        else:
            le = parse_load(sys.model, sensor.text, f"sensor '{sensor.name}'", "signal")
            p = program(sensor, le, "sensor")
        sn.append((p, sensor.direction, int(sensor.action == "stop"), sensor.value))
    if switches:
        for e in elems:
            if isinstance(e, Stop):
                walls = ([f"x - {float(e.lower)!r}"] if e.lower is not None else []) + \
                        ([f"{float(e.upper)!r} - x"] if e.upper is not None else [])
                for text in walls:
                    sn.append((program(e, _coordinate_expression(text, e.joint, e.dof), "stop"), 0, 2, 0.0))
        from ..expressions import parse
        for row, radius in _contact_gaps(sys):
            ms.append(row)
            measures[("contact gap", len(ms))] = len(ms) - 1   # (x[len(ms)]: this measure's value)
            progs.append(_compile(parse(f"g - {radius!r}", ("t", "g")), {"t": 0, "g": len(ms)}, {}, []))
            sn.append((len(progs) - 1, 0, 2, 0.0))
    if not loads and not sn:
        return empty(), 4
    pk = exprvm.pack(progs)
    if input_slots is not None and local_inputs:
        offset = np.concatenate([[0], np.cumsum([len(p.consts) for p in progs])])
        input_slots.extend((name, int(offset[p] + k)) for p, k, name in local_inputs)
    i = np.int64
    nm = len(ms)
    ex = (np.array([m[0] for m in ms], i).reshape(nm), np.array([m[1] for m in ms], i).reshape(nm, 3),
          np.array([m[2] for m in ms], float).reshape(nm, 2, 3), np.array([m[3] for m in ms], float).reshape(nm, 3, 3, 3),
          np.array([m[4] for m in ms], float).reshape(nm, 3, 3), np.array([m[5] for m in ms], i).reshape(nm),
          np.array([m[6] for m in ms], float).reshape(nm, 2),
          np.array([x[0] for x in loads], i), np.array([x[1] for x in loads], i).reshape(-1, 3),
          np.array([x[2] for x in loads], float).reshape(-1, 2, 3), np.array([x[3] for x in loads], float).reshape(-1, 3, 3),
          np.array([x[4] for x in loads], float).reshape(-1, 3, 3), np.array([x[5] for x in loads], i).reshape(-1, 3),
          pk.code, pk.consts, pk.tables, pk.start, pk.end,
          *(np.array([x[c] for x in sn], dt).reshape(len(sn)) for c, dt in enumerate((i, i, i, float))))
    return ex, int(pk.stack_size)


def _contact_gaps(sys):
    """(measure row, radii) of each sphere-sphere and sphere-plane contact (system.compiled._contacts): the
    distance of the centres (DM) or the centre's height over the plane along its normal (DZ in axes whose
    z is the normal), the gap [m] being that minus the radii."""
    from .compiled import _contacts
    ct_f, ct_kind, ct_s, ct_n, ct_par = _contacts(sys)
    out = []
    eye3 = np.broadcast_to(np.eye(3), (3, 3, 3))
    for c in range(len(ct_kind)):
        fi, fj = int(ct_f[c, 0]), int(ct_f[c, 1])
        if ct_kind[c] == 0:
            out.append(((3, (fi, fj, 0), np.array([ct_s[c, 0], ct_s[c, 1]]), eye3, np.zeros((3, 3)), -1, (0.0, 1.0)),
                        float(ct_par[c, 0] + ct_par[c, 1])))
            continue
        fs, fp, R, ss, sp = (fj, fi, ct_par[c, 1], ct_s[c, 1], ct_s[c, 0]) if ct_kind[c] == 1 else \
            (fi, fj, ct_par[c, 0], ct_s[c, 0], ct_s[c, 1])
        n = np.asarray(ct_n[c], float) / np.linalg.norm(ct_n[c])
        a = np.eye(3)[int(np.argmin(np.abs(n)))]
        x = np.cross(a, n)
        x /= np.linalg.norm(x)
        Rk = np.column_stack([x, np.cross(n, x), n])   # body axes of the plane: z along its normal
        out.append(((2, (fs, fp, fp), np.array([ss, sp]), np.stack([np.eye(3), np.eye(3), Rk]), np.zeros((3, 3)), -1,
                     (0.0, 1.0)), float(R)))
    return out


def _measure_row(sys, m, mode, tree, fr):
    """(kind, (fi, fj, fk), (s_i, s_j), (R_i, R_j, R_k), joint vectors, tree index, (offset, sign))."""
    if m.joint is not None:
        kind, f, v, jq, jc = _joint_measure(sys, m, mode, tree, fr)
        return kind, f, np.zeros((2, 3)), np.broadcast_to(np.eye(3), (3, 3, 3)), v, jq, jc
    (fi, si, Ri), (fj, sj, Rj), (fk, _, Rk) = (_target(sys, x) for x in (m.i, m.j, m.k))
    return m.kind, (fi, fj, fk), (si, sj), (Ri, Rj, Rk), np.zeros((3, 3)), -1, (0.0, 1.0)
