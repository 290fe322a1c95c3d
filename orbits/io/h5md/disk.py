"""Writing safely: space reserved on disk ahead of each write, a file whose
writes fail closed without writing again, temporary files made exclusively.

A full disk stops a run between two writes: before each write the disk is
asked (``posix_fallocate``) for the space it may take, and where there is
none the run stops with an :class:`OrbitsFileError` that says the disk is
full, the file closed whole, ending at or after its last checkpoint, and the
space reserved past its end given back.  While it is being written a file
may therefore be larger than the end its superblock records.  Temporary
files (``<file>.creating``, ``<file>.resume``) are made exclusively, never
through a link that has their name, and a destination that is a link is
refused unless asked to be replaced.

HDF5 closing a dataset or a file flushes it first.  Where that flush fails (a
full disk), HDF5 frees the object but keeps its identifier, and closes it
again when the library shuts down at exit: a use after free, and the
interpreter's segmentation fault after a full disk.  So space is reserved on
disk ahead of what a write takes (_reserve), which makes a full disk show as
a failed reservation between two writes, with nothing pending that cannot be
written; and a file whose writes failed anyway (a file system that cannot
reserve) is closed with what HDF5 still holds for it sent to /dev/null
(_abandon).  Temporary files are made exclusively (_new_file).
"""

import errno
import functools
import os
import pathlib

import h5py

from ...errors import OrbitsError
from .errors import OrbitsFileError, _DISK_FULL, _write_error
from .safety import _superblock

__all__ = []

try:
    import resource     # the file-size limit (ulimit -f); POSIX only
except ImportError:     # pragma: no cover - not POSIX
    resource = None

#: bytes reserved beyond what the next write needs, so that the disk is asked
#: for space about once per this much output rather than at every write
_RESERVE_BYTES = 4 << 20
#: bytes of HDF5's own bookkeeping a write may add besides the data and the
#: chunks it starts (chunk indexes, object headers, heaps): the first write,
#: which starts a chunk of every series, adds the most, up to about this
#: much (benchmarks/RESULTS.md)
_METADATA_BYTES = 1 << 19
#: bytes reserved for a row of the collision or encounter log (a few floats,
#: and names kept in HDF5's global heap)
_LOG_ROW_BYTES = 1024


class _NoRoom(OSError):
    """The disk has no room for what the next write may take (see _reserve)."""


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
