"""Opening a file that may be damaged or made to harm, before anything in it is used.

HDF5 reading a file in SWMR mode retries a metadata block whose checksum
fails, sleeping twice as long each time, about forever at its default number
of tries: a truncated file would hang the reader.  So the superblock is read
first (:func:`_superblock`).  A file recording more bytes than it has is
named truncated (after waiting up to a second for a live writer, which
records a new end a moment before it writes there).  A file not marked as
being written is opened without SWMR, where damage fails at once; one marked
as being written (by a live writer or a killed one) is opened in SWMR mode
with the tries bounded (:data:`SWMR_READ_ATTEMPTS`).  The groups and
datasets the layout needs are then checked (:mod:`orbits.io.h5md.checks`),
and a missing one is named in words.

HDF5 gives no way to bound those tries through h5py: the library's own
``H5Pset_metadata_read_attempts`` is called through ctypes
(:func:`_read_attempts_setter`).  Global heap collections, which HDF5 would
walk for ever where damaged, are walked first (:func:`_check_global_heaps`).
A file carries data, never code, and nothing outside it is read: external
and user-defined links, datasets stored in external files or as virtual
views, and filters that HDF5 would load as plugins are refused
(:func:`_inventory`); of a time series only the rows stored are read
(:func:`_covered`).
"""

import ctypes
import functools
import os
import re
import struct
import time as _time
from typing import NamedTuple

import h5py
import numpy as np

from .errors import FileInUse, OrbitsFileError
from .lock import _writer

__all__ = ["SWMR_READ_ATTEMPTS"]

#: tries of a metadata read whose checksum fails, in SWMR mode.  HDF5 sleeps
#: 1, 2, 4, ... ns between tries, so 24 tries give up after 2**24 ns = 17 ms
#: (the wait doubles with each further try); a live writer rewrites a
#: metadata block in microseconds.  HDF5's default, 100, never gives up.
SWMR_READ_ATTEMPTS = 24


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
        # reaches it (rarely: benchmarks/RESULTS.md): look again while its lock
        # says it runs
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
