"""Reading and writing runs: :mod:`orbits.io.hdf5`."""

from .hdf5 import FileInUse, OrbitsFileError, TangentShapeError, describe, load

__all__ = ["load", "describe", "OrbitsFileError", "FileInUse", "TangentShapeError"]
