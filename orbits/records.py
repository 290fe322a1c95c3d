"""The records a simulation is described and saved by.

Plain named tuples, shared by :mod:`orbits.simulation` (which makes them) and
:mod:`orbits.io.h5md` and :mod:`orbits.ensemble` (which store and ship them),
so that neither of those reads a simulation's private attributes and the
modules do not import each other.  ``orbits.simulation`` re-exports them.
"""

from typing import NamedTuple

import numpy as np

from ._quantity_json import from_plain, is_quantity, to_plain

__all__ = ["RunPlan", "SimulationConfig", "SimulationState", "Snapshot",
           "SimulationDescription"]


class RunPlan(NamedTuple):
    """Where one ``run`` takes its steps and outputs; stored in output files so
    that an interrupted run resumes with exactly the same steps.

    Times (``until``, ``start_time``, and what :meth:`output_time` returns) are
    floats in the simulation's unit of time.

    Examples
    --------
    >>> from orbits.records import RunPlan
    >>> plan = RunPlan(until=10.0, outputs=3, ratio=10.5, n_full=10, has_partial=True,
    ...                start_step=0)
    >>> plan.total_steps, list(plan.marks()), plan.output_time(1)
    (11, [5], 5.0)
    """

    until: float            # end time (internal units)
    outputs: int
    ratio: float            # |until - start| / dt (dt > 0: the step size)
    n_full: int             # whole steps of dt
    has_partial: bool       # one shortened last step to land on until
    start_step: int         # Simulation.steps when the run began
    start_time: float = 0.0  # time when the run began (adaptive runs' output times)

    @property
    def direction(self):
        """+1 for a run forwards in time, -1 for one backwards (``until`` before
        ``start_time``).

        Examples
        --------
        >>> from orbits.records import RunPlan
        >>> RunPlan(-10.0, 3, 10.0, 10, False, 0, start_time=0.0).direction
        -1
        """
        return -1 if self.until < self.start_time else 1

    @property
    def total_steps(self):
        """Steps the run takes (int): the whole steps and the shortened last one, if any.

        Examples
        --------
        >>> from orbits.records import RunPlan
        >>> RunPlan(10.0, 3, 10.5, 10, True, 0).total_steps   # ten whole steps and a short one
        11
        """
        return self.n_full + int(self.has_partial)

    def output_time(self, k):
        """Time of output ``k`` of an adaptive run (exactly ``until`` for the last).

        Examples
        --------
        >>> from orbits.records import RunPlan
        >>> plan = RunPlan(until=10.0, outputs=5, ratio=10.0, n_full=10, has_partial=False,
        ...                start_step=0, start_time=2.0)
        >>> [plan.output_time(k) for k in range(5)]
        [2.0, 4.0, 6.0, 8.0, 10.0]
        """
        if k >= self.outputs - 1:
            return self.until
        return self.start_time + k * (self.until - self.start_time) / (self.outputs - 1)

    def output_times(self, first, count):
        """Times of outputs ``first`` to ``first + count - 1`` (an array), each
        the float :meth:`output_time` gives, computed at once.

        Examples
        --------
        >>> from orbits.records import RunPlan
        >>> plan = RunPlan(until=10.0, outputs=4, ratio=0.0, n_full=0, has_partial=False,
        ...                start_step=0, start_time=1.0)
        >>> plan.output_times(1, 3).tolist(), [plan.output_time(k) for k in (1, 2, 3)]
        ([4.0, 7.0, 10.0], [4.0, 7.0, 10.0])
        """
        k = np.arange(first, first + count, dtype=np.float64)
        # the operations of output_time, in its order, on every k
        times = self.start_time + k * (self.until - self.start_time) / (self.outputs - 1)
        times[k >= self.outputs - 1] = self.until
        return times

    def marks(self, first=0):
        """Step counts (from the run's start) of the outputs between the first and
        last, from the ``first``-th on; a generator, so a run of a million outputs
        holds none of them in memory.

        Examples
        --------
        >>> from orbits.records import RunPlan
        >>> plan = RunPlan(until=100.0, outputs=5, ratio=100.0, n_full=100, has_partial=False,
        ...                start_step=0)
        >>> list(plan.marks()), list(plan.marks(first=2))
        ([25, 50, 75], [75])
        """
        for k in range(first + 1, self.outputs - 1):
            yield min(int(round(k * self.ratio / (self.outputs - 1))), self.n_full)

    def marks_between(self, lo, hi):
        """The marks (as :meth:`marks`, the same integers) after step ``lo`` and
        up to step ``hi``, as an int64 array, for a plan with at least one step
        from an output to the next (``ratio >= outputs - 1``; they increase).

        Examples
        --------
        >>> from orbits.records import RunPlan
        >>> plan = RunPlan(until=100.0, outputs=8, ratio=100.0, n_full=100, has_partial=False,
        ...                start_step=0)
        >>> list(plan.marks()), plan.marks_between(14, 57).tolist()
        ([14, 29, 43, 57, 71, 86], [29, 43, 57])
        """
        if self.outputs < 3 or hi <= lo:
            return np.zeros(0, dtype=np.int64)
        per = self.ratio / (self.outputs - 1)
        j_lo = max(1, int(lo / per) - 1)
        j_hi = min(self.outputs - 2, int(hi / per) + 2)
        if j_hi < j_lo:
            return np.zeros(0, dtype=np.int64)
        j = np.arange(j_lo, j_hi + 1, dtype=np.int64)
        # the same operations as marks(): (j ratio) / (outputs - 1), rounded half to even
        s = np.minimum(np.round(j * self.ratio / (self.outputs - 1)).astype(np.int64),
                       self.n_full)
        return s[(s > lo) & (s <= hi)]


class SimulationConfig(NamedTuple):
    """Everything but the bodies that makes a :class:`Simulation`: one object that
    output files store and ensembles ship, so that a simulation is rebuilt with
    :meth:`Simulation.from_config` rather than by re-listing its arguments.

    Quantities stay Quantities; :meth:`to_dict` gives plain JSON-able values.

    Examples
    --------
    >>> cfg = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day).config
    >>> cfg.integrator, cfg.dt, cfg.monitors
    ('leapfrog', <Quantity 1. d>, ('energy', 'angular_momentum'))
    """

    integrator: str
    integrator_options: dict
    dt: object              # Quantity (time) or None
    forces: tuple           # ForceTerm dictionaries, the Gravity term first
    monitors: tuple
    monitor_every: object   # int or None
    stop_conditions: dict   # Simulation keyword -> value
    variations: object = None  # None, "state", "all" or an int
    seed: object = None        # the seed of the random tangent vectors (int) or None

    def to_dict(self):
        """Plain values: Quantities as ``[value, unit]``.

        Examples
        --------
        >>> d = sim.config.to_dict()
        >>> d["integrator"], d["dt"]
        ('leapfrog', [1.0, 'd'])
        """
        return {"integrator": self.integrator,
                "integrator_options": dict(self.integrator_options),
                "dt": to_plain(self.dt), "forces": list(self.forces),
                "monitors": list(self.monitors), "monitor_every": self.monitor_every,
                "stop_conditions": {k: (to_plain(v) if is_quantity(v)
                                        else _function_name(v) if callable(v) else v)
                                    for k, v in self.stop_conditions.items()},
                "variations": self.variations, "seed": self.seed}

    @classmethod
    def from_dict(cls, d):
        """The :class:`SimulationConfig` that :meth:`to_dict` describes.

        Parameters
        ----------
        d : dict
            As :meth:`to_dict` gives it: Quantities as ``[value, unit]``.

        Returns
        -------
        SimulationConfig

        Examples
        --------
        >>> from orbits.records import SimulationConfig
        >>> cfg = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day).config
        >>> SimulationConfig.from_dict(cfg.to_dict()) == cfg
        True
        """
        return cls(d["integrator"], dict(d["integrator_options"]), from_plain(d["dt"]),
                   tuple(d["forces"]), tuple(d["monitors"]), d["monitor_every"],
                   {k: from_plain(v) for k, v in d["stop_conditions"].items()},
                   d.get("variations"), d.get("seed"))


class SimulationState(NamedTuple):
    """A simulation's dynamical state, exactly: what a restart checkpoint saves
    and :meth:`Simulation.set_state` puts back (bit for bit).

    Arrays are in the simulation's internal order (massive bodies first,
    ``order[i]`` the body set's row of internal row ``i``) and units.

    Examples
    --------
    >>> state = sim.state
    >>> _ = sim.run(until=10 * u.day, outputs=2, progress=False)
    >>> state.steps, sim.state.steps, sim.state.x.shape
    (0, 10, (2, 3))
    """

    x: np.ndarray                # (N, 3), the integrator's current positions
    v: np.ndarray                # (N, 3)
    order: np.ndarray            # (N,) int64
    t_base: float                # time = t_base + steps_since_base * dt
    steps_since_base: int
    steps: int                   # accepted steps since the simulation was made
    force_evaluations: int
    steps_rejected: int
    # the integrator's arrays (name -> ndarray); with non-conservative force
    # terms also "work": W, the energy they took out, and its rounding
    # compensation (see Simulation.work), carried with the state it belongs to
    workspace: dict
    reference: np.ndarray        # the monitors' reference row (errors are against it)
    scales: tuple                # (energy scale, angular momentum scale)


class Snapshot(NamedTuple):
    """One output: time, step count, and the state in the body set's order.

    Examples
    --------
    >>> _ = sim.run(until=10 * u.day, outputs=2, progress=False)
    >>> snap = sim.snapshot()
    >>> snap.t, snap.steps, snap.x.shape, snap.v.shape
    (10.0, 10, (2, 3), (2, 3))
    """

    t: float
    steps: int
    x: np.ndarray
    v: np.ndarray
    monitors: np.ndarray         # one monitor row (orbits._kernels.invariants layout,
                                 # the work of non-conservative terms in its last column)
    # a simulation whose collisions change the bodies: their names, masses and
    # radii now (body-set order), for recorders that keep the columns of the
    # bodies at the start; None otherwise
    names: tuple = None
    masses: np.ndarray = None
    radii: np.ndarray = None


class SimulationDescription(NamedTuple):
    """What an output file says about a simulation, beside its state: the
    bodies, units and set-up (:meth:`Simulation.description`).

    Numbers are plain floats in the simulation's units; ``names``,
    ``masses`` and ``radii`` are in the body set's order.

    Examples
    --------
    >>> d = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day).description()
    >>> d.names, d.masses.tolist(), d.radii.tolist(), d.dt, d.integrator.name
    (('Star', 'Planet'), [1.0, 0.001], [0.0, 0.0], 1.0, 'leapfrog')
    """

    names: tuple
    masses: np.ndarray           # (N,) body-set order
    radii: np.ndarray            # (N,) body-set order, length: physical radii (0: a point)
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
    epoch: object = None         # astropy Time (TDB) of time 0, or None (orbits.epochs)


#: how a plain record names a function it cannot hold (a collisions function)
FUNCTION_PREFIX = "function:"


def _function_name(func):
    return FUNCTION_PREFIX + getattr(func, "__module__", "?") + "." + getattr(
        func, "__qualname__", type(func).__name__)
