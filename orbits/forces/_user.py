"""A force of the user's own (:class:`UserForce`): numba functions compiled
into the same loop as gravity, and how its dictionary names them,
``"module:qualname"``, without holding them: a record's functions come back
from the caller, checked against the names and parameters it records, and
nothing is imported from a name."""

import inspect
import math
from collections.abc import Mapping

import numpy as np

from .._kernels import terms as _k
from ..errors import ForceTermError
from ._base import ForceTerm
from ._binding import BoundTerm

__all__ = ["UserForce"]


class UserForce(ForceTerm):
    """A force of your own, added to gravity and compiled into the same loop.

    Parameters
    ----------
    func : numba-compiled function
        ``func(x, v, t, m) -> a``: positions and velocities (shape (N, 3)),
        time and masses (shape (N,)) in the body set's units and order, and
        the accelerations of this term alone, shape (N, 3).  It must be
        compiled with ``@numba.njit`` so that it runs inside the loop.
    velocity_dependent : bool
        Whether ``a`` reads ``v``.
    potential : numba-compiled function, optional
        ``potential(x, m) -> float``, the term's potential energy, whose
        negative gradient divided by the masses is ``a``: the energy monitor
        adds it, and with ``velocity_dependent=False`` the Wisdom-Holman
        family can take the term.  Without it the term counts as
        non-conservative: its work is integrated into
        :attr:`orbits.Simulation.work` and the energy monitor reports
        ``|E + W - E0| / |E0|``.

    Raises
    ------
    ForceTermError
        ``func`` (or ``potential``) is not a numba function; when bound, ``func``
        returns the wrong shape or a non-finite value on the initial state.

    Examples
    --------
    >>> import numba
    >>> @numba.njit
    ... def drag(x, v, t, m):
    ...     return -1e-6 * v
    >>> term = orbits.forces.UserForce(drag, velocity_dependent=True)

    Its dictionary names the function and does not hold it; the function
    comes back from the caller, by its recorded name or its ``qualname``:

    >>> d = term.to_dict()
    >>> d["type"], d["func"].endswith(":drag"), d["potential"]
    ('UserForce', True, None)
    >>> list(term.functions().values()) == [drag]
    True
    >>> orbits.forces.UserForce.from_dict(d, functions={"drag": drag})
    UserForce(drag, velocity_dependent=True)
    >>> try:
    ...     orbits.forces.UserForce.from_dict(d)
    ... except orbits.ForceTermError as exc:
    ...     print(exc.field, "functions={'drag': ...}" in str(exc))
    func True
    """

    def __init__(self, func, velocity_dependent=False, potential=None):
        for field, f in (("func", func), ("potential", potential)):
            if f is not None and not hasattr(f, "py_func"):
                raise ForceTermError(
                    f"{field} must be compiled with @numba.njit so that it runs inside "
                    f"the compiled loop; got the Python function {f!r} (for a plain "
                    "Python force use orbits.integrate)", term="UserForce", field=field)
        self.func = func
        self.potential = potential
        self.velocity_dependent = bool(velocity_dependent)
        self.conservative = potential is not None
        self.wisdom_holman = self.conservative and not self.velocity_dependent
        self.why_not_wisdom_holman = ("it depends on velocities" if self.velocity_dependent
                                      else "it has no potential")

    takes_functions = True
    #: the parameters of each function, as the class documents them
    _SIGNATURES = {"func": ("x", "v", "t", "m"), "potential": ("x", "m")}

    def to_dict(self):
        """Plain values: the functions by name, ``"module:qualname"``, beside
        whether the term reads velocities.  A dictionary names the functions
        but never holds them: :meth:`from_dict` takes them from its caller,
        and nothing is imported from a name."""
        return {"type": "UserForce", "func": _reference(self.func),
                "velocity_dependent": self.velocity_dependent,
                "potential": _reference(self.potential)}

    def functions(self):
        """The term's functions by the names its dictionary records."""
        return {_reference(f): f for f in (self.func, self.potential) if f is not None}

    @classmethod
    def functions_needed(cls, d):
        """The functions the dictionary ``d`` names, each with what it is.

        Raises
        ------
        ForceTermError
            ``d`` names them in a form other than ``"module:qualname"``, or
            its ``velocity_dependent`` is not a bool.

        Examples
        --------
        >>> orbits.forces.UserForce.functions_needed(
        ...     {"func": "models:pull", "velocity_dependent": False, "potential": "models:pot"})
        {'models:pull': 'UserForce func(x, v, t, m)', 'models:pot': 'UserForce potential(x, m)'}
        """
        if not isinstance(d, Mapping):
            raise ForceTermError(f"a UserForce record must be a dictionary, got {d!r}",
                                 term="UserForce")
        if not isinstance(d.get("velocity_dependent"), bool):
            raise ForceTermError(f"velocity_dependent must be true or false, got "
                                 f"{d.get('velocity_dependent')!r}", term="UserForce",
                                 field="velocity_dependent")
        needed = {}
        for field in ("func", "potential"):
            ref = d.get(field)
            if ref is None and field == "potential":
                continue
            if not _is_reference(ref):
                raise ForceTermError(
                    f"{field} must be named as 'module:qualname', got {ref!r}",
                    term="UserForce", field=field)
            what = f"UserForce {field}({', '.join(cls._SIGNATURES[field])})"
            if field == "func" and d["velocity_dependent"]:
                what += ", velocity-dependent"
            needed[ref] = what
        return needed

    @classmethod
    def from_dict(cls, d, functions=None):
        """The term that :meth:`to_dict` describes, with its functions taken from
        ``functions``.

        Parameters
        ----------
        d : dict
            As :meth:`to_dict` gives it.
        functions : mapping, optional
            Recorded name -> function: the name as the dictionary records it
            (``"module:qualname"``) or its ``qualname`` alone.  Each function
            must have the recorded ``qualname`` and the parameters the class
            documents (``func(x, v, t, m)``, ``potential(x, m)``).

        Raises
        ------
        ForceTermError
            ``functions`` does not give a function the dictionary names (the
            error lists them), or gives one of another name or signature.
        """
        needed = cls.functions_needed(d)
        functions = {} if functions is None else functions
        if not isinstance(functions, Mapping):
            raise ForceTermError(f"functions must be a mapping of recorded names to "
                                 f"functions, got {functions!r}", term="UserForce",
                                 field="functions")
        missing = [ref for ref in needed if _lookup(functions, ref) is None]
        if missing:
            raise ForceTermError(
                "the record names the function(s) "
                + "; ".join(f"{ref!r} ({needed[ref]})" for ref in missing)
                + ", which a record cannot hold; pass them: functions={"
                + ", ".join(f"{_qualname(ref)!r}: ..." for ref in missing) + "}",
                term="UserForce", field="func" if d["func"] in missing else "potential")
        func = _take(functions, d["func"], "func")
        potential = (None if d.get("potential") is None
                     else _take(functions, d["potential"], "potential"))
        return cls(func, velocity_dependent=d["velocity_dependent"], potential=potential)

    def __repr__(self):
        return (f"UserForce({getattr(self.func, '__name__', self.func)}, "
                f"velocity_dependent={self.velocity_dependent})")

    def bind(self, ctx):
        # the body set's row k is internal row pos[k]
        pos = np.argsort(ctx.order)
        self._check(ctx, np.ascontiguousarray(ctx.m[pos]))
        return BoundTerm(_k.TermRow(_k.USER), user=self)

    def _check(self, ctx, m_user):
        # through the run's own pointers, which a new process loads from the
        # cache; only where they fail, or give what is not finite, do the
        # functions' own calls (compiled for Python's arguments) name the cause
        from .. import _user_functions
        x = ctx.x_user
        v = ctx.v_user
        tried = _user_functions.try_term(self, x, v, m_user)
        if tried is not None:
            a, e = tried
            if np.all(np.isfinite(a)) and (self.potential is None or math.isfinite(e)):
                return
        try:
            a = np.asarray(self.func(x.copy(), v.copy(), 0.0, m_user))
        except Exception as exc:  # a numba typing error names the cause
            raise ForceTermError(f"calling func(x, v, t, m) on the initial state failed: "
                                 f"{exc}", term=repr(self), field="func") from None
        if a.shape != x.shape:
            raise ForceTermError(f"func returned an array of shape {a.shape} for "
                                 f"{len(m_user)} bodies; expected accelerations of shape "
                                 f"{x.shape}", term=repr(self), field="func")
        if not np.all(np.isfinite(a)):
            raise ForceTermError("func returned non-finite accelerations on the initial "
                                 "state", term=repr(self), field="func")
        if self.potential is not None:
            e = self.potential(x.copy(), m_user)
            if not (np.ndim(e) == 0 and math.isfinite(float(e))):
                raise ForceTermError(f"potential must return a finite float, got {e!r}",
                                     term=repr(self), field="potential")
        raise ForceTermError("func or potential failed inside the compiled loop on the "
                             "initial state", term=repr(self), field="func")


def _reference(f):
    # how a record names a function: "module:qualname"
    return None if f is None else f"{f.__module__}:{f.__qualname__}"


def _is_reference(ref):
    if not isinstance(ref, str):
        return False
    module, colon, qualname = ref.partition(":")
    return bool(colon and module and qualname)


def _qualname(ref):
    return ref.partition(":")[2]


def _lookup(functions, ref):
    # the caller's function for a recorded name: by the whole name, or its qualname
    if ref in functions:
        return functions[ref]
    return functions.get(_qualname(ref))


def _take(functions, ref, field):
    """The caller's function for the recorded ``ref``, checked against it: its
    ``qualname`` and its parameters (those :class:`UserForce` documents)."""
    f = _lookup(functions, ref)
    given = getattr(f, "__qualname__", None)
    if given != _qualname(ref):
        raise ForceTermError(
            f"the function given for {ref!r} is {f!r} (qualname {given!r}); the record "
            f"names one of qualname {_qualname(ref)!r}", term="UserForce", field=field)
    py_func = getattr(f, "py_func", f)
    want = UserForce._SIGNATURES[field]
    try:
        params = inspect.signature(py_func).parameters.values()
    except (TypeError, ValueError):
        params = None
    positional = (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)
    if params is None or len(params) != len(want) or any(p.kind not in positional
                                                          for p in params):
        raise ForceTermError(
            f"the function given for {ref!r} takes {_signature_text(py_func)}; a UserForce "
            f"{field} takes ({', '.join(want)})", term="UserForce", field=field)
    return f


def _signature_text(f):
    try:
        return str(inspect.signature(f))
    except (TypeError, ValueError):
        return "arguments that cannot be read"
