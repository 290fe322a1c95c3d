"""A user's compiled functions as pointers of declared signatures, cached by their code.

A compiled loop that called a user's function by name would be a new loop for
every function, compiled again in every process (numba cannot cache a loop
that binds a function it did not compile from a file).  Here each user
function is wrapped in a small function of a fixed signature, compiled as a C
callable (``numba.cfunc``) and cached on disk under a name made from the
user's code (:func:`code_key`); the loops take the pointer as an argument of
that signature (numba's first-class function types), so one cached loop
serves every user function, and a new process loads both from the cache.

A wrapper cannot raise into the loop (an exception in a C callable is printed
and dropped), so a function that returns the wrong shape or raises fills the
accelerations with NaN and sets ``flag[0]`` (:data:`FORCE_SIZE`,
:data:`RAISED`, ...): the loop stops as for a non-finite state at the last
good state, and the caller names the cause.  A potential that raises gives a
NaN energy.
"""

import hashlib
import math
import sys
import types

import numpy as np
from numba.core import types as nbtypes

from ._kernels._jit import KERNEL_STAMP, bound_globals, cfunc, slots, specialize
from ._kernels import terms as _kterms

# the names the templates below are written against, bound by specialize
adder, head, tail, user, user_accel, user_jac, user_potential = slots(
    "adder", "head", "tail", "user", "user_accel", "user_jac", "user_potential")

__all__ = ["code_key", "cacheable", "term_pointers", "try_term", "pointers_run",
           "force_pointer", "force_args", "jacobian_pointer", "FORCE_SIZE", "JACOBIAN_SIZE",
           "RAISED", "JACOBIAN_RAISED"]

#: ``flag[0]`` after a user function returned the wrong number of values
FORCE_SIZE = 1
#: ``flag[0]`` after a user's Jacobian returned matrices of the wrong shape
JACOBIAN_SIZE = 2
#: ``flag[0]`` after a user's force raised an exception
RAISED = 3
#: ``flag[0]`` after a user's Jacobian raised an exception
JACOBIAN_RAISED = 4

_SIMPLE = (bool, int, float, complex, str, bytes, type(None))


def _describe_value(value):
    # what of a global or a closure cell numba freezes into the compiled code
    if isinstance(value, _SIMPLE):
        return repr(value)
    if isinstance(value, np.ndarray):
        return f"ndarray{value.shape}{value.dtype}" + hashlib.sha1(
            np.ascontiguousarray(value).tobytes()).hexdigest()
    if isinstance(value, (tuple, list)):
        return "(" + ",".join(_describe_value(v) for v in value) + ")"
    py = getattr(value, "py_func", None)
    if py is not None:
        return "jit:" + code_key(value)
    if isinstance(value, types.ModuleType):
        return "module:" + value.__name__
    return "object:" + type(value).__qualname__


def _code_text(code, out):
    out.append(code.co_code)
    out.append(repr(code.co_names).encode())
    out.append(repr(code.co_varnames).encode())
    for c in code.co_consts:
        if isinstance(c, types.CodeType):
            _code_text(c, out)
        else:
            out.append(repr(c).encode())


def code_key(func, _seen=None):
    """A short hash of what numba compiles of ``func`` (a numba dispatcher or a
    Python function): its module and name, its byte code and constants, the
    simple values of the globals and closure cells it reads (numba freezes
    them), and the functions it calls, recursively.  Editing any of them gives
    a new key, so a cached wrapper is never reused for changed code."""
    py = getattr(func, "py_func", func)
    seen = set() if _seen is None else _seen
    if id(py) in seen:
        return "recursive"
    seen.add(id(py))
    parts = [f"{py.__module__}:{py.__qualname__}".encode()]
    code = py.__code__
    _code_text(code, parts)
    glob = py.__globals__
    for name in code.co_names:
        if name in glob:
            value = glob[name]
            parts.append(name.encode())
            if getattr(value, "py_func", None) is not None:
                parts.append(code_key(value, seen).encode())
            else:
                parts.append(_describe_value(value).encode())
    for cell in py.__closure__ or ():
        try:
            parts.append(_describe_value(cell.cell_contents).encode())
        except ValueError:  # an empty cell
            parts.append(b"empty")
    parts.append(repr(getattr(func, "targetoptions", {})).encode())
    return hashlib.sha1(b"\0".join(parts)).hexdigest()[:16]


def cacheable(func):
    """Whether code compiled with ``func`` can be cached on disk: a new
    process finds it again by its module and qualified name (numba's cache
    refers to the functions a compiled function calls that way).  A function
    made by ``exec`` in a namespace that is no module, as some documentation
    and notebook tools do, cannot be found: code that calls it is compiled
    in each process instead of failing to load."""
    py = getattr(func, "py_func", func)
    obj = sys.modules.get(getattr(py, "__module__", None) or "")
    if obj is None:
        return False
    for part in py.__qualname__.split("."):
        obj = getattr(obj, part, None)
        if obj is None:
            return False
    return getattr(obj, "py_func", obj) is py


def _cfunc(template, signature, suffix, cache=True, **bindings):
    # a copy of template with bindings as its globals, compiled as a C
    # callable, cached on disk with cache
    glob = bound_globals(template, bindings)
    name = f"{template.__name__}__{suffix}__{KERNEL_STAMP}"
    func = types.FunctionType(template.__code__, glob, name, template.__defaults__,
                              template.__closure__)
    func.__qualname__ = name
    func.__module__ = template.__module__
    return cfunc(signature, func, cache=cache)


# -- user terms of a simulation (orbits.forces.UserForce) ------------------------------

def _term_add(x, v, t, pos, xu, vu, mu, flag, acc):
    # the user's rows are the body set's order; internal row pos[k] is user row k
    n = pos.shape[0]
    for k in range(n):
        for d in range(3):
            xu[k, d] = x[pos[k], d]
            vu[k, d] = v[pos[k], d]
    failed = 0
    try:
        a = user(xu, vu, t, mu)
        if a.shape[0] != n or a.shape[1] != 3:
            failed = FORCE_SIZE
    except Exception:  # noqa: BLE001 - any exception of the user's: named by the caller
        failed = RAISED
    if failed:
        flag[0] = failed
        for k in range(n):
            for d in range(3):
                acc[pos[k], d] = math.nan
        return
    for k in range(n):
        for d in range(3):
            acc[pos[k], d] += a[k, d]


def _term_chain(x, v, t, pos, xu, vu, mu, flag, acc):
    head(x, v, t, pos, xu, vu, mu, flag, acc)
    tail(x, v, t, pos, xu, vu, mu, flag, acc)


def _term_none(x, v, t, pos, xu, vu, mu, flag, acc):
    pass


def _term_pointer(x, v, t, pos, xu, vu, mu, flag, acc):
    adder(x, v, t, pos, xu, vu, mu, flag, acc)


def _potential_one(x, pos, xu, mu):
    for k in range(pos.shape[0]):
        for d in range(3):
            xu[k, d] = x[pos[k], d]
    try:
        return user_potential(xu, mu)
    except Exception:  # noqa: BLE001 - a monitor of NaN, which the user sees
        return math.nan


def _potential_chain(x, pos, xu, mu):
    return head(x, pos, xu, mu) + tail(x, pos, xu, mu)


def _potential_none(x, pos, xu, mu):
    return 0.0


def _potential_pointer(x, pos, xu, mu):
    return adder(x, pos, xu, mu)


_POINTERS = {}


def term_pointers(terms):
    """The compiled pointers ``(accel, energy)`` of :data:`~orbits._kernels.terms.USER_ACCEL`
    and :data:`~orbits._kernels.terms.USER_ENERGY` that add up the
    :class:`~orbits.forces.UserForce` terms ``terms``: compiled once for their
    code and cached on disk, so a new process loads them."""
    keys = tuple((code_key(t.func), None if t.potential is None else code_key(t.potential))
                 for t in terms)
    if keys in _POINTERS:
        return _POINTERS[keys]
    cache = all(cacheable(t.func) and (t.potential is None or cacheable(t.potential))
                for t in terms)
    add = specialize(_term_none, "none")
    pot = specialize(_potential_none, "none")
    akey = "none"
    pkey = "none"
    for term, (fk, pk) in reversed(list(zip(terms, keys))):
        one = specialize(_term_add, fk, cache=cache, user=term.func)
        akey = f"{fk}_{akey}" if akey != "none" else fk
        add = specialize(_term_chain, hashlib.sha1(akey.encode()).hexdigest()[:16],
                         cache=cache, head=one, tail=add)
        if pk is not None:
            pone = specialize(_potential_one, pk, cache=cache, user_potential=term.potential)
            pkey = f"{pk}_{pkey}" if pkey != "none" else pk
            pot = specialize(_potential_chain, hashlib.sha1(pkey.encode()).hexdigest()[:16],
                             cache=cache, head=pone, tail=pot)
    suffix = hashlib.sha1(f"{akey}|{pkey}".encode()).hexdigest()[:16]
    out = (_cfunc(_term_pointer, _kterms.USER_ACCEL, suffix, cache=cache, adder=add),
           _cfunc(_potential_pointer, _kterms.USER_ENERGY, suffix, cache=cache, adder=pot))
    _POINTERS[keys] = out
    return out


def try_term(term, x, v, mu):
    """Calls the pointers of the :class:`~orbits.forces.UserForce` ``term``
    alone (:func:`term_pointers`) on the state ``x``, ``v`` at t = 0 with
    masses ``mu`` (the body set's order): ``(acc, energy)``, or None where
    the pointers did not compile or the function returned the wrong shape
    or raised (the flag), and the caller must find out how by calling the
    function itself.

    The pointers are the run's own, loaded from the cache in a new process:
    a check through them compiles nothing of the user's (a call from Python
    would compile the function for Python's arguments)."""
    try:
        accel, energy = term_pointers([term])
    except Exception:  # a typing error: the caller's own call names it
        return None
    n = x.shape[0]
    u = _kterms.user_terms(accel.address, energy.address, np.arange(n, dtype=np.int64),
                           np.ascontiguousarray(mu, dtype=np.float64), term.velocity_dependent)
    x = np.ascontiguousarray(x, dtype=np.float64).copy()
    v = np.ascontiguousarray(v, dtype=np.float64).copy()
    acc = np.zeros((n, 3))
    _kterms.user_accel(u, x, v, 0.0, acc)
    if _kterms.user_flag(u) != 0:
        return None
    return acc, _kterms.user_energy(u, x)


def pointers_run(accel, jac, x, v, t, shape):
    """Whether the pointers of a user's compiled ``accel`` (and ``jac``, or
    None) for :func:`orbits.integrate` run cleanly once on the state ``x``,
    ``v`` (the loops' (rows, 3) arrays) at ``t``, for a state of ``shape``:
    they compile (or load), return as many values as the state has, and
    raise nothing (the flag stays 0).  Where not, the caller calls the functions themselves to
    name the cause; where so, a new process has compiled nothing of the
    user's to check them (as :func:`try_term`)."""
    from ._kernels import jacobians as _jacobians
    from ._kernels import stepping as _stepping
    try:
        fargs = force_args(accel, shape)
        if jac is not None:
            fargs = fargs + (jacobian_pointer(jac, len(shape)),)
    except Exception:  # a typing error: the caller's own call names it
        return False
    m = x.size
    _stepping.user_force_call()(x.copy(), v.copy(), float(t), fargs, np.zeros_like(x))
    if jac is not None and fargs[3][0] == 0:
        _jacobians.user_jacobian_call()(x.copy(), v.copy(), float(t), fargs,
                                        np.zeros((m, m)), np.zeros((m, m)))
    return fargs[3][0] == 0


# -- a user's force replacing gravity (orbits.integrate) ----------------------------------

_C2 = nbtypes.float64[:, ::1]


def force_signature(ndim):
    """The signature of :func:`force_pointer`'s pointer for a state of ``ndim``
    dimensions: ``(x, v, t, size, shape, flag, acc)``."""
    return nbtypes.void(_C2, _C2, nbtypes.float64, nbtypes.int64,
                        nbtypes.UniTuple(nbtypes.int64, ndim), nbtypes.int64[::1], _C2)


def _force_pointer(x, v, t, size, shape, flag, acc):
    # the user's arrays (any shape, size values) fill the (rows, 3) state
    # arrays in order; the padding stays zero
    xu = x.ravel()[:size].reshape(shape)
    vu = v.ravel()[:size].reshape(shape)
    flat = acc.ravel()
    failed = 0
    try:
        a = np.asarray(user_accel(xu, vu, t)).ravel()
        if a.size != size:
            failed = FORCE_SIZE
    except Exception:  # noqa: BLE001 - any exception of the user's: named by the caller
        failed = RAISED
    if failed:
        flag[0] = failed
        for i in range(size):
            flat[i] = math.nan
        return
    for i in range(size):
        flat[i] = a[i]


def force_pointer(accel, ndim):
    """The compiled pointer of ``accel(x, v, t)`` for a state of ``ndim``
    dimensions (:func:`force_signature`), cached on disk for its code."""
    key = (code_key(accel), ndim)
    if key not in _POINTERS:
        _POINTERS[key] = _cfunc(_force_pointer, force_signature(ndim), f"{key[0]}_{ndim}",
                                cache=cacheable(accel), user_accel=accel)
    return _POINTERS[key]


_A2 = nbtypes.float64[:, :]


def jacobian_signature(ndim):
    """The signature of :func:`jacobian_pointer`'s pointer for a state of
    ``ndim`` dimensions: ``(x, v, t, size, shape, flag, jx, jv)``."""
    return nbtypes.void(_C2, _C2, nbtypes.float64, nbtypes.int64,
                        nbtypes.UniTuple(nbtypes.int64, ndim), nbtypes.int64[::1], _A2, _A2)


def _jacobian_pointer(x, v, t, size, shape, flag, jx, jv):
    # the user's (size, size) matrices over the flattened state fill the
    # leading block of jx, jv (orbits._kernels.jacobians.user_jacobian)
    xu = x.ravel()[:size].reshape(shape)
    vu = v.ravel()[:size].reshape(shape)
    failed = 0
    try:
        dadx, dadv = user_jac(xu, vu, t)
        jxu = np.asarray(dadx)
        jvu = np.asarray(dadv)
        if jxu.shape[0] != size or jxu.shape[1] != size or jvu.shape[0] != size \
                or jvu.shape[1] != size:
            failed = JACOBIAN_SIZE
    except Exception:  # noqa: BLE001 - any exception of the user's: named by the caller
        failed = JACOBIAN_RAISED
    if failed:
        flag[0] = failed
        for p in range(size):
            for q in range(size):
                jx[p, q] = math.nan
                jv[p, q] = math.nan
        return
    for p in range(size):
        for q in range(size):
            jx[p, q] = jxu[p, q]
            jv[p, q] = jvu[p, q]


def jacobian_pointer(jac, ndim):
    """The compiled pointer of a user's ``jac(x, v, t) -> (da/dx, da/dv)``
    for a state of ``ndim`` dimensions (:func:`jacobian_signature`), cached
    on disk for its code, as :func:`force_pointer`."""
    key = ("jacobian", code_key(jac), ndim)
    if key not in _POINTERS:
        _POINTERS[key] = _cfunc(_jacobian_pointer, jacobian_signature(ndim),
                                f"{key[1]}_{ndim}", cache=cacheable(jac), user_jac=jac)
    return _POINTERS[key]


def force_args(accel, shape):
    """The ``fargs`` of :func:`orbits._kernels.stepping.user_force` for a
    compiled ``accel`` on a state of ``shape``: ``(size, shape, pointer, flag)``."""
    shape = tuple(int(s) for s in shape)
    size = 1
    for s in shape:
        size *= s
    return (size, shape, force_pointer(accel, len(shape)), np.zeros(1, dtype=np.int64))
