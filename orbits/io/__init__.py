"""Reading and writing runs: :mod:`orbits.io.hdf5`."""

from .hdf5 import FileInUse, OrbitsFileError, describe, load

__all__ = ["load", "describe", "OrbitsFileError", "FileInUse"]
