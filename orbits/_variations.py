"""Variations and chaos indicators' set-up: the tangent vectors integrated
beside the bodies (``variations=`` and the chaos monitors of
:class:`~orbits.Simulation`), their initial directions, the force of the
augmented system (:mod:`orbits._kernels.variational`), and the derivatives
read back from them (:attr:`~orbits.Simulation.jacobian`,
:attr:`~orbits.Simulation.tangent_vectors`).

The tangent rows follow the bodies' rows in one pair of arrays (``_rows_x``,
``_rows_v``), so that every integrator advances them as more bodies.
"""

import numbers

import numpy as np

from ._compiling import TERMS, CompileClock
from ._kernels import terms as _kterms
from ._kernels import variational as _var
from .errors import IntegratorOptionError, SimulationOptionError
from .monitors import CHAOS_MONITORS

__all__ = ["bind", "tangent_rows", "jacobian", "renormalise"]


def bind(sim, variations, seed):
    """Tangent rows after the bodies' and the force of the augmented system
    (:mod:`orbits._kernels.variational`), for ``variations`` and the chaos
    monitors; the force without them is kept as ``_base_force``,
    ``_base_fargs``."""
    chaos = [name for name in sim.monitors if name in CHAOS_MONITORS]
    if sim._resolves_collisions and (variations is not None or chaos):
        # a merger takes a body out and a bounce changes velocities at once:
        # the tangent vectors follow neither
        asked = ("variations=" if variations is not None
                 else f"the chaos monitors ({', '.join(chaos)})")
        raise SimulationOptionError(
            f"collisions={sim._stop_config['collisions']!r} changes the bodies during the "
            f"run, which the variational equations cannot follow; use collisions='halt' "
            f"with {asked}")
    sim._base_force, sim._base_fargs = sim._force, sim._fargs
    n = len(sim._m)
    chaos = bool(chaos)
    if chaos and not sim.integrator.chaos_indicators:
        raise IntegratorOptionError(
            f"{sim.integrator.name!r} does not integrate the variational equations that "
            f"the chaos monitors "
            f"{', '.join(n for n in sim.monitors if n in CHAOS_MONITORS)} follow; use "
            "'ias15', 'dop853', 'leapfrog' or 'wh'")
    if variations is None:
        n_state, n_mass, n_random = 0, 0, 0
    elif isinstance(variations, str) and variations in ("state", "all"):
        n_state, n_mass, n_random = 6 * n, (n if variations == "all" else 0), 0
    elif (isinstance(variations, numbers.Integral) and not isinstance(variations, bool)
          and variations >= 1):
        n_state, n_mass, n_random = 0, 0, int(variations)
    else:
        raise IntegratorOptionError(
            f"variations must be None, 'state', 'all' or a whole number of random "
            f"tangent vectors >= 1, got {variations!r}")
    if seed is not None and not isinstance(seed, numbers.Integral):
        raise IntegratorOptionError(f"seed must be an integer, got {seed!r}")
    if seed is None and (chaos or n_random):
        # drawn once and kept in the config, so that a rebuilt simulation
        # (a file, an ensemble's member) starts from the same vectors
        seed = int(np.random.SeedSequence().entropy % 2 ** 63)
    sim._variations = variations
    sim._seed = None if seed is None else int(seed)
    sim._n_chaos = int(chaos)
    k = sim._n_chaos + n_random + n_state + n_mass
    sim._n_tangent = k
    sim._tangent_layout = (sim._n_chaos, n_random, n_state, n_mass)
    sim._rows_x = np.zeros((n * (1 + k), 3))
    sim._rows_v = np.zeros((n * (1 + k), 3))
    sim._rows_x[:n] = sim._x
    sim._rows_v[:n] = sim._v
    sim._x = sim._rows_x[:n]
    sim._v = sim._rows_v[:n]
    sim._chaos_box = None
    if k == 0:
        return
    if n_mass and sim._terms:
        raise IntegratorOptionError(
            "variations='all' (derivatives with respect to the masses) take gravity's "
            "dependence on the masses only, and the force terms "
            f"{', '.join(map(repr, sim._terms))} depend on them too; use "
            "variations='state', or drop the terms")
    if sim._terms:
        # the variational equations read the terms' Jacobians
        with CompileClock(TERMS["jacobians"]) as clock, clock.loop():
            _kterms.with_jacobian(sim._base_fargs[1])
    dx, dv, dm = _initial_tangents(sim, n, seed)
    sim._rows_x[n:] = dx.reshape(-1, 3)
    sim._rows_v[n:] = dv.reshape(-1, 3)
    sim._chaos_box = _var.chaos_box(0.0)
    sim._force = _var.with_variations(sim._base_force, chaos=chaos)
    sim._fargs = _var.variation_args(sim._base_fargs, n, dm, sim._chaos_box,
                                      sim.units.G, sim._eps2, chaos)


def tangent_rows(sim):
    """The tangent vectors now, shape (k, N, 6) in the body set's order, and
    the mass parts (k, N)."""
    sim.integrator.synchronize(sim._ws, sim._rows_x, sim._rows_v)
    n = len(sim._m)
    k = sim._n_tangent
    t = np.concatenate([sim._rows_x[n:].reshape(k, n, 3),
                        sim._rows_v[n:].reshape(k, n, 3)], axis=2)
    return t[:, sim._inverse]


def jacobian(sim):
    """The derivatives of the current state with respect to the initial one
    (:attr:`Simulation.jacobian`), or None without ``variations="state"`` or ``"all"``."""
    n_chaos, n_random, n_state, n_mass = sim._tangent_layout
    if not n_state:
        return None
    t = tangent_rows(sim)[n_chaos + n_random:]
    n = len(sim._m)
    return t.reshape(n_state + n_mass, 6 * n).T.copy()


def renormalise(sim):
    """The chaos monitors' tangent vector scaled back to a norm in [0.5, 1), the
    scale noted in the chaos box (:func:`orbits._kernels.variational.renormalise`)."""
    sim.integrator.synchronize(sim._ws, sim._rows_x, sim._rows_v)
    _var.renormalise(sim._rows_x, sim._rows_v, len(sim._m), sim._ws["chaos"])
    sim.integrator.invalidate(sim._ws)


def _initial_tangents(sim, n, seed):
    # (k, n, 3) position and velocity parts and (k, n) mass parts, in the
    # internal (massive first) order: the chaos vector, the random ones,
    # then a unit vector per initial coordinate of each body in the body
    # set's order (x, y, z, vx, vy, vz), then per mass
    n_chaos, n_random, n_state, n_mass = sim._tangent_layout
    k = sim._n_tangent
    dx = np.zeros((k, n, 3))
    dv = np.zeros((k, n, 3))
    dm = np.zeros((k, n))
    rng = np.random.default_rng(seed)
    for j in range(n_chaos + n_random):
        w = rng.standard_normal((2, n, 3))
        w /= np.sqrt(np.sum(w * w))
        dx[j], dv[j] = w
    j = n_chaos + n_random
    inv = sim._inverse
    for b in range(n if n_state else 0):
        for c in range(6):
            (dx if c < 3 else dv)[j + 6 * b + c, inv[b], c % 3] = 1.0
    j += n_state
    for b in range(n_mass):
        dm[j + b, inv[b]] = 1.0
    return dx, dv, dm
