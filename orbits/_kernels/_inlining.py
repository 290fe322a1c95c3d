"""Quicker inlining in numba's front end: compile time only, the same code.

The kernels inline with numba's ``inline="always"`` (see :mod:`._jit`), and
the loops inline kernels that inline others, so a loop's front end handles
callees of thousands of variables.  Two costs of numba's inliner grow with
that size, and this module removes both for the calls ``inline="always"``
makes (numba's ``InlineWorker.inline_function``):

* **The callee's front end, once per function.**  numba runs the untyped
  pipeline (bytecode to IR, and the inlining of the callee's own callees) on
  the callee again at every call site.  Here its result is kept per function
  and compile options and handed to every later site; numba copies it there
  before changing anything, as it copies a fresh one.
* **One copy of the scope per copy of the IR.**  numba copies a callee's IR
  block by block, each with a deep copy of its own.  Every variable refers to
  the function's scope, which holds all the function's variables, so each
  block's copy copied the whole scope again: the cost went as blocks times
  variables.  Here the blocks of one copy share one memo, so the scope is
  copied once, and the copy's blocks share one scope as the blocks they copy
  do.

The loops that inline most (``wh``, the ensembles' batches) compile in
about two thirds of the time numba's own inliner takes, to the same code;
``python benchmarks/bench_compile.py`` measures it, and the figures are in
benchmarks/RESULTS.md.

Both are applied only where numba's inliner has the shape they were written
against (:func:`_compatible`); elsewhere numba's own path runs unchanged.
:func:`disabled` switches them off for a block (the tests compare).
"""

import contextlib
import copy
import inspect

__all__ = ["ACTIVE", "disabled"]

#: whether numba's inliner is patched here (False where its shape differs)
ACTIVE = False

_enabled = True
_front_ends = {}


@contextlib.contextmanager
def disabled():
    """Compile with numba's own inliner inside the block."""
    global _enabled
    before = _enabled
    _enabled = False
    try:
        yield
    finally:
        _enabled = before


class _SharedMemo:
    """Stands for the :mod:`copy` module inside numba's inliner: while
    ``active``, the deep copies of blocks of one scope share a memo."""

    def __init__(self, block_type):
        self._block_type = block_type
        self.active = False
        self._scope = None
        self._memo = None

    def reset(self, active):
        self.active = active
        self._scope = None
        self._memo = None

    def deepcopy(self, obj, memo=None):
        if self.active and memo is None and isinstance(obj, self._block_type):
            if obj.scope is not self._scope:
                # the first block of another IR (the inliner copies the
                # callee, then copies that copy, whose scope is new)
                self._scope = obj.scope
                self._memo = {}
            return copy.deepcopy(obj, self._memo)
        return copy.deepcopy(obj, memo)

    def __getattr__(self, name):
        return getattr(copy, name)


def _compatible(icc):
    # the names and arguments these wrappers rely on
    worker = getattr(icc, "InlineWorker", None)
    if worker is None or getattr(icc, "copy", None) is not copy:
        return False
    expected = {"inline_function": ["self", "caller_ir", "block", "i", "function", "arg_typs"],
                "inline_ir": ["self", "caller_ir", "block", "i", "callee_ir",
                              "callee_freevars", "arg_typs"],
                "run_untyped_passes": ["self", "func", "enable_ssa"]}
    for name, params in expected.items():
        method = getattr(worker, name, None)
        if method is None or list(inspect.signature(method).parameters) != params:
            return False
    return True


def _install():
    global ACTIVE
    try:
        import numba.core.inline_closurecall as icc
        from numba.core import ir
    except ImportError:  # pragma: no cover - another numba layout
        return
    if not _compatible(icc):  # pragma: no cover - another numba version
        return
    shared = _SharedMemo(ir.Block)
    own = icc.InlineWorker.inline_function

    def inline_function(self, caller_ir, block, i, function, arg_typs=None):
        if not _enabled or self.locals:
            return own(self, caller_ir, block, i, function, arg_typs)
        # numba sets the caller's flags' enable_ssa to False on every such
        # call (its front end for the callee runs without SSA): so here
        self.flags.enable_ssa = False
        key = (function, id(self.typingctx), id(self.targetctx), self.flags.summary())
        callee_ir = _front_ends.get(key)
        if callee_ir is None:
            callee_ir = _front_ends[key] = self.run_untyped_passes(function)
        shared.reset(True)
        try:
            return self.inline_ir(caller_ir, block, i, callee_ir,
                                  function.__code__.co_freevars, arg_typs=arg_typs)
        finally:
            shared.reset(False)

    icc.InlineWorker.inline_function = inline_function
    icc.copy = shared
    ACTIVE = True


_install()
