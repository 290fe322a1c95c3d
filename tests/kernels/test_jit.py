"""The package's numba options (orbits._kernels._jit)."""

import numba
import numpy
import pytest
from numba.core import types as nbtypes

from orbits._kernels import _jit, wh_batch


def test_a_cached_kernel_is_cached_under_the_stamp_of_every_kernel_source():
    # numba keys a cached function by its own file only; a kernel that
    # inlines another file's kernel (the monitor row inlines nothing, but
    # the batch loop inlines the lanes' drift) would load its old
    # compilation after that file changed, so the cache's name carries the
    # hash of every kernel source (as specialize's copies do).  The function
    # keeps its own name.
    from orbits._kernels import invariants
    kernel = invariants.monitor_row
    assert kernel.__qualname__ == kernel.py_func.__qualname__ == "monitor_row"
    index = kernel._cache._cache_file._index_name     # numba's own name of the cache
    assert index.startswith(f"invariants.monitor_row__{_jit.KERNEL_STAMP}")
    batch = wh_batch.advance_lanes._cache._cache_file._index_name
    assert _jit.KERNEL_STAMP in batch


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


def test_a_constant_handed_on_by_value_compiles_the_callee_once():
    # numba types a constant argument as a literal: without value, the
    # callee has one compilation per constant (the first pair of callers)
    @numba.njit
    def callee(a, flag, k):
        return a + k if flag else a - k

    @numba.njit
    def literal_true(a):
        return callee(a, True, 1)

    @numba.njit
    def literal_false(a):
        return callee(a, False, 2)

    assert literal_true(1.0) == 2.0 and literal_false(1.0) == -1.0
    assert len(callee.signatures) == 2

    @numba.njit
    def value_true(a):
        return callee(a, _jit.value(True), _jit.value(1))

    @numba.njit
    def value_false(a):
        return callee(a, _jit.value(False), _jit.value(2))

    assert value_true(1.0) == 2.0 and value_false(1.0) == -1.0
    assert len(callee.signatures) == 3
    assert callee.signatures[2] == (nbtypes.float64, nbtypes.boolean, nbtypes.int64)


def test_a_pointer_is_an_argument_typed_by_its_signature():
    # numba types a Pointer from _numba_type_ and takes its address through
    # the wrapper address protocol; a numba that read neither would fail here
    for kernel, expected in ((_halve, 1.5), (_triple, 9.0)):
        p = _jit.pointer(kernel, _UNARY)
        assert numba.typeof(p) == numba.typeof(p.cfunc)
        assert _call(p, 3.0) == expected
        assert p(3.0) == expected           # from Python: the function as Python
    assert len(_call.signatures) == 1       # one compilation for every such pointer


_FILL = nbtypes.void(nbtypes.float64[:, :], nbtypes.float64, nbtypes.int64[::1])
_call_fill = _jit.address_caller(_FILL)
_call_unary = _jit.address_caller(_UNARY)


def _fill(out, a, flag):
    for i in range(out.shape[0]):
        for d in range(out.shape[1]):
            out[i, d] += a * (3 * i + d)
    flag[0] = 7


@_jit.njit(cache=False)
def _by_address(addresses, out, flag):
    # arrays of other layouts than the signature's are converted (C to A)
    _call_fill(addresses[0], (out, 2.0, flag))
    return _call_unary(addresses[1], (4.0,))


def test_an_address_calls_its_c_callable_with_its_signature():
    # user terms travel as addresses in an int64 array (orbits._kernels.terms);
    # on a numba whose C callables take their arguments otherwise than its
    # first-class functions' prototype, this fails or crashes
    fill = _jit.cfunc(_FILL, _fill)
    for kernel, expected in ((_halve, 2.0), (_triple, 12.0)):
        unary = _jit.pointer(kernel, _UNARY)
        addresses = numpy.array([fill.address, unary.cfunc.address], dtype=numpy.int64)
        out = numpy.ones((2, 3))
        flag = numpy.zeros(1, dtype=numpy.int64)
        assert _by_address(addresses, out, flag) == expected
        assert out.tolist() == [[1.0, 3.0, 5.0], [7.0, 9.0, 11.0]] and flag[0] == 7
    assert len(_by_address.signatures) == 1   # one compilation for every address


def test_an_address_caller_refuses_arguments_of_another_signature():
    with pytest.raises(numba.TypingError):
        _by_address_wrongly(numpy.zeros(2, dtype=numpy.int64))


@_jit.njit(cache=False)
def _by_address_wrongly(addresses):
    return _call_unary(addresses[1], (4.0, 1.0))


def test_a_kernel_pointer_is_its_own_code_cached_under_the_stamp():
    # the C callable of a compiled kernel is the kernel's code (not a function
    # calling it), cached as a kernel is (see the test above)
    p = _jit.pointer(_halve, _UNARY)
    assert p.cfunc._pyfunc.__code__ is _halve.py_func.__code__
    index = p.cfunc._cache._cache_file._index_name
    assert index.startswith(f"test_jit._halve__pointer__{_jit.KERNEL_STAMP}")


@_jit.njit(cache=False)
def _maybe_call(f, call, x):
    if call:
        return f(x)
    return -1.0


def test_an_idle_pointer_is_typed_as_the_pointer_of_its_signature():
    # a loop takes an idle pointer where its data say it calls none (wh's
    # escape check without conditions): the loop compiled for it serves the
    # real pointer of the signature, without a compilation more, and no C
    # callable is compiled for the idle one
    idle = _jit.idle_pointer(_UNARY)
    assert idle.cfunc is None and idle.__wrapper_address__() > 0
    assert _jit.idle_pointer(_UNARY) is idle
    real = _jit.pointer(_halve, _UNARY)
    assert numba.typeof(real) == idle._numba_type_
    assert _maybe_call(idle, False, 4.0) == -1.0
    assert _maybe_call(real, True, 4.0) == 2.0
    assert len(_maybe_call.signatures) == 1


# -- templates and their slots (specialize) ---------------------------------------

_kernel, _scale = _jit.slots("_kernel", _scale=2.0)


def _template(x):
    return _scale * _kernel(x)


def test_called_makes_one_copy_of_a_kernel_and_calling_a_copy_is_the_copy():
    # a loop whose drift is already called (wh's scalar loop) hands it on as
    # its owed drift too: a second call of called must not compile the same
    # code again under another name (it did, 3 s of a first wh run)
    once = _jit.called(_halve)
    assert _jit.called(_halve) is once
    assert _jit.called(once) is once
    assert once.py_func.__name__ == f"_halve__called__{_jit.KERNEL_STAMP}"
    # a copy without numba's runtime is another function, under another name
    # (numba's disk cache keys a compilation by name, code and types alone)
    bare = _jit.called(once, nrt=False)
    assert bare is not once and _jit.called(bare, nrt=False) is bare
    assert once(3.0) == bare(3.0) == 1.5
    names = {_jit.called(_halve, nrt=r).py_func.__qualname__ for r in (True, False)}
    assert len(names) == 2


def test_compiled_for_is_the_code_a_call_runs_typed_once():
    # the code numba runs for the arguments' types, called without typing them
    # again (scipy's solvers call the force so, once an evaluation): the same
    # result as the dispatcher's, and on a numba whose dispatcher.compile does
    # not return that code this fails (orbits._kernels._jit.compiled_for)
    pointer = _jit.pointer(_halve, _UNARY)
    args = (2.0, (3.0, pointer.cfunc))    # a table holds its C callables so
    code = _jit.compiled_for(_apply_held, *args)
    assert code is not _apply_held and callable(code)
    assert code(*args) == _apply_held(*args) == 1.5 + 2.0
    assert len(_apply_held.signatures) == 1          # the same compilation
    # a plain Python function is its own code
    assert _jit.compiled_for(_triple, 1.0) is _triple


@_jit.njit(cache=False)
def _apply_held(a, held):
    b, f = held
    return f(b) + a


def test_specialize_binds_a_declared_slot_and_a_default():
    double = _jit.specialize(_template, "test_double", jit=False, _kernel=lambda x: x + 1.0)
    assert double(1.0) == 4.0              # (1 + 1) * the default scale 2
    triple = _jit.specialize(_template, "test_triple", jit=False, _kernel=abs, _scale=3.0)
    assert triple(-2.0) == 6.0


def test_one_suffix_with_other_bindings_is_another_copy_with_another_name():
    # a loop for a force that reads velocities and one for a force that does
    # not once shared a suffix: the second run took the first one's copy, in
    # the process and from the cache on disk, and stepped with stale
    # velocities.  The bindings name the copy too.
    neg = _jit.specialize(_template, "test_same", jit=False, _kernel=abs)
    assert _jit.specialize(_template, "test_same", jit=False, _kernel=abs) is neg
    other = _jit.specialize(_template, "test_same", jit=False, _kernel=abs, _scale=3.0)
    assert other is not neg and other.__qualname__ != neg.__qualname__
    assert (neg(-2.0), other(-2.0)) == (4.0, 6.0)


def test_one_loop_serves_terms_that_do_and_do_not_read_velocities():
    # whether gravity with terms reads velocities is the terms' table's to
    # say at run time: IAS15 predicts the substeps' velocities for GR, not
    # for GRPotential, from one loop
    import astropy.units as u
    import orbits
    from orbits import forces
    from orbits._kernels import ias15, terms

    def bound(term):
        return orbits.Simulation(orbits.scenes.outer_solar_system(), "ias15", forces=[term])

    gr, potential = bound(forces.GR("Sun")), bound(forces.GRPotential("Sun", c=1 * u.au / u.day))
    assert ias15.ias15_loop(gr._force) is ias15.ias15_loop(potential._force)
    assert terms.table_reads_velocities(gr._fargs[1])
    assert not terms.table_reads_velocities(potential._fargs[1])


def test_specialize_refuses_a_name_that_is_not_a_slot():
    with pytest.raises(TypeError, match="has no slot 'kernel'.*'_kernel', '_scale'"):
        _jit.specialize(_template, "test_typo", jit=False, kernel=abs)


def test_specialize_refuses_a_slot_left_unbound():
    with pytest.raises(TypeError, match="needs its slot '_kernel' bound"):
        _jit.specialize(_template, "test_unbound", jit=False)


def test_an_unbound_slot_cannot_run():
    with pytest.raises(TypeError, match="slot '_kernel' is not bound"):
        _template(1.0)


def test_every_template_module_declares_its_slots():
    # the kernels' templates name no global their module leaves undefined:
    # each such name is a declared slot (compile's bookkeeping of names used
    # by functions, against the module's own names and the builtins)
    import builtins
    import pathlib
    import symtable
    root = pathlib.Path(_jit.__file__).parents[1]
    paths = sorted((root / "_kernels").glob("*.py")) + [root / "_user_functions.py"]
    missing = []
    for path in paths:
        top = symtable.symtable(path.read_text(), str(path), "exec")
        defined = {s.get_name() for s in top.get_symbols() if s.is_assigned() or s.is_imported()}
        defined |= {"__file__", "__name__", "__doc__", "__spec__", "__package__"}
        stack = list(top.get_children())
        while stack:
            tab = stack.pop()
            stack.extend(tab.get_children())
            for sym in tab.get_symbols():
                name = sym.get_name()
                if (sym.is_global() and sym.is_referenced() and name not in defined
                        and not hasattr(builtins, name)):
                    missing.append(f"{path.name}: {name} in {tab.get_name()}")
    assert not missing, missing


def test_no_slot_shadows_a_name_its_module_imports_or_defines():
    # a slot declared after an import of the same name replaces the function
    # with the slot, and a binding that passes the module's name passes the slot
    import ast
    import pathlib
    root = pathlib.Path(_jit.__file__).parents[1]
    clashes = []
    for path in sorted((root / "_kernels").glob("*.py")) + [root / "_user_functions.py"]:
        tree = ast.parse(path.read_text())
        slotted, other = set(), set()
        for node in tree.body:
            names = set()
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                names = {(a.asname or a.name).split(".")[0] for a in node.names}
            elif isinstance(node, (ast.FunctionDef, ast.ClassDef)):
                names = {node.name}
            elif isinstance(node, ast.Assign):
                names = {n.id for t in node.targets for n in ast.walk(t) if isinstance(n, ast.Name)}
                call = node.value
                if isinstance(call, ast.Call) and getattr(call.func, "id", None) == "slots":
                    slotted |= names
                    continue
            other |= names
        clashes += [f"{path.name}: {n}" for n in sorted(slotted & other)]
    assert not clashes, clashes


def test_importing_the_package_first_turns_off_numbas_message_highlighting():
    # numba re-wraps the standard streams for every rejected overload it
    # formats while typing, where colorama is installed (the tests' and docs'
    # extras install it); the package sets numba's documented switch before
    # numba is imported.  A message formatted with highlighting carries ANSI
    # escapes; here it must not (a fresh process: this one imported numba
    # before the package)
    import subprocess
    import sys
    code = ("import orbits, numba\n"
            "@numba.njit\n"
            "def f(x):\n"
            "    return x.no_such_attribute\n"
            "try:\n"
            "    f(1.0)\n"
            "except numba.core.errors.TypingError as e:\n"
            "    print(repr(str(e)))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert "no_such_attribute" in out
    assert "\\x1b[" not in out
