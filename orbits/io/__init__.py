"""Reading and writing runs: :mod:`orbits.io.h5md`."""

from . import hdf5      # the name orbits.io.h5md's public names had before, kept for users
from .h5md import FileInUse, OrbitsFileError, TangentShapeError, describe, load

__all__ = ["load", "describe", "OrbitsFileError", "FileInUse", "TangentShapeError"]
