"""The compiled model's and work arrays as the kernels take them: `Slots`, one pointer (issue 32).

The kernels take the compiled model ``cm`` (`system.compiled.CompiledModel.arrays()`, about 50 slots,
some of them nested tuples) and the work arrays ``wk`` (`Work.arrays()`) and read them as ``cm[9]``,
``wk[44][2]``. Passed as numba tuples, of about 200 arrays each, every compiled function that takes them
has some 1,400 scalar arguments (numba flattens a tuple of array structs into its calls), and numba's
wrappers unbox all of them at every call from Python (bench/RESULTS.md, Cold compile;
bench/startup_tuples.py). A `Slots` holds the tuple as numba's own in-memory form of it (each array's
struct: meminfo, parent, nitems, itemsize, data, shape, strides; nested tuples inline, in order) in one
buffer, and reaches the kernels as one pointer to it: ``cm[k]`` with a constant k is a load of slot k from
that buffer (`_lower_slot`), so kernel bodies read their slots exactly as from a tuple, and a slot
appended to `arrays()` / `Work` needs no edit here. The buffer is written here, in Python, from the
arrays' addresses, shapes and strides: nothing is compiled to build it.

Lifetime and sharing: the arrays are shared, not copied (what Python writes into them is what the
kernels read); the `Slots` keeps them alive. Their structs carry no numba reference count (a null
meminfo: reference counting skips them) and their array object as parent, so a kernel may read, write,
slice and pass them on like any argument array, and must not keep them past the call (as any kernel
argument). In Python a `Slots` indexes, slices, iterates and has a length as the tuple it holds.
"""
from __future__ import annotations

import operator

import numpy as np
from numba import typeof, types
from numba.core import cgutils, imputils
from numba.core.datamodel import default_manager, models
from numba.core.extending import NativeValue, intrinsic, lower_builtin, overload, register_model, typeof_impl, unbox
from numba.core.typing.templates import AbstractTemplate, infer, signature

# numba's array struct, one pointer-sized word each (shape and strides: ndim words each)
ARRAY_FIELDS = ("meminfo", "parent", "nitems", "itemsize", "data", "shape", "strides")
if tuple(default_manager.lookup(types.float64[:, ::1])._fields) != ARRAY_FIELDS:   # pragma: no cover
    raise ImportError("mbdsim._slots: this numba's array layout is not the one the kernels' slots are "
                      f"written in ({ARRAY_FIELDS})")


class SlotsType(types.Type):
    """numba type of a `Slots` holding a tuple of type `tup`: a pointer to the tuple in memory."""

    def __init__(self, tup, words: int = -1):
        self.tup = tup
        self.words = words   # the tuple's size in pointer-sized words (not part of the type's identity)
        super().__init__(name=f"Slots({len(tup)}, {tup})")


register_model(SlotsType)(models.OpaqueModel)


class Slots:
    """The tuple `t` of arrays (and nested tuples of arrays) in numba's in-memory form: what the kernels
    take as ``cm`` / ``wk`` (module docstring). Python indexing, slicing, ``len`` and iteration are the tuple's."""

    __slots__ = ("_t", "_buf", "_addr", "_numba_type_")

    def __init__(self, t, numba_type: "SlotsType | None" = None):
        """numba_type: the type of a Slots of the same structure (every slot's dtype, ndim and layout) made
        before, which saves typing the tuple again (~0.7 ms for a Work's 110 arrays); a type whose slot
        count or size in words differs from t's is not used."""
        t = tuple(t)
        words = []
        _words(t, words)
        if numba_type is None or len(numba_type.tup) != len(t) or numba_type.words != len(words):
            key = _structure(t)   # every run compiles its model anew: typed once per structure
            numba_type = _TYPES.get(key)
            if numba_type is None:
                numba_type = SlotsType(typeof(t), len(words))   # (typeof also checks that numba takes every slot)
                if len(_TYPES) < 256:
                    _TYPES[key] = numba_type
        self._numba_type_ = numba_type
        self._t, self._buf = t, np.array(words, dtype=np.intp)
        self._addr = self._buf.ctypes.data

    def __getitem__(self, k):
        return self._t[k]

    def __len__(self) -> int:
        return len(self._t)

    def __iter__(self):
        return iter(self._t)

    def __repr__(self) -> str:
        return f"Slots({len(self._t)} slots)"

    def __reduce__(self):
        return Slots, (self._t,)   # (a copy or another process builds its own storage)

    def replace(self, k: int, value) -> "Slots":
        """A new Slots with slot k replaced by `value` (the other slots shared)."""
        t = list(self._t)
        t[k] = value
        return Slots(t, self._numba_type_)


@typeof_impl.register(Slots)
def _typeof_slots(val, c):
    return val._numba_type_


@unbox(SlotsType)
def _unbox_slots(typ, obj, c):
    addr = c.pyapi.object_getattr_string(obj, "_addr")
    ptr = c.pyapi.long_as_voidptr(addr)
    c.pyapi.decref(addr)
    return NativeValue(ptr, is_error=c.pyapi.c_api_error())


_TYPES: dict = {}   # the SlotsType of each tuple structure met (`_structure`)


def _structure(x):
    """What numba's type of x (an array, or a tuple of them, nested) depends on: each array's dtype, ndim,
    contiguity, alignment and writeability, and the nesting (~0.1 ms for a model's 200 arrays where typeof
    takes several)."""
    if isinstance(x, tuple):
        return tuple(_structure(y) for y in x)
    if not isinstance(x, np.ndarray):
        raise TypeError(f"a kernel slot holds a {type(x).__name__}: only arrays and tuples of arrays")
    f = x.flags
    return x.dtype.str, x.ndim, f.c_contiguous, f.f_contiguous, f.aligned, f.writeable


def _words(x, out: list) -> None:
    """Append numba's in-memory form of x (an array, or a tuple of them, nested) to `out` (words)."""
    if isinstance(x, tuple):
        for y in x:
            _words(y, out)
        return
    if not isinstance(x, np.ndarray):
        raise TypeError(f"a kernel slot holds a {type(x).__name__}: only arrays and tuples of arrays")
    out += (0, id(x), x.size, x.itemsize, x.ctypes.data, *x.shape, *x.strides)


def _slot_ptr(context, builder, styp, ptr, k):
    """Pointer to slot k of the tuple that `ptr` (a SlotsType value) points to."""
    tup = builder.bitcast(ptr, context.get_value_type(styp.tup).as_pointer())
    return cgutils.gep_inbounds(builder, tup, 0, k)


def _index(styp, k):
    n = len(styp.tup)
    if not -n <= k < n:
        raise IndexError(f"slot {k} of a model with {n} slots (system.compiled)")
    return k % n


@infer
class _StaticSlot(AbstractTemplate):
    """``cm[k]``, k a constant: the type of slot k."""

    key = "static_getitem"

    def generic(self, args, kws):
        s, k = args
        if isinstance(s, SlotsType) and isinstance(k, int) and not isinstance(k, bool):
            return signature(s.tup.types[_index(s, k)], *args)


@lower_builtin("static_getitem", SlotsType, types.IntegerLiteral)
def _lower_slot(context, builder, sig, args):
    styp, (ptr, k) = sig.args[0], args
    val = builder.load(_slot_ptr(context, builder, styp, ptr, _index(styp, k)))
    return imputils.impl_ret_borrowed(context, builder, sig.return_type, val)


@overload(operator.getitem)
def _getitem(s, k):
    """``cm[k]`` with k a literal integer reaching getitem (e.g. through a constant variable)."""
    if isinstance(s, SlotsType) and isinstance(k, types.IntegerLiteral):
        i = _index(s, k.literal_value)
        return lambda s, k: _slot(s, i)


@intrinsic
def _slot(typingctx, s, k):
    if not (isinstance(s, SlotsType) and isinstance(k, types.IntegerLiteral)):
        return None
    i = _index(s, k.literal_value)
    ret = s.tup.types[i]

    def codegen(context, builder, sig, args):
        val = builder.load(_slot_ptr(context, builder, s, args[0], i))
        return imputils.impl_ret_borrowed(context, builder, ret, val)
    return ret(s, k), codegen
