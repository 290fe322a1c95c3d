"""The one private numba option the kernels use, ``_nrt`` (orbits._kernels._jit):
these fail on a numba that lacks it or ignores it."""

import numba
import numpy as np
import pytest

from orbits._kernels._jit import specialize


def _fill(a):
    for i in range(a.shape[0]):
        a[i] = 2.0 * i


def _allocates(n):
    return np.zeros(n)


def test_a_loop_compiled_without_the_runtime_runs():
    f = specialize(_fill, "test_nrt_off", cache=False, nrt=False)
    a = np.zeros(4)
    f(a)
    assert a.tolist() == [0.0, 2.0, 4.0, 6.0]
    assert f.targetoptions.get("_nrt") is False


def test_without_the_runtime_numba_refuses_to_allocate():
    # if numba ignored the option, this would compile and return an array
    f = specialize(_allocates, "test_nrt_off", cache=False, nrt=False)
    with pytest.raises(numba.core.errors.NumbaError):
        f(3)
