"""The public names of :mod:`orbits.io.h5md` under a second name,
``orbits.io.hdf5``, the one scripts and notebooks import: the same objects."""

from .h5md import (BUFFER_ROWS, CHECKPOINT_SECONDS, FORMAT, FORMAT_VERSION,
                   SWMR_READ_ATTEMPTS, Checkpoint, FileInUse, FileRecorder, OrbitsFileError,
                   ResumePoint, TangentShapeError, describe, load, read_checkpoint, truncate,
                   whole_run)

__all__ = ["FileRecorder", "load", "describe", "read_checkpoint", "Checkpoint", "truncate",
           "ResumePoint", "whole_run",
           "OrbitsFileError", "FileInUse", "TangentShapeError",
           "FORMAT", "FORMAT_VERSION", "CHECKPOINT_SECONDS", "BUFFER_ROWS",
           "SWMR_READ_ATTEMPTS"]
