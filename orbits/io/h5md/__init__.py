"""The orbits output file: H5MD 1.1 with a restart group, streamed while a run
goes and read back as Quantities.

One module an idea, each importing only those above it:

``errors``
    :class:`OrbitsFileError`, :class:`FileInUse`, :class:`TangentShapeError`,
    and the error a failed write becomes.
``lock``
    the writers' lock, ``<file>.lock``: one process writes a file at a time.
``safety``
    opening a file that may be damaged or made to harm: its superblock read
    first, SWMR reads with bounded tries (a ctypes call into libhdf5), links
    and storage that leave the file refused.
``disk``
    writing safely: space reserved ahead of each write, a file whose writes
    fail closed without writing again, temporary files made exclusively.
``layout``
    the format: its paths, attributes and version, and a new file made in it.
``checks``
    what a reader trusts: a file's layout and every value a reader uses,
    checked before use.
``writer``
    :class:`FileRecorder`, which ``Simulation.run`` writes through.
``reader``
    :func:`load`, :func:`describe` (``orbits info``) and :func:`whole_run`.
``checkpoint``
    :func:`read_checkpoint` (``Simulation.from_file``) and :func:`truncate`
    (before a resume); files written before the configuration record.

Examples
--------
>>> import os, tempfile
>>> from orbits.io import h5md
>>> path = os.path.join(tempfile.mkdtemp(), "run.h5")
>>> sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
>>> _ = sim.run(until=10 * u.day, outputs=3, output=path, progress=False)
>>> h5md.load(path).times
<Quantity [ 0.,  5., 10.] d>
"""

from .checkpoint import Checkpoint, ResumePoint, read_checkpoint, truncate
from .errors import FileInUse, OrbitsFileError, TangentShapeError
from .layout import FORMAT, FORMAT_VERSION
from .reader import describe, load, whole_run
from .safety import SWMR_READ_ATTEMPTS
from .writer import BUFFER_ROWS, CHECKPOINT_SECONDS, FileRecorder

__all__ = ["FileRecorder", "load", "describe", "read_checkpoint", "Checkpoint", "truncate",
           "ResumePoint", "whole_run",
           "OrbitsFileError", "FileInUse", "TangentShapeError",
           "FORMAT", "FORMAT_VERSION", "CHECKPOINT_SECONDS", "BUFFER_ROWS",
           "SWMR_READ_ATTEMPTS"]
