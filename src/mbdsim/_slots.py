"""The compiled model's and work arrays as the kernels take them: `Slots`, one pointer (issue 32).

The kernels take the compiled model ``cm`` (`system.compiled.CompiledModel.arrays()`, about 50 slots,
some of them nested tuples) and the work arrays ``wk`` (`Work.arrays()`) and read them as ``cm[9]``,
``wk[44][2]``. Passed as numba tuples, each of about 200 arrays, every compiled function that takes them
has some 1,400 scalar arguments (numba flattens a tuple of array structs), and numba and LLVM spend ~4 s
on each such function (bench/RESULTS.md, Cold compile; bench/startup_tuples.py). A `Slots` holds the same
tuple in compiled storage and reaches the kernels as one pointer: ``cm[k]`` with a literal k is a load of
slot k from that storage (`_lower_slot`), so kernel bodies read their slots exactly as from a tuple, and
a slot appended to `arrays()` / `Work` needs no edit here.

Lifetime and sharing: the storage is a numba structref (`_OwnerType`, NRT-managed) holding a reference to
every array of the tuple; the Python `Slots` keeps it and the tuple alive. The arrays are shared, not
copied: what Python writes into them is what the kernels read. A kernel never owns a `Slots` (it is a
plain pointer to them, no reference counting), so it must not outlive its Python `Slots`, which the
runs hold for as long as they call kernels. In Python a `Slots` indexes, slices, iterates and has a length
as the tuple it holds.
"""
from __future__ import annotations

import operator

from numba import typeof, types
from numba.core import cgutils, imputils
from numba.core.datamodel import models
from numba.core.extending import (NativeValue, intrinsic, lower_builtin, overload, register_model,
                                  typeof_impl, unbox)
from numba.core.typing.templates import AbstractTemplate, infer, signature
from numba.experimental import structref

from ._jit import entry


class SlotsType(types.Type):
    """numba type of a `Slots` holding a tuple of type `tup`: a pointer to its compiled storage."""

    def __init__(self, tup):
        self.tup = tup
        super().__init__(name=f"Slots({len(tup)}, {tup})")


register_model(SlotsType)(models.OpaqueModel)


@structref.register
class _OwnerType(types.StructRef):
    """The compiled storage of a `Slots`: one field ``t``, the tuple."""

    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(t)) for name, t in fields)


class _Owner(structref.StructRefProxy):
    """Python handle on the storage (keeps it alive)."""


structref.define_boxing(_OwnerType, _Owner)


def _payload(tup):
    return _OwnerType([("t", tup)]).get_data_type()


class Slots:
    """The tuple `t` of arrays (and nested tuples of arrays) in compiled storage: what the kernels take
    as ``cm`` / ``wk`` (module docstring). Python indexing, slicing, ``len`` and iteration are the tuple's."""

    __slots__ = ("_t", "_owner", "_addr", "_numba_type_")

    def __init__(self, t):
        t = tuple(t)
        self._t = t
        self._owner, self._addr = _store(t)
        self._numba_type_ = SlotsType(typeof(t))

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
        return Slots(t)


@typeof_impl.register(Slots)
def _typeof_slots(val, c):
    return val._numba_type_


@unbox(SlotsType)
def _unbox_slots(typ, obj, c):
    addr = c.pyapi.object_getattr_string(obj, "_addr")
    ptr = c.pyapi.long_as_voidptr(addr)
    c.pyapi.decref(addr)
    return NativeValue(ptr, is_error=c.pyapi.c_api_error())


def _own(t):
    raise NotImplementedError   # compiled only (`_own_impl`)


@overload(_own)
def _own_impl(t):
    typ = _OwnerType([("t", t)])

    def impl(t):
        s = structref.new(typ)
        s.t = t
        return s
    return impl


@intrinsic
def _address(typingctx, s):
    """The address of the storage's payload (its field ``t`` first)."""
    def codegen(context, builder, sig, args):
        ptr = structref._Utils(context, builder, sig.args[0]).get_data_pointer(args[0])
        return builder.ptrtoint(ptr, cgutils.intp_t)
    return types.intp(s), codegen


@entry
def _store(t):
    """The storage of tuple t and its address (compiled once per tuple type, cached)."""
    s = _own(t)
    return s, _address(s)


def _slot_ptr(context, builder, styp, ptr, k):
    """Pointer to slot k in the storage that `ptr` (a SlotsType value) points to."""
    payload = _payload(styp.tup)
    ptype = context.data_model_manager[payload].get_value_type().as_pointer()
    data = cgutils.create_struct_proxy(payload)(context, builder, ref=builder.bitcast(ptr, ptype))
    return cgutils.gep_inbounds(builder, data._get_ptr_by_name("t"), 0, k)


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
