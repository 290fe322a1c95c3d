"""Restart from a file: a simulation rebuilt at the last checkpoint of an output
file, with the user's functions its run named checked against what the file
records, and the recorder that finishes an interrupted run in that file.

A file carries data, never code: the functions it names come from the caller
(:meth:`orbits.Simulation.from_file`).  The simulation's class comes from the
caller too, so that files do not import the simulation.
"""

from collections.abc import Mapping

import astropy.units as u
import numpy as np

from .. import forces as _forces
from ..errors import OrbitsError, SimulationOptionError
from ..records import FUNCTION_PREFIX, _function_name
from . import hdf5
from .hdf5 import OrbitsFileError

__all__ = ["restored", "resumed_recorder", "callers_config"]


def restored(cls, path, collisions=None, functions=None):
    """``(sim, checkpoint)``: the simulation (a ``cls``, :class:`orbits.Simulation`)
    that the last checkpoint of the output file ``path`` records, its state
    put back, and that :class:`~orbits.io.hdf5.Checkpoint` (see
    :meth:`orbits.Simulation.from_file`, which sets its epoch and the file to
    write on)."""
    if functions is None:
        functions = {}
    if not isinstance(functions, Mapping) or not all(
            isinstance(k, str) and callable(f) for k, f in functions.items()):
        raise SimulationOptionError(
            f"functions must map the names a file records to functions, as "
            f"{{'drag': drag}}; got {functions!r}")
    cp = hdf5.read_checkpoint(path)
    config = callers_config(path, cp.config, collisions, functions)
    try:
        sim = cls.from_config(cp.bodies, config, _restoring=True, functions=functions)
    except OrbitsError:
        raise
    except (TypeError, ValueError, KeyError, AttributeError, IndexError,
            u.UnitsError) as exc:
        raise OrbitsFileError(f"{path}: its recorded configuration does not make a "
                              f"simulation: {exc}") from None
    made = sim.state
    if not np.array_equal(made.order, cp.state.order):
        raise OrbitsFileError(f"{path}: the stored body order does not match the masses")
    made = made.workspace
    for name, arr in cp.state.workspace.items():
        want = made.get(name)
        if want is not None and (np.shape(arr) != np.shape(want) or np.asarray(
                arr).dtype.kind != np.asarray(want).dtype.kind):
            raise OrbitsFileError(
                f"{path}: /restart/ws/{name} holds {np.asarray(arr).dtype} values of "
                f"shape {np.shape(arr)} at the checkpoint; the simulation the file "
                f"describes keeps {np.asarray(want).dtype} values of shape "
                f"{np.shape(want)} there")
    sim.set_state(cp.state)
    return sim, cp


def resumed_recorder(sim, path, point, checkpoint_interval=None):
    """The recorder that finishes the run interrupted at ``point``
    (:class:`~orbits.io.hdf5.ResumePoint`) in the file ``path``: the rows
    written after that checkpoint are dropped, to be computed again."""
    hdf5.truncate(path, point)
    return hdf5.FileRecorder(path, sim, point.plan, checkpoint_interval=checkpoint_interval,
                             resume_rows=point.outputs_written)


def callers_config(path, config, collisions, functions):
    """The configuration ``config`` that the file ``path`` records, with the
    collisions function the caller gives; a :class:`SimulationOptionError`
    unless the caller gives every function of the user's that it names, and
    no other (see :meth:`orbits.Simulation.from_file`)."""
    try:
        needed = _forces.functions_needed(config["forces"])
    except _forces.ForceTermError as exc:
        raise OrbitsFileError(f"{path}: its recorded force terms do not rebuild: "
                              f"{exc}") from None
    given = lambda ref: ref in functions or ref.partition(":")[2] in functions  # noqa: E731
    used = {k for k in functions for ref in needed if k in (ref, ref.partition(":")[2])}
    missing = {ref: what for ref, what in needed.items() if not given(ref)}
    asks = [ref.partition(":")[2] for ref in missing]
    missing = [f"{ref!r} ({what})" for ref, what in missing.items()]
    named = config["stop_conditions"].get("collisions")
    if isinstance(named, str) and named.startswith(FUNCTION_PREFIX):
        recorded = named[len(FUNCTION_PREFIX):]
        keys = [k for k in functions if _names_function(recorded, k)]
        used.update(keys)
        if collisions is None and keys:
            collisions = functions[keys[0]]
        if collisions is None:
            missing.append(f"{recorded!r} (the collisions function; or collisions=...)")
            asks.append(recorded.rpartition(".")[2])
        elif not (_function_name(collisions) == named or _names_function(
                recorded, getattr(collisions, "__qualname__", ""))):
            raise SimulationOptionError(
                f"{path}: its run resolved collisions with the function {recorded}; the "
                f"function given, {collisions!r}, has another name")
        else:
            config = dict(config, stop_conditions=dict(config["stop_conditions"],
                                                       collisions=collisions))
    if missing:
        raise SimulationOptionError(
            f"{path}: its run used function(s) that a file names but never holds: "
            + "; ".join(missing) + "; pass them again: Simulation.from_file(path, "
            "functions={" + ", ".join(f"{name!r}: ..." for name in asks) + "})")
    unused = sorted(set(functions) - used)
    if unused:
        raise SimulationOptionError(
            f"{path}: functions names {', '.join(map(repr, unused))}, which its run did "
            f"not use; it records: {', '.join(map(repr, needed)) or 'no functions'}")
    return config


def _names_function(recorded, name):
    """Whether ``name`` (a qualname, or ``module.qualname``) is the function a
    plain record names as ``recorded`` (``module.qualname``)."""
    return bool(name) and (recorded == name or recorded.endswith("." + name))
