"""Perturbed copies of one simulation (:meth:`orbits.Ensemble.perturbed`).

What travels to the workers is :class:`_Perturbation`, a body set and the
simulation's configuration, which pickle; each worker rebuilds the
simulation and shifts its positions.  A copy's shift depends only on the
seed and the copy's number.
"""

import hashlib
import json

import numpy as np

from ..forces import functions_of
from ..simulation import Simulation

__all__ = []


class _Perturbation:
    """Rebuilds a simulation with shifted positions on a worker: holds a body set
    and the simulation's options, which pickle, rather than the simulation."""

    def __init__(self, sim, scale, seed):
        self.bodies = sim.bodies
        self.config = sim.config
        # the user's functions of the force terms, by the names the
        # configuration records: shipped as objects (pickled by reference),
        # since a record names a function and is never imported from
        self.functions = functions_of(sim.forces)
        self.scale = scale
        self.seed = seed

    def __call__(self, member):
        bodies = self.bodies.copy()
        x = bodies._x
        r = np.linalg.norm(x - bodies._com()[0], axis=1)
        rng = np.random.default_rng(np.random.SeedSequence(self.seed, spawn_key=(member,)))
        direction = rng.standard_normal((len(bodies), 3))
        direction /= np.linalg.norm(direction, axis=1)[:, None]
        bodies._x = x + (self.scale * r)[:, None] * direction
        bodies.history.append({"from": "perturbed", "scale": self.scale, "seed": self.seed,
                               "member": int(member)})
        return Simulation.from_config(bodies, self.config, functions=self.functions)

    def fingerprint(self):
        b = self.bodies
        h = hashlib.sha1()
        # radii only where some body has one: a sweep of point masses keeps
        # the fingerprint it had before bodies had sizes
        for a in (b._m, b._x, b._v) + ((b._r,) if np.any(b._r) else ()):
            h.update(np.ascontiguousarray(a).tobytes())
        h.update(json.dumps([b.names, self.config.to_dict(), self.scale, self.seed],
                            sort_keys=True, default=str).encode())
        return h.digest()
