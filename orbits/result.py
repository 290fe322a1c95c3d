"""What a run returns: outputs as Quantities, monitor series, and a summary.

A :class:`Result` also analyses its outputs: orbital elements over time
(:meth:`Result.elements`), the same outputs in another frame
(:meth:`Result.relative_to`, :meth:`Result.barycentric`,
:meth:`Result.in_frame`), tables (:meth:`Result.to_pandas`,
:meth:`Result.to_xarray`) and plots (:meth:`Result.plot`,
:meth:`Result.plot_elements`).  :func:`orbits.load` returns a Result, so all
of this works on output files as well.
"""

import copy as _copy
import math

import astropy.units as u
import numpy as np

from . import epochs as _epochs
from ._kernels import elements as _elements
from ._kernels.status import describe_status
from .body import Track, unknown_body
from .errors import (BodyError, ElementsError, NoEpochError, NoMassiveBodyError,
                     UnknownBodyError)
from .geometry import angle_between, barycentre, is_barycentre
from ._monitor_specs import BY_NAME, RECORDED_FIELDS, RESULT_FIELDS
from .monitors import massless_energy_errors
from .units import UnitSystem, format_time, time_unit

__all__ = ["Result", "FRAMES", "DOMINANT_MASS_FRACTION"]

#: Frame names that :meth:`Result.in_frame` and the plots take besides a body's name.
FRAMES = ("barycentric", "heliocentric")

#: The default frame of :meth:`Result.in_frame` is about the most massive body
#: when that body holds more than this fraction of the total mass (a star with
#: planets, a planet with moons); otherwise (three comparable stars, a
#: cluster) about the barycentre, where no body is a natural centre.
DOMINANT_MASS_FRACTION = 0.5

_ELEMENT_KEYS = ("a", "e", "inc", "Omega", "omega", "f", "M")

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
    >>> import astropy.units as u
    >>> import orbits
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    >>> result = sim.run(until=10 * u.yr, outputs=11, progress=False)
    >>> result
    <Result: 11 outputs of 2 bodies, leapfrog, completed>
    >>> result.times[-1].to(u.yr), result.positions.shape, result.positions.unit
    (<Quantity 10. yr>, (11, 2, 3), Unit("AU"))
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
        >>> import astropy.units as u
        >>> import orbits
        >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
        >>> result = sim.run(until=1 * u.yr, outputs=5, progress=False)
        >>> result["Planet"].positions.shape
        (5, 3)
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
        >>> import astropy.units as u
        >>> import orbits
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

    def _repr_html_(self):
        """Outputs, time span, integrator, status and largest errors, for Jupyter."""
        import html
        opts = ", ".join(f"{k[7:]}={v!r}" for k, v in self.integrator.items()
                         if k.startswith("option."))
        if len(self.times):
            start = self.times[0] if self.start_time is None else self.start_time
            span = f"{start:.6g} to {self.times[-1]:.6g}"
            length = self.times[-1] - start
            if length.unit.physical_type == "time" and abs(length) > 1 * u.yr:
                span += f" ({length.to(u.yr):.6g})"
        else:
            span = "no outputs"
        names = ", ".join(self.names[:6]) + (", ..." if len(self.names) > 6 else "")
        tp = self.test_particle_energy_error
        errors = (("largest energy error", self.max_energy_error()),
                  ("largest test-particle energy error",
                   None if tp is None or not np.isfinite(tp).any() else float(np.nanmax(tp))),
                  ("largest ang. momentum error", self.max_angular_momentum_error()))
        rows = [("outputs", str(len(self))), ("bodies", f"{len(self.names)}: {names}"),
                ("time", span),
                ("integrator", self.integrator["name"] + (f"({opts})" if opts else "")),
                ("steps", str(self.steps)), ("status", str(self.status)),
                *((k, f"{v:.3e}") for k, v in errors if v is not None)]
        cells = "".join(f"<tr><th style='text-align:left'>{k}</th><td>{html.escape(v)}</td>"
                        f"</tr>" for k, v in rows)
        return f"<div><strong>Result</strong><table>{cells}</table></div>"

    def max_energy_error(self):
        """Largest relative energy error seen, at outputs or by the in-loop monitor.

        Returns
        -------
        float or None
            Dimensionless; None where the energy was not monitored.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
        >>> result = sim.run(until=10 * u.yr, outputs=11, progress=False)
        >>> err = result.max_energy_error()
        >>> bool(0 < err < 1e-10), bool(err == result.energy_error.max())
        (True, True)
        """
        return self._max_error("energy")

    def max_angular_momentum_error(self):
        """Largest relative angular-momentum error seen.

        Returns
        -------
        float or None
            Dimensionless; None where the angular momentum was not monitored.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
        >>> result = sim.run(until=10 * u.yr, outputs=11, progress=False)
        >>> bool(result.max_angular_momentum_error() < 1e-13)
        True
        """
        return self._max_error("angular_momentum")

    def _max_error(self, name):
        """The largest relative error of monitor ``name`` seen: at the outputs,
        in the in-loop series, and over the whole run where the result holds
        only part of it (:attr:`largest_errors`); None where it was not
        monitored."""
        field = BY_NAME[name].error_field
        recorded = (self.largest_errors or {}).get(name)
        return _largest(getattr(self, field), self.monitor and self.monitor.get(field),
                        None if recorded is None else np.array([recorded]))

    @property
    def test_particle_energy_error(self):
        """The massless bodies' largest relative energy change at each output
        (see the class's attributes), or None.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> b = orbits.scenes.kepler()
        >>> b.add("comet", mass=0 * u.Msun, primary="Star", a=3 * u.au, e=0.9)
        >>> sim = orbits.Simulation(b, "ias15")
        >>> result = sim.run(until=10 * u.yr, outputs=11, progress=False)
        >>> err = result.test_particle_energy_error
        >>> err.shape, bool(err.max() < 1e-13)
        ((11,), True)
        >>> line = result.summary().splitlines()[7]      # the planet's orbit is circular
        >>> line[:45], line.split("(")[1]
        ('test particles  largest relative energy error', 'comet; Jacobi integral)')
        """
        found = self._massless_errors()
        return None if found is None else np.fmax.reduce(found[3], axis=1)

    def _massless_errors(self):
        """(kind, primary's name, the massless bodies' names, errors (n, k)) of
        :func:`orbits.monitors.massless_energy_errors` on the outputs, made once;
        None where ``test_particle_energy_error`` is."""
        if "_massless" not in self.__dict__:
            self.__dict__["_massless"] = self._make_massless_errors()
        return self.__dict__["_massless"]

    def _make_massless_errors(self):
        if "energy" not in (getattr(self, "monitors", None) or ()):
            return None
        m0 = self.masses.value
        if not np.any(m0 == 0) or not np.any(m0 > 0) or not len(self.times):
            return None
        if self.start_time is not None and self.start_time != self.times[0]:
            return None             # the last output of a run written to a file
        U, x, v, m = self._internal()
        masses = (None if self.masses_at_outputs is None
                  else self.masses_at_outputs.to_value(U.unit("mass")))
        kind, primary, index, errors = massless_energy_errors(x, v, m, U.G, masses)
        return (kind, None if primary is None else self.names[primary],
                [self.names[i] for i in index], errors)

    def summary(self):
        """A few lines for a person: what ran, how long, and how well it kept the invariants.

        Returns
        -------
        str

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
        >>> result = sim.run(until=10 * u.yr, outputs=11, progress=False)
        >>> lines = result.summary().splitlines()
        >>> lines[0]
        'integrator      leapfrog (order 2, symplectic)'
        >>> [line.split()[0] for line in lines[1:]]
        ['bodies', 'time', 'steps', 'units', 'forces', 'energy', 'ang.', 'status']
        """
        opts = ", ".join(f"{k[7:]}={v}" for k, v in self.integrator.items()
                         if k.startswith("option."))
        wall_text = _wall_text(self.wall_time, self.__dict__.get("compile_time"), self.steps)
        forces = ("force evaluations not recorded" if self.force_evaluations is None
                  else f"{self.force_evaluations} force evaluations")
        if len(self.times):
            start = self.times[0] if self.start_time is None else self.start_time
            end = self.times[-1]
            # both ends in the unit of the larger, so that they read alike
            unit = time_unit(max(abs(start), abs(end)))
            span = f"{start.to_value(unit):.6g} -> {format_time(end, unit)}"
        else:
            span = "no outputs"
        lines = [
            f"integrator      {self.integrator['name']} (order {self.integrator['order']}"
            f"{', symplectic' if self.integrator['symplectic'] else ''})"
            + (f" [{opts}]" if opts else ""),
            f"bodies          {len(self.names)}: {', '.join(self.names[:6])}"
            + (", ..." if len(self.names) > 6 else ""),
            f"time            {span}, "
            + ("adaptive steps" if self.integrator.get("adaptive")
               else f"dt = {format_time(self.dt)}"),
            f"steps           {self.steps} "
            + (f"(+{self.steps_rejected} rejected) " if self.integrator.get("adaptive") else "")
            + f"({forces}), {wall_text}",
            f"units           {self.units.name}, G = {self.units.G!r} "
            f"({self.units.G_source})",
            f"forces          {' + '.join(['Newtonian gravity', *self.forces])}",
        ]
        e = self.max_energy_error()
        if e is not None:
            lines.append(f"energy          largest relative error {e:.3e}"
                         + _final(self.energy_error))
        found = self._massless_errors()
        if found is not None:
            kind, primary, names, errors = found
            worst = np.fmax.reduce(errors, axis=0)
            k = int(np.nanargmax(worst)) if np.isfinite(worst).any() else 0
            what = "Jacobi integral" if kind == "jacobi" else f"Kepler energy about {primary}"
            lines.append(f"test particles  largest relative energy error {worst[k]:.3e} "
                         f"({names[k]}; {what})")
        lerr = self.max_angular_momentum_error()
        if lerr is not None:
            lines.append(f"ang. momentum   largest relative error {lerr:.3e}"
                         + _final(self.angular_momentum_error))
        if self.collisions is not None:
            kinds = ", ".join(f"{k} {int(np.sum(self.collisions['resolution'] == k))}"
                              for k in ("merge", "bounce")
                              if np.any(self.collisions["resolution"] == k))
            lines.append(f"collisions      {len(self.collisions)}"
                         + (f" ({kinds})" if kinds else ""))
        if self.encounters is not None:
            lines.append(f"encounters      {len(self.encounters)} logged")
        lines.append(f"status          {self.status}")
        return "\n".join(lines)

    # -- analysis ---------------------------------------------------------------
    def elements(self, body, primary=None):
        """Osculating orbital elements of a body at every output.

        The elements, angle conventions and default primary of
        :meth:`orbits.BodySet.elements`, from the same compiled kernel, run on
        all outputs at once; and the orbital period.

        Parameters
        ----------
        body : str
            The body's name.
        primary : str, optional
            The body the orbit is about, by name; or ``"barycentre"`` (or
            ``"barycenter"``): the centre of mass of all bodies at each output,
            ``body`` included, with ``mu = G (M + m)`` (REBOUND's
            ``particle.orbit(primary=sim.com())``; bodies merged away by a
            collision left out).  Default: the centre of mass of the bodies
            before ``body`` in the set (Jacobi-like, as in
            :meth:`~orbits.BodySet.elements` and REBOUND's ``Particle.orbit()``).

        Returns
        -------
        dict of Quantity, each of shape (n,) for n outputs
            ``a`` (length; negative for a hyperbolic orbit), ``e``
            (dimensionless), ``inc``, ``Omega``, ``omega``, ``f``, ``M`` (angles
            in rad), and ``P`` (time; NaN for a hyperbolic orbit, which has no
            period), in the run's unit system.

        Raises
        ------
        UnknownBodyError
            ``body`` or ``primary`` is not one of the bodies.
        BodyError
            ``primary`` is ``body`` itself, or no massive body comes before
            ``body`` in the set and no primary is named.
        ElementsError
            At some output the state describes no orbit: the body is on its
            primary, or the orbit is radial or parabolic to within rounding.  The
            message gives the first such output.

        Notes
        -----
        With ``mu = G (m_primary + m_body)`` and the relative state ``r, v``:
        ``1/a = 2/|r| - |v|^2/mu``, the eccentricity vector is
        ``(v x h)/mu - r/|r|`` with ``h = r x v``, and ``P = 2 pi sqrt(a^3/mu)``.
        ``inc`` lies in [0, pi], ``Omega`` and ``omega`` in [0, 2 pi), ``f`` and
        ``M`` in [-pi, pi]; ``M`` of a hyperbola is ``e sinh F - F``.  REBOUND
        reduces some angles to other ranges (compare them modulo 2 pi) and gives
        a hyperbola the negative period ``-2 pi sqrt(|a|^3/mu)``.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> sim = orbits.Simulation(orbits.scenes.outer_solar_system(),
        ...                         integrator="leapfrog", dt=10 * u.day)
        >>> result = sim.run(until=100 * u.yr, outputs=11, progress=False)
        >>> el = result.elements("Jupiter", primary="Sun")
        >>> el["a"].shape
        (11,)
        >>> print(el["a"][0].round(2), el["P"][0].to(u.yr).round(1))
        5.2 AU 11.9 yr
        """
        U = self.units
        mu, dx, dv, here = self._relative_states(body, primary)
        n = len(mu)
        out = np.full((n, 7), np.nan)
        status = np.zeros(n, dtype=np.int64)
        if here.all():
            _elements.state_to_elements_many(mu, dx, dv, out, status)
        elif here.any():
            part = np.empty((int(here.sum()), 7))
            st = np.zeros(len(part), dtype=np.int64)
            _elements.state_to_elements_many(np.ascontiguousarray(mu[here]),
                                             np.ascontiguousarray(dx[here]),
                                             np.ascontiguousarray(dv[here]), part, st)
            out[here], status[here] = part, st
        bad = np.flatnonzero(status)
        if bad.size:
            k = int(bad[0])
            more = f" (and at {bad.size - 1} later outputs)" if bad.size > 1 else ""
            raise ElementsError(f"at output {k} (t = {self.times[k]:.10g}){more}: "
                                f"{describe_status(status[k])}", body=body,
                                field="elements")
        a = out[:, 0]
        period = np.full(n, np.nan)
        bound = a > 0
        period[bound] = 2.0 * math.pi * np.sqrt(a[bound] ** 3 / mu[bound])
        q = U.quantity
        elements = {"a": q(a, "length"), "e": out[:, 1] << u.dimensionless_unscaled}
        for k, key in enumerate(_ELEMENT_KEYS[2:], start=2):
            elements[key] = out[:, k] << u.rad
        elements["P"] = q(period, "time")
        return elements

    def _relative_states(self, body, primary):
        """``mu`` (n,), the body's position and velocity relative to its
        primary (n, 3) each, in the run's internal units, and where both are
        present (n,) (False once a collision merged either away)."""
        i = self._index(body)
        U, x, v, m = self._internal()
        n = x.shape[0]
        # masses at each output where collisions changed them (NaN: merged
        # away), else the masses at the start for every output
        mh = (np.nan_to_num(self.masses_at_outputs.to_value(U.unit("mass")))
              if self.masses_at_outputs is not None else np.broadcast_to(m, (n, len(m))))
        if is_barycentre(primary):
            if not np.any(m > 0):
                raise NoMassiveBodyError("the barycentre needs a body with positive mass")
            mp, xp, vp = barycentre(mh, x, v)
        elif primary is None:
            interior = m[:i]
            if i == 0 or not np.any(interior > 0):
                raise BodyError("orbital elements need a primary: no massive body comes "
                                "before this one in the set; name one with primary=",
                                body=body, field="primary")
            w = mh[:, :i]
            mp = w.sum(axis=1)
            with np.errstate(invalid="ignore", divide="ignore"):
                xp = np.einsum("kj,kjd->kd", w, np.nan_to_num(x[:, :i])) / mp[:, None]
                vp = np.einsum("kj,kjd->kd", w, np.nan_to_num(v[:, :i])) / mp[:, None]
        else:
            if not isinstance(primary, str) or primary not in self.names:
                raise unknown_body(primary, self.names, field="primary", body=body,
                                   what=f"unknown primary {primary!r}",
                                   label="known bodies")
            j = self.names.index(primary)
            if j == i:
                raise BodyError("a body has no orbit about itself; name another primary",
                                body=body, field="primary")
            mp, xp, vp = mh[:, j], x[:, j], v[:, j]
        mu = np.ascontiguousarray(U.G * (mp + mh[:, i]), dtype=float)
        if not np.any(mu > 0):
            raise ElementsError("the primary and the body are both massless; an orbit "
                                "needs mass", body=body, field="primary")
        # outputs after a collision merged the body (or its primary) away: NaN
        here = np.isfinite(x[:, i, 0]) & np.isfinite(xp[:, 0])
        return (mu, np.ascontiguousarray(x[:, i] - xp), np.ascontiguousarray(v[:, i] - vp),
                here)

    def mutual_inclination(self, a, b, primary=None):
        """The angle between the orbital planes of two bodies at every output.

        Parameters
        ----------
        a, b, primary
            As for :meth:`orbits.BodySet.mutual_inclination`.

        Returns
        -------
        Quantity, shape (n,), rad
            In [0, pi]: the angle between the orbits' angular momentum vectors
            ``r x v`` (relative to their primaries); for two orbits about one
            primary, ``cos I = cos i_a cos i_b + sin i_a sin i_b
            cos(Omega_a - Omega_b)``.  NaN at outputs after a collision merged
            either body (or its primary) away.

        Raises
        ------
        UnknownBodyError, BodyError
            As :meth:`elements` raises them.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "leapfrog",
        ...                         dt=10 * u.day)
        >>> result = sim.run(until=1000 * u.yr, outputs=3, progress=False)
        >>> result.mutual_inclination("Jupiter", "Saturn", primary="Sun").to(u.deg).round(3)
        <Quantity [1.251, 1.257, 1.25 ] deg>
        """
        normals = []
        for name in (a, b):
            _, dx, dv, here = self._relative_states(name, primary)
            h = np.cross(dx, dv)
            h[~here] = np.nan
            normals.append(h)
        return angle_between(*normals) << u.rad

    def elements_table(self, body, primary=None):
        """:meth:`elements` at every output as a plain table for people and files.

        Parameters
        ----------
        body : str
            The body's name.
        primary : str, optional
            As for :meth:`elements`.

        Returns
        -------
        columns : list of str
            ``"time [d]"``, ``"a [AU]"``, ``"e"``, ``"inc [deg]"``,
            ``"Omega [deg]"``, ``"omega [deg]"``, ``"f [deg]"``, ``"M [deg]"``,
            ``"P [d]"``: the run's units of time and length, angles in degrees.
        table : ndarray, shape (n, 9)
            One row per output.

        Raises
        ------
        UnknownBodyError, BodyError, ElementsError
            As :meth:`elements` raises them.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> sim = orbits.Simulation(orbits.scenes.outer_solar_system(),
        ...                         integrator="leapfrog", dt=10 * u.day)
        >>> result = sim.run(until=100 * u.yr, outputs=11, progress=False)
        >>> columns, table = result.elements_table("Saturn", primary="Sun")
        >>> columns[:4], table.shape
        (['time [d]', 'a [AU]', 'e', 'inc [deg]'], (11, 9))
        """
        el = self.elements(body, primary=primary)
        values = [self.times.value]
        columns = [_label("time", self.times.unit)]
        for key in (*_ELEMENT_KEYS, "P"):
            q = el[key].to(u.deg) if el[key].unit == u.rad else el[key]
            values.append(q.value)
            columns.append(_label(key, q.unit))
        return columns, np.column_stack(values)

    def relative_to(self, body):
        """The same outputs in the frame in which ``body`` is at rest at the origin.

        Parameters
        ----------
        body : str
            The body's name.

        Returns
        -------
        Result
            A new result whose ``positions`` and ``velocities`` (Quantity, shape
            (n, N, 3), same units) are those of this one minus ``body``'s, and
            whose ``frame`` is ``body``.  Times, masses and monitors are shared,
            unchanged.

        Raises
        ------
        UnknownBodyError
            ``body`` is not one of the bodies.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> sim = orbits.Simulation(orbits.scenes.outer_solar_system(com=True),
        ...                         integrator="leapfrog", dt=10 * u.day)
        >>> helio = sim.run(until=10 * u.yr, outputs=3, progress=False).relative_to("Sun")
        >>> helio.frame, helio.positions[:, 0].max()
        ('Sun', <Quantity 0. AU>)
        """
        j = self._index(body, field="frame")
        return self._shifted(self.positions[:, j:j + 1], self.velocities[:, j:j + 1], body)

    def barycentric(self):
        """The same outputs in the frame of the centre of mass of all bodies.

        Returns
        -------
        Result
            A new result whose ``positions`` and ``velocities`` (Quantity, shape
            (n, N, 3), same units) are measured from the centre of mass at each
            output, and whose ``frame`` is ``"barycentric"``.  Times, masses and
            monitors are shared, unchanged.

        Raises
        ------
        NoMassiveBodyError
            No body has mass.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> sim = orbits.Simulation(orbits.scenes.outer_solar_system(),
        ...                         integrator="leapfrog", dt=10 * u.day)
        >>> bary = sim.run(until=10 * u.yr, outputs=3, progress=False).barycentric()
        >>> com = bary.masses.value @ bary.positions / bary.masses.value.sum()
        >>> bool(abs(com).max() < 1e-15 * u.au)
        True
        """
        m = self.masses.value
        total = m.sum()
        if not total > 0:
            raise NoMassiveBodyError("the barycentre needs a body with positive mass")
        if self.masses_at_outputs is not None:
            # bodies merged away: the masses of each output, without them
            m = np.nan_to_num(self.masses_at_outputs.to_value(self.masses.unit))
            w = m / m.sum(axis=1, keepdims=True)

            def centre(a):
                return np.einsum("kn,knd->kd", w, np.nan_to_num(a.value)) << a.unit
            return self._shifted(centre(self.positions)[:, None],
                                 centre(self.velocities)[:, None], "barycentric")
        w = m / total
        return self._shifted((w @ self.positions)[:, None], (w @ self.velocities)[:, None],
                             "barycentric")

    def in_frame(self, frame=None):
        """The same outputs in a frame given by name.

        Parameters
        ----------
        frame : str, optional
            ``"barycentric"`` (:meth:`barycentric`); ``"heliocentric"``: about
            the most massive body (the star); or a body's name
            (:meth:`relative_to`).  Default: about the most massive body when it
            holds more than :data:`DOMINANT_MASS_FRACTION` of the mass,
            otherwise barycentric.

        Returns
        -------
        Result
            With ``frame`` set to ``"barycentric"`` or the central body's name.

        Raises
        ------
        UnknownBodyError
            ``frame`` is neither a frame name nor a body's name (field ``frame``).

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> sim = orbits.Simulation(orbits.scenes.outer_solar_system(),
        ...                         integrator="leapfrog", dt=10 * u.day)
        >>> result = sim.run(until=10 * u.yr, outputs=3, progress=False)
        >>> result.in_frame().frame, result.in_frame("barycentric").frame
        ('Sun', 'barycentric')
        """
        if frame is None:
            frame = self._default_frame()
        if frame == "barycentric":
            return self.barycentric()
        if frame == "heliocentric":
            return self.relative_to(self.names[int(np.argmax(self.masses.value))])
        if isinstance(frame, str) and frame in self.names:
            return self.relative_to(frame)
        raise UnknownBodyError(f"unknown frame; expected one of {', '.join(FRAMES)} or a "
                               f"body's name ({', '.join(self.names)})", body=frame,
                               field="frame")

    # -- tables -------------------------------------------------------------------
    def to_pandas(self):
        """The outputs as a table, one row per output, units in the column names.

        Returns
        -------
        pandas.DataFrame
            Columns ``"time [d]"``; for each body ``"<name>.x [AU]"``, ``.y``,
            ``.z``, ``.vx [AU / d]``, ``.vy``, ``.vz`` (in the units of
            ``positions``, ``velocities`` and ``times``); then the monitors that
            were recorded: ``"energy [...]"``, ``"energy_error"``,
            ``"test_particle_energy_error"`` (with massless bodies),
            ``"angular_momentum.x [...]"`` ..., ``"angular_momentum_error"``,
            ``"momentum.x [...]"`` ..., ``"center_of_mass.x [...]"`` ....
            Dimensionless quantities have no bracket.  ``DataFrame.attrs``
            holds ``frame``, ``names``, ``masses`` (a list of floats),
            ``mass_unit`` and ``units`` (the unit system, as
            :meth:`~orbits.UnitSystem.to_dict` gives it).

        Raises
        ------
        ImportError
            pandas is not installed (``pip install pandas``).

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> sim = orbits.Simulation(orbits.scenes.kepler(e=0.5), integrator="leapfrog",
        ...                         dt=1 * u.day)
        >>> df = sim.run(until=10 * u.day, outputs=3, progress=False).to_pandas()
        >>> list(df.columns[:4])
        ['time [d]', 'Star.x [AU]', 'Star.y [AU]', 'Star.z [AU]']
        """
        try:
            import pandas as pd
        except ImportError:
            raise ImportError("Result.to_pandas needs pandas: pip install pandas") from None
        x, v = self.positions, self.velocities
        columns = [_label("time", self.times.unit)]
        data = [self.times.value[:, None]]
        n, nb = x.shape[0], x.shape[1]
        per_body = np.concatenate([x.value, v.value], axis=2)       # (n, N, 6)
        data.append(per_body.reshape(n, 6 * nb))
        for name in self.names:
            columns += [_label(f"{name}.{c}", x.unit) for c in "xyz"]
            columns += [_label(f"{name}.{c}", v.unit) for c in ("vx", "vy", "vz")]
        for key, values in self._monitor_series():
            if values.ndim == 2:
                columns += [_label(f"{key}.{c}", getattr(values, "unit", None))
                            for c in "xyz"]
            else:
                columns.append(_label(key, getattr(values, "unit", None)))
            data.append(np.asarray(getattr(values, "value", values)).reshape(n, -1))
        df = pd.DataFrame(np.concatenate(data, axis=1), columns=columns)
        df.attrs.update(frame=self.frame, names=list(self.names),
                        masses=self.masses.value.tolist(),
                        mass_unit=self.masses.unit.to_string(), units=self.units.to_dict())
        return df

    def to_xarray(self):
        """The outputs as an ``xarray.Dataset``, units in the variables' attributes.

        Returns
        -------
        xarray.Dataset
            Coordinates ``time`` (n), ``body`` (N names) and ``axis``
            (``"x", "y", "z"``); variables ``position`` and ``velocity``
            (time, body, axis), ``mass`` (body) and the monitors that were
            recorded (``energy``, ``energy_error``, ``angular_momentum``
            (time, axis), ...).  Each has a ``units`` attribute (astropy's
            spelling, ``""`` for dimensionless); the dataset's attributes say
            the ``frame``, the ``integrator`` and the unit system.

        Raises
        ------
        ImportError
            xarray is not installed (``pip install xarray``).

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> sim = orbits.Simulation(orbits.scenes.kepler(e=0.5), integrator="leapfrog",
        ...                         dt=1 * u.day)
        >>> result = sim.run(until=10 * u.day, outputs=3, progress=False)
        >>> ds = result.to_xarray()                     # doctest: +SKIP
        >>> ds["position"].attrs["units"]               # doctest: +SKIP
        'AU'
        """
        try:
            import xarray as xr
        except ImportError:
            raise ImportError("Result.to_xarray needs xarray: pip install xarray") from None

        def var(dims, q):
            unit = getattr(q, "unit", u.dimensionless_unscaled)
            return xr.Variable(dims, np.asarray(getattr(q, "value", q)),
                               attrs={"units": unit.to_string()})

        data = {"position": var(("time", "body", "axis"), self.positions),
                "velocity": var(("time", "body", "axis"), self.velocities),
                "mass": var(("body",), self.masses)}
        for key, values in self._monitor_series():
            data[key] = var(("time", "axis") if values.ndim == 2 else ("time",), values)
        coords = {"time": var(("time",), self.times), "body": list(self.names),
                  "axis": ["x", "y", "z"]}
        attrs = {"frame": "as integrated" if self.frame is None else self.frame,
                 "integrator": str(self.integrator.get("name", "")),
                 "status": str(self.status)}
        attrs.update({f"units_{k}": str(val) for k, val in self.units.to_dict().items()})
        return xr.Dataset(data, coords=coords, attrs=attrs)

    # -- plots --------------------------------------------------------------------
    def plot(self, frame=None, path=None, fig=None):
        """Orbits in the x-y plane in a chosen frame, and the invariants' errors.

        See :func:`orbits.plotting.plot_result`.

        Parameters
        ----------
        frame : str, optional
            As for :meth:`in_frame`: by default about the most massive body where
            it holds most of the mass, else barycentric.
        path : str or path-like, optional
            Also write the figure there (PNG).
        fig : matplotlib.figure.Figure, optional
            An empty figure to draw into (``matplotlib.pyplot.figure()`` for
            one that pyplot shows); default a new one pyplot does not manage.

        Returns
        -------
        matplotlib.figure.Figure

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> sim = orbits.Simulation(orbits.scenes.outer_solar_system(),
        ...                         integrator="leapfrog", dt=10 * u.day)
        >>> fig = sim.run(until=100 * u.yr, outputs=50, progress=False).plot()
        >>> fig.axes[0].get_title()
        'orbits (x-y plane), about Sun'
        """
        from .plotting import plot_result
        return plot_result(self, path=path, frame=frame, fig=fig)

    def plot_elements(self, bodies=None, primary=None, path=None, fig=None):
        """Semi-major axis, eccentricity and inclination against time.

        See :func:`orbits.plotting.plot_elements`.

        Parameters
        ----------
        bodies : sequence of str, optional
            Default: every body but ``primary`` (but the first when no primary
            is named), at most 12.
        primary : str, optional
            As for :meth:`elements`.
        path : str or path-like, optional
            Also write the figure there (PNG).
        fig : matplotlib.figure.Figure, optional
            An empty figure to draw into (``matplotlib.pyplot.figure()`` for
            one that pyplot shows); default a new one pyplot does not manage.

        Returns
        -------
        matplotlib.figure.Figure

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> sim = orbits.Simulation(orbits.scenes.outer_solar_system(),
        ...                         integrator="leapfrog", dt=10 * u.day)
        >>> fig = sim.run(until=100 * u.yr, outputs=50, progress=False).plot_elements()
        >>> [ax.get_ylabel() for ax in fig.axes]
        ['a [AU]', 'e', 'inc [deg]']
        """
        from .plotting import plot_elements
        return plot_elements(self, bodies=bodies, primary=primary, path=path, fig=fig)

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

    def _default_frame(self):
        m = self.masses.value
        k = int(np.argmax(m))
        total = m.sum()
        if total > 0 and m[k] > DOMINANT_MASS_FRACTION * total:
            return self.names[k]
        return "barycentric"

    def _shifted(self, dx, dv, frame):
        new = _copy.copy(self)
        new.positions = self.positions - dx
        new.velocities = self.velocities - dv
        new.frame = frame
        return new

    def _monitor_series(self):
        """(name, series) of the monitors recorded at every output."""
        n = len(self.times)
        for key in RESULT_FIELDS:
            values = getattr(self, key, None)
            if values is not None and len(values) == n:
                yield key, values


def _label(name, unit):
    """``"name [unit]"``, or ``"name"`` for a dimensionless quantity."""
    text = "" if unit is None else u.Unit(unit).to_string()
    return f"{name} [{text}]" if text else name


def _wall_text(wall, compiling, steps):
    """The run's time for :meth:`Result.summary`: steps per second over the
    time spent stepping, the compiling apart.

    Examples
    --------
    >>> from orbits.result import _wall_text
    >>> _wall_text(34.0, 31.0, 290000)
    'wall time 34 s (compiling 31 s, stepping 3 s, 9.67e+04 steps/s)'
    >>> _wall_text(0.5, 0.0, 50000)
    'wall time 0.5 s (1e+05 steps/s)'
    """
    if wall is None or not np.isfinite(wall):
        return "wall time not recorded"
    if not compiling or not np.isfinite(compiling):
        rate = steps / wall if wall > 0 else float("inf")
        return f"wall time {wall:.3g} s ({rate:.3g} steps/s)"
    stepping = max(wall - compiling, 0.0)
    rate = steps / stepping if stepping > 0 else float("inf")
    return (f"wall time {wall:.3g} s (compiling {compiling:.3g} s, stepping {stepping:.3g} s, "
            f"{rate:.3g} steps/s)")


def _final(series):
    return f", final {series[-1]:.3e}" if series is not None and len(series) else ""


def _largest(*series):
    vals = [np.max(s) for s in series if s is not None and len(s)]
    return float(max(vals)) if vals else None
