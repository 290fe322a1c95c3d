"""Compiling the stepping loops ahead of time: ``orbits compile`` and
:func:`compile_ahead`, for clusters, containers and CI (see :mod:`._compiling`)."""

import functools
import os
from typing import NamedTuple

import astropy.units as u
from tqdm.auto import tqdm

from . import integrators, scenes
from .bodies import BodySet
from ._compiling import ADDED, COMMON, CompileClock, loop_label, stderr_is_terminal
from .errors import IntegratorOptionError
from .integrators.wisdom_holman import COORDINATES
from .simulation import Simulation

__all__ = ["compile_ahead"]


#: The step of the fixed-step runs that compile a loop ahead, in days.
_AHEAD_DT_DAYS = 10.0
#: Steps of each such run (enough for the loop's in-loop outputs to be used).
_AHEAD_STEPS = 10


class Loop(NamedTuple):
    """A run that compiles one of an integrator's loops: the integrator's
    registry name and options, whether it steps with the planets in vector
    lanes, and what the run adds to plain gravity (:data:`ADDS`)."""

    name: str
    options: dict
    lanes: bool
    adds: str = ""


#: What a run may add to gravity, which ``orbits compile`` compiles unless
#: told ``plain``: ``"terms"``, any combination of built-in force terms (the
#: terms' kernels, once for every integrator: each integrator's loop serves
#: runs with and without terms); ``"variations"``, the variational equations
#: and the chaos monitors (one loop for every kind of variations, with or
#: without terms); ``"terms+variations"``, both together (the terms'
#: Jacobians, once for every integrator); ``"checks"``, the stopping
#: conditions, collisions and the encounter log (one compiled check for every
#: integrator, and what a run with them calls, with or without the others).
ADDS = tuple(ADDED)


def _variants(name, plain=False):
    """The loops ``name`` compiles, as :class:`Loop`: one per set of
    coordinates for the methods that take them, and for those with a
    ``lanes`` option (``wh``, the SABA methods, ``trace``) the scalar loop
    and the lanes' one of each; then, unless ``plain``, for each scalar loop
    the loops of runs with force terms, with variations and with both where
    the integrator takes them (:data:`ADDS`), and one run with every
    stopping condition where it checks them."""
    integ = integrators.get(name)
    options = type(integ).options
    coords = options.get("coordinates")
    modes = ("off", "on") if "lanes" in options else (None,)
    order = [None] if coords is None else [coords] + [c for c in COORDINATES if c != coords]
    loops = []
    for c in order:
        extra = {} if c is None else {"coordinates": c}
        loops += [Loop(name, dict(extra) if mode is None else dict(extra, lanes=mode),
                       mode == "on") for mode in modes]
    if plain:
        return loops
    scalar = [loop for loop in loops if not loop.lanes]
    if _terms_for(integ) is not None:
        loops += [loop._replace(adds="terms") for loop in scalar]
    if integ.chaos_indicators:
        loops += [loop._replace(adds="variations") for loop in scalar]
        if _terms_for(integ) is not None:
            loops += [loop._replace(adds="terms+variations") for loop in scalar]
    if integ.stop_conditions:
        loops.append(scalar[0]._replace(adds="checks"))
    return loops


def _terms_for(integ):
    """Built-in terms that ``integ`` takes and that compile its loop for
    terms: GR and a migration (velocities read, work integrated) where it
    takes them, else GRPotential (the Wisdom-Holman family); None where it
    takes no added terms."""
    from . import forces
    for terms in ([forces.GR("Sun"), forces.Migration("Neptune", tau_a=1e7 * u.yr)],
                  [forces.GRPotential("Sun")]):
        try:
            integ.check_terms(terms)
        except IntegratorOptionError:
            continue
        return terms
    return None


def _checks_for(integ):
    """The keywords of :class:`~orbits.Simulation` for every stopping
    condition ``integ`` checks, with the outer solar system's bodies given
    sizes (collisions need them); none is met in the few steps of the run."""
    every = dict(encounter_distance=0.01 * u.au, escape_distance=1000 * u.au,
                 collisions="merge", encounter_log=0.1 * u.au)
    taken = integ.stop_conditions
    return every if taken is True else {k: every[k] for k in taken if k in every}


def _compile_loop(name, options, lanes, adds=""):
    """Compile one loop in this process (a few steps of the outer solar
    system, with what ``adds`` names, :data:`ADDS`): ``(its label, the
    seconds spent compiling)``."""
    integ = integrators.get(name, **options)
    if (adds == "terms" or lanes) and integ.config.get("corrector") == 0:
        # with a corrector where the method takes one (wh): its loops call it
        # through a pointer compiled for the runs that have one (the scalar
        # loop's with the run with terms, the lanes' loop's with its run)
        try:
            integ = integrators.get(name, **{**options, "corrector": 11})
        except IntegratorOptionError:
            pass
    label = loop_label(integ, lanes, adds)
    dt = None if integ.adaptive else _AHEAD_DT_DAYS * u.day
    until = _AHEAD_STEPS * _AHEAD_DT_DAYS * u.day
    bodies = scenes.outer_solar_system()
    kw = {}
    if adds in ("terms", "terms+variations"):
        kw["forces"] = _terms_for(integ)
    if adds in ("variations", "terms+variations"):
        kw["monitors"] = ("energy", "megno")
    if adds == "checks":
        kw = _checks_for(integ)
        if "collisions" in kw:
            bodies = BodySet.from_arrays(bodies.masses, bodies.positions, bodies.velocities,
                                         names=bodies.names, units=bodies.units,
                                         radii=[1e-3] * len(bodies) * u.au)
    with CompileClock() as clock:
        sim = Simulation(bodies, integrator=integ, dt=dt, **kw)
        sim.run(until=until, outputs=3, progress=False)
        if adds == "checks":
            # the check a run with escape conditions alone takes instead
            from ._kernels.stopping import ESCAPE, check_pointer
            check_pointer(ESCAPE)
    return label, clock.seconds


def _pool_order(loops):
    """The indices of ``loops`` after the first in the order a pool takes
    them: the first run with each addition (which compiles what every
    integrator's runs with it share: the terms' table, the stopping
    conditions' check), then the loops of gravity alone, then the other
    runs with additions, which by then load what they share."""
    rest = range(1, len(loops))
    firsts = {}
    for i in rest:
        firsts.setdefault(loops[i].adds, i)
    head = [i for adds, i in firsts.items() if adds]
    return (head + [i for i in rest if not loops[i].adds]
            + [i for i in rest if loops[i].adds and i not in head])


#: Bases that say nothing of a method's loop: a method whose next base is one
#: of these has a loop family of its own (:func:`_family`)
_GENERIC_BASES = ("Integrator", "AdaptiveIntegrator")


@functools.lru_cache(maxsize=None)
def _family(name):
    """The family of methods whose loops ``name``'s may be: its class's first
    base (the SABA methods wh's, the splitting methods theirs, dopri5 and
    dop853 the embedded methods'), or its class where that base is generic."""
    mro = type(integrators.get(name)).__mro__
    return mro[0] if mro[1].__name__ in _GENERIC_BASES else mro[1]


@functools.lru_cache(maxsize=None)
def _loop_adds(name, adds):
    """The addition whose loop a run of ``name`` with ``adds`` takes: an
    integrator that takes force terms as data runs the same loop with and
    without them (its runs with terms compile only the terms' kernels)."""
    if integrators.get(name).terms_as_data:
        return {"terms": "", "terms+variations": "variations"}.get(adds, adds)
    return adds


def _startable(i, loops, running, waiting):
    """Whether ``loops[i]`` may start while the indices ``running`` run and
    ``waiting`` wait: not beside a run of the same family, coordinates,
    lanes and loop (:func:`_loop_adds`; a loop they share would be compiled
    twice at once), nor before the first run with its addition has ended
    (which compiles what they all share: the terms' table, the stopping
    conditions' check)."""
    loop = loops[i]

    def key(k):
        other = loops[k]
        return (_family(other.name), other.options.get("coordinates"), other.lanes,
                _loop_adds(other.name, other.adds))

    if any(key(k) == key(i) for k in running):
        return False
    if loop.adds:
        first = min(k for k in (*running, *waiting, i) if loops[k].adds == loop.adds)
        return first == i or first not in (*running, *waiting)
    return True


def _check_jobs(jobs):
    """``jobs`` as a number of processes (0: one a core); a named error for
    anything else."""
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 0:
        raise ValueError(f"jobs must be a whole number >= 0 (0: one process a core), "
                         f"got {jobs!r}")
    return (os.cpu_count() or 1) if jobs == 0 else jobs


def _pool(jobs):
    """A pool of ``jobs`` new processes (each imports the package afresh: no
    numba state is forked), or a named error where they would import an
    unguarded main script again."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from .ensemble.guard import _unguarded_main_call, _where
    where = _unguarded_main_call("spawn")
    if where is not None:
        raise RuntimeError(
            f"compile_ahead(jobs={jobs}) was called from {_where(*where)}, outside "
            f'`if __name__ == "__main__":`: each of its processes imports the main script '
            f"again and would run it; put the call under the guard, or use jobs=1")
    return ProcessPoolExecutor(max_workers=jobs,
                               mp_context=multiprocessing.get_context("spawn"))


def compile_ahead(names=None, progress=None, report=None, jobs=1, plain=False):
    """Compile the stepping loops of ``names`` now, so that later runs load them.

    ``orbits compile`` on the command line.

    Each integrator runs the outer solar system
    (:func:`orbits.scenes.outer_solar_system`) for a few steps, in both
    Wisdom-Holman coordinate systems where it takes them, which compiles its
    loop and the kernels it calls into numba's cache (:func:`orbits._compiling.cache_dir`).
    Unless ``plain``, it runs again with what a run may add: built-in force
    terms (their kernels, once for every integrator; every loop serves runs
    with and without terms), the variational equations and chaos monitors
    (one loop for every kind) with and without terms, and the stopping
    conditions, collisions and encounter log (one compiled check for every
    integrator).  Afterwards a run that adds any of
    these compiles nothing (a user's own force compiles its function once).
    Integrators that run in Python (scipy's ``radau`` and ``lsoda``) have
    nothing to compile and are skipped.  The cache is per CPU and numba
    version: compile on the machine (or image) that runs, before many
    processes start at once.

    Parameters
    ----------
    names : sequence of str, optional
        Registry names; default ``leapfrog``, ``ias15`` and ``wh``
        (:data:`COMMON`).  All of them:
        ``[i.name for i in orbits.integrators.available()]``.
    progress : bool, optional
        A progress bar over the loops on the standard error: shown on a
        terminal by default.
    report : callable, optional
        Called with ``(label, seconds)`` after each loop (``orbits compile``
        prints a line with it), in the order the loops are done.
    jobs : int, optional
        Processes that compile at once (default 1, this one; 0: one a core).
        With more, the first loop is compiled here, so that the kernels every
        loop shares are in the cache, and the others in that many new
        processes, which share numba's cache: the wall time falls with the
        cores, for a little more CPU time (a kernel that two loops of
        different methods share may be compiled in both; a process starts
        no loop that a running one may share).  From a script, call it
        under ``if __name__ == "__main__":`` (each new process imports the
        main script again).
    plain : bool, optional
        Only the loops of runs of gravity alone, without terms, variations
        or stopping conditions (about a third of the time).

    Returns
    -------
    list of (str, float)
        Each loop's name (:func:`loop_label`) and the seconds spent
        compiling it (0 for a loop that was loaded from the cache), in the
        order of ``names``.

    Raises
    ------
    UnknownIntegratorError
        A name that is not registered (checked before anything compiles).
    ValueError
        ``jobs`` not a whole number >= 0.
    RuntimeError
        ``jobs`` > 1 from the top level of a script without the
        ``__main__`` guard.

    Examples
    --------
    >>> [label for label, _ in orbits.compile_ahead(["leapfrog"], progress=False,
    ...                                               plain=True)]
    ['leapfrog']

    Without ``plain``, ``leapfrog`` compiles ``['leapfrog', 'leapfrog with
    force terms', 'leapfrog with variations', 'leapfrog with stopping
    conditions']``.

    ``wh`` (and ``saba2`` to ``saba4``) compile a loop for each set of
    coordinates, and each of them with the planets in vector lanes (which
    runs take by the ``lanes`` option): ``['wh', 'wh lanes', 'wh
    democratic-heliocentric', 'wh democratic-heliocentric lanes']``, then
    the scalar loops with terms and with variations; ``trace`` its loop and
    the one with its steps far from encounters in vector lanes: ``['trace',
    'trace lanes']``, then the others it takes.
    """
    names = COMMON if names is None else tuple(names)
    jobs = _check_jobs(jobs)
    loops = [spec for name in names if getattr(integrators.get(name), "compiled", True)
             for spec in _variants(name, plain)]
    if progress is None:
        progress = stderr_is_terminal()
    bar = None
    if progress:
        bar = tqdm(total=len(loops), unit="loop", desc="compiling", leave=False)
    done = [None] * len(loops)

    def note(i, result):
        done[i] = result
        if report is not None:
            report(*result)
        if bar is not None:
            bar.set_postfix_str(result[0])
            bar.update(1)

    try:
        if jobs == 1 or len(loops) <= 1:
            for i, spec in enumerate(loops):
                note(i, _compile_loop(*spec))
        else:
            from concurrent.futures import FIRST_COMPLETED, wait
            workers = min(jobs, len(loops) - 1)
            with _pool(workers) as pool:
                # the first loop here, so that the kernels the loops share
                # (the monitors, the Kepler drift) are in the cache before
                # the processes start; then as many at once as there are
                # processes, each started when it would not compile what
                # one running compiles (_startable)
                note(0, _compile_loop(*loops[0]))
                waiting = _pool_order(loops)
                futures = {}
                while waiting or futures:
                    running = list(futures.values())
                    for i in list(waiting):
                        if len(futures) >= workers:
                            break
                        if _startable(i, loops, running, waiting) or not futures:
                            waiting.remove(i)
                            futures[pool.submit(_compile_loop, *loops[i])] = i
                            running.append(i)
                    done_now, _ = wait(futures, return_when=FIRST_COMPLETED)
                    for future in done_now:
                        note(futures.pop(future), future.result())
    finally:
        if bar is not None:
            bar.close()
    return done
