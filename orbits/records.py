"""The records a simulation is described and saved by.

Plain named tuples, shared by :mod:`orbits.simulation` (which makes them) and
:mod:`orbits.io.hdf5` and :mod:`orbits.ensemble` (which store and ship them),
so that neither of those reads a simulation's private attributes and the
modules do not import each other.  ``orbits.simulation`` re-exports them.
"""

from typing import NamedTuple

import astropy.units as u
import numpy as np

__all__ = ["RunPlan", "SimulationConfig", "SimulationState", "Snapshot",
           "SimulationDescription"]


class RunPlan(NamedTuple):
    """Where one ``run`` takes its steps and outputs; stored in output files so
    that an interrupted run resumes with exactly the same steps."""

    until: float            # end time (internal units)
    outputs: int
    ratio: float            # (until - start) / dt
    n_full: int             # whole steps of dt
    has_partial: bool       # one shortened last step to land on until
    start_step: int         # Simulation.steps when the run began
    start_time: float = 0.0  # time when the run began (adaptive runs' output times)

    @property
    def total_steps(self):
        return self.n_full + int(self.has_partial)

    def output_time(self, k):
        """Time of output ``k`` of an adaptive run (exactly ``until`` for the last)."""
        if k >= self.outputs - 1:
            return self.until
        return self.start_time + k * (self.until - self.start_time) / (self.outputs - 1)

    def marks(self, first=0):
        """Step counts (from the run's start) of the outputs between the first and
        last, from the ``first``-th on; a generator, so a run of a million outputs
        holds none of them in memory."""
        for k in range(first + 1, self.outputs - 1):
            yield min(int(round(k * self.ratio / (self.outputs - 1))), self.n_full)


class SimulationConfig(NamedTuple):
    """Everything but the bodies that makes a :class:`Simulation`: one object that
    output files store and ensembles ship, so that a simulation is rebuilt with
    :meth:`Simulation.from_config` rather than by re-listing its arguments.

    Quantities stay Quantities; :meth:`to_dict` gives plain JSON-able values.
    """

    integrator: str
    integrator_options: dict
    dt: object              # Quantity (time) or None
    forces: tuple           # ForceTerm dictionaries, the Gravity term first
    monitors: tuple
    monitor_every: object   # int or None
    stop_conditions: dict   # Simulation keyword -> value

    def to_dict(self):
        """Plain values: Quantities as ``[value, unit]``."""
        from .forces import _quantity_dict
        return {"integrator": self.integrator,
                "integrator_options": dict(self.integrator_options),
                "dt": _quantity_dict(self.dt), "forces": list(self.forces),
                "monitors": list(self.monitors), "monitor_every": self.monitor_every,
                "stop_conditions": {k: (_quantity_dict(v) if isinstance(v, u.Quantity) else v)
                                    for k, v in self.stop_conditions.items()}}

    @classmethod
    def from_dict(cls, d):
        from .forces import _quantity_from
        return cls(d["integrator"], dict(d["integrator_options"]), _quantity_from(d["dt"]),
                   tuple(d["forces"]), tuple(d["monitors"]), d["monitor_every"],
                   {k: _quantity_from(v) for k, v in d["stop_conditions"].items()})


class SimulationState(NamedTuple):
    """A simulation's dynamical state, exactly: what a restart checkpoint saves
    and :meth:`Simulation.set_state` puts back (bit for bit).

    Arrays are in the simulation's internal order (massive bodies first,
    ``order[i]`` the body set's row of internal row ``i``) and units.
    """

    x: np.ndarray                # (N, 3), the integrator's current positions
    v: np.ndarray                # (N, 3)
    order: np.ndarray            # (N,) int64
    t_base: float                # time = t_base + steps_since_base * dt
    steps_since_base: int
    steps: int                   # accepted steps since the simulation was made
    force_evaluations: int
    steps_rejected: int
    workspace: dict              # the integrator's arrays (name -> ndarray)
    reference: np.ndarray        # the monitors' reference row (errors are against it)
    scales: tuple                # (energy scale, angular momentum scale)


class Snapshot(NamedTuple):
    """One output: time, step count, and the state in the body set's order."""

    t: float
    steps: int
    x: np.ndarray
    v: np.ndarray
    monitors: np.ndarray         # one monitor row (orbits._kernels.invariants layout)


class SimulationDescription(NamedTuple):
    """What an output file says about a simulation, beside its state: the
    bodies, units and set-up (:meth:`Simulation.description`).

    Numbers are plain floats in the simulation's units; ``masses`` and
    ``names`` are in the body set's order.
    """

    names: tuple
    masses: np.ndarray           # (N,) body-set order
    units: object                # the UnitSystem
    integrator: object           # the Integrator (name, config, info())
    dt: float                    # 0 for an adaptive method left to choose
    softening: float
    monitors: tuple
    monitor_every: object        # int or None
    parallel: bool
    rebound_arithmetic: bool
    stop_conditions: dict        # keyword -> plain value (lengths in the units)
    history: list                # how the body set was made
    config: SimulationConfig     # the record that rebuilds the simulation
    forces: tuple                # the ForceTerms added to gravity
