"""What a force term is bound to and what binding gives: the simulation's
bodies as a term sees them (:class:`Context`), and the term's row of the
simulation's table of terms (:class:`BoundTerm`)."""

from typing import NamedTuple

import numpy as np

from .._kernels import terms as _k
from ..errors import ForceTermError, UnknownBodyError

__all__ = ["Context", "BoundTerm"]


class BoundTerm(NamedTuple):
    """A term bound to one simulation's bodies: its row of the simulation's
    table of terms (:class:`orbits._kernels.terms.TermTable`), and for a
    :class:`~orbits.forces.UserForce` the term itself, whose functions the
    table calls through a compiled pointer.

    Examples
    --------
    >>> from orbits.forces import Context
    >>> bound = orbits.forces.GRPotential("Star").bind(Context.of(orbits.scenes.kepler()))
    >>> type(bound).__name__, bound.args[0]    # the source's internal index
    ('BoundTerm', 0)
    """

    row: _k.TermRow
    user: object = None     # the UserForce, for a term of the user's functions

    @property
    def args(self):
        """The row's integers, then its reals, then its per-body values, if any."""
        r = self.row
        return tuple(r.ints) + tuple(r.reals) + (() if r.per_body is None else (r.per_body,))


class Context(NamedTuple):
    """What a term sees of the simulation when it is bound."""

    names: list         # body names, in the internal order (massive bodies first)
    m: np.ndarray       # masses, internal order
    gm: np.ndarray      # G times the masses
    n_active: int
    units: object       # the UnitSystem
    bare_ok: bool       # plain numbers are read in the body set's units
    order: np.ndarray   # internal row i is the body set's row order[i]
    x_user: np.ndarray  # the initial state in the body set's order
    v_user: np.ndarray

    @classmethod
    def of(cls, bodies):
        """The context of a body set in the order a simulation holds it
        (massive bodies first), its plain numbers not read: what examples and
        tests bind terms to.

        Examples
        --------
        >>> from orbits.forces import Context
        >>> ctx = Context.of(orbits.scenes.kepler())
        >>> ctx.names, ctx.n_active
        (['Star', 'Planet'], 2)
        """
        m = bodies.masses.value
        order = np.argsort(m == 0, kind="stable")
        return cls([bodies.names[k] for k in order], m[order], bodies.units.G * m[order],
                   int(np.sum(m > 0)), bodies.units, False, order, bodies.positions.value,
                   bodies.velocities.value)

    def index(self, name, term, field):
        """The internal index of body ``name``, or a named error."""
        try:
            return self.names.index(name)
        except ValueError:
            shown = ", ".join(map(repr, self.names[:10])) + (
                f", ... ({len(self.names)} bodies)" if len(self.names) > 10 else "")
            raise UnknownBodyError(
                f"{term} names body {name!r} as its {field}, but the body set has no "
                f"such body (bodies: {shown})", body=name, field=field) from None

    def massive_index(self, name, term, field, role):
        """The internal index of body ``name``, which must have mass: it is the
        term's ``role`` (``"source"``, ``"oblate body"``...)."""
        i = self.index(name, term, field)
        if not self.m[i] > 0:
            raise ForceTermError(f"the {role} {name!r} has no mass", term=term, field=field,
                                 body=name)
        return i
