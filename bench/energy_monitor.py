"""Cost of simulate's run monitor (the energy balance's dissipated energy D, issue 29): each scene timed with
monitor=True and monitor=False in the same run (best of REPEATS after a warm-up that compiles), the
monitor's share = 1 - t(off) / t(on), and where the compiled run accumulated D itself (res.stats
"energy": "compiled") the Python reference quadrature's D at the last output for comparison.

Scenes: a ball rolling in a triangle-mesh bowl (tests/test_shape_contact_mesh.py), a planetary gear set with a
spring-damper on the carrier (bench/vocabulary.py's planetary plus the damper), and the contact bench's
scenes (bench/contact_shapes.py: box sliding, cylinder rolling, pile of eight boxes, cam and follower).

    PYTHONPATH=src python3 bench/energy_monitor.py [scene ...]     (REPEATS=n, REFERENCE=0: no reference)
"""
from __future__ import annotations

import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import mbdsim as mb

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE.parent / "tests"))
sys.path.insert(0, str(HERE))
REPEATS = int(os.environ.get("REPEATS", 2))
G = 9.81


def bowl():
    from test_shape_contact_mesh import grid_surface
    R, r, rho, k, e = 0.5, 0.05, 1000.0, 1e6, 1.5
    L, n = 0.08, 48
    v, f = grid_surface(-L, -L, n, 2 * L / n, lambda x, y: R - np.sqrt(R * R - x * x - y * y))
    ball = mb.Sphere(radius=r)
    mass = ball.mass_properties(rho)[0]
    rc = R - r + (mass * G / k) ** (1 / e)
    th0 = 0.05
    m = mb.Model(gravity=(0, 0, -G))
    b = m.add_body("ball", 0.0, position=(rc * np.sin(th0), 0.0, R - rc * np.cos(th0)))
    s = b.add_shape("geo", ball, density=rho)
    m.add_contact("c", m.ground.add_shape("bowl", mb.Mesh(v, f)), s, k, e, 20.0, 1e-4, mu=0.5,
                  friction_velocity=1e-2)
    T = 2 * np.pi / np.sqrt(5 * G / (7 * rc))
    return m, dict(end_time=1.9 * T, output_step=T / 200, method="dop853", rtol=1e-7)


def planetary_damper():
    from vocabulary import planetary
    m = planetary(True)
    p = m.bodies["planet"].add_marker("pd", (0.045, 0.0, 0.0))
    g = m.ground.add_marker("gd", (0.045, 0.05, 0.0))
    m.add_spring_damper("damper", g, p, 5.0, 0.5, 0.05)
    return m, dict(end_time=1.0, output_step=0.01)


def _contact(name):
    import contact_shapes as cs   # the scenes as the contact bench builds them
    from test_shape_contact_plane import box_on_incline
    if name == "box_slide":
        m, _ = box_on_incline(np.radians(30), "box", None, v0=0.5, mu=0.3, friction_velocity=1e-3)
        return m, dict(end_time=0.5, output_step=0.005, method="dop853", rtol=1e-6)
    if name == "cyl_roll":
        return cs.cyl_roll_model()[0], dict(end_time=0.5, output_step=0.005, method="dop853", rtol=1e-6)
    if name == "pile":
        return cs.pile_model(), dict(end_time=1.5, output_step=0.01, method="dop853", rtol=1e-5)
    if name == "cam":
        from test_shape_contact_cam import cam_model, lift_off_speed
        w = 0.7 * lift_off_speed()
        m, _ = cam_model(w)
        T = 2 * np.pi / w
        return m, dict(end_time=T, output_step=T / 100, method="dop853", rtol=1e-8)
    raise KeyError(name)


SCENES = {"bowl": bowl, "planetary_damper": planetary_damper,
          **{k: (lambda k=k: _contact(k)) for k in ("box_slide", "cyl_roll", "pile", "cam")}}


def _best(fn):
    best, out = np.inf, None
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def measure(name):
    m, opts = SCENES[name]()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mb.simulate(m, monitor=False, **opts)   # warm-up: compiles, assembles
        t_off, _ = _best(lambda: mb.simulate(m, monitor=False, **opts))
        t_on, res = _best(lambda: mb.simulate(m, monitor=True, **opts))
    d = res.diagnostics
    line = {"scene": name, "off_s": t_off, "on_s": t_on, "share": 1.0 - t_off / t_on,
            "energy": res.stats.get("energy", "python"), "method": res.stats.get("method"),
            "energy_error": d.summary().get("energy_error") if d is not None else None,
            "notes": d.notes if d is not None else None}
    if res.stats.get("energy") == "compiled" and os.environ.get("REFERENCE", "1") != "0":
        from mbdsim.results.energy import dissipated_energy_reference
        t0 = time.perf_counter()
        ref = dissipated_energy_reference(res)
        line["python_quadrature_s"] = time.perf_counter() - t0
        D = res.dissipated_energy()
        line["D_end"] = float(D[-1])
        line["D_rel_diff"] = float(np.max(np.abs(D - ref)) / max(np.max(np.abs(ref)), 1e-300))
    return line


if __name__ == "__main__":
    for name in sys.argv[1:] or list(SCENES):
        r = measure(name)
        print(" ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in r.items()), flush=True)
