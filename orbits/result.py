"""What a run returns: the :class:`Result` record of its outputs as Quantities
and its monitor series.

A Result also analyses its outputs, each idea in a module of its own whose
functions are the result's methods: how well the run kept its invariants and
its summary (:meth:`Result.max_energy_error`, :meth:`Result.summary`;
``orbits._result_summary``), orbital elements over time
(:meth:`Result.elements`; ``orbits._result_elements``), the same outputs in
another frame (:meth:`Result.relative_to`, :meth:`Result.barycentric`,
:meth:`Result.in_frame`; ``orbits._result_frames``), tables and plots
(:meth:`Result.to_pandas`, :meth:`Result.to_xarray`, :meth:`Result.plot`,
:meth:`Result.plot_elements`; ``orbits._result_exports``).
:func:`orbits.load` returns a Result, so all of this works on output files
as well.
"""

from . import _result_elements, _result_exports, _result_frames, _result_summary
from . import epochs as _epochs
from ._monitor_specs import RECORDED_FIELDS
from .body import Track, unknown_body
from .errors import NoEpochError
from .units import UnitSystem

__all__ = ["Result", "FRAMES", "DOMINANT_MASS_FRACTION"]

#: Frame names that :meth:`Result.in_frame` and the plots take besides a body's name.
FRAMES = _result_frames.FRAMES

#: The default frame of :meth:`Result.in_frame` is about the most massive body
#: when that body holds more than this fraction of the total mass (a star with
#: planets, a planet with moons); otherwise (three comparable stars, a
#: cluster) about the barycentre, where no body is a natural centre.
DOMINANT_MASS_FRACTION = _result_frames.DOMINANT_MASS_FRACTION


class Result:
    """Outputs of one :meth:`orbits.Simulation.run`.

    Attributes
    ----------
    times : Quantity, shape (n,)
        Times of the outputs (the first is the state the run started from);
        decreasing for a run backwards in time.
    epoch : astropy.time.Time or None
        The date of time 0 (TDB): the epoch of the body set the simulation
        was made from, or None where it had none.  :attr:`epochs` gives the
        outputs' dates.
    positions, velocities : Quantity, shape (n, N, 3)
        States at the outputs, bodies in the order of the body set.
    names : list of str
    masses : Quantity, shape (N,)
        At the start of the run.
    masses_at_outputs : Quantity, shape (n, N), or None
        With ``collisions=`` that merge (``"merge"``, ``"bounce"`` or a
        function): the masses at every output, NaN for a body merged away (its
        positions and velocities are NaN from then on, and the merged body
        keeps the survivor's column); None otherwise.
    collisions : astropy.table.QTable or None
        With ``collisions=`` resolved by the run: one row per collision,
        ``time`` (of contact), ``step_time`` (the end of the step, where it
        was resolved), ``body_1``, ``body_2``, ``resolution`` (``"merge"`` or
        ``"bounce"``), ``survivor`` (of a merger), ``distance`` and ``speed``
        at contact and ``energy_change`` (what the resolution changed the
        bodies' energy by; the energy monitor books it as work).  Also in
        output files (group ``collisions``).  None otherwise.
    encounters : astropy.table.QTable or None
        With ``encounter_log=``: one row per close approach inside the
        threshold, ``time`` (of closest approach), ``body_1``, ``body_2``,
        ``distance`` and ``speed`` (relative); None without the log.  Also in
        output files (group ``encounters``), which :func:`orbits.load` reads.
    radii : Quantity, shape (N,), length, or None
        The bodies' physical radii (0 for a point mass; all 0 when read from a
        file written before radii were kept); None where not recorded.
    energy : Quantity, shape (n,) or None
        Total energy at the outputs (None if the energy monitor is off).
    work : Quantity, shape (n,) or None
        With non-conservative force terms (drag, tides, migration, radiation
        pressure, a :class:`~orbits.forces.UserForce` without a potential) and
        the energy monitor: ``W``, the energy those terms have taken out of the
        bodies since the simulation was made (see
        :attr:`orbits.Simulation.work`); None otherwise.
    energy_error : ndarray, shape (n,) or None
        ``|E + W - E0| / |E0|`` against the energy when the simulation was
        made: the integration's error, the work ``W`` of non-conservative terms
        (zero without them) accounted for.  Massless bodies add nothing to
        ``E``; ``test_particle_energy_error`` watches them.
    test_particle_energy_error : ndarray, shape (n,) or None
        With the energy monitor and massless bodies: at each output, the
        largest over the massless bodies of ``|e - e0| / |e0|``, the relative
        change of the specific energy each keeps since the first output
        (:func:`orbits.monitors.massless_energies`): the Jacobi integral when
        two massive bodies are on a circular orbit (the circular restricted
        three-body problem), else the Kepler energy about the most massive
        body.  Both are constants of the motion with one massive body or a
        circular binary, so the figure measures the integration there; with
        more massive bodies their pull changes the Kepler energy by about
        their mass ratio to the primary, so it tells an orbit kept from one
        destroyed (a change of order one), not round-off.  Newtonian: force
        terms acting on test particles change it too.  Computed from the
        outputs when first read (no cost per step); its reference is the first
        output, where ``energy_error``'s is the simulation's start.  None
        without massless bodies or the energy monitor, and for a run written
        to a file, whose result holds the last output only (:func:`orbits.load`
        the file for the series).  :meth:`summary` names the body.
    angular_momentum : Quantity, shape (n, 3) or None
    angular_momentum_error : ndarray, shape (n,) or None
        ``|L - L0| / |L0|`` (see :func:`orbits.monitors.vector_relative_error`).
    momentum, center_of_mass : Quantity, shape (n, 3) or None
        When those monitors are on.
    megno, fli : ndarray, shape (n,) or None
        With those monitors: the running mean of MEGNO (Cincotta & Simo
        2000; tends to 2 on a regular orbit and grows as ``lambda t / 2`` on a
        chaotic one) and the fast Lyapunov indicator ``max ln |delta|`` at
        the outputs (see :class:`orbits.Simulation`'s ``monitors``).
    lyapunov : Quantity (1 / time), shape (n,) or None
        With that monitor: the largest Lyapunov exponent's estimate
        ``ln(|delta(t)| / |delta(0)|) / t`` at the outputs.
    jacobian : ndarray, shape (6N, 6N) or (6N, 7N), or None
        With ``variations="state"`` or ``"all"``: the derivatives of the final
        state with respect to the initial one (see
        :attr:`orbits.Simulation.jacobian`).
    tangent_vectors : ndarray, shape (k, N, 6) or None
        With variations or chaos monitors: the final tangent vectors (see
        :attr:`orbits.Simulation.tangent_vectors`); ``seed`` is the seed of
        the random ones.
    monitor : dict or None
        Series recorded inside the compiled loop every ``monitor_every``
        steps: ``times`` and the same error arrays as above.
    steps : int
        Steps taken (accepted) in this run.  ``force_evaluations`` and
        ``steps_rejected`` (adaptive integrators) likewise; ``force_evaluations``
        is None where it was not recorded (files written by older versions).
    wall_time : float or None
        Seconds of wall-clock time the run took (None where not recorded).
    compile_time : float or None
        Seconds of ``wall_time`` that numba spent compiling the run's loops
        and kernels (0 when all were loaded from its cache, or compiled by an
        earlier run of the process); the rest was stepping.  None where not
        recorded (a result read from a file).
    start_time : Quantity or None
        Time the run started from, where ``times`` may not begin there (a run
        written to a file returns only its last output).
    largest_errors : dict or None
        Largest relative errors of ``"energy"`` and ``"angular_momentum"`` over
        the whole run, where the series kept here do not hold all of it (a run
        written to a file); :meth:`max_energy_error` takes them into account.
    integrator : dict
        Name and options of the integrator.
    units : UnitSystem
        The run's unit system, G and where it came from included, as
        :func:`orbits.load` reads it back from a file: a body set made from
        the result's arrays takes it (``BodySet.from_arrays(...,
        units=result.units)``) and keeps the run's G.
    status : str
        ``"completed"`` or the reason the run stopped.
    forces : tuple of str
        The force terms added to gravity, as written (``"GR(source='Sun')"``).
    frame : str or None
        The frame of ``positions`` and ``velocities``: None for the frame the
        run was integrated in, ``"barycentric"``, or the name of the body at
        the origin (see :meth:`relative_to`).  Monitors (energy, momentum,
        centre of mass) are always those of the run, in its own frame.

    Notes
    -----
    A run hands its arrays to the result as they are; the Quantities (times,
    states, masses, step) and the monitor series are made the first time one
    of them is read.  A script that calls ``run`` many times for a few steps
    each then does not pay for what it never reads.  Copies and pickles
    carry the values themselves.

    Examples
    --------
    Two runs, which the examples of the methods use as ``two_body`` and
    ``planets``:

    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    >>> two_body = sim.run(until=10 * u.yr, outputs=11, progress=False)
    >>> two_body
    <Result: 11 outputs of 2 bodies, leapfrog, completed>
    >>> two_body.times[-1].to(u.yr), two_body.positions.shape, two_body.positions.unit
    (<Quantity 10. yr>, (11, 2, 3), Unit("AU"))
    >>> sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "leapfrog",
    ...                         dt=10 * u.day)
    >>> planets = sim.run(until=100 * u.yr, outputs=11, progress=False)
    >>> planets.names
    ['Sun', 'Jupiter', 'Saturn', 'Uranus', 'Neptune', 'Pluto']
    """

    def __init__(self, _deferred=(), **fields):
        self.monitor = None
        for name in RECORDED_FIELDS:       # the monitors' series: None unless recorded
            setattr(self, name, None)
        self.jacobian = self.tangent_vectors = self.seed = None
        self.radii = None
        self.encounters = None
        self.masses_at_outputs = self.collisions = None
        self.status = "completed"
        self.steps_rejected = 0
        self.compile_time = None
        self.forces = ()
        self.start_time = None
        self.largest_errors = None
        self.frame = None
        self.epoch = None
        for k, v in fields.items():
            setattr(self, k, v)
        if isinstance(self.__dict__.get("units"), dict):   # as UnitSystem.to_dict() gives it
            self.units = UnitSystem.from_dict(self.units)
        # fields made when first read: ``_deferred`` holds (names, make)
        # pairs, ``make()`` returning a dict of those names (a run's arrays
        # with their units, its monitor series); reading any of them makes
        # the group.  A run called many times for a few steps each then does
        # not pay for the Quantities it never reads.
        self._deferred = {}
        for names, make in _deferred:
            for name in names:
                self.__dict__.pop(name, None)
                self._deferred[name] = (names, make)

    def _defer(self, name, make):
        """The field ``name`` made by ``make()`` where it is first read (None:
        the field is None), as the fields deferred at construction."""
        if make is None:
            self.__dict__[name] = None
            return
        self.__dict__.pop(name, None)
        self._deferred[name] = ((name,), lambda: {name: make()})

    def __getattr__(self, name):
        # only for names not set: a deferred field, made now
        deferred = self.__dict__.get("_deferred")
        if deferred and name in deferred:
            self._make(name)
            return self.__dict__[name]
        raise AttributeError(f"'Result' object has no attribute '{name}'")

    def _make(self, name):
        names, make = self._deferred[name]
        values = make()
        for k in names:
            self._deferred.pop(k, None)
            self.__dict__.setdefault(k, values[k])

    def __getstate__(self):
        # a copy or pickle carries the fields themselves
        while self.__dict__.get("_deferred"):
            self._make(next(iter(self._deferred)))
        return self.__dict__

    def __len__(self):
        return len(self.times)

    def __getitem__(self, name):
        """One body's track through the outputs, by name.

        Parameters
        ----------
        name : str

        Returns
        -------
        orbits.body.Track
            ``times``, ``positions`` and ``velocities`` (shape (n, 3), NaN once
            a collision merged the body away), ``masses``, ``elements()`` and
            ``mutual_inclination()``.

        Raises
        ------
        UnknownBodyError
            No body of that name; the message suggests the nearest name.
        TypeError
            ``name`` is not a string (an index would be ambiguous between
            outputs and bodies: ``result.positions[k]`` is output ``k``).

        Examples
        --------
        >>> two_body["Planet"].positions.shape
        (11, 3)
        """
        if not isinstance(name, str):
            raise TypeError(f"a result's bodies are looked up by name (str), got "
                            f"{type(name).__name__}; result.positions[k] is output k")
        return Track(self, self._index(name))

    def __contains__(self, name):
        """Whether a body of this name is in the result."""
        return isinstance(name, str) and name in self.names

    __iter__ = None     # not a sequence of outputs or bodies: iterate over result.names

    @property
    def epochs(self):
        """The outputs' dates, ``epoch + times``: an ``astropy.time.Time`` array in
        TDB, of the shape of :attr:`times`.

        Raises
        ------
        orbits.errors.NoEpochError
            The bodies of the run carried no epoch (:attr:`epoch` is None); a
            run without a date has only :attr:`times`.

        Examples
        --------
        >>> sim = orbits.Simulation(orbits.scenes.de421(epoch="2000-01-01T12:00:00 TDB"),
        ...                         "wh", dt=1 * u.day)
        >>> result = sim.run(until=1 * u.yr, outputs=3, progress=False)
        >>> result.epochs.isot.tolist()
        ['2000-01-01T12:00:00.000', '2000-07-02T12:00:00.000', '2000-12-31T18:00:00.000']
        """
        if self.epoch is None:
            raise NoEpochError(
                "this run's bodies carried no epoch, so its outputs have times but no "
                "dates; give the bodies one before making the simulation "
                "(bodies.epoch = Time('2000-01-01T12:00:00', scale='tdb'), or "
                "scenes.de421(epoch=...)), or read result.times")
        return _epochs.at_times(self.epoch, self.times)

    def __repr__(self):
        return (f"<Result: {len(self)} outputs of {len(self.names)} bodies, "
                f"{self.integrator['name']}, {self.status}>")

    # -- the invariants' errors and the summary (orbits._result_summary) --------
    max_energy_error = _result_summary.max_energy_error
    max_angular_momentum_error = _result_summary.max_angular_momentum_error
    _max_error = _result_summary._max_error
    test_particle_energy_error = property(_result_summary.particle_energy_error)
    summary = _result_summary.summary
    _repr_html_ = _result_summary._repr_html_

    # -- orbital elements over time (orbits._result_elements) ------------------
    elements = _result_elements.elements
    mutual_inclination = _result_elements.mutual_inclination
    elements_table = _result_elements.elements_table

    # -- the outputs in another frame (orbits._result_frames) ------------------
    relative_to = _result_frames.relative_to
    barycentric = _result_frames.barycentric
    in_frame = _result_frames.in_frame

    # -- tables and plots (orbits._result_exports) -----------------------------
    to_pandas = _result_exports.to_pandas
    to_xarray = _result_exports.to_xarray
    plot = _result_exports.plot
    plot_elements = _result_exports.plot_elements

    # -- internals ----------------------------------------------------------------
    def _index(self, name, field="body"):
        if isinstance(name, str) and name in self.names:
            return list(self.names).index(name)
        raise unknown_body(name, self.names, field=field)

    def _internal(self):
        """The unit system and plain arrays of positions, velocities and masses in it."""
        U = self.units
        return (U, self.positions.to_value(U.unit("length")),
                self.velocities.to_value(U.unit("velocity")),
                self.masses.to_value(U.unit("mass")))
