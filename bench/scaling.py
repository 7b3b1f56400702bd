"""Cost against model size (planar chains N = 2..512) and start-up times, measured in this run."""
from __future__ import annotations

import os
import subprocess
import sys
import time
import warnings

import engines as E
from problems import PlanarChain

SIZES = (2, 8, 32, 128, 512)
RTOL = 1e-6            # mbdsim's default method, only rtol given
MUJOCO_DT = 1e-3       # MuJoCo RK4, fixed step, for comparison


def _best(f, reps):
    out = [f() for _ in range(reps)]
    return min(out, key=lambda x: x[0])


def scaling_table(quick, log):
    """Wall time per simulated second of the N-rod chain (1 s, output every 0.01 s)."""
    log("\nscaling: planar chain of N rods, 1 s simulated, mbdsim default method rtol 1e-6; MuJoCo RK4 dt 1e-3")
    rows = []
    for n in (SIZES[:-1] if quick else SIZES):
        p = PlanarChain(n)
        reps = 3   # best of 3 at every size: the N = 512 / N = 2 ratio is as noisy as either of its terms
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            E.run_mbdsim(p, "auto", RTOL)   # untimed: the model's first call assembles and compiles it, as
            # for every problem of run.py (the chains up to 128 ran there already, N = 512 did not)
            t_mb, _, info = _best(lambda: E.run_mbdsim(p, "auto", RTOL), reps)
            t_mj, why = None, None
            if E.mujoco:
                try:
                    t_mj = _best(lambda: E.run_mujoco(p, MUJOCO_DT), reps)[0]
                except ValueError as exc:   # MuJoCo's XML parser refuses bodies nested this deep
                    why = str(exc).splitlines()[-1][:120]
        rows.append({"n": n, "mbdsim_s": t_mb, "mbdsim_steps": info.get("steps"), "mujoco_s": t_mj,
                     "mujoco_note": why})
    base = rows[0]["mbdsim_s"]
    for r in rows:
        r["mbdsim_ratio_to_n2"] = r["mbdsim_s"] / base
        log(f"  N={r['n']:4d}  mbdsim {r['mbdsim_s']:8.4f} s ({r['mbdsim_ratio_to_n2']:7.1f}x N=2, "
            f"{r['mbdsim_steps']} steps)  mujoco {r['mujoco_s'] if r['mujoco_s'] is None else round(r['mujoco_s'], 4)} s")
    return rows


_FIRST = """
import time
t0 = time.perf_counter()
import mbdsim as mb
t1 = time.perf_counter()
m = mb.Model("p", gravity=(0, -9.81, 0))
b = m.add_body("b", 1.0, inertia=(1e-3, 1 / 12, 1 / 12), position=(0.5, 0, 0))
m.add_revolute("j", m.ground, b, (0, 0, 0), (0, 0, 1))
mb.simulate(m, 1.0)
print(t1 - t0, time.perf_counter() - t1)
"""


def startup(log):
    """`import mbdsim` and the first simulate of a new model in a fresh process (numba cache warm), best of 5;
    `mbdsim validate` (all 30 cases) wall time.  The processes may write Python's bytecode cache (a
    PYTHONDONTWRITEBYTECODE of this environment is dropped for them) and a first run writes it, as the
    first import after any install does: the timed runs then read it, as a user's fresh process does."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    subprocess.run([sys.executable, "-c", _FIRST], capture_output=True, text=True, check=True, env=env)
    runs = []
    for _ in range(5):
        out = subprocess.run([sys.executable, "-c", _FIRST], capture_output=True, text=True, check=True, env=env)
        runs.append(tuple(float(x) for x in out.stdout.split()))
    imp, first = min(r[0] for r in runs), min(r[1] for r in runs)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "mbdsim", "validate", "--no-report"], capture_output=True, check=False)
    val = time.perf_counter() - t0
    log(f"\nstart-up: import mbdsim {imp:.3f} s, first simulate in a fresh process {first:.3f} s, "
        f"mbdsim validate (30 cases) {val:.1f} s")
    return {"import_s": imp, "first_simulate_s": first, "validate_s": val}
