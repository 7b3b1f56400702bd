"""Speed of loads written as expressions against the same model with the equivalent built-in elements.

Run: ``PYTHONPATH=src python3 bench/expression_loads.py`` (writes bench/EXPRESSION_LOADS.md).
Not a timed unit test: the machine's load changes the numbers; the ratio is what matters.

Models (compiled DOP853, rtol 1e-8, both variants on the same path):
- ``spring chain``: 6 free bodies hung from ground in a chain of 6 translational spring-dampers
  (absolute-coordinate compiled core) against 6 line forces "k*(DM(i, j) - L0) + c*VR(i, j)".
- ``damped pendulum chain``: 5 links, revolute joints (joint-coordinate path), each joint damped by a
  rotational bushing (c on the joint axis) against 5 joint forces "-c*<joint>_dot".
Each run is timed as the best of `REPEAT` after a warm-up run (compilation excluded); the results of
the two variants are compared (max difference of positions) to show they are the same model.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

import mbdsim as mb

REPEAT, END, STEP, RTOL = 15, 5.0, 0.01, 1e-8
K, C, L0, N_SPRING, N_LINK, C_JOINT = 200.0, 0.8, 0.25, 6, 5, 0.05


def spring_chain(expr: bool):
    m = mb.Model("spring chain", gravity=(0, 0, -9.81))
    prev = m.ground.add_marker("top", (0, 0, 0))
    for k in range(N_SPRING):
        b = m.add_body(f"b{k}", mass=0.5, inertia=(1e-3, 2e-3, 3e-3), position=(0.05 * k, 0.0, -0.3 * (k + 1)),
                       velocity=(0.0, 0.2 * (k % 2), 0.0))
        up = b.add_marker("up", (0.05 * k, 0.01, -0.3 * (k + 1) + 0.02))
        dn = b.add_marker("dn", (0.05 * k, -0.01, -0.3 * (k + 1) - 0.02))
        if expr:
            i, j = f"{b.name}.up", f"{prev.body.name}.{prev.name}"
            m.add_line_force(f"s{k}", up, prev, f"{K}*(DM({i}, {j}) - {L0}) + {C}*VR({i}, {j})")
        else:
            m.add_spring_damper(f"s{k}", up, prev, K, C, L0)
        prev = dn
    return m


def pendulum_chain(expr: bool):
    m = mb.Model("damped pendulum chain", gravity=(0, -9.81, 0))
    prev = m.ground
    for k in range(N_LINK):
        b = m.add_body(f"l{k}", mass=1.0, inertia=(1e-3, 0.02, 0.02), position=(0.25 + 0.5 * k, 0, 0))
        m.add_revolute(f"j{k}", prev, b, (0.5 * k, 0, 0), (0, 0, 1))
        if expr:
            m.add_joint_force(f"d{k}", f"j{k}", f"-{C_JOINT}*j{k}_dot")
        else:
            mi = prev.add_marker(f"d{k}i", (0.5 * k, 0, 0))
            mj = b.add_marker(f"d{k}j", (0.5 * k, 0, 0))
            m.add_bushing(f"d{k}", mi, mj, damping=(0, 0, 0, 0, 0, C_JOINT))
        prev = b
    return m


def timed(build, expr):
    model = build(expr)
    res = mb.simulate(model, END, output_step=STEP, rtol=RTOL)   # warm-up (compilation)
    best = np.inf
    for _ in range(REPEAT):
        t0 = time.perf_counter()
        res = mb.simulate(model, END, output_step=STEP, rtol=RTOL)
        best = min(best, time.perf_counter() - t0)
    return best, res


def main(out=Path(__file__).with_name("EXPRESSION_LOADS.md")):
    rows = []
    for build in (spring_chain, pendulum_chain):
        (tb, rb), (te, re) = timed(build, False), timed(build, True)
        bodies = [n for n in rb.system.model.bodies if n != "ground"]
        diff = max(np.abs(re.position(b) - rb.position(b)).max() for b in bodies)
        rows.append((build(False).name, tb, te, te / tb, rb.stats["method"], re.stats["method"],
                     re.stats.get("formulation", "absolute coordinates"), rb.stats.get("steps"),
                     re.stats.get("steps"), diff))
    lines = ["# Expression loads against built-in elements", "",
             f"`bench/expression_loads.py`: {END} s simulated, output every {STEP} s, rtol {RTOL}, best of "
             f"{REPEAT} runs after a warm-up (compilation excluded). Python {sys.version.split()[0]}.", "",
             "| model | built-in [ms] | expressions [ms] | ratio | path | steps (built-in / expr) | max position difference [m] |",
             "|---|---|---|---|---|---|---|"]
    for name, tb, te, ratio, mb_, me, form, sb, se, diff in rows:
        lines.append(f"| {name} | {1e3 * tb:.1f} | {1e3 * te:.1f} | {ratio:.2f} | {me}, {form} | {sb} / {se} | {diff:.1e} |")
    text = "\n".join(lines) + "\n"
    out.write_text(text)
    print(text)
    return rows


if __name__ == "__main__":
    main()
