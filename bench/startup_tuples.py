"""Issue 32 prototype: numba's compile time per function that takes a 200-array model (bench/RESULTS.md, Start-up).

    python3 bench/startup_tuples.py flat|sub|struct K

A chain of K jitted functions g0..g(K-1), each calling the previous and reading one array, under a loop:
flat: the whole 200-array tuple passed at every call (as the kernels pass cm/wk); sub: only the array used;
struct: a numba StructRef of the 200 arrays (one pointer) with getitem on literal ints, so `cm[46]` still
works. The compile time's slope in K is the cost per non-inlined function (no numba cache involved).
"""
import sys, time
import numpy as np
from numba import njit, types
variant, K = sys.argv[1], int(sys.argv[2]); N = 200
arrs = tuple(np.ones(4) if i % 3 else np.ones((2, 2)) for i in range(N))
t0 = time.perf_counter()
if variant == "struct":
    from numba.experimental import structref
    from numba.core.extending import overload
    import operator
    @structref.register
    class CMType(types.StructRef):
        def preprocess_fields(self, fields):
            return tuple((n, types.unliteral(t)) for n, t in fields)
    class CM(structref.StructRefProxy): pass
    structref.define_proxy(CM, CMType, ["f%d" % i for i in range(N)])
    cm = CM(*arrs)
    @overload(operator.getitem)
    def _gi(s, i):
        if isinstance(s, CMType) and isinstance(i, types.IntegerLiteral):
            ns = {}
            exec("def impl(s, i): return s.f%d" % i.literal_value, ns)
            return ns["impl"]
else:
    cm = arrs
g = {"njit": njit}
prev = None
for k in range(K):
    arg = "cm" if variant != "sub" else "a"
    acc = ("cm[%d][0]" % (3 * k + 1)) if variant != "sub" else "a[0]"
    body = "x + %s" % acc if prev is None else "%s(%s, x) * 0.5 + %s" % (prev, arg, acc)
    exec("@njit\ndef g%d(%s, x):\n    return %s\n" % (k, arg, body), g)
    prev = "g%d" % k
exec("@njit\ndef run(cm, n):\n    s = 0.0\n    for i in range(n):\n        s = %s(%s, s)\n    return s\n" % (prev, "cm" if variant != "sub" else "cm[1]"), g)
g["run"](cm, 1)
print(f"{variant:7s} K={K:2d} compile {time.perf_counter() - t0:6.2f} s")
