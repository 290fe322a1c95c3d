"""The named exceptions of ``orbits``.

Input errors say which body, which field, and what was expected.  Run-time
failures say when and at which step they happened, and carry the result up to
the last good state, so that nothing computed is lost.

:class:`BodyUnitsError` is also astropy's ``UnitsError``; astropy is imported
when that class is first asked for, so that code without units (such as
:func:`orbits.integrate`) never imports it.
"""

__all__ = [
    "OrbitsError",
    "BodyError",
    "BodyUnitsError",
    "ElementsError",
    "UnknownBodyError",
    "DuplicateBodyError",
    "CoincidentBodiesError",
    "NoMassiveBodyError",
    "UnknownIntegratorError",
    "IntegratorOptionError",
    "ForceTermError",
    "SystemFileError",
    "EpochError",
    "NoEpochError",
    "RunError",
    "SimulationStopped",
    "NonFiniteState",
    "StepSizeUnderflow",
    "ConvergenceFailure",
    "WallTimeExceeded",
    "CloseEncounter",
    "Collision",
    "Escape",
    "SimulationOptionError",
    "RunInterrupted",
    "OrbitsWarning",
]


class OrbitsError(Exception):
    """Base class of every exception raised by ``orbits``.

    Examples
    --------
    >>> try:
    ...     orbits.integrators.get("rk45")
    ... except orbits.OrbitsError as exc:
    ...     print(type(exc).__name__)
    UnknownIntegratorError
    """


class OrbitsWarning(UserWarning):
    """Something was changed or may not be what was meant, and the run went on.

    Examples
    --------
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     _ = sim.run(until=3 * u.day, progress=False)   # fewer steps than outputs
    >>> [w.category.__name__ for w in caught]
    ['OrbitsWarning']
    """


def _named(kind, value):
    """``"kind 'value'"``, or None where there is no value."""
    return None if value is None else f"{kind} {value!r}"


def _where(*places):
    """The places a message concerns, those not None or empty, joined:
    ``"body 'comet', field 'mass'"``."""
    return ", ".join(p for p in places if p)


def _located(message, *places):
    """``message`` after the places it concerns: ``"body 'comet', field 'mass': message"``."""
    where = _where(*places)
    return f"{where}: {message}" if where else message


class BodyError(OrbitsError, ValueError):
    """A body's value is not acceptable.

    Attributes
    ----------
    body : str or None
        Name (or index) of the body concerned.
    field : str or None
        The field concerned: ``"mass"``, ``"position"``, ``"e"``, ...

    Examples
    --------
    >>> try:
    ...     orbits.scenes.kepler().add("comet", mass=-1 * u.kg)
    ... except orbits.OrbitsError as exc:
    ...     print(type(exc).__name__, exc.body, exc.field)
    BodyError comet mass
    """

    def __init__(self, message, body=None, field=None):
        self.body = body
        self.field = field
        super().__init__(_located(message, _named("body", body), _named("field", field)))


_BODY_UNITS_ERROR_DOC = """A body's value has the wrong physical type, or no unit where one is needed.

    Examples
    --------
    >>> orbits.scenes.kepler().add("moon", mass=1 * u.au)
    Traceback (most recent call last):
        ...
    orbits.errors.BodyUnitsError: body 'moon', field 'mass': expected a mass ...
    >>> issubclass(orbits.errors.BodyUnitsError, u.UnitsError)
    True
    """

#: the examples of the class made on first use, which doctest finds here
__test__ = {"BodyUnitsError": _BODY_UNITS_ERROR_DOC}


def _body_units_error():
    import astropy.units as u

    class BodyUnitsError(BodyError, u.UnitsError):
        __doc__ = _BODY_UNITS_ERROR_DOC

    BodyUnitsError.__module__ = __name__
    BodyUnitsError.__qualname__ = "BodyUnitsError"
    return BodyUnitsError


def __getattr__(name):
    # the one class made on first use (see the module notes)
    if name == "BodyUnitsError":
        cls = globals()["BodyUnitsError"] = _body_units_error()
        return cls
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class ElementsError(BodyError):
    """Orbital elements that describe no orbit (e >= 1 with a > 0, e < 0, ...).

    Examples
    --------
    >>> orbits.scenes.kepler().add("comet", mass=0 * u.kg, a=1 * u.au, e=1.5)
    Traceback (most recent call last):
        ...
    orbits.errors.ElementsError: body 'comet', field 'e': e = 1.5 >= 1 needs a < 0 ...
    """


class UnknownBodyError(BodyError, KeyError):
    """A name that is not in the body set (an unknown ``primary=``, for example).

    Examples
    --------
    >>> orbits.scenes.kepler().index("Moon")
    Traceback (most recent call last):
        ...
    orbits.errors.UnknownBodyError: body 'Moon': no such body; known: Star, Planet
    >>> issubclass(orbits.errors.UnknownBodyError, KeyError)
    True
    """

    def __str__(self):  # KeyError would quote the message
        return Exception.__str__(self)


class DuplicateBodyError(BodyError):
    """A body name that is already used.

    Examples
    --------
    >>> orbits.scenes.kepler().add("Star", mass=1 * u.Msun)
    Traceback (most recent call last):
        ...
    orbits.errors.DuplicateBodyError: body 'Star', field 'name': a body of this name ...
    """


class CoincidentBodiesError(BodyError):
    """Two bodies at exactly the same position: their mutual force is infinite.

    Examples
    --------
    >>> bodies = orbits.scenes.kepler()
    >>> bodies.add("twin", mass=1 * u.Mearth, position=bodies.positions[1])
    >>> bodies.check()
    Traceback (most recent call last):
        ...
    orbits.errors.CoincidentBodiesError: body 'Planet', field 'position': is at the same ...
    """


class NoMassiveBodyError(OrbitsError, ValueError):
    """A simulation needs at least one body with positive mass.

    Examples
    --------
    >>> bodies = orbits.BodySet()
    >>> bodies.add("dust", mass=0 * u.kg)
    >>> bodies.check()
    Traceback (most recent call last):
        ...
    orbits.errors.NoMassiveBodyError: the body set has no body with positive mass ...
    """


class UnknownIntegratorError(OrbitsError, ValueError):
    """An integrator name that is not in the registry.

    Examples
    --------
    >>> orbits.integrators.get("rk45")
    Traceback (most recent call last):
        ...
    orbits.errors.UnknownIntegratorError: unknown integrator 'rk45'; did you mean 'rk4'?; ...
    """


class IntegratorOptionError(OrbitsError, ValueError):
    """An integrator option that is unknown, or whose value is not acceptable.

    Examples
    --------
    >>> orbits.integrators.get("ias15", eps=1e-9)
    Traceback (most recent call last):
        ...
    orbits.errors.IntegratorOptionError: integrator 'ias15' has no option 'eps'; valid options: ...
    """


class EpochError(OrbitsError, ValueError):
    """A value given as an epoch that is not one: not an ``astropy.time.Time``
    (where a Time is asked for), not a single date, or a date that cannot be
    read or carried to TDB (:mod:`orbits.epochs`).

    Examples
    --------
    >>> bodies = orbits.scenes.kepler()
    >>> bodies.epoch = "2000-01-01"
    Traceback (most recent call last):
        ...
    orbits.errors.EpochError: epoch must be an astropy.time.Time, got str; ...
    """


class NoEpochError(EpochError):
    """Dates asked of a simulation or result whose bodies carry no epoch
    (``result.epochs`` of a run without one).

    Examples
    --------
    >>> result = orbits.Simulation(orbits.scenes.kepler(), "leapfrog",
    ...                            dt=1 * u.day).run(until=2 * u.day, progress=False)
    >>> result.epochs
    Traceback (most recent call last):
        ...
    orbits.errors.NoEpochError: this run's bodies carried no epoch, ...
    """


class ForceTermError(OrbitsError, ValueError):
    """A force term (:mod:`orbits.forces`) whose parameters are not acceptable, or
    that does not fit the body set: an unknown source body, a negative radius,
    a user force of the wrong shape.

    Attributes
    ----------
    term : str
        The term concerned, as written (``"GR('Sun')"``).
    field : str or None
        Its parameter concerned: ``"source"``, ``"radius"``, ``"func"``, ...
    body : str or None
        The body concerned (the body of a tide, the body a ``beta`` is for), or None.

    Examples
    --------
    >>> try:
    ...     orbits.forces.ZonalHarmonics("Star", radius=-1 * u.km, J2=1e-3)
    ... except orbits.OrbitsError as exc:
    ...     print(type(exc).__name__, exc.field)
    ForceTermError radius
    """

    def __init__(self, message, term=None, field=None, body=None):
        self.term = term
        self.field = field
        self.body = body
        super().__init__(_located(message, term, _named("body", body),
                                  _named("parameter", field or None)))


class RunError(OrbitsError, RuntimeError):
    """Base class of failures during a run.

    Attributes
    ----------
    time : astropy.units.Quantity or float
        Simulation time of the last good state.
    step : int
        Number of steps completed (since the simulation was made) at the last good state.
    result : orbits.Result or None
        Everything recorded up to the failure, ending with the last good state.

    Examples
    --------
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day,
    ...                         escape_distance=0.5 * u.au)
    >>> try:
    ...     sim.run(until=10 * u.day, outputs=2, progress=False)
    ... except orbits.OrbitsError as exc:
    ...     print(type(exc).__name__, exc.time, exc.step, len(exc.result.times))
    Escape 1.0 d 1 2
    """

    def __init__(self, message, time=None, step=None, result=None):
        self.time = time
        self.step = step
        self.result = result
        super().__init__(message)


class SimulationStopped(RunError):
    """A stopping condition ended the run.

    Attributes
    ----------
    bodies : tuple of str
        The bodies concerned (the pair for an encounter, the one for an escape).

    Examples
    --------
    >>> for stop in ({"encounter_distance": 2 * u.au}, {"escape_distance": 0.5 * u.au}):
    ...     sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day, **stop)
    ...     try:
    ...         sim.run(until=10 * u.day, outputs=2, progress=False)
    ...     except orbits.errors.SimulationStopped as exc:
    ...         print(type(exc).__name__, exc.bodies)
    CloseEncounter ('Star', 'Planet')
    Escape ('Planet',)
    """

    def __init__(self, message, time=None, step=None, result=None, bodies=()):
        self.bodies = tuple(bodies)
        super().__init__(message, time=time, step=step, result=result)


class NonFiniteState(RunError):
    """A position or velocity became NaN or infinite.

    Examples
    --------
    >>> bodies = orbits.BodySet()
    >>> bodies.add("A", mass=1 * u.Msun)
    >>> bodies.add("B", mass=1 * u.Msun, position=[1e-200, 0, 0] * u.au)   # r**3 underflows
    >>> sim = orbits.Simulation(bodies, "leapfrog", dt=1 * u.day)
    >>> sim.run(until=2 * u.day, outputs=2, progress=False)
    Traceback (most recent call last):
        ...
    orbits.errors.NonFiniteState: the state became non-finite in step 1 (from t = 0 d); ...
    """


class StepSizeUnderflow(RunError):
    """An adaptive integrator's step size collapsed below its minimum.

    Examples
    --------
    >>> ias15 = orbits.integrators.get("ias15", min_dt=1e4)   # days: above any step it takes
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), ias15)
    >>> sim.run(until=100 * u.day, outputs=2, progress=False)
    Traceback (most recent call last):
        ...
    orbits.errors.StepSizeUnderflow: the step size of 'ias15' collapsed at t = 0 d (step 0); ...
    """


class ConvergenceFailure(RunError):
    """An implicit integrator's Newton iteration did not converge in a step.

    The step was too large for the iteration (a close encounter, a force that
    changes too fast): a smaller step usually cures it.

    Examples
    --------
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "implicit-midpoint", dt=100 * u.day)
    >>> sim.run(until=1000 * u.day, outputs=2, progress=False)
    Traceback (most recent call last):
        ...
    orbits.errors.ConvergenceFailure: the Newton iteration of 'implicit-midpoint' did not ...
    >>> sim.time                                    # left at the last good state
    <Quantity 0. d>
    """


class WallTimeExceeded(RunError):
    """A run took longer than the wall-clock limit it was given (``wall_limit=``).

    The simulation is left at the last state reached, which ``result`` ends
    with, so the run can be continued with another :meth:`~orbits.Simulation.run`.

    Examples
    --------
    >>> sim.run(until=1000 * u.day, progress=False, wall_limit=1e-9)
    Traceback (most recent call last):
        ...
    orbits.errors.WallTimeExceeded: the run passed its wall-time limit of 1e-09 s at t = ...
    >>> bool(sim.time > 0 * u.day)                  # left at the last state reached
    True
    """


class CloseEncounter(SimulationStopped):
    """Two bodies came closer than the encounter distance.

    Examples
    --------
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day,
    ...                         encounter_distance=2 * u.au)
    >>> sim.run(until=10 * u.day, outputs=2, progress=False)
    Traceback (most recent call last):
        ...
    orbits.errors.CloseEncounter: close encounter of 'Star' and 'Planet' (closest at t = 1 d, ...
    """


class Collision(SimulationStopped):
    """Two bodies touched: their separation fell below the sum of their radii
    (``collisions="halt"``).

    Attributes
    ----------
    contact_time : astropy.units.Quantity
        When the pair was closest inside the step in which they touched (the
        end of that step if they already overlapped there).  ``time`` is the
        end of the step, where the run stopped and the state is kept; where
        the integrator could not carry the bodies through their contact
        (``trace``'s inner step collapsing on a head-on fall), it is the last
        state reached whole, before the contact, and ``contact_time`` the
        first touch of the pair's two-body orbits from there.
    distance, speed : astropy.units.Quantity
        Their separation and relative speed at ``contact_time``.

    Examples
    --------
    >>> b = orbits.BodySet()
    >>> b.add("Star", mass=1 * u.Msun, radius=0.005 * u.au)
    >>> b.add("Comet", mass=0 * u.kg, position=[1, 0, 0] * u.au,
    ...       velocity=[-0.001, 0, 0] * u.au / u.day, radius=1 * u.km)
    >>> sim = orbits.Simulation(b, "ias15", collisions="halt")
    >>> try:
    ...     sim.run(until=1 * u.yr, outputs=2, progress=False)
    ... except orbits.OrbitsError as exc:
    ...     print(type(exc).__name__, exc.bodies, exc.distance < 0.005 * u.au)
    Collision ('Star', 'Comet') True
    """

    def __init__(self, message, time=None, step=None, result=None, bodies=(),
                 contact_time=None, distance=None, speed=None):
        self.contact_time = contact_time
        self.distance = distance
        self.speed = speed
        super().__init__(message, time=time, step=step, result=result, bodies=bodies)


class SimulationOptionError(OrbitsError, ValueError):
    """An option of :class:`~orbits.Simulation` that cannot be taken as given
    (which option, the value and what is expected are in the message).

    Examples
    --------
    >>> orbits.Simulation(orbits.scenes.kepler(), "ias15", collisions="explode")
    Traceback (most recent call last):
        ...
    orbits.errors.SimulationOptionError: collisions='explode' is not a resolution; ...
    """


class Escape(SimulationStopped):
    """A body left the system.

    Examples
    --------
    >>> bodies = orbits.scenes.kepler()
    >>> bodies.add("comet", mass=0 * u.kg, a=-1 * u.au, e=1.5)      # on a hyperbola
    >>> sim = orbits.Simulation(bodies, "leapfrog", dt=1 * u.day, escape_distance=3 * u.au)
    >>> sim.run(until=1 * u.yr, outputs=2, progress=False)
    Traceback (most recent call last):
        ...
    orbits.errors.Escape: 'comet' escaped at t = 120 d (step 120); ...
    """


class RunInterrupted(KeyboardInterrupt):
    """A run stopped by SIGINT (Ctrl-C) or SIGTERM, between two compiled chunks.

    A subclass of :class:`KeyboardInterrupt`, so ``except KeyboardInterrupt``
    catches it.  The simulation is left at the last completed step, with its
    clock and state agreeing, so it can be continued with another
    :meth:`~orbits.Simulation.run`; a run writing a file has written a restart
    checkpoint there first, from which ``orbits resume`` finishes it.

    Attributes
    ----------
    signal : int
        The signal received (``signal.SIGINT`` or ``signal.SIGTERM``).
    time : astropy.units.Quantity
        Simulation time at which the run stopped.
    step : int
        Number of steps completed (since the simulation was made).
    result : orbits.Result or None
        Everything recorded up to there, ending with the state the run stopped at.

    Examples
    --------
    >>> import signal
    >>> from orbits.errors import RunInterrupted
    >>> try:   # what a run raises on Ctrl-C
    ...     raise RunInterrupted("interrupted", signal=signal.SIGINT, step=10)
    ... except KeyboardInterrupt as exc:
    ...     print(exc.signal == signal.SIGINT, exc.step)
    True 10
    """

    def __init__(self, message, signal=None, time=None, step=None, result=None):
        self.signal = signal
        self.time = time
        self.step = step
        self.result = result
        super().__init__(message)


class SystemFileError(BodyError):
    """A body-set file (:mod:`orbits.systemfile`, TOML or CSV) that cannot be read.

    The message starts with the file and the line, then the body and the
    field where there is one: ``system.toml, line 12: body 'Jupiter', field
    'a': ...``.

    Attributes
    ----------
    path : str
        The file, as given (``"<string>"`` for text).
    line : int or None
        Line of the file (1-based) where the problem is.
    body, field : str or None
        As for :class:`BodyError`.

    Examples
    --------
    >>> try:
    ...     orbits.systemfile.loads('[[body]]\\nname = "Sun"\\nmass = 1\\n')
    ... except orbits.OrbitsError as exc:
    ...     print(type(exc).__name__, exc.path, exc.line, exc.field)
    SystemFileError <string> 3 mass
    """

    def __init__(self, message, path=None, line=None, body=None, field=None):
        super().__init__(message, body=body, field=field)
        self.path = path
        self.line = line
        self.args = (_located(self.args[0], path, None if line is None else f"line {line}"),)
