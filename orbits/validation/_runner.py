"""Run the report's measurements in parallel on this machine's cores.

A :class:`Task` names a module-level function and its keyword arguments, so
that it travels to a worker as a few bytes and imports what it needs there.
:func:`run_tasks` runs a list of them on a Dask cluster (the ensemble
machinery of :mod:`orbits.ensemble`: one single-threaded process per core,
kernels loaded from numba's cache once per worker), or serially with one
worker, and returns their rows in the order given.  Each task times its own
run, on a core of its own, so wall times are those of one core whatever the
number of workers.

A task that needs the whole machine (one that starts processes of its own
and times them, such as a sweep against a process pool) is marked
``exclusive``: it runs after all the others, in this process, with nothing
else running, and is given the pool's size as ``workers=``.
"""

import importlib
import os
import time
from typing import NamedTuple

from tqdm.auto import tqdm

from ..ensemble import local_cluster
from ..ensemble.compiles import _sync_numba_config

__all__ = ["Task", "run_tasks", "Pool"]


class Task(NamedTuple):
    """``module.function(**kwargs)``: one measurement.  ``cost`` is a rough
    relative run time, used to start the longest first."""

    function: str          # "orbits.validation.accuracy:measure"
    kwargs: dict
    cost: float = 1.0
    # runs alone, after the others, in this process, with workers=<pool size>
    exclusive: bool = False


def _call(task):
    _sync_numba_config()
    module, name = task.function.split(":")
    func = getattr(importlib.import_module(module), name)
    t0 = time.perf_counter()
    row = func(**task.kwargs)
    if isinstance(row, dict):   # compilation and warm-up included: what the task cost
        row["task_seconds"] = time.perf_counter() - t0
    return row


class Pool:
    """Where the tasks run: a Dask client (given, or a local cluster of
    ``n_workers`` made on first use and closed by :meth:`close`), or this
    process when ``n_workers == 1`` and no client is given."""

    def __init__(self, client=None, n_workers=None):
        self._client = client
        self._own = False
        self.n_workers = (len(client.scheduler_info()["workers"]) if client is not None
                          else int(n_workers or os.cpu_count() or 1))

    @property
    def serial(self):
        return self._client is None and self.n_workers == 1

    def client(self):
        if self._client is None:
            self._client = local_cluster(self.n_workers)
            self._own = True
        return self._client

    def close(self):
        if self._own and self._client is not None:
            cluster = self._client.cluster
            self._client.close()
            cluster.close()
            self._client = None
            self._own = False

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def run_tasks(tasks, pool, progress=True, desc="measuring"):
    """Run ``tasks`` (a list of :class:`Task`) and return their rows in order."""
    tasks = list(tasks)
    order = sorted(range(len(tasks)), key=lambda i: -tasks[i].cost)
    shared = [i for i in order if not tasks[i].exclusive]
    alone = [i for i in order if tasks[i].exclusive]
    rows = [None] * len(tasks)
    bar = tqdm(total=len(tasks), desc=desc, disable=not progress, leave=False)
    t0 = time.perf_counter()
    try:
        if pool.serial or not shared:
            for i in shared:
                rows[i] = _call(tasks[i])
                bar.update(1)
        else:
            from distributed import as_completed
            client = pool.client()
            futures = {client.submit(_call, tasks[i], pure=False, key=f"{desc}-{i}-{t0}"): i
                       for i in shared}
            for fut in as_completed(futures):
                rows[futures[fut]] = fut.result()
                bar.update(1)
        for i in alone:     # the pool's workers are idle by now
            task = tasks[i]
            rows[i] = _call(task._replace(kwargs={**task.kwargs, "workers": pool.n_workers}))
            bar.update(1)
    finally:
        bar.close()
    return rows
