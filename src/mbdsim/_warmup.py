"""Compile (or load) the kernels most analyses use, ahead of the first real run: `mbdsim cache warm` and the
test suite's controller process (tests/conftest.py) use it, so that the cache is filled once, by two
processes compiling different kernels side by side, instead of by every worker.

PARTS: "dynamics" (the compiled step loop on a joint-coordinate tree and on a closed loop, with the output
kernels: dense output, reactions, `Result.at`), "kinematics" (the kinematic sweep, assembly, statics and
the Python path's kernels: HHT) and "stepping" (the compiled Radau IIA and the Simulator's step loop). `python -m mbdsim._warmup PART...` runs the parts in this process; `warm()`
runs each part in its own process, in parallel, and returns their wall times [s].
"""
from __future__ import annotations

import math
import os
import subprocess
import sys
import time
import warnings

PARTS = ("dynamics", "kinematics", "stepping")


def _pendulum():
    import mbdsim as mb
    model = mb.Model("pendulum", gravity=(0.0, -9.81, 0.0))
    rod = model.add_body("rod", mass=2.0, inertia=(2.0 / 12, 0.0, 2.0 / 12), position=(0.5, 0, 0))
    tip = rod.add_marker("tip", point=(1.0, 0, 0))
    pin = model.add_revolute("pin", model.ground, rod, point=(0, 0, 0), axis=(0, 0, 1))
    return model, rod, tip, pin


def _four_bar(driven: bool):
    """A planar crank-rocker (links along their body x axes), free or with the crank driven."""
    import mbdsim as mb
    from scipy.spatial.transform import Rotation
    z = lambda a: Rotation.from_rotvec((0.0, 0.0, a))   # noqa: E731
    model = mb.Model("four_bar", gravity=(0, -9.81, 0), planar=True)
    crank = model.add_body("crank", 0.5, inertia=(1e-4, 5e-4, 5e-4), position=(0.0, 0.05, 0.0), orientation=z(math.pi / 2))
    coupler = model.add_body("coupler", 1.0, inertia=(1e-4, 0.015, 0.015), position=(0.15, 0.25, 0.0),
                             orientation=z(math.pi / 4))
    rocker = model.add_body("rocker", 0.8, inertia=(1e-4, 0.0113, 0.0113), position=(0.35, 0.2, 0.0),
                            orientation=z(math.atan2(-0.4, 0.1)))
    model.add_revolute("O2", model.ground, crank, point=(0, 0, 0), axis=(0, 0, 1))
    model.add_revolute("A", crank, coupler, point=(0, 0.1, 0), axis=(0, 0, 1))
    model.add_revolute("B", coupler, rocker, point=(0.3, 0.4, 0), axis=(0, 0, 1))
    model.add_revolute("O4", rocker, model.ground, point=(0.4, 0, 0), axis=(0, 0, 1))
    if driven:
        model.add_motion("drive", "O2", displacement="2*pi*t")
    return model


def dynamics() -> None:
    """The README's first example (tree, compiled DOP853 and its outputs), then a closed loop."""
    import mbdsim as mb
    model, rod, tip, pin = _pendulum()
    res = mb.simulate(model, end_time=0.2, output_step=0.01)
    res.minimum(lambda r: r.joint_coordinate(pin))
    res.reaction_force(pin)
    res.velocity(tip, frame=rod)
    res.to_dataframe()
    res.at(0.105)
    res = mb.simulate(_four_bar(False), end_time=0.1, output_step=0.01)
    res.reaction_force("A")


def kinematics() -> None:
    """Kinematics of a driven four-bar, assembly, equilibrium and the implicit (Python-path) HHT."""
    import mbdsim as mb
    res = mb.kinematics(_four_bar(True), end_time=0.1, output_step=0.01)
    res.reaction_force("A")
    model = _pendulum()[0]
    mb.assemble(model)
    mb.simulate(model, end_time=0.05, output_step=0.01, method="hht")
    mb.equilibrium(model)


def stepping() -> None:
    """The compiled Radau IIA (method "radau", the stiff hand-over's stepper) and the Simulator's step loop."""
    import mbdsim as mb
    model = _pendulum()[0]
    mb.simulate(model, end_time=0.05, output_step=0.01, method="radau")
    sim = mb.Simulator(model)
    sim.step(0.01)
    sim.outputs()


def run_parts(names) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name in names:
            {"dynamics": dynamics, "kinematics": kinematics, "stepping": stepping}[name]()


def warm(parts=PARTS, quiet: bool = True) -> dict:
    """Run each part in its own Python process, all at once; {part: (wall time [s], exit status)} (a
    failing part is left to the analyses that need those kernels, which report it).
    `quiet` silences the compile note (mbdsim._compilenote) of those processes."""
    env = dict(os.environ)
    src = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))   # this mbdsim, wherever it is
    env["PYTHONPATH"] = os.pathsep.join([src] + [p for p in [env.get("PYTHONPATH")] if p])
    if quiet:
        env["MBDSIM_QUIET_COMPILE"] = "1"
    t0 = time.perf_counter()
    procs = {p: subprocess.Popen([sys.executable, "-m", "mbdsim._warmup", p], env=env,
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for p in parts}
    out = {}
    while len(out) < len(procs):   # each part's own wall time
        for p, proc in procs.items():
            if p not in out and proc.poll() is not None:
                out[p] = (time.perf_counter() - t0, proc.returncode)
        time.sleep(0.05)
    return out


if __name__ == "__main__":
    run_parts(sys.argv[1:] or PARTS)
