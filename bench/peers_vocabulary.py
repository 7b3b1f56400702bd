"""Issue 29's models against the peers that can build them (MuJoCo, Exudyn), measured in the same run:
time at equal accuracy.

    python3 bench/peers_vocabulary.py            # writes bench/PEERS_VOCABULARY.md and peers_vocabulary.json
    python3 bench/peers_vocabulary.py --quick    # fewer settings

Models (each with a closed form, computed here, as the reference):

* gear train: three shafts on revolutes to ground coupled by two gear pairs (ratios -0.5 and -0.4), a
  torsion spring (k = 2 N m/rad) on the output shaft, started with the output turning at 1 rad/s: the
  output angle is (w0 / w) sin(w t), w^2 = k / J_eff, J_eff = J3 + J2 / r2^2 + J1 / (r1 r2)^2; 2 s.
  mbdsim: `add_gear`; MuJoCo: hinge joints coupled by `<equality joint polycoef>` (soft constraints);
  Exudyn: three 1-D coordinates coupled by two ObjectConnectorCoordinate (factor1 = ratio), a
  CoordinateSpringDamper on the output.
* stiff two-mass chain: ground -k1- m1 -k2- m2 along x, k2 = 1e4 k1 (k1 = 100 N/m, 1 kg each), released on
  the slow mode's shape: x(t) = a v_slow cos(w_slow t) exactly; 2 s. mbdsim: translational joints and
  spring-dampers; MuJoCo: slide joints with joint stiffness (the second slide relative to the first mass);
  Exudyn: two 1-D masses and two CoordinateSpringDampers.
* friction slider: a 1 kg block on a horizontal translational joint, Coulomb mu = 0.3 (normal force m g
  from the joint's reaction), launched at 2 m/s: x = v0 t - mu g t^2 / 2 until it stops at v0 / (mu g),
  then rest; 1 s. mbdsim: `add_friction`; MuJoCo: a slide joint with frictionloss = mu m g; Exudyn: a 1-D
  mass on a CoordinateSpringDamperExt with stiffness 0, dynamicFrictionForce = mu m g, regularised for
  |v| < 1e-4 m/s (its error floor, ~4e-9, scales as v_reg^2).
Exudyn's builds and runner are in bench/peers_exudyn.py.

Each engine is swept (mbdsim: rtol of the default method "auto"; MuJoCo: RK4's fixed step; Exudyn:
SolveDynamic's fixed step with GeneralizedAlpha at spectral radius 1 and with RK44, one front over both)
and the time to reach an error (max over the outputs, relative to the motion's amplitude) is read off the
Pareto front as in bench/run.py. Ratios are mbdsim time / peer time at the same error; where one engine
never reaches an error, its best error is reported instead. Absolute times on this shared machine move by 30 %.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
import warnings

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "src"))
sys.path.insert(0, HERE)

import numpy as np  # noqa: E402

import mbdsim as mb  # noqa: E402
from run import front, time_at, fmt_t  # noqa: E402
from sections import replace_section  # noqa: E402
import peers_exudyn as pe  # noqa: E402

try:
    import mujoco
except Exception:  # pragma: no cover
    mujoco = None

G = 9.81
OUT_DT = 0.01
TARGETS = (1e-4, 1e-6)


# ------------------------------------------------------------------------------------------- gear train
GEAR = dict(J=(0.01, 0.02, 0.05), r1=-0.5, r2=-0.4, k=2.0, w0=1.0, T=2.0)


def gear_exact(t):
    J1, J2, J3 = GEAR["J"]
    r1, r2 = GEAR["r1"], GEAR["r2"]
    J_eff = J3 + J2 / r2 ** 2 + J1 / (r1 * r2) ** 2
    w = math.sqrt(GEAR["k"] / J_eff)
    return (GEAR["w0"] / w) * np.sin(w * t), GEAR["w0"] / w


def gear_mbdsim():
    J, r1, r2, w0 = GEAR["J"], GEAR["r1"], GEAR["r2"], GEAR["w0"]
    rates = (w0 / (r1 * r2), w0 / r2, w0)
    m = mb.Model("gear_train")
    joints = []
    for k in range(3):
        b = m.add_body(f"shaft{k + 1}", 1.0, inertia=(J[k], J[k], J[k]), position=(0.3 * k, 0, 0),
                       angular_velocity=(0, 0, rates[k]))
        joints.append(m.add_revolute(f"pin{k + 1}", m.ground, b, (0.3 * k, 0, 0), (0, 0, 1)))
    m.add_gear("mesh1", joints[0], joints[1], r1)
    m.add_gear("mesh2", joints[1], joints[2], r2)
    m.add_torsion_spring("spring", joints[2], stiffness=GEAR["k"])
    return m, lambda res: np.asarray(res.joint_coordinate("pin3")).reshape(len(res.time))


def gear_mujoco(dt):
    J, r1, r2, w0 = GEAR["J"], GEAR["r1"], GEAR["r2"], GEAR["w0"]
    stiff = ' stiffness="%r"' % GEAR["k"]
    bodies = "".join(
        f'<body name="s{k + 1}" pos="{0.3 * k} 0 0"><joint name="j{k + 1}" type="hinge" axis="0 0 1"'
        f'{stiff if k == 2 else ""}/>'
        f'<inertial pos="0 0 0" mass="1" diaginertia="{J[k]} {J[k]} {J[k]}"/></body>' for k in range(3))
    xml = (f'<mujoco><option timestep="{dt!r}" integrator="RK4" gravity="0 0 0"/>'
           f'<worldbody>{bodies}</worldbody><equality>'
           f'<joint joint1="j2" joint2="j1" polycoef="0 {r1!r} 0 0 0"/>'
           f'<joint joint1="j3" joint2="j2" polycoef="0 {r2!r} 0 0 0"/></equality></mujoco>')
    rates = np.array((w0 / (r1 * r2), w0 / r2, w0))
    return xml, rates, lambda qpos: qpos[:, 2]


# ------------------------------------------------------------------------------------------ stiff chain
CHAIN = dict(m=(1.0, 1.0), k1=100.0, k2=1e6, a=0.01, T=2.0)


def chain_modes():
    m1, m2 = CHAIN["m"]
    k1, k2 = CHAIN["k1"], CHAIN["k2"]
    K = np.array([[k1 + k2, -k2], [-k2, k2]])
    Mh = np.diag([1 / math.sqrt(m1), 1 / math.sqrt(m2)])
    w2, V = np.linalg.eigh(Mh @ K @ Mh)
    v = Mh @ V[:, 0]
    return math.sqrt(w2[0]), v / v[0]


def chain_exact(t):
    w, v = chain_modes()
    return CHAIN["a"] * np.cos(w * t)[:, None] * v[None, :], CHAIN["a"] * abs(v).max()


def chain_mbdsim():
    w, v = chain_modes()
    x0 = CHAIN["a"] * v
    m = mb.Model("stiff_chain")
    b1 = m.add_body("m1", CHAIN["m"][0], inertia=(1e-3, 1e-3, 1e-3), position=(1.0 + x0[0], 0, 0))
    b2 = m.add_body("m2", CHAIN["m"][1], inertia=(1e-3, 1e-3, 1e-3), position=(2.0 + x0[1], 0, 0))
    m.add_translational("s1", m.ground, b1, (1.0 + x0[0], 0, 0), (1, 0, 0))
    m.add_translational("s2", b1, b2, (2.0 + x0[1], 0, 0), (1, 0, 0))
    m.add_spring_damper("k1", (m.ground, (0, 0, 0)), (b1, (1.0 + x0[0], 0, 0)), CHAIN["k1"], free_length=1.0)
    m.add_spring_damper("k2", (b1, (1.0 + x0[0], 0, 0)), (b2, (2.0 + x0[1], 0, 0)), CHAIN["k2"], free_length=1.0)

    def read(res):
        return np.stack([np.asarray(res.position("m1"))[:, 0] - 1.0, np.asarray(res.position("m2"))[:, 0] - 2.0], 1)
    return m, read


def chain_mujoco(dt):
    w, v = chain_modes()
    x0 = CHAIN["a"] * v
    xml = (f'<mujoco><option timestep="{dt!r}" integrator="RK4" gravity="0 0 0"/><worldbody>'
           f'<body name="m1" pos="1 0 0"><joint name="s1" type="slide" axis="1 0 0" stiffness="{CHAIN["k1"]!r}"/>'
           f'<inertial pos="0 0 0" mass="{CHAIN["m"][0]!r}" diaginertia="1e-3 1e-3 1e-3"/>'
           f'<body name="m2" pos="1 0 0"><joint name="s2" type="slide" axis="1 0 0" stiffness="{CHAIN["k2"]!r}"/>'
           f'<inertial pos="0 0 0" mass="{CHAIN["m"][1]!r}" diaginertia="1e-3 1e-3 1e-3"/></body></body>'
           f'</worldbody></mujoco>')
    qpos0 = np.array([x0[0], x0[1] - x0[0]])
    return xml, qpos0, lambda qpos: np.stack([qpos[:, 0], qpos[:, 0] + qpos[:, 1]], 1)


# ------------------------------------------------------------------------------------------ friction
FRIC = dict(m=1.0, mu=0.3, v0=2.0, T=1.0)


def fric_exact(t):
    mu, v0 = FRIC["mu"], FRIC["v0"]
    ts = v0 / (mu * G)
    tt = np.minimum(t, ts)
    return v0 * tt - 0.5 * mu * G * tt ** 2, v0 ** 2 / (2 * mu * G)


def fric_mbdsim():
    m = mb.Model("friction_slider", gravity=(0, -G, 0))
    b = m.add_body("block", FRIC["m"], inertia=(1e-3, 1e-3, 1e-3), velocity=(FRIC["v0"], 0, 0))
    j = m.add_translational("slide", m.ground, b, (0, 0, 0), (1, 0, 0))
    m.add_friction("friction", j, FRIC["mu"], FRIC["mu"])
    return m, lambda res: np.asarray(res.position("block"))[:, 0]


def fric_mujoco(dt):
    fl = FRIC["mu"] * FRIC["m"] * G
    xml = (f'<mujoco><option timestep="{dt!r}" integrator="RK4" gravity="0 -{G!r} 0"/><worldbody>'
           f'<body name="block"><joint name="slide" type="slide" axis="1 0 0" frictionloss="{fl!r}"/>'
           f'<inertial pos="0 0 0" mass="{FRIC["m"]!r}" diaginertia="1e-3 1e-3 1e-3"/></body>'
           f'</worldbody></mujoco>')
    return xml, np.array([FRIC["v0"]]), lambda qpos: qpos[:, 0]


# ------------------------------------------------------------------------------------------ runners
def run_mbdsim(build, T, rtol, repeat):
    model, read = build()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = mb.simulate(model, T, OUT_DT, rtol=rtol)   # warm-up: assembly and kernels
        best = math.inf
        for _ in range(repeat):
            t0 = time.perf_counter()
            res = mb.simulate(model, T, OUT_DT, rtol=rtol)
            best = min(best, time.perf_counter() - t0)
    return best, np.asarray(res.time), read(res), res.stats.get("method", "?"), bool(res.success)


def run_mujoco(xml, T, dt, qvel0=None, qpos0=None, repeat=3):
    m = mujoco.MjModel.from_xml_string(xml)
    n_out = int(round(T / OUT_DT))
    nstep = int(round(OUT_DT / dt))
    best, qp = math.inf, None
    for _ in range(repeat):
        d = mujoco.MjData(m)
        if qpos0 is not None:
            d.qpos[:] = qpos0
        if qvel0 is not None:
            d.qvel[:] = qvel0
        out = np.empty((n_out + 1, m.nq))
        t0 = time.perf_counter()
        out[0] = d.qpos
        for k in range(n_out):
            mujoco.mj_step(m, d, nstep=nstep)
            out[k + 1] = d.qpos
        best = min(best, time.perf_counter() - t0)
        qp = out
    return best, np.linspace(0, T, n_out + 1), qp


def error(t, x, exact):
    ref, scale = exact(t)
    return float(np.max(np.abs(np.asarray(x).reshape(ref.shape) - ref)) / scale)


CASES = {
    "gear train (2 stages, torsion spring)": dict(
        T=GEAR["T"], exact=gear_exact, mbdsim=gear_mbdsim,
        mujoco=lambda dt: (lambda x, r, rd: dict(xml=x, qvel0=r, read=rd))(*gear_mujoco(dt)),
        exudyn=lambda mbs: pe.gear_exudyn(mbs, GEAR)),
    "stiff two-mass chain (k2 = 1e4 k1), slow mode": dict(
        T=CHAIN["T"], exact=chain_exact, mbdsim=chain_mbdsim,
        mujoco=lambda dt: (lambda x, q, rd: dict(xml=x, qpos0=q, read=rd))(*chain_mujoco(dt)),
        exudyn=lambda mbs: pe.chain_exudyn(mbs, CHAIN, CHAIN["a"] * chain_modes()[1])),
    "friction slider coasting to rest": dict(
        T=FRIC["T"], exact=fric_exact, mbdsim=fric_mbdsim,
        mujoco=lambda dt: (lambda x, v, rd: dict(xml=x, qvel0=v, read=rd))(*fric_mujoco(dt)),
        exudyn=lambda mbs: pe.fric_exudyn(mbs, FRIC, G)),
}


def sweep(case, quick, log):
    rtols = (1e-4, 1e-6, 1e-8) if quick else (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-10)
    divs = (1, 4, 16, 64) if quick else (1, 2, 5, 10, 20, 50, 100, 200, 500)
    rows = []
    for rtol in rtols:
        try:
            el, t, x, method, ok = run_mbdsim(case["mbdsim"], case["T"], rtol, 1 if quick else 3)
            e = error(t, x, case["exact"]) if ok else math.nan
        except Exception as exc:   # noqa: BLE001  (a failed setting is reported, not fatal)
            el, e, method = math.nan, math.nan, f"failed: {exc}"
        rows.append(dict(engine="mbdsim", setting=f"rtol {rtol:g}", time_s=el, error=e, method=method))
        log(f"    mbdsim rtol {rtol:g}: {el * 1e3:.2f} ms, error {e:.2e} ({method})")
    if mujoco is not None:
        for div in divs:
            dt = OUT_DT / div
            spec = case["mujoco"](dt)
            el, t, qp = run_mujoco(spec["xml"], case["T"], dt, spec.get("qvel0"), spec.get("qpos0"))
            x = spec["read"](qp)
            e = error(t, x, case["exact"]) if np.all(np.isfinite(x)) else math.nan
            rows.append(dict(engine="mujoco", setting=f"RK4 dt {dt:g}", time_s=el, error=e, method="RK4"))
            log(f"    mujoco RK4 dt {dt:g}: {el * 1e3:.2f} ms, error {e:.2e}")
    if pe.exu is not None:
        for solver in pe.SOLVERS:
            for div in divs:
                dt = OUT_DT / div
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    el, t, x = pe.run_exudyn(case["exudyn"], case["T"], dt, OUT_DT, solver, 1 if quick else 3)
                ok = t is not None and np.all(np.isfinite(x))
                e = error(t, x, case["exact"]) if ok else math.nan
                rows.append(dict(engine="exudyn", setting=f"{solver} dt {dt:g}", time_s=el, error=e, method=solver))
                log(f"    exudyn {solver} dt {dt:g}: {el * 1e3:.2f} ms, error {e:.2e}"
                    + ("" if t is not None else f" ({x})"))
                if t is None and math.isnan(el):
                    break   # the solver refuses the model: no use trying smaller steps
    return rows


def _time_at(pts, target):
    """run.time_at, with an extrapolation along a nearly flat front (a soft constraint's floor) as n/a."""
    try:
        t, how = time_at(pts, target)
    except OverflowError:
        return None, "n/a"
    return (None, "n/a") if how == "extrap" and t > 1e3 else (t, how)


ENGINES = ("mbdsim", "mujoco", "exudyn")


def summary(rows):
    out = {}
    for eng in ENGINES:
        pts = [(r["time_s"], r["error"]) for r in rows if r["engine"] == eng and math.isfinite(r["time_s"])]
        f = front(pts)
        out[eng] = dict(best_error=min((e for _, e in f), default=math.nan),
                        at={f"{tg:g}": _time_at(pts, tg) for tg in TARGETS})
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    lines, results = [], {}
    log = lambda s: (print(s, flush=True), lines.append(s))  # noqa: E731
    for name, case in CASES.items():
        log(f"== {name}")
        rows = sweep(case, args.quick, log)
        results[name] = dict(rows=rows, summary=summary(rows))
    md = ["# Issue 29's models against MuJoCo and Exudyn (time at equal accuracy, one run)", "",
          "Written by `python3 bench/peers_vocabulary.py`" + (" --quick" if args.quick else "") +
          f" (MuJoCo {getattr(mujoco, '__version__', 'absent')}, Exudyn {pe.EXUDYN}). Error: max over 0.01 s "
          "outputs of the difference to the closed form, relative to the motion's amplitude. Ratio: mbdsim "
          "time / peer time to reach the same error (`<=`: the cheapest run is already more accurate, `~*`: "
          "extrapolated); `n/a`: not reached (see the best error). Exudyn's front is over both of its "
          "solvers (GeneralizedAlpha with spectral radius 1, RK44; fixed steps; RK44 refuses the gear "
          "train's node-to-node coordinate constraints). Exudyn's friction: regularised for |v| < "
          f"{pe.FRICTION_VREG:g} m/s (floor ~4e-9, as v_reg^2); its adaptive step reduction at the stop "
          "moves the later samples off the 0.01 s grid, where they are compared with the closed form.", "",
          "| model | target error | mbdsim | MuJoCo | Exudyn | mbdsim / MuJoCo | mbdsim / Exudyn | "
          "best error mbdsim / MuJoCo / Exudyn | mbdsim method (rtol 1e-6) |",
          "|---|---|---|---|---|---|---|---|---|"]
    for name, r in results.items():
        s = r["summary"]
        meth = next((x["method"] for x in r["rows"] if x["engine"] == "mbdsim" and x["setting"] == "rtol 1e-06"), "?")
        for tg in TARGETS:
            (tm, hm), (tj, hj), (tx, hx) = (s[e]["at"][f"{tg:g}"] for e in ENGINES)
            ratio = lambda a, b: f"{a / b:.3g}x" if a and b else "n/a"  # noqa: E731
            best = " / ".join(f"{s[e]['best_error']:.1e}" for e in ENGINES)
            md.append(f"| {name} | {tg:g} | {fmt_t(tm, hm)} | {fmt_t(tj, hj)} | {fmt_t(tx, hx)} | "
                      f"{ratio(tm, tj)} | {ratio(tm, tx)} | {best} | {meth} |")
    table = md[2:]
    md += ["", "## Sweeps", "", "```", *lines, "```", ""]
    with open(os.path.join(HERE, "PEERS_VOCABULARY.md"), "w") as fh:
        fh.write("\n".join(md))
    replace_section(os.path.join(HERE, "RESULTS.md"), "\n".join(
        ["## Issue 29's models against MuJoCo and Exudyn", ""] + table + ["", "Sweeps: bench/PEERS_VOCABULARY.md."]))
    with open(os.path.join(HERE, "peers_vocabulary.json"), "w") as fh:
        json.dump(results, fh, indent=1, default=str)


if __name__ == "__main__":
    main()
