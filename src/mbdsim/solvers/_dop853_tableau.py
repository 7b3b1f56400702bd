"""The DOP853 tableau (Hairer's coefficients, as scipy ships them) without importing `scipy.integrate`.

`scipy.integrate` pulls in scipy.optimize, scipy.sparse.linalg, scipy.special and more (~17 MB resident)
that the compiled integrator does not need; its coefficient module is plain numpy. It is executed here
from scipy's own file, so the values are scipy's to the last bit; when that file is not where scipy
1.x keeps it, the ordinary import is the fallback.
"""
from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType


def load() -> ModuleType:
    """scipy's `dop853_coefficients` module (A, B, C, E3, E5, D, N_STAGES, ...)."""
    import scipy
    path = Path(scipy.__file__).parent / "integrate" / "_ivp" / "dop853_coefficients.py"
    spec = importlib.util.spec_from_file_location("mbdsim.solvers._dop853_scipy", path) if path.is_file() else None
    if spec is None or spec.loader is None:
        from scipy.integrate._ivp import dop853_coefficients
        return dop853_coefficients
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


coefficients = load()
