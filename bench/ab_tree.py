"""Same-machine A/B of the step loop on joint-coordinate trees: best of 15 `mb.simulate` calls (rtol 1e-8) of
bench/problems' pendulum, double pendulum and chain2d_8, for the mbdsim of a given checkout.

    python3 bench/ab_tree.py /path/to/checkout_a
    python3 bench/ab_tree.py /path/to/checkout_b      # e.g. a `git worktree add` of an older commit

Run the two back to back on a quiet machine (absolute times move by 30 % with load). Session 38 found the
pendulum at 3.09 ms on 0e11f6e and 5.59 ms on the merged main with the same 2,628 right-hand sides.
"""
import os
import sys
import time
import warnings

CHECKOUT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, os.path.join(CHECKOUT, "src"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mbdsim as mb  # noqa: E402
import engines as E  # noqa: E402
from problems import PROBLEMS  # noqa: E402

warnings.simplefilter("ignore")
for key in ("pendulum", "double_pendulum", "chain2d_8"):
    p = PROBLEMS[key]
    model = E.mbdsim_model(p)[0]
    res = mb.simulate(model, p.t_end, p.out_dt, rtol=1e-8)
    ts = []
    for _ in range(15):
        t0 = time.perf_counter()
        mb.simulate(model, p.t_end, p.out_dt, rtol=1e-8)
        ts.append(time.perf_counter() - t0)
    print(f"{key}: {min(ts) * 1e3:.2f} ms, nfev {res.stats.get('nfev')} ({mb.__file__})")
