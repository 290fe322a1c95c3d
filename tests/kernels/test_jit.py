"""The package's numba options (orbits._kernels._jit)."""

import numba
from numba.core import types as nbtypes

from orbits._kernels import _jit, wh_batch


def test_a_cached_kernel_is_cached_under_the_stamp_of_every_kernel_source():
    # numba keys a cached function by its own file only; the batch loop
    # inlines the lanes' drift of another file, and loaded its old
    # compilation after that file changed until the cache's name carried the
    # hash of every kernel source (as specialize's copies do).  The function
    # keeps its own name.
    loop = wh_batch.advance_lanes
    assert loop.__qualname__ == loop.py_func.__qualname__ == "advance_lanes"
    index = loop._cache._cache_file._index_name     # numba's own name of the cache
    assert index.startswith(f"wh_batch.advance_lanes__{_jit.KERNEL_STAMP}")


@_jit.njit(cache=False)
def _fused_and_not(a, b, c):
    return _jit.fma(a, b, c), a * b + c


def test_fma_rounds_once():
    # (1 + 2^-30)(1 - 2^-30) - 1 = -2^-60 exactly; the product rounded first
    # is 1 (2^-60 is below half an ulp of 1), which leaves 0
    a = 1.0 + 2.0 ** -30
    b = 1.0 - 2.0 ** -30
    fused, plain = _fused_and_not(a, b, -1.0)
    assert fused == -2.0 ** -60
    assert plain == 0.0


_UNARY = nbtypes.float64(nbtypes.float64)


@_jit.njit
def _halve(a):
    return 0.5 * a


def _triple(a):
    return 3.0 * a


@_jit.njit(cache=False)
def _call(f, a):
    return f(a)


def test_a_pointer_is_an_argument_typed_by_its_signature():
    # numba types a Pointer from _numba_type_ and takes its address through
    # the wrapper address protocol; a numba that read neither would fail here
    for kernel, expected in ((_halve, 1.5), (_triple, 9.0)):
        p = _jit.pointer(kernel, _UNARY)
        assert numba.typeof(p) == numba.typeof(p.cfunc)
        assert _call(p, 3.0) == expected
        assert p(3.0) == expected           # from Python: the function as Python
    assert len(_call.signatures) == 1       # one compilation for every such pointer


def test_a_kernel_pointer_is_its_own_code_cached_under_the_stamp():
    # the C callable of a compiled kernel is the kernel's code (not a function
    # calling it), cached as a kernel is (see the test above)
    p = _jit.pointer(_halve, _UNARY)
    assert p.cfunc._pyfunc.__code__ is _halve.py_func.__code__
    index = p.cfunc._cache._cache_file._index_name
    assert index.startswith(f"test_jit._halve__pointer__{_jit.KERNEL_STAMP}")
