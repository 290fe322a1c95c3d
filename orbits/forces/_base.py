"""The force term: the facts a term declares (:class:`ForceTerm`), the
dictionary it is stored as, and the registry by name that rebuilds a term
from its dictionary (:func:`from_dict`), with the user's functions that a
dictionary names but cannot hold (:func:`functions_needed`,
:func:`functions_of`)."""

import inspect
from collections.abc import Mapping

from .._quantity_json import from_plain, to_plain
from ..errors import ForceTermError

__all__ = ["ForceTerm", "from_dict", "functions_needed", "functions_of"]

_REGISTRY = {}


class ForceTerm:
    """Base class of the force terms; see the notes of :mod:`orbits.forces`.

    A subclass sets the class facts below, implements ``bind(ctx)``, returning
    a :class:`~orbits.forces.BoundTerm`, and names in :attr:`FIELDS` what its
    dictionary holds; it is registered by name for :func:`from_dict` (output
    files and ensembles rebuild terms from their dictionaries).

    Examples
    --------
    >>> from orbits.forces import ForceTerm
    >>> [cls.__name__ for cls in (orbits.forces.GR, orbits.forces.ZonalHarmonics)
    ...  if issubclass(cls, ForceTerm)]
    ['GR', 'ZonalHarmonics']
    >>> orbits.forces.GR.velocity_dependent, orbits.forces.GRPotential.wisdom_holman
    (True, True)
    """

    velocity_dependent = False
    conservative = True
    wisdom_holman = False
    #: why the Wisdom-Holman interaction step cannot take it (for the error)
    why_not_wisdom_holman = ""
    #: whether the term holds functions of the user's, which its dictionary
    #: names but cannot hold: :func:`from_dict` takes them from the caller
    takes_functions = False
    #: the keys of the term's dictionary after ``type``, in order: each the
    #: name of a parameter of the constructor and of the attribute that holds it
    FIELDS = ()
    #: those of :attr:`FIELDS` whose values are Quantities, stored as ``[value, unit]``
    QUANTITIES = ()

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if not cls.__name__.startswith("_"):    # a private base is no term of its own
            _REGISTRY[cls.__name__] = cls

    def bind(self, ctx):
        """Compile the term for one simulation's bodies.

        Parameters
        ----------
        ctx : Context
            The bodies as the simulation holds them (names, masses and ``G m`` in
            the internal order and units).

        Returns
        -------
        BoundTerm
            The kernel and its arguments, in the simulation's units.

        Raises
        ------
        ForceTermError, UnknownBodyError, BodyUnitsError
            A parameter does not fit the body set: a body it names is not in the
            set or has no mass where it needs one, a Quantity is not of its kind.

        Examples
        --------
        >>> from orbits.forces import Context
        >>> bound = orbits.forces.GR("Star").bind(Context.of(orbits.scenes.kepler()))
        >>> bound.args[0], round(1 / bound.args[1] ** 0.5, 1)   # source index; c in au/day
        (0, 173.1)
        """
        raise NotImplementedError

    def to_dict(self):
        """Plain JSON-able values, Quantities as ``[value, unit]``: what output
        files and ensembles store.

        Examples
        --------
        >>> orbits.forces.GRPotential("Sun", c=3e5 * u.km / u.s).to_dict()
        {'type': 'GRPotential', 'source': 'Sun', 'c': [300000.0, 'km / s']}
        """
        d = {"type": type(self).__name__}
        for field in self.FIELDS:
            value = getattr(self, field)
            d[field] = (to_plain(value) if field in self.QUANTITIES
                        else dict(value) if isinstance(value, dict)
                        else list(value) if isinstance(value, list) else value)
        return d

    @classmethod
    def from_dict(cls, d):
        """The term that :meth:`to_dict` describes.

        Raises
        ------
        ForceTermError
            ``d`` lacks a value the constructor needs, or holds one it refuses.

        Examples
        --------
        >>> term = orbits.forces.Migration("Planet", tau_e=-300 * u.yr, primary="Star")
        >>> orbits.forces.Migration.from_dict(term.to_dict()) == term
        True
        """
        needed = [p.name for p in inspect.signature(cls).parameters.values()
                  if p.default is p.empty and p.name not in d]
        if needed:
            raise ForceTermError(f"the record {dict(d)!r} has no {needed[0]!r}",
                                 term=cls.__name__, field=needed[0])
        return cls(**{field: from_plain(d[field]) if field in cls.QUANTITIES else d[field]
                      for field in cls.FIELDS if field in d})

    @classmethod
    def functions_needed(cls, d):
        """The functions the dictionary ``d`` of this term names and
        :func:`from_dict` takes from its caller: recorded name -> what it is
        (none for a term that holds only numbers).

        Examples
        --------
        >>> orbits.forces.GR.functions_needed({"type": "GR", "source": "Sun", "c": None})
        {}
        """
        return {}

    def functions(self):
        """The user's functions this term holds, by the names its dictionary
        records (none for a term that holds only numbers).

        Examples
        --------
        >>> orbits.forces.GR("Sun").functions()
        {}
        """
        return {}

    def __eq__(self, other):
        return type(self) is type(other) and self.to_dict() == other.to_dict()

    def __hash__(self):
        return hash(repr(self))

    def __repr__(self):
        d = self.to_dict()
        d.pop("type")
        args = ", ".join(f"{k}={v!r}" for k, v in d.items() if v is not None)
        return f"{type(self).__name__}({args})"


def from_dict(d, functions=None):
    """The term a :meth:`ForceTerm.to_dict` dictionary describes.

    Nothing a dictionary names is imported: the functions of a
    :class:`~orbits.forces.UserForce` come from ``functions``.

    Parameters
    ----------
    d : dict
        As :meth:`ForceTerm.to_dict` gives it.
    functions : mapping, optional
        The functions the dictionary names (see
        :meth:`~orbits.forces.UserForce.from_dict`): recorded name
        (``"module:qualname"``, or the bare ``qualname``) -> the function.

    Raises
    ------
    ForceTermError
        The dictionary's ``type`` names no known term, or it names a function
        that ``functions`` does not give.

    Examples
    --------
    >>> term = orbits.forces.from_dict({"type": "GR", "source": "Sun", "c": None})
    >>> term
    GR(source='Sun')
    >>> orbits.forces.from_dict(term.to_dict()) == term
    True
    """
    cls = _record_class(d)
    d = dict(d)
    d.pop("type")
    if cls.takes_functions:
        return cls.from_dict(d, functions=functions)
    return cls.from_dict(d)


def _record_class(d):
    # the registered class a term's dictionary names, or a named error
    if not isinstance(d, Mapping):
        raise ForceTermError(f"a force term's record must be a dictionary, got {d!r}")
    name = d.get("type")
    if not isinstance(name, str) or name not in _REGISTRY:
        raise ForceTermError(f"unknown force term type {name!r}; known: "
                             f"{', '.join(sorted(_REGISTRY))}")
    return _REGISTRY[name]


def functions_needed(records):
    """The functions that force terms' dictionaries name but cannot hold.

    Parameters
    ----------
    records : sequence of dict
        :meth:`ForceTerm.to_dict` dictionaries.

    Returns
    -------
    dict
        Recorded name (``"module:qualname"``) -> what it is, in words, for
        every function :func:`from_dict` needs from its caller.

    Raises
    ------
    ForceTermError
        A record names no known term, or names a function in a form that is
        not ``"module:qualname"``.

    Examples
    --------
    >>> orbits.forces.functions_needed([{"type": "UserForce", "func": "models:drag",
    ...                                  "velocity_dependent": True, "potential": None}])
    {'models:drag': 'UserForce func(x, v, t, m), velocity-dependent'}
    """
    needed = {}
    for d in records:
        needed.update(_record_class(d).functions_needed(d))
    return needed


def functions_of(terms):
    """The functions of the user's that ``terms`` hold, by the names their
    dictionaries record: what :func:`from_dict` takes to rebuild them (an
    ensemble ships these with a simulation's configuration).

    Examples
    --------
    A :class:`~orbits.forces.UserForce` holds functions (see its example); a
    term of numbers holds none:

    >>> orbits.forces.functions_of([orbits.forces.GR("Sun"), orbits.forces.GRFull()])
    {}
    """
    out = {}
    for term in terms:
        out.update(term.functions())
    return out
