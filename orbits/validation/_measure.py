"""One measured run: an integrator of ours or of REBOUND on one problem.

Both sides are measured the same way, so that a table can put them in one
column: the state at the end (plain floats in the body set's units), the
largest relative energy and angular-momentum errors at the outputs (computed
with the same formulas, :mod:`orbits.monitors`), steps, force evaluations and
wall time.  Compilation is kept out of the wall time by a short run of the
same configuration first.

A failure is never lost and never raised: it becomes the row's ``outcome``
(the exception's class name, e.g. ``"NonFiniteState"``) with its message, and
the errors are measured up to the last good state that the exception keeps.
"""

import math
import time
import warnings

import numpy as np

from .. import integrators as _integrators
from .._kernels import anomalies as _anomalies
from .._kernels import elements as _elements
from ..errors import OrbitsError, RunError
from ..monitors import vector_relative_error
from ..simulation import Simulation
from . import cases

__all__ = ["run_orbits", "run_rebound", "row_template", "on_steps", "REBOUND_INTEGRATORS",
           "WALL_LIMIT", "energy_and_momentum", "position_error", "exact_two_body",
           "rebound_with_extras", "REBOUNDX_MISSING"]

#: Seconds a single measured run may take before it is stopped with
#: ``WallTimeExceeded`` (recorded as its outcome): a sweep cell whose step
#: collapses without underflowing must not hold up the report for hours.
WALL_LIMIT = 120.0

#: REBOUND's integrators that the report runs beside ours.
REBOUND_INTEGRATORS = ("ias15", "whfast", "leapfrog")


def row_template(label, **fields):
    """A result row with every field present (NaN or empty where unmeasured)."""
    row = {"label": label, "outcome": "completed", "message": "", "warning": "",
           "t_end": math.nan, "x": None, "times": None, "energy_error": None,
           "angular_momentum_error": None, "energy_error_max": math.nan,
           "angular_momentum_error_max": math.nan, "steps": 0, "force_evaluations": 0,
           "steps_rejected": 0, "wall_time": math.nan}
    row.update(fields)
    return row


def _quantity(bodies, value, kind):
    return None if value is None else bodies.units.quantity(float(value), kind)


def run_orbits(bodies, integrator, options=None, *, dt=None, until, outputs=2, times=None,
               wall_limit=WALL_LIMIT, warm=True, label=None, simulation_options=None):
    """Run one of our integrators and measure it.

    Parameters
    ----------
    bodies : BodySet
    integrator : str
        Registry name.
    options : dict, optional
        The integrator's options (``epsilon``, ``rtol``, ``corrector``, ...).
    dt : float, optional
        Step (fixed-step methods) in the body set's time unit.
    until : float
        End time in the body set's time unit.
    outputs : int
        Evenly spaced outputs, the start and the end included.  Ignored when
        ``times`` is given.
    times : array_like, optional
        Increasing output times (after 0): the run is made of one
        :meth:`Simulation.run` per time, so any spacing (logarithmic, for drift
        laws) is possible.  Fixed-step methods shorten no step but the last.
    wall_limit : float
        Seconds before the run is stopped (outcome ``"WallTimeExceeded"``).
    warm : bool
        Compile first with a short run of the same configuration.
    simulation_options : dict, optional
        More keyword arguments of :class:`Simulation` (``monitors``, ...).

    Returns
    -------
    dict
        See :func:`row_template`; ``x`` is the final position array (N, 3),
        ``times``, ``energy_error`` and ``angular_momentum_error`` the series
        at the outputs.
    """
    options = dict(options or {})
    sim_opts = dict(simulation_options or {})
    label = label or integrator
    times = None if times is None else on_steps(times, dt)
    until = float(on_steps([until], dt)[-1])       # whole steps, as REBOUND's run
    row = row_template(label, integrator=integrator, options=options, dt=dt)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            integ = _integrators.get(integrator, **options)
            make = lambda: Simulation(bodies, integrator=integ,  # noqa: E731
                                      dt=_quantity(bodies, dt, "time"), **sim_opts)
            sim = make()
        except OrbitsError as exc:
            row.update(outcome=type(exc).__name__, message=str(exc))
            return row
        if warm:
            _warm_up(make, dt, until)
        segments = ([until] if times is None else [float(t) for t in times])
        pieces = []
        t_start = time.perf_counter()
        try:
            for k, t_out in enumerate(segments):
                left = wall_limit - (time.perf_counter() - t_start)
                n_out = outputs if times is None else (2 if k == 0 else 1)
                r = sim.run(until=_quantity(bodies, t_out, "time"), outputs=n_out,
                            progress=False, wall_limit=max(left, 1e-3))
                pieces.append(r)
        except RunError as exc:
            row.update(outcome=type(exc).__name__, message=str(exc))
            if exc.result is not None:
                pieces.append(exc.result)
        wall = time.perf_counter() - t_start
        row["warning"] = "; ".join(sorted({f"{w.category.__name__}: {w.message}"
                                           for w in caught
                                           if not issubclass(w.category, DeprecationWarning)}))
    row["wall_time"] = wall
    row["steps"] = sim.steps
    row["force_evaluations"] = sim.force_evaluations
    row["steps_rejected"] = sim.steps_rejected
    row["t_end"] = float(sim.time_value)
    row["x"] = np.array(sim.bodies.positions.value)
    if pieces:
        t = np.concatenate([p.times.to_value(bodies.units.time) for p in pieces])
        e = _joined(pieces, "energy_error")
        lerr = _joined(pieces, "angular_momentum_error")
        row.update(times=t, energy_error=e, angular_momentum_error=lerr,
                   energy_error_max=_nanmax(e), angular_momentum_error_max=_nanmax(lerr))
    return row


def on_steps(times, dt):
    """Output times moved to whole multiples of ``dt`` (duplicates dropped), so
    that a fixed-step method reaches each with whole steps; unchanged if
    ``dt`` is None (adaptive methods hit any time)."""
    times = np.asarray(times, dtype=float)
    if dt is None:
        return times
    k = np.unique(np.maximum(np.round(times / dt), 1).astype(np.int64))
    return k * float(dt)


def _joined(pieces, field):
    parts = [getattr(p, field) for p in pieces]
    if any(p is None for p in parts):
        return None
    return np.concatenate(parts)


def _nanmax(a):
    if a is None or len(a) == 0:
        return math.nan
    a = np.asarray(a, dtype=float)
    if not np.all(np.isfinite(a)):
        return math.inf
    return float(a.max())


def _warm_up(make, dt, until):
    """Compile the configuration: a few steps of a fresh copy (errors ignored)."""
    try:
        sim = make()
        short = until * 1e-6 if dt is None else min(until, 4 * dt)
        sim.run(until=sim.units.quantity(short, "time"), outputs=2, progress=False,
                wall_limit=WALL_LIMIT)
    except (RunError, ValueError):
        pass


def energy_and_momentum(sim):
    """Energy and angular-momentum vector of a REBOUND simulation."""
    return sim.energy(), np.array(sim.angular_momentum())


#: a REBOUNDx run's outcome message where REBOUNDx is not installed
REBOUNDX_MISSING = "reboundx is not installed (pip install reboundx)"


def rebound_with_extras(bodies, load=None):
    """REBOUND's IAS15 on ``bodies`` with direct-summation gravity, and REBOUNDx's
    ``Extras`` on it that ``load(sim, extras)`` fills, where ``load`` is given.

    Returns ``(sim, extras)`` (``extras`` None without ``load``; the caller keeps
    it while ``sim`` integrates); ImportError where REBOUNDx is needed and missing.
    """
    sim = bodies.to_rebound()
    sim.gravity = "basic"
    sim.integrator = "ias15"
    if load is None:
        return sim, None
    import reboundx
    extras = reboundx.Extras(sim)
    load(sim, extras)
    return sim, extras


def run_rebound(bodies, integrator, options=None, *, dt=None, until, outputs=2, times=None,
                wall_limit=WALL_LIMIT, label=None, count_evaluations=False):
    """Run one of REBOUND's integrators on the same floats and G, and measure it.

    ``integrator`` is ``"ias15"``, ``"whfast"`` or ``"leapfrog"``; ``options``
    are set on ``sim.integrator`` (REBOUND 4 and 5 both take them there:
    ``epsilon``, ``corrector``, ``safe_mode``, ...).  Gravity is REBOUND's
    ``"basic"`` pairwise sum, as ours.  Outputs end exactly on their times
    (``exact_finish_time=1``), as ours do.  The energy error is
    ``|E - E0| / |E0|`` and the angular-momentum error uses the same scale as
    :class:`Simulation` (:func:`orbits.monitors.vector_relative_error`).
    ``count_evaluations`` counts IAS15's force evaluations in a second run.
    """

    options = dict(options or {})
    label = label or f"REBOUND {integrator}"
    until = float(on_steps([until], dt)[-1])
    if integrator == "whfast":
        # synchronise (and apply a corrector) only when an output needs it, as
        # our wh does; REBOUND's default safe mode does it after every step
        options.setdefault("safe_mode", 0)
    row = row_template(label, integrator=f"rebound-{integrator}", options=options, dt=dt)
    sim = bodies.to_rebound()
    sim.gravity = "basic"
    sim.integrator = integrator
    _set_options(sim, integrator, options)
    if dt is not None:
        sim.dt = float(dt)
    m = bodies._m
    x0, v0 = bodies._x, bodies._v
    l_scale = float(np.sum(m * np.linalg.norm(x0, axis=1) * np.linalg.norm(v0, axis=1))) or 1.0
    e0, l0 = energy_and_momentum(sim)
    out_t = (np.linspace(0.0, until, max(outputs, 2))[1:] if times is None
             else np.asarray(times, dtype=float))
    if dt is not None:
        # whole steps only, as our fixed-step runs take them: integrating to
        # half a step short of k dt (exact_finish_time=0) takes exactly k steps
        # whatever the rounding of REBOUND's accumulated time
        out_t = on_steps(out_t, dt)
    ts, es, ls = [0.0], [e0], [l0]
    steps0 = 0
    t_start = time.perf_counter()
    try:
        for t_out in out_t:
            if dt is None:
                sim.integrate(float(t_out), exact_finish_time=1)
            else:
                sim.integrate(float(t_out) - 0.5 * dt, exact_finish_time=0)
            e, lvec = energy_and_momentum(sim)
            ts.append(sim.t)
            es.append(e)
            ls.append(lvec)
            x = np.array([p.xyz for p in sim.particles])
            if not (np.all(np.isfinite(x)) and math.isfinite(e)):
                row.update(outcome="NonFiniteState", message=f"REBOUND state non-finite "
                           f"by t = {sim.t:.10g}")
                break
            if time.perf_counter() - t_start > wall_limit:
                row.update(outcome="WallTimeExceeded",
                           message=f"passed {wall_limit:g} s at t = {sim.t:.10g}")
                break
    except Exception as exc:  # REBOUND raises its own kinds (Encounter, ...)
        row.update(outcome=type(exc).__name__, message=str(exc))
    wall = time.perf_counter() - t_start
    es = np.array(es)
    row.update(wall_time=wall, steps=int(sim.steps_done) - steps0, t_end=float(sim.t),
               x=np.array([p.xyz for p in sim.particles]), times=np.array(ts))
    row["energy_error"] = np.abs(es - e0) / abs(e0) if e0 != 0 else np.abs(es - e0)
    row["angular_momentum_error"] = vector_relative_error(np.array(ls), l0, l_scale)
    row["energy_error_max"] = _nanmax(row["energy_error"])
    row["angular_momentum_error_max"] = _nanmax(row["angular_momentum_error"])
    if integrator == "ias15":
        row["force_evaluations"] = (_count_evaluations(bodies, options, row["times"][-1])
                                    if count_evaluations else math.nan)
    else:
        row["force_evaluations"] = row["steps"]     # one kick a step
    return row


def _set_options(sim, integrator, options):
    # REBOUND 5 keeps an integrator's options on sim.integrator, REBOUND 4 on
    # sim.ri_<name>
    owner = getattr(sim, f"ri_{integrator}", None)
    if owner is None or not hasattr(owner, "_fields_"):
        owner = sim.integrator
    for key, val in options.items():
        setattr(owner, key, val)


def _count_evaluations(bodies, options, until):
    """Force evaluations of REBOUND's IAS15 over the same run, counted in a
    second, untimed run by a no-op additional force (REBOUND exposes no such
    counter).  The extra force adds nothing, so the steps are the same."""
    sim = bodies.to_rebound()
    sim.gravity = "basic"
    sim.integrator = "ias15"
    _set_options(sim, "ias15", options)
    count = [0]

    def tally(_sim):
        count[0] += 1

    sim.additional_forces = tally
    sim.force_is_velocity_dependent = 0
    sim.integrate(float(until), exact_finish_time=1)
    return count[0]


def exact_two_body(body_set, t):
    """Positions (N=2, 3) of a two-body problem at time ``t``, from its Kepler
    orbit: the mean anomaly advances by ``n t`` (reduced modulo 2 pi in two
    parts, so its rounding is that of one orbit's, ~1e-15 rad) and the centre
    of mass moves uniformly."""
    m = body_set._m
    x, v = body_set._x, body_set._v
    mu = body_set.units.G * (m[0] + m[1])
    el = np.zeros(7)
    _elements.state_to_elements(mu, x[1] - x[0], v[1] - v[0], el)
    a, e, inc, node, peri, _, mean0 = el
    n = math.sqrt(mu / a ** 3)
    period = 2 * math.pi / n
    whole = math.floor(t / period)
    mean = mean0 + n * (t - whole * period)
    f = _anomalies.true_from_mean(math.fmod(mean, 2 * math.pi), e)
    pos, vel = np.zeros(3), np.zeros(3)
    _elements.elements_to_state(mu, a, e, inc, node, peri, f, pos, vel)
    com = (m[:, None] * x).sum(0) / m.sum() + (m[:, None] * v).sum(0) / m.sum() * t
    return np.array([com - m[1] / m.sum() * pos, com + m[0] / m.sum() * pos])


def position_error(row, ref, problem=None):
    """Largest final position error of ``row``: against the exact Kepler orbit
    for the two-body problems, else against the reference row ``ref``."""
    if row["x"] is None or row["outcome"] != "completed":
        return math.nan
    prob = cases.problem(problem) if problem is not None else None
    if prob is not None and prob.scene == "kepler":
        exact = exact_two_body(cases.bodies(prob), row["t_end"])
        return float(np.abs(np.asarray(row["x"]) - exact).max())
    if ref is None or ref["x"] is None or ref["outcome"] != "completed":
        return math.nan
    return float(np.abs(np.asarray(row["x"]) - np.asarray(ref["x"])).max())
