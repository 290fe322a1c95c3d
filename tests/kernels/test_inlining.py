"""The quicker inlining of orbits._kernels._inlining: the same results as
numba's own inliner, each inlined function's front end run once."""

import math

import numba
import numpy as np
from numba.core import inline_closurecall as icc
from numba.core import ir

from orbits._kernels import _inlining


@numba.njit(inline="always")
def _inner(a, k):
    # a loop, a branch and names that the callers use too
    s = 0.0
    for i in range(a.shape[0]):
        t = a[i] * k
        if t > 0.5:
            s += math.sqrt(t)
        else:
            s -= t * t
    return s


@numba.njit(inline="always")
def _middle(a, b, k):
    s = _inner(a, k)
    t = _inner(b, k + 1.0)
    return s * t + _inner(a, -k)


def _caller(a, b):
    s = 0.0
    t = _middle(a, b, 0.25)
    for i in range(3):
        s += _middle(b, a, 0.5 * i) + _inner(a, i)
    return s + t


def _python(a, b):
    # the same arithmetic without numba
    def inner(a, k):
        s = 0.0
        for x in a:
            t = x * k
            s = s + math.sqrt(t) if t > 0.5 else s - t * t
        return s

    def middle(a, b, k):
        return inner(a, k) * inner(b, k + 1.0) + inner(a, -k)

    s = 0.0
    t = middle(a, b, 0.25)
    for i in range(3):
        s += middle(b, a, 0.5 * i) + inner(a, i)
    return s + t


def test_the_inliner_is_patched_on_this_numba():
    # the numba the package is tested with has the inliner's expected shape;
    # where it has not, the package runs numba's own (slower to compile) path
    assert _inlining.ACTIVE, f"numba {numba.__version__}: the inliner's shape changed"


def test_inlined_code_gives_numbas_own_results_bit_for_bit(monkeypatch):
    runs = []
    own = icc.InlineWorker.run_untyped_passes

    def counted(self, func, enable_ssa=False):
        runs.append(func.__name__)
        return own(self, func, enable_ssa)

    monkeypatch.setattr(icc.InlineWorker, "run_untyped_passes", counted)
    rng = np.random.default_rng(5)
    a, b = rng.uniform(-2.0, 3.0, 17), rng.uniform(0.0, 1.0, 9)
    quick = numba.njit(cache=False)(_caller)
    got = quick(a, b)
    quick_runs = list(runs)
    runs.clear()
    with _inlining.disabled():
        slow = numba.njit(cache=False)(_caller)
        expected = slow(a, b)
    # equal to the bit, and to Python's arithmetic (the same operations in the
    # same order, without fused multiply-adds)
    assert got == expected
    assert got == _python(a, b)
    # numba runs _inner's front end for each of its sites: one in _caller's
    # loop and three in each _middle, whose front end it runs for each of its
    # two sites; here _middle's once, _inner's once, reused at every site
    assert runs.count("_inner") == 7 and runs.count("_middle") == 2
    assert quick_runs.count("_inner") == 1 and quick_runs.count("_middle") == 1


def test_the_blocks_of_one_copy_share_one_copy_of_their_scope():
    loc = ir.Loc("test", 1)
    scope = ir.Scope(None, loc)
    other = ir.Scope(None, loc)
    blocks = []
    for s in (scope, scope, other):
        block = ir.Block(s, loc)
        var = s.redefine("x", loc)
        block.append(ir.Assign(ir.Const(1.0, loc), var, loc))
        blocks.append(block)
    shim = _inlining._SharedMemo(ir.Block)
    shim.reset(True)
    c0, c1, c2 = (shim.deepcopy(b) for b in blocks)
    # copies, their variables' scope copied once for the first two blocks
    assert c0 is not blocks[0] and c0.scope is not scope
    assert c0.scope is c1.scope
    assert c2.scope is not c0.scope
    assert c0.body[0].target.scope is c0.scope
    # inactive: a deep copy of its own for each block, as numba makes
    shim.reset(False)
    d0, d1 = shim.deepcopy(blocks[0]), shim.deepcopy(blocks[1])
    assert d0.scope is not d1.scope
