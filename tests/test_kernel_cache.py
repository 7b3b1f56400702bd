"""Start-up (issue 32): the compiled-kernel cache is keyed on the kernels' content and the machine, not on
where mbdsim lives, so a second clone or a new virtual environment loads the kernels instead of compiling
them; inner kernels (compiled without numba's wrappers) still work when Python calls them; the compile
note; `mbdsim cache info` / `clear`."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

import mbdsim

# a child process: the README's pendulum, a short compiled run; prints where mbdsim came from and how many
# of mbdsim's kernels numba compiled (numba's compile events; a load from the cache raises none)
CHILD = """
import sys
from numba.core import event
count = [0]
class Count(event.Listener):
    def on_start(self, ev):
        count[0] += ev.data["dispatcher"].py_func.__module__.startswith("mbdsim.")
    def on_end(self, ev):
        pass
event.register("numba:compile", Count())
import mbdsim as mb
model = mb.Model("pendulum", gravity=(0.0, -9.81, 0.0))
rod = model.add_body("rod", mass=2.0, inertia=(2.0 / 12, 0.0, 2.0 / 12), position=(0.5, 0, 0))
pin = model.add_revolute("pin", model.ground, rod, point=(0, 0, 0), axis=(0, 0, 1))
res = mb.simulate(model, end_time=0.05, output_step=0.01)
assert res.success and "DOP853 (compiled)" in res.stats["method"], res.stats
import os
print(os.path.abspath(mb.__file__))
print(count[0])
"""


def _child(src: Path) -> tuple[str, int, float]:
    env = dict(os.environ, PYTHONPATH=str(src), MBDSIM_QUIET_COMPILE="1")
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True, text=True, timeout=1200,
                         cwd=str(src.parent))
    assert out.returncode == 0, out.stderr[-3000:]
    where, count = out.stdout.splitlines()[-2:]
    return where, int(count), time.perf_counter() - t0


def test_second_clone_loads_the_cache_without_compiling(tmp_path):
    here = Path(mbdsim.__file__).resolve().parent
    where, _, _ = _child(here.parent)   # fills the cache if it was cold (minutes, once)
    assert Path(where).resolve().parent == here
    clone = tmp_path / "second clone" / "src" / "mbdsim"
    # copyfile, not copy2: new modification times, as a fresh `git clone` or `pip install` gives
    shutil.copytree(here, clone, copy_function=shutil.copyfile, ignore=shutil.ignore_patterns("__pycache__"))
    where, compiled, seconds = _child(clone.parent)
    assert Path(where).resolve().parent == clone.resolve()
    assert compiled == 0, f"the second clone compiled {compiled} kernels ({seconds:.1f} s)"


def test_inner_kernel_called_from_python():
    """An inner kernel (no CPython wrapper) called from Python runs through its wrapped twin."""
    from mbdsim._jit import KernelDispatcher
    from mbdsim.system import kernels
    assert isinstance(kernels._cr, KernelDispatcher)
    a, b = np.array([1.0, 2.0, 3.0]), np.array([-2.0, 0.5, 4.0])
    assert np.allclose(kernels._cr(a, b), np.cross(a, b), rtol=0, atol=1e-15)
    assert kernels._dt(a, b) == float(a @ b)


class _Event:
    def __init__(self, module: str, name: str) -> None:
        f = type("F", (), {"__module__": module, "__qualname__": name})
        self.data = {"dispatcher": type("D", (), {"py_func": f})()}


def test_compile_note_one_line_after_the_delay(tmp_path, monkeypatch):
    import io

    from mbdsim import _compilenote
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(_compilenote, "DELAY", 0.05)
    out = io.StringIO()
    note = _compilenote.CompileNote(stream=out)
    quick = _Event("mbdsim.solvers.fastdop", "quick")
    note.on_start(quick)
    note.on_end(quick)            # done before the delay: nothing said
    time.sleep(0.15)
    assert out.getvalue() == ""
    outer, inner, other = (_Event("mbdsim.solvers.fastdop", "run"), _Event("mbdsim.solvers.fastdyn", "rhs"),
                           _Event("someone_else", "f"))
    for _ in range(2):            # two long compilations: one line for the process
        note.on_start(other)      # not mbdsim's: ignored
        note.on_start(outer)
        note.on_start(inner)
        time.sleep(0.3)
        note.on_end(inner)
        note.on_end(outer)
        note.on_end(other)
    lines = out.getvalue().splitlines()
    assert len(lines) == 1 and lines[0].startswith("mbdsim: compiling the numba kernels") and " s" in lines[0]
    seconds, count = json.loads((tmp_path / "compile-times.json").read_text())["solvers.fastdop.run"]
    assert 0.2 < seconds < 5.0 and count == 2   # the next estimate: this machine's last time
    assert f"about {_compilenote.ESTIMATE_S:.0f} s" in lines[0]   # no record yet: the default
    note.on_start(outer)          # a later compilation of fewer kernels (its callees cached) keeps the record
    time.sleep(0.06)
    note.on_end(outer)
    assert json.loads((tmp_path / "compile-times.json").read_text())["solvers.fastdop.run"] == [seconds, 2]


def test_cache_info_and_clear(tmp_path, monkeypatch):
    from mbdsim._jitcache import _digest
    from mbdsim.cli.app import app
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    stale = tmp_path / "0123456789abcdef" / "mbdsim" / "solvers"
    stale.mkdir(parents=True)
    (stale / "fastdop.run-1.py311.nbi").write_bytes(b"x" * 100)
    (tmp_path / "someone_elses_numba_cache").mkdir()
    current = tmp_path / _digest() / "mbdsim"
    current.mkdir(parents=True)
    (current / "k.nbi").write_bytes(b"y" * 10)
    r = CliRunner().invoke(app, ["cache", "info"])
    assert r.exit_code == 0, r.output
    assert str(tmp_path) in r.output and f"current {_digest()}  1 kernels" in r.output
    assert "stale   0123456789abcdef  1 kernels, 100 B" in r.output
    r = CliRunner().invoke(app, ["cache", "clear", "--stale"])
    assert r.exit_code == 0 and "removed 1 cached version(s), 100 B" in r.output
    assert not stale.exists() and current.exists() and (tmp_path / "someone_elses_numba_cache").exists()
    r = CliRunner().invoke(app, ["cache", "clear"])
    assert r.exit_code == 0 and not current.exists() and (tmp_path / "someone_elses_numba_cache").exists()


def test_help_imports_no_engine():
    """`mbdsim --help` loads the command line only (no numpy, numba or the engine; issue 32: within 0.3 s)."""
    code = ("import sys; from mbdsim.cli.app import main\n"
            "try:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
            "heavy = [m for m in ('numpy', 'numba', 'scipy', 'pandas', 'mbdsim.solvers', 'typer.rich_utils') "
            "if m in sys.modules]\nprint('HEAVY', heavy)")
    env = dict(os.environ, PYTHONPATH=str(Path(mbdsim.__file__).resolve().parents[1]))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
    assert "HEAVY []" in out.stdout, out.stdout[-500:] + out.stderr[-2000:]
