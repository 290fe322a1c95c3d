"""Force terms bound to a simulation: the ``forces`` given split into the gravity
term and the added terms (:mod:`orbits.forces`), gravity's kernel and
arguments chosen for the bodies and options, and the added terms compiled
with gravity into one force and its argument tables
(:func:`orbits._kernels.stepping.with_terms`), the pointers of the user's
functions included; the non-conservative terms are chained once more on their
own, for the work the loops integrate.
"""

import math

import numpy as np

from . import _user_functions
from . import forces as _forces
from ._compiling import TERMS, CompileClock
from ._kernels import gravity as _gravity
from ._kernels import stepping as _stepping
from ._kernels import terms as _kterms
from .errors import IntegratorOptionError

__all__ = ["split", "bind_gravity", "bind_terms"]


def split(forces, softening, parallel, rebound_arithmetic):
    """The added terms and the gravity term (with the keywords' options) of ``forces``."""
    if isinstance(forces, _forces.ForceTerm):
        forces = (forces,)
    try:
        forces = tuple(forces)
    except TypeError:
        raise TypeError(f"forces must be a sequence of force terms (orbits.forces), "
                        f"got {forces!r}") from None
    for term in forces:
        if not isinstance(term, _forces.ForceTerm):
            raise TypeError(f"forces must hold force terms of orbits.forces (GR, "
                            f"GRPotential, GRFull, ZonalHarmonics, UserForce, Gravity); "
                            f"got {term!r}")
    gravities = [t for t in forces if isinstance(t, _forces.Gravity)]
    if len(gravities) > 1:
        raise ValueError("forces holds more than one Gravity term; give one")
    keywords = softening is not None or parallel is not None or rebound_arithmetic
    if gravities and keywords:
        raise ValueError("gravity's options are given twice: set softening, parallel and "
                         "rebound_arithmetic either on the Gravity term or as keywords")
    gravity = (gravities[0] if gravities
               else _forces.Gravity(softening, parallel, rebound_arithmetic))
    return tuple(t for t in forces if not isinstance(t, _forces.Gravity)), gravity


def bind_gravity(sim, gravity, parallel_threshold):
    """Newtonian gravity with ``gravity``'s options (an :class:`orbits.forces.Gravity`)
    for the simulation's bodies: its softening in the internal units, the
    kernel (threaded from ``parallel_threshold`` bodies on, unless the term
    says), the compiled force and its arguments."""
    softening = gravity.softening
    eps = 0.0 if softening is None else float(
        sim.units.to_internal(softening, "length", bare_ok=sim._bare_ok, field="softening"))
    if not (eps >= 0 and math.isfinite(eps)):
        raise IntegratorOptionError(f"softening must be a finite length >= 0, got {softening}")
    sim._eps2 = eps * eps
    sim._softening = None if softening is None else sim.units.quantity(eps, "length")
    n = len(sim._m)
    sim.parallel = ((n >= parallel_threshold) if gravity.parallel is None
                    else bool(gravity.parallel))
    sim.rebound_arithmetic = bool(gravity.rebound_arithmetic)
    kind = ("rebound" if sim.rebound_arithmetic else "parallel" if sim.parallel else
            _gravity.serial_kind(n, sim._n_active))
    sim._force = _stepping.gravity_force(kind)
    sim._fargs = _gravity.gravity_args(sim.units.G, sim._m, sim._n_active, sim._eps2,
                                       sim.parallel)
    sim._gm = sim._fargs[0]


def bind_terms(sim, bodies):
    """Compile gravity and the added terms into one force (see :mod:`orbits.forces`).

    The non-conservative terms (``conservative = False``) are tabled once
    more on their own: the loops integrate their work from that table
    (:func:`orbits._kernels.stepping.with_terms`), so that the energy
    monitor can report ``E + W``.  Without such terms the table is empty
    and the loops do no work: the same loops serve both.
    """
    ctx = _forces.Context([sim._names[k] for k in sim._order], sim._m, sim._gm,
                          sim._n_active, sim.units, sim._bare_ok, sim._order,
                          np.ascontiguousarray(bodies._x), np.ascontiguousarray(bodies._v))
    bound = [term.bind(ctx) for term in sim._terms]
    dissipative = [b for term, b in zip(sim._terms, bound) if not term.conservative]
    terms = _kterms.TABLE
    sim._force = _stepping.with_terms(sim._force, terms,
                                       any(t.velocity_dependent for t in sim._terms),
                                       work=terms, dissipative=bool(dissipative))
    table = _term_table(sim, bound, ctx, sim.integrator.reads_jacobians)
    sim._fargs = (sim._fargs, table,
                  _stepping.work_args(_term_table(sim, dissipative, ctx), sim._m))
    sim._eargs = table


def _term_table(sim, bound, ctx, jacobian=False):
    """The :class:`~orbits._kernels.terms.TermTable` of bound terms, with
    the pointers of their user functions, if any (and their Jacobians' with
    ``jacobian``)."""
    users = [b.user for b in bound if b.user is not None]
    rows = [b.row for b in bound if b.user is None]
    user = None
    if users:
        accel, energy = _user_functions.term_pointers(users)
        pos = np.argsort(ctx.order).astype(np.int64)
        # the functions stay alive in term_pointers' cache for the process
        user = _kterms.user_terms(accel.address, energy.address, pos,
                                  np.ascontiguousarray(ctx.m[pos]),
                                  any(u.velocity_dependent for u in users))
        rows.append(_kterms.TermRow(_kterms.USER))
    with CompileClock(TERMS["jacobians" if jacobian else "kernels"]) as clock, clock.loop():
        return _kterms.table(rows, sim._gm, sim._m, user, jacobian)
