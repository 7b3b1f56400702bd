"""Warnings shown at the user's line: `warn` points a warning at the caller of the outermost mbdsim
frame (the user's script, test or notebook cell), whatever the depth of the call inside the package
(decorators, solver callbacks), so that `warnings.filterwarnings(module=...)` and the printed location
name the user's code."""
from __future__ import annotations

import os
import sys
import warnings

_PACKAGE = os.path.dirname(os.path.abspath(__file__)) + os.sep


def user_stacklevel() -> int:
    """The `stacklevel` (counted from the caller of this function's caller, as warnings.warn counts from
    its caller) of the frame that called into mbdsim from outside: 1 + the depth of the outermost mbdsim
    frame; 2 when none is found (the direct caller)."""
    frame, level, outside = sys._getframe(2), 2, 2
    while frame is not None:
        if frame.f_code.co_filename.startswith(_PACKAGE):
            outside = level + 1
        frame, level = frame.f_back, level + 1
    return outside


def warn(message: str, category: type[Warning]) -> None:
    """warnings.warn(message, category) at the user's line (see the module docstring)."""
    warnings.warn(message, category, stacklevel=user_stacklevel())
