"""Issue 10: hypothesis fuzzer of random mechanisms (chains, trees, loops; every joint type; springs) and of
mutated model files, with a bounded budget. Asserted: no exception other than an mbdsim error, no hang
(an alarm per example), and for conservative models an energy drift below a tolerance tied to rtol.

Budget: FUZZ_EXAMPLES (environment MBDSIM_FUZZ_EXAMPLES, default 200 mechanisms and 100 files, about 20 s on
one core; issue 35: a few hundred random mechanisms in every CI run), derandomized so
that CI is reproducible; set MBDSIM_FUZZ_SEED=random for fresh draws). The outcome counts are printed with
`pytest -s` (and kept in STATS)."""
import copy
import os
import signal
import warnings
from collections import Counter
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
import yaml

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings, strategies as st  # noqa: E402

import mbdsim as mb  # noqa: E402
from mbdsim.errors import MbdsimError  # noqa: E402
from mbdsim.io import model_from_dict  # noqa: E402

N_MECH = int(os.environ.get("MBDSIM_FUZZ_EXAMPLES", "200"))
N_FILES = int(os.environ.get("MBDSIM_FUZZ_FILE_EXAMPLES", "100"))
RANDOM = os.environ.get("MBDSIM_FUZZ_SEED") == "random"
HANG_S = 60
RTOL = 1e-7
STATS = {"mechanisms": Counter(), "files": Counter()}
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
JOINTS = ("revolute", "translational", "cylindrical", "spherical", "universal", "planar", "fixed")


class Hang(BaseException):
    """An example ran past HANG_S (BaseException: no analysis may swallow it)."""


def _alarm(*_):
    raise Hang()


@contextmanager
def _deadline():
    """Raise Hang inside the block once it runs past HANG_S (SIGALRM; the previous handler restored)."""
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(HANG_S)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _settings(n):
    return settings(max_examples=n, deadline=None, derandomize=not RANDOM, database=None,
                    suppress_health_check=list(HealthCheck))


def _unit(draw):
    v = np.array(draw(st.lists(st.floats(-1, 1, allow_nan=False), min_size=3, max_size=3)))
    n = np.linalg.norm(v)
    return tuple(v / n) if n > 0.1 else (0.0, 0.0, 1.0)


@st.composite
def mechanisms(draw):
    """(model, conservative): 1-4 bodies as a chain, a tree or with a loop closed by a spherical joint to
    ground; joints of every type; springs (and dampers: not conservative)."""
    n = draw(st.integers(1, 4))
    topo = draw(st.sampled_from(["chain", "tree", "loop"]))
    m = mb.Model("fuzz", gravity=draw(st.sampled_from([(0, 0, -9.81), (0, -9.81, 0), (0, 0, 0)])))
    bodies, conservative = [m.ground], True
    for k in range(n):
        mass = draw(st.floats(0.1, 10.0))
        dims = [draw(st.floats(0.05, 1.0)) for _ in range(3)]
        inertia = (mass * (dims[1] ** 2 + dims[2] ** 2) / 12, mass * (dims[0] ** 2 + dims[2] ** 2) / 12,
                   mass * (dims[0] ** 2 + dims[1] ** 2) / 12)
        pos = tuple(draw(st.floats(-1.0, 1.0)) for _ in range(3))
        b = m.add_body(f"b{k}", mass, inertia=inertia, position=pos)
        parent = bodies[-1] if topo != "tree" else bodies[draw(st.integers(0, len(bodies) - 1))]
        kind = draw(st.sampled_from(JOINTS))
        point = tuple(0.5 * (np.asarray(pos) + (np.zeros(3) if parent is m.ground else parent.position)))
        args = {"revolute": dict(axis=_unit(draw)), "translational": dict(axis=_unit(draw)),
                "cylindrical": dict(axis=_unit(draw)), "spherical": {}, "fixed": {},
                "universal": dict(axis_i=(1.0, 0.0, 0.0), axis_j=(0.0, 1.0, 0.0)),
                "planar": dict(normal=_unit(draw))}[kind]
        getattr(m, f"add_{kind}")(f"j{k}", parent, b, point, **args)
        bodies.append(b)
    if topo == "loop" and n >= 2:
        last = bodies[-1]
        m.add_spherical("close", m.ground, last, tuple(last.position))
    for s in range(draw(st.integers(0, 2))):
        i, j = draw(st.integers(0, n)), draw(st.integers(0, n))
        if i == j:
            continue
        damping = draw(st.sampled_from([0.0, 0.0, 5.0]))
        conservative &= damping == 0.0
        bi, bj = bodies[i], bodies[j]
        pi = (0.0, 0.0, 0.0) if bi is m.ground else tuple(bi.position)
        pj = tuple(np.asarray(pi) + 0.3) if bj is m.ground else tuple(bj.position)
        m.add_spring_damper(f"s{s}", (bi, pi), (bj, pj), draw(st.floats(1.0, 200.0)), damping=damping)
    return m, conservative


@given(mechanisms())
@_settings(N_MECH)
def test_random_mechanisms(case):
    model, conservative = case
    try:
        with _deadline(), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = mb.simulate(model, 0.3, 0.01, rtol=RTOL)
    except Hang:
        STATS["mechanisms"]["hang"] += 1
        pytest.fail(f"simulate ran past {HANG_S} s")
    except MbdsimError as exc:
        STATS["mechanisms"][f"refused: {type(exc).__name__}"] += 1
        return
    if not res.success:
        assert isinstance(res.error, MbdsimError) and res.message
        STATS["mechanisms"][f"failed run: {type(res.error).__name__}"] += 1
        return
    STATS["mechanisms"]["ok"] += 1
    if conservative and "HHT" not in res.stats.get("method", ""):
        E = res.kinetic_energy() + res.potential_energy()
        scale = max(np.max(res.kinetic_energy()), np.ptp(res.potential_energy()), 1e-9)
        # the global error of a run at rtol stays within a few hundred rtol of the energy scale here; a
        # nearly static model drifts by round-off of its absolute energy (V measured from the origin)
        roundoff = 1e3 * np.finfo(float).eps * np.max(np.abs(E))
        assert np.max(np.abs(E - E[0])) <= 1e3 * RTOL * scale + 1e-12 + roundoff, res.stats.get("method")
        STATS["mechanisms"]["energy checked"] += 1


JUNK = st.one_of(st.none(), st.booleans(), st.integers(-10**6, 10**6), st.floats(allow_nan=True),
                 st.text(max_size=12), st.lists(st.floats(-1e3, 1e3), max_size=4),
                 st.sampled_from(["1 kg", "-3 m", "sin(", "__import__('os')", "t**t**t", "1e999", "nan", "ground",
                                  "1 parsec", {"body": "nobody"}, [[1, 2], [3]], {}]))


def _paths(node, prefix=()):
    """Every (path, value) of a nested dict/list model description."""
    out = []
    if isinstance(node, dict):
        for k, v in node.items():
            out.append((prefix + (k,), v))
            out += _paths(v, prefix + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out.append((prefix + (i,), v))
            out += _paths(v, prefix + (i,))
    return out


@st.composite
def mutated_files(draw):
    name = draw(st.sampled_from(sorted(p.name for p in EXAMPLES.glob("*.yaml") if "study" not in p.name)))
    data = yaml.safe_load((EXAMPLES / name).read_text())
    for _ in range(draw(st.integers(1, 3))):
        paths = _paths(data)
        path, _ = draw(st.sampled_from(paths))
        parent = data
        for k in path[:-1]:
            parent = parent[k]
        action = draw(st.sampled_from(["replace", "delete", "duplicate"]))
        if action == "delete" and isinstance(parent, dict):
            del parent[path[-1]]
        elif action == "duplicate" and isinstance(parent, list):
            parent.append(copy.deepcopy(parent[path[-1]]))
        else:
            parent[path[-1]] = draw(JUNK)
    return name, data


@given(mutated_files())
@_settings(N_FILES)
def test_mutated_model_files(case):
    name, data = case
    try:
        with _deadline(), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                model = model_from_dict(data, source=name)
            except MbdsimError:
                STATS["files"]["refused when loaded"] += 1
                return
            try:
                res = mb.simulate(model, 0.05, 0.01)
            except MbdsimError:
                STATS["files"]["loaded, analysis refused"] += 1
                return
        assert res.success or isinstance(res.error, MbdsimError)
        STATS["files"]["loaded and ran" if res.success else "loaded, run failed (named)"] += 1
    except Hang:
        pytest.fail(f"a mutated {name} ran past {HANG_S} s")


def test_print_fuzz_statistics():
    """Runs last in this file: the outcome counts (pytest -s shows them)."""
    for k, c in STATS.items():   # "energy checked" counts a subset of the "ok" mechanisms, not more examples
        print(f"fuzz {k}: {sum(v for o, v in c.items() if o != 'energy checked')} examples: {dict(c)}")
