"""A fingerprint of a Model's content, so that an assembled System (and its compiled model) is reused
only while the Model is exactly what it was: every entity's fields by value (numbers, strings, arrays
by their bytes, containers element by element), functions and other opaque objects by identity.

`assemble_system` keeps the last System of a Model with its fingerprint; any change made since (an
added entity, `body.mass = 2.0`, an array edited in place) gives another fingerprint and a new
assembly.  The walk costs about a microsecond per field (0.35 ms for the chain of 8 rods of bench/).

`model_digests` is the portable variant that a streamed run's checkpoint keeps (mbdsim.solvers.stream): the
same walk with Python functions by their module, qualified name, bytecode, constants, defaults and
closure values instead of their identity (so the same model built in another process has the same
digests; module globals a function reads are not included), one digest per entity ("body 'rod'", "spring 'k'", ...; another entity it refers to counts by
name) and one for the rest of the model ("model": name, gravity, ...), so that a mismatch names what
differs."""
from __future__ import annotations

import hashlib
import struct
import types

import numpy as np

_SCALARS = (bool, int, float, complex, str, bytes, type(None), np.generic)
_OPAQUE = (types.FunctionType, types.BuiltinFunctionType, types.MethodType, type)


def model_fingerprint(model) -> bytes:
    """Digest of everything reachable from `model` (see the module docstring)."""
    return fingerprint(model)[0]


def fingerprint(model) -> tuple[bytes, bool]:
    """(digest, whether a Python callable is reachable: what it returns may change while it stays the
    same object, so results computed by calling it are not cached)."""
    return _walk(model, getattr(model, "__dict__", None))


_KINDS = {"bodies": "body", "joints": "joint", "motions": "motion", "forces": "force", "sensors": "sensor",
          "couplers": "coupler"}


def model_digests(model) -> dict[str, str]:
    """{"model": hex digest of the model's own fields, "<kind> '<name>'": hex digest of each entity} by
    value and portable across processes (see the module docstring)."""
    attrs = {k: v for k, v in getattr(model, "__dict__", {}).items() if k != "_assembled"}
    groups = {k: v for k, v in attrs.items() if isinstance(v, dict) and v and
              all(hasattr(e, "__dict__") and not callable(e) for e in v.values())}
    refs = {id(e): f"{_KINDS.get(g, g)} '{name}'" for g, d in groups.items() for name, e in d.items()}
    rest = {k: (sorted(v) if k in groups else v) for k, v in attrs.items()}
    out = {"model": _walk(rest, None, refs, portable=True)[0].hex()}
    for g, d in groups.items():
        for name, e in d.items():
            out[refs[id(e)]] = _walk(e, None, refs, portable=True)[0].hex()
    return out


def _code(fn) -> list:
    """What a Python function computes, by value: name, bytecode, constants (nested code objects by
    theirs), defaults and closure values."""
    def code(c):
        return [c.co_name, c.co_code, c.co_names,
                [code(k) if isinstance(k, types.CodeType) else k for k in c.co_consts]]
    cells = []
    for cell in fn.__closure__ or ():
        try:
            cells.append(cell.cell_contents)
        except ValueError:   # an empty cell
            cells.append(None)
    return [getattr(fn, "__module__", None), fn.__qualname__, code(fn.__code__), fn.__defaults__,
            fn.__kwdefaults__, cells]


def _walk(root, model_attrs, refs=None, portable=False) -> tuple[bytes, bool]:
    """The digest of everything reachable from `root` (model_attrs: the dict whose "_assembled" entry is
    left out; refs: {id: label} of objects counted by label, except the root; portable: functions by
    value, see model_digests)."""
    parts: list = []
    add = parts.append
    seen: dict[int, int] = {}
    alive = []            # every object seen stays referenced, so no id is reused during the walk
    callables = False
    stack = [root]
    pop, push, extend = stack.pop, stack.append, stack.extend
    while stack:
        obj = pop()
        t = type(obj)
        if t is float:
            add(b"f" + _DOUBLE(obj))
            continue
        if t is str:
            b = obj.encode("utf-8", "surrogatepass")
            add(b"s%d:" % len(b) + b)
            continue
        if t is int or t is bool:
            add(b"i%d" % obj if t is int else (b"T" if obj else b"F"))
            continue
        if obj is None:
            add(b"N")
            continue
        if isinstance(obj, _SCALARS):
            add(b"g" + type(obj).__name__.encode() + repr(obj).encode())
            continue
        k = id(obj)
        if refs and k in refs and obj is not root:   # another entity: by its name
            add(b"R" + refs[k].encode("utf-8", "surrogatepass"))
            continue
        if k in seen:                       # shared or cyclic reference: its position in the walk
            add(b"@%d" % seen[k])
            continue
        seen[k] = len(seen)
        alive.append(obj)
        if t is np.ndarray:
            dt = _DTYPE_NAMES.get(obj.dtype)
            if dt is None:                  # (str(dtype) costs microseconds: once per dtype)
                dt = _DTYPE_NAMES[obj.dtype] = b"A" + str(obj.dtype).encode()
            add(dt + str(obj.shape).encode())
            add(obj.tobytes() if obj.dtype != object else repr(obj.tolist()).encode())
        elif t is dict or isinstance(obj, dict):
            items = [kv for kv in obj.items() if kv[0] != "_assembled"] if obj is model_attrs else obj.items()
            add(b"D%d" % len(items))      # (the model's own cache is not part of it)
            for key, val in items:
                push(val)
                push(key)
        elif t is list or t is tuple or isinstance(obj, (list, tuple)):
            add(b"L%d" % len(obj))
            extend(reversed(obj))
        elif isinstance(obj, (set, frozenset)):
            items = sorted(obj, key=repr)
            add(b"S%d" % len(items))
            extend(reversed(items))
        elif isinstance(obj, types.ModuleType):   # a module (e.g. numpy in a closure): by its name
            add(b"M" + obj.__name__.encode())
        elif t.__module__.startswith("numba.") and isinstance(getattr(obj, "py_func", None), types.FunctionType):
            add(b"J")                       # a numba.njit dispatcher: as the Python function it compiles
            push(obj.py_func)               # (its own fields are numba's caches: megabytes of objects)
        elif t.__module__.startswith("numba.") and isinstance(getattr(obj, "_pyfunc", None), types.FunctionType):
            add(b"K")                       # a numba.cfunc: as its Python function and signature
            push([obj._pyfunc, str(getattr(obj, "_sig", ""))])
        elif t.__module__ == "mbdsim.userfunctions" and t.__name__ == "UserFunction":
            add(b"U")                       # a user function: by name, arity and what it compiles (not its
            push([obj.name, obj.nargs, obj.fn])   # C address, which differs between processes)
        elif portable and isinstance(obj, types.FunctionType):
            add(b"P")
            push(_code(obj))
        elif portable and isinstance(obj, (types.MethodType, types.BuiltinFunctionType, type)):
            add(b"Q" + f"{getattr(obj, '__module__', '')}.{getattr(obj, '__qualname__', '')}".encode())
            if isinstance(obj, types.MethodType):
                push(obj.__func__)
        elif isinstance(obj, _OPAQUE) or not hasattr(obj, "__dict__") and not hasattr(obj, "__slots__"):
            if portable:   # an object without fields of its own (a C extension's): by its type and value
                add(b"Q" + type(obj).__qualname__.encode() + _stable_repr(obj))
                continue
            add(b"O%d" % k)                 # by identity: the same callable (what it computes is run time)
            callables = callables or callable(obj) and not isinstance(obj, type)
        else:
            add(b"C" + t.__qualname__.encode())
            # a user's callable object (mbdsim's own, e.g. expression time functions, are walked by value
            # and hold any user function they wrap, which is flagged there)
            callables = callables or (callable(obj) and not t.__module__.startswith("mbdsim."))
            slots = getattr(t, "__slots__", ())
            if slots:
                push([getattr(obj, n, None) for n in slots])
            if hasattr(obj, "__dict__"):
                push(obj.__dict__)
    return hashlib.blake2b(b"".join(parts), digest_size=20).digest(), callables


def _stable_repr(obj) -> bytes:
    """repr(obj) unless it holds a memory address (then nothing: the type alone counts)."""
    try:
        r = repr(obj)
    except Exception:  # noqa: BLE001 - any repr failure: the type alone counts
        return b""
    return b"" if " at 0x" in r else r.encode("utf-8", "surrogatepass")


_DOUBLE = struct.Struct("<d").pack
_DTYPE_NAMES: dict = {}   # dtype -> b"A" + its name
