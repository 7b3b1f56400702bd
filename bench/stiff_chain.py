"""Issue 29's stiff chain: a two-mass chain with one spring 1e4 times stiffer than the other against its soft
counterpart, at default settings (`mb.simulate`, method "auto"), in one process run.

ground -k1- m1 -k2- m2 along x on translational joints, k1 = 100 N/m, m1 = 1 kg, m2 = 2 kg, 1 s, outputs
every 0.01 s. Stiff: k2 = 1e6 N/m; soft: k2 = 100 N/m. Error: the largest deviation of the slow mode's
coordinate (M-orthonormal eigenvectors of the 2 x 2 system) from its exact solution, relative to its
amplitude. Three releases of the stiff chain:
  * on the slow mode's shape (the fast mode not excited),
  * both masses displaced alike (the stiff spring unstretched: the fast mode excited at ~1e-4 of the
    slow one, undamped, so that an integrator meeting the tolerance on every output resolves it),
  * the same with the stiff spring damped (damping ratio 0.05 of the fast mode: it dies out).
Median of REPEAT calls after a warm-up. Writes its table into bench/STIFF_RESULTS.md (between the
markers below; the rest of that file is bench/stiff.py's).

    PYTHONPATH=src python3 bench/stiff_chain.py [repeats]
"""
from __future__ import annotations

import statistics
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from scipy.linalg import eigh

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
import mbdsim as mb  # noqa: E402

REPEAT = int(sys.argv[1]) if len(sys.argv) > 1 else 5
K1, M1, M2, D, T = 100.0, 1.0, 2.0, 0.01, 1.0
BEGIN, END = "<!-- stiff chain (bench/stiff_chain.py) -->", "<!-- end stiff chain -->"


def chain(k2, release, zeta=0.0):
    M, K = np.diag([M1, M2]), np.array([[K1 + k2, -k2], [-k2, k2]])
    w2, V = eigh(K, M)
    x0 = D * V[:, 0] / V[0, 0] if release == "slow mode" else np.array([D, D])
    c2 = 2 * zeta * np.sqrt(w2[1]) * M1 * M2 / (M1 + M2)   # fast mode ~ the relative motion of the masses
    m = mb.Model("two-mass chain", gravity=(0, 0, 0))
    p1 = m.add_particle("p1", M1, position=(1.0 + x0[0], 0, 0))
    p2 = m.add_particle("p2", M2, position=(2.0 + x0[1], 0, 0))
    m.add_translational("s1", m.ground, p1, (1.0, 0, 0), (1, 0, 0))
    m.add_translational("s2", m.ground, p2, (2.0, 0, 0), (1, 0, 0))
    m.add_spring_damper("k1", m.ground, p1, K1, 0.0, 1.0)
    m.add_spring_damper("k2", p1, p2, k2, c2, 1.0)
    return m, M, w2, V, x0, c2


def slow_error(res, M, w2, V, x0, zeta, c2=0.0, k2=0.0):
    """Undamped: the slow mode's coordinate against its exact solution, relative to its amplitude.
    Damped (non-proportional damping): both displacements against the exact solution of the first-order
    system (its eigen-decomposition), relative to the release displacement D."""
    x = np.stack([res.position("p1")[:, 0] - 1.0, res.position("p2")[:, 0] - 2.0], 1)
    if zeta == 0.0:
        eta0 = V[:, 0] @ M @ x0
        exact = eta0 * np.cos(np.sqrt(w2[0]) * res.time)
        return float(np.max(np.abs(x @ M @ V[:, 0] - exact)) / abs(eta0))
    K = np.array([[K1 + k2, -k2], [-k2, k2]])
    C = np.array([[c2, -c2], [-c2, c2]])
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-Minv @ K, -Minv @ C]])
    lam, W = np.linalg.eig(A)
    coef = np.linalg.solve(W, np.concatenate([x0, [0.0, 0.0]]))
    exact = np.real((W[:2, :] * coef) @ np.exp(lam[:, None] * res.time[None, :])).T
    return float(np.max(np.abs(x - exact)) / D)


def zeta_of(name):
    return 0 if "damped" not in name else 1


def timed(fn):
    res = fn()
    ts = []
    for _ in range(REPEAT):
        t0 = time.perf_counter()
        res = fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts), res


def main():
    warnings.simplefilter("ignore")
    rows = []
    soft, Ms, w2s, Vs, x0s, _ = chain(K1, "alike")
    ts_, rs = timed(lambda: mb.simulate(soft, T, output_step=0.01))
    es = slow_error(rs, Ms, w2s, Vs, x0s, 0.0)
    for release, zeta in (("slow mode", 0.0), ("alike", 0.0), ("alike", 0.05)):
        m, M, w2, V, x0, c2 = chain(1e4 * K1, release, zeta)
        te, re = timed(lambda: mb.simulate(m, T, output_step=0.01))
        err = slow_error(re, M, w2, V, x0, zeta, c2, 1e4 * K1)
        rows.append((release + (f", damped (zeta {zeta:g})" if zeta else ""), te, re, err))
    lines = [BEGIN, "", "## Stiff two-mass chain (k2 = 1e4 k1) against the soft one (k2 = k1), default settings",
             "", f"Written by `bench/stiff_chain.py`: median of {REPEAT} calls after a warm-up, same process; "
             "1 s, outputs every 0.01 s; slow-mode error relative to its amplitude (exact modal solution).", "",
             "| stiff chain released | time | soft chain | ratio | steps (stiff / soft) | method | slow-mode error |",
             "|---|---|---|---|---|---|---|"]
    for name, te, re, err in rows:
        lines.append(f"| {name} | {te * 1e3:.2f} ms | {ts_ * 1e3:.2f} ms | {te / ts_:.2f}x | "
                     f"{re.stats['steps']} / {rs.stats['steps']} | {re.stats['method']} | "
                     f"{err:.1e}{'' if zeta_of(name) == 0 else ' (both displacements)'} |")
        print(lines[-1], flush=True)
    lines += ["", f"Soft chain: {rs.stats['method']}, slow-mode error {es:.1e}.", "", END]
    out = Path(__file__).with_name("STIFF_RESULTS.md")
    text = out.read_text() if out.exists() else ""
    if BEGIN in text and END in text:
        text = text[:text.index(BEGIN)] + "\n".join(lines) + text[text.index(END) + len(END):]
    else:
        text = text.rstrip("\n") + "\n\n" + "\n".join(lines) + "\n"
    out.write_text(text)
    print("wrote", out)


if __name__ == "__main__":
    main()
