"""The contract every integrator meets.

An integrator is a class with a registry name and a few facts about itself,
plus the compiled loop it runs.  Concretely, a subclass of :class:`Integrator`

1. sets ``name`` (the registry name, lowercase with hyphens), ``order`` (the
   global order of accuracy, measured by the test suite), ``symplectic``,
   ``time_symmetric``, ``adaptive`` and ``needs_central_body``;
2. declares its options in ``option_specs``, a tuple of :class:`Option`
   (name, type, default, help, unit, the values it takes), the one place
   they are listed: ``options`` (name -> default) and the command line's
   flags are made from it.  Unknown options and values that do not fit
   their declaration are rejected in ``__init__`` with
   :class:`~orbits.errors.IntegratorOptionError`, and ``_check_options``
   checks what a declaration cannot say.  The arguments of an ``Option``
   are literals or names of module constants, so that the command line
   reads them without importing the integrator
   (:mod:`orbits._integrator_options`);
3. implements ``workspace(n)``, returning the arrays a run keeps between
   calls (force cache, stage buffers, internal state) as a dict.  Everything
   a bit-exact restart needs lives there, as numpy arrays (a flag or a scalar
   as a one-element array): checkpoints save and restore exactly these
   arrays (:mod:`orbits.io.h5md`), and a test parametrized over the registry
   checks that a resumed run is bit-identical;
4. implements ``advance(ws, x, v, t, dt, nsteps, force, fargs, mon, step0,
   mon_t, mon_out, velocity_dependent, check_every, stop)``, which advances ``x`` and ``v`` (shape (N, 3), in place)
   by ``nsteps`` steps of ``dt`` from time ``t`` with the compiled loop for
   ``force`` and returns ``(status, steps_done, n_monitor_rows)`` as
   described in :mod:`orbits._kernels.stepping`; for a force with
   non-conservative terms it integrates their work into ``ws["work"]``
   (``fargs`` bound to it by :func:`~orbits._kernels.stepping.work_bound`),
   or refuses such terms in ``check_terms``;
5. implements ``synchronize(ws, x, v)`` (bring x and v to the same time
   where the method keeps them apart; a no-op for methods that never do) and
   ``invalidate(ws)`` (forget cached forces after the state was changed from
   outside); a method whose loop checks the stopping conditions elsewhere
   than at the ends of its steps says where in ``checked_state(ws, t)``, and
   one whose loop can stop with the state before the steps it counts (a
   step it cannot finish) says how far before in ``behind(ws)``;
6. is registered in :mod:`orbits.integrators` and documented with its update
   equations, its reference and an example.

Adaptive methods (:class:`AdaptiveIntegrator`, ``adaptive = True``) meet
the same contract with ``advance_to`` in place of ``advance``: they integrate
to an exact time with their own step control (see there).

Fixed-step methods are data over a shared loop: a splitting method is a table
of drift and kick coefficients (:class:`SplittingMethod`), an explicit
Runge-Kutta method a Butcher table (:class:`ExplicitRungeKutta`).
"""

import math
import warnings

import numpy as np

from .._compiling import TERMS
from .._integrator_options import Option
from .._kernels import gravity
from .._kernels import records
from .._kernels.records import NO_MARK_STEPS, NO_MARKS, checks, outputs
from .._kernels import stepping
from .._kernels.invariants import MONITOR_WIDTH
from .._kernels.status import with_status
from .._kernels.stopping import stop_record
from ..errors import IntegratorOptionError, OrbitsWarning
from ._loops import loop_for

__all__ = ["Integrator", "SplittingMethod", "ExplicitRungeKutta", "AdaptiveIntegrator",
           "ToleranceControlled", "CompiledToleranceControlled", "Option", "MIN_DT", "RTOL_FLOOR", "NO_MARKS",
           "NO_MARK_STEPS", "around_a_circle"]


#: The smallest relative tolerance an adaptive method is run with: 100 float64
#: roundings (the floor scipy's ``solve_ivp`` also applies).
RTOL_FLOOR = 100 * float(np.finfo(float).eps)

#: The smallest step an adaptive method may take, an option of those that
#: honour one.
MIN_DT = Option("min_dt", float, 0.0, "smallest allowed step; a run whose step control "
                "asks for less stops with StepSizeUnderflow (0: none)", unit="time",
                sign="non-negative")


def around_a_circle(integ, steps=1000):
    """Advance a test particle once around a circle of radius 1 about a unit mass
    (G = M = 1, period 2 pi) from (1, 0, 0), in ``steps`` steps of a fixed-step
    integrator's compiled loop: the first check of an integrator, which ends
    near where it started.

    Parameters
    ----------
    integ : Integrator
        A fixed-step integrator (the contract's :meth:`Integrator.advance`).
    steps : int
        Steps of ``2 pi / steps``.

    Returns
    -------
    tuple
        ``(status, steps_done, x, v, ws)``: the state (shape (2, 3), the
        unit mass first) and the workspace after the steps, before any
        :meth:`Integrator.synchronize`.

    Examples
    --------
    >>> from orbits import integrators
    >>> from orbits.integrators.base import around_a_circle
    >>> status, steps, x, v, ws = around_a_circle(integrators.get("leapfrog"), 100)
    >>> status.name, steps, bool(abs(x[1, 0] - 1) < 1e-3)
    ('OK', 100, True)
    """
    x = np.array([[0.0, 0, 0], [1, 0, 0]])
    v = np.array([[0.0, 0, 0], [0, 1, 0]])
    force = stepping.gravity_force("small")
    fargs = gravity.gravity_args(1.0, np.array([1.0, 0.0]), 1, 0.0)  # G, m, N_active, eps2
    mon = (0, 0, np.zeros(2), 1.0, 1, 0.0)                            # no monitor rows
    ws = integ.workspace(2)
    integ.bind(ws, force, fargs)
    status, done, _ = integ.advance(ws, x, v, 0.0, 2 * math.pi / steps, steps, force, fargs,
                                    mon, 0, np.empty(0), np.zeros((0, MONITOR_WIDTH)))
    return status, done, x, v, ws


class Integrator:
    """Base class; see the module docstring for the contract.

    Examples
    --------
    >>> import math
    >>> from orbits import integrators
    >>> from orbits._kernels import gravity, stepping
    >>> x = np.array([[0.0, 0, 0], [1, 0, 0]])    # a test particle on a circle of
    >>> v = np.array([[0.0, 0, 0], [0, 1, 0]])    # radius 1 (G = M = 1, period 2 pi)
    >>> force = stepping.gravity_force("small")
    >>> fargs = gravity.gravity_args(1.0, np.array([1.0, 0.0]), 1, 0.0)  # G, m, N_act, eps2
    >>> mon = (0, 0, np.zeros(2), 1.0, 1, 0.0)    # no monitor rows
    >>> integ = integrators.get("leapfrog")
    >>> ws = integ.workspace(2)
    >>> integ.bind(ws, force, fargs)
    >>> status, steps, rows = integ.advance(ws, x, v, 0.0, 2 * math.pi / 1000, 1000, force,
    ...                                      fargs, mon, 0, np.empty(0), np.zeros((0, 11)))
    >>> integ.synchronize(ws, x, v)
    >>> status.name, steps, np.round(x[1], 3)        # one period: back at the start
    ('OK', 1000, array([ 1., -0.,  0.]))
    >>> integ.info()["order"], integ.symplectic
    (2, True)
    """

    name = None
    order = None
    symplectic = False
    time_symmetric = False
    adaptive = False
    needs_central_body = False
    #: the options, each declared once (see the contract, point 2)
    option_specs = ()
    #: option name -> default value, made from ``option_specs``
    options = {}
    #: one line for listings
    summary = ""
    #: force evaluations per step (for the counts in results)
    forces_per_step = 1
    #: whether its steps run in a loop that numba compiles (``orbits compile``
    #: fills the cache with it ahead of time); False for methods run in Python
    compiled = True
    #: whether ``advance`` checks the stopping conditions (``stop=``) inside its
    #: loop: True for all of them, or a tuple of the :class:`~orbits.Simulation`
    #: keywords of those it checks
    stop_conditions = False
    #: whether its loop, with stopping conditions, takes the look-ahead of a
    #: step that may not finish (:func:`orbits._kernels.stopping.ahead_pointer`),
    #: which the run compiles before the loop, as it does the check
    looks_ahead = False
    #: whether its loop updates the chaos indicators after every step (the
    #: shared step epilogue, :mod:`orbits._kernels.variational`)
    chaos_indicators = True
    #: whether its runs without force terms take its loop with terms, an empty
    #: table of them (:func:`orbits._kernels.terms.table`): one loop for runs
    #: with and without terms, so that adding a term compiles nothing new
    terms_as_data = False
    #: with ``terms_as_data``, whether that empty table is bound into the
    #: force the loop calls (gravity then always carries a table), or the
    #: integrator hands it to its loop itself (Wisdom-Holman's kick of the
    #: terms is its own, so its force is gravity alone without terms)
    table_in_force = True
    #: whether its loop reads the force's Jacobian (the force terms' table
    #: then carries theirs, :func:`orbits._kernels.terms.with_jacobian`)
    reads_jacobians = False
    #: whether ``advance`` records at the steps ``mon_t`` holds on entry when
    #: ``mon[0]`` is -1 (:func:`orbits._kernels.stepping.first_record`), so that
    #: outputs that do not fall a whole number of steps apart are recorded in
    #: its loop; the compiled fixed-step methods do
    records_step_marks = False

    @property
    def batchable(self):
        """Whether several systems integrated by this method with these options
        can share one compiled loop, each in a vector lane
        (``Ensemble.run(..., batch=B)``); False unless a method says otherwise."""
        return False

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if "option_specs" in vars(cls):
            cls.options = {spec.name: spec.default for spec in cls.option_specs}

    def __init__(self, **options):
        unknown = sorted(set(options) - set(self.options))
        if unknown:
            valid = ", ".join(sorted(self.options)) or "none"
            raise IntegratorOptionError(
                f"integrator {self.name!r} has no option {', '.join(map(repr, unknown))}; "
                f"valid options: {valid}")
        self.config = {**self.options, **options}
        for spec in self.option_specs:
            try:
                self.config[spec.name] = spec.checked(self.config[spec.name])
            except ValueError as exc:
                raise IntegratorOptionError(f"integrator {self.name!r}: {exc}") from None
        self._check_options()

    def _check_options(self):
        """Subclasses check here what their options' declarations cannot say
        (a value that one method of a family refuses, a pair of options)."""

    def parts_ahead(self, force, x, fargs):
        """What a run of ``force`` (with its arguments ``fargs``, on a state
        like ``x``) compiles besides the loop, as ``(label, make)`` pairs:
        the run calls each ``make()`` before the loop, so that a first
        compile is announced as the part's (the notice's label, a value of
        :data:`orbits._compiling.TERMS`) and not as the loop's.  None here."""
        return ()

    # contract, parts 3-5
    def workspace(self, n):
        """The arrays a run keeps between calls, for ``n`` bodies (contract, part 3).

        Parameters
        ----------
        n : int
            Number of bodies.

        Returns
        -------
        dict of str to numpy.ndarray
            The arrays a run keeps between calls (point 3 of the contract).

        Examples
        --------
        >>> from orbits import integrators
        >>> ws = integrators.get("rk4").workspace(5)
        >>> sorted(ws), ws["kx"].shape
        (['kv', 'kx', 'vs', 'xs'], (4, 5, 3))
        """
        raise NotImplementedError

    def advance(self, ws, x, v, t, dt, nsteps, force, fargs, mon, step0, mon_t, mon_out,
                velocity_dependent=False, check_every=1, stop=None):
        """Advance ``x``, ``v`` by ``nsteps`` steps of ``dt`` (contract, part 4).

        Parameters
        ----------
        ws : dict
            The workspace (:meth:`workspace`), updated in place.
        x, v : numpy.ndarray, shape (N, 3)
            Positions and velocities in the internal units, advanced in place.
        t, dt : float
            Time at the start and step size, in the internal unit of time.
        nsteps : int
            Steps to take.
        force, fargs
            The compiled force and its arguments.
        mon, step0, mon_t, mon_out
            Monitor settings, the step count at the start, and the arrays the
            monitor rows are written into.

        Returns
        -------
        tuple
            ``(status, steps_done, n_monitor_rows)``.

        Examples
        --------
        One period of a circular orbit in 1000 steps of ``rk4``, as
        :func:`around_a_circle` takes them (the class's example makes the call
        itself):

        >>> from orbits import integrators
        >>> from orbits.integrators.base import around_a_circle
        >>> status, steps, x, v, ws = around_a_circle(integrators.get("rk4"))
        >>> status.name, steps, np.round(x[1], 6)
        ('OK', 1000, array([1., 0., 0.]))
        """
        raise NotImplementedError

    def bind(self, ws, force, fargs):
        """Called once a workspace meets its force (also after a restore); for
        methods that keep something of the force beside their arrays.

        Examples
        --------
        >>> from orbits import integrators
        >>> from orbits._kernels import gravity, stepping
        >>> integ = integrators.get("wh")
        >>> ws = integ.workspace(2)
        >>> integ.bind(ws, stepping.gravity_force("small"),      # gravity alone: nothing
        ...            gravity.gravity_args(1.0, np.ones(2), 2, 0.0))  # kept beside the arrays
        >>> "terms" in ws
        False
        """

    def check_terms(self, terms):
        """Refuse, with :class:`~orbits.errors.IntegratorOptionError`, a force term
        (of :mod:`orbits.forces`) this method cannot honour; every term by default.

        Examples
        --------
        >>> gr = orbits.forces.GR("Sun")
        >>> orbits.integrators.get("ias15").check_terms([gr])      # accepted
        >>> try:
        ...     orbits.integrators.get("wh").check_terms([gr])
        ... except orbits.IntegratorOptionError as exc:
        ...     print(type(exc).__name__)
        IntegratorOptionError
        """

    def synchronize(self, ws, x, v):
        """Fixed-step methods here always end a step with x and v at one time.

        Examples
        --------
        >>> from orbits import integrators
        >>> from orbits.integrators.base import around_a_circle
        >>> integ = integrators.get("leapfrog")
        >>> status, steps, x, v, ws = around_a_circle(integ)
        >>> before = x.copy()
        >>> integ.synchronize(ws, x, v)                # x and v are at one time already
        >>> bool((x == before).all())
        True
        """

    def invalidate(self, ws):
        """Forget anything computed from the old state (nothing here; a method
        that caches a force drops it, as :meth:`SplittingMethod.invalidate`)."""

    def checked_state(self, ws, t):
        """The state the stopping conditions last looked at, if the loop that
        ended at ``t`` checked them elsewhere than at ``t``: ``(x, v, time)``;
        None (the default) when they were checked at the end of its last step,
        on the state that :meth:`synchronize` gives."""
        return None

    def behind(self, ws):
        """How far before the end of the steps a loop call counted the state
        lies (the synchronised ``x``, ``v``), after a call that stopped early:
        0.0 (the default) where a loop stops only at the end of a step.

        Examples
        --------
        >>> integ = orbits.integrators.get("leapfrog")
        >>> integ.behind(integ.workspace(2))
        0.0
        """
        return 0.0

    def info(self):
        """The integrator and its options, for results and files.

        Returns
        -------
        dict
            ``name``, ``order``, ``symplectic``, ``adaptive``, and each option as
            ``option.<name>``.

        Examples
        --------
        >>> orbits.integrators.get("ias15", epsilon=1e-10).info()["option.epsilon"]
        1e-10
        """
        return {"name": self.name, "order": self.order, "symplectic": self.symplectic,
                "adaptive": self.adaptive, **{f"option.{k}": v for k, v in self.config.items()}}

    def __repr__(self):
        opts = ", ".join(f"{k}={v!r}" for k, v in self.config.items())
        return f"{type(self).__name__}({opts})"


class SplittingMethod(Integrator):
    """A symplectic splitting method given by its table of operators.

    Subclasses set ``operators``: a sequence of ``("drift", c)`` and
    ``("kick", c)``, applied left to right, where a drift advances positions by
    ``c dt v`` and a kick velocities by ``c dt a(x)``.  Drift and kick
    coefficients must each sum to one.  A table that reads the same backwards
    makes a time-symmetric method (``time_symmetric`` is set from it).

    Examples
    --------
    >>> from orbits import integrators
    >>> leapfrog = integrators.get("leapfrog")
    >>> leapfrog.operators
    (('drift', 0.5), ('kick', 1.0), ('drift', 0.5))
    >>> sum(c for kind, c in integrators.get("yoshida4").operators if kind == "kick")
    1.0
    """

    #: outputs that do not fall a whole number of steps apart are recorded in the
    #: loop too (``every = -1``: the steps in ``mon_t``)
    records_step_marks = True

    operators = ()
    symplectic = True
    stop_conditions = True
    terms_as_data = True

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.operators:
            codes = {"drift": stepping.DRIFT, "kick": stepping.KICK}
            cls._kinds = np.array([codes[k] for k, _ in cls.operators], dtype=np.int64)
            cls._coefs = np.array([float(c) for _, c in cls.operators])
            cls._table = stepping.Splitting(cls._kinds, cls._coefs)
            kinds = [k for k, _ in cls.operators]
            cls.time_symmetric = tuple(cls.operators) == tuple(cls.operators)[::-1]
            # a closing kick shares its force with the next step's opening kick
            cls.forces_per_step = kinds.count("kick") - (kinds[0] == kinds[-1] == "kick")

    def workspace(self, n):
        # vm: the implicit kick's midpoint velocities (velocity-dependent forces)
        """``acc`` (the cached force), ``vm`` and the cache flag, for ``n`` bodies.

        Examples
        --------
        >>> from orbits import integrators
        >>> sorted(integrators.get("leapfrog").workspace(3))
        ['acc', 'cache', 'vm']
        """
        return {"acc": np.zeros((n, 3)), "vm": np.zeros((n, 3)),
                "cache": np.zeros(1, dtype=np.int64)}

    def parts_ahead(self, force, x, fargs):
        """The implicit kick of a force that reads velocities
        (:func:`~orbits._kernels.stepping.implicit_kick`), compiled once for
        every splitting method and only for runs with such a force."""
        if not (force.jit and force.velocity_dependent) or stepping.kick_made(force):
            return ()
        fargs = stepping.work_bound(force, fargs, {})
        return ((TERMS["kick"], lambda: stepping.implicit_kick(force, x, fargs, True)),)

    def advance(self, ws, x, v, t, dt, nsteps, force, fargs, mon, step0, mon_t, mon_out,
                velocity_dependent=False, check_every=1, stop=None):
        """Apply the operator table ``nsteps`` times in the compiled loop (see
        :meth:`Integrator.advance`)."""
        sargs, check = stop_record(stop)
        fargs = stepping.work_bound(force, fargs, ws)
        velocity_dependent = bool(velocity_dependent or force.velocity_dependent)
        # the kick's pointer, kept in the workspace (not an array: neither
        # saved nor restored) for the force it was made for: its type is
        # that of the force's arguments, which numba types in Python in some
        # hundred microseconds, more than a short call's whole run
        kick = ws.get("kick")
        if kick is None or kick[0] != (force.key, velocity_dependent):
            kick = ws["kick"] = ((force.key, velocity_dependent),
                                 stepping.implicit_kick(force, x, fargs, velocity_dependent))
        return with_status(*loop_for(stepping.splitting_loop, force)(
            x, v, t, dt, nsteps, self._table,
            stepping.SplittingWork(ws["acc"], ws["vm"], ws["cache"]), fargs, velocity_dependent,
            kick[1], outputs(mon, step0, mon_t, mon_out), checks(check_every, sargs), check))

    def invalidate(self, ws):
        """Drop the cached force: the next kick evaluates it again.

        Examples
        --------
        >>> from orbits import integrators
        >>> from orbits.integrators.base import around_a_circle
        >>> integ = integrators.get("verlet")
        >>> *_, ws = around_a_circle(integ)
        >>> int(ws["cache"][0])                        # the last force is cached
        1
        >>> integ.invalidate(ws)
        >>> int(ws["cache"][0])
        0
        """
        ws["cache"][0] = 0


class ExplicitRungeKutta(Integrator):
    """An explicit Runge-Kutta method given by its Butcher table ``A``, ``B``, ``C``.

    Applied to ``y = (x, v)`` with ``y' = (v, a(x, v, t))``.

    Examples
    --------
    >>> from orbits import integrators
    >>> rk4 = integrators.get("rk4")
    >>> round(float(np.sum(rk4.B)), 12), np.allclose(np.sum(rk4.A, axis=1), rk4.C)
    (1.0, True)
    """

    #: outputs that do not fall a whole number of steps apart are recorded in the
    #: loop too (``every = -1``: the steps in ``mon_t``)
    records_step_marks = True

    A = None
    B = None
    C = None
    stop_conditions = True
    terms_as_data = True

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.B is not None:
            cls.forces_per_step = len(cls.B)
            cls._tableau = stepping.Tableau(cls.A, cls.B, cls.C)

    def workspace(self, n):
        """Stage buffers: ``kx``, ``kv`` of shape (stages, n, 3), and the stage
        state ``xs``, ``vs``.

        Examples
        --------
        >>> from orbits import integrators
        >>> ws = integrators.get("rk2").workspace(3)
        >>> ws["kx"].shape, ws["xs"].shape
        ((2, 3, 3), (3, 3))
        """
        s = len(self.B)
        return {"kx": np.zeros((s, n, 3)), "kv": np.zeros((s, n, 3)),
                "xs": np.zeros((n, 3)), "vs": np.zeros((n, 3))}

    def advance(self, ws, x, v, t, dt, nsteps, force, fargs, mon, step0, mon_t, mon_out,
                velocity_dependent=False, check_every=1, stop=None):
        """Take ``nsteps`` steps of the Butcher table in the compiled loop (see
        :meth:`Integrator.advance`)."""
        loop = loop_for(stepping.runge_kutta_loop, force)
        fargs = stepping.work_bound(force, fargs, ws)
        sargs, check = stop_record(stop)
        work = stepping.RungeKuttaWork(ws["kx"], ws["kv"], ws["xs"], ws["vs"])
        return with_status(*loop(x, v, t, dt, nsteps, self._tableau, work, fargs,
                                 outputs(mon, step0, mon_t, mon_out),
                                 checks(check_every, sargs), check))


class AdaptiveIntegrator(Integrator):
    """Base of the adaptive integrators: they choose their own steps.

    Contract (in addition to points 1-3, 5 and 6 of the module docstring):

    * ``advance_to(ws, x, v, t, t_end, force, fargs, mon, step0, mon_t, mon_out,
      stop, max_steps)`` integrates ``x``, ``v`` (in place) from ``t`` to
      exactly ``t_end``, or returns early after ``max_steps`` accepted steps
      (so that Python can show progress), and returns ``(status, t_reached,
      steps_accepted, steps_rejected, force_evaluations, n_monitor_rows)``.
      ``t_end`` is hit by shortening the last step; the step size the method
      proposed is kept in ``ws`` and used again afterwards, so outputs do not
      disturb the step sequence.
    * On a non-OK status (``Status.NON_FINITE``, ``Status.STEP_UNDERFLOW``, or a
      stopping condition) ``x`` and ``v`` hold the last good state and
      ``t_reached`` its time; ``ws["info"]`` (int64, shape (2,)) names the
      bodies concerned (internal indices, -1 for none).
    * ``ws["dt"]`` (shape (1,)) holds the next step size; ``initial_step`` is
      the ``dt`` the user gave (or 0 to let the method choose).
    * Everything a bit-exact restart needs lives in ``ws`` as arrays, as for
      every integrator.
    * Options are declared and checked as every integrator's (point 2);
      :class:`ToleranceControlled` declares ``rtol`` and ``atol``, and
      :data:`MIN_DT` is the ``min_dt`` option of those that take one.
    """

    adaptive = True
    stop_conditions = True

    def advance_to(self, ws, x, v, t, t_end, force, fargs, mon, step0, mon_t, mon_out,
                   stop, max_steps):
        raise NotImplementedError

    def workspace(self, n, initial_step=0.0):
        raise NotImplementedError

    def _counted_call(self, loop, lead, ws, mon, step0, mon_t, mon_out, t_end, max_steps,
                      marks, mark_steps, stop):
        """:meth:`advance_to`'s return from a compiled loop that counts its steps in
        ``ws["counts"]`` (accepted, rejected, force evaluations): the loop is called
        with its own arguments ``lead``, then the outputs, the landing (with the
        option ``min_dt``) and the stopping conditions' record."""
        sargs, check = stop_record(stop)
        status, t_reached, n_mon = loop(
            *lead, outputs(mon, step0, mon_t, mon_out),
            records.landing(t_end, max_steps, self.config["min_dt"], marks, mark_steps),
            sargs, check)
        c = ws["counts"]
        return with_status(status, t_reached, int(c[0]), int(c[1]), int(c[2]), n_mon)


class ToleranceControlled(AdaptiveIntegrator):
    """An adaptive method whose step keeps an estimate of the local error
    within ``atol + rtol |y|``: the options ``rtol`` and ``atol``.

    A relative tolerance below :data:`RTOL_FLOOR` is raised to it with a
    warning: a relative error below a few float64 roundings cannot be
    delivered (the error estimate of a step then reads zero only where the
    stages round to the same numbers, and the method creeps on with steps far
    too short to matter: 23 million steps to t = 5e-5 d at rtol = 1e-30).

    Examples
    --------
    >>> orbits.integrators.get("dopri5", rtol=1e-10).config
    {'rtol': 1e-10, 'atol': 1e-12}
    """

    option_specs = (
        Option("rtol", float, 1e-9, "relative tolerance of a step's error estimate",
               sign="positive"),
        Option("atol", float, 1e-12, "absolute tolerance of a step's error estimate, in "
               "the simulation's units of length and velocity", sign="positive"),
    )

    def _check_options(self):
        if self.config["rtol"] < RTOL_FLOOR:
            warnings.warn(f"integrator {self.name!r}: rtol = {self.config['rtol']:g} is below "
                          f"what float64 arithmetic can deliver; using {RTOL_FLOOR:.3g} "
                          f"(100 roundings)", OrbitsWarning, stacklevel=4)
            self.config["rtol"] = RTOL_FLOOR


class CompiledToleranceControlled(ToleranceControlled):
    """A tolerance-controlled method whose compiled loop keeps the force at a
    step's end for the next step (the flag ``ws["fsal"]``) and records the
    outputs at their times (``advance_to``'s ``marks``): the embedded pairs
    and ``rk4-doubling``.  A subclass gives its loop and the arguments that
    are its own in :meth:`_loop_call`.
    """

    #: outputs can be recorded inside the loop (``advance_to``'s ``marks``)
    records_marks = True
    terms_as_data = True

    def _loop_call(self, ws, force):
        """``(loop, lead, work)``: the compiled loop for ``force``, its
        arguments between the time and the tolerances (the method's tables),
        and its workspace record."""
        raise NotImplementedError

    def invalidate(self, ws):
        """The state was changed from outside: the force kept from the last step
        is stale."""
        ws["fsal"][0] = 0

    def advance_to(self, ws, x, v, t, t_end, force, fargs, mon, step0, mon_t, mon_out, stop,
                   max_steps, marks=NO_MARKS, mark_steps=NO_MARK_STEPS):
        """Advance to ``t_end``; with ``marks`` (times, the last ``t_end``), land
        on each and record there a row of ``mon_out`` (monitors and state),
        its time in ``mon_t`` and its step count in ``mark_steps``."""
        loop, lead, work = self._loop_call(ws, force)
        fargs = stepping.work_bound(force, fargs, ws)
        tolerances = records.Tolerances(float(self.config["rtol"]), float(self.config["atol"]))
        sargs, check = stop_record(stop)
        return with_status(*loop(x, v, float(t), *lead, tolerances, work, fargs,
                                 outputs(mon, step0, mon_t, mon_out),
                                 records.landing(t_end, max_steps, 0.0, marks, mark_steps),
                                 sargs, check))
