"""Start-up times (issue 32): a new user's first commands, and every later process against MuJoCo's.

    python3 bench/startup.py                 # all of it (a cold compile: minutes on 2 cores)
    python3 bench/startup.py --warm-only     # only the warm-cache measurements (a minute)
    python3 bench/startup.py --cases 1-3     # the cold `mbdsim validate` on these cases only

Cold (a fresh virtual environment, an empty HOME and an empty compiled-kernel cache):
1. the README's first command, `python3 -m pip install -e . && mbdsim validate` (its report written): the
   install, the time to the first case's line and to the end (the package's compiled kernels unpacked into
   the empty cache: mbdsim._kernelpack; MBDSIM_NO_PACK=1 in the environment measures a full compile instead) (with --cases, those cases only: say so when quoting it);
   the virtual environment sees this machine's packages (--system-site-packages: "the registries' wheels
   already downloaded") and the install is `pip install -e . --no-deps` (pip fetches its build tools);
2. the README's first Python example in a fresh process on the then warm cache, and on an empty one.

Warm (this environment, the cache filled by a first run; best of 5 fresh processes each):
3. the first simulate of the README pendulum in a fresh process (import, model, 2 s of simulation with
   0.01 s outputs), the whole process timed, against MuJoCo's fresh process (import, MJCF load of the same
   pendulum, 2,000 RK4 steps of 1 ms); 4. `mbdsim --help`.

Prints a Markdown table (paste it into bench/RESULTS.md) and writes bench/startup.json.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import venv

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

README_EXAMPLE = """
import mbdsim as mb

model = mb.Model("pendulum", gravity=(0.0, -9.81, 0.0))
rod = model.add_body("rod", mass=2.0, inertia=(2.0 / 12, 0.0, 2.0 / 12), position=(0.5, 0, 0))
tip = rod.add_marker("tip", point=(1.0, 0, 0))
pin = model.add_revolute("pin", model.ground, rod, point=(0, 0, 0), axis=(0, 0, 1))

res = mb.simulate(model, end_time=2.0, output_step=0.01)          # compiled O(N) core, 8th order
t_low, angle = res.minimum(lambda r: r.joint_coordinate(pin))     # refined on the dense output
F = res.reaction_force(pin)                                       # (N, 3) [N] on the rod, ground axes
v_tip = res.velocity(tip, frame=rod)                              # expressed in the rod's axes
print(res.to_dataframe().head())
"""

FIRST_SIMULATE = """
import mbdsim as mb
model = mb.Model("pendulum", gravity=(0.0, -9.81, 0.0))
rod = model.add_body("rod", mass=2.0, inertia=(2.0 / 12, 0.0, 2.0 / 12), position=(0.5, 0, 0))
pin = model.add_revolute("pin", model.ground, rod, point=(0, 0, 0), axis=(0, 0, 1))
res = mb.simulate(model, end_time=2.0, output_step=0.01)
assert res.success
"""

# the same pendulum in MuJoCo: a 1 m rod of 2 kg about a z hinge at the origin, CM at x = 0.5
MUJOCO = """
import mujoco
XML = '''<mujoco><option gravity="0 -9.81 0" timestep="0.001" integrator="RK4"/>
<worldbody><body pos="0 0 0"><joint type="hinge" axis="0 0 1"/>
<inertial pos="0.5 0 0" mass="2" diaginertia="0.0001 0.16667 0.16667"/></body></worldbody></mujoco>'''
m = mujoco.MjModel.from_xml_string(XML)
d = mujoco.MjData(m)
for _ in range(2000):
    mujoco.mj_step(m, d)
"""


def _timed(cmd, env=None, cwd=None, first_line=None, timeout=3600):
    """Run cmd; (wall time [s], seconds to the first stderr/stdout line containing first_line, rc, output)."""
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, env=env, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    t_first, lines = None, []
    for line in p.stdout:
        lines.append(line)
        if t_first is None and first_line is not None and first_line in line:
            t_first = time.perf_counter() - t0
    p.wait(timeout=timeout)
    return time.perf_counter() - t0, t_first, p.returncode, "".join(lines)


def _best(cmd, env=None, n=5):
    return min(_timed(cmd, env=env)[0] for _ in range(n))


def _best_cpu(cmd, env=None, n=5):
    """Least CPU time (user + system, [s]) of the child over n runs: fair on a loaded machine."""
    import resource
    out = []
    for _ in range(n):
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        _timed(cmd, env=env)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        out.append(r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime)
    return min(out)


def cold(cases, log):
    """Steps 1-2 in a fresh virtual environment with an empty HOME and cache."""
    tmp = tempfile.mkdtemp(prefix="mbdsim-startup-")
    try:
        home, env_dir = os.path.join(tmp, "home"), os.path.join(tmp, "venv")
        os.makedirs(home)
        venv.create(env_dir, system_site_packages=True, with_pip=False)
        py = os.path.join(env_dir, "bin", "python")
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "NUMBA_CACHE_DIR", "XDG_CACHE_HOME")}
        env.update(HOME=home, PATH=os.path.join(env_dir, "bin") + os.pathsep + env.get("PATH", ""))
        install, _, rc, out = _timed([py, "-m", "pip", "install", "-q", "-e", ".", "--no-deps"], env=env, cwd=ROOT)
        assert rc == 0, out[-3000:]
        log(f"install (pip install -e . --no-deps): {install:.1f} s")
        cmd = [os.path.join(env_dir, "bin", "mbdsim"), "validate"] + (["--case", cases] if cases else [])
        total, first, rc, out = _timed(cmd, env=env, cwd=tmp, first_line="case ")
        first_case = next((ln for ln in out.splitlines() if ln.strip().startswith("case ")), "")
        log(f"mbdsim validate{' --case ' + cases if cases else ''}: first case line after {first} s, "
            f"done in {total:.1f} s (exit {rc})\n  {first_case.strip()}")
        notes = [ln for ln in out.splitlines() if ln.startswith("mbdsim: compiling")]
        example_warm = _timed([py, "-c", README_EXAMPLE], env=env, cwd=tmp)
        shutil.rmtree(os.path.join(home, ".cache"), ignore_errors=True)   # an empty cache again
        example_cold = _timed([py, "-c", README_EXAMPLE], env=env, cwd=tmp)
        log(f"README example: {example_cold[0]:.1f} s on an empty cache, {example_warm[0]:.2f} s after validate")
        return {"install_s": install, "validate_first_case_s": first, "validate_s": total, "validate_rc": rc,
                "validate_cases": cases or "all", "compile_note": notes[:1],
                "readme_example_cold_s": example_cold[0], "readme_example_after_validate_s": example_warm[0]}
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def warm(log):
    """Steps 3-4 in this environment (this checkout's src first), the cache filled first."""
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "src") + os.pathsep + os.environ.get("PYTHONPATH", ""))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    _timed([sys.executable, "-c", FIRST_SIMULATE], env=env)            # fills the cache and the bytecode
    out = {"mbdsim_first_simulate_s": _best([sys.executable, "-c", FIRST_SIMULATE], env=env),
           "python_s": _best([sys.executable, "-c", "pass"], env=env),
           "help_s": _best([sys.executable, "-m", "mbdsim", "--help"], env=env)}
    try:
        import mujoco  # noqa: F401
        _timed([sys.executable, "-c", MUJOCO], env=env)
        out["mujoco_s"] = _best([sys.executable, "-c", MUJOCO], env=env)
        out["ratio"] = out["mbdsim_first_simulate_s"] / out["mujoco_s"]
        out["mbdsim_first_simulate_cpu_s"] = _best_cpu([sys.executable, "-c", FIRST_SIMULATE], env=env)
        out["mujoco_cpu_s"] = _best_cpu([sys.executable, "-c", MUJOCO], env=env)
        out["ratio_cpu"] = out["mbdsim_first_simulate_cpu_s"] / out["mujoco_cpu_s"]
    except ImportError:
        out["mujoco_s"] = None
    log(f"fresh process, cache warm: mbdsim import + pendulum + simulate {out['mbdsim_first_simulate_s']:.2f} s, "
        f"MuJoCo import + load + 2000 steps {out['mujoco_s'] or float('nan'):.2f} s "
        f"(ratio {out.get('ratio', float('nan')):.2f}; CPU time {out.get('mbdsim_first_simulate_cpu_s', float('nan')):.2f} s "
        f"against {out.get('mujoco_cpu_s', float('nan')):.2f} s, ratio {out.get('ratio_cpu', float('nan')):.2f}); python -c pass {out['python_s']:.3f} s; "
        f"mbdsim --help {out['help_s']:.3f} s")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--warm-only", action="store_true", help="skip the fresh-environment (cold) measurements")
    ap.add_argument("--cases", default=None, help="cold `mbdsim validate` on these cases only (e.g. 1-3)")
    ap.add_argument("--out", default=os.path.join(HERE, "startup.json"))
    args = ap.parse_args()
    results = {"machine": {"cpus": os.cpu_count(), "load": os.getloadavg()}}
    log = lambda s: print(s, flush=True)   # noqa: E731
    results["warm"] = warm(log)
    if not args.warm_only:
        results["cold"] = cold(args.cases, log)
    with open(args.out, "w") as f:
        json.dump(results, f, indent=1)
    print(f"written {args.out}")


if __name__ == "__main__":
    main()
