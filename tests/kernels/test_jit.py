"""The package's numba options (orbits._kernels._jit)."""

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
