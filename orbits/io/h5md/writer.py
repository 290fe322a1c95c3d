"""The writer: :class:`FileRecorder` streams one run's outputs, monitors and
restart checkpoints into its file.

Crash safety
------------
The file is written in HDF5's single-writer/multiple-reader (SWMR) mode, which
keeps it consistent on disk whenever the writer stops, and outputs are flushed
in blocks.  A checkpoint goes into the slot not holding the last one, is
flushed, and only then is ``count`` advanced and flushed: the slot ``count``
names is always complete.  A run killed in the middle (even by SIGKILL)
leaves a file that :func:`orbits.load` and :func:`orbits.io.describe` open, and that
:meth:`orbits.Simulation.from_file` resumes from its last checkpoint; rows
written after that checkpoint are dropped on resume and computed again, so
the resumed file ends the same as an uninterrupted one.  A file whose writer
died can be read with plain h5py as ``h5py.File(path, "r", swmr=True)``.

Every run writes a checkpoint as soon as its file is open and its first output
written, so even a run stopped before its first periodic checkpoint resumes;
:meth:`FileRecorder.checkpoint` may be called at any point between two
compiled chunks (a signal handler does).
"""

import errno
import os
import pathlib
import time as _time

import h5py
import numpy as np

from ..._kernels.invariants import MONITOR_WIDTH
from ...errors import OrbitsError
from ..._monitor_specs import WITH_ERROR
from ...monitors import monitor_fields, row_errors, row_series
from ...result import Result
from .disk import (_LOG_ROW_BYTES, _METADATA_BYTES, _NoRoom, _RESERVE_BYTES, _close_written,
                   _descriptor, _reserve, _trim, _writes)
from .errors import (OrbitsFileError, TangentShapeError, _DISK_FULL, _error_number,
                     _write_error)
from .layout import (_SLOTS, _append, _create, _datasets, _decode, _keeps_work, _padded,
                     _radii, _series_errors, _tangent_layout, _write_box, _write_rows)
from .lock import _acquire, _release

__all__ = ["FileRecorder", "CHECKPOINT_SECONDS", "BUFFER_ROWS"]

#: default wall-clock seconds between restart checkpoints
CHECKPOINT_SECONDS = 60.0
#: outputs held in memory before they are written as one block
BUFFER_ROWS = 256


#: seconds an append waits for readers that hold HDF5's lock on the file
READER_WAIT_SECONDS = 5.0


def _open_to_append(path):
    """``path`` opened to append to.  A reader that opened it without SWMR
    writing under way (plain ``h5py.File(path, "r")``, or ``swmr=True``
    between two runs) holds HDF5's lock on it, which a writer needs to open
    it: the open is tried again for :data:`READER_WAIT_SECONDS`, then
    refused with an :class:`OrbitsFileError` that says so."""
    deadline = _time.monotonic() + READER_WAIT_SECONDS
    while True:
        try:
            return h5py.File(path, "a", libver="latest")
        except OSError as exc:
            if _error_number(exc) == errno.EAGAIN and _time.monotonic() < deadline:
                _time.sleep(0.02)
                continue
            if _error_number(exc) == errno.EAGAIN:
                raise OrbitsFileError(
                    f"{path}: open in another program, which holds HDF5's lock on it "
                    f"(waited {READER_WAIT_SECONDS:g} s); close it there, or read it with "
                    f"orbits.load, which takes no lock") from None
            raise OrbitsFileError(
                f"{path}: cannot be opened to append to ({exc}); if the run writing it "
                f"was killed, finish that run first with resume() (orbits resume)") from None


class FileRecorder:
    """Streams one run's outputs into an HDF5 file (used by ``Simulation.run``).

    It holds the file's writers' lock from opening to :meth:`close`, writes a
    restart checkpoint as soon as the file is open (after the run's first
    output), and keeps the largest relative errors of the monitors over every
    output and in-loop row it passes on, so that :meth:`result`, which holds
    only the last output, still reports them for the whole run.

    A destination that is a symbolic link is refused unless ``overwrite``
    (which replaces the link).  Appending to a file whose last output is the
    simulation's present state (a run continued into its file), it does not
    write that output again.  Before each write it reserves the space the
    write may take (see :mod:`orbits.io.h5md.disk`); where the disk has none, or a
    write fails, it raises an :class:`OrbitsFileError` (whose message says
    the disk is full where it is, and what the file holds), writes nothing
    more, and its :meth:`close` only closes the file.

    Examples
    --------
    The methods' examples start from a ``sim`` and a ``rec`` made so:

    >>> import os, tempfile
    >>> from orbits.io import h5md
    >>> from orbits.records import RunPlan
    >>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    >>> plan = RunPlan(until=10.0, outputs=2, ratio=10.0, n_full=10, has_partial=False,
    ...                start_step=0)
    >>> rec = h5md.FileRecorder(path, sim, plan)   # writes the first output, a checkpoint
    >>> _ = sim.run(until=10 * u.day, outputs=2, progress=False)
    >>> rec.output(sim, final=True)                   # the last output, and a checkpoint
    >>> rec.result(sim, wall=0.0).times
    <Quantity [10.] d>
    >>> rec.close()
    >>> orbits.load(path).times
    <Quantity [ 0., 10.] d>
    """

    def __init__(self, path, sim, plan, overwrite=False, checkpoint_interval=None,
                 resume_rows=None):
        self.path = pathlib.Path(path)
        self.sim = sim
        self.plan = plan
        interval = CHECKPOINT_SECONDS if checkpoint_interval is None else checkpoint_interval
        try:
            self.interval = float(interval)
        except (TypeError, ValueError):
            raise ValueError(f"checkpoint_interval must be a number of seconds >= 0, "
                             f"got {checkpoint_interval!r}") from None
        if not self.interval >= 0:
            raise ValueError(f"checkpoint_interval must be a number of seconds >= 0, "
                             f"got {checkpoint_interval!r}")
        # the public records of the simulation: this module reads nothing else of it
        self.desc = sim.description()
        state = sim.state
        # the work of non-conservative terms is kept beside the energy
        self.work = _keeps_work(self.desc)
        self.reference = state.reference
        self.scales = state.scales
        self.inv = np.argsort(state.order)
        self.buffer = []
        self._rowbuf = None          # outputs recorded in the loop (row_buffer)
        self._checkpoint_due = False
        self.mon_buffer = []
        self.outputs_written = 0     # in this plan
        self.last = None
        self.steps0 = sim.steps
        self.forces0 = sim.force_evaluations
        self.rejected0 = sim.steps_rejected
        self.closed = False
        self.end_status = 0          # a Status code when a run ends early
        self.largest = {}            # monitor -> largest relative error seen in this plan
        self.checkpoints = 0         # written by this recorder
        self._failed = None          # the OrbitsFileError of a write that failed
        self._fd = None              # the file's descriptor, to reserve space on
        self._unflushed = 0          # bytes written since the last flush
        self._checkpoint_step = None  # the step of the file's last checkpoint
        mine = sim.output_path
        mine = mine is not None and os.path.abspath(mine) == os.path.abspath(self.path)
        if self.path.is_symlink() and not overwrite:
            raise OrbitsFileError(f"{self.path}: a symbolic link (to "
                                  f"{os.readlink(self.path)}), which orbits does not write "
                                  f"through; write to the file itself, or pass "
                                  f"overwrite=True (--force) to replace the link with a "
                                  f"new file")
        if self.path.exists() and not overwrite and not mine:
            raise OrbitsFileError(f"{self.path}: exists; pass overwrite=True (or --force) "
                                  f"to replace it")
        self.f = None
        _acquire(self.path)
        try:
            self.wall0 = _time.perf_counter()
            self.wall_before = 0.0
            if self.path.exists() and mine and not overwrite:
                self.f = _open_to_append(self.path)
                self._check_same_layout()
                # a file written before the work was kept goes on without it
                self.work = self.work and "work" in self.f["observables"]
                self.f.swmr_mode = True
                self.wall_before = self._stored_wall()
            else:
                self.f = _create(self.path, self.desc, state)
            sim.output_path = str(self.path)
            self._series = self._series_handles()
            r = self.f["restart"]
            self._restart = {name: r[name] for name in r if isinstance(r[name], h5py.Dataset)}
            self._ws = {name: r["ws"][name] for name in r["ws"]}
            self.rows = self.f["particles/bodies/position/value"].shape[0]
            self._fd = _descriptor(self.f)
            self._headroom, self._row_bytes, self._inloop_bytes = self._sizes()
            count = int(r["count"][()])
            if count:
                self._checkpoint_step = int(r["clock"][(count - 1) % _SLOTS][0])
            # the columns: the bodies when the file was made
            b = self.f["particles/bodies"]
            self.columns = _decode(b["names"][()])
            self.masses0, self.radii0 = b["mass"][()], _radii(b)[0]
            self.varying = "masses" in r
            self.last_checkpoint = _time.perf_counter()
            if resume_rows is not None:
                self.outputs_written = resume_rows
                self._largest_so_far()
            else:
                if plan.outputs > 1 and self._ends_with(sim):
                    # a run continued into its file: its first output is the
                    # file's last row, kept once
                    self.last = self._columns_of(sim.snapshot())
                    self._note_rows(self.last[4][None])
                    self.outputs_written = 1
                elif plan.outputs > 1:
                    self.output(sim)
                if not self.checkpoints:
                    self.checkpoint()       # a run stopped at once still resumes
        except BaseException as exc:
            self.closed = True
            self._shut()
            if isinstance(exc, (OSError, RuntimeError)) and not isinstance(exc, OrbitsError):
                raise _write_error(self.path, exc) from None
            raise

    def _ends_with(self, sim):
        """Whether the file's last output row is the simulation's present state."""
        if not self.rows:
            return False
        g = self.f["particles/bodies/position"]
        return (int(g["step"][self.rows - 1]) == sim.steps
                and float(g["time"][self.rows - 1]) == sim.time_value)

    def _sizes(self):
        """``(headroom, row, in-loop row)``: the bytes a write may take besides its
        data (a chunk of every time series, each of which it may start, and
        HDF5's bookkeeping), and the bytes of data of an output row and of an
        in-loop monitor row.  The checkpoints' datasets not yet given their
        storage, which a checkpoint's first write allocates, are kept in
        ``_unplaced``."""
        series, inloop = self._series
        outs = [d for dsets, _, _ in series for d in dsets]
        loops = [d for dsets in inloop.values() for d in dsets]
        fixed = list(self._restart.values()) + list(self._ws.values())
        self._unplaced = [d for d in fixed if d.id.get_storage_size() == 0]

        def row(d):
            return int(np.prod(d.shape[1:], dtype=np.int64)) * d.dtype.itemsize

        def chunk(d):
            return int(np.prod(d.chunks)) * d.dtype.itemsize
        headroom = _METADATA_BYTES + sum(map(chunk, outs + loops))
        return headroom, sum(map(row, outs)), sum(map(row, loops))

    def _reserve(self, nbytes):
        """Room on disk for a write of ``nbytes`` of data and what is still
        unflushed (:func:`_reserve`); where the file system cannot reserve,
        the writes go on unreserved."""
        self._unflushed += nbytes
        if self._fd is None:
            return
        if self._unplaced:
            self._unplaced = [d for d in self._unplaced if d.id.get_storage_size() == 0]
        need = (self._unflushed + self._headroom
                + sum(d.size * d.dtype.itemsize for d in self._unplaced))
        if not _reserve(self._fd, self.f.id.get_filesize(), need):
            self._fd = None

    def _stopped_by(self, exc):
        """The OrbitsFileError of ``exc``, a write that failed, saying what the file holds."""
        sim = self.sim
        then = f" at t = {sim.time:.10g} (step {sim.steps})"
        if self._checkpoint_step is None:
            then += ("; the file holds no checkpoint to resume from: run again (with "
                     "overwrite=True, or --force) once there is room")
        else:
            then += (f"; the file holds the run up to its last checkpoint (step "
                     f"{self._checkpoint_step})")
            if not isinstance(exc, _NoRoom):
                then += (", but HDF5 was stopped in the middle of a write, and it may "
                         "not resume")
            else:
                room = ("there is room again" if _error_number(exc) in _DISK_FULL
                        else "the file can be written again")
                then += (f": once {room}, 'orbits resume {self.path}' (or Simulation."
                         f"from_file(path).resume()) finishes the run")
        return _write_error(self.path, exc, then)

    def _shut(self):
        # the file closed and the lock released, whatever the disk holds: a
        # file whose last flush failed is abandoned (_abandon), else the space
        # reserved ahead is given back
        try:
            if self.f is not None and _close_written(self.f) is None:
                _trim(self.path)
        finally:
            _release(self.path)

    def _check_same_layout(self):
        n = self.f["particles/bodies/names"].shape[0]
        names = set(_decode(self.f["particles/bodies/names"][()]))
        if "masses" in self.f["restart"] and set(self.desc.names) <= names:
            n = len(self.desc.names)     # collisions merged some of the file's bodies
        if n != len(self.desc.names):
            raise OrbitsFileError(f"{self.path}: holds {n} bodies, the simulation "
                                  f"{len(self.desc.names)}")
        # the tangent vectors' shapes: the rows the checkpoints restore, and the
        # derivatives (which files written before they were kept lack)
        r = self.f["restart"]
        layout = _tangent_layout(self.desc.monitors, self.desc.config.variations, n)
        tangent = self.sim.state.workspace.get("tangent")
        rows = r["ws/tangent"].shape[1:] if "tangent" in r["ws"] else None
        if rows != (None if tangent is None else tangent.shape):
            self._tangent_mismatch("tangent rows", rows,
                                   None if tangent is None else tangent.shape)
        if "tangent_vectors" in r and r["tangent_vectors"].shape[1:] != (sum(layout), n, 6):
            self._tangent_mismatch("tangent vectors", r["tangent_vectors"].shape[1:],
                                   (sum(layout), n, 6))

    def _tangent_mismatch(self, what, have, want):
        raise TangentShapeError(
            f"{self.path}: holds {what} of shape {have}, but the simulation appending to it "
            f"has {want} (variations={self.desc.config.variations!r}, monitors "
            f"{', '.join(self.desc.monitors) or 'none'}); write to a new file",
            expected=want, found=have)

    def _stored_wall(self):
        r = self.f["restart"]
        count = int(r["count"][()])
        if count == 0 or "wall" not in r:
            return 0.0
        return float(r["wall"][(count - 1) % _SLOTS])

    def _series_handles(self):
        # (step, time, value) datasets and the column of a snapshot they take
        p = self.f["particles/bodies"]
        obs = self.f["observables"]
        series = [(_datasets(p["position"]), 2, None), (_datasets(p["velocity"]), 3, None)]
        if "masses_at_outputs" in p:
            series.append((_datasets(p["masses_at_outputs"]), 5, None))
        names = self._series_names()
        series += [(_datasets(obs[name]), 4, name) for name in names]
        inloop = {name: _datasets(obs["in_loop"][name]) for name in names}
        return series, inloop

    def _series_names(self):
        return tuple(self.sim.monitors) + (("work",) if self.work else ())

    def _largest_so_far(self):
        # a resumed run's largest errors include those of its outputs and
        # in-loop rows already in the file
        plan, sim = self.plan, self.sim
        first = max(0, self.rows - self.outputs_written)
        obs = self.f["observables"]
        for spec in WITH_ERROR:
            if spec.name not in sim.monitors:
                continue
            self._note(spec.name, _series_errors(obs, spec.name, slice(first, self.rows),
                                                 self.reference, self.scales))
            t = obs["in_loop"][spec.name]["time"][()]
            keep = (t > plan.start_time) & (t <= sim.time_value)
            if keep.any():
                self._note(spec.name, _series_errors(obs["in_loop"], spec.name,
                                                     np.flatnonzero(keep), self.reference,
                                                     self.scales))

    def _note(self, name, err):
        # the largest of the relative errors ``err`` of monitor ``name`` so far
        if not len(err):
            return
        top = float(np.max(err))
        old = self.largest.get(name)
        self.largest[name] = top if old is None else float(np.max([old, top]))

    def _note_rows(self, rows):
        for spec in WITH_ERROR:
            if spec.name in self.sim.monitors:
                self._note(spec.name, row_errors(spec.name, rows, self.reference, self.scales))

    # Recorder interface ----------------------------------------------------------------
    @_writes
    def output(self, sim, final=False):
        """Record the simulation's current state as the next output row (buffered).

        Parameters
        ----------
        sim : Simulation
            Its :meth:`~orbits.Simulation.snapshot` is the output.
        final : bool
            The run's last output: a checkpoint marked finished follows.

        Examples
        --------
        >>> _ = sim.run(until=10 * u.day, outputs=2, progress=False)
        >>> rec.output(sim, final=True)
        >>> rec.outputs_written, rec.checkpoints
        (2, 2)
        >>> rec.close()
        """
        self.last = self._columns_of(sim.snapshot())
        self.buffer.append(self.last)
        self.outputs_written += 1
        if len(self.buffer) >= BUFFER_ROWS:
            self._flush_outputs()
        if final or _time.perf_counter() - self.last_checkpoint >= self.interval:
            self.checkpoint(finished=final)

    #: outputs a call of the compiled loop records at most, so that a run of
    #: any number of outputs holds no more than this many in memory
    max_rows = 16 * BUFFER_ROWS

    @property
    def records_in_loop(self):
        """Whether outputs may be recorded inside the compiled loop: not with
        ``checkpoint_interval=0``, which asks for a checkpoint at every output."""
        return self.interval > 0

    def row_buffer(self, k):
        """Where the compiled loop writes the next ``k`` outputs (at most
        :attr:`max_rows`): rows of the monitors, then the bodies' positions
        and velocities in the simulation's internal order (see
        :meth:`orbits._driver.Driven.execute`)."""
        width = MONITOR_WIDTH + 6 * len(self.desc.names)
        if self._rowbuf is None or len(self._rowbuf) < k:
            self._rowbuf = np.zeros((k, width))
        return self._rowbuf[:k]

    @_writes
    def output_rows(self, sim, steps, t, rows):
        """The loop wrote ``rows`` (from :meth:`row_buffer`) at ``steps`` and
        times ``t``: written to the file as they are, after the buffered
        outputs before them."""
        if self.buffer or self.mon_buffer:
            self._flush_outputs(sync=False)
        series, _ = self._series
        w, n, k = MONITOR_WIDTH, len(self.desc.names), len(t)
        self._reserve(k * self._row_bytes)
        x = rows[:, w:w + 3 * n].reshape(k, n, 3)
        v = rows[:, w + 3 * n:w + 6 * n].reshape(k, n, 3)
        if not np.array_equal(self.inv, np.arange(n)):
            x, v = x[:, self.inv], v[:, self.inv]
        mon = rows[:, :w]
        self._note_rows(mon)
        steps = np.asarray(steps, dtype=np.int64)
        for dsets, col, name in series:
            if name is None:
                values = x if col == 2 else v
            else:
                values = row_series(name, mon)
            _append(dsets, self.rows, steps, t, values)
        self.rows += k
        self.outputs_written += k
        self.last = (float(t[-1]), int(steps[-1]), x[-1], v[-1], mon[-1].copy())
        self._checkpoint_due = True
        if self._unflushed > _RESERVE_BYTES:
            # flushed every few MB, so that the space reserved ahead need not
            # cover more than that of written data HDF5 has not placed yet
            self.f.flush()
            self._unflushed = 0

    @_writes
    def between_chunks(self):
        """The simulation's clock and state agree again: write the checkpoint
        that outputs recorded in the loop made due, if its interval passed."""
        if self._checkpoint_due and \
                _time.perf_counter() - self.last_checkpoint >= self.interval:
            self._checkpoint_due = False
            self.checkpoint()

    def monitor_rows(self, t, rows):
        """In-loop monitor rows of the chunk the simulation has just run; called
        before its step count moves on, so the rows' steps are the multiples
        of ``monitor_every`` after ``sim.steps`` (as the compiled loops record).

        Examples
        --------
        >>> rec.monitor_rows(np.array([1.0]), np.zeros((1, 11)))
        >>> len(rec.mon_buffer)
        1
        >>> rec.close()
        """
        self._note_rows(rows)
        every = self.sim.monitor_every or 1
        steps = (self.sim.steps // every + 1 + np.arange(len(t), dtype=np.int64)) * every
        self.mon_buffer.append((t.copy(), steps, rows.copy()))

    def stopped(self, sim):
        """A run stopped between outputs (by a signal, after :meth:`checkpoint`): the
        result ends at this state; the file gets no row off the outputs' grid.

        Examples
        --------
        >>> _ = sim.run(until=4 * u.day, outputs=2, progress=False)
        >>> rec.stopped(sim)
        >>> rec.result(sim, wall=0.0).times
        <Quantity [4.] d>
        >>> rec.close()
        """
        self.last = self._columns_of(sim.snapshot())
        self._note_rows(self.last[4][None])

    def _columns_of(self, snap):
        """An output as the file keeps it: ``(t, steps, x, v, monitors)`` and,
        where collisions change the bodies, the masses, in the columns of the
        bodies at the start (NaN for one merged away)."""
        if not self.varying:
            return tuple(snap)[:5]
        n = len(self.columns)
        cols = [self.columns.index(name) for name in snap.names]
        x, v, m = np.full((n, 3), np.nan), np.full((n, 3), np.nan), np.full(n, np.nan)
        x[cols], v[cols], m[cols] = snap.x, snap.v, snap.masses
        return (snap.t, snap.steps, x, v, snap.monitors, m)

    @_writes
    def collision_rows(self, sim, rows):
        """Append the collisions a run resolved (rows of
        :func:`orbits.collisions.table`, internal units) to the file's group
        ``collisions``, made on first use."""
        if not rows or self.closed:
            return
        self._reserve(_LOG_ROW_BYTES * len(rows))
        unit = lambda kind: sim.units.unit(kind).to_string()  # noqa: E731
        _append_columns(self.f.require_group("collisions"), rows, (
            ("time", unit("time")), ("step_time", unit("time")), ("body_1", None),
            ("body_2", None), ("resolution", None), ("survivor", None),
            ("distance", unit("length")), ("speed", unit("velocity")),
            ("energy_change", unit("energy"))))

    @_writes
    def encounter_rows(self, sim, rows):
        """Append rows ``(t, body_1, body_2, distance, speed)`` of the encounter
        log (internal units) to the file's group ``encounters``, made on first
        use: datasets ``time``, ``distance``, ``speed`` (each with its
        ``unit``) and ``body_1``, ``body_2`` (names), of a length that grows."""
        if not rows or self.closed:
            return
        self._reserve(_LOG_ROW_BYTES * len(rows))
        U = sim.units
        _append_columns(self.f.require_group("encounters"), rows, (
            ("time", U.unit("time").to_string()), ("body_1", None), ("body_2", None),
            ("distance", U.unit("length").to_string()),
            ("speed", (U.unit("length") / U.unit("time")).to_string())))

    def close(self):
        """Flush what is buffered, close the file and release the writers' lock (idempotent).

        Examples
        --------
        >>> rec.close()
        >>> import os
        >>> rec.closed, os.path.exists(f"{rec.path}.lock")  # the writers' lock is released
        (True, False)
        """
        if not self.closed:
            self.closed = True
            try:
                if self._failed is None:
                    self._flush_outputs()
            finally:
                self._shut()

    def result(self, sim, wall, status="completed"):
        """The run's :class:`~orbits.Result`, as :meth:`orbits.Simulation.run`
        returns it for a file.

        Parameters
        ----------
        sim : Simulation
        wall : float
            Seconds of wall-clock time the run took.
        status : str
            How the run ended.

        Returns
        -------
        Result
            The last output only, with the largest relative errors of the whole
            run in ``largest_errors``.

        Examples
        --------
        >>> _ = sim.run(until=10 * u.day, outputs=2, progress=False)
        >>> rec.output(sim, final=True)
        >>> r = rec.result(sim, wall=0.5)
        >>> r.times, r.wall_time, r.path == str(rec.path)
        (<Quantity [10.] d>, 0.5, True)
        >>> rec.close()
        """
        q = sim.units.quantity
        t, step, x, v, row = self.last[:5]
        if self.varying:
            # the columns of the bodies at the start, and their masses then
            names, masses, radii = self.columns, self.masses0, self.radii0
        else:
            names, masses, radii = self.desc.names, self.desc.masses, self.desc.radii
        fields = dict(times=q(np.array([t]), "time"), positions=q(x[None], "length"),
                      velocities=q(v[None], "velocity"), names=list(names),
                      masses=q(np.array(masses, dtype=float), "mass"),
                      radii=q(np.array(radii, dtype=float), "length"),
                      steps=sim.steps - self.steps0,
                      force_evaluations=sim.force_evaluations - self.forces0, wall_time=wall,
                      steps_rejected=sim.steps_rejected - self.rejected0,
                      integrator=sim.integrator.info(), units=sim.units,
                      dt=sim.dt, status=status, monitors=sim.monitors, path=str(self.path),
                      forces=tuple(map(repr, sim.forces)),
                      start_time=q(self.plan.start_time, "time"),
                      largest_errors=dict(self.largest), epoch=self.desc.epoch)
        if sim.monitors:
            fields.update(monitor_fields(row[None], sim.monitors, self.reference, self.scales,
                                         sim.units, work=self.work))
        tangents = sim.tangent_vectors
        if tangents is not None:
            fields.update(jacobian=sim.jacobian, tangent_vectors=tangents,
                          seed=self.desc.config.seed)
        if self.varying:
            fields["masses_at_outputs"] = q(self.last[5][None], "mass")
        return Result(**fields)

    # writing ---------------------------------------------------------------------------
    @_writes
    def _flush_outputs(self, sync=True):
        # the buffered outputs and in-loop rows into their datasets; sync:
        # and the file flushed to disk
        series, inloop = self._series
        if self.buffer or self.mon_buffer:
            self._reserve(len(self.buffer) * self._row_bytes
                          + sum(len(part[0]) for part in self.mon_buffer) * self._inloop_bytes)
        if self.buffer:
            k = len(self.buffer)
            n0 = self.rows
            t = np.array([b[0] for b in self.buffer])
            steps = np.array([b[1] for b in self.buffer], dtype=np.int64)
            self._note_rows(np.array([b[4] for b in self.buffer]))
            for dsets, col, name in series:
                values = np.array([b[col] for b in self.buffer])
                if name is not None:
                    values = row_series(name, values)
                _append(dsets, n0, steps, t, values)
            self.rows = n0 + k
            self.buffer = []
        if self.mon_buffer:
            t, steps, rows = (np.concatenate(part) for part in zip(*self.mon_buffer))
            for name, dsets in inloop.items():
                _append(dsets, dsets[1].shape[0], steps, t, row_series(name, rows))
            self.mon_buffer = []
        if sync:
            self.f.flush()
            self._unflushed = 0

    @_writes
    def checkpoint(self, finished=False):
        """Write the restart state into the free slot, then advance ``count``.

        Callable at any point between two compiled chunks: the outputs so far
        are flushed first, and the state, clock, plan and progress written are
        those of that moment, from which a resumed run finishes bit for bit as
        the uninterrupted one.

        Parameters
        ----------
        finished : bool
            Mark the run as finished (nothing left to resume).

        Examples
        --------
        >>> rec.checkpoints
        1
        >>> rec.checkpoint()
        >>> rec.checkpoints
        2
        >>> rec.close()
        >>> orbits.io.h5md.read_checkpoint(rec.path).point.finished
        False
        """
        sim = self.sim
        self._flush_outputs()
        self._reserve(0)        # the slot's datasets are in the headroom
        r = self._restart
        count = int(r["count"][()])
        slot = count % _SLOTS
        state = sim.state
        p = self.plan
        for name, value in (
                ("x", _padded(state.x, r["x"].shape[1])),
                ("v", _padded(state.v, r["v"].shape[1])),
                ("clock", (state.steps, state.steps_since_base, state.force_evaluations,
                           self.rows, state.steps_rejected)),
                ("t_base", state.t_base),
                ("plan", (p.until, p.outputs, p.ratio, p.n_full, float(p.has_partial),
                          p.start_step, p.start_time)),
                ("progress", (self.outputs_written, int(finished), self.end_status)),
                ("wall", self.wall_before + _time.perf_counter() - self.wall0)):
            if name in r:
                _write_rows(r[name], slot, np.asarray(value)[None], extend=False)
        for name, arr in state.workspace.items():
            _write_box(self._ws[name], slot, arr)
        if self.varying:
            desc = sim.description()
            n = len(self.columns)
            cols = [self.columns.index(name) for name in desc.names]
            m, rad = np.full(n, np.nan), np.full(n, np.nan)
            m[cols], rad[cols] = desc.masses, desc.radii
            order = np.full(n, -1, dtype=np.int64)
            order[:len(state.order)] = state.order
            for name, value in (("masses", m), ("radii", rad), ("orders", order)):
                _write_rows(r[name], slot, value[None], extend=False)
        if "tangent_vectors" in r:
            _write_rows(r["tangent_vectors"], slot, sim.tangent_vectors[None], extend=False)
        self.f.flush()
        r["count"][()] = count + 1
        r["count"].flush()
        self.f.flush()
        self._unflushed = 0
        self.checkpoints += 1
        self._checkpoint_step = state.steps
        self.last_checkpoint = _time.perf_counter()


def _append_columns(group, rows, columns):
    """Append ``rows`` (tuples) to the one-dimensional datasets of ``group``, one
    a column: ``columns`` are ``(name, unit)``, a number with its ``unit``
    attribute, or a name (text) where the unit is None; a dataset is made, of a
    length that grows, on first use."""
    text = h5py.string_dtype()
    for k, (name, unit) in enumerate(columns):
        dtype = text if unit is None else np.float64
        values = [row[k] for row in rows]
        if name not in group:
            ds = group.create_dataset(name, shape=(0,), maxshape=(None,), dtype=dtype,
                                      chunks=(256,))
            if unit is not None:
                ds.attrs["unit"] = unit
        ds = group[name]
        start = ds.shape[0]
        ds.resize((start + len(values),))
        ds[start:] = np.asarray(values, dtype=object if unit is None else dtype)
