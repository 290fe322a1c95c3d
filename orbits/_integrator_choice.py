"""How a :class:`~orbits.Simulation` takes its integrator: a registry name with
its options given beside it, or a configured instance, and the step that a
fixed-step method cannot go without."""

import difflib
import inspect

from . import integrators as _integrators
from .errors import IntegratorOptionError

__all__ = ["configured", "step_required"]


def configured(integrator, options, signature_of):
    """The integrator instance that ``Simulation(bodies, integrator, **options)``
    means.

    Parameters
    ----------
    integrator : str or Integrator
        A registry name or alias, or a configured instance.
    options : dict
        The keywords given to the simulation that are not its own: the
        integrator's options.
    signature_of : callable
        The function whose keywords the error message suggests beside the
        integrator's options (the simulation's constructor).

    Raises
    ------
    IntegratorOptionError
        Options beside an instance, or an option the integrator does not
        have (the message lists those it has, and suggests the nearest of
        them and of the simulation's keywords).
    UnknownIntegratorError
        An unknown name (the nearest is suggested).

    Examples
    --------
    >>> from orbits._integrator_choice import configured
    >>> configured("wh", {"corrector": 17}, orbits.Simulation.__init__)
    WisdomHolman(coordinates='jacobi', corrector=17, lanes='auto')
    """
    if isinstance(integrator, _integrators.Integrator):
        if options:
            given = ", ".join(f"{k}={v!r}" for k, v in options.items())
            raise IntegratorOptionError(
                f"options ({given}) are given beside an integrator instance "
                f"({integrator!r}); give its name with them, Simulation(bodies, "
                f"{integrator.name!r}, {given}), or configure the instance with "
                f"orbits.integrators.get({integrator.name!r}, {given})")
        return integrator
    plain = _integrators.get(integrator)
    unknown = [k for k in options if k not in plain.options]
    if unknown:
        raise IntegratorOptionError(_unknown_options(plain, unknown, signature_of))
    return _integrators.get(integrator, **options) if options else plain


def _unknown_options(integ, unknown, signature_of):
    own = sorted(integ.options)
    keywords = [k for k, p in inspect.signature(signature_of).parameters.items()
                if p.kind is inspect.Parameter.KEYWORD_ONLY]
    parts = []
    for key in unknown:
        near = difflib.get_close_matches(key, own + keywords, n=1, cutoff=0.6)
        hint = f" (did you mean {near[0]!r}?)" if near else ""
        parts.append(f"{key!r}{hint}")
    valid = ", ".join(own) or "none"
    return (f"integrator {integ.name!r} has no option {', '.join(parts)}, nor is it a "
            f"keyword of Simulation; the options of {integ.name!r}: {valid}")


def step_required(integ):
    """The error for a fixed-step integrator given no ``dt``: it names the
    adaptive integrators, which need none.

    Examples
    --------
    >>> from orbits._integrator_choice import step_required
    >>> str(step_required(orbits.integrators.get("wh"))).split(";")[0]
    "integrator 'wh' takes fixed steps and needs dt (a time)"
    """
    adaptive = ", ".join(_integrators.adaptive_names())
    return IntegratorOptionError(
        f"integrator {integ.name!r} takes fixed steps and needs dt (a time); the adaptive "
        f"integrators choose their own steps and need none: {adaptive} (the default is "
        f"{_integrators.DEFAULT!r})")
