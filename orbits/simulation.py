"""Simulation: bodies + gravity + integrator + monitors, and ``run``.

Units are converted once, when the simulation is made; the run works on
float64 arrays in the body set's unit system and attaches units again only
to what it returns.

This module is the facade: :class:`Simulation`'s construction and public
methods.  The ideas it draws on live in modules of their own: the integrator
and its options (:mod:`orbits._integrator_choice`), gravity's and the force
terms' binding (:mod:`orbits._force_binding`), the monitors
(:mod:`orbits._monitoring`), variations and chaos indicators
(:mod:`orbits._variations`), stopping conditions and the encounter log
(:mod:`orbits._stop_conditions`), the collision resolver
(:mod:`orbits._collision_resolver`), the state and its records
(:mod:`orbits._state`), the run's plan (:mod:`orbits._run_plan`) and failures
(:mod:`orbits._failures`), the driver (:mod:`orbits._driver`), the recorder of
a run in memory (:mod:`orbits.recorder`), restart from a file
(:mod:`orbits.io.restart`) and the simulation in words for its ``repr``
(:mod:`orbits._described`).
"""

import copy
import math

import numpy as np

from . import _collision_resolver as _resolver
from . import _described
from . import _failures
from . import _force_binding as _binding
from . import _integrator_choice as _choice
from . import _monitoring
from . import _run_plan
from . import _state
from . import _stop_conditions as _stops
from . import _variations
from . import collisions as _collisions
from . import forces as _forces
from . import integrators as _integrators
from ._driver import (CHUNK_SECONDS, FIRST_CHUNK, PROGRESS_DELAY,  # noqa: F401 - documented here
                      Driven)
from ._kernels import stepping as _stepping
from .bodies import BodySet
from .errors import BodyUnitsError, IntegratorOptionError
from .io import hdf5 as _hdf5
from .io import restart as _restart
from .monitors import DEFAULT_MONITORS
from .recorder import Recorder
from .records import (RunPlan, SimulationConfig, SimulationDescription, SimulationState,
                      Snapshot)

__all__ = ["Simulation", "SimulationConfig", "SimulationState", "SimulationDescription",
           "Snapshot", "RunPlan", "PARALLEL_THRESHOLD", "LOG_ROWS"]

#: Rows of the encounter log's table when a run starts (``encounter_log``):
#: the compiled loop hands it back half full, and a step with more
#: approaches than it holds has it doubled (see orbits._kernels.stopping).
LOG_ROWS = 1024

#: Bodies from which the threaded gravity kernel is used: below it thread
#: start-up (~4 us a step) outweighs the split work, against the one-thread
#: lanes kernel (orbits._kernels.gravity.LANES_FROM) on two cores.
#: benchmarks/bench_gravity.py measures the break-even (benchmarks/RESULTS.md).
PARALLEL_THRESHOLD = 128

#: Outputs of a run when none are asked for.
DEFAULT_OUTPUTS = 500

class Simulation(Driven):
    """A body set evolving under Newtonian gravity and added force terms with a
    chosen integrator.

    Parameters
    ----------
    bodies : BodySet
        Copied; later changes to it do not affect the simulation.
    integrator : str or Integrator
        Registry name or alias (see :func:`orbits.integrators.available`) or
        a configured instance from :func:`orbits.integrators.get`.  Default
        ``"ias15"``, which needs no ``dt``.
    dt : Quantity (time) or float
        Step size; for adaptive integrators the first step to try (optional:
        by default they choose it).  A plain number is read in the body set's
        unit of time, and is accepted only when the body set was given its
        unit system explicitly.  A fixed-step integrator without it is an
        :class:`~orbits.errors.IntegratorOptionError` that names the adaptive
        ones.
    **options
        The integrator's options, given by name beside it, as
        ``Simulation(bodies, "ias15", epsilon=1e-10)``: the same as
        ``integrator=orbits.integrators.get("ias15", epsilon=1e-10)``.  An
        option the integrator does not have, or options beside an instance,
        are an :class:`~orbits.errors.IntegratorOptionError`.
    monitors : sequence of str
        Any of ``"energy"``, ``"angular_momentum"``, ``"momentum"``,
        ``"center_of_mass"``, and the chaos indicators ``"megno"`` (the running
        mean of MEGNO, Cincotta & Simo 2000: 2 on a regular orbit, growing as
        ``lambda t / 2`` on a chaotic one), ``"lyapunov"`` (the largest
        Lyapunov exponent's estimate ``ln(|delta(t)| / |delta(0)|) / t``, in
        1 / time) and ``"fli"`` (the fast Lyapunov indicator,
        ``max ln |delta|``), from a tangent vector integrated alongside (see
        ``variations`` and ``seed``).  Default: energy and angular momentum.
        An empty sequence switches them off and costs nothing.
    monitor_every : int, optional
        Also record the monitors inside the compiled loop every this many
        steps (in ``result.monitor``).  Default: only at outputs.
    softening : Quantity (length) or float, optional
        Plummer softening length.
    parallel : bool, optional
        Force the threaded (True) or serial (False) gravity kernel.  Default:
        threaded from :data:`PARALLEL_THRESHOLD` bodies on.
    encounter_distance : Quantity (length), optional
        Stop with :class:`~orbits.errors.CloseEncounter` when two bodies come
        closer than this, at the end of a step or inside it: the closest
        approach along the step from both its ends, as for ``collisions``
        (:func:`orbits._kernels.stopping.encounter_check`), so that a fast
        pass between two step ends stops a fixed-step run too.  The run stops
        at the end of that step; the message names when the pair was closest
        and how close.
    encounter_hill : float, optional
        Stop with :class:`~orbits.errors.CloseEncounter` when two bodies other
        than the central (most massive) one come within this many mutual Hill
        radii, ``((m_i + m_j) / (3 m_c))^(1/3) (r_i + r_j) / 2`` (the
        distances ``r`` from the central body at the end of the step), found
        as for ``encounter_distance``.
    escape_distance : Quantity (length), optional
        Stop with :class:`~orbits.errors.Escape` when a body is farther than
        this from the centre of mass at the end of a step.  The one condition
        that ``wh`` and the SABA methods check too.
    escape_unbound : bool
        With ``escape_distance``: count a body beyond it only if it is also
        unbound (positive energy about the centre of mass).
    collisions : {None, "halt", "merge", "bounce"} or callable
        ``"halt"``: stop with :class:`~orbits.errors.Collision` when two bodies
        touch, their separation below the sum of their radii
        (:meth:`BodySet.add`'s ``radius``; a body without one is a point);
        ``"merge"``, ``"bounce"`` or a function resolve the collision and go
        on (:mod:`orbits.collisions`).  The pairs are looked at the end of
        every step and inside it, the first step included, along their
        relative motion between its ends (:mod:`orbits._kernels.stopping`), so
        a grazing passage inside one step is caught too.  At least one body
        must have a radius.  Bodies that touch at the start are merged there
        with ``"merge"`` (a row of the first run's ``result.collisions`` at
        t = 0); otherwise they are refused, naming the pair.  For integrators
        that check stopping conditions (not the Wisdom-Holman family).
    encounter_log : float or Quantity (length), optional
        Log, without stopping, every closest approach of two bodies within
        this many mutual Hill radii (a number; pairs without the central
        body, Hill radii as for ``encounter_hill``) or this distance (a
        length): ``result.encounters`` is a table of the time of closest
        approach, the two bodies, their separation and relative speed.  The
        minimum is found inside the step from both its ends
        (:func:`orbits._kernels.encounters.closest_approach`).  For the
        integrators that check stopping conditions.

    variations : {None, "state", "all"} or int, optional
        Integrate the first-order variational equations alongside
        (:mod:`orbits._kernels.variational`): ``"state"`` the derivatives of
        the state with respect to every initial position and velocity,
        ``"all"`` also with respect to every mass, an int that many random
        tangent vectors (unit norm over positions and velocities, from
        ``seed``).  Each force term contributes through its Jacobian.  The
        derivatives of the current state are :attr:`jacobian` and
        :attr:`tangent_vectors`, and the result of a run and its file carry
        them.  The chaos monitors (``"megno"``, ``"lyapunov"``, ``"fli"``) add
        a random tangent vector of their own.
    seed : int, optional
        Seed of the random tangent vectors (the chaos monitors' and an int
        ``variations``); the same seed gives the same vectors and results.
    rebound_arithmetic : bool
        Compute gravity with REBOUND's floating-point operations (its serial
        ``gravity = "basic"``), so that ``leapfrog`` reproduces REBOUND's
        ``leapfrog`` bit for bit from the same floats and G (see
        :mod:`orbits.integrators.leapfrog`).  Serial and up to 1.5 % slower
        per pair than the default kernels, which round differently by an ulp
        or so.

    The stopping conditions are checked inside the compiled loop after every
    step; without them the check is one branch a step.

    A simulation pickles and deep-copies (``copy.deepcopy(sim)``,
    ``pickle``, Python's ``multiprocessing``): the copy is made again from
    its configuration with its exact state, as a restart from a file is, and
    runs on to the same bits as the original, its date and resolved
    collisions with it.  A :class:`~orbits.forces.UserForce`'s functions go
    by reference, so in another process they must come from an importable
    module.

    The examples of the members start from ``sim``, a star and a planet on
    a circular orbit in days (:func:`orbits.scenes.kepler`) with
    ``leapfrog`` at a step of one day, and take ``astropy.units as u`` and
    ``orbits`` as imported::

        sim = orbits.Simulation(orbits.scenes.kepler(), integrator="leapfrog",
                                dt=1 * u.day)

    Examples
    --------
    >>> sim = orbits.Simulation(orbits.scenes.earth_moon(), integrator="leapfrog",
    ...                         dt=1 * u.hour)
    >>> result = sim.run(until=30 * u.day, outputs=31, progress=False)
    >>> result.positions.shape
    (31, 2, 3)
    >>> orbits.Simulation(orbits.scenes.earth_moon()).integrator.name
    'ias15'
    >>> orbits.Simulation(orbits.scenes.earth_moon(), "ias15", epsilon=1e-10).integrator
    IAS15(epsilon=1e-10, min_dt=0.0, adaptive_mode='global')
    """

    def __init__(self, bodies, integrator=_integrators.DEFAULT, dt=None, *, forces=(),
                 monitors=DEFAULT_MONITORS, monitor_every=None, softening=None, parallel=None,
                 encounter_distance=None, encounter_hill=None, escape_distance=None,
                 escape_unbound=False, collisions=None, restitution=None, encounter_log=None,
                 rebound_arithmetic=False, variations=None, seed=None, **options):
        if not isinstance(bodies, BodySet):
            raise TypeError(f"bodies must be a BodySet, got {type(bodies).__name__}")
        bodies.check()
        terms, gravity = _binding.split(forces, softening, parallel, rebound_arithmetic)
        self.units = bodies.units
        self._bare_ok = bodies._bare_ok
        self._names = bodies.names
        self._history = list(bodies.history)
        # the date of time 0: the bodies' epoch (None: a set of no date)
        self._epoch = bodies.epoch
        self.integrator = _choice.configured(integrator, options, Simulation.__init__)
        adaptive = self.integrator.adaptive
        if dt is None and not adaptive:
            raise _choice.step_required(self.integrator)
        self._dt = 0.0 if (adaptive and dt is None) else self._time_value(dt, "dt")
        # an adaptive method's dt is only its first step; 0 lets it choose
        if not ((self._dt > 0 or (adaptive and self._dt == 0)) and math.isfinite(self._dt)):
            raise IntegratorOptionError(f"dt must be a positive finite time, got {dt}")

        _state.take_bodies(self, bodies)
        _binding.bind_gravity(self, gravity, PARALLEL_THRESHOLD)
        self._terms = terms
        self._eargs = None
        if terms:
            self.integrator.check_terms(terms)
        if terms or (self.integrator.terms_as_data and self.integrator.table_in_force):
            _binding.bind_terms(self, bodies)

        _monitoring.set_up(self, monitors, monitor_every)

        self._stop_info = np.zeros(2, dtype=np.int64)
        self._stop = _stops.set_up(self, encounter_distance, encounter_hill, escape_distance,
                                   escape_unbound, collisions, encounter_log, restitution,
                                   LOG_ROWS)
        _variations.bind(self, variations, seed)
        self._ws = _state.workspace(self)
        self._collisions = []
        self._bodies_changed = 0    # how often collisions changed the set of bodies
        self.steps_rejected = 0
        self._t_base = 0.0          # time = t_base + steps_since_base * dt
        self._steps_since_base = 0
        self.steps = 0              # steps since the simulation was made
        self.force_evaluations = 0
        self._chunk = FIRST_CHUNK   # steps per compiled call; adapts in run()
        #: the HDF5 file this simulation writes to (set by ``run(output=...)``
        #: and :meth:`from_file`): a later ``run`` with the same ``output``
        #: appends to it
        self.output_path = None
        self._resume = None
        _monitoring.take_references(self)
        if self.__dict__.pop("_merge_at_start", False):
            # bodies in contact at the start with collisions="merge": merged
            # now, at t = 0, as a run merges them (collisions table, offsets)
            self._resolve_collisions(None, None)

    @property
    def tangent_vectors(self):
        """The tangent vectors now (None without variations): an array of shape
        (k, N, 6), each the derivative of the state (positions, then
        velocities, bodies in the body set's order, in the internal units)
        along its initial direction.  The chaos monitors' vector comes first
        (renormalised, so only its direction is meaningful), then the random
        ones, then those of ``variations="state"`` or ``"all"``."""
        if not self._n_tangent:
            return None
        return _variations.tangent_rows(self)

    @property
    def jacobian(self):
        """The derivatives of the current state with respect to the initial one
        (with ``variations="state"`` or ``"all"``; None otherwise): an array
        of shape (6N, 6N), or (6N, 7N) with the masses, whose entry ``[6 i +
        c, 6 j + d]`` is the derivative of body i's coordinate c (x, y, z, vx,
        vy, vz) with respect to body j's initial coordinate d, bodies in the
        body set's order, and column ``6N + j`` that with respect to body j's
        mass; in the simulation's internal units (:attr:`units`).

        Examples
        --------
        >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day,
        ...                         variations="state")
        >>> _ = sim.run(until=1 * u.yr, outputs=2, progress=False)
        >>> sim.jacobian.shape
        (12, 12)
        """
        return _variations.jacobian(self)

    @property
    def config(self):
        """The :class:`SimulationConfig` that rebuilds this simulation from its bodies.

        Examples
        --------
        >>> cfg = sim.config
        >>> cfg.integrator, cfg.dt
        ('leapfrog', <Quantity 1. d>)
        """
        return SimulationConfig(
            self.integrator.name, dict(self.integrator.config),
            None if (self.integrator.adaptive and self._dt == 0) else self.dt,
            tuple([self.gravity.to_dict()] + [t.to_dict() for t in self._terms]),
            tuple(self.monitors), self.monitor_every,
            {k: v for k, v in self.stop_conditions.items() if v is not None and v is not False},
            self._variations, self._seed)

    @classmethod
    def from_config(cls, bodies, config, _restoring=False, functions=None):
        """A simulation of ``bodies`` made as ``config`` (a :class:`SimulationConfig`
        or its :meth:`~SimulationConfig.to_dict`) says.

        ``functions`` gives the user's functions that the configuration's
        force terms name (see :func:`orbits.forces.from_dict`): a record names
        a function but never holds it.

        Examples
        --------
        >>> twin = orbits.Simulation.from_config(orbits.scenes.kepler(), sim.config.to_dict())
        >>> twin.integrator.name, twin.dt
        ('leapfrog', <Quantity 1. d>)
        """
        if isinstance(config, dict):
            config = SimulationConfig.from_dict(config)
        integ = _integrators.get(config.integrator, **config.integrator_options)
        terms = [t if isinstance(t, _forces.ForceTerm) else _forces.from_dict(t, functions)
                 for t in config.forces]
        sim = cls.__new__(cls)
        # a state restored from a file may hold bodies in contact (a bounce
        # that had not yet separated them)
        sim._touching_ok = _restoring
        sim.__init__(bodies, integ, dt=config.dt, forces=terms, monitors=config.monitors,
                     monitor_every=config.monitor_every, variations=config.variations,
                     seed=config.seed, **config.stop_conditions)
        del sim._touching_ok
        return sim

    @property
    def forces(self):
        """The force terms added to Newtonian gravity (a tuple, maybe empty).

        Examples
        --------
        >>> sim = orbits.Simulation(orbits.scenes.kepler(), integrator="ias15",
        ...                         forces=[orbits.forces.GR("Star")])
        >>> [type(term).__name__ for term in sim.forces]
        ['GR']
        """
        return self._terms

    @property
    def gravity(self):
        """The gravity term with this simulation's options (:class:`orbits.forces.Gravity`).

        Examples
        --------
        >>> type(sim.gravity).__name__
        'Gravity'
        """
        return _forces.Gravity(softening=self._softening, parallel=self.parallel,
                       rebound_arithmetic=self.rebound_arithmetic)

    @property
    def stop_conditions(self):
        """The stopping conditions as the keyword arguments that set them (Quantities).

        Examples
        --------
        >>> sim = orbits.Simulation(orbits.scenes.kepler(), dt=1 * u.day,
        ...                         escape_distance=100 * u.au)
        >>> sim.stop_conditions["escape_distance"], sim.stop_conditions["escape_unbound"]
        (<Quantity 100. AU>, False)
        """
        return _stops.keywords(self)

    @property
    def softening(self):
        """The softening length (Quantity), or None.

        Examples
        --------
        >>> print(sim.softening)
        None
        >>> orbits.Simulation(orbits.scenes.kepler(), dt=1 * u.day,
        ...                   softening=1e-3 * u.au).softening
        <Quantity 0.001 AU>
        """
        return self._softening

    # -- the driver's hooks: monitors, the encounter log, resolved collisions, chaos
    _mon = _monitoring.loop_args
    _monitor_row = _monitoring.row
    _has_work = property(_monitoring.has_work)
    _drain_log = _stops.drain_log
    _log_full = _stops.log_full
    _encounter_table = _stops.encounter_table
    _resolves_collisions = property(_resolver.resolves)
    _offset_rows = _resolver.offset_rows
    _resolve_collisions = _resolver.resolve
    _collision_table = _resolver.table
    _renormalise = _variations.renormalise

    #: the ways a collision can be resolved (Simulation's ``collisions``; or a
    #: function, see :mod:`orbits.collisions`)
    COLLISION_RESOLUTIONS = _collisions.RESOLUTIONS

    def _names_internal(self):
        return [self._names[k] for k in self._order]

    # -- files ------------------------------------------------------------------------
    @classmethod
    def from_file(cls, path, collisions=None, functions=None):
        """The simulation at the last checkpoint of an output file.

        Everything is restored, the integrator's internal state included, so
        that continuing gives bit for bit what an uninterrupted run gives.  If
        the run that wrote the file was interrupted, :meth:`resume` finishes
        it; :meth:`run` with ``output=path`` appends a new run to the file.

        A file carries data, never code: the functions of the user's that its
        run used (a :class:`~orbits.forces.UserForce`'s, a collisions
        function) are named in it, never held, and nothing a file names is
        imported.  They come from the caller, and are checked against the
        names (and, for a force term, the parameters) the file records.

        Parameters
        ----------
        path : str or path-like
        collisions : callable, optional
            The collisions function of a run that resolved collisions with one.
        functions : mapping, optional
            The user's functions by the names the file records: the whole
            name (``"module:qualname"``) or the ``qualname`` alone, as in
            ``functions={"drag": drag}``; a collisions function may come here
            too.

        Raises
        ------
        SimulationOptionError
            The file's run used functions that were not given (the message
            lists them), or ``functions`` names one the file does not record.
        orbits.forces.ForceTermError
            A function given has another name or other parameters than the
            file records.
        orbits.io.hdf5.OrbitsFileError
            The file is damaged, or holds values that do not rebuild a simulation.

        Examples
        --------
        >>> import os, tempfile
        >>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
        >>> _ = sim.run(until=10 * u.day, outputs=3, output=path, progress=False)
        >>> again = orbits.Simulation.from_file(path)
        >>> again.time, bool((again.bodies.positions == sim.bodies.positions).all())
        (<Quantity 10. d>, True)
        >>> again.resume_point.finished   # the run finished: nothing to resume
        True
        """
        sim, cp = _restart.restored(cls, path, collisions, functions)
        sim._epoch = cp.epoch       # the date of time 0, as the file keeps it
        sim.output_path = cp.path
        sim._resume = cp.point
        return sim

    @property
    def resume_point(self):
        """Where the run that wrote the file this simulation was restored from
        stood at its last checkpoint (:class:`orbits.io.hdf5.ResumePoint`; its
        ``finished`` says whether that run ended), until :meth:`resume`
        finishes it; None for a simulation not restored from a file.

        Examples
        --------
        >>> print(sim.resume_point)
        None
        """
        return self._resume

    def resume(self, progress=None, checkpoint_interval=None):
        """Finish the run that was interrupted, writing on into its file.

        Output rows written after the last checkpoint are dropped and computed
        again, so the file ends as if the run had never stopped.

        Returns
        -------
        Result
            As :meth:`run` with ``output`` returns it: the last output, and the
            whole run's invariants' errors.

        Raises
        ------
        ValueError
            The simulation was not restored from a file (:meth:`from_file`), or
            the run in it finished (:attr:`resume_point`): :meth:`run` with
            ``output`` continues it.

        Examples
        --------
        >>> sim.resume(progress=False)
        Traceback (most recent call last):
            ...
        ValueError: this simulation was not restored from a file (use Simulation.from_file)
        """
        point = self._resume
        if point is None:
            raise ValueError("this simulation was not restored from a file "
                             "(use Simulation.from_file)")
        if point.finished:
            raise ValueError(f"the run in {self.output_path} finished; continue with "
                             f"run(until=..., output={self.output_path!r})")
        rec = _restart.resumed_recorder(self, self.output_path, point, checkpoint_interval)
        self._resume = None
        first_mark = max(0, point.outputs_written - 1)
        return self.execute(point.plan, rec, progress, first_mark=first_mark)

    # -- state ------------------------------------------------------------------------
    @property
    def time(self):
        """Current simulation time (Quantity).

        Examples
        --------
        >>> _ = sim.run(until=10 * u.day, outputs=2, progress=False)
        >>> sim.time
        <Quantity 10. d>
        """
        return self.units.quantity(self._now(), "time")

    @property
    def dt(self):
        """Step size (Quantity).

        Examples
        --------
        >>> sim.dt
        <Quantity 1. d>
        """
        return self.units.quantity(self._dt, "time")

    @property
    def bodies(self):
        """The current state as a new :class:`BodySet`.

        A snapshot made each time it is read: ``sim.bodies["Planet"].position``
        is the body's position now, but a set or a body view
        (:class:`~orbits.body.Body`) kept from before a run still holds the
        state it was read at.  Changing it changes a copy, not the
        simulation: make a new :class:`Simulation` from it for that.

        Examples
        --------
        >>> _ = sim.run(until=10 * u.day, outputs=2, progress=False)
        >>> b = sim.bodies
        >>> b.names, b.positions.unit, b.radii.unit
        (['Star', 'Planet'], Unit("AU"), Unit("AU"))
        >>> sim.bodies["Planet"].position.shape
        (3,)
        """
        return _state.body_set(self)

    @property
    def epoch(self):
        """The date of time 0 (``astropy.time.Time``, TDB): the epoch of the body
        set the simulation was made from, or None where it had none.  The
        present date is ``sim.epoch + sim.time``, and :attr:`bodies` carries it.

        Examples
        --------
        >>> from astropy.time import Time
        >>> bodies = orbits.scenes.kepler()
        >>> bodies.epoch = Time("2030-01-01T00:00:00", scale="tdb")
        >>> sim = orbits.Simulation(bodies, "leapfrog", dt=1 * u.day)
        >>> _ = sim.run(until=10 * u.day, outputs=2, progress=False)
        >>> sim.epoch.isot, sim.bodies.epoch.isot
        ('2030-01-01T00:00:00.000', '2030-01-11T00:00:00.000')
        """
        return self._epoch

    @property
    def state(self):
        """The :class:`SimulationState` (copies), as a checkpoint stores it.

        Examples
        --------
        >>> s = sim.state
        >>> s.x.shape, s.steps
        ((2, 3), 0)
        """
        return _state.record(self)

    def set_state(self, state):
        """Put back a :class:`SimulationState` taken from a simulation made alike
        (same bodies' order, integrator and forces).

        Examples
        --------
        >>> start = sim.state
        >>> _ = sim.run(until=10 * u.day, outputs=2, progress=False)
        >>> sim.set_state(start)
        >>> sim.time
        <Quantity 0. d>
        """
        _state.put_back(self, state)

    def description(self):
        """The :class:`SimulationDescription`: bodies, units and set-up, as an
        output file records them beside the :attr:`state`.

        Examples
        --------
        >>> d = sim.description()
        >>> d.names, d.dt, d.units.name
        (('Star', 'Planet'), 1.0, 'au-Msun-day')
        """
        return _state.description(self)

    @property
    def time_value(self):
        """The current time as a float in the simulation's unit of time.

        Examples
        --------
        >>> _ = sim.run(until=1 * u.yr, outputs=2, progress=False)
        >>> sim.time_value, sim.time.unit
        (365.25, Unit("d"))
        """
        return self._now()

    def snapshot(self):
        """The current output (:class:`Snapshot`): the integrator synchronised, the
        state in the body set's order, and the monitors asked for.

        Examples
        --------
        >>> snap = sim.snapshot()
        >>> snap.t, snap.steps, snap.x.shape
        (0.0, 0, (2, 3))
        """
        return _state.snapshot(self)

    def _now(self):
        return self._t_base + self._steps_since_base * self._dt

    def _time_value(self, value, field):
        if value is None:
            raise IntegratorOptionError(f"{field} is required for integrator "
                                        f"{self.integrator.name!r}")
        try:
            val = self.units.to_internal(value, "time", bare_ok=self._bare_ok, field=field)
        except BodyUnitsError as exc:
            raise BodyUnitsError(str(exc).replace("field ", "argument ", 1)) from None
        if val.shape != ():
            raise IntegratorOptionError(f"{field} must be a scalar time, got shape {val.shape}")
        return float(val)

    @property
    def work(self):
        """W, the energy the non-conservative force terms have taken out of the
        bodies since the simulation was made (Quantity, energy; zero without
        such terms).

        ``W = -int sum_i m_i a_i . v_i dt`` over the accelerations of the terms
        with ``conservative = False`` alone (drag, tides, migration, radiation
        pressure, a :class:`~orbits.forces.UserForce` without a potential),
        integrated inside the compiled loop by the integrator's own quadrature,
        so that ``E + W`` stays the initial energy up to the integration error:
        the energy monitor reports ``|E + W - E0| / |E0|``.  A restart from a
        file carries it on bit for bit.

        Examples
        --------
        >>> sim.work                               # no non-conservative terms
        <Quantity 0. AU2 solMass / d2>
        """
        off = self._ws.get("collision_offset")
        return self.units.quantity(_stepping.work_total(self._ws)
                                   + (0.0 if off is None else off[0]), "energy")

    # -- running ------------------------------------------------------------------------
    def run(self, until, outputs=None, progress=None, output=None, overwrite=False,
            checkpoint_interval=None, wall_limit=None):
        """Advance to ``until``, recording ``outputs`` evenly spread states.

        Parameters
        ----------
        until : Quantity (time) or float
            End time, later than :attr:`time` or earlier: a run backwards in
            time takes the steps ``-dt`` (an adaptive method chooses negative
            steps), and its outputs' times decrease.  Not :attr:`time` itself.
        outputs : int, optional
            Number of outputs, the current state first and the state at
            ``until`` last (1: only the state at ``until``).  Default
            :data:`DEFAULT_OUTPUTS` (500), or one per step for a fixed-step
            run of fewer steps (with an :class:`~orbits.errors.OrbitsWarning`).  Fixed-step
            methods never change their step inside a run: each output is taken
            at the step boundary nearest its even spacing (``result.times``
            are the exact times), and only the very last step is shortened, if
            needed, to end exactly at ``until``.
        progress : bool, optional
            Show a progress bar.  Default: shown only if the run goes on for
            more than a few seconds.  False also silences the line on the
            standard error that a stepping loop's first compile prints
            ("orbits: compiling the wh loop for this CPU, once ...";
            :mod:`orbits._compiling`).
        output : str or path, optional
            Stream the outputs and monitors to this HDF5 file instead of
            keeping them in memory, with restart checkpoints (see
            :mod:`orbits.io.hdf5`).  The returned result then holds only the
            last output (its :meth:`~orbits.Result.max_energy_error`,
            :meth:`~orbits.Result.max_angular_momentum_error` and
            :meth:`~orbits.Result.summary` still cover the whole run);
            :func:`orbits.load` reads the whole file.  A file that
            this simulation wrote (or was restored from) is appended to; any
            other existing file is an error unless ``overwrite=True``.
        overwrite : bool
            Replace an existing file at ``output``.
        checkpoint_interval : float, optional
            Seconds of wall time between restart checkpoints in the file
            (default :data:`orbits.io.hdf5.CHECKPOINT_SECONDS`); 0 writes one
            at every output.  One is also written when the file is opened, at
            the end, and on SIGINT or SIGTERM; each costs about 2 ms and
            overwrites one of two fixed slots, so the interval does not change
            the file's size.
        wall_limit : float, optional
            Seconds of wall-clock time after which the run stops with
            :class:`~orbits.errors.WallTimeExceeded` (checked about every
            ``CHUNK_SECONDS`` from the first step on: the first call of the
            compiled loop takes one step and its time sizes the next), for
            sweeps in which some runs may need far more steps than expected.
            Default: no limit.

        Returns
        -------
        Result

        Raises
        ------
        NonFiniteState
            A position or velocity became NaN or infinite.  The exception
            carries ``time``, ``step`` and ``result``, which ends with the last
            good state; the simulation is left at that state.

        Examples
        --------
        >>> result = sim.run(until=1 * u.yr, outputs=5, progress=False)
        >>> result.times.round(2)
        <Quantity [  0.  ,  91.  , 183.  , 274.  , 365.25] d>
        >>> bool(result.max_energy_error() < 1e-5)
        True
        >>> back = sim.run(until=0 * u.day, outputs=3, progress=False)   # and back
        >>> back.times.round(3), sim.time
        (<Quantity [365.25, 182.25,   0.  ] d>, <Quantity 0. d>)
        """
        plan = self._plan(self._time_value(until, "until"), outputs, until)
        self._wall_limit = _run_plan.checked_seconds(wall_limit, checkpoint_interval)
        if output is None:
            rec = Recorder(self, initial=plan.outputs > 1, capacity=plan.outputs)
        else:
            rec = _hdf5.FileRecorder(output, self, plan, overwrite=overwrite,
                                     checkpoint_interval=checkpoint_interval)
        return self.execute(plan, rec, progress)

    def _plan(self, until_v, outputs, until=None):
        """Where a run to ``until_v`` takes its outputs: a :class:`RunPlan`."""
        return _run_plan.plan(self, until_v, outputs, until, DEFAULT_OUTPUTS)

    def _fail(self, status, rec, wall0):
        _failures.fail(self, status, rec, wall0)

    def __reduce__(self):
        # not field by field, which would lose which arrays are views of which
        # (the bodies' rows of the state, the workspace's bound arrays) and
        # run to other numbers: made again from its configuration, with its
        # exact state, as a restart from a file is (_state.twin_parts)
        return (_state.rebuilt, (type(self),) + _state.twin_parts(self))

    def __deepcopy__(self, memo):
        parts = list(_state.twin_parts(self))
        parts[5] = copy.deepcopy(parts[5], memo)     # the collisions resolved
        return _state.rebuilt(type(self), *parts)

    def __repr__(self):
        """One line: bodies, time, integrator and its options, step, forces, stopping
        conditions."""
        return _described.one_line(self)

    def _repr_html_(self):
        """The same as a table, for Jupyter."""
        return _described.html_table(self)
