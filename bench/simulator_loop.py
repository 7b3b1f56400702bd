"""A PD loop sampled at 1 kHz, written in Python around a pendulum: mbdsim.Simulator against MuJoCo's
mj_step loop on the same pendulum, measured side by side in the same run (issue 33).

    python3 bench/simulator_loop.py            # prints the markdown section of bench/RESULTS.md

Both loops read the angle and rate, compute the torque in Python and advance 1 ms, 1,000 times; times
are the best of REPEATS runs of the whole loop (models built and compiled outside it). MuJoCo steps its
semi-implicit Euler once per ms (its own accuracy); mbdsim runs its error-controlled DOP853 over each ms
at the Simulator's default tolerance (and at rtol = 1e-10) with the torque held over the step.
"""
from __future__ import annotations

import time

import numpy as np

STEPS, DT, REPEATS = 1000, 1e-3, 7
M, L, IZZ, G = 1.0, 0.5, 0.02, 9.81
KP, KD, REF = 40.0, 4.0, 0.8


def _mbdsim_loop(rtol):
    import mbdsim as mb
    m = mb.Model("pendulum", gravity=(0, -G, 0))
    m.add_input("u")
    m.add_body("rod", mass=M, inertia=(0.01, IZZ, IZZ), position=(L, 0, 0))
    m.add_revolute("pin", "ground", "rod", (0, 0, 0), (0, 0, 1))
    m.add_joint_force("motor", "pin", "u")
    m.add_output("theta", "pin")
    m.add_output("omega", "pin_dot")
    sim = mb.Simulator(m, rtol=rtol)
    sim.step(DT)   # kernels loaded before timing
    start = sim.state()

    def loop():
        sim.restore(start)
        for _ in range(STEPS):
            sim.set_input("u", -KP * (sim.output("theta") - REF) - KD * sim.output("omega"))
            sim.step(DT)
        return sim.output("theta")
    return loop


def _mujoco_loop():
    import mujoco
    xml = f"""<mujoco><option timestep="{DT}" gravity="0 -{G} 0"/><worldbody><body>
      <joint name="pin" type="hinge" axis="0 0 1"/>
      <inertial pos="{L} 0 0" mass="{M}" diaginertia="0.01 {IZZ} {IZZ}"/></body></worldbody>
      <actuator><motor joint="pin" gear="1"/></actuator></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)

    def loop():
        mujoco.mj_resetData(model, data)
        for _ in range(STEPS):
            data.ctrl[0] = -KP * (data.qpos[0] - REF) - KD * data.qvel[0]
            mujoco.mj_step(model, data)
        return float(data.qpos[0])
    return loop


def _best(fn):
    fn()
    best = np.inf
    for _ in range(REPEATS):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def main():
    loops = {"MuJoCo mj_step": _mujoco_loop(), "mbdsim Simulator (default rtol)": _mbdsim_loop(None),
             "mbdsim Simulator (rtol 1e-10)": _mbdsim_loop(1e-10)}
    times = {k: _best(f) for k, f in loops.items()}
    finals = {k: f() for k, f in loops.items()}
    ref = times["MuJoCo mj_step"]
    print(f"## Step loop: {STEPS} steps of {DT * 1e3:g} ms with a Python PD controller (bench/simulator_loop.py)\n")
    print("| loop | total | per step | / MuJoCo | final angle [rad] |")
    print("|---|---:|---:|---:|---:|")
    for k, t in times.items():
        print(f"| {k} | {t * 1e3:.2f} ms | {t / STEPS * 1e6:.1f} us | {t / ref:.1f}x | {finals[k]:.6f} |")


if __name__ == "__main__":
    main()
