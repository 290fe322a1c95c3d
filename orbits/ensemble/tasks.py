"""A sweep's tasks: how its runs are cut into Dask tasks (:class:`_Chunks`,
in the process that runs the sweep), and what a task does on a worker
(:func:`run_chunk`: its runs one by one, or in batches).
"""

import math

from .batch import run_batched
from .worker import run_one

__all__ = ["run_chunk", "TASK_SECONDS", "CHUNK_MAX", "QUEUED_PER_WORKER", "RUN_OVERHEAD_S"]


#: A sweep's runs go to the workers in tasks of about this many seconds: the
#: first ones alone, then as many together as the runs so far say take this
#: long.  Each task costs the scheduler, the worker and this process a few
#: milliseconds, which on runs of tens of milliseconds would take a third of
#: the machine (benchmarks/RESULTS.md); runs of seconds or more still go one a task, so
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
    """:func:`~orbits.ensemble.worker.run_one` for several runs in one task:
    ``(rows, error)``, the rows of the runs done and the exception that stopped
    the task (None), so that the rows finished before an error are kept.  With
    ``batch``, the runs that can are integrated that many at a time
    (:mod:`orbits.ensemble.batch`)."""
    if batch is not None:
        return run_batched(build, params, indices, spec, paths, batch)
    rows = []
    for p, i, path in zip(params, indices, paths):
        try:
            rows.append(run_one(build, p, i, spec, path))
        except Exception as exc:     # build's own errors stop the sweep, as in a loop
            return rows, exc
    return rows, None
