"""Every numba option the package uses, in one place.

Kernels import :func:`njit` from here instead of from numba so that the
compilation options are the same everywhere and can be changed once.

* ``cache=True``: compiled code is written next to the module, so a new
  process loads it instead of compiling again.
* ``error_model="numpy"``: division by zero gives inf/nan as in numpy instead
  of raising; the Python error model puts a branch before every division and
  stops LLVM from vectorising the pair loops.  Non-finite states are caught
  explicitly by the stepping loops instead.
* ``fastmath`` is off: results must be reproducible and comparable bit for bit.
  The one exception is the parallel gravity kernel, which allows
  re-association of its inner sums so that they vectorise (see there).
* :func:`fma` is a fused multiply-add, ``a * b + c`` with one rounding
  (LLVM's ``llvm.fma``): correctly rounded by IEEE 754 on every machine, so
  the Kepler drift that uses it gives the same bits everywhere, where
  fastmath's contraction would fuse whatever the target allows.  Processors
  with AVX2 have it in hardware; elsewhere LLVM calls the C library's
  ``fma``, which is slower but gives the same result.
* ``nrt=False`` in :func:`specialize` (numba's ``_nrt`` option) compiles a loop
  without reference counting, for loops that allocate nothing.  Every array
  that a kernel inlined with ``inline="always"`` receives is a new reference
  to numba, counted up on entry and down on exit with atomic instructions,
  which also drain the processor's store buffer: in the Wisdom-Holman loop
  they cost more than a kick with nothing to do (benchmarks/RESULTS.md).
  Without the runtime the loop cannot create arrays: numba refuses to
  compile one that tries.
* :func:`value` hands a constant to a compiled (not inlined) function as a
  value of its type: numba types a constant argument (``0``, ``True``, a
  bound slot's flag) as a literal, and compiles the callee once for each
  constant it meets, each a compilation as long as the first.
* :mod:`._inlining` makes numba's ``inline="always"`` quicker to compile
  (each inlined function's front end once, and one copy of its scope per
  copy of its IR): the same code, in half the time for the largest loops.
"""

import ctypes
import functools
import hashlib
import pathlib
import types

import numba
from numba.core import types as nbtypes
from numba.extending import intrinsic

from . import _inlining  # noqa: F401 - installs itself

__all__ = ["njit", "njit_parallel", "specialize", "slots", "Slot", "bound_globals", "called",
           "contiguous_data",
           "compiled_for",
           "cfunc", "pointer", "idle_pointer", "Pointer", "address_caller", "fma", "value",
           "cpu_name",
           "KERNEL_STAMP", "NUMBA_OPTIONS"]

NUMBA_OPTIONS = dict(cache=True, error_model="numpy", fastmath=False, nogil=True)


def njit(func=None, **overrides):
    """``numba.njit`` with the package's options; usable bare or with overrides.

    A cached function's cache carries :data:`KERNEL_STAMP` in its name (see
    :func:`_compile`)."""
    options = dict(NUMBA_OPTIONS, **overrides)
    if func is None:
        return lambda f: _compile(f, options)
    return _compile(func, options)


def _compile(func, options):
    # numba keys a function's on-disk cache by the function's own source file
    # only: a function that inlines a kernel of another file (the batch loop
    # inlines the lanes' drift) would load its old compilation after that
    # kernel changed.  So the cache is named, as specialize names its copies,
    # with the hash of every kernel source: numba reads the name when the
    # dispatcher is made, and the function keeps its own name
    if not options.get("cache"):
        return numba.njit(**options)(func)
    qualname = func.__qualname__
    func.__qualname__ = f"{qualname}__{KERNEL_STAMP}"
    try:
        dispatcher = numba.njit(**options)(func)
    finally:
        func.__qualname__ = qualname
    dispatcher.__qualname__ = qualname
    return dispatcher


def cfunc(signature, func, cache=True, nrt=True):
    """``func`` compiled as a C callable of the declared ``signature``, with the
    package's options: a pointer that compiled loops take as an argument of
    that type (numba's first-class functions), so that one loop serves every
    function of the signature.  Cached on disk (unless ``cache`` is False)
    under ``func``'s qualified name and :data:`KERNEL_STAMP`, as :func:`njit`
    caches (a pointer compiles the kernels it calls into itself).  ``nrt``
    as in :func:`specialize` (and in the name, as :func:`called` names it)."""
    options = {k: v for k, v in NUMBA_OPTIONS.items() if k != "nogil"}
    options["cache"] = cache
    if not nrt:
        options["_nrt"] = False
    qualname = func.__qualname__
    func.__qualname__ = f"{qualname}{'' if nrt else '__bare'}__{KERNEL_STAMP}"
    try:
        return numba.cfunc(signature, **options)(func)
    finally:
        func.__qualname__ = qualname


class Pointer:
    """A C callable (:func:`cfunc`) to hand compiled code as an argument,
    typed at once: numba types a ``CFunc`` argument by building its function
    type anew at every call, and an argument that is a tuple holding one is
    typed element by element in Python, where a tuple of arrays and numbers
    alone takes numba's compiled path, some hundred times quicker (the
    figures are in benchmarks/RESULTS.md).  So a pointer travels as an argument of
    its own, as this object: its type is ready (numba reads
    ``_numba_type_``), and numba takes its address through the wrapper
    address protocol (``__wrapper_address__``, as for any first-class
    function).  Called from Python, it runs the function as Python."""

    __slots__ = ("cfunc", "_numba_type_", "_address")

    def __init__(self, compiled):
        self.cfunc = compiled
        self._numba_type_ = numba.typeof(compiled)
        self._address = compiled.address

    def __wrapper_address__(self):
        return self._address

    def signature(self):
        return self.cfunc._sig

    def __call__(self, *args):
        return self.cfunc(*args)


def pointer(kernel, signature, cache=True, nrt=True):
    """``kernel`` (a compiled function, or a plain one) compiled as a C
    callable of ``signature`` (:func:`cfunc`), as a :class:`Pointer`.  A
    compiled kernel's own code is compiled, cached under its name, not a
    function that calls it, so that a call through the pointer hands the
    arguments over once (a wrapper would hand them on again, which shows
    beside the stopping conditions' 16 arguments, nine of them arrays).
    ``cache``: False where the kernel cannot be cached (it binds a user's
    function); ``nrt``: False for a kernel that allocates nothing, compiled
    without numba's reference counts (see :func:`specialize`)."""
    py = getattr(kernel, "py_func", None)
    if py is None:
        return Pointer(cfunc(signature, kernel, cache, nrt))
    name = f"{py.__name__}__pointer"
    func = types.FunctionType(py.__code__, py.__globals__, name, py.__defaults__,
                              py.__closure__)
    func.__qualname__ = name
    func.__module__ = py.__module__
    return Pointer(cfunc(signature, func, cache, nrt))


#: a C callable that takes nothing and returns 0, for :func:`idle_pointer`
_IDLE = ctypes.CFUNCTYPE(ctypes.c_int64)(lambda: 0)
_IDLE_POINTERS = {}


def idle_pointer(signature):
    """A :class:`Pointer` of ``signature`` that is never to be called: for a
    loop argument the loop calls only where its data say so, in a run whose
    data say not (wh's escape check without stopping conditions).  The loop
    is typed, compiled and cached as for the real pointer of the signature,
    and nothing else is compiled.  numba takes no address of 0: the address
    is that of a C callable that takes nothing and returns the integer 0."""
    found = _IDLE_POINTERS.get(signature)
    if found is None:
        found = _IDLE_POINTERS[signature] = Pointer.__new__(Pointer)
        found.cfunc = None
        found._numba_type_ = nbtypes.FunctionType(signature)
        found._address = ctypes.cast(_IDLE, ctypes.c_void_p).value
    return found


def compiled_for(kernel, *args):
    """The compiled code ``kernel`` runs for arguments of the types of
    ``args`` (compiled now, or loaded from the cache, where need be), as a
    function to call from Python with arguments of exactly those types; a
    plain Python ``kernel`` is returned as it is.

    A call of a compiled function from Python first types every argument:
    arrays and numbers take numba's quick path, but an argument that holds
    a compiled pointer (a table of force terms with a user's term) is typed
    element by element in Python, some milliseconds a call.  A caller that
    calls a kernel many times with the same arguments' types (scipy's
    solvers call the force once an evaluation) types them once here.  The
    function returned converts its arguments by those types without
    checking them: an array of another layout or type is read wrongly, so
    callers hand it C-contiguous float64 arrays as they did the first time.

    Built on the dispatcher's ``compile(signature)``, which returns that
    code; ``tests/kernels/test_jit.py`` fails on a numba where it does not.
    """
    if not isinstance(kernel, numba.core.dispatcher.Dispatcher):
        return kernel
    return kernel.compile(tuple(numba.typeof(a) for a in args))


@intrinsic
def fma(typingctx, a, b, c):
    """``a * b + c`` rounded once (see the module notes); float64 arguments,
    in compiled code only."""
    sig = nbtypes.float64(nbtypes.float64, nbtypes.float64, nbtypes.float64)

    def codegen(context, builder, signature, args):
        return builder.fma(*args)

    return sig, codegen


def cpu_name():
    """The processor numba compiles for (``NUMBA_CPU_NAME`` where set), as
    its cache keys compiled code by it.

    Examples
    --------
    >>> from orbits._kernels._jit import cpu_name
    >>> isinstance(cpu_name(), str) and cpu_name() != ""
    True
    """
    from numba.core import config
    return config.CPU_NAME or _host_cpu_name()


@functools.lru_cache(maxsize=None)
def _host_cpu_name():
    # LLVM's name of this processor: asked once (a run's call asks for it
    # where a lanes' loop may have been compiled by another process)
    import llvmlite.binding as llvm
    return llvm.get_host_cpu_name()


@intrinsic
def value(typingctx, x):
    """``x`` as a value of its type, not the constant it may be (see the module
    notes); in compiled code only."""
    sig = nbtypes.unliteral(x)(x)

    def codegen(context, builder, signature, args):
        return context.cast(builder, args[0], signature.args[0], signature.return_type)

    return sig, codegen


@intrinsic
def contiguous_data(typingctx, a):
    """The data pointer of a C-contiguous array ``a`` (typed ``CPointer`` of
    its dtype), for a C callable that views the array again with
    ``numba.carray``: a pointer is one word, where an array hands over its
    whole structure, and the view it makes counts no references; in
    compiled code only, while the array lives.  Any other layout is a
    typing error."""
    if not isinstance(a, nbtypes.Array) or a.layout != "C":
        return None
    sig = nbtypes.CPointer(a.dtype)(a)

    def codegen(context, builder, signature, args):
        return context.make_array(signature.args[0])(context, builder, args[0]).data

    return sig, codegen


def address_caller(signature):
    """``call(address, args)``, in compiled code only: calls the C callable
    (:func:`cfunc`) of ``signature`` whose address is the integer
    ``address`` (a ``CFunc``'s ``address``) with the tuple ``args``, each
    converted to the signature's type, and returns what it returns.

    A compiled function called from Python types its arguments first, and
    an argument holding a compiled function is typed element by element in
    Python (half a millisecond for a simulation's force arguments), where
    arrays and numbers take numba's quick path.  An address in an int64
    array travels as data: the arguments' type is the same whatever
    function it names, so one compiled loop serves every function of the
    signature.  The address must name a live C callable of that signature:
    the caller keeps the ``CFunc`` alive and never sends the address to
    another process.  The call is the one numba makes for a first-class
    function of the signature (its ``FunctionPrototype``);
    ``tests/kernels/test_jit.py`` fails on a numba where it is not."""
    proto = nbtypes.FunctionPrototype(signature.return_type, signature.args)
    declared = signature.args

    def codegen(context, builder, sig, args):
        address, packed = args
        given = sig.args[1]
        values = [context.cast(builder, builder.extract_value(packed, i), given[i], declared[i])
                  for i in range(len(declared))]
        function = builder.inttoptr(address, context.get_value_type(proto))
        out = builder.call(function, values)
        if signature.return_type == nbtypes.void:
            return context.get_dummy_value()
        return out

    @intrinsic
    def call(typingctx, address, args):
        if not isinstance(address, nbtypes.Integer) or not isinstance(args, nbtypes.BaseTuple):
            return None
        if len(args) != len(declared) or not all(
                typingctx.can_convert(a, d) for a, d in zip(args, declared)):
            return None
        return signature.return_type(nbtypes.int64, args), codegen

    return call


def njit_parallel(func=None, **overrides):
    """Like :func:`njit` but with ``parallel=True`` (threads over ``prange``)."""
    return njit(func, parallel=True, **overrides)


def _stamp():
    # numba only invalidates a cached function when its own file changes, not
    # when a kernel it calls does.  Specialised loops carry a hash of every
    # kernel source in their name, so editing any kernel gives fresh cache keys.
    h = hashlib.sha1()
    for path in sorted(pathlib.Path(__file__).parent.glob("*.py")):
        h.update(path.read_bytes())
    return h.hexdigest()[:10]


KERNEL_STAMP = _stamp()

_SPECIALISED = {}
_BY_IDENTITY = {}


class Slot:
    """A global name that templates are written against and :func:`specialize`
    binds: a kernel (the force, the step's epilogue) or a constant (whether
    the loop integrates work).  Declared at module level with :func:`slots`;
    ``default`` is what an unbound slot takes (None: it must be bound)."""

    __slots__ = ("name", "default")

    def __init__(self, name, default=None):
        self.name = name
        self.default = default

    def __repr__(self):
        return f"Slot({self.name!r})"

    def __call__(self, *args, **kwargs):
        raise TypeError(f"slot {self.name!r} is not bound: only the copies that "
                        f"specialize makes can run")


def slots(*names, **defaults):
    """Declare the slots of a module's templates: ``force, rows = slots("force",
    "rows")``; a keyword declares a slot with its default,
    ``record, = slots(record=_record)``.  Returns the :class:`Slot` objects in
    the order given, names first."""
    return tuple([Slot(n) for n in names] + [Slot(n, d) for n, d in defaults.items()])


def _used_names(code):
    names = set(code.co_names)
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            names |= _used_names(const)
    return names


def bound_globals(template, bindings):
    """The template's globals with its slots bound; an unknown binding and a
    slot left unbound without a default are errors that name them."""
    glob = template.__globals__
    declared = {k for k, v in glob.items() if isinstance(v, Slot)}
    unknown = sorted(set(bindings) - declared)
    if unknown:
        raise TypeError(f"{template.__module__}.{template.__name__} has no slot "
                        f"{', '.join(map(repr, unknown))}; its module declares "
                        f"{', '.join(map(repr, sorted(declared))) or 'none'}")
    used = _used_names(template.__code__) & declared
    bound = dict(glob)
    for name in used:
        if name in bindings:
            continue
        default = glob[name].default
        if default is None:
            raise TypeError(f"{template.__module__}.{template.__name__} needs its slot "
                            f"{name!r} bound")
        bound[name] = default
    bound.update(bindings)
    return bound


def _sign(value):
    # what names a bound value in a copy's name: a kernel by its module and
    # qualified name (a specialised copy's carries its own bindings' digest),
    # a constant by its repr; anything else by its identity, which is correct
    # but differs from process to process (no binding of the package's is
    # such: a test run that raised here instead passed)
    func = getattr(value, "py_func", value)
    if isinstance(func, (types.FunctionType, types.BuiltinFunctionType, type)):
        return f"{func.__module__}.{func.__qualname__}"
    if value is None or isinstance(value, (bool, int, float, str)):
        return repr(value)
    if isinstance(value, tuple):
        return tuple(_sign(v) for v in value)
    return f"{type(value).__qualname__}@{id(value)}"


def _binding_signs(template, glob):
    used = _used_names(template.__code__)
    return tuple(sorted((k, _sign(v.default if isinstance(v, Slot) else v))
                        for k, v in glob.items()
                        if k in used and isinstance(template.__globals__.get(k), Slot)))


def specialize(template, suffix, jit=True, cache=True, inline=False, nrt=True, **bindings):
    """Compile a copy of ``template`` whose global names are bound to ``bindings``.

    A stepping loop is written once, with the force (or another kernel) as a
    global name, a :class:`Slot` its module declares.  Each scene's loop is
    a copy of that code with the name bound to the kernel it needs, compiled and cached under its own name, so a scene
    compiles only the kernels it uses.  (Passing the kernel as an argument
    would defeat numba's on-disk cache; closures do too.)

    Parameters
    ----------
    template : function
        Plain Python function (not yet jitted) written against global names.
    suffix : str
        Distinguishes this copy in the cache; use the names of the bindings.
    jit : bool
        False returns the plain Python copy (for a user's Python force).
    cache : bool
        False when a binding cannot be cached on disk (a user's function).
    inline : bool
        Inline the copy into its callers at numba's IR level (for small wrappers
        called once a step, whose call overhead would otherwise show).
    nrt : bool
        False compiles without numba's runtime, so without reference counts
        (see the module notes); only for code that allocates nothing.
    **bindings
        The template's slots (:func:`slots`) to bind, typically to jitted
        kernels; a name that is not a slot of the template's module is an
        error, as is a slot the template uses that is left unbound without
        a default.
    """
    # the loops are fetched at every call of an integrator's advance: a copy
    # already made is found by the identity of its bindings first (the memo
    # keeps them, so no identity is reused), without naming them
    quick = (template, suffix, jit, cache, inline, nrt,
             tuple(sorted((k, id(v)) for k, v in bindings.items())))
    found = _BY_IDENTITY.get(quick)
    if found is not None:
        return found[0]
    glob = bound_globals(template, bindings)
    # the copy is named by what its slots are bound to as well as by the
    # suffix: two copies under one suffix with different bindings (a loop
    # for a force that reads velocities and one for a force that does not)
    # are two functions, in this process and in the cache on disk
    signs = _binding_signs(template, glob)
    key = (template, suffix, jit, cache, inline, nrt, signs)
    if key in _SPECIALISED:
        _BY_IDENTITY[quick] = (_SPECIALISED[key], bindings)
        return _SPECIALISED[key]
    safe = "".join(ch if ch.isalnum() else "_" for ch in suffix)
    digest = hashlib.sha1(repr(signs).encode()).hexdigest()[:8]
    name = f"{template.__name__}__{safe}__{digest}__{KERNEL_STAMP}"
    func = types.FunctionType(template.__code__, glob, name,
                              template.__defaults__, template.__closure__)
    func.__qualname__ = name
    func.__module__ = template.__module__
    func.__doc__ = template.__doc__
    options = dict(NUMBA_OPTIONS, cache=cache)
    if inline:
        options["inline"] = "always"
    if not nrt:
        options["_nrt"] = False
    result = numba.njit(**options)(func) if jit else func
    _SPECIALISED[key] = result
    _BY_IDENTITY[quick] = (result, bindings)
    return result


_CALLED = {}
_CALLED_COPIES = {}


def called(kernel, nrt=True):
    """``kernel`` (a compiled function, inlined where it is called) as a
    function of its own that callers call instead of inlining: for the paths
    a loop runs rarely (the corrector, an output's synchronisation, the
    conversions at a call's start), where a call costs nothing that shows and
    each inlined copy would cost its compilation again.  The same code, so
    the same results bit for bit; compiled once and cached under the
    kernel's name.  ``nrt`` as in :func:`specialize`."""
    if _CALLED_COPIES.get(kernel) == nrt:
        # already a called copy (with the same runtime): the same function
        return kernel
    key = (kernel, nrt)
    if key in _CALLED:
        return _CALLED[key]
    py = kernel.py_func
    # the runtime in the name as well: numba's cache keys a compilation by the
    # function's name, code and argument types, not by its options, so two
    # copies under one name would share one entry on disk and a new process
    # could load the one with reference counts where the other was asked for
    name = f"{py.__name__}__called{'' if nrt else '_bare'}__{KERNEL_STAMP}"
    func = types.FunctionType(py.__code__, py.__globals__, name, py.__defaults__,
                              py.__closure__)
    func.__qualname__ = name
    func.__module__ = py.__module__
    func.__doc__ = py.__doc__
    options = dict(NUMBA_OPTIONS)
    if not nrt:
        options["_nrt"] = False
    _CALLED[key] = result = numba.njit(**options)(func)
    _CALLED_COPIES[result] = nrt
    return result
