"""The errors of orbits files: a file that is not one, is damaged or has another
layout version (:class:`OrbitsFileError`), one another process is writing
(:class:`FileInUse`), tangent vectors of the wrong shape
(:class:`TangentShapeError`); and the error a failed write becomes, which says
where the disk is full."""

import errno
import os
import re

from ...errors import OrbitsError

__all__ = ["OrbitsFileError", "FileInUse", "TangentShapeError"]

class OrbitsFileError(OrbitsError, OSError):
    """A file that is not an orbits output, is damaged, or has another layout version.

    Examples
    --------
    >>> import os, tempfile
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
    >>> from orbits.io.h5md import FileInUse, OrbitsFileError
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
    >>> from orbits.io.h5md import OrbitsFileError, TangentShapeError
    >>> exc = TangentShapeError("run.h5: tangent vectors of shape (2, 3, 6)", expected=(19, 3, 6),
    ...                         found=(2, 3, 6))
    >>> isinstance(exc, OrbitsFileError), exc.expected, exc.found
    (True, (19, 3, 6), (2, 3, 6))
    """

    def __init__(self, message, expected=None, found=None):
        self.expected = expected
        self.found = found
        super().__init__(message)


# their public home, where tracebacks, pickles and the reference name them
OrbitsFileError.__module__ = FileInUse.__module__ = TangentShapeError.__module__ = "orbits.io"


#: errno values of a full disk: no space left, a file larger than allowed (the
#: file system's limit, or ``ulimit -f``), the user's quota used up
_DISK_FULL = (errno.ENOSPC, errno.EFBIG, errno.EDQUOT)


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
