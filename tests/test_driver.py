"""One driver over the Python steppers (solvers/driver.py): the index-1 scipy methods and HHT share
event location, output sampling, progress and Result building; checked on closed forms."""
import numpy as np
import pytest

import mbdsim as mb
from mbdsim.system.force_elements._common import element_state

G = 9.81


def ball_drop(h=0.3, R=0.05):
    m = mb.Model(gravity=(0, 0, -G))
    ball = m.add_body("ball", 1.0, (0.4 * R * R,) * 3, position=(0, 0, R + h))
    m.add_contact("floor", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), mb.Sphere(ball, R), 1e5, 1.5, 20.0, 1e-3)
    return m, ball


@pytest.mark.parametrize("method, kw", [("hht", dict(rtol=1e-6)), ("rk45", dict(rtol=1e-9, atol=1e-11)),
                                        ("radau", dict(rtol=1e-8, atol=1e-10))])
def test_contact_onset_is_a_step_boundary_at_the_free_fall_time(method, kw):
    """Free fall is exactly quadratic: the onset is located at sqrt(2 h / g) on the step's dense output and
    the step is cut there (index-1) or redone to end there (HHT, whose cubic interpolant of a step that
    ends inside the contact places the root to ~1e-9 s only: the redone step is searched again on its own
    interpolant until no root is left inside it; the compiled HHT cuts its step at the root of the cubic
    of the step that crossed the onset, not redone: a few 1e-9 s)."""
    h = 0.3
    m, ball = ball_drop(h)
    res = mb.simulate(m, 0.3, 0.01, method=method, **kw)
    assert res.success, res.message
    t_fall = np.sqrt(2 * h / G)
    ts = res.steps()[0]
    tol = 1e-8 if method == "hht" else 1e-9
    assert np.min(np.abs(ts - t_fall)) < tol                      # a step ends at the onset
    events = element_state(res.system, "floor").get("events")   # the Python path records its events
    assert ("compiled" in res.stats["method"]) if events is None else abs(events[0] - t_fall) < tol
    before = res.time < t_fall
    z = res.position(ball)[before, 2]
    assert np.allclose(z, 0.05 + h - 0.5 * G * res.time[before] ** 2, rtol=0, atol=1e-8)


@pytest.mark.parametrize("method", ["hht", "rk45"])
def test_progress_partial_results_and_final_result(method):
    """Progress calls carry the time reached and a partial Result of the outputs so far; the final
    Result has every output and the stepper's statistics."""
    m = mb.Model(gravity=(0, -G, 0))
    b = m.add_body("b", 1.0, inertia=(1e-3, 1 / 12, 1 / 12), position=(0.5, 0, 0))
    m.add_revolute("j", m.ground, b, (0, 0, 0), (0, 0, 1))

    class Monitor:   # the RunMonitor protocol of mbdsim.results.stream.notify
        def __init__(self):
            self.times, self.partial = [], []

        def __call__(self, t):
            self.times.append(t)

        def offer(self, build):
            self.partial.append(build())

    mon = Monitor()
    res = mb.simulate(m, 0.5, 0.01, method=method, progress=mon)
    assert res.success and len(res.time) == 51
    ts = mon.times
    assert ts == sorted(ts) and ts[-1] == pytest.approx(0.5)
    partial = mon.partial
    assert partial and all(p.message.startswith("partial") for p in partial)
    last = partial[-1]
    n = len(last.time)
    assert np.array_equal(last.time, res.time[:n]) and np.allclose(last.q, res.q[:n], rtol=0, atol=1e-14)
    assert res.stats["steps"] >= 1 and res.stats["method"].split(" (")[0] in ("HHT", "RK45")
    # energy of the rigid pendulum: conserved to the method's accuracy (HHT dissipates slightly)
    E = res.kinetic_energy() + res.potential_energy()
    assert np.max(np.abs(E - E[0])) < (1e-3 if method == "hht" else 1e-6)
