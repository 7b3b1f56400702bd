"""Issue 35, scale: a 10,000-body chain (and 10,000 free bodies) assembles, runs and is tabled within a
4 GB address-space limit (a dense Jacobian alone would be 24 GB, the dense mass matrix 29 GB), in a child
process; its pin reactions at release are checked against statics of the hanging chain's first link.
The chain with a coupler between its first two joints and a held joint angle (rows outside the kernels'
compact format: the sparse assembly's coupler rows, the joints' reactions from their own rows) too."""
import json
import subprocess
import sys
import textwrap

import pytest

CHILD = textwrap.dedent("""
    import json, resource, sys, time
    resource.setrlimit(resource.RLIMIT_AS, (4 * 2**30, 4 * 2**30))
    import numpy as np, mbdsim as mb
    N, kind = int(sys.argv[1]), sys.argv[2]
    t0 = time.perf_counter()
    m = mb.Model("big", gravity=(0.0, -9.81, 0.0))
    prev = m.ground
    for k in range(N):
        if kind != "free":   # hanging straight down, at rest: every pin carries the weight below it
            b = m.add_body(f"b{k}", 1.0, inertia=(0.01, 0.01, 0.01), position=(0.0, -0.5 - k, 0.0))
            m.add_revolute(f"j{k}", prev, b, (0.0, -float(k), 0.0), (0, 0, 1))
            prev = b
        else:
            m.add_body(f"b{k}", 1.0, inertia=(0.01, 0.02, 0.03), position=(float(k), 0.0, 0.0),
                       angular_velocity=(0.0, 0.0, 1.0))
    if kind == "coupled":   # a coupler (theta_1 = 2 theta_0) and a held angle: still at rest, hanging
        m.add_coupler("c", "j0", "j1", 2.0)
        m.joints["j5"].initial_displacement = np.array([0.0])
    t_build = time.perf_counter() - t0
    res = mb.simulate(m, 0.01, 0.005)
    t_run = time.perf_counter() - t0 - t_build
    df = res.to_dataframe()
    t_table = time.perf_counter() - t0 - t_build - t_run
    out = {"success": res.success, "rows": len(df), "cols": df.shape[1], "times": [t_build, t_run, t_table],
           "rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}
    if kind != "free":
        out["F0"] = df["j0.Fy [N]"].tolist()
        out["Flast"] = df[f"j{N - 1}.Fy [N]"].tolist()
        out["y_last"] = df[f"b{N - 1}.y [m]"].tolist()
    print(json.dumps(out))
""")


@pytest.mark.parametrize("kind", ["chain", "free", "coupled"])
def test_10000_bodies_within_4_gb(kind):
    N = 10_000
    proc = subprocess.run([sys.executable, "-c", CHILD, str(N), kind], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out["success"] and out["rows"] == 3 and out["rss_mb"] < 4096
    assert sum(out["times"]) < 300.0   # about 25 s alone on this machine: O(N) work, not O(N^2)
    if kind != "free":
        g = 9.81
        # the hanging chain stays at rest: the first pin (on body b0) carries the weight of all N links
        # (force on b0 from ground: +N m g), the last one the weight of one link
        assert out["F0"] == pytest.approx([N * g] * 3, rel=1e-9)
        assert out["Flast"] == pytest.approx([g] * 3, rel=1e-9)
        assert out["y_last"] == pytest.approx([-0.5 - (N - 1)] * 3, abs=1e-9)
