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

This module is the facade; each part of a sweep has a module of its own:
:mod:`~orbits.ensemble.cluster` (the local Dask cluster and its workers'
settings, :data:`~orbits.ensemble.cluster.WORKER_ENVIRONMENT` and
:data:`~orbits.ensemble.cluster.WORKER_DASK_CONFIG`),
:mod:`~orbits.ensemble.guard` (a script without the ``__main__`` guard),
:mod:`~orbits.ensemble.tasks` (runs cut into tasks),
:mod:`~orbits.ensemble.batch` (runs integrated together),
:mod:`~orbits.ensemble.worker` (one run and its row,
:data:`~orbits.ensemble.worker.ELEMENTS_MAX_BODIES`),
:mod:`~orbits.ensemble.compiles` (numba on a worker),
:mod:`~orbits.ensemble.index` (the record in ``out_dir``,
:data:`~orbits.ensemble.index.INDEX_FILE` and
:data:`~orbits.ensemble.index.SWEEP_FILE`),
:mod:`~orbits.ensemble.perturbation` (perturbed copies),
:mod:`~orbits.ensemble.table` (the columns) and
:mod:`~orbits.ensemble.errors`.  Each imports only modules listed after it.
"""

import math
import numbers
import pathlib
import sys

import numpy as np
from tqdm.auto import tqdm

from .cluster import WORKER_DASK_CONFIG, WORKER_ENVIRONMENT, _without_warnings, local_cluster
from .errors import EnsembleOptionError, MissingMainGuard
from .index import (INDEX_FILE, SWEEP_FILE, _describe, _finish, _fingerprint, _open_out_dir,
                    _path, _saved_runs)
from .perturbation import _Perturbation
from .table import _check_parameter_names, _column_order, _frame_attrs, _plain
from .tasks import CHUNK_MAX, _Chunks, run_chunk
from .worker import ELEMENTS_MAX_BODIES, _Spec, run_one

__all__ = ["Ensemble", "local_cluster", "MissingMainGuard", "EnsembleOptionError",
           "INDEX_FILE", "SWEEP_FILE", "ELEMENTS_MAX_BODIES", "PROGRESS_DELAY",
           "WORKER_ENVIRONMENT", "WORKER_DASK_CONFIG"]

#: The sweep's progress bar appears after this many seconds, so short sweeps stay quiet.
PROGRESS_DELAY = 3.0


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
            most massive, when there are at most
            :data:`~orbits.ensemble.worker.ELEMENTS_MAX_BODIES`.
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
        return _fingerprint(self.build, self.parameters, spec)


def _interrupted(out_dir, n, finished):
    """The line that :meth:`Ensemble.run` prints when Ctrl-C stops it."""
    if out_dir is None:
        return (f"orbits ensemble: interrupted after {finished} of {n} runs; without "
                f"out_dir nothing is kept, and the same call starts again from the first")
    saved = _saved_runs(out_dir / INDEX_FILE, n)
    return (f"orbits ensemble: interrupted; {saved} of {n} runs are saved in {out_dir}, "
            f"and the same call (with this out_dir) continues with the other {n - saved}")


def _check_batch(batch):
    if batch is None:
        return None
    if isinstance(batch, bool) or not isinstance(batch, numbers.Integral) or batch < 1:
        raise EnsembleOptionError(f"batch must be None or a whole number of systems per "
                                  f"batch >= 1, got {batch!r}")
    return int(batch)


def _bar(total, progress):
    return tqdm(total=total, unit="run", desc="orbits ensemble", disable=progress is False,
                delay=0 if progress else PROGRESS_DELAY, leave=progress is True)
