"""Ensembles and parameter sweeps: many simulations, run on Dask.

An :class:`Ensemble` is a list of runs, each described by a dictionary of
parameters, and one function that turns a dictionary into a
:class:`~orbits.Simulation`.  What travels to the workers is that function
and the dictionaries, never a simulation (its compiled kernels do not
pickle); each worker builds its own simulations and keeps the kernels it
compiled, or loaded from numba's on-disk cache, for every later task.

:meth:`Ensemble.run` returns a :class:`pandas.DataFrame`, one row per run.
Its columns:

``run``
    The run's number (the frame's index), its place in the parameter list.
parameters
    One column per parameter; a Quantity ``x`` becomes ``x_<unit>``.
``outcome``
    ``"completed"``; for a run that failed, the name of the
    :class:`~orbits.errors.RunError` it raised in lower case with hyphens:
    ``"close-encounter"``, ``"escape"``, ``"non-finite-state"``,
    ``"step-size-underflow"``, ...; ``"invalid"`` where ``build`` or the
    simulation rejected the parameters with another
    :class:`~orbits.errors.OrbitsError`.
``message``, ``stop_bodies``
    The exception's text and the bodies it names (comma-separated); empty for
    a completed run.
``t_stop_<time unit>``
    Time at which the run ended: ``until``, or the time of the stop.
``steps``
    Steps taken.
``energy_error_max``, ``angular_momentum_error_max``
    Largest relative errors at the outputs (and in the in-loop monitor series,
    if the simulation records one); NaN when the monitor is off.
``megno``, ``lyapunov_per_<time unit>``, ``fli``
    With those chaos monitors (:class:`~orbits.Simulation`'s ``monitors``):
    their values at the end of the run (at the stop, for a run that stopped
    early), so that a stability map is one sweep.  The Lyapunov exponent's
    estimate is in 1 / the run's unit of time (``lyapunov_per_day``).  A row
    reproduces bit for bit when ``build`` gives its simulations a ``seed``;
    without one each run draws its own (kept in its file with ``out_dir``).
``<body>_a_<length unit>``, ``<body>_e``, ``<body>_inc_rad``
    Osculating elements at the end, of every body but the most massive one,
    about the most massive one; NaN where no orbit is defined.
``collisions``, ``bodies_left``
    With ``collisions=`` that the run resolves (``"merge"``, ``"bounce"``, a
    function): how many it resolved, and how many bodies were left at the end;
    a body merged away has NaN elements.
``wall_time_s``
    Seconds the run itself took (building and elements excluded).
``worker``, ``kernels_compiled``, ``kernels_loaded``
    Where the run ran (``host:pid``), and how many compiled loops this task
    compiled, and loaded from the on-disk cache, before it could start: only a
    worker's first task of a kind loads any; none compiles once the cache is
    warm.
``file``
    The run's HDF5 file, relative to ``out_dir`` (empty without one).

``df.attrs`` holds ``until``, the units of the columns, and the element
columns' primary.

Runs are deterministic: a run gives the same numbers, bit for bit, on any
worker as in a serial loop (``client="serial"``).
"""

import ast
import contextlib
import csv
import functools
import hashlib
import io
import json
import linecache
import logging
import math
import multiprocessing
import numbers
import os
import pathlib
import socket
import sys
import time as _time
import warnings

import astropy.units as u
import numpy as np

from . import integrators as _integrators
from ._csvcells import read_cell, safe_cell
from .errors import OrbitsError, RunError
from .forces import functions_of

__all__ = ["Ensemble", "local_cluster", "MissingMainGuard", "EnsembleOptionError",
           "INDEX_FILE", "SWEEP_FILE", "ELEMENTS_MAX_BODIES", "PROGRESS_DELAY",
           "WORKER_ENVIRONMENT", "WORKER_DASK_CONFIG"]

#: The index of finished runs in ``out_dir``: one CSV row per run, appended as
#: each finishes (one write of a whole line, then fsync), so that an interrupted
#: sweep knows what it has done.  On reading, only complete rows count: a line
#: cut off by a crash, or any row that does not parse whole, is dropped with a
#: warning and its run is done again.  A text cell that a spreadsheet would take
#: for a formula (a body named ``=HYPERLINK(...)``, in a column's name or in
#: ``stop_bodies``) begins with a single quote, which reading takes away.
INDEX_FILE = "index.csv"

#: What the sweep in ``out_dir`` is (runs, ``until``, outputs, a hash of the
#: parameters), so that a different sweep is not resumed into it by mistake.
#: Every row of the index is also checked against the parameters of the run of
#: its number, so that without this file (deleted) another sweep is still
#: refused.
SWEEP_FILE = "sweep.json"

#: Final elements are reported for every non-central body up to this many
#: bodies; above it only for the bodies named in ``elements=``.
ELEMENTS_MAX_BODIES = 16

#: The sweep's progress bar appears after this many seconds, so short sweeps stay quiet.
PROGRESS_DELAY = 3.0

#: Set in every worker of :func:`local_cluster`.  One numba thread per worker
#: process: the workers already use every core, and threads on top of them
#: would only compete (the threaded gravity kernel starts at 128 bodies).
WORKER_ENVIRONMENT = {"NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "1",
                      "MKL_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}

#: Dask settings of :func:`local_cluster`'s scheduler and workers, given to
#: the workers as their configuration (a worker takes its nanny's, not its
#: environment's).  Dask's defaults wake each process many times a second on
#: the cores the runs use: the statistical profiler sampled the running task
#: every 10 ms from a thread of its own, the event loop's latency probe ran
#: every 20 ms (it only measures; Dask's own tests take 500 ms), the memory
#: monitor every 0.1 s (1 s still stops a worker whose memory runs away) and
#: the system monitor every 0.5 s.  Measured on two workers: the 512-run MEGNO
#: map's runs took 17.3-17.8 s summed without the profiler against 18.4-19.0
#: s with it; idle for 10 s, the workers used 0.07-0.12 s of CPU with these
#: settings against 0.40-0.54 s with only the profiler off, and the
#: scheduler's process 0.10-0.14 s against 0.52-0.61 (0.40-0.45 s against
#: 0.90-1.07 s over the map).  The preload (``orbits._daskworker``) has
#: each worker process ignore SIGINT, which Ctrl-C in a terminal sends to every
#: process of the foreground group: the process that started the cluster closes
#: it, instead of each worker stopping with its own tracebacks.
WORKER_DASK_CONFIG = {"distributed.worker.profile.enabled": False,
                      "distributed.admin.system-monitor.interval": "2s",
                      "distributed.admin.tick.interval": "500ms",
                      "distributed.worker.memory.monitor-interval": "1s",
                      "distributed.worker.preload": "orbits._daskworker"}


_GUARD_ADVICE = ('each worker process of a local cluster imports the main script again and '
                 'runs its top level: put the code that runs the sweep under '
                 '`if __name__ == "__main__":` (as in the README\'s ensemble example), '
                 'or run the sweep in this process with client="serial"')


class MissingMainGuard(OrbitsError, RuntimeError):
    """A script started a local cluster of worker processes from its top level,
    outside ``if __name__ == "__main__":``.

    Python starts the workers by importing the main script afresh in each of them
    (the ``spawn`` start method, which Dask uses); a script that starts the sweep
    as it is imported has each worker start another cluster, and the workers fail.
    Put the sweep under the guard::

        def build(a, e):
            ...

        if __name__ == "__main__":
            df = orbits.Ensemble.grid(build, a=..., e=...).run(until=...)

    Attributes
    ----------
    script : str or None
        The main script.
    line : int or None
        The line of the script from which the cluster was started.

    Examples
    --------
    >>> import orbits
    >>> from orbits.ensemble import MissingMainGuard
    >>> exc = MissingMainGuard("starts a cluster at import", script="sweep.py", line=12)
    >>> isinstance(exc, (orbits.OrbitsError, RuntimeError)), exc.script, exc.line
    (True, 'sweep.py', 12)
    """

    def __init__(self, message, script=None, line=None):
        self.script = script
        self.line = line
        super().__init__(message)


class EnsembleOptionError(OrbitsError, ValueError):
    """An argument of :class:`Ensemble` or :meth:`Ensemble.run` that cannot be
    taken as given (the message names it, the value and what is expected): a
    parameter with the name of a result column, an ``out_dir`` that holds
    another sweep, a ``batch`` that is no whole number.

    Examples
    --------
    >>> import astropy.units as u
    >>> import orbits
    >>> from orbits.ensemble import EnsembleOptionError
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "wh", dt=1 * u.day)
    >>> try:
    ...     orbits.Ensemble.perturbed(sim, n=2).run(until=1 * u.yr, client="serial",
    ...                                             batch=0)
    ... except EnsembleOptionError as exc:
    ...     print(exc)
    batch must be None or a whole number of systems per batch >= 1, got 0
    """


class Ensemble:
    """Many simulations, built from parameters by one function.

    Parameters
    ----------
    build : callable
        ``build(**p)`` returns a :class:`~orbits.Simulation` for one parameter
        dictionary ``p``.  It is sent to the workers, so it must pickle: a
        function defined at module level (or in the script being run) always
        does; Dask's cloudpickle also sends most closures and lambdas.
    parameters : iterable of dict, or pandas.DataFrame
        One dictionary (or row) per run.  Values may be numbers, strings or
        scalar Quantities.  A name (or ``name_<unit>`` of a Quantity) may not
        be that of a result column (``outcome``, ``steps``, ``file``, ...;
        the module docstring lists them): :class:`EnsembleOptionError`.

    Examples
    --------
    >>> import astropy.units as u
    >>> import orbits
    >>> def build(e):
    ...     return orbits.Simulation(orbits.scenes.kepler(e=e), integrator="leapfrog",
    ...                              dt=1 * u.day)
    >>> ens = orbits.Ensemble(build, [{"e": 0.1}, {"e": 0.5}])
    >>> df = ens.run(until=1 * u.yr, client="serial", progress=False)
    >>> list(df.outcome)
    ['completed', 'completed']
    """

    def __init__(self, build, parameters):
        if not callable(build):
            raise TypeError(f"build must be callable, got {type(build).__name__}")
        if hasattr(parameters, "to_dict") and hasattr(parameters, "columns"):
            parameters = parameters.to_dict(orient="records")
        params = [dict(p) for p in parameters]
        for i, p in enumerate(params):
            bad = [k for k in p if not isinstance(k, str) or not k.isidentifier()]
            if bad:
                raise ValueError(f"parameter set {i}: names must be identifiers "
                                 f"(they are passed as keywords), got {bad}")
            _check_parameter_names(p, i)
        self.build = build
        self.parameters = params

    # -- construction ---------------------------------------------------------------
    @classmethod
    def grid(cls, build, **axes):
        """Every combination of the values along each axis (the first varies slowest).

        >>> import numpy as np
        >>> ens = Ensemble.grid(lambda a, e: None, a=[1.0, 2.0], e=np.linspace(0, 0.2, 3))
        >>> len(ens), ens.parameters[1]
        (6, {'a': 1.0, 'e': 0.1})
        """
        if not axes:
            raise ValueError("grid needs at least one axis, e.g. a=[...]")
        names = list(axes)
        values = [list(axes[k]) for k in names]
        shape = [len(v) for v in values]
        params = []
        for flat in range(int(np.prod(shape))):
            idx = np.unravel_index(flat, shape)
            params.append({k: _plain(values[j][idx[j]]) for j, k in enumerate(names)})
        return cls(build, params)

    @classmethod
    def perturbed(cls, sim, n=100, scale=1e-10, seed=1):
        """``n`` copies of a simulation with slightly shifted positions.

        Each body's position moves by ``scale`` times its distance from the
        centre of mass, in a random direction; velocities are kept.  Run ``k``
        draws its directions from ``numpy.random.SeedSequence(seed,
        spawn_key=(k,))``, so a run's perturbation depends only on ``seed`` and
        ``k`` (not on ``n``) and is the same on any machine.

        Parameters
        ----------
        sim : Simulation
            Its current state (time reset to zero), integrator and options,
            step, monitors, softening and stopping conditions are copied.
        n : int
            Number of runs; the parameter of run ``k`` is ``member = k``.
        scale : float
            Relative size of the shifts (dimensionless).
        seed : int

        Returns
        -------
        Ensemble

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
        >>> ens = orbits.Ensemble.perturbed(sim, n=3, scale=1e-10)
        >>> ens.parameters
        [{'member': 0}, {'member': 1}, {'member': 2}]
        >>> shift = ens.simulation(1).bodies.positions - sim.bodies.positions
        >>> shift.unit, bool(0 < abs(shift[1]).max().value < 1e-9)        # 1e-10 of 1 au
        (Unit("AU"), True)
        """
        if int(n) != n or n < 1:
            raise ValueError(f"n must be a whole number >= 1, got {n}")
        if not (scale >= 0 and math.isfinite(scale)):
            raise ValueError(f"scale must be a finite number >= 0, got {scale}")
        recipe = _Perturbation(sim, float(scale), int(seed))
        return cls(recipe, [{"member": k} for k in range(int(n))])

    # -- access ---------------------------------------------------------------------
    def __len__(self):
        return len(self.parameters)

    def __repr__(self):
        return f"<Ensemble of {len(self)} runs of {_describe(self.build)}>"

    def simulation(self, run):
        """The simulation of run number ``run``, built here (to look at or run alone).

        Parameters
        ----------
        run : int
            Index into :attr:`parameters`.

        Returns
        -------
        Simulation

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> def build(e):
        ...     return orbits.Simulation(orbits.scenes.kepler(e=e), "leapfrog", dt=1 * u.day)
        >>> ens = orbits.Ensemble.grid(build, e=[0.1, 0.5])
        >>> sim = ens.simulation(1)
        >>> round(float(sim.bodies.elements("Planet")["e"]), 6)
        0.5
        """
        return self.build(**self.parameters[run])

    # -- running --------------------------------------------------------------------
    def run(self, until, client=None, *, outputs=100, out_dir=None, n_workers=None,
            elements=None, progress=None, batch=None):
        """Run every simulation to ``until`` and tabulate how each went.

        Parameters
        ----------
        until : Quantity (time) or float
            End time of every run (a float is read in each body set's time unit).
        client : None, "serial", str or distributed.Client
            ``None``: a local cluster of ``n_workers`` processes with one thread
            each (:func:`local_cluster`), closed at the end.  ``"serial"``: one
            after the other in this process.  A scheduler address such as
            ``"tcp://10.0.0.5:8786"``: that cluster.  A ``Client``: its cluster.
        outputs : int
            Outputs per run (see :meth:`orbits.Simulation.run`); the largest
            energy and angular-momentum errors are taken over them.
        out_dir : str or path, optional
            Write each run's outputs to ``out_dir/run-00042.h5`` and its row to
            ``out_dir/index.csv`` as it finishes.  Called again with the same
            ``out_dir`` the sweep skips the runs the index lists, and starts the
            others afresh (a run cut off in the middle is run again from its
            start, and so is a run whose row a crash cut off: only complete
            rows count).  The directory must be reachable by the workers under
            the same path.
        n_workers : int, optional
            Workers of the local cluster (default: ``os.cpu_count()``).
        elements : sequence of str, optional
            Bodies whose final elements to report.  Default: every body but the
            most massive, when there are at most :data:`ELEMENTS_MAX_BODIES`.
        progress : bool, optional
            A bar counting finished runs.  Default: shown once the sweep has
            gone on for :data:`PROGRESS_DELAY` seconds.
        batch : int, optional
            Integrate up to this many runs together in one compiled loop, one
            system per vector lane (:mod:`orbits._kernels.wh_batch`): runs
            that use ``wh`` with its default options, the same number of
            bodies (and massive bodies), step, units, monitors and start, and
            no added force terms, stopping conditions, variations, chaos
            monitors, ``monitor_every`` or softening.  The other runs go on
            alone as without it.  The rows are those of the runs made one by
            one, bit for bit (``wall_time_s`` is the batch's time shared out
            among its runs); a run whose state turns non-finite is run again
            alone, so that its row is that of its own failure.  Default None:
            every run alone.

        Returns
        -------
        pandas.DataFrame
            One row per run, indexed by run number; the columns are listed in
            the module docstring.  A failed run is a row with its outcome; an
            exception from ``build`` other than an
            :class:`~orbits.errors.OrbitsError` stops the sweep (the rows
            finished before are kept in ``out_dir``).  So does Ctrl-C, after
            one line on standard error saying how many runs ``out_dir`` holds:
            the same call continues from there.

        Raises
        ------
        EnsembleOptionError
            ``batch`` is not None or a whole number >= 1; ``out_dir`` holds
            another sweep (its ``sweep.json`` says so, or a row of its index
            has other parameters than this sweep's run of that number); a
            parameter has the name of a column of the results.
        MissingMainGuard
            With ``client=None``, when called from the top level of a script
            outside ``if __name__ == "__main__":``: each worker process imports
            the script again, so a script that starts a local cluster needs the
            guard.

        Examples
        --------
        >>> import astropy.units as u
        >>> import orbits
        >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
        >>> ens = orbits.Ensemble.perturbed(sim, n=3, scale=1e-10)
        >>> df = ens.run(until=1 * u.yr, client="serial", outputs=5, progress=False)
        >>> list(df.outcome), df.t_stop_day.tolist()
        (['completed', 'completed', 'completed'], [365.25, 365.25, 365.25])
        >>> bool((df.energy_error_max < 1e-8).all()), round(float(df.Planet_a_au.mean()), 4)
        (True, 1.0)
        """
        import pandas as pd

        batch = _check_batch(batch)
        spec = _Spec(until, int(outputs), None if elements is None else tuple(elements))
        n = len(self.parameters)
        done = {}
        if out_dir is not None:
            out_dir = pathlib.Path(out_dir)
            done = _open_out_dir(out_dir, self._fingerprint(spec), self.parameters)
        todo = [i for i in range(n) if i not in done]
        rows = dict(done)
        try:
            if todo and isinstance(client, str) and client == "serial":
                self._run_serial(todo, spec, out_dir, rows, progress, batch)
            elif todo:
                self._run_dask(todo, spec, out_dir, rows, progress, client, n_workers, batch)
        except KeyboardInterrupt as exc:
            # one line, not the traceback through Dask's internals: how many runs
            # are safe, and what to do next
            print(_interrupted(out_dir, n, len(rows)), file=sys.stderr, flush=True)
            raise exc.with_traceback(None) from None
        frame = pd.DataFrame([rows[i] for i in range(n)])
        frame = frame[_column_order(frame.columns, self.parameters)].set_index("run")
        frame.attrs.update(_frame_attrs(spec, frame))
        return frame

    def _run_serial(self, todo, spec, out_dir, rows, progress, batch=None):
        bar = _bar(len(todo), progress)
        try:
            if batch is None:
                for i in todo:
                    row = run_one(self.build, self.parameters[i], i, spec, _path(out_dir, i))
                    _finish(row, rows, out_dir)
                    bar.update(1)
                return
            # a few batches' worth at a time, so that runs of one kind that are
            # not neighbours in the list still fill a batch
            size = batch * max(1, CHUNK_MAX // batch)
            for k in range(0, len(todo), size):
                chunk = todo[k:k + size]
                done, error = run_chunk(self.build, [self.parameters[i] for i in chunk],
                                        chunk, spec, [_path(out_dir, i) for i in chunk],
                                        batch)
                for row in done:
                    _finish(row, rows, out_dir)
                bar.update(len(done))
                if error is not None:
                    raise error
        finally:
            bar.close()

    def _run_dask(self, todo, spec, out_dir, rows, progress, client, n_workers, batch=None):
        from distributed import Client, as_completed

        own = None
        if client is None:
            client = own = local_cluster(n_workers)
        elif isinstance(client, str):
            client = own = Client(client)
        token = self._fingerprint(spec)[:12]
        bar = _bar(len(todo), progress)
        futures = []
        try:
            [build] = client.scatter([self.build], broadcast=True, hash=False)
            workers = max(1, len(client.scheduler_info().get("workers", ())))
            chunks = _Chunks(todo, workers, batch)

            def submit(chunk):
                fut = client.submit(run_chunk, build, [self.parameters[i] for i in chunk],
                                    chunk, spec, [_path(out_dir, i) for i in chunk], batch,
                                    key=f"orbits-run-{token}-{chunk[0]}-{len(chunk)}",
                                    pure=False)
                futures.append(fut)
                return fut

            pending = as_completed([submit(c) for c in chunks.first()])
            for fut in pending:
                done, error = fut.result()
                for row in done:
                    _finish(row, rows, out_dir)
                bar.update(len(done))
                fut.release()
                if error is not None:
                    raise error
                chunks.took(done)
                for chunk in chunks.next(pending.count()):
                    pending.add(submit(chunk))
        finally:
            bar.close()
            unfinished = [f for f in futures if not f.done()]
            if unfinished:
                client.cancel(unfinished)
            if own is not None:
                cluster = own.cluster
                # a worker busy with a run (one cut short by Ctrl-C) is killed
                # after Dask's grace period, with a warning that says no more
                # than that: the run is done again by the next call
                with _without_warnings("distributed.nanny"):
                    own.close()
                    if cluster is not None:
                        cluster.close()

    def _fingerprint(self, spec):
        h = hashlib.sha1()
        h.update(json.dumps([_describe(self.build), len(self), str(spec.until), spec.outputs,
                             spec.elements, self.parameters],
                            sort_keys=True, default=str).encode())
        if isinstance(self.build, _Perturbation):
            h.update(self.build.fingerprint())
        return h.hexdigest()


def local_cluster(n_workers=None):
    """A Dask client of a new cluster on this machine: ``n_workers`` processes
    (default ``os.cpu_count()``) of one thread each, on the loopback interface,
    without dashboard, each with :data:`WORKER_ENVIRONMENT` and
    :data:`WORKER_DASK_CONFIG`.  Close it with
    ``client.close(); client.cluster.close()`` (or use it in a ``with``).

    Raises :class:`MissingMainGuard` when called from the top level of a script
    that lacks ``if __name__ == "__main__":`` (the workers cannot start).

    Parameters
    ----------
    n_workers : int, optional
        Worker processes, >= 1.

    Returns
    -------
    distributed.Client

    Raises
    ------
    ValueError
        ``n_workers`` < 1.
    MissingMainGuard
        Called from the top level of an unguarded script.

    Examples
    --------
    >>> from orbits.ensemble import local_cluster
    >>> try:
    ...     local_cluster(n_workers=0)
    ... except ValueError as exc:
    ...     print(exc)
    n_workers must be >= 1, got 0
    >>> client = local_cluster(n_workers=2)     # doctest: +SKIP
    >>> client.close(); client.cluster.close()  # doctest: +SKIP
    """
    import dask
    from distributed import Client, LocalCluster

    n = os.cpu_count() if n_workers is None else int(n_workers)
    if n < 1:
        raise ValueError(f"n_workers must be >= 1, got {n_workers}")
    if _importing_main_in_a_child():
        # a worker importing an unguarded script: stop here with the reason, rather
        # than have this worker try to start a cluster of its own
        script, line = _top_level_call(sys.modules.get("__mp_main__")) or (None, None)
        raise MissingMainGuard(f"a new worker process, importing the main script again, "
                               f"reached {_where(script, line)}, which starts another "
                               f"cluster; {_GUARD_ADVICE}", script=script, line=line)
    # no dashboard; the scheduler's small HTTP endpoint (health, metrics) takes a
    # free loopback port rather than 8787, so that two sweeps at once do not clash
    try:
        with dask.config.set(WORKER_DASK_CONFIG):
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                   host="127.0.0.1", dashboard_address=None,
                                   scheduler_kwargs={"dashboard": False,
                                                     "dashboard_address": "127.0.0.1:0"},
                                   env=dict(WORKER_ENVIRONMENT))
    except Exception as exc:
        # Dask says only "Nanny failed to start."; name the usual cause when it is
        # this one, and leave every other failure as it was
        where = _unguarded_main_call()
        if where is None:
            raise
        script, line = where
        raise MissingMainGuard(f"the workers of the local cluster could not start (Dask: "
                               f"{exc}) because {_where(script, line)} starts the cluster "
                               f"from the top level of the script, outside "
                               f"`if __name__ == \"__main__\":`; {_GUARD_ADVICE}",
                               script=script, line=line) from None
    return Client(cluster)


def _importing_main_in_a_child():
    """Whether this is a new process of ``multiprocessing`` still importing the
    main script (the state in which multiprocessing itself refuses to start
    processes, "before the current process has finished its bootstrapping
    phase")."""
    return bool(getattr(multiprocessing.current_process(), "_inheriting", False))


def _unguarded_main_call():
    """``(script, line)`` when this call comes from the top level of the main
    script, outside any ``if`` that tests ``__name__``, and the workers re-import
    that script (every start method but ``fork``); ``None`` otherwise (a notebook,
    ``python -c``, a call under the guard or from a function called under it)."""
    import dask

    if dask.config.get("distributed.worker.multiprocessing-method", "spawn") == "fork":
        return None
    main = sys.modules.get("__main__")
    if getattr(main, "__file__", None) is None and getattr(main, "__spec__", None) is None:
        return None   # nothing that a worker would import
    where = _top_level_call(main)
    if where is None:
        return None
    script, line = where
    try:
        tree = ast.parse("".join(linecache.getlines(script)))
    except (SyntaxError, ValueError):
        return None
    if not tree.body:
        return None   # the source is not at hand
    for node in ast.walk(tree):
        if (isinstance(node, ast.If) and node.lineno <= line <= node.end_lineno
                and any(isinstance(n, ast.Name) and n.id == "__name__"
                        for n in ast.walk(node.test))):
            return None
    return script, line


def _top_level_call(module):
    """``(file, line)`` of the statement of ``module``'s top level that is running
    now and led to this call; ``None`` when none is running."""
    if module is None:
        return None
    frame = sys._getframe(1)
    while frame is not None and not (frame.f_globals is vars(module)
                                     and frame.f_code.co_name == "<module>"):
        frame = frame.f_back
    return None if frame is None else (frame.f_code.co_filename, frame.f_lineno)


def _where(script, line):
    return "the main script" if script is None else f"line {line} of {script}"


@contextlib.contextmanager
def _without_warnings(logger):
    """Leave out the records below ERROR of ``logger`` (a name) inside a ``with``."""
    log = logging.getLogger(logger)

    def keep(record):
        return record.levelno >= logging.ERROR
    log.addFilter(keep)
    try:
        yield
    finally:
        log.removeFilter(keep)


def _interrupted(out_dir, n, finished):
    """The line that :meth:`Ensemble.run` prints when Ctrl-C stops it."""
    if out_dir is None:
        return (f"orbits ensemble: interrupted after {finished} of {n} runs; without "
                f"out_dir nothing is kept, and the same call starts again from the first")
    saved = _saved_runs(out_dir / INDEX_FILE, n)
    return (f"orbits ensemble: interrupted; {saved} of {n} runs are saved in {out_dir}, "
            f"and the same call (with this out_dir) continues with the other {n - saved}")


# -- one run (on a worker) -------------------------------------------------------------

class _Spec:
    """What every run of a sweep shares; small, so that it travels with each task."""

    def __init__(self, until, outputs, elements):
        self.until = until
        self.outputs = outputs
        self.elements = elements


#: A sweep's runs go to the workers in tasks of about this many seconds: the
#: first ones alone, then as many together as the runs so far say take this
#: long.  Each task costs the scheduler, the worker and this process a few
#: milliseconds, which on runs of tens of milliseconds would take a third of
#: the machine (measured: 7.5 ms a run of a 512-run MEGNO map, against 1.1 ms
#: for a process pool); runs of seconds or more still go one a task, so
#: that an ``out_dir`` index loses nothing to grouping.
TASK_SECONDS = 0.5

#: The most runs one task takes, and the tasks kept queued per worker.
CHUNK_MAX = 64
QUEUED_PER_WORKER = 2

#: What a task costs beyond its runs' ``wall_time_s`` (building, elements,
#: the row), seconds a run, for sizing the tasks.
RUN_OVERHEAD_S = 2e-3


class _Chunks:
    """The runs still to submit, cut into tasks (lists of run numbers) sized
    from the time the finished runs took (see :data:`TASK_SECONDS`); with
    ``batch``, tasks of whole batches."""

    def __init__(self, todo, workers, batch=None):
        self.todo = list(todo)
        self.workers = workers
        self.seconds = 0.0
        self.runs = 0
        self.unit = batch or 1

    def first(self):
        # one run (one batch) a task until some have finished
        out = []
        while self.todo and len(out) < QUEUED_PER_WORKER * self.workers:
            out.append(self.todo[:self.unit])
            self.todo = self.todo[self.unit:]
        return out

    def took(self, rows):
        for row in rows:
            wall = row.get("wall_time_s", 0.0)
            self.seconds += (wall if math.isfinite(wall) else 0.0) + RUN_OVERHEAD_S
            self.runs += 1

    def next(self, queued):
        """Tasks to submit while ``queued`` are waiting or running."""
        out = []
        while self.todo and queued + len(out) < QUEUED_PER_WORKER * self.workers:
            per_run = self.seconds / self.runs if self.runs else TASK_SECONDS
            size = int(TASK_SECONDS / per_run) if per_run > 0 else CHUNK_MAX
            # the last tasks smaller, so that the workers finish together
            share = len(self.todo) // (QUEUED_PER_WORKER * self.workers)
            size = max(1, min(size, CHUNK_MAX, share))
            size = -(-size // self.unit) * self.unit
            chunk, self.todo = self.todo[:size], self.todo[size:]
            out.append(chunk)
        return out


def run_chunk(build, params, indices, spec, paths, batch=None):
    """:func:`run_one` for several runs in one task: ``(rows, error)``, the rows
    of the runs done and the exception that stopped the task (None), so that
    the rows finished before an error are kept.  With ``batch``, the runs
    that can are integrated that many at a time (:mod:`orbits._batch`)."""
    if batch is not None:
        from ._batch import run_batched
        return run_batched(build, params, indices, spec, paths, batch)
    rows = []
    for p, i, path in zip(params, indices, paths):
        try:
            rows.append(run_one(build, p, i, spec, path))
        except Exception as exc:     # build's own errors stop the sweep, as in a loop
            return rows, exc
    return rows, None


def _check_parameter_names(params, i):
    """Refuse a parameter whose column would be a result column: the result
    would overwrite it (``run`` would even lose the rows' numbering)."""
    for k, val in params.items():
        col = _column(k, val.unit) if isinstance(val, u.Quantity) else k
        if col in _RESULT_COLUMNS or any(col == p or col.startswith(p + "_")
                                         for p in _RESULT_PREFIXES):
            named = f"{k!r}" if col == k else f"{k!r} (the column {col!r})"
            raise EnsembleOptionError(
                f"parameter set {i}: the parameter {named} has the name of a column "
                f"of the results, which would overwrite it; give it another name")


def _add_results(row, results):
    """``row`` (the run number and parameters) with the run's ``results``; a
    parameter whose name a result takes (a body's final elements,
    ``<body>_e``, above all) stops the sweep rather than lose its values."""
    clash = [k for k in results if k in row]
    if clash:
        raise EnsembleOptionError(
            f"the parameter {clash[0]!r} has the name of a column of the results of "
            f"run {row['run']} (the final elements of a body are '<body>_a_<unit>', "
            f"'<body>_e' and '<body>_inc_rad'), which would overwrite it; give the "
            f"parameter another name")
    row.update(results)
    return row


def run_one(build, params, index, spec, path=None):
    """Build and run one simulation; return its row (a dict).  Runs on a worker.

    Failures of the run become its outcome; an :class:`~orbits.errors.OrbitsError`
    from ``build`` is the outcome ``"invalid"``.
    """
    _sync_numba_config()
    row = _parameter_row(params, index)
    loaded0 = _cache_loads()
    with _CompileRecorder() as log:
        try:
            sim = build(**params)
            outcome, exc, wall, result = _advance(sim, spec, path)
        except OrbitsError as err:     # parameters that make no simulation
            return _invalid_row(row, err, _worker_fields(loaded0, log))
    return _run_row(row, sim, spec, path, outcome, exc, wall, result,
                    lambda: _worker_fields(loaded0, log))


def _parameter_row(params, index):
    """A row's run number and parameter columns."""
    row = {"run": index}
    for k, val in params.items():
        if isinstance(val, u.Quantity):
            row[_column(k, val.unit)] = float(val.value)
        else:
            row[k] = _plain(val)
    return row


def _invalid_row(row, err, worker):
    """The row of a run whose parameters made no simulation (``err``)."""
    return _add_results(row, dict(
        outcome="invalid", message=str(err), stop_bodies="", steps=0,
        energy_error_max=math.nan, angular_momentum_error_max=math.nan,
        wall_time_s=0.0, **worker, file=""))


def _run_row(row, sim, spec, path, outcome, exc, wall, result, worker):
    """The row of a run that ran (``worker()``: where, and its kernels)."""
    out = {"outcome": outcome}
    out["message"] = "" if exc is None else str(exc)
    out["stop_bodies"] = ",".join(getattr(exc, "bodies", ()) or ())
    units = sim.units
    t_end = sim.time_value if exc is None or exc.time is None else exc.time
    out[_column("t_stop", units.time)] = _value(t_end, units.time)
    out["steps"] = sim.steps
    if path is not None:   # the result of a run to a file holds only its last output
        from .io.h5md import load
        result = load(path)
    e = result.max_energy_error() if result is not None else None
    lerr = result.max_angular_momentum_error() if result is not None else None
    out["energy_error_max"] = math.nan if e is None else e
    out["angular_momentum_error_max"] = math.nan if lerr is None else lerr
    out.update(_chaos_indicators(sim, result))
    if result is not None and getattr(result, "collisions", None) is not None:
        # collisions the run resolved (merged or bounced) and the bodies left
        out["collisions"] = len(result.collisions)
        out["bodies_left"] = len(sim.bodies.names)
    out.update(_final_elements(sim, spec.elements))
    out["wall_time_s"] = wall
    out.update(worker())
    out["file"] = "" if path is None else path.name
    return _add_results(row, out)


_NUMBA_SYNCED = []


def _sync_numba_config():
    """Keep this task to the numba threads its environment allows.

    On a worker whose script imported orbits at the top, numba read its
    environment before the nanny set the worker's (``NUMBA_NUM_THREADS=1``):
    its thread pool has the machine's size, fixed at import.  Re-read the
    environment now, before the pool starts, or the first compilation after it
    started would fail on the changed setting; and use no more threads than the
    environment says.
    """
    from numba.core import config
    from numba.np.ufunc import parallel
    if not _NUMBA_SYNCED:      # reading the environment costs 0.2 ms: once a process
        _NUMBA_SYNCED.append(True)
        try:
            config.reload_config()
        except RuntimeError:   # the pool already runs with another size: leave it
            return
    if config.NUMBA_NUM_THREADS < parallel.NUM_THREADS:
        import numba
        numba.set_num_threads(config.NUMBA_NUM_THREADS)   # this thread's share


def _advance(sim, spec, path):
    wall0 = _time.perf_counter()
    try:
        result = sim.run(spec.until, outputs=spec.outputs, progress=False, output=path,
                         overwrite=True)
    except RunError as exc:
        return _outcome(exc), exc, _time.perf_counter() - wall0, exc.result
    return "completed", None, _time.perf_counter() - wall0, result


def _outcome(exc):
    """The exception's class name in lower case with hyphens: ``CloseEncounter``
    -> ``"close-encounter"``, so that every kind of failure has its own outcome."""
    return _outcome_name(type(exc))


def _outcome_name(cls):
    name = cls.__name__
    return "".join(("-" + ch.lower()) if ch.isupper() and k else ch.lower()
                   for k, ch in enumerate(name))


def _chaos_indicators(sim, result):
    """The chaos monitors' last values in ``result`` (NaN where it has none), as
    ``{"megno": ..., "lyapunov_per_<time unit>": ..., "fli": ...}`` for the
    monitors ``sim`` follows."""
    from .monitors import CHAOS_MONITORS
    out = {}
    for name in CHAOS_MONITORS:
        if name not in sim.monitors:
            continue
        series = None if result is None else getattr(result, name, None)
        if name == "lyapunov":
            time = sim.units.time
            value = (math.nan if series is None or not len(series)
                     else float(series[-1].to_value(time ** -1)))
            out[_lyapunov_column(time)] = value
        else:
            out[name] = math.nan if series is None or not len(series) else float(series[-1])
    return out


def _lyapunov_column(time):
    """``lyapunov_per_<time unit>``: the column of the Lyapunov estimate, in 1 / ``time``."""
    return _column("lyapunov_per", time)


def _final_elements(sim, names):
    bodies = sim.bodies
    m = bodies._m
    central = bodies.names[int(np.argmax(m))]
    if names is None:
        names = ([b for b in bodies.names if b != central]
                 if len(bodies) <= ELEMENTS_MAX_BODIES else [])
    out = {}
    for b in names:
        # BodySet.elements' numbers without its Quantities
        try:
            el, status = bodies._element_values(b, central)
        except OrbitsError:
            status = 1
        vals = (float(el[0]), float(el[1]), float(el[2])) if status == 0 else (math.nan,) * 3
        out[_column(f"{b}_a", bodies.units.length)] = vals[0]
        out[f"{b}_e"] = vals[1]
        out[f"{b}_inc_rad"] = vals[2]
    return out


# kernel bookkeeping: what this task had to compile or load before it could run

_DISPATCHERS = [None, ()]


def _dispatchers():
    # walked again only when a module was imported or a loop specialised
    # since the last walk (a walk of sys.modules costs milliseconds, which
    # every member of a sweep would pay twice)
    import sys

    from numba.core.dispatcher import Dispatcher

    from ._kernels import _jit
    state = (len(sys.modules), len(_jit._SPECIALISED))
    if _DISPATCHERS[0] == state:
        return _DISPATCHERS[1]
    found = [d for d in list(_jit._SPECIALISED.values()) if isinstance(d, Dispatcher)]
    for name, mod in list(sys.modules.items()):
        if name.startswith("orbits._kernels") and mod is not None:
            found.extend(d for d in vars(mod).values() if isinstance(d, Dispatcher))
    found = list({id(d): d for d in found}.values())
    # the dispatchers' own counters, which they keep for their lives: their
    # public ``stats`` builds a record and a cache path on every call, a
    # millisecond over the package's dispatchers, twice for every run
    counters = [getattr(d, "_cache_hits", None) for d in found]
    _DISPATCHERS[:] = [state, ([c for c in counters if c is not None],
                               [d for c, d in zip(counters, found) if c is None])]
    return _DISPATCHERS[1]


def _cache_loads():
    """Compiled functions of the package loaded from numba's disk cache so far."""
    counters, others = _dispatchers()
    # a counter holds one key for each signature loaded, counted once: a
    # dispatcher loads a signature only when it has none for it.  len() in
    # C (0.01 ms for the package's 225 dispatchers) instead of summing the
    # counts in Python (0.2 ms, twice a run)
    return (sum(map(len, counters))
            + sum(sum(d.stats.cache_hits.values()) for d in others))


class _CompileRecorder:
    """Counts numba compilations (not cache loads) inside a ``with``."""

    def __enter__(self):
        from numba.core import event
        self._ctx = event.install_recorder("numba:compile")
        self.recorder = self._ctx.__enter__()
        return self

    def __exit__(self, *exc):
        return self._ctx.__exit__(*exc)

    @property
    def compiled(self):
        return sum(1 for _, ev in self.recorder.buffer if ev.is_start)


def _worker_fields(loaded0, log):
    compiled = log.compiled
    return {"worker": f"{socket.gethostname()}:{os.getpid()}",
            "kernels_compiled": compiled,
            "kernels_loaded": _cache_loads() - loaded0}


# -- perturbed copies of one simulation --------------------------------------------------

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
        from .simulation import Simulation
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


# -- output directory ---------------------------------------------------------------------

def _open_out_dir(out_dir, fingerprint, parameters):
    """Create ``out_dir`` or check it holds this sweep; the rows already finished.

    The sweep is this one if ``sweep.json`` says so and every row of the index
    has the parameters of this sweep's run of its number; without a
    ``sweep.json`` (deleted), the rows alone decide.
    """
    out_dir.mkdir(parents=True, exist_ok=True)
    sweep = out_dir / SWEEP_FILE
    stored = _stored_fingerprint(sweep) if sweep.exists() else None
    if stored is not None and stored != fingerprint:
        raise EnsembleOptionError(f"{out_dir} holds another sweep (different build, "
                                  f"parameters, until, outputs or elements); use a new "
                                  f"out_dir")
    index = out_dir / INDEX_FILE
    rows = {}
    if index.exists():
        frame = _read_index(index, len(parameters))
        for rec in frame.to_dict(orient="records"):
            rec = {k: _from_csv(k, val) for k, val in rec.items()}
            rows[int(rec["run"])] = rec
        _check_rows_are_of(rows, parameters, out_dir)
    if stored is None:
        _write_whole(sweep, json.dumps({"fingerprint": fingerprint}) + "\n")
    return rows


def _stored_fingerprint(sweep):
    """The fingerprint ``sweep.json`` records; a file that holds none is refused
    by name rather than trusted or overwritten."""
    try:
        stored = json.loads(sweep.read_bytes().decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as exc:
        stored = exc
    if not (isinstance(stored, dict) and isinstance(stored.get("fingerprint"), str)):
        raise EnsembleOptionError(
            f"{sweep} does not record a sweep (expected a JSON object with its "
            f"'fingerprint'); delete it to resume the sweep whose rows {INDEX_FILE} "
            f"holds, which are checked against the parameters, or use a new out_dir")
    return stored["fingerprint"]


def _check_rows_are_of(rows, parameters, out_dir):
    """Refuse rows of another sweep: every row must hold the parameters of the
    run of its number, and no parameter this sweep does not have."""
    expected = [_parameter_row(p, i) for i, p in enumerate(parameters)]
    columns = {k for row in expected for k in row}
    for i, rec in rows.items():
        want = expected[i]
        for col in sorted(set(rec) | set(want)):
            if col == "run" or (col not in columns and _is_result_column(col)):
                continue
            got = rec.get(col, _ABSENT)
            if col not in want and _is_empty(got):
                continue
            if not _same_value(want.get(col, _ABSENT), got):
                raise EnsembleOptionError(
                    f"{out_dir} holds another sweep: in its {INDEX_FILE}, run {i} has "
                    f"{col} = {_shown(got)}, where this sweep's run {i} has "
                    f"{col} = {_shown(want.get(col, _ABSENT))}; use a new out_dir")


_ABSENT = type("_Absent", (), {"__repr__": lambda self: "(no such column)"})()


def _shown(value):
    return "(none)" if value is _ABSENT else repr(value)


def _is_empty(value):
    return value is None or value == "" or (isinstance(value, float) and math.isnan(value))


def _same_value(want, got):
    """Whether ``got``, a parameter as read back from the index, is ``want``."""
    if want is _ABSENT or got is _ABSENT:
        return want is got
    if want is None or _is_empty(want):
        return _is_empty(got)
    if isinstance(want, bool) or isinstance(got, bool):
        return str(want) == str(got)
    if isinstance(want, numbers.Real) or isinstance(got, numbers.Real):
        # a number, or text that pandas reads as one ("5")
        try:
            a, b = float(want), float(got)
        except (TypeError, ValueError):
            return False
        return a == b or (math.isnan(a) and math.isnan(b))
    return str(want) == str(got)


def _is_result_column(name):
    """Whether ``name`` is, or has the form of, a column of a run's results."""
    return (name in _RESULT_COLUMNS
            or any(name == p or name.startswith(p + "_") for p in _RESULT_PREFIXES)
            or name.endswith(("_e", "_inc_rad", "_a")) or "_a_" in name)


def _index_records(data, n_runs):
    """What an index's bytes hold: ``(header, header_raw, good, dropped)``, the
    header's fields and text, ``(fields, raw text)`` of each complete row, and
    how many rows were not complete (see :func:`_read_index`)."""
    # every write ends a row with "\n": whatever follows the last one is a cut-off row
    end = data.rfind(b"\n") + 1
    records = list(_csv_records(data[:end].decode("utf-8", errors="replace")))
    dropped = int(end < len(data))
    header, header_raw = records.pop(0) if records else (None, "")
    if header is None or "run" not in header or "outcome" not in header:
        header, dropped = None, dropped + len(records)   # without a header no row counts
        records = []
    good = []
    for fields, raw in records:
        if fields is not None and _complete_row(dict(zip(header, fields)), len(fields),
                                                len(header), n_runs):
            good.append((fields, raw))
        else:
            dropped += 1
    return header, header_raw, good, dropped


def _saved_runs(index, n_runs):
    """How many runs ``index`` holds complete rows of (read only)."""
    try:
        header, _, good, _ = _index_records(index.read_bytes(), n_runs)
    except OSError:
        return 0
    if header is None:
        return 0
    at = header.index("run")
    return len({float(fields[at]) for fields, _ in good})


def _read_index(index, n_runs):
    """The complete rows of ``index`` as a DataFrame.

    A row counts only if it ends with its newline, parses as CSV into as many
    fields as the header has, names a run of this sweep and a known outcome, and
    has numbers where numbers belong.  Anything else (the half-written line a
    crash leaves, above all) is dropped with a warning, and the file is rewritten
    without it, so that its runs are done again and the next row starts on a
    line of its own.
    """
    import pandas as pd

    header, header_raw, good, dropped = _index_records(index.read_bytes(), n_runs)
    good = [raw for _, raw in good]
    if dropped:
        warnings.warn(f"{index}: dropped {dropped} incomplete or unreadable row(s) "
                      f"(a write cut off); their runs will be run again", stacklevel=4)
        if header is None:
            index.unlink()
        else:
            _write_whole(index, header_raw + "".join(good))
    if header is None:
        return pd.DataFrame({"run": []})
    return _parse_index(header_raw + "".join(good))


def _parse_index(text):
    import pandas as pd
    # floats come back bit for bit: pandas 3 parses them exactly by default,
    # pandas 2 only when asked for "round_trip"
    exact = {} if int(pd.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}
    frame = pd.read_csv(io.StringIO(text), keep_default_na=False, na_values=[""], **exact)
    # text cells as they were before _to_csv made them safe for a spreadsheet
    frame = frame.rename(columns=read_cell)
    for c in frame.columns:
        if frame[c].dtype.kind == "O":
            frame[c] = frame[c].map(lambda v: read_cell(v) if isinstance(v, str) else v)
    return frame


def _csv_records(text):
    """``(fields, raw text)`` of each CSV record of ``text``; ``fields`` is None
    for a record that does not parse (an unterminated quote, above all)."""
    raw = []

    def lines():
        for line in io.StringIO(text, newline=""):
            raw.append(line)
            yield line

    reader = csv.reader(lines(), strict=True)
    while True:
        try:
            fields = next(reader)
        except StopIteration:
            return
        except csv.Error:
            fields = None
        yield fields, "".join(raw)
        raw.clear()


_INTEGER_COLUMNS = ("run", "steps", "kernels_compiled", "kernels_loaded")
_REAL_COLUMNS = ("energy_error_max", "angular_momentum_error_max", "wall_time_s", "megno",
                 "fli")


def _complete_row(row, n_fields, n_header, n_runs):
    if n_fields != n_header:
        return False
    try:
        if not 0 <= float(row["run"]) < n_runs:
            return False
        for key, val in row.items():
            if key in _INTEGER_COLUMNS and not float(val).is_integer():
                return False
            if (key in _REAL_COLUMNS or key.startswith(("t_stop", "lyapunov_per"))) \
                    and val != "":
                float(val)
    except ValueError:
        return False
    return row["outcome"] in _known_outcomes()


def _known_outcomes():
    names, classes = {"completed", "invalid"}, [RunError]
    while classes:
        cls = classes.pop()
        names.add(_outcome_name(cls))
        classes.extend(cls.__subclasses__())
    return names


_TEXT_COLUMNS = ("outcome", "message", "stop_bodies", "worker", "file")


def _from_csv(key, val):
    if key in _TEXT_COLUMNS:
        return "" if isinstance(val, float) and math.isnan(val) else str(val)
    return val.item() if isinstance(val, np.generic) else val


def _finish(row, rows, out_dir):
    rows[row["run"]] = row
    if out_dir is None:
        return
    import pandas as pd

    index = out_dir / INDEX_FILE
    frame = pd.DataFrame([row])
    header = _index_header(index)
    if header is not None and set(frame.columns) <= set(header):
        _append_whole(index, _to_csv(frame.reindex(columns=header), header=False))
        return
    if header is not None:
        # keep one header: a row with columns the file lacks rewrites the file (its
        # rows are all complete: _open_out_dir kept only those, and rows are
        # appended whole)
        frame = pd.concat([_parse_index(index.read_text(encoding="utf-8")), frame],
                          ignore_index=True)
    _write_whole(index, _to_csv(frame, header=True))


def _index_header(index):
    try:
        with open(index, encoding="utf-8", newline="") as f:
            first = f.readline()
    except FileNotFoundError:
        return None
    header = next(csv.reader([first]), None) if first.endswith("\n") else None
    return None if header is None else [read_cell(c) for c in header]


def _to_csv(frame, header):
    """``frame`` as CSV rows, every text cell (a header, a name, a message) safe
    to open in a spreadsheet (``orbits._csvcells``); numbers as they are."""
    frame = frame.rename(columns=safe_cell)
    for c in frame.columns:
        if frame[c].dtype.kind == "O":
            frame[c] = frame[c].map(lambda v: safe_cell(v) if isinstance(v, str) else v)
    return frame.to_csv(index=False, header=header, lineterminator="\n")


def _append_whole(path, text):
    """Append ``text`` (whole lines) in one write and make it durable before the
    next run is counted: a crash leaves the file without the line or with a
    line that lacks its newline, which :func:`_read_index` drops."""
    data = memoryview(text.encode("utf-8"))
    fd = os.open(path, os.O_WRONLY | os.O_APPEND | getattr(os, "O_BINARY", 0))
    try:
        while data:   # one write for a regular file; the loop is for a short write
            data = data[os.write(fd, data):]
        os.fsync(fd)
    finally:
        os.close(fd)


def _write_whole(path, text):
    """Replace ``path`` by ``text`` at once: written to a temporary file, synced,
    then renamed over it, so that a crash leaves the old file or the new one."""
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "w", encoding="utf-8", newline="") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


_FIRST = ("outcome", "message", "stop_bodies")
_MIDDLE = ("steps", "energy_error_max", "angular_momentum_error_max")
_LAST = ("wall_time_s", "worker", "kernels_compiled", "kernels_loaded", "file")

#: Columns of the results whatever the bodies (those of the elements,
#: ``<body>_a_<unit>``, ``<body>_e``, ``<body>_inc_rad``, depend on them), and
#: the beginnings of those that end with a unit (``t_stop_day``)
_RESULT_COLUMNS = frozenset(("run", *_FIRST, *_MIDDLE, "megno", "fli", "collisions",
                             "bodies_left", *_LAST))
_RESULT_PREFIXES = ("t_stop", "lyapunov_per")


def _column_order(columns, parameters):
    """run, parameters, outcome, stop time, errors, chaos indicators, elements
    (sorted), where it ran: the same order whether the rows were computed now or
    read from the index."""
    columns = list(columns)
    params = []
    for p in parameters:
        for k, val in p.items():
            name = _column(k, val.unit) if isinstance(val, u.Quantity) else k
            if name not in params:
                params.append(name)
    t_stop = sorted(c for c in columns if c.startswith("t_stop"))
    chaos = ["megno", *sorted(c for c in columns if c.startswith("lyapunov_per")), "fli"]
    fixed = ["run", *params, *_FIRST, *t_stop, *_MIDDLE, *chaos]
    elements = sorted(c for c in columns if c not in fixed and c not in _LAST)
    return [c for c in (*fixed, *elements, *_LAST) if c in columns]


def _path(out_dir, i):
    return None if out_dir is None else out_dir / f"run-{i:05d}.h5"


# -- small helpers ----------------------------------------------------------------------

def _check_batch(batch):
    if batch is None:
        return None
    if isinstance(batch, bool) or not isinstance(batch, numbers.Integral) or batch < 1:
        raise EnsembleOptionError(f"batch must be None or a whole number of systems per "
                                  f"batch >= 1, got {batch!r}")
    return int(batch)


def _bar(total, progress):
    from tqdm.auto import tqdm
    return tqdm(total=total, unit="run", desc="orbits ensemble", disable=progress is False,
                delay=0 if progress else PROGRESS_DELAY, leave=progress is True)


def _frame_attrs(spec, frame):
    return {"until": str(spec.until), "outputs": spec.outputs,
            "elements_primary": "the most massive body"}


def _plain(val):
    if isinstance(val, np.generic):
        return val.item()
    return val


def _column(name, unit):
    """``name_<unit>``, e.g. ``t_stop_day``, ``a_au``; just ``name`` without a unit."""
    return f"{name}{_unit_suffix(u.Unit(unit))}"


@functools.lru_cache(maxsize=256)
def _unit_suffix(unit):
    # "_<unit>" of a column name (a unit's string costs 20 us, several a run)
    s = unit.to_string()
    s = {"d": "day"}.get(s, s.lower())
    s = "".join(ch if ch.isalnum() else "_" for ch in s)
    return f"_{s}" if s else ""


def _value(t, unit):
    if isinstance(t, u.Quantity):
        return float(t.to_value(unit))
    return float(t)


def _describe(build):
    if isinstance(build, _Perturbation):
        return "perturbed copies of a simulation"
    return getattr(build, "__qualname__", type(build).__name__)
