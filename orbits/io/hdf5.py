"""HDF5 output: streamed trajectories, monitors, metadata and restart checkpoints.

Layout
------
The file follows H5MD 1.1 (de Buyl, Colberg & Höfling 2014, the published
HDF5 layout for particle simulations) where it has a place for a thing, and
adds two groups of its own::

    /                        attrs: orbits_format = "orbits-h5md", orbits_format_version
    /h5md                    attrs: version = [1, 1]; /h5md/author, /h5md/creator (name, version)
    /particles/bodies
        names                (N,) str, in the order of the body set
        mass                 (N,) float, attr unit
        radius               (N,) float, attr unit (length): the bodies' physical
                             radii, 0 for a point mass (files written before it
                             was kept lack it, and read as all 0)
        position/step        (T,) int64, steps since the simulation was made
        position/time        (T,) float, attr unit
        position/value       (T, N, 3) float, attr unit
        velocity/{step,time,value}   likewise
    /observables             each an H5MD time-dependent element {step, time, value}
        energy               value (T,)
        angular_momentum     value (T, 3)
        momentum             value (T, 3)
        center_of_mass       value (T, 3)
        work                 value (T,): W, the energy non-conservative force terms
                             took out since the simulation was made (with the
                             energy monitor and such terms only; the energy error
                             is that of E + W)
        megno, fli           value (T,), dimensionless (unit "1"): the chaos monitors'
                             running mean of MEGNO and fast Lyapunov indicator
        lyapunov             value (T,), unit 1 / time: the Lyapunov exponent's estimate
        in_loop/<same>       the series recorded inside the compiled loop every
                             monitor_every steps, when that was asked for
    /parameters              attrs: the run's metadata (orbits and library versions,
                             integrator and its options, dt, unit system, G and its
                             source, softening, monitors, stopping conditions, when
                             written, how the body set was made, as JSON where
                             structured); epoch_tdb, where the bodies carried an
                             epoch: (2,) float64, the Julian date of time 0 in
                             TDB in two parts (jd1 + jd2, as astropy's Time
                             keeps it; files without it have no date)
        reference            (14,) the monitors' values when the simulation was made
                             (the layout of orbits._kernels.invariants.MONITOR_COLUMNS;
                             older files have (10,), without the work, or (11,),
                             without the chaos indicators)
        scales               (2,) energy and angular-momentum scales for relative errors
    /restart                 the last two checkpoints, in alternating slots
        count                () int64: complete checkpoints written; the valid slot
                             is (count - 1) % 2
        x, v                 (2, N, 3) internal order (massive bodies first)
        order                (N,) int64: internal index -> body-set index
        clock                (2, 5) int64: steps, steps_since_base (negative in a
                             run backwards in time: time = t_base +
                             steps_since_base * dt, dt > 0), force_evaluations,
                             output rows written, steps rejected
        t_base               (2,) float
        plan                 (2, 7) float: the run in progress (until, outputs, ratio,
                             n_full, has_partial, start_step, start_time) and
        progress             (2, 3) int64: (outputs of that run written, run finished,
                             status code when it ended early: 1 non-finite state,
                             2 step-size underflow, 3 close encounter, 4 escape)
        wall                 (2,) float, seconds: wall-clock time the runs writing
                             the file had taken at the checkpoint
        ws/<name>            (2, ...) the integrator's workspace arrays (with
                             non-conservative terms, ws/work: W and its rounding
                             compensation; with variations or chaos monitors,
                             ws/tangent (2, 2, k N, 3): the k tangent vectors'
                             position and velocity rows, internal order, and
                             ws/chaos: the chaos monitors' accumulators)
        tangent_vectors      (2, k, N, 6) with variations or chaos monitors: the
                             tangent vectors at the checkpoint as
                             Simulation.tangent_vectors gives them (synchronised,
                             body-set order, internal units); attr layout = the
                             numbers of vectors (chaos, random, state, mass), from
                             which load() rebuilds the Jacobian
    /parameters/start_clock  (3,) int64: steps, force evaluations and rejected steps
                             of the simulation when the file was made (the
                             totals since are ``clock`` less these)

Files written before ``wall`` and ``start_clock`` read back with those totals
"not recorded".  The time series are chunked without compression, so that a
partly filled chunk written at a checkpoint is rewritten in place: a
compressed chunk changes size, and HDF5 gives it new space each time (a run
with a checkpoint at every output grew to 180 times its data).

Every float dataset has a ``unit`` attribute (H5MD's convention); ``orbits.load``
gives Quantities back.

Crash safety
------------
The file is written in HDF5's single-writer/multiple-reader (SWMR) mode, which
keeps it consistent on disk whenever the writer stops, and outputs are flushed
in blocks.  A checkpoint goes into the slot not holding the last one, is
flushed, and only then is ``count`` advanced and flushed: the slot ``count``
names is always complete.  A run killed in the middle (even by SIGKILL)
leaves a file that :func:`load` and :func:`describe` open, and that
:meth:`orbits.Simulation.from_file` resumes from its last checkpoint; rows
written after that checkpoint are dropped on resume and computed again, so
the resumed file ends the same as an uninterrupted one.  A file whose writer
died can be read with plain h5py as ``h5py.File(path, "r", swmr=True)``.

Every run writes a checkpoint as soon as its file is open and its first output
written, so even a run stopped before its first periodic checkpoint resumes;
:meth:`FileRecorder.checkpoint` may be called at any point between two
compiled chunks (a signal handler does).

A full disk stops a run between two writes: before each write the disk is
asked (``posix_fallocate``) for the space it may take, and where there is
none the run stops with an :class:`OrbitsFileError` that says the disk is
full, the file closed whole, ending at or after its last checkpoint, and the
space reserved past its end given back.  While it is being written a file
may therefore be larger than the end its superblock records.  Temporary
files (``<file>.creating``, ``<file>.resume``) are made exclusively, never
through a link that has their name, and a destination that is a link is
refused unless asked to be replaced.

Damaged files
-------------
HDF5 reading a file in SWMR mode retries a metadata block whose checksum
fails, sleeping twice as long each time, about forever at its default number
of tries: a truncated file would hang the reader.  So the superblock is read
first (:func:`_superblock`).  A file recording more bytes than it has is
named truncated (after waiting up to a second for a live writer, which
records a new end a moment before it writes there).  A file not marked as
being written is opened without SWMR, where damage fails at once; one marked
as being written (by a live writer or a killed one) is opened in SWMR mode
with the tries bounded (:data:`SWMR_READ_ATTEMPTS`).  The groups and
datasets the layout needs are then checked, and a missing one is named in
words.

What a reader trusts
--------------------
A file carries data, never code.  Nothing it names is imported (the
functions of a run are named in ``/parameters`` and come back from the
caller of :meth:`orbits.Simulation.from_file`), and nothing outside it is
read: external and user-defined links, datasets stored in external files or
as virtual views, and filters that HDF5 would load as plugins are refused
(:func:`_inventory`).  Declared shapes are checked against the bodies' count
and against the bytes the file stores before anything is read, and of a time
series only the rows stored are read (:func:`_covered`), so that a small file
cannot make a reader allocate for data it does not hold.  Every control
value (the checkpoints' count, clock, plan, progress, the bodies' order, the
units and the recorded configuration) is checked for type, shape and range
(:func:`_check_values`); what fails is an :class:`OrbitsFileError` naming the
dataset or attribute and what was expected.

Writers' lock
-------------
A writer holds ``<file>.lock`` (made atomically; it names the host, process
id and its start time) while the file is open, and removes it on closing.
A second writer, or a resume, of a file whose lock names a live process is
refused with :class:`FileInUse`; a lock left by a process that has died (on
this host) is taken over.
"""

import ctypes
import datetime
import errno
import functools
import json
import math
import os
import pathlib
import re
import socket
import stat
import struct
import time as _time
import uuid
from typing import NamedTuple

import h5py
import numpy as np

try:
    import resource     # the file-size limit (ulimit -f); POSIX only
except ImportError:     # pragma: no cover - not POSIX
    resource = None

from .. import epochs as _epochs
from .._kernels import invariants as _inv
from ..errors import OrbitsError
from ..monitors import CHAOS_MONITORS, _work_column, monitor_fields
from ..records import RunPlan, SimulationState
from ..units import format_time, time_unit

__all__ = ["FileRecorder", "load", "describe", "read_checkpoint", "Checkpoint", "truncate",
           "ResumePoint", "whole_run",
           "OrbitsFileError", "FileInUse", "TangentShapeError",
           "FORMAT", "FORMAT_VERSION", "CHECKPOINT_SECONDS", "BUFFER_ROWS",
           "SWMR_READ_ATTEMPTS"]

FORMAT = "orbits-h5md"
FORMAT_VERSION = 1
#: default wall-clock seconds between restart checkpoints
CHECKPOINT_SECONDS = 60.0
#: outputs held in memory before they are written as one block
BUFFER_ROWS = 256
_SLOTS = 2
#: the largest |jd1| an epoch attribute may hold: 1e9 days, 2.7 million years
#: either side of JD 0 (a damaged attribute, not a date, beyond)
_EPOCH_JD_LIMIT = 1e9
_MONITOR_NAMES = ("energy", "angular_momentum", "momentum", "center_of_mass")
#: the chaos indicators, one value per row each (orbits.monitors.CHAOS_MONITORS)
_CHAOS = ("megno", "lyapunov", "fli")
_MONITOR_COLUMNS = {"energy": slice(0, 1), "angular_momentum": slice(1, 4),
                    "momentum": slice(4, 7), "center_of_mass": slice(7, 10),
                    "work": slice(10, 11),
                    **{name: slice(_inv.MONITOR_COLUMNS.index(name),
                                   _inv.MONITOR_COLUMNS.index(name) + 1) for name in _CHAOS}}
#: the unit of each series: a kind of orbits.units.UnitSystem, or "1 / time"
_MONITOR_KIND = {"energy": "energy", "angular_momentum": "angular_momentum",
                 "momentum": "momentum", "center_of_mass": "length", "work": "energy",
                 "megno": "dimensionless", "lyapunov": "1 / time", "fli": "dimensionless"}
#: the series of one value per row (the others are 3-vectors)
_SCALAR_SERIES = ("energy", "work") + _CHAOS
#: tries of a metadata read whose checksum fails, in SWMR mode.  HDF5 sleeps
#: 1, 2, 4, ... ns between tries, so 24 tries give up after 2**24 ns = 17 ms
#: (measured: 41 ms for 25 tries, 1.1 s for 30); a live writer rewrites a
#: metadata block in microseconds.  HDF5's default, 100, never gives up.
SWMR_READ_ATTEMPTS = 24
#: a writer's lock this many seconds old that cannot be read is taken to be
#: left over (a lock is written whole before it appears, see _acquire)
_LOCK_UNREADABLE_SECONDS = 5.0


class OrbitsFileError(OrbitsError, OSError):
    """A file that is not an orbits output, is damaged, or has another layout version.

    Examples
    --------
    >>> import os, tempfile
    >>> import orbits
    >>> path = os.path.join(tempfile.mkdtemp(), "notes.h5")
    >>> with open(path, "w") as fh:
    ...     _ = fh.write("not HDF5")
    >>> try:
    ...     orbits.load(path)
    ... except orbits.OrbitsError as exc:
    ...     print(type(exc).__name__, str(exc).endswith("(it has no HDF5 signature)"))
    OrbitsFileError True
    """


class FileInUse(OrbitsFileError):
    """Another process is writing the file: its lock names a live process.

    Attributes
    ----------
    pid : int or None
        The writer's process id.
    host : str or None
        The host it runs on.

    Examples
    --------
    >>> import os
    >>> from orbits.io.hdf5 import FileInUse, OrbitsFileError
    >>> exc = FileInUse("run.h5: being written by process 4242", pid=4242, host="node7")
    >>> isinstance(exc, OrbitsFileError), exc.pid, exc.host
    (True, 4242, 'node7')
    """

    def __init__(self, message, pid=None, host=None):
        self.pid = pid
        self.host = host
        super().__init__(message)


class TangentShapeError(OrbitsFileError):
    """A file whose stored tangent vectors do not have the shape that its
    simulation's ``variations`` and chaos monitors call for (a damaged file,
    or one edited by hand), so that neither the derivatives nor a restart can
    be read from it.

    Attributes
    ----------
    expected, found : tuple of int
        The shapes.

    Examples
    --------
    >>> from orbits.io.hdf5 import OrbitsFileError, TangentShapeError
    >>> exc = TangentShapeError("run.h5: tangent vectors of shape (2, 3, 6)", expected=(19, 3, 6),
    ...                         found=(2, 3, 6))
    >>> isinstance(exc, OrbitsFileError), exc.expected, exc.found
    (True, (19, 3, 6), (2, 3, 6))
    """

    def __init__(self, message, expected=None, found=None):
        self.expected = expected
        self.found = found
        super().__init__(message)


# -- opening ---------------------------------------------------------------------------

_SIGNATURE = b"\x89HDF\r\n\x1a\n"
_OPEN_FOR_WRITE = 0x01      # superblock (v2, v3) file consistency flags
_OPEN_FOR_SWMR_WRITE = 0x04


class _Superblock(NamedTuple):
    version: int
    flags: int      # file consistency flags (superblock versions 2 and 3), else 0
    eof: int        # the end of file the superblock records (bytes), -1 where not read
    size: int       # the file's size on disk


def _superblock(path):
    """The file's HDF5 superblock, read with plain file I/O; None if it has none.

    HDF5 looks for the signature at 0, 512, 1024, 2048, ... (a user block
    may come first).  Versions 2 and 3 (``libver="latest"``, SWMR) keep the
    consistency flags and the end-of-file address at fixed places.
    """
    size = path.stat().st_size
    with open(path, "rb") as fh:
        offset = 0
        while offset + len(_SIGNATURE) <= size:
            fh.seek(offset)
            head = fh.read(48)
            if head.startswith(_SIGNATURE):
                break
            offset = 512 if offset == 0 else 2 * offset
        else:
            return None
    version = head[8] if len(head) > 8 else -1
    if version in (2, 3) and len(head) >= 44 and head[9] == 8:    # 8-byte addresses
        base, _extension, eof, _root = struct.unpack_from("<4Q", head, 12)
        return _Superblock(version, head[11], base + eof, size)
    return _Superblock(version, 0, -1, size)


@functools.lru_cache(maxsize=None)
def _read_attempts_setter():
    """``H5Pset_metadata_read_attempts`` of the HDF5 library h5py runs on, or None.

    h5py does not wrap it.  The library is found among those this process has
    mapped (Linux), and taken only if a property set through it reads back
    through h5py: the same library, not another copy.
    """
    try:
        with open("/proc/self/maps") as fh:
            maps = fh.read()
    except OSError:
        return None
    paths = sorted(set(re.findall(r"(/\S*/libhdf5(?!_hl)[^/\s]*\.so[^/\s]*)$", maps,
                                  re.MULTILINE)))
    for lib_path in paths:
        try:
            lib = ctypes.CDLL(lib_path)
            setter = lib.H5Pset_metadata_read_attempts
            probe = lib.H5Pset_meta_block_size
        except (OSError, AttributeError):
            continue
        setter.argtypes = [ctypes.c_int64, ctypes.c_uint]
        setter.restype = ctypes.c_int
        probe.argtypes = [ctypes.c_int64, ctypes.c_uint64]
        probe.restype = ctypes.c_int
        fapl = h5py.h5p.create(h5py.h5p.FILE_ACCESS)
        if probe(fapl.id, 12_345) >= 0 and fapl.get_meta_block_size() == 12_345:
            return setter
    return None


def _open_swmr(path):
    """Open for reading in SWMR mode, with metadata read tries bounded if possible."""
    setter = _read_attempts_setter()
    if setter is None:
        return h5py.File(path, "r", swmr=True)
    fapl = h5py.h5p.create(h5py.h5p.FILE_ACCESS)
    fapl.set_fclose_degree(h5py.h5f.CLOSE_STRONG)
    if setter(fapl.id, SWMR_READ_ATTEMPTS) < 0:
        return h5py.File(path, "r", swmr=True)
    fid = h5py.h5f.open(os.fsencode(path), h5py.h5f.ACC_RDONLY | h5py.h5f.ACC_SWMR_READ,
                        fapl=fapl)
    return h5py.File(fid)


#: bytes at the start of a file searched for global heap collections: HDF5
#: keeps variable-length strings there, and orbits writes all of its own
#: (attributes, body names) when it makes a file, before any output
_HEAP_SEARCH_BYTES = 1 << 20
_HEAP_MIN_BYTES = 4096      # the smallest collection HDF5 makes (H5HG_MINSIZE)
_HEAP_OBJECT_HEADER = 16    # index, references, reserved, size (8-byte lengths)


def _check_global_heaps(path, size):
    """Raise an OrbitsFileError for a global heap collection HDF5 would never finish
    reading.

    A global heap collection carries no checksum, and HDF5 walks its objects
    by their stored sizes: an object of size 0 (zeros over the collection)
    makes it loop for ever, in any mode.  The collections are walked here
    first, as HDF5 walks them; a valid one is tiled exactly by its objects.
    """
    with open(path, "rb") as fh:
        head = fh.read(_HEAP_SEARCH_BYTES)
        at = head.find(b"GCOL")
        while at >= 0:
            if len(head) >= at + 16 and head[at + 4] == 1:          # version 1
                extent = struct.unpack_from("<Q", head, at + 8)[0]
                if _HEAP_MIN_BYTES <= extent <= size - at:
                    fh.seek(at)
                    if not _heap_tiles(fh.read(extent)):
                        raise OrbitsFileError(
                            f"{path}: damaged: the HDF5 global heap at byte {at} (where "
                            f"its strings are kept) does not parse")
            at = head.find(b"GCOL", at + 4)


def _heap_tiles(body):
    p, end = 16, len(body)
    while p + _HEAP_OBJECT_HEADER <= end:
        index = struct.unpack_from("<H", body, p)[0]
        length = struct.unpack_from("<Q", body, p + 8)[0]
        # object 0 is the free space, its size counting its header
        need = _HEAP_OBJECT_HEADER + (length + 7) // 8 * 8 if index else length
        if need <= 0 or p + need > end:
            return False
        p += need
    return True


def _truncated(path, sb, writer=None):
    if writer is not None:
        return FileInUse(f"{path}: being written by process {writer.get('pid')}, and what "
                         f"its header says ({sb.eof} bytes) is not all on disk yet "
                         f"({sb.size}); try again", pid=writer.get("pid"),
                         host=writer.get("host"))
    return OrbitsFileError(
        f"{path}: truncated: it has {sb.size} bytes, but its HDF5 header says {sb.eof}; "
        f"the rest of the file is missing (an interrupted copy, a full disk, or a writer "
        f"killed while it was extending the file)")


def _open_hdf5(path):
    sb = _superblock(path)
    if sb is None:
        what = "it is empty" if path.stat().st_size == 0 else "it has no HDF5 signature"
        raise OrbitsFileError(f"{path}: not a readable HDF5 file ({what})")
    writing = sb.flags & (_OPEN_FOR_WRITE | _OPEN_FOR_SWMR_WRITE)
    if sb.eof > sb.size:
        # a live writer records a new end of file a moment before the file
        # reaches it (measured: 0.06 % of the time with a checkpoint at every
        # output): look again while its lock says it runs
        writer, alive = _writer(path) if writing else (None, False)
        deadline = _time.monotonic() + 1.0
        while alive is not False and sb.eof > sb.size and _time.monotonic() < deadline:
            _time.sleep(0.01)
            sb = _superblock(path) or sb
            writer, alive = _writer(path)
        if sb.eof > sb.size:
            raise _truncated(path, sb, writer if alive is not False else None)
    _check_global_heaps(path, sb.size)
    if not writing:
        try:
            # no file lock: a writer about to append must not find it taken
            return h5py.File(path, "r", locking=False)
        except OSError as exc:
            raise OrbitsFileError(f"{path}: not a readable HDF5 file (damaged?): "
                                  f"{exc}") from None
    if not sb.flags & _OPEN_FOR_SWMR_WRITE:
        raise OrbitsFileError(f"{path}: open for writing by a program not in SWMR mode, or "
                              f"left so by one that was killed (h5clear -s clears the mark)")
    # being written, or its writer was killed: SWMR mode reads it either way
    try:
        return _open_swmr(path)
    except (OSError, RuntimeError) as exc:
        raise OrbitsFileError(f"{path}: not a readable HDF5 file (damaged?): {exc}") from None


#: what an orbits file holds, in words for the message that names what is missing
_GROUPS = {
    "particles": "the trajectories",
    "particles/bodies": "the bodies and their trajectories",
    "particles/bodies/position": "the positions",
    "particles/bodies/velocity": "the velocities",
    "observables": "the monitors' series",
    "observables/in_loop": "the monitors' in-loop series",
    "parameters": "the run's metadata",
    "restart": "the restart checkpoints",
    "restart/ws": "the integrator's state in the checkpoints",
}
_DATASETS = {
    "particles/bodies/names": "the bodies' names",
    "particles/bodies/mass": "the bodies' masses",
    "particles/bodies/position/step": "the outputs' step counts",
    "particles/bodies/position/time": "the outputs' times",
    "particles/bodies/position/value": "the positions",
    "particles/bodies/velocity/step": "the outputs' step counts",
    "particles/bodies/velocity/time": "the outputs' times",
    "particles/bodies/velocity/value": "the velocities",
    "parameters/reference": "the monitors' reference values",
    "parameters/scales": "the monitors' error scales",
    "restart/count": "the number of checkpoints",
    "restart/order": "the bodies' order in the checkpoints",
    "restart/x": "the checkpoints' positions",
    "restart/v": "the checkpoints' velocities",
    "restart/clock": "the checkpoints' step counts",
    "restart/t_base": "the checkpoints' times",
    "restart/plan": "the checkpoints' run plans",
    "restart/progress": "the checkpoints' progress",
}
# (each checked where present: older files have no particles/bodies/radius)
_UNITS = ("particles/bodies/mass", "particles/bodies/radius",
          "particles/bodies/position/time", "particles/bodies/position/value",
          "particles/bodies/velocity/value")
_PARAMETERS = ("orbits_version", "written", "integrator", "integrator_options",
               "integrator_info", "dt", "dt_unit", "units", "monitors", "bodies_history")


def _check_layout(f, path, contents):
    """Raise an OrbitsFileError naming, in words, what the layout misses
    (``contents``: the file's :func:`_inventory`)."""
    missing = []
    absent = set()

    def exists(name, kind):
        if name in absent:
            return False
        parent, _, _ = name.rpartition("/")
        if parent and not exists(parent, h5py.Group):
            return False
        if name in (contents.groups if kind is h5py.Group else contents.datasets):
            return True
        absent.add(name)
        what = _GROUPS.get(name) or _DATASETS.get(name, "")
        noun = "the group /" if kind is h5py.Group else "/"
        missing.append(f"{noun}{name} ({what})" if what else f"{noun}{name}")
        return False

    for name in _DATASETS:
        exists(name, h5py.Dataset)
    exists("observables/in_loop", h5py.Group)
    exists("restart/ws", h5py.Group)
    monitors = ()
    if "parameters" in contents.groups:
        par = f["parameters"].attrs
        missing += [f"the attribute {k!r} of /parameters (the run's metadata)"
                    for k in _PARAMETERS if k not in par]
        if "monitors" in par:
            monitors = _monitors_attr(f["parameters"], path)
    for name in monitors:
        for part in ("step", "time", "value"):
            exists(f"observables/{name}/{part}", h5py.Dataset)
            exists(f"observables/in_loop/{name}/{part}", h5py.Dataset)
    for name in _UNITS:
        obj = f.get(name) if not missing else None
        if isinstance(obj, h5py.Dataset) and "unit" not in obj.attrs:
            missing.append(f"the unit of /{name}")
    if missing:
        shown = missing[:6] + ([f"and {len(missing) - 6} more"] if len(missing) > 6 else [])
        raise OrbitsFileError(f"{path}: damaged or incomplete orbits file: missing "
                              + "; ".join(shown))
    return monitors


def _open_read(path):
    path = pathlib.Path(path)
    if not path.exists():
        raise OrbitsFileError(f"{path}: no such file")
    if path.is_dir():
        raise OrbitsFileError(f"{path}: a folder, not an orbits output file")
    f = _open_hdf5(path)
    try:
        fmt = f.attrs.get("orbits_format")
        if not isinstance(fmt, str) or fmt != FORMAT:
            raise OrbitsFileError(f"{path}: not an orbits output file (no "
                                  f"orbits_format = {FORMAT!r} attribute)")
        version = f.attrs.get("orbits_format_version", -1)
        if not _is_int(version) or version != FORMAT_VERSION:
            shown = int(version) if _is_int(version) else repr(version)
            raise OrbitsFileError(f"{path}: layout version {shown}, but this orbits "
                                  f"reads version {FORMAT_VERSION}")
        # nothing is opened by name before the links are known to stay in the file
        contents = _inventory(f, path)
        _check_values(f, contents.datasets, path, _check_layout(f, path, contents))
    except BaseException as exc:
        f.close()
        if isinstance(exc, (OSError, RuntimeError)) and not isinstance(exc, OrbitsFileError):
            raise OrbitsFileError(f"{path}: damaged orbits file: {exc}") from None
        raise
    return f


def _decode(a):
    return [s.decode() if isinstance(s, bytes) else str(s) for s in a]


# -- what a reader trusts --------------------------------------------------------------
#
# A file carries data, never code, and its declared shapes are claims: nothing
# it names is imported, nothing outside it is read, and every shape, type and
# control value is checked against the file's own counts and size before a
# reader allocates for it or acts on it.

#: HDF5 filters that the library and h5py provide; any other is found and
#: loaded as a plugin, code that a file would choose
_KNOWN_FILTERS = {h5py.h5z.FILTER_DEFLATE: "gzip", h5py.h5z.FILTER_SHUFFLE: "shuffle",
                  h5py.h5z.FILTER_FLETCHER32: "fletcher32", h5py.h5z.FILTER_LZF: "lzf"}
#: the most bytes of data a filtered byte of storage gives back: deflate's
#: limit (a 258-byte match in a 2-bit code, 1032 : 1; RFC 1951), which LZF
#: (at most 264 bytes from 2) stays below
_FILTER_EXPANSION = 1032
#: links a file may hold; an orbits file holds about fifty
_MAX_LINKS = 10_000
#: bytes a file keeps for each variable-length string (its global heap id)
_VLEN_BYTES = 16


class _Contents(NamedTuple):
    """A file's datasets (name -> :class:`_Stored`) and groups (names), as hard
    links reach them."""

    datasets: dict
    groups: set


class _Stored(NamedTuple):
    """What the file says of one dataset, read without reading its data."""

    shape: tuple        # None for a dataset without a dataspace
    dtype: np.dtype     # None for a type numpy has no match for
    stored: int         # the most bytes of data its storage gives back


def _inventory(f, path):
    """The file's :class:`_Contents`: every group, and every dataset with what
    the file says of it (:class:`_Stored`); an OrbitsFileError
    for anything that reaches outside the file or loads code: external and
    user-defined links, datasets whose storage is external files or a virtual
    mapping of other datasets, and filters other than those h5py provides.
    Taken before anything in the file is opened by name, since opening an
    external link opens the file it names."""
    names = []
    seen = []

    def visit(name, info):
        seen.append(None)
        if len(seen) > _MAX_LINKS:
            return f"it holds more than {_MAX_LINKS} links (an orbits file holds about fifty)"
        if info.type == h5py.h5l.TYPE_HARD:
            names.append(name)
        elif info.type != h5py.h5l.TYPE_SOFT:       # soft links stay inside the file
            what = ("an external link" if info.type == h5py.h5l.TYPE_EXTERNAL
                    else f"a user-defined link (type {info.type})")
            return f"/{name.decode(errors='replace')} is {what}, which leaves the file"
        return None

    refused = f.id.links.visit(visit, info=True)
    out, groups = {}, set()
    for name in names if refused is None else ():
        obj = h5py.h5o.open(f.id, name)
        shown = name.decode(errors="replace")
        if isinstance(obj, h5py.h5g.GroupID):
            groups.add(shown)
        if not isinstance(obj, h5py.h5d.DatasetID):
            continue
        dcpl = obj.get_create_plist()
        codes = [dcpl.get_filter(k)[0] for k in range(dcpl.get_nfilters())]
        unknown = [code for code in codes if code not in _KNOWN_FILTERS]
        if dcpl.get_layout() == h5py.h5d.VIRTUAL:
            refused = f"/{shown} is a virtual dataset (a view of other datasets or files)"
        elif dcpl.get_external_count():
            refused = f"/{shown} keeps its data in external files"
        elif unknown:
            refused = (f"/{shown} is stored through HDF5 filter {unknown[0]}, which would be "
                       f"loaded as a plugin (known filters: "
                       f"{', '.join(_KNOWN_FILTERS.values())})")
        if refused:
            break
        try:
            dtype = obj.dtype
        except (TypeError, ValueError):     # a type numpy has no match for: never read
            dtype = None
        stored = obj.get_storage_size() * (_FILTER_EXPANSION if codes else 1)
        out[shown] = _Stored(obj.shape, dtype, stored)
    if refused:
        raise OrbitsFileError(f"{path}: refused: {refused}; an orbits file keeps all of its "
                              f"data inside itself")
    return _Contents(out, groups)


def _covered(ds):
    """The rows of a time series ``ds`` (axis 0) that its storage holds: its
    declared length, but no more than the bytes the file keeps for it.  Rows
    declared beyond them (a writer killed between extending a series and
    flushing its data, or a crafted file) hold no data and are not read."""
    element = _VLEN_BYTES if ds.dtype.kind == "O" else ds.dtype.itemsize
    row = element * int(np.prod(ds.shape[1:], dtype=np.int64))
    stored = ds.id.get_storage_size()
    if ds.id.get_create_plist().get_nfilters():
        stored *= _FILTER_EXPANSION
    return min(ds.shape[0], stored // max(row, 1))


_KINDS = {"float": "f", "int": "iu", "str": "OS", "number": "fiub"}


def _checked(stored, name, path, shape, kind, backed=True):
    """The :class:`_Stored` of the dataset ``name``, checked before anything is
    read from it: its ``shape`` (None for an axis of any length), its type,
    and (``backed``) that the file stores all the data that shape declares."""
    ds = stored.get(name)
    if ds is None:
        raise OrbitsFileError(f"{path}: damaged or incomplete orbits file: /{name} is not "
                              f"a dataset")
    if ds.shape is None or len(ds.shape) != len(shape) or any(
            want is not None and have != want for have, want in zip(ds.shape, shape)):
        want = "(" + ", ".join("any" if k is None else str(k) for k in shape) + \
            ("," if len(shape) == 1 else "") + ")"
        raise OrbitsFileError(f"{path}: /{name} has shape {ds.shape}; expected {want}")
    ok = ds.dtype is not None and ds.dtype.kind in _KINDS[kind]
    if ok and ds.dtype.kind == "O":
        ok = kind == "str" and h5py.check_string_dtype(ds.dtype) is not None
    if not ok:
        raise OrbitsFileError(f"{path}: /{name} holds values of type {ds.dtype}; expected "
                              f"{'strings' if kind == 'str' else kind + 's'}")
    element = _VLEN_BYTES if ds.dtype.kind == "O" else ds.dtype.itemsize
    declared = int(np.prod(ds.shape, dtype=np.int64)) * element
    if backed and declared > ds.stored:
        raise OrbitsFileError(
            f"{path}: /{name} declares shape {ds.shape} ({declared} bytes), but the file "
            f"stores less of it; refused before reading")
    return ds


@functools.lru_cache(maxsize=256)
def _parsed_unit(text, like):
    """``(unit, of the kind of like)`` for a unit's name; None if it names none
    (parsed once: astropy takes about a millisecond for ``"AU / d"``).  The
    empty name, plain numbers, stands for every kind: N-body units
    (``UnitSystem.nbody()``) write it for lengths, masses and times alike."""
    import astropy.units as u
    try:
        unit = u.Unit(text)
    except (ValueError, TypeError):
        return None
    return unit, (like is None or unit == u.dimensionless_unscaled
                  or unit.is_equivalent(u.Unit(like)))


#: the physical type that a unit's name in _unit's ``like`` stands for
_KIND_OF = {"m": "length", "kg": "mass", "s": "time", "m / s": "speed"}


def _unit(f, name, path, like=None):
    """The ``unit`` attribute of the dataset ``name``, parsed, and (``like``, a
    unit's name) of the physical type of that unit."""
    text = f[name].attrs.get("unit")
    parsed = _parsed_unit(text, like) if isinstance(text, str) else None
    if parsed is None:
        raise OrbitsFileError(f"{path}: /{name} has the unit {text!r}; expected a unit's "
                              f"name")
    if not parsed[1]:
        raise OrbitsFileError(f"{path}: /{name} has the unit {text!r}; expected a unit of "
                              f"{_KIND_OF[like]}")
    return parsed[0]


def _json_attr(par, key, path, kind):
    """The /parameters attribute ``key``, a JSON text, parsed and of type ``kind``."""
    text = par.attrs[key]
    try:
        value = json.loads(text)
    except (TypeError, ValueError, RecursionError):
        raise OrbitsFileError(f"{path}: the {key!r} attribute of /parameters is not "
                              f"readable JSON") from None
    if not isinstance(value, kind):
        raise OrbitsFileError(f"{path}: the {key!r} attribute of /parameters is "
                              f"{type(value).__name__}; expected a JSON "
                              f"{'object' if kind is dict else 'array'}")
    return value


def _monitors_attr(par, path):
    """The monitors a file records: a list of distinct known names."""
    monitors = _json_attr(par, "monitors", path, list)
    known = [name for name in _MONITOR_KIND if name != "work"]
    for name in monitors:
        if not isinstance(name, str) or name not in known:
            raise OrbitsFileError(f"{path}: the 'monitors' attribute of /parameters names "
                                  f"{name!r}; expected monitors among {', '.join(known)}")
    if len(set(monitors)) != len(monitors):
        raise OrbitsFileError(f"{path}: the 'monitors' attribute of /parameters names a "
                              f"monitor twice: {monitors}")
    return tuple(monitors)


def _is_int(value):
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def _is_number(value):
    return isinstance(value, (int, float, np.integer, np.floating)) and \
        not isinstance(value, (bool, np.bool_)) and math.isfinite(value)


def _attr(par, key, path, check, expected):
    value = par.attrs[key]
    if not check(value):
        raise OrbitsFileError(f"{path}: the {key!r} attribute of /parameters is {value!r}; "
                              f"expected {expected}")
    return value


def _epoch(par, path):
    """The file's epoch (``astropy.time.Time``, TDB) from the ``epoch_tdb``
    attribute of /parameters, or None where it has none; an
    :class:`OrbitsFileError` where the attribute is not two finite float64
    parts of a Julian date (``|jd2| <= 1``, as :func:`orbits.epochs.to_pair`
    writes them)."""
    if "epoch_tdb" not in par.attrs:
        return None
    value = par.attrs["epoch_tdb"]
    arr = np.asarray(value)
    ok = arr.shape == (2,) and arr.dtype.kind == "f"
    if ok:
        jd1, jd2 = (float(a) for a in arr)
        ok = math.isfinite(jd1) and math.isfinite(jd2) and abs(jd2) <= 1.0 \
            and abs(jd1) < _EPOCH_JD_LIMIT
    if not ok:
        raise OrbitsFileError(f"{path}: the 'epoch_tdb' attribute of /parameters is "
                              f"{value!r}; expected the Julian date of the run's time 0 in "
                              f"TDB as two float64 parts (jd1, jd2), |jd2| <= 1")
    return _epochs.from_pair(jd1, jd2)


def _check_units_record(units, path):
    """Raise an OrbitsFileError where the unit system a file records (a
    UnitSystem.to_dict()) does not have the fields and kinds of units it needs."""
    plain = []
    for key, like in (("length", "m"), ("mass", "kg"), ("time", "s")):
        text = units.get(key)
        parsed = _parsed_unit(text, like) if isinstance(text, str) else None
        if parsed is None or not parsed[1]:
            raise OrbitsFileError(f"{path}: the unit system in /parameters has {key} "
                                  f"{text!r}; expected a unit of {_KIND_OF[like]}")
        plain.append(text == "")
    if any(plain) and not all(plain):
        raise OrbitsFileError(f"{path}: the unit system in /parameters has plain numbers "
                              f"for some of length, mass and time but not all: "
                              f"{[units[k] for k in ('length', 'mass', 'time')]}")
    if not (_is_number(units.get("G")) and units["G"] > 0):
        raise OrbitsFileError(f"{path}: the unit system in /parameters has G = "
                              f"{units.get('G')!r}; expected a number > 0")
    for key in ("name", "G_source"):
        if not isinstance(units.get(key), str):
            raise OrbitsFileError(f"{path}: the unit system in /parameters has {key} "
                                  f"{units.get(key)!r}; expected a string")


def _unit_system(par, path):
    """The UnitSystem of a file's /parameters (checked by :func:`_check_values`)."""
    import astropy.units as u
    from ..units import UnitSystem
    try:
        return UnitSystem.from_dict(json.loads(par.attrs["units"]))
    except (OrbitsError, ValueError, TypeError, u.UnitsError) as exc:
        raise OrbitsFileError(f"{path}: the unit system in /parameters does not rebuild: "
                              f"{exc}") from None


def _check_config(config, path, monitors):
    """Raise an OrbitsFileError where the configuration record (a
    SimulationConfig.to_dict()) a file keeps is not of the types that record has."""
    def bad(field, value, expected):
        return OrbitsFileError(f"{path}: the configuration in /parameters has {field} = "
                               f"{value!r}; expected {expected}")

    def quantity(value):
        return (isinstance(value, list) and len(value) == 2 and isinstance(value[1], str)
                and (_is_number(value[0]) or isinstance(value[0], list)))

    for key in ("integrator", "integrator_options", "dt", "forces", "monitors",
                "monitor_every", "stop_conditions"):
        if key not in config:
            raise OrbitsFileError(f"{path}: the configuration in /parameters lacks "
                                  f"{key!r}")
    if not isinstance(config["integrator"], str):
        raise bad("integrator", config["integrator"], "an integrator's name")
    if not isinstance(config["integrator_options"], dict):
        raise bad("integrator_options", config["integrator_options"], "a JSON object")
    if config["dt"] is not None and not quantity(config["dt"]):
        raise bad("dt", config["dt"], "null or [value, unit]")
    forces = config["forces"]
    if not isinstance(forces, list) or not forces or not all(
            isinstance(d, dict) and isinstance(d.get("type"), str) for d in forces):
        raise bad("forces", forces, "a list of force terms' records, gravity's first")
    if config["monitors"] != list(monitors):
        raise bad("monitors", config["monitors"],
                  f"the monitors the file keeps, {list(monitors)}")
    every = config["monitor_every"]
    if every is not None and not (_is_int(every) and every >= 1):
        raise bad("monitor_every", every, "null or a whole number >= 1")
    stops = config["stop_conditions"]
    if not isinstance(stops, dict) or not all(
            v is None or isinstance(v, (bool, str)) or _is_number(v) or quantity(v)
            for v in stops.values()):
        raise bad("stop_conditions", stops, "an object of numbers, names and [value, unit]")
    variations = config.get("variations")
    if not (variations is None or variations in ("state", "all")
            or (_is_int(variations) and variations >= 1)):
        raise bad("variations", variations, 'null, "state", "all" or a whole number >= 1')
    seed = config.get("seed")
    if seed is not None and not (_is_int(seed) and seed >= 0):
        raise bad("seed", seed, "null or a whole number >= 0")


def _check_values(f, stored, path, monitors):
    """Raise an OrbitsFileError for a value a reader would use that is not of the
    type, shape or range the layout gives it; called by :func:`_open_read`
    once the layout is complete, with the file's :func:`_inventory`.

    Shapes are checked against the bodies' count and the file's own size
    before anything is read, so that a small file cannot make a reader
    allocate for data it does not hold; the control values (the checkpoints'
    count, clock, plan and progress) are read and checked.
    """
    par = f["parameters"]
    for key in ("orbits_version", "written", "integrator", "dt_unit"):
        _attr(par, key, path, lambda v: isinstance(v, str), "a string")
    _attr(par, "dt", path, lambda v: _is_number(v) and v >= 0, "a number >= 0")
    parsed = _parsed_unit(par.attrs["dt_unit"], "s")
    if parsed is None or not parsed[1]:
        raise OrbitsFileError(f"{path}: the 'dt_unit' attribute of /parameters is "
                              f"{par.attrs['dt_unit']!r}; expected a unit of time")
    _json_attr(par, "integrator_options", path, dict)
    info = _json_attr(par, "integrator_info", path, dict)
    if not (isinstance(info.get("name"), str) and _is_int(info.get("order"))
            and isinstance(info.get("symplectic"), bool)
            and isinstance(info.get("adaptive", False), bool)):
        raise OrbitsFileError(f"{path}: the 'integrator_info' attribute of /parameters is "
                              f"{info!r}; expected the integrator's name, order and kind")
    _json_attr(par, "bodies_history", path, list)
    _check_units_record(_json_attr(par, "units", path, dict), path)
    if "forces" in par.attrs:
        records = _json_attr(par, "forces", path, list)
        if not all(isinstance(d, dict) and isinstance(d.get("type"), str) for d in records):
            raise OrbitsFileError(f"{path}: the 'forces' attribute of /parameters is "
                                  f"{records!r}; expected force terms' records")
    if "config" in par.attrs:
        _check_config(_json_attr(par, "config", path, dict), path, monitors)
    _epoch(par, path)

    # the bodies: their count N is the length of every per-body axis
    b = "particles/bodies"
    n = _checked(stored, f"{b}/names", path, (None,), "str").shape[0]
    if n < 1:
        raise OrbitsFileError(f"{path}: /{b}/names is empty; expected one name a body")
    _checked(stored, f"{b}/mass", path, (n,), "float")
    _unit(f, f"{b}/mass", path, "kg")
    if f"{b}/radius" in stored:
        _checked(stored, f"{b}/radius", path, (n,), "float")
        _unit(f, f"{b}/radius", path, "m")
    # the time series: any number of rows, of which only those stored are read
    series = {f"{b}/position": ((n, 3), "m"), f"{b}/velocity": ((n, 3), "m / s")}
    if f"{b}/masses_at_outputs/value" in stored:
        series[f"{b}/masses_at_outputs"] = ((n,), "kg")
    kept = list(monitors) + (["work"] if "observables/work/value" in stored else [])
    for name in kept:
        shape = () if name in _SCALAR_SERIES else (3,)
        series[f"observables/{name}"] = (shape, None)
        if f"observables/in_loop/{name}/value" in stored:
            series[f"observables/in_loop/{name}"] = (shape, None)
    for group, (shape, like) in series.items():
        _checked(stored, f"{group}/step", path, (None,), "int", backed=False)
        _checked(stored, f"{group}/time", path, (None,), "float", backed=False)
        _checked(stored, f"{group}/value", path, (None,) + shape, "float", backed=False)
        _unit(f, f"{group}/time", path, "s")
        _unit(f, f"{group}/value", path, like)
    # the parameters' arrays
    width = len(_inv.MONITOR_COLUMNS)
    ref = _checked(stored, "parameters/reference", path, (None,), "float")
    if not 10 <= ref.shape[0] <= width:
        raise OrbitsFileError(f"{path}: /parameters/reference has {ref.shape[0]} values; "
                              f"expected 10 to {width}")
    _checked(stored, "parameters/scales", path, (2,), "float")
    if "parameters/start_clock" in stored:
        _checked(stored, "parameters/start_clock", path, (3,), "int")
        start = par["start_clock"][()]
        if (start < 0).any():
            raise OrbitsFileError(f"{path}: /parameters/start_clock is {start.tolist()}; "
                                  f"expected counts >= 0")
    _check_restart(f, stored, path, n)
    # the logs, one row per event
    for group, columns in (("collisions", _COLLISION_COLUMNS),
                           ("encounters", _ENCOUNTER_COLUMNS)):
        if group in f:
            _check_log(f, stored, group, columns, path)


def _check_restart(f, stored, path, n):
    r = "restart"
    _checked(stored, f"{r}/count", path, (), "int")
    count = f[r]["count"][()]
    if count < 0:
        raise OrbitsFileError(f"{path}: /{r}/count is {count}; expected the number of "
                              f"checkpoints written, >= 0")
    written = count > 0          # the slots hold data only once one was written
    _checked(stored, f"{r}/order", path, (n,), "int")
    order = f[r]["order"][()]
    if not np.array_equal(np.sort(order), np.arange(n)):
        raise OrbitsFileError(f"{path}: /{r}/order is not an order of the {n} bodies (a "
                              f"permutation of 0 .. {n - 1})")
    arrays = {"x": ((_SLOTS, n, 3), "float"), "v": ((_SLOTS, n, 3), "float"),
              "clock": ((_SLOTS, 5), "int"), "t_base": ((_SLOTS,), "float"),
              "plan": ((_SLOTS, 7), "float"), "progress": ((_SLOTS, 3), "int"),
              "wall": ((_SLOTS,), "float"), "masses": ((_SLOTS, n), "float"),
              "radii": ((_SLOTS, n), "float"), "orders": ((_SLOTS, n), "int")}
    varying = [name in stored for name in (f"{r}/masses", f"{r}/radii", f"{r}/orders")]
    if any(varying) and not all(varying):
        raise OrbitsFileError(f"{path}: /{r} holds some of masses, radii and orders but "
                              f"not all three")
    for name, (shape, kind) in arrays.items():
        if f"{r}/{name}" in stored:
            _checked(stored, f"{r}/{name}", path, shape, kind, backed=written)
    g = f[r]
    # tangent vectors of a shape other than the configuration's are named by
    # TangentShapeError where they would be read (_check_tangent_rows,
    # _derivatives), before anything is read from them
    k = sum(_config_layout(_config(f), n))
    tangent_shapes = {"tangent": (_SLOTS, 2, n * k, 3), "tangent_vectors": (_SLOTS, k, n, 6)}
    for name, ds in g["ws"].items():
        shape = stored[f"{r}/ws/{name}"].shape or ()
        d = _checked(stored, f"{r}/ws/{name}", path, (_SLOTS,) + (None,) * (
            max(1, len(shape)) - 1), "number",
            backed=written and tangent_shapes.get(name, shape) == shape)
        if "body_axes" in ds.attrs:
            axes = ds.attrs["body_axes"]
            if not (isinstance(axes, np.ndarray) and axes.ndim == 1
                    and (axes.dtype.kind in "iu" or axes.size == 0)
                    and all(0 <= k < len(d.shape) - 1 for k in axes.tolist())):
                raise OrbitsFileError(f"{path}: /{r}/ws/{name} has body_axes {axes!r}; "
                                      f"expected axes of its slot's shape {d.shape[1:]}")
    if f"{r}/tangent_vectors" in stored:
        _checked(stored, f"{r}/tangent_vectors", path, (_SLOTS, None, n, 6), "float",
                 backed=written and tangent_shapes["tangent_vectors"]
                 == stored[f"{r}/tangent_vectors"].shape)
        layout = g["tangent_vectors"].attrs.get("layout")
        if layout is not None and not (isinstance(layout, np.ndarray)
                                       and layout.shape == (4,) and layout.dtype.kind in "iu"
                                       and (layout >= 0).all()):
            raise OrbitsFileError(f"{path}: /{r}/tangent_vectors has the layout {layout!r}; "
                                  f"expected four counts (chaos, random, state, mass)")
    if written:
        _check_slot(g, path, (count - 1) % _SLOTS)


def _check_slot(g, path, slot):
    # the control values of the checkpoint in ``slot`` of the group /restart ``g``
    def bad(name, value, expected):
        return OrbitsFileError(f"{path}: /restart/{name} at the last checkpoint (slot "
                               f"{slot}) is {value}; expected {expected}")

    clock = g["clock"][slot]
    # every count but steps_since_base, which a run backwards counts down
    if (np.delete(clock, 1) < 0).any():
        raise bad("clock", clock.tolist(), "counts of steps, force evaluations, rows and "
                                           "rejected steps, each >= 0")
    t_base = float(g["t_base"][slot])
    if not math.isfinite(t_base):
        raise bad("t_base", t_base, "a finite time")
    plan = g["plan"][slot]
    until, outputs, ratio, n_full, partial, start_step, start_time = plan.tolist()
    whole = lambda x: x == int(x) and x >= 0  # noqa: E731
    if not (np.isfinite(plan).all() and whole(outputs) and outputs >= 1 and whole(n_full)
            and partial in (0.0, 1.0) and whole(start_step) and ratio >= 0):
        raise bad("plan", plan.tolist(), "a run's plan: finite times, a whole number of "
                                         "outputs >= 1, whole step counts >= 0")
    # the checkpoint's time lies within its run: from the plan's start to its
    # end, either way, up to a step and rounding (steps_since_base may be
    # negative, so its sign says nothing by itself)
    dt = float(g.file["parameters"].attrs["dt"])
    t = t_base + clock[1] * dt
    slack = dt + 1e-9 * max(abs(until), abs(start_time), 1.0)
    if not min(start_time, until) - slack <= t <= max(start_time, until) + slack:
        raise bad("clock", clock.tolist(),
                  f"a clock whose time, t_base + steps_since_base * dt = {t:.10g}, lies "
                  f"within its run, from {start_time:.10g} to {until:.10g}")
    done, finished, code = g["progress"][slot].tolist()
    if not (0 <= done <= outputs and finished in (0, 1) and code >= 0):
        raise bad("progress", [done, finished, code],
                  f"(outputs written, 0 .. {int(outputs)}; finished, 0 or 1; status >= 0)")
    if "wall" in g:
        wall = float(g["wall"][slot])
        if not (math.isfinite(wall) and wall >= 0):
            raise bad("wall", wall, "seconds >= 0")
    if "masses" in g:
        m = g["masses"][slot]
        alive = np.isfinite(m)
        left = int(alive.sum())
        orders = g["orders"][slot]
        if (m[alive] < 0).any() or left < 1 or not np.array_equal(
                np.sort(orders[:left]), np.arange(left)) or (orders[left:] != -1).any():
            raise bad("masses and orders", f"{m.tolist()} and {orders.tolist()}",
                      "masses >= 0 (NaN for a body merged away) and the order of the "
                      "bodies left, then -1")


#: the columns of the logs and the type of each
_COLLISION_COLUMNS = {"time": "float", "step_time": "float", "body_1": "str", "body_2": "str",
                      "resolution": "str", "survivor": "str", "distance": "float",
                      "speed": "float", "energy_change": "float"}
_ENCOUNTER_COLUMNS = {"time": "float", "body_1": "str", "body_2": "str", "distance": "float",
                      "speed": "float"}


def _check_log(f, stored, group, columns, path):
    # columns of any length (a live writer extends one before the next): the
    # readers take the rows all of them store (_log_rows)
    for name, kind in columns.items():
        _checked(stored, f"{group}/{name}", path, (None,), kind, backed=False)
        if kind == "float":
            _unit(f, f"{group}/{name}", path)


def _log_rows(g, columns):
    """The rows of a log (group ``collisions`` or ``encounters``) that every one
    of its columns stores."""
    return min(_covered(g[name]) for name in columns)


# -- the writers' lock ---------------------------------------------------------------------

_HELD = {}      # lock path -> token, for the locks this process holds


def _lock_path(path):
    return pathlib.Path(os.path.abspath(path) + ".lock")


def _process_start(pid):
    """(state, start time in clock ticks) of a process on this host, from /proc; or None."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            text = fh.read()
    except OSError:
        return None
    fields = text[text.rindex(")") + 2:].split()
    return fields[0], int(fields[19])           # stat(5) fields 3 and 22


#: the most bytes of a writers' lock read (one holds about 150)
_LOCK_BYTES = 4096


def _read_lock(lock):
    """The lock's record; None if there is no lock, {} if it cannot be read.

    Read without following a link, and only from a regular file, the kind a
    writer makes (a link to a named pipe would block the read for ever).
    """
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
    try:
        fd = os.open(lock, flags)
    except FileNotFoundError:
        return None
    except OSError:
        return {}
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return {}
        text = os.read(fd, _LOCK_BYTES).decode("utf-8", "replace")
    except OSError:
        return {}
    finally:
        os.close(fd)
    try:
        rec = json.loads(text)
    except ValueError:
        return {}
    return rec if isinstance(rec, dict) else {}


def _alive(rec):
    """Whether the lock's process runs: True, False, or None where it cannot be told."""
    if rec.get("host") != socket.gethostname():
        return None
    pid = rec.get("pid")
    if not isinstance(pid, int) or pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass
    found = _process_start(pid)
    if found is not None:
        state, start = found
        if state in ("Z", "X"):                 # exited, not yet reaped
            return False
        if rec.get("start") is not None and rec["start"] != start:
            return False                        # the pid was reused
    return True


def _writer(path):
    """``(record, alive)`` of the lock on ``path``; ``(None, False)`` if there is none."""
    rec = _read_lock(_lock_path(path))
    if rec is None:
        return None, False
    if not rec:
        return rec, None
    return rec, _alive(rec)


def _acquire(path):
    """Take the writers' lock of ``path`` (or keep it, if this process holds it)."""
    lock = _lock_path(path)
    key = str(lock)
    if key in _HELD and (_read_lock(lock) or {}).get("token") == _HELD[key]:
        return
    started = _process_start(os.getpid())
    token = uuid.uuid4().hex
    me = {"host": socket.gethostname(), "pid": os.getpid(),
          "start": started[1] if started else None, "token": token,
          "since": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}
    tmp = lock.with_name(f"{lock.name}.{token}")
    made = False
    try:
        with open(tmp, "x") as fh:              # a new file, never one a link names
            made = True
            fh.write(json.dumps(me))
    except OSError as exc:
        if made:
            tmp.unlink(missing_ok=True)
        raise _write_error(path, exc, f"when making its writers' lock {lock}") from None
    try:
        for _ in range(5):
            if _link(tmp, lock):
                _HELD[key] = token
                return
            rec = _read_lock(lock)
            if rec is None:
                continue                        # released meanwhile
            alive = _alive(rec) if rec else None
            if not rec:
                try:
                    info = lock.lstat()
                except FileNotFoundError:
                    continue
                # a writer's lock is a regular file: anything else there (a
                # link, a pipe) is not one, and is taken over at once
                if not stat.S_ISREG(info.st_mode) or \
                        _time.time() - info.st_mtime > _LOCK_UNREADABLE_SECONDS:
                    alive = False
            if alive is False:
                _remove_stale(lock, rec)
                continue
            raise _in_use(path, lock, rec)
        raise FileInUse(f"{path}: could not take its lock {lock} (other writers keep "
                        f"taking it)")
    except OrbitsFileError:
        raise
    except OSError as exc:
        raise _write_error(path, exc, f"when taking its writers' lock {lock}") from None
    finally:
        tmp.unlink(missing_ok=True)


def _link(tmp, lock):
    # the lock appears whole: a hard link made only if nothing has the name
    try:
        os.link(tmp, lock)
        return True
    except FileExistsError:
        return False
    except OSError:                             # a file system without hard links
        try:
            fd = os.open(lock, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
        except FileExistsError:
            return False
        with os.fdopen(fd, "w") as fh:
            fh.write(tmp.read_text())
        return True


def _remove_stale(lock, rec):
    # renamed away first, so that of two processes taking it over only one
    # removes it, and a lock taken meanwhile by a live writer is put back
    grave = lock.with_name(f"{lock.name}.stale.{uuid.uuid4().hex}")
    try:
        os.rename(lock, grave)
    except FileNotFoundError:
        return
    if _read_lock(grave) != rec:
        _link(grave, lock)
    grave.unlink(missing_ok=True)


def _in_use(path, lock, rec):
    pid, host = rec.get("pid"), rec.get("host")
    if not rec:
        who = "another process (its lock cannot be read yet)"
    elif host == socket.gethostname():
        who = f"process {pid}"
    else:
        who = f"process {pid} on host {host!r}"
    since = f" since {rec['since']}" if rec.get("since") else ""
    return FileInUse(f"{path}: being written by {who}{since} (lock {lock}); wait for it "
                     f"to finish or stop it first"
                     + ("; if that process is gone, delete the lock file"
                        if rec and host != socket.gethostname() else ""),
                     pid=pid, host=host)


def _release(path):
    lock = _lock_path(path)
    token = _HELD.pop(str(lock), None)
    if token is not None and (_read_lock(lock) or {}).get("token") == token:
        lock.unlink(missing_ok=True)


# -- writing safely --------------------------------------------------------------------
#
# HDF5 closing a dataset or a file flushes it first.  Where that flush fails (a
# full disk), HDF5 frees the object but keeps its identifier, and closes it
# again when the library shuts down at exit: a use after free, and the
# interpreter's segmentation fault after a full disk.  So space is reserved on
# disk ahead of what a write takes (_reserve), which makes a full disk show as
# a failed reservation between two writes, with nothing pending that cannot be
# written; and a file whose writes failed anyway (a file system that cannot
# reserve) is closed with what HDF5 still holds for it sent to /dev/null
# (_abandon).  Temporary files are made exclusively (_new_file).

#: errno values of a full disk: no space left, a file larger than allowed (the
#: file system's limit, or ``ulimit -f``), the user's quota used up
_DISK_FULL = (errno.ENOSPC, errno.EFBIG, errno.EDQUOT)
#: bytes reserved beyond what the next write needs, so that the disk is asked
#: for space about once per this much output rather than at every write
_RESERVE_BYTES = 4 << 20
#: bytes of HDF5's own bookkeeping a write may add besides the data and the
#: chunks it starts (chunk indexes, object headers, heaps).  Measured: the
#: largest growth of a file past the data of one write, in runs of 2 and 6
#: bodies (fixed steps, ias15 with a checkpoint at every output, in-loop
#: monitors, variations), was 0.2 to 0.5 MB (the first write, which starts a
#: chunk of every series), against a headroom of 0.8 to 1 MB with this
_METADATA_BYTES = 1 << 19
#: bytes reserved for a row of the collision or encounter log (a few floats,
#: and names kept in HDF5's global heap)
_LOG_ROW_BYTES = 1024


class _NoRoom(OSError):
    """The disk has no room for what the next write may take (see _reserve)."""


def _error_number(exc):
    """The errno of an error of writing: an OSError's own, or the one HDF5 names in
    the message h5py passes on (``..., errno = 28, error message = ...``)."""
    code = getattr(exc, "errno", None)
    if code is None:
        found = re.search(r"errno = (\d+)", str(exc))
        code = int(found.group(1)) if found else None
    return code


def _write_error(path, exc, then=""):
    """The OrbitsFileError of ``exc``, an error of writing ``path``: one that says the
    disk is full where the file system said so, with the errno on ``.errno``;
    ``then`` follows the first clause."""
    code = _error_number(exc)
    if code in _DISK_FULL:
        what = f"the disk is full ({os.strerror(code)})"
    else:
        what = f"cannot be written ({os.strerror(code) if code else exc})"
    err = OrbitsFileError(f"{path}: {what}{then}")
    err.errno = code
    return err


def _reserve(fd, end, need):
    """Have the disk hold ``need`` bytes for the file open on ``fd`` beyond ``end``
    (where HDF5 allocates next), and :data:`_RESERVE_BYTES` more if it can.

    ``posix_fallocate`` allocates the blocks, so that the writes after it
    cannot fail for space (on a file system that writes in place; one that
    copies on write, such as btrfs or ZFS, may still run out); the file grows
    past its end meanwhile, and :func:`_trim` gives that back when it
    closes.  Returns False where the file system (or the platform) cannot
    reserve space: the writes then go on unreserved.  Raises
    :class:`_NoRoom` where there is no room for ``need``.
    """
    want = end + need
    size = os.fstat(fd).st_size
    if size >= want:
        return True
    fallocate = getattr(os, "posix_fallocate", None)     # not on macOS or Windows
    if fallocate is None:
        return False
    limit = resource.getrlimit(resource.RLIMIT_FSIZE)[0] if resource else None
    failed = None
    for target in (want + _RESERVE_BYTES, want):
        if limit is not None and limit != resource.RLIM_INFINITY and target > limit:
            # past ulimit -f the kernel would end the process (SIGXFSZ)
            failed = errno.EFBIG
            continue
        try:
            fallocate(fd, size, target - size)
            return True
        except OSError as exc:
            if exc.errno not in _DISK_FULL:
                return False
            failed = exc.errno
    raise _NoRoom(failed, os.strerror(failed))


def _descriptor(f):
    """The descriptor HDF5 writes the open file ``f`` through (its sec2 driver), or None."""
    try:
        return f.id.get_vfd_handle()
    except (NotImplementedError, ValueError, RuntimeError, OSError):
        return None


def _abandon(f):
    """Close ``f``, whose writes fail, without writing to it again.

    What HDF5 still holds to write is sent to /dev/null: its descriptor is
    pointed there, so that every close succeeds and HDF5 keeps no freed
    object for its shutdown at exit.  The file on disk keeps what was
    written before, and stays marked as being written, as a killed writer
    leaves it.
    """
    fd = _descriptor(f)
    if fd is not None:
        null = os.open(os.devnull, os.O_RDWR)
        try:
            os.dup2(null, fd)
        finally:
            os.close(null)
    try:
        f.close()
    except (OSError, RuntimeError):
        pass


def _close_written(f):
    """Close ``f``, open for writing, flushing it first; where the flush fails,
    abandon it (:func:`_abandon`).  Returns the flush's error, or None."""
    try:
        f.flush()
    except (OSError, RuntimeError) as exc:
        _abandon(f)
        return exc
    f.close()
    return None


def _trim(path):
    """Give back the space reserved past the end of a file closed cleanly: the end
    its superblock records (a file still marked as being written is left as it is)."""
    try:
        sb = _superblock(pathlib.Path(path))
        if sb is not None and sb.eof > 0 and not sb.flags and sb.size > sb.eof:
            os.truncate(path, sb.eof)
    except OSError:
        pass


def _new_file(path):
    """A new HDF5 file at ``path`` (a temporary beside an output file whose writers'
    lock this process holds), opened for writing.

    Made exclusively (``O_CREAT | O_EXCL``), so that it is never a file a
    link there names.  What had its name is left over from a writer that
    died, or was put there to be written through: it is removed first (a link
    is removed, not what it names).
    """
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass
    except OSError as exc:
        raise OrbitsFileError(f"{path}: in the way of the temporary file orbits makes "
                              f"there, and cannot be removed ({exc.strerror})") from None
    try:
        return h5py.File(path, "x", libver="latest")
    except FileExistsError:
        raise OrbitsFileError(f"{path}: made again by another process while orbits was "
                              f"making it; nothing is written through it") from None
    except OSError as exc:
        raise _write_error(path, exc, " when making it") from None


# -- writing ---------------------------------------------------------------------------

def _writes(method):
    """A method of :class:`FileRecorder` that writes to its file: an error of
    the file system becomes an :class:`OrbitsFileError` (one saying the disk is
    full where it is), raised once; after it the recorder writes nothing more
    (its methods that write return at once, as the run's cleanup calls them),
    and its :meth:`~FileRecorder.close` only closes the file."""
    @functools.wraps(method)
    def writing(self, *args, **kwargs):
        if self._failed is not None:
            return None
        try:
            return method(self, *args, **kwargs)
        except OrbitsFileError as exc:
            self._failed = exc
            raise
        except OrbitsError:
            raise
        except (OSError, RuntimeError) as exc:
            self._failed = self._stopped_by(exc)
            raise self._failed from None
    return writing


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
    write may take (see the module's notes); where the disk has none, or a
    write fails, it raises an :class:`OrbitsFileError` (whose message says
    the disk is full where it is, and what the file holds), writes nothing
    more, and its :meth:`close` only closes the file.

    Examples
    --------
    >>> import os, tempfile
    >>> import astropy.units as u
    >>> import orbits
    >>> from orbits.io import hdf5
    >>> from orbits.records import RunPlan
    >>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    >>> plan = RunPlan(until=10.0, outputs=2, ratio=10.0, n_full=10, has_partial=False,
    ...                start_step=0)
    >>> rec = hdf5.FileRecorder(path, sim, plan)   # writes the first output, a checkpoint
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
                try:
                    self.f = h5py.File(self.path, "a", libver="latest")
                except OSError as exc:
                    raise OrbitsFileError(
                        f"{self.path}: cannot be opened to append to ({exc}); if the run "
                        f"writing it was killed, finish that run first with resume() "
                        f"(orbits resume)") from None
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
        for name in ("energy", "angular_momentum"):
            if name not in sim.monitors:
                continue
            g = obs[name]["value"]
            values = g[first:self.rows]
            if name == "energy" and self.work:
                values = values + obs["work"]["value"][first:self.rows]
            self._note(name, values)
            t = obs["in_loop"][name]["time"][()]
            keep = (t > plan.start_time) & (t <= sim.time_value)
            if keep.any():
                rows = np.flatnonzero(keep)
                values = obs["in_loop"][name]["value"][rows]
                if name == "energy" and self.work:
                    values = values + obs["in_loop"]["work"]["value"][rows]
                self._note(name, values)

    def _note(self, name, values):
        from ..monitors import relative_error, vector_relative_error
        ref = self.reference
        if not len(values):
            return
        if name == "energy":
            # values are E + W, against E0 + W0
            err = relative_error(np.asarray(values, dtype=float).reshape(-1),
                                 ref[0] + float(_work_column(ref)), scale=self.scales[0])
        else:
            err = vector_relative_error(np.asarray(values, dtype=float).reshape(-1, 3),
                                        ref[1:4], self.scales[1])
        top = float(np.max(err))
        old = self.largest.get(name)
        self.largest[name] = top if old is None else float(np.max([old, top]))

    def _note_rows(self, rows):
        names = self.sim.monitors
        if "energy" in names:
            self._note("energy", rows[:, 0] + _work_column(rows))
        if "angular_momentum" in names:
            self._note("angular_momentum", rows[:, 1:4])

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
        >>> import os, tempfile
        >>> import astropy.units as u
        >>> import orbits
        >>> from orbits.io import hdf5
        >>> from orbits.records import RunPlan
        >>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
        >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
        >>> plan = RunPlan(until=10.0, outputs=2, ratio=10.0, n_full=10, has_partial=False,
        ...                start_step=0)
        >>> rec = hdf5.FileRecorder(path, sim, plan)   # writes the first output, a checkpoint
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
        from .._kernels.invariants import MONITOR_WIDTH
        width = MONITOR_WIDTH + 6 * len(self.desc.names)
        if self._rowbuf is None or len(self._rowbuf) < k:
            self._rowbuf = np.zeros((k, width))
        return self._rowbuf[:k]

    @_writes
    def output_rows(self, sim, steps, t, rows):
        """The loop wrote ``rows`` (from :meth:`row_buffer`) at ``steps`` and
        times ``t``: written to the file as they are, after the buffered
        outputs before them."""
        from .._kernels.invariants import MONITOR_WIDTH
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
                values = mon[:, _MONITOR_COLUMNS[name]]
                if name in _SCALAR_SERIES:
                    values = values[:, 0]
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
        >>> import os, tempfile
        >>> import astropy.units as u
        >>> import orbits
        >>> from orbits.io import hdf5
        >>> from orbits.records import RunPlan
        >>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
        >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
        >>> plan = RunPlan(until=10.0, outputs=2, ratio=10.0, n_full=10, has_partial=False,
        ...                start_step=0)
        >>> rec = hdf5.FileRecorder(path, sim, plan)   # writes the first output, a checkpoint
        >>> import numpy as np
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
        >>> import os, tempfile
        >>> import astropy.units as u
        >>> import orbits
        >>> from orbits.io import hdf5
        >>> from orbits.records import RunPlan
        >>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
        >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
        >>> plan = RunPlan(until=10.0, outputs=2, ratio=10.0, n_full=10, has_partial=False,
        ...                start_step=0)
        >>> rec = hdf5.FileRecorder(path, sim, plan)   # writes the first output, a checkpoint
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
        U = sim.units
        g = self.f.require_group("collisions")
        text = h5py.string_dtype()
        unit = lambda kind: U.unit(kind).to_string()  # noqa: E731
        cols = (("time", np.float64, unit("time")), ("step_time", np.float64, unit("time")),
                ("body_1", text, None), ("body_2", text, None), ("resolution", text, None),
                ("survivor", text, None), ("distance", np.float64, unit("length")),
                ("speed", np.float64, unit("velocity")),
                ("energy_change", np.float64, unit("energy")))
        for k, (name, dtype, u_) in enumerate(cols):
            values = [row[k] for row in rows]
            if name not in g:
                ds = g.create_dataset(name, shape=(0,), maxshape=(None,), dtype=dtype,
                                      chunks=(256,))
                if u_ is not None:
                    ds.attrs["unit"] = u_
            ds = g[name]
            start = ds.shape[0]
            ds.resize((start + len(values),))
            ds[start:] = np.asarray(values, dtype=object if dtype is text else dtype)

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
        g = self.f.require_group("encounters")
        cols = {"time": ([r[0] for r in rows], np.float64, U.unit("time").to_string()),
                "body_1": ([r[1] for r in rows], h5py.string_dtype(), None),
                "body_2": ([r[2] for r in rows], h5py.string_dtype(), None),
                "distance": ([r[3] for r in rows], np.float64, U.unit("length").to_string()),
                "speed": ([r[4] for r in rows], np.float64,
                          (U.unit("length") / U.unit("time")).to_string())}
        for name, (values, dtype, unit) in cols.items():
            if name not in g:
                ds = g.create_dataset(name, shape=(0,), maxshape=(None,), dtype=dtype,
                                      chunks=(256,))
                if unit is not None:
                    ds.attrs["unit"] = unit
            ds = g[name]
            k = ds.shape[0]
            ds.resize((k + len(values),))
            ds[k:] = np.asarray(values, dtype=object if dtype is not np.float64 else dtype)

    def close(self):
        """Flush what is buffered, close the file and release the writers' lock (idempotent).

        Examples
        --------
        >>> import os, tempfile
        >>> import astropy.units as u
        >>> import orbits
        >>> from orbits.io import hdf5
        >>> from orbits.records import RunPlan
        >>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
        >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
        >>> plan = RunPlan(until=10.0, outputs=2, ratio=10.0, n_full=10, has_partial=False,
        ...                start_step=0)
        >>> rec = hdf5.FileRecorder(path, sim, plan)   # writes the first output, a checkpoint
        >>> rec.close()
        >>> rec.closed, os.path.exists(path + ".lock")    # the writers' lock is released
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
        >>> import os, tempfile
        >>> import astropy.units as u
        >>> import orbits
        >>> from orbits.io import hdf5
        >>> from orbits.records import RunPlan
        >>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
        >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
        >>> plan = RunPlan(until=10.0, outputs=2, ratio=10.0, n_full=10, has_partial=False,
        ...                start_step=0)
        >>> rec = hdf5.FileRecorder(path, sim, plan)   # writes the first output, a checkpoint
        >>> _ = sim.run(until=10 * u.day, outputs=2, progress=False)
        >>> rec.output(sim, final=True)
        >>> r = rec.result(sim, wall=0.5)
        >>> r.times, r.wall_time, r.path == path
        (<Quantity [10.] d>, 0.5, True)
        >>> rec.close()
        """
        from ..result import Result
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
                    values = values[:, _MONITOR_COLUMNS[name]]
                    if name in _SCALAR_SERIES:
                        values = values[:, 0]
                _append(dsets, n0, steps, t, values)
            self.rows = n0 + k
            self.buffer = []
        if self.mon_buffer:
            t, steps, rows = (np.concatenate(part) for part in zip(*self.mon_buffer))
            for name, dsets in inloop.items():
                vals = rows[:, _MONITOR_COLUMNS[name]]
                if name == "work" and rows.shape[1] <= _MONITOR_COLUMNS["work"].start:
                    vals = np.zeros((len(rows), 1))   # rows without the work column
                _append(dsets, dsets[1].shape[0], steps, t,
                        vals[:, 0] if name in _SCALAR_SERIES else vals)
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
        >>> import os, tempfile
        >>> import astropy.units as u
        >>> import orbits
        >>> from orbits.io import hdf5
        >>> from orbits.records import RunPlan
        >>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
        >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
        >>> plan = RunPlan(until=10.0, outputs=2, ratio=10.0, n_full=10, has_partial=False,
        ...                start_step=0)
        >>> rec = hdf5.FileRecorder(path, sim, plan)   # writes the first output, a checkpoint
        >>> rec.checkpoints
        1
        >>> rec.checkpoint()
        >>> rec.checkpoints
        2
        >>> rec.close()
        >>> hdf5.read_checkpoint(path).point.finished
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


def _bodies_vary(desc):
    """Whether the described simulation's collisions may merge bodies away
    (a resolution other than ``"halt"``)."""
    c = desc.stop_conditions.get("collisions")
    return c is not None and c != "halt"


def _body_axes(integrator, n):
    """The axes of each workspace array that run over the bodies (those whose
    length differs between a workspace of ``n`` and of ``n + 1`` bodies)."""
    a, b = integrator.workspace(n), integrator.workspace(n + 1)
    axes = {name: tuple(k for k, (p, q) in enumerate(zip(arr.shape, b[name].shape)) if p != q)
            for name, arr in a.items() if isinstance(arr, np.ndarray)}
    # the collision check's state of the step before: (positions and velocities, bodies, 3)
    axes["stop_prev"] = (1,)
    return axes


def _padded(x, n):
    """Rows of ``x`` followed by NaN rows up to ``n`` (a state after mergers,
    in a dataset made for the bodies at the start)."""
    if len(x) == n:
        return x
    out = np.full((n,) + x.shape[1:], np.nan)
    out[:len(x)] = x
    return out


def _write_box(d, slot, arr):
    """``d[slot]`` gets ``arr``, in its leading corner where ``arr`` is smaller
    (a workspace of fewer bodies than the file was made for)."""
    if arr.shape == d.shape[1:]:
        _write_rows(d, slot, arr[None], extend=False)
    else:
        d[(slot,) + tuple(slice(0, k) for k in arr.shape)] = arr


def _read_box(d, slot, n, n0):
    """``d[slot]`` for ``n`` bodies where it was made for ``n0`` (its
    ``body_axes`` attribute says which axes run over them)."""
    axes = set(d.attrs.get("body_axes", ())) if n != n0 else set()
    return d[(slot,) + tuple(slice(0, n if k in axes else size)
                             for k, size in enumerate(d.shape[1:]))]


def _datasets(group):
    return group["step"], group["time"], group["value"]


def _keeps_work(desc):
    """Whether a file of the simulation ``desc`` describes keeps the work series:
    with the energy monitor and a non-conservative force term, or collisions
    that the run resolves (what they take out of the bodies' energy)."""
    return "energy" in desc.monitors and (any(not t.conservative for t in desc.forces)
                                          or _bodies_vary(desc))


def _append(dsets, n0, steps, t, values):
    for d, data in zip(dsets, (steps, t, values)):
        _write_rows(d, n0, data)


def _write_rows(d, n0, data, extend=True):
    """``d[n0:n0 + len(data)] = data``, extending ``d`` first if asked.

    Through h5py's low-level calls: its slicing costs ten times the write
    itself (0.2 ms against 0.02), which a checkpoint at every output pays
    some thirty times.
    """
    data = np.ascontiguousarray(data, dtype=d.dtype)
    shape = data.shape
    if extend:
        d.id.set_extent((n0 + shape[0],) + shape[1:])
    space = d.id.get_space()
    space.select_hyperslab((n0,) + (0,) * (len(shape) - 1), shape)
    d.id.write(h5py.h5s.create_simple(shape), space, data)


#: bytes of a time series' chunk: 1024 outputs of a few bodies, fewer of many
_CHUNK_BYTES = 1 << 16


def _element(parent, name, shape, unit):
    # uncompressed chunks: a partial chunk rewritten at each checkpoint keeps
    # its place in the file (see the module's notes); positions and
    # velocities compress by about 12 % only (gzip level 4, shuffle)
    g = parent.create_group(name)
    g.create_dataset("step", shape=(0,), maxshape=(None,), dtype=np.int64, chunks=(1024,))
    t = g.create_dataset("time", shape=(0,), maxshape=(None,), dtype=np.float64,
                         chunks=(1024,))
    t.attrs["unit"] = unit[1]
    rows = max(1, min(1024, _CHUNK_BYTES // (8 * max(1, int(np.prod(shape))))))
    v = g.create_dataset("value", shape=(0,) + shape, maxshape=(None,) + shape,
                         dtype=np.float64, chunks=(rows,) + shape)
    v.attrs["unit"] = unit[0]
    return g


def _package_version():
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("orbits")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree
        return "0+unknown"


def _series_unit(U, name):
    """The unit (a string) of the monitor series ``name`` in the unit system ``U``."""
    kind = _MONITOR_KIND[name]
    if kind == "1 / time":
        return (U.unit("time") ** -1).to_string()
    if kind == "dimensionless":
        return "1"
    return U.unit(kind).to_string()


def _tangent_layout(monitors, variations, n):
    """``(chaos, random, state, mass)``: how many tangent vectors of each kind a
    simulation of ``n`` bodies with these ``monitors`` and ``variations``
    integrates, in the order :attr:`orbits.Simulation.tangent_vectors` lists
    them (one for the chaos monitors; an int ``variations`` random ones; 6 n
    for ``"state"``; 6 n and n for ``"all"``).  Read off the configuration,
    as the simulation lays them out, so that a file is checked against what
    its own record says."""
    chaos = int(any(name in CHAOS_MONITORS for name in monitors))
    if isinstance(variations, str):
        state = 6 * n if variations in ("state", "all") else 0
        return chaos, 0, state, (n if variations == "all" else 0)
    random = int(variations) if variations is not None and not isinstance(variations, bool) \
        else 0
    return chaos, random, 0, 0


def _config_layout(config, n):
    # the tangent layout of a configuration dictionary (SimulationConfig.to_dict())
    return _tangent_layout(config.get("monitors", ()), config.get("variations"), n)


def _jacobian(tangents, layout):
    """The Jacobian (6 N, 6 N) or (6 N, 7 N) that tangent vectors (k, N, 6)
    laid out as ``layout`` hold, as :attr:`orbits.Simulation.jacobian`; None
    without ``variations="state"`` or ``"all"``."""
    chaos, random, state, mass = layout
    if not state:
        return None
    n = tangents.shape[1]
    return tangents[chaos + random:].reshape(state + mass, 6 * n).T.copy()


def _create(path, desc, state):
    """A new file for the simulation described by ``desc`` (a
    :class:`~orbits.records.SimulationDescription`) at ``state``, open for
    appending in SWMR mode.

    It is written whole as ``<path>.creating`` (made exclusively, see
    :func:`_new_file`) and then renamed to ``path``, which replaces a file or
    a link there, never what a link names.  Where that fails (a full disk),
    the temporary is removed and ``path`` is left as it was.
    """
    tmp = path.with_name(path.name + ".creating")
    f = _new_file(tmp)
    try:
        _write_layout(f, desc, state)
    except BaseException as exc:
        _close_written(f)
        tmp.unlink(missing_ok=True)
        if isinstance(exc, (OSError, RuntimeError)) and not isinstance(exc, OrbitsError):
            raise _write_error(path, exc, " when making it; nothing was written") from None
        raise
    f.close()
    os.replace(tmp, path)
    f = h5py.File(path, "a", libver="latest")
    f.swmr_mode = True
    return f


def _write_layout(f, desc, state):
    """The groups, datasets and metadata of a new file ``f`` (the layout of the
    module's notes) for the simulation ``desc`` describes, at ``state``; flushed."""
    __version__ = _package_version()
    import astropy
    import numba

    U = desc.units
    f.attrs["orbits_format"] = FORMAT
    f.attrs["orbits_format_version"] = FORMAT_VERSION
    h = f.create_group("h5md")
    h.attrs["version"] = np.array([1, 1], dtype=np.int32)
    h.create_group("author").attrs["name"] = os.environ.get("USER", "unknown")
    c = h.create_group("creator")
    c.attrs["name"] = "orbits"
    c.attrs["version"] = __version__
    n = len(desc.names)
    unit = lambda kind: U.unit(kind).to_string()  # noqa: E731
    b = f.create_group("particles/bodies")
    b.create_dataset("names", data=np.array(list(desc.names), dtype=h5py.string_dtype()))
    b.create_dataset("mass", data=desc.masses).attrs["unit"] = unit("mass")
    b.create_dataset("radius", data=desc.radii).attrs["unit"] = unit("length")
    _element(b, "position", (n, 3), (unit("length"), unit("time")))
    _element(b, "velocity", (n, 3), (unit("velocity"), unit("time")))
    varying = _bodies_vary(desc)
    if varying:
        # collisions may merge bodies away: the outputs keep the columns of
        # the bodies at the start (NaN for one that is gone) and the masses
        _element(b, "masses_at_outputs", (n,), (unit("mass"), unit("time")))
    obs = f.create_group("observables")
    inloop = obs.create_group("in_loop")
    for name in tuple(desc.monitors) + (("work",) if _keeps_work(desc) else ()):
        shape = () if name in _SCALAR_SERIES else (3,)
        u_ = (_series_unit(U, name), unit("time"))
        _element(obs, name, shape, u_)
        _element(inloop, name, shape, u_)
    par = f.create_group("parameters")
    meta = {
        "orbits_version": __version__, "numpy_version": np.__version__,
        "numba_version": numba.__version__, "h5py_version": h5py.__version__,
        "astropy_version": astropy.__version__,
        "written": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "integrator": desc.integrator.name,
        "integrator_options": json.dumps(desc.integrator.config),
        "integrator_info": json.dumps(desc.integrator.info()),
        "dt": desc.dt, "dt_unit": unit("time"),
        "units": json.dumps(U.to_dict()), "G": U.G, "G_source": U.G_source,
        "softening": float(desc.softening), "softening_unit": unit("length"),
        "monitors": json.dumps(list(desc.monitors)),
        "monitor_every": desc.monitor_every or 0,
        "parallel": bool(desc.parallel),
        "stop_conditions": json.dumps(desc.stop_conditions),
        "rebound_arithmetic": bool(desc.rebound_arithmetic),
        "bodies_history": json.dumps(desc.history, default=str),
        # the one record that rebuilds the simulation from its bodies (Simulation.from_file)
        "config": json.dumps(desc.config.to_dict()),
        "forces": json.dumps([t.to_dict() for t in desc.forces]),
    }
    for k, v in meta.items():
        par.attrs[k] = v
    if desc.epoch is not None:
        par.attrs["epoch_tdb"] = np.array(_epochs.to_pair(desc.epoch), dtype=np.float64)
    ref = par.create_dataset("reference", data=state.reference)
    ref_units = ([unit("energy")] + [unit("angular_momentum")] * 3 + [unit("momentum")] * 3
                 + [unit("length")] * 3 + [unit("energy")]
                 + [_series_unit(U, name) for name in _CHAOS])
    ref.attrs["unit"] = ", ".join(ref_units[:len(state.reference)])
    par.create_dataset("scales", data=np.array(state.scales)).attrs["unit"] = \
        f"{unit('energy')}, {unit('angular_momentum')}"
    par.create_dataset("start_clock", data=np.array(
        [state.steps, state.force_evaluations, state.steps_rejected], dtype=np.int64))
    r = f.create_group("restart")
    r.create_dataset("count", data=np.int64(0))
    r.create_dataset("order", data=np.asarray(state.order, dtype=np.int64))
    for name in ("x", "v"):
        r.create_dataset(name, shape=(_SLOTS, n, 3), dtype=np.float64).attrs["unit"] = \
            unit("length" if name == "x" else "velocity")
    r.create_dataset("clock", shape=(_SLOTS, 5), dtype=np.int64)
    r.create_dataset("t_base", shape=(_SLOTS,), dtype=np.float64).attrs["unit"] = unit("time")
    r.create_dataset("plan", shape=(_SLOTS, 7), dtype=np.float64).attrs["unit"] = \
        f"{unit('time')}, 1, 1, 1, 1, 1, {unit('time')}"
    r.create_dataset("progress", shape=(_SLOTS, 3), dtype=np.int64)
    r.create_dataset("wall", shape=(_SLOTS,), dtype=np.float64).attrs["unit"] = "s"
    layout = _tangent_layout(desc.monitors, desc.config.variations, n)
    if sum(layout):
        # the derivatives at the checkpoint, as Simulation.tangent_vectors gives
        # them (the integrator synchronised, body-set order), so that a reader
        # needs neither the integrator nor the internal order
        d = r.create_dataset("tangent_vectors", shape=(_SLOTS, sum(layout), n, 6),
                             dtype=np.float64)
        d.attrs["unit"] = "internal"
        d.attrs["layout"] = np.array(layout, dtype=np.int64)
    ws = r.create_group("ws")
    axes = _body_axes(desc.integrator, n) if varying else {}
    for name, arr in state.workspace.items():
        if isinstance(arr, np.ndarray):
            d = ws.create_dataset(name, shape=(_SLOTS,) + arr.shape, dtype=arr.dtype)
            if arr.dtype.kind == "f":
                # the integrator's own state, in the run's units (see /parameters/units)
                d.attrs["unit"] = "internal"
            if varying:
                d.attrs["body_axes"] = np.array(axes.get(name, ()), dtype=np.int64)
    if varying:
        # the bodies at each checkpoint, in the columns of those at the start:
        # masses and radii (NaN: merged away) and the internal order
        for name, kind in (("masses", "mass"), ("radii", "length")):
            r.create_dataset(name, shape=(_SLOTS, n), dtype=np.float64).attrs["unit"] = \
                unit(kind)
        r.create_dataset("orders", shape=(_SLOTS, n), dtype=np.int64)
    f.flush()


# -- reading ---------------------------------------------------------------------------

def _damaged(func):
    # a file can open and still fail on reading a truncated chunk: name it
    @functools.wraps(func)
    def wrapper(path, *args, **kwargs):
        try:
            return func(path, *args, **kwargs)
        except OrbitsFileError:
            raise
        except (OSError, RuntimeError, KeyError, ValueError) as exc:
            raise OrbitsFileError(f"{path}: damaged or incomplete orbits file "
                                  f"(truncated?): {exc}") from None
        except (TypeError, AttributeError, IndexError) as exc:
            # a value of a kind the checks above did not foresee: still the file's
            raise OrbitsFileError(f"{path}: damaged orbits file: a value of the wrong kind "
                                  f"({type(exc).__name__}: {exc})") from exc
    return wrapper


def _rows(f, monitors, in_loop=False):
    """Rows that every series of the outputs (or the in-loop monitors) holds: a
    reader of a live file may see one series extended before the next."""
    obs = f["observables/in_loop"] if in_loop else f["observables"]
    # the work series, where the file keeps it, goes with the energy's
    names = list(monitors) + (["work"] if "energy" in monitors and "work" in obs else [])
    if in_loop:
        groups = [obs[name] for name in names]
    else:
        b = f["particles/bodies"]
        groups = [b["position"], b["velocity"]] + [obs[name] for name in names]
        if "masses_at_outputs" in b:
            groups.append(b["masses_at_outputs"])
    # only the rows the file stores data for (see _covered)
    return min((_covered(g[k]) for g in groups for k in ("step", "time", "value")), default=0)


def _totals(f):
    """(steps, force evaluations, rejected steps, wall seconds) of the runs that wrote
    the file, at its last checkpoint; None for files from before they were kept."""
    r, par = f["restart"], f["parameters"]
    count = int(r["count"][()])
    if count == 0 or "wall" not in r or "start_clock" not in par:
        return None
    slot = (count - 1) % _SLOTS
    clock = r["clock"][slot]
    start = par["start_clock"][()]
    return (int(clock[0] - start[0]), int(clock[2] - start[1]), int(clock[4] - start[2]),
            float(r["wall"][slot]))


@_damaged
def whole_run(path):
    """What a summary of every run that wrote a file needs, without its outputs:
    the fields of :class:`~orbits.Result` that :func:`load` gives for the
    whole file, for a result that holds only a last output (from
    :meth:`orbits.Simulation.resume` or a run continued into the file).

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    dict
        ``steps``, ``force_evaluations``, ``steps_rejected`` and ``wall_time``
        (totals at the last checkpoint, as :func:`load` reads them),
        ``start_time`` (the first output's time, a Quantity), and
        ``largest_errors`` (the largest relative errors of the monitored
        invariants at every output and in-loop row); ``collisions`` and
        ``encounters`` where the file logs them.

    Examples
    --------
    >>> import os, tempfile
    >>> import astropy.units as u
    >>> import orbits
    >>> from orbits.io import hdf5
    >>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    >>> _ = sim.run(until=10 * u.day, outputs=3, output=path, progress=False)
    >>> last = sim.run(until=20 * u.day, outputs=3, output=path, progress=False)
    >>> whole = hdf5.whole_run(path)
    >>> last.steps, last.start_time, whole["steps"], whole["start_time"]
    (10, <Quantity 10. d>, 20, <Quantity 0. d>)
    """
    import astropy.units as u
    from ..monitors import relative_error, vector_relative_error

    with _open_read(path) as f:
        b, par, obs = f["particles/bodies"], f["parameters"], f["observables"]
        monitors = json.loads(par.attrs["monitors"])
        n = _rows(f, monitors)
        totals = _totals(f)
        if totals is None:
            step = b["position/step"]
            totals = (int(step[n - 1] - step[0]) if n else 0, None, 0, None)
        t = b["position/time"]
        fields = dict(zip(("steps", "force_evaluations", "steps_rejected", "wall_time"),
                          totals))
        if n:
            fields["start_time"] = float(t[0]) << u.Unit(t.attrs["unit"])
        ref = par["reference"][()]
        scales = par["scales"][()]
        work = "energy" in monitors and "work" in obs
        m = _rows(f, monitors, in_loop=True)
        largest = {}
        for name in ("energy", "angular_momentum"):
            if name not in monitors:
                continue
            errors = []
            for group, rows in ((obs, n), (obs["in_loop"], m)):
                if not rows:
                    continue
                values = group[name]["value"][:rows]
                if name == "energy":
                    if work:
                        values = values + group["work"]["value"][:rows]
                    errors.append(relative_error(values, ref[0] + float(_work_column(ref)),
                                                 scale=scales[0]))
                else:
                    errors.append(vector_relative_error(values, ref[1:4], scales[1]))
            if errors:
                largest[name] = float(max(np.max(e) for e in errors))
        fields["largest_errors"] = largest
        if "encounters" in f:
            fields["encounters"] = _encounters(f["encounters"])
        if "masses" in f["restart"]:
            fields["collisions"] = _collisions(f.get("collisions"), par)
    return fields


@_damaged
def load(path):
    """Read an output file into a :class:`~orbits.Result` with Quantities.

    Works on a file whose writer was killed: it reads what the last flush left.
    ``steps``, ``force_evaluations``, ``steps_rejected`` and ``wall_time``
    are the totals of the runs that wrote the file, at its last checkpoint
    (None for force evaluations and wall time in files written before they
    were kept).  With variations or chaos monitors, ``jacobian`` and
    ``tangent_vectors`` are those at the last checkpoint too, which for a
    finished run is its last output, and ``seed`` the seed of the random
    tangent vectors.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    Result
        Every output row, as Quantities in the file's units.

    Raises
    ------
    OrbitsFileError
        Not an orbits output, or damaged beyond reading.

    Examples
    --------
    >>> import os, tempfile
    >>> import astropy.units as u
    >>> import orbits
    >>> from orbits.io import hdf5
    >>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    >>> _ = sim.run(until=10 * u.day, outputs=3, output=path, progress=False)
    >>> result = orbits.load(path)
    >>> result.times, result.positions.unit, result.steps
    (<Quantity [ 0.,  5., 10.] d>, Unit("AU"), 10)
    """
    from ..result import Result
    import astropy.units as u
    from ..monitors import relative_error, vector_relative_error

    with _open_read(path) as f:
        b = f["particles/bodies"]
        par = f["parameters"]
        monitors = json.loads(par.attrs["monitors"])
        n = _rows(f, monitors)

        def q(ds, rows=n):
            return ds[:rows] << u.Unit(ds.attrs["unit"])

        totals = _totals(f)
        radii, radius_unit = _radii(b)
        if totals is None:
            step = b["position/step"]
            steps = int(step[n - 1] - step[0]) if n else 0
            totals = (steps, None, 0, None)
        fields = dict(
            times=q(b["position/time"]), positions=q(b["position/value"]),
            velocities=q(b["velocity/value"]), names=_decode(b["names"][()]),
            masses=b["mass"][()] << u.Unit(b["mass"].attrs["unit"]),
            radii=radii << u.Unit(radius_unit), steps=totals[0],
            force_evaluations=totals[1], steps_rejected=totals[2], wall_time=totals[3],
            integrator=json.loads(par.attrs["integrator_info"]),
            units=json.loads(par.attrs["units"]),
            dt=par.attrs["dt"] * u.Unit(par.attrs["dt_unit"]), monitors=tuple(monitors),
            status=_status(f, path), path=str(path), metadata=dict(par.attrs),
            epoch=_epoch(par, path))
        ref = par["reference"][()]
        e_scale, l_scale = par["scales"][()]
        obs = f["observables"]
        for name in monitors:
            fields[name] = _series(obs[name], name, n)
        # the work of non-conservative terms, where the file keeps it
        work = "energy" in monitors and "work" in obs
        w0 = float(_work_column(ref))
        if work:
            fields["work"] = q(obs["work"]["value"])
        if "energy" in monitors:
            e = obs["energy/value"][:n]
            if work:
                e = e + obs["work/value"][:n]
            fields["energy_error"] = relative_error(e, ref[0] + w0, scale=e_scale)
        if "angular_momentum" in monitors:
            fields["angular_momentum_error"] = vector_relative_error(
                obs["angular_momentum/value"][:n], ref[1:4], l_scale)
        inloop = obs["in_loop"]
        m = _rows(f, monitors, in_loop=True)
        if monitors and m:
            mon = {"times": q(inloop[monitors[0]]["time"], m)}
            if "energy" in monitors:
                e = inloop["energy/value"][:m]
                if work:
                    mon["work"] = q(inloop["work"]["value"], m)
                    e = e + inloop["work/value"][:m]
                mon["energy_error"] = relative_error(e, ref[0] + w0, scale=e_scale)
            if "angular_momentum" in monitors:
                mon["angular_momentum_error"] = vector_relative_error(
                    inloop["angular_momentum/value"][:m], ref[1:4], l_scale)
            for name in _CHAOS:
                if name in monitors:
                    mon[name] = _series(inloop[name], name, m)
            fields["monitor"] = mon
        fields.update(_derivatives(f, path))
        if "encounters" in f:
            fields["encounters"] = _encounters(f["encounters"])
        if "masses_at_outputs" in b:
            fields["masses_at_outputs"] = q(b["masses_at_outputs/value"])
        if "masses" in f["restart"]:
            fields["collisions"] = _collisions(f.get("collisions"), par)
    return Result(**fields)


def _collisions(g, par):
    """The collisions a run resolved (group ``collisions``; none yet: an
    empty table) as the QTable of ``Result.collisions``."""
    from ..collisions import table
    from ..units import UnitSystem
    units = UnitSystem.from_dict(json.loads(par.attrs["units"]))
    if g is None:
        return table([], units)
    k = _log_rows(g, _COLLISION_COLUMNS)
    cols = [_decode(g[name][:k]) if kind == "str" else g[name][:k]
            for name, kind in _COLLISION_COLUMNS.items()]
    return table(list(zip(*cols)), units)


def _encounters(g):
    """The encounter log of a file (group ``encounters``) as the QTable of
    ``Result.encounters``."""
    import astropy.units as u
    from astropy.table import QTable
    k = _log_rows(g, _ENCOUNTER_COLUMNS)
    col = lambda name: g[name][:k] << u.Unit(g[name].attrs["unit"])  # noqa: E731
    text = lambda name: np.array(_decode(g[name][:k]), dtype=str)  # noqa: E731
    return QTable({"time": col("time"), "body_1": text("body_1"), "body_2": text("body_2"),
                   "distance": col("distance"), "speed": col("speed")})


def _radii(b):
    """The bodies' radii from the group ``particles/bodies`` (float64 in the run's
    unit of length) and that unit's name; all 0 in a file written before they
    were kept."""
    if "radius" in b:
        return np.asarray(b["radius"][()], dtype=np.float64), b["radius"].attrs["unit"]
    return np.zeros(b["names"].shape[0]), b["position/value"].attrs["unit"]


def _series(group, name, rows):
    """The first ``rows`` values of a monitor series, as a result holds them:
    Quantities, but MEGNO and the FLI as plain arrays (dimensionless)."""
    import astropy.units as u
    values = group["value"][:rows]
    if _MONITOR_KIND[name] == "dimensionless":
        return values
    return values << u.Unit(group["value"].attrs["unit"])


def _config(f):
    """The configuration record (SimulationConfig.to_dict()) a file keeps; {} for
    files written before it."""
    par = f["parameters"]
    return json.loads(par.attrs["config"]) if "config" in par.attrs else {}


def _derivatives(f, path):
    """``jacobian``, ``tangent_vectors`` and ``seed`` of a file with variations or
    chaos monitors, at its last checkpoint (the last output of a finished run),
    as a Result holds them; {} for a file without (or written before the
    derivatives were kept, or before its first checkpoint)."""
    config = _config(f)
    n = f["particles/bodies/names"].shape[0]
    layout = _config_layout(config, n)
    if not sum(layout):
        return {}
    out = {"seed": config.get("seed")}
    r = f["restart"]
    count = int(r["count"][()])
    if "tangent_vectors" not in r or not count:
        return out
    d = r["tangent_vectors"]
    want = (_SLOTS, sum(layout), n, 6)
    stored = tuple(int(k) for k in d.attrs.get("layout", layout))
    if d.shape != want or stored != tuple(layout):
        raise TangentShapeError(
            f"{path}: holds tangent vectors of shape {d.shape[1:]} (laid out as {stored}: "
            f"chaos, random, state, mass), but its configuration (variations="
            f"{config.get('variations')!r}, monitors {', '.join(config['monitors']) or 'none'}"
            f") calls for {want[1:]} (laid out as {tuple(layout)})",
            expected=want[1:], found=d.shape[1:])
    tangents = d[(count - 1) % _SLOTS]
    out.update(tangent_vectors=tangents, jacobian=_jacobian(tangents, layout))
    return out


def _status(f, path=None):
    from .._kernels.status import Status
    count = int(f["restart/count"][()])
    finished = code = 0
    if count:
        _, finished, code = (int(a) for a in f["restart/progress"][(count - 1) % _SLOTS])
    if code:
        return {Status.NON_FINITE: "non-finite state", Status.CLOSE_ENCOUNTER:
                "close encounter", Status.ESCAPE: "escape",
                Status.STEP_UNDERFLOW: "step-size underflow",
                Status.NO_CONVERGENCE: "no convergence",
                Status.COLLISION: "collision"}.get(code, f"stopped ({code})")
    if finished:
        return "completed"
    rec, alive = _writer(path) if path is not None else (None, False)
    if rec is not None and alive is not False:
        who = f"process {rec.get('pid')}" + (f" on {rec.get('host')}" if alive is None
                                              else "")
        return f"running (being written by {who})"
    if count == 0:
        return "no checkpoint yet (the writer stopped early)"
    return "interrupted (resumable from the last checkpoint)"


def _read_ends(f, monitors):
    # the first and last rows of every series: what describe() says is there can be read
    n = _rows(f, monitors)
    groups = [f["particles/bodies/position"], f["particles/bodies/velocity"]]
    groups += [f["observables"][name] for name in monitors]
    for g in groups:
        for k in ("step", "time", "value"):
            if n:
                g[k][0]
                g[k][n - 1]
    count = int(f["restart/count"][()])
    if count:
        slot = (count - 1) % _SLOTS
        r = f["restart"]
        for name in ("x", "v", "clock", "t_base", "plan", "progress"):
            r[name][slot]
    return n


@_damaged
def describe(path):
    """A few sentences saying what an output file holds.

    Raises :class:`OrbitsFileError` for a damaged file, as :func:`load` does.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    str

    Examples
    --------
    >>> import os, tempfile
    >>> import astropy.units as u
    >>> import orbits
    >>> from orbits.io import hdf5
    >>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    >>> _ = sim.run(until=10 * u.day, outputs=3, output=path, progress=False)
    >>> text = hdf5.describe(path)
    >>> [line.split()[0] for line in text.splitlines()[1:4]]
    ['bodies', 'integrator', 'units']
    """
    import astropy.units as u
    with _open_read(path) as f:
        b = f["particles/bodies"]
        par = f["parameters"]
        names = _decode(b["names"][()])
        monitors = json.loads(par.attrs["monitors"])
        n_out = _read_ends(f, monitors)
        t = b["position/time"]
        tu = u.Unit(t.attrs["unit"])
        units = json.loads(par.attrs["units"])
        # times in the unit of the larger end of the outputs', so that they read alike
        ends = (t[0], t[n_out - 1]) if n_out else (0.0,)
        shown = time_unit(max(abs(v) for v in ends) * tu)
        lines = [
            f"{path}: orbits output (layout {FORMAT} v{FORMAT_VERSION}), written by "
            f"orbits {par.attrs['orbits_version']} on {par.attrs['written']}",
            f"bodies          {len(names)}: {', '.join(names[:8])}"
            + (", ..." if len(names) > 8 else ""),
            f"integrator      {par.attrs['integrator']} {par.attrs['integrator_options']}, "
            f"dt = {format_time(par.attrs['dt'] * u.Unit(par.attrs['dt_unit']))}",
            f"units           {units['name']}, G = {units['G']!r} ({units['G_source']})",
            f"epoch           {_describe_epoch(_epoch(par, path))}",
            f"outputs         {n_out}"
            + (f", t = {(t[0] * tu).to_value(shown):.6g} .. "
               f"{format_time(t[n_out - 1] * tu, shown)}" if n_out else ""),
            f"monitors        {', '.join(monitors) or 'none'}",
            f"forces          {_describe_forces(par, path)}",
        ]
        config = _config(f)
        layout = _config_layout(config, len(names))
        if sum(layout):
            kinds = [f"{k} {what}" for k, what in zip(
                layout, ("for the chaos monitors", "random", "of the state", "of the masses"))
                if k]
            lines.append(f"variations      {config.get('variations')}; {sum(layout)} tangent "
                         f"vectors ({', '.join(kinds)}), seed {config.get('seed')}")
        count = int(f["restart/count"][()])
        if count:
            slot = (count - 1) % _SLOTS
            clock = f["restart/clock"][slot]
            tb = f["restart/t_base"][slot]
            t_ck = tb + clock[1] * par.attrs["dt"]
            lines.append(f"checkpoint      {count} written; the last at step {clock[0]}, "
                         f"t = {format_time(t_ck * tu, shown)}")
        totals = _totals(f)
        if totals is not None:
            lines.append(f"work            {totals[0]} steps, {totals[1]} force evaluations, "
                         f"wall time {totals[3]:.3g} s")
        if "masses" in f["restart"]:
            k = _log_rows(f["collisions"], _COLLISION_COLUMNS) if "collisions" in f else 0
            left = (int(np.isfinite(f["restart/masses"][(count - 1) % _SLOTS]).sum())
                    if count else None)
            lines.append(f"collisions      {k} resolved" + (
                f"; {left} bodies at the last checkpoint" if left is not None else ""))
        if "encounters" in f:
            lines.append(f"encounters      {_log_rows(f['encounters'], _ENCOUNTER_COLUMNS)} "
                         f"logged")
        lines.append(f"status          {_status(f, path)}")
        return "\n".join(lines)


def _describe_epoch(epoch):
    # the date of time 0, or that there is none
    return "none (times only)" if epoch is None else f"{_epochs.describe(epoch)} at t = 0"


def _describe_forces(par, path):
    # Newtonian gravity and the added terms, as their constructors would be
    # written; a term of the user's functions by the names the file records
    # (a file names functions, never holds them, and nothing is imported)
    from .. import forces
    text = ["Newtonian gravity"]
    records = json.loads(par.attrs["forces"]) if "forces" in par.attrs else []
    for d in records:
        try:
            needed = forces.functions_needed([d])
            if needed:
                text.append(f"{d['type']}({', '.join(needed)})")
            else:
                text.append(repr(forces.from_dict(d)))
        except (OrbitsError, TypeError, ValueError, KeyError) as exc:
            raise OrbitsFileError(f"{path}: the force term {d!r} in /parameters does not "
                                  f"rebuild: {exc}") from None
    return " + ".join(text)


class Checkpoint(NamedTuple):
    """What a file's last checkpoint rebuilds a simulation from
    (:meth:`orbits.Simulation.from_file`).

    Examples
    --------
    >>> import os, tempfile
    >>> import astropy.units as u
    >>> import orbits
    >>> from orbits.io import hdf5
    >>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    >>> _ = sim.run(until=10 * u.day, outputs=3, output=path, progress=False)
    >>> cp = hdf5.read_checkpoint(path)
    >>> cp.bodies.names, cp.config["integrator"], cp.state.steps
    (['Star', 'Planet'], 'leapfrog', 10)
    """

    bodies: object          # the BodySet at the checkpoint (its epoch: the date there)
    config: dict            # SimulationConfig.to_dict() of the simulation
    state: SimulationState  # put back with Simulation.set_state
    point: object           # the ResumePoint: where the run that wrote the file stood
    path: str
    epoch: object = None    # astropy Time (TDB) of the simulation's time 0, or None


@_damaged
def read_checkpoint(path):
    """The file's last complete checkpoint, as a :class:`Checkpoint`;
    :class:`OrbitsFileError` for a file that is damaged or holds none.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    Checkpoint

    Examples
    --------
    >>> import os, tempfile
    >>> import astropy.units as u
    >>> import orbits
    >>> from orbits.io import hdf5
    >>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    >>> _ = sim.run(until=10 * u.day, outputs=3, output=path, progress=False)
    >>> cp = hdf5.read_checkpoint(path)
    >>> cp.point.finished, cp.point.time            # time in the file's unit (days)
    (True, 10.0)
    """
    from ..bodies import BodySet

    with _open_read(path) as f:
        count = int(f["restart/count"][()])
        if count == 0:
            raise OrbitsFileError(f"{path}: holds no complete checkpoint to restore from")
        slot = (count - 1) % _SLOTS
        par = f["parameters"]
        r = f["restart"]
        units = _unit_system(par, path)
        order = r["order"][()]
        inv = np.argsort(order)
        names = _decode(f["particles/bodies/names"][()])
        m = f["particles/bodies/mass"][()]
        radii, _ = _radii(f["particles/bodies"])
        n0 = len(names)
        x = r["x"][slot]
        v = r["v"][slot]
        if "masses" in r:
            # the bodies at this checkpoint: those of the start that collisions left
            m = r["masses"][slot]
            alive = np.isfinite(m)
            n = int(alive.sum())
            names = [name for name, keep in zip(names, alive) if keep]
            m, radii = m[alive], r["radii"][slot][alive]
            order = r["orders"][slot][:n]
            inv = np.argsort(order)
            x, v = x[:n], v[:n]
        try:
            bodies = BodySet.from_arrays(m, x[inv], v[inv], names=names, units=units,
                                         radii=radii)
        except OrbitsError as exc:
            raise OrbitsFileError(f"{path}: the bodies at its last checkpoint are not a body "
                                  f"set: {exc}") from None
        bodies.history = json.loads(par.attrs["bodies_history"])
        epoch = _epoch(par, path)
        if "config" in par.attrs:
            config = json.loads(par.attrs["config"])
        else:
            config = _legacy_config(par, units, path)
            _check_config(config, path, config["monitors"])
        _check_tangent_rows(r["ws"], config, len(names), path)
        clock = r["clock"][slot]
        state = SimulationState(
            x, v, order, float(r["t_base"][slot]), int(clock[1]), int(clock[0]),
            int(clock[2]), int(clock[4]),
            {name: _read_box(r["ws"][name], slot, len(names), n0) for name in r["ws"]},
            par["reference"][()], tuple(par["scales"][()]))
        p = r["plan"][slot]
        plan = RunPlan(float(p[0]), int(p[1]), float(p[2]), int(p[3]), bool(p[4]), int(p[5]),
                       float(p[6]))
        written, finished, _ = (int(a) for a in r["progress"][slot])
        rows = int(clock[3])
        held = _rows(f, json.loads(par.attrs["monitors"]))
        if rows > held:
            raise OrbitsFileError(f"{path}: /restart/clock at the last checkpoint counts "
                                  f"{rows} output rows, but the file holds {held}; the "
                                  f"checkpoint does not belong to these outputs")
        t = state.t_base + state.steps_since_base * float(par.attrs["dt"])
        if epoch is not None:
            bodies.epoch = epoch + units.quantity(t, "time")
    return Checkpoint(bodies, config, state, ResumePoint(plan, written, bool(finished), rows, t),
                      str(path), epoch)


def _check_tangent_rows(ws, config, n, path):
    """Raise :class:`TangentShapeError` where the checkpoints' tangent rows
    (``ws/tangent``: positions and velocities of every tangent vector, after
    the bodies' rows) do not have the shape the configuration calls for."""
    k = sum(_config_layout(config, n))
    want = (2, n * k, 3) if k else None
    found = ws["tangent"].shape[1:] if "tangent" in ws else None
    if found != want:
        what = ("no tangent rows" if found is None else
                f"tangent rows of shape {found}" + (f" ({found[1] / n:g} vectors of {n} bodies)"
                                                     if len(found) == 3 else ""))
        raise TangentShapeError(
            f"{path}: its checkpoints hold {what}, but its configuration (variations="
            f"{config.get('variations')!r}, monitors {', '.join(config['monitors']) or 'none'}"
            f") calls for " + (f"{k} tangent vectors, rows of shape {want}" if k else "none")
            + "; the file cannot restore the simulation", expected=want, found=found)


def _legacy_config(par, units, path):
    # files written before the configuration record: the same record, from the
    # attributes they have
    try:
        return _legacy_record(par, units)
    except (KeyError, TypeError, ValueError, IndexError, AttributeError) as exc:
        raise OrbitsFileError(f"{path}: the attributes of /parameters do not make a "
                              f"configuration ({type(exc).__name__}: {exc})") from None


def _legacy_record(par, units):
    soft = float(par.attrs["softening"])
    unit = lambda val, kind: None if val is None else [val, units.unit(kind).to_string()]  # noqa: E731
    stop = json.loads(par.attrs["stop_conditions"])
    dt = float(par.attrs["dt"])
    adaptive = json.loads(par.attrs.get("integrator_info", "{}")).get("adaptive", dt == 0)
    return {"integrator": par.attrs["integrator"],
            "integrator_options": json.loads(par.attrs["integrator_options"]),
            "dt": unit(dt, "time") if dt > 0 or not adaptive else None,
            "forces": [{"type": "Gravity",
                        "softening": unit(soft, "length") if soft > 0 else None,
                        "parallel": bool(par.attrs["parallel"]),
                        "rebound_arithmetic": bool(par.attrs.get("rebound_arithmetic", False))}],
            "monitors": json.loads(par.attrs["monitors"]),
            "monitor_every": int(par.attrs["monitor_every"]) or None,
            "stop_conditions": {
                "encounter_distance": unit(stop["encounter_distance"], "length"),
                "encounter_hill": stop["encounter_hill"],
                "escape_distance": unit(stop["escape_distance"], "length"),
                "escape_unbound": stop["escape_unbound"],
                "collisions": stop.get("collisions"),
                "encounter_log": _encounter_log_option(stop.get("encounter_log"), unit)}}


def _encounter_log_option(value, unit):
    # (distance or None, Hill radii or None) as written -> the keyword's value
    if not value:
        return None
    distance, hill = value
    return unit(distance, "length") if distance else hill


class ResumePoint(NamedTuple):
    """Where a restored simulation stands in the run its file was written by.

    Examples
    --------
    >>> import os, tempfile
    >>> import astropy.units as u
    >>> import orbits
    >>> from orbits.io import hdf5
    >>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    >>> _ = sim.run(until=10 * u.day, outputs=3, output=path, progress=False)
    >>> point = hdf5.read_checkpoint(path).point
    >>> point.outputs_written, point.rows, point.finished, point.plan.until
    (3, 3, True, 10.0)
    """

    plan: object            # the RunPlan of that run
    outputs_written: int    # of that run, at the checkpoint
    finished: bool
    rows: int               # output rows in the file at the checkpoint
    time: float             # simulation time at the checkpoint


def truncate(path, point):
    """Drop what was written after the checkpoint ``point`` (a :class:`ResumePoint`).

    The file is copied (into ``<path>.resume``, made exclusively, with room
    for the whole copy reserved first), which also leaves a file whose writer
    was killed clean for writing again.  The writers' lock is taken first
    (:class:`FileInUse` if a live process holds it) and kept for the
    :class:`FileRecorder` that writes on, which releases it when it closes.

    Parameters
    ----------
    path : str or path-like
    point : ResumePoint
        Rows after ``point.rows``, and in-loop monitor rows after
        ``point.time`` (in the file's unit of time), are dropped.

    Raises
    ------
    FileInUse
        Another live process is writing the file.
    OrbitsFileError
        ``path`` is a symbolic link, is damaged, or the disk has no room for
        the copy (the message says which); the file is then as it was, and
        neither the copy nor the lock is left behind.

    Examples
    --------
    >>> import os, tempfile
    >>> import astropy.units as u
    >>> import orbits
    >>> from orbits.io import hdf5
    >>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    >>> _ = sim.run(until=10 * u.day, outputs=3, output=path, progress=False)
    >>> point = hdf5.read_checkpoint(path).point
    >>> hdf5.truncate(path, point._replace(rows=1, time=0.0))   # back to the first output
    >>> orbits.load(path).times
    <Quantity [0.] d>
    """
    if os.path.islink(path):
        raise OrbitsFileError(f"{path}: a symbolic link (to {os.readlink(path)}); resume the "
                              f"file it names, so that the copy resuming makes does not "
                              f"replace the link")
    _acquire(path)
    tmp = pathlib.Path(str(path) + ".resume")
    size = os.path.getsize(path)
    need = size + size // 8 + _METADATA_BYTES       # the copy, laid out anew, and HDF5's own
    dst = None
    try:
        with _open_read(path) as src:
            dst = _new_file(tmp)
            fd = _descriptor(dst)
            if fd is not None:
                # room for the whole copy first: a full disk stops it before it starts
                _reserve(fd, 0, need)
            for k, v in src.attrs.items():
                dst.attrs[k] = v
            for name in src:
                src.copy(src[name], dst, name=name)
            groups = [dst["particles/bodies/position"], dst["particles/bodies/velocity"]]
            groups += [dst["observables"][k] for k in dst["observables"] if k != "in_loop"]
            for g in groups:
                for ds in g.values():
                    ds.resize(min(ds.shape[0], point.rows), axis=0)
            for g in dst["observables/in_loop"].values():
                # only the rows stored (see _covered): a series declared longer holds no more
                keep = int(np.count_nonzero(g["time"][:_covered(g["time"])] <= point.time))
                for ds in g.values():
                    ds.resize(keep, axis=0)
        failed, dst = _close_written(dst), None
        if failed is not None:
            raise failed
        _trim(tmp)
        os.replace(tmp, path)
    except BaseException as exc:
        # the file as it was, and neither the copy nor the lock left behind
        if dst is not None:
            _close_written(dst)
        tmp.unlink(missing_ok=True)
        _release(path)
        if isinstance(exc, OrbitsError) or not isinstance(exc, (OSError, RuntimeError)):
            raise
        if _error_number(exc) in _DISK_FULL:
            raise _write_error(path, exc, f" when copying it to resume (resuming needs "
                                          f"about {need / 1e6:.3g} MB free beside it); the "
                                          f"file is unchanged") from None
        raise OrbitsFileError(f"{path}: damaged, or its copy cannot be written: resuming "
                              f"copies the file, and the copy failed ({exc}); the file is "
                              f"unchanged") from None
