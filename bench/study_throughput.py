"""Study throughput: slider-crank variants per minute (2 s simulated, rtol 1e-6) -- not a test.

    python bench/study_throughput.py [--n 32] [--workers 2] [--exudyn] [--repeat 3]

Each variant: the slider-crank of mbdsim.studies.models.slider_crank with its crank and rod lengths,
masses and drive speed from a Latin hypercube, dynamics over 2 s (output every 10 ms, rtol 1e-6), and
two outputs: the peak rod force at the crank pin and the slider's peak acceleration.  Rows:
  python loop       a plain Python loop: build, mb.simulate, measure (the user's baseline)
  study, serial     mb.Study.run(workers=0): the same in this process through the study machinery
  study, dask N     mb.Study.run on a LocalCluster of N processes, cluster start-up included
  study, warm dask  the same on an already started cluster (imports and kernels loaded)
  exudyn loop       (--exudyn) a Python loop over Exudyn's 2D slider-crank (generalized-alpha, 2 ms
                    steps), peak force and acceleration from its sensors
Every timed row is the fastest of --repeat runs (the machine is shared; the same for every row).
Prints a table and writes bench/STUDY_RESULTS.md.
"""
from __future__ import annotations

import argparse
import math
import os
import platform
import time
import warnings
from pathlib import Path

import numpy as np

import mbdsim as mb
from mbdsim.studies.models import slider_crank

OUTPUTS = {"peak_rod_force": "max(norm(reaction_force('crank_rod')))",
           "slider_peak_acceleration": "peak(x(acceleration('slider')))"}
ANALYSIS = {"end_time": 2.0, "output_step": 0.01, "rtol": 1e-6}
PARAMETERS = {"crank": {"range": [0.15, 0.25]}, "rod": {"range": [0.4, 0.6]}, "crank_mass": {"range": [0.5, 1.5]},
              "rod_mass": {"range": [1.5, 3.0]}, "slider_mass": {"range": [1.0, 2.0]},
              "speed": {"range": ["30 rpm", "90 rpm"]}}


def make_study(n: int) -> mb.Study:
    return mb.Study(slider_crank, PARAMETERS, OUTPUTS, analysis=ANALYSIS, sampling="lhs", samples=n, seed=7)


def python_loop(design) -> tuple[float, float, list]:
    """The baseline a user writes: one model after the other in this process, Result.maximum for the peak."""
    def loop():
        rows = []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for params in design.to_dict("records"):
                res = mb.simulate(slider_crank(**params), 2.0, 0.01, rtol=1e-6)
                _, force = res.maximum(lambda r: np.linalg.norm(r.reaction_force("crank_rod"), axis=1))
                acc = np.max(np.abs(res.acceleration("slider")[:, 0]))
                rows.append((force, acc))
        return rows
    return timed(loop)


def timed(fn):
    """(wall seconds, CPU seconds of this process, result)."""
    t0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return time.perf_counter() - t0, time.process_time() - c0, out


def best_of(n, fn):
    """`timed(fn)` n times: (fastest wall seconds, CPU seconds of that repeat, its result).  The machine is
    shared (VM neighbours): the fastest repeat is the least disturbed one; every row of the table gets
    the same treatment."""
    runs = [fn() for _ in range(max(1, n))]
    return min(runs, key=lambda r: r[0])


STAGES = ("build", "assembly", "compile and run", "outputs")


def breakdown(design) -> dict:
    """CPU ms per variant of each stage of a run in this process (build the model, assemble, compile and
    integrate, measure the outputs) and of the compiled kernels inside them (timed by wrapping them here)."""
    from mbdsim.results.diagnostics import monitor   # noqa: F401 - imported before timing
    from mbdsim.solvers import compiled_run, fastdop, fastkin, kinsweep, minnorm
    from mbdsim.solvers.assembly import assemble_state
    from mbdsim.solvers.dynamic import AUTO_LOCAL
    from mbdsim.studies.measures import evaluate_outputs
    from mbdsim.system import kernels
    from mbdsim.system.assemble import assemble_system, single_use
    kernel_time = {}

    def wrap(mod, name):
        fn = getattr(mod, name)

        def timed_kernel(*a, **k):
            c = time.process_time()
            try:
                return fn(*a, **k)
            finally:
                kernel_time[name] = kernel_time.get(name, 0.0) + time.process_time() - c
        setattr(mod, name, timed_kernel)
        return mod, name, fn
    saved = [wrap(fastdop, n) for n in ("run", "outputs_at", "from_checkpoint")] + \
        [wrap(fastkin, n) for n in ("sweep", "states_at")] + \
        [wrap(minnorm, "min_norm_multipliers"), wrap(kernels, "jacobian_batch")]
    stage = dict.fromkeys(STAGES, 0.0)
    try:
        with warnings.catch_warnings(), single_use():   # as the study's runs: each model assembled once
            warnings.simplefilter("ignore")
            for params in design.to_dict("records"):
                c0 = time.process_time()
                model = slider_crank(**params)
                c1 = time.process_time()
                sys_ = assemble_system(model)
                rep = assemble_state(sys_, sys_.q0, sys_.v0, 0.0)
                c2 = time.process_time()
                times = np.linspace(0.0, 2.0, 201)   # as simulate's automatic method: the kinematic sweep
                res = kinsweep.integrate_kinematic(sys_, rep, times) if rep.dof == 0 else None   # (zero DOF)
                if res is None:
                    res = compiled_run.integrate_compiled(sys_, rep, times, AUTO_LOCAL * 1e-6, AUTO_LOCAL * 1e-9,
                                                          None, None, stiff_check=True)
                c3 = time.process_time()
                evaluate_outputs(OUTPUTS, res)
                c4 = time.process_time()
                for k, dt in zip(STAGES, (c1 - c0, c2 - c1, c3 - c2, c4 - c3)):
                    stage[k] += dt
    finally:
        for mod, name, fn in saved:
            setattr(mod, name, fn)
    n = len(design)
    return {**{k: 1000 * v / n for k, v in stage.items()}, **{f"kernel {k}": 1000 * v / n for k, v in kernel_time.items()}}


def worker_cpu(client) -> float:
    """CPU seconds used so far by all the cluster's worker processes (tasks, Dask's own work included)."""
    return sum(client.run(time.process_time).values())


def exudyn_accuracy(design, serial, steps=(2e-3, 1e-3, 5e-4, 2.5e-4), n=2, target=1e-6, cap=8.0):
    """Exudyn's error on the peak rod force against mbdsim's (exact to the Newton tolerance: the kinematic
    sweep with the peak refined on the dense output) and its wall time per variant, at fixed steps [s]
    over the first n variants: the given steps, then the step halved again until the error is at most
    `target` (the study's rtol) or a variant takes more than `cap` seconds. Returns
    [(step, max relative error, s per variant), ...]; the last row is the equal-accuracy one when its
    error is within the target."""
    from exudyn_slider_crank import run_variant
    rows = []
    ref = serial.peak_rod_force.to_numpy()[:n]

    def measure(h):
        t0 = time.perf_counter()
        f = np.array([run_variant(**p, step=h)[0] for p in design.iloc[:n].to_dict("records")])
        rows.append((h, float(np.max(np.abs(f / ref - 1))), (time.perf_counter() - t0) / n))
    for h in steps:
        measure(h)
    while rows[-1][1] > target and rows[-1][2] * 2 <= cap:
        measure(rows[-1][0] / 2)
    return rows


def exudyn_loop(design):
    """One timed pass of the Python loop over Exudyn (a callable giving (wall s, CPU s, rows)), warmed up."""
    from exudyn_slider_crank import run_variant   # bench/exudyn_slider_crank.py
    run_variant(**design.iloc[0].to_dict())       # warm-up
    return lambda: timed(lambda: [run_variant(**p) for p in design.to_dict("records")])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=32, help="variants (default 32)")
    ap.add_argument("--workers", type=int, default=2, help="Dask worker processes (default 2)")
    ap.add_argument("--exudyn", action="store_true", help="also a Python loop over Exudyn")
    ap.add_argument("--repeat", type=int, default=3, help="repeats of each timed row, the fastest kept (default 3)")
    ap.add_argument("--out", default=str(Path(__file__).with_name("STUDY_RESULTS.md")))
    args = ap.parse_args(argv)
    study = make_study(args.n)
    design = study.variants()
    python_loop(design.iloc[:1])                                  # warm-up: kernels loaded, as in a session
    load0 = os.getloadavg()[0]
    results = []
    secs, cpu, loop_rows = best_of(args.repeat, lambda: python_loop(design))
    results.append(("python loop (mbdsim, Result.maximum)", secs, cpu, 1))
    secs, cpu, serial = best_of(args.repeat, lambda: timed(lambda: study.run(workers=0, progress=False)))
    results.append(("study, serial (workers=0)", secs, cpu, 1))
    assert (serial.status == "ok").all(), serial[serial.status != "ok"].message.tolist()
    assert np.allclose(serial.peak_rod_force, [r[0] for r in loop_rows], rtol=1e-12)
    secs, _, cold = timed(lambda: study.run(workers=args.workers, progress=False))
    results.append((f"study, dask {args.workers} workers (cluster start included)", secs, math.nan, args.workers))
    import dask
    from distributed import Client, LocalCluster

    from mbdsim.studies.runner import local_cluster_config
    with dask.config.set(local_cluster_config()), \
            LocalCluster(n_workers=args.workers, threads_per_worker=1, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        make_study(2 * args.workers).run(client=client, chunk_size=1, progress=False)   # warm the workers
        def warm_run():
            cpu0 = worker_cpu(client)
            secs, _, df = timed(lambda: study.run(client=client, progress=False))
            return secs, worker_cpu(client) - cpu0, df
        # the warm study and the Exudyn loop (the ratio's two terms) are timed in alternation, so that a burst
        # of load from the VM's neighbours does not fall on one of them alone; the fastest of each is kept
        ex_loop = exudyn_loop(design) if args.exudyn else None
        warm_runs, ex_runs = [], []
        for _ in range(max(1, args.repeat)):
            warm_runs.append(warm_run())
            if ex_loop:
                ex_runs.append(ex_loop())
        secs, cpu, warm = min(warm_runs, key=lambda r: r[0])
    results.append((f"study, dask {args.workers} workers (warm cluster)", secs, cpu, args.workers))
    cols = ["peak_rod_force", "slider_peak_acceleration"]
    same = all(np.array_equal(serial[cols].to_numpy(), df[cols].to_numpy()) for df in (cold, warm))
    if args.exudyn:
        secs, cpu, ex_rows = min(ex_runs, key=lambda r: r[0])
        results.append(("python loop (Exudyn 2D, 2 ms steps)", secs, cpu, 1))
        ex = np.array(ex_rows)
        dev = np.max(np.abs(ex[:, 0] / serial.peak_rod_force.to_numpy() - 1))
        results.append((f"  (Exudyn peak rod force vs mbdsim: max deviation {100 * dev:.2f} %)", math.nan, math.nan, 0))
    loads = (load0, os.getloadavg()[0])
    accuracy = exudyn_accuracy(design, serial) if args.exudyn else None
    report(results, args, same, loads, breakdown(design), accuracy)


def report(results, args, same, loads, stages=None, accuracy=None):
    lines = ["| method | seconds | variants/min | per worker | CPU ms/variant |", "|---|---:|---:|---:|---:|"]
    rate = {}
    for name, secs, cpu, nw in results:
        if math.isnan(secs):
            lines.append(f"| {name} | | | | |")
            continue
        rate[name] = 60 * args.n / secs
        cpu_txt = "" if math.isnan(cpu) else f"{1000 * cpu / args.n:.1f}"
        lines.append(f"| {name} | {secs:.2f} | {rate[name]:.0f} | {rate[name] / nw:.0f} | {cpu_txt} |")
    ex = next((v for k, v in rate.items() if "Exudyn" in k), None)
    warm = next(v for k, v in rate.items() if "warm" in k)
    serial = next(v for k, v in rate.items() if "serial" in k)
    ratio = ""
    if ex and accuracy and accuracy[-1][1] <= 1e-6:   # the project's measure: time at equal accuracy
        h_eq, e_eq, s_eq = accuracy[-1]
        ratio += (f"\nAt equal accuracy (target 10x): the warm Dask study is {s_eq * warm / 60:.0f}x the Exudyn loop "
                  f"run at the step that brings its peak rod force within the study's rtol 1e-6 ({1000 * h_eq:g} ms "
                  f"steps, error {e_eq:.1e}, {s_eq:.2f} s per variant, measured below).")
    ratio += (f"\nAgainst the table's Exudyn loop at 2 ms steps (its peak rod force {accuracy[0][1]:.0e} from the "
              "exact value, far looser than the study's rtol): " if accuracy else "\nRatio to the Exudyn loop: ") + \
        (f"dask warm {warm / ex:.2f}x, serial study {serial / ex:.2f}x; variants per minute, dask warm: {warm:.0f} "
         "(target 1000).\n" if ex else "")
    cpu = {name: 1000 * c / args.n for name, secs, c, nw in results if not math.isnan(c)}
    ex_cpu = next((v for k, v in cpu.items() if "Exudyn" in k), None)
    warm_cpu = next((v for k, v in cpu.items() if "warm" in k), None)
    if ex_cpu and warm_cpu:   # what the wall clock would give on dedicated cores (the machine is shared)
        ideal = 60000 * args.workers / warm_cpu
        ratio += (f"On CPU time (far less sensitive than the wall clock to the other load on the machine, though contention inflates it too): dask warm {warm_cpu:.1f} ms per "
                  f"variant in the workers, {ideal:.0f} variants/min on {args.workers} dedicated cores, "
                  f"{ideal / (60000 / ex_cpu):.2f}x the Exudyn 2 ms loop ({ex_cpu:.1f} ms per variant on one core).\n")
    if stages:
        compiled = sum(v for k, v in stages.items() if k.startswith("kernel"))
        total = sum(stages[k] for k in STAGES)
        ratio += ("\nCPU ms per variant in one process, by stage: " +
                  ", ".join(f"{k} {stages[k]:.1f}" for k in STAGES) + f" (total {total:.1f}); inside them the "
                  "compiled kernels: " + ", ".join(f"{k[7:]} {v:.1f}" for k, v in stages.items() if k.startswith("kernel"))
                  + f" (total {compiled:.1f}), Python {total - compiled:.1f}.\n")
        if ex_cpu:
            ratio += (f"Bound: the compiled kernels alone take {compiled:.1f} ms per variant, so even with no Python "
                      f"and no Dask at all {args.workers} dedicated cores would give at most "
                      f"{60000 * args.workers / compiled:.0f} variants/min, {args.workers * ex_cpu / compiled:.1f}x the "
                      f"Exudyn 2 ms loop; 10x that loop needs at most {args.workers * ex_cpu / 10:.1f} ms of CPU per "
                      "variant.\n")
    if accuracy:
        warm_s = 60.0 / warm                     # wall seconds per variant of the warm Dask study
        h_eq, e_eq, s_eq = accuracy[-1]
        ratio += ("\nExudyn's accuracy (first 2 variants; error of its peak rod force against mbdsim's, which is exact "
                  "to the Newton tolerance, and wall time per variant): " +
                  "; ".join(f"{1000 * h:g} ms steps: {e:.1e} in {1000 * s:.0f} ms" for h, e, s in accuracy) + ". ")
        if e_eq > 1e-6:
            ratio += (f"Exudyn did not reach 1e-6 within the time cap: at its finest step ({1000 * h_eq:g} ms, error "
                      f"{e_eq:.1e}, {s_eq:.2f} s per variant) the warm study is already {s_eq / warm_s:.0f}x faster, "
                      "at far better accuracy. ")
        ratio += (f"The table's Exudyn row is the 2 ms loop (error {accuracy[0][1]:.1e}), not at equal accuracy.\n")
    table = "\n".join(lines)
    print(table + ratio)
    head = (f"# Study throughput: slider-crank variants per minute\n\n"
            f"`python bench/study_throughput.py --n {args.n} --workers {args.workers}"
            f"{' --exudyn' if args.exudyn else ''} --repeat {args.repeat}` on {platform.node()} ({os.cpu_count()} cores, "
            f"{platform.python_version()}), {time.strftime('%Y-%m-%d %H:%M')}; load average "
            f"{loads[0]:.1f} at the start, {loads[1]:.1f} at the end (the cores are shared: wall-clock rates "
            "are pessimistic by about that factor over the core count; the CPU column is this process's "
            "CPU time, for the warm Dask row the workers' CPU time, Dask's own work included; every timed row "
            f"the fastest of {args.repeat} repeats, that repeat's CPU time; the warm Dask row and the Exudyn loop "
            "are repeated in alternation).\n\n"
            "Each variant: slider-crank (crank, rod, three masses, drive speed from a Latin hypercube), dynamics "
            "over 2 s, output every 10 ms, rtol 1e-6 (the model is driven, zero DOF: simulate's automatic method "
            "solves it by the compiled kinematic sweep, exact to 1e-12 at every output); outputs: peak rod "
            "force at the crank pin (refined on the "
            "dense output) and the slider's peak acceleration.  The loop and the serial study run the same "
            "work in one process; the Dask rows use worker processes (the first including the cluster start: "
            "one run in this process, then workers forked from it).\n\n"
            f"Dask results bit-identical to the serial run: {'yes' if same else 'NO'}.\n\n"
            + ("Exudyn: the same slider-crank as 2D rigid bodies (bench/exudyn_slider_crank.py), generalized-alpha "
               "with 1000 fixed steps of 2 ms, the drive a coordinate constraint whose offset theta = w t is a "
               "symbolic user function (Exudyn's compiled user functions; 13 % faster than a Python one), "
               "peak values from its sensors at every step (no refinement); one process.\n\n" if args.exudyn else ""))
    Path(args.out).write_text(head + table + "\n" + ratio, encoding="utf-8")
    print(f"written: {args.out}")


if __name__ == "__main__":
    main()
