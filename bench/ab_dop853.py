"""Same-machine A/B of the compiled DOP853 on bench/problems' pendulum (joint-coordinate tree) and 3D chain
(absolute coordinates): best of 15 `mb.simulate` calls at rtol 1e-4, 1e-6, 1e-8 (atol = 1e-2 rtol), for the
mbdsim of a given checkout (the kernels' cache warm: the first call of each setting is not timed).

    python3 bench/ab_dop853.py /path/to/checkout_a
    python3 bench/ab_dop853.py /path/to/checkout_b

Alternate the two a few times (absolute times move with the machine's load). Issue 32 (bench/RESULTS.md,
Cold compile after Slots and link-only kernels) used it for main against the Slots / link-only branch.
"""
import os
import sys

CHECKOUT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, os.path.join(CHECKOUT, "src"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import engines as E  # noqa: E402
from problems import PROBLEMS  # noqa: E402

out = []
for key in ("pendulum", "chain"):
    p = PROBLEMS[key]
    for tol in (1e-4, 1e-6, 1e-8):
        E.run_mbdsim(p, "dop853", tol)
        best = min(E.run_mbdsim(p, "dop853", tol)[0] for _ in range(15))
        out.append(f"{key}@{tol:g} {best * 1e3:.3f} ms")
print("  ".join(out))
