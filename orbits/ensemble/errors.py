"""The exceptions of ensembles: an argument that cannot be taken, and a script
that starts a local cluster without the ``__main__`` guard.

Both are :class:`~orbits.errors.OrbitsError`; they are shown, pickled and
imported as ``orbits.ensemble.<name>``, where users meet them.
"""

from ..errors import OrbitsError

__all__ = ["MissingMainGuard", "EnsembleOptionError"]


class MissingMainGuard(OrbitsError, RuntimeError):
    """A script started a local cluster of worker processes from its top level,
    outside ``if __name__ == "__main__":``.

    Python starts the workers by importing the main script afresh in each of them
    (the ``spawn`` start method, which Dask uses); a script that starts the sweep
    as it is imported has each worker start another cluster, and the workers fail.
    Put the sweep under the guard::

        def build(a, e):
            ...

        if __name__ == "__main__":
            df = orbits.Ensemble.grid(build, a=..., e=...).run(until=...)

    Attributes
    ----------
    script : str or None
        The main script.
    line : int or None
        The line of the script from which the cluster was started.

    Examples
    --------
    >>> from orbits.ensemble import MissingMainGuard
    >>> exc = MissingMainGuard("starts a cluster at import", script="sweep.py", line=12)
    >>> isinstance(exc, (orbits.OrbitsError, RuntimeError)), exc.script, exc.line
    (True, 'sweep.py', 12)
    """

    def __init__(self, message, script=None, line=None):
        self.script = script
        self.line = line
        super().__init__(message)


class EnsembleOptionError(OrbitsError, ValueError):
    """An argument of :class:`~orbits.Ensemble` or :meth:`~orbits.Ensemble.run`
    that cannot be taken as given (the message names it, the value and what is
    expected): a parameter with the name of a result column, an ``out_dir``
    that holds another sweep, a ``batch`` that is no whole number.

    Examples
    --------
    >>> from orbits.ensemble import EnsembleOptionError
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "wh", dt=1 * u.day)
    >>> try:
    ...     orbits.Ensemble.perturbed(sim, n=2).run(until=1 * u.yr, client="serial",
    ...                                             batch=0)
    ... except EnsembleOptionError as exc:
    ...     print(exc)
    batch must be None or a whole number of systems per batch >= 1, got 0
    """


# the public name, in tracebacks and pickles
MissingMainGuard.__module__ = EnsembleOptionError.__module__ = "orbits.ensemble"
