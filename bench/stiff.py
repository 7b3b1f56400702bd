"""Issue 8 stiff-model benchmark: the default method against method='hht' (and scipy's 'radau', 'bdf').

Three stiff models, every method at its default tolerances and default output step (span / 500), all
methods timed in the same process, interleaved, best of REPEATS runs each (this machine is shared).
Error: max over the outputs of |r_cm - r_cm_ref| [m], divided by the model's length scale, against
  * the exact solution of the linear ODE (overdamped 1e9 N/m spring),
  * a tight reference run: method='dop853', rtol 1e-11, atol 1e-13 (bushing pendulum, bouncing ball).
The first run of each method is a warm-up (kernel loading), not timed; runs over SLOW seconds are
timed once.
Writes bench/STIFF_RESULTS.md. Usage: PYTHONPATH=src python3 bench/stiff.py [repeats]
"""
from __future__ import annotations

import os
import platform
import sys
import time
import warnings

import numpy as np

import mbdsim as mb

G = 9.81
METHODS = (None, "hht", "radau", "bdf")
REPEATS = int(sys.argv[1]) if len(sys.argv) > 1 else 3
SLOW = 5.0   # [s]: runs slower than this are timed once (their noise is small against their length)
HERE = os.path.dirname(os.path.abspath(__file__))


def spring_1e9():
    """1 kg on a slider, spring 1e9 N/m with 1e5 N s/m (eigenvalues -1.01e4 and -9.9e4 1/s) at its free
    length under gravity -x: settles at -m g / k; 0.5 s."""
    m = mb.Model("spring 1e9", gravity=(-G, 0, 0))
    p = m.add_particle("p", 1.0, position=(1.0, 0, 0))
    m.add_translational("slide", m.ground, p, (1.0, 0, 0), (1, 0, 0))
    m.add_spring_damper("k", m.ground, p, 1e9, 1e5, 1.0)
    k, c = 1e9, 1e5

    def exact(t):
        r1, r2 = (-c + np.sqrt(c * c - 4 * k)) / 2, (-c - np.sqrt(c * c - 4 * k)) / 2
        u0 = G / k   # starts u0 above the equilibrium 1 - g / k
        a = -r2 * u0 / (r1 - r2)
        x = 1.0 - G / k + a * np.exp(r1 * t) + (u0 - a) * np.exp(r2 * t)
        return np.stack([x, 0 * t, 0 * t], -1)[:, None, :]
    return m, ["p"], 0.5, G / 1e9, exact


def bushing_pendulum(c=1e3):
    """A 1 m, 2 kg rod pendulum hung on a 1e8 N/m bushing instead of a hinge (translational damping c
    [N s/m]: 1e3 rings lightly (damping ratio 0.035), 2e4 is well damped (0.71); rotations about x and y
    1e5 N m/rad, free about z), released horizontal; 0.2 s."""
    m = mb.Model(f"bushing pendulum, c = {c:g} N s/m", gravity=(0, -G, 0))
    rod = m.add_body("rod", 2.0, (2e-4, 2.0 / 12, 2.0 / 12), position=(0.5, 0, 0))
    m.add_bushing("pivot", (m.ground, (0, 0, 0)), (rod, (0, 0, 0)), stiffness=(1e8, 1e8, 1e8, 1e5, 1e5, 0.0),
                  damping=(c, c, c, 10.0, 10.0, 0.0))
    return m, ["rod"], 0.2, 1.0, None


def bushing_pendulum_damped():
    return bushing_pendulum(2e4)


def bouncing_ball():
    """A 1 kg, 5 cm ball dropped 0.1 m onto a plane: Adams IMPACT contact 1e7 N/m^1.5, 100 N s/m at
    1e-4 m penetration; 0.6 s (several bounces, then resting)."""
    R = 0.05
    m = mb.Model("bouncing ball", gravity=(0, 0, -G))
    ball = m.add_body("ball", 1.0, (0.4 * R * R,) * 3, position=(0, 0, R + 0.1))
    m.add_contact("floor", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), mb.Sphere(ball, R), 1e7, 1.5, 100.0, 1e-4)
    return m, ["ball"], 0.6, 0.1, None


def positions(res, names):
    return np.stack([res.position(n) for n in names], 1)


def run(build, method, **kw):
    model, names, T, _, _ = build()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.perf_counter()
        res = mb.simulate(model, T, method=method, **kw)
        el = time.perf_counter() - t0
    return el, res, names


def main():
    rows = []
    for build in (spring_1e9, bushing_pendulum, bushing_pendulum_damped, bouncing_ball):
        model, names, T, scale, exact = build()
        if exact is None:
            _, ref, _ = run(build, "dop853", rtol=1e-11, atol=1e-13)
            assert ref.success, ref.message
            r_ref = positions(ref, names)
        best, results = {}, {}
        for method in METHODS:   # warm-up (numba loads or compiles the kernels on first use), then timed
            run(build, method)
            best[method], results[method], _ = run(build, method)
        for _ in range(REPEATS - 1):
            for method in METHODS:   # interleaved: load changes hit every method alike
                if best[method] < SLOW:
                    best[method] = min(best[method], run(build, method)[0])
        for method in METHODS:
            res = results[method]
            r = positions(res, names)
            r_ref_m = exact(res.time) if exact is not None else r_ref
            err = float(np.max(np.linalg.norm(r - r_ref_m, axis=-1))) / scale if res.success else np.inf
            rows.append((model.name, method or "default", best[method], best[method] / best["hht"], err,
                         res.stats.get("steps"), res.stats.get("method")))
            print(rows[-1], flush=True)
    write(rows)


def write(rows):
    lines = ["# Stiff models: default method against HHT, Radau and BDF (bench/stiff.py)", "",
             f"Machine: {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, Python "
             f"{platform.python_version()}; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}. "
             f"Wall time: best of {REPEATS} interleaved runs per method (one for runs over {SLOW:g} s) in one process (shared machine: compare "
             "within a model only). Default tolerances and output step (span / 500) for every method. "
             "Error: max over the outputs of |r_cm - r_ref| / length scale; reference: the exact solution "
             "(spring) or method='dop853' at rtol 1e-11 (the others). Length scales: the spring's static "
             "deflection g / k = 9.8e-9 m, the rod length 1 m, the drop height 0.1 m.", "",
             "| model | method | wall [s] | time / HHT | error | steps | method used |",
             "|---|---|---:|---:|---:|---:|---|"]
    for name, method, el, ratio, err, steps, used in rows:
        lines.append(f"| {name} | {method} | {el:.3f} | {ratio:.2f} | {err:.2e} | {steps} | {used} |")
    path = os.path.join(HERE, "STIFF_RESULTS.md")
    keep = ""   # the stiff chain's section (bench/stiff_chain.py) is kept
    if os.path.exists(path):
        old = open(path).read()
        if "<!-- stiff chain" in old:
            keep = "\n" + old[old.index("<!-- stiff chain"):]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n" + keep)


if __name__ == "__main__":
    main()
