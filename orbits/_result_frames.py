"""A result's outputs in another frame: about a body, about the barycentre,
or about the frame a name gives (:class:`~orbits.Result`'s methods
``relative_to``, ``barycentric`` and ``in_frame``), each a new result that
shares the times, masses and monitors.
"""

import copy as _copy

import numpy as np

from .errors import NoMassiveBodyError, UnknownBodyError

__all__ = []

#: the frame names besides a body's (orbits.result.FRAMES)
FRAMES = ("barycentric", "heliocentric")

#: the default frame's threshold (orbits.result.DOMINANT_MASS_FRACTION)
DOMINANT_MASS_FRACTION = 0.5


def relative_to(result, body):
    """The same outputs in the frame in which ``body`` is at rest at the origin.

    Parameters
    ----------
    body : str
        The body's name.

    Returns
    -------
    Result
        A new result whose ``positions`` and ``velocities`` (Quantity, shape
        (n, N, 3), same units) are those of this one minus ``body``'s, and
        whose ``frame`` is ``body``.  Times, masses and monitors are shared,
        unchanged.

    Raises
    ------
    UnknownBodyError
        ``body`` is not one of the bodies.

    Examples
    --------
    >>> helio = planets.relative_to("Sun")
    >>> helio.frame, helio.positions[:, 0].max()
    ('Sun', <Quantity 0. AU>)
    """
    j = result._index(body, field="frame")
    return _shifted(result, result.positions[:, j:j + 1], result.velocities[:, j:j + 1],
                    body)


def barycentric(result):
    """The same outputs in the frame of the centre of mass of all bodies.

    Returns
    -------
    Result
        A new result whose ``positions`` and ``velocities`` (Quantity, shape
        (n, N, 3), same units) are measured from the centre of mass at each
        output, and whose ``frame`` is ``"barycentric"``.  Times, masses and
        monitors are shared, unchanged.

    Raises
    ------
    NoMassiveBodyError
        No body has mass.

    Examples
    --------
    >>> bary = planets.barycentric()
    >>> com = bary.masses.value @ bary.positions / bary.masses.value.sum()
    >>> bool(abs(com).max() < 1e-15 * u.au)
    True
    """
    m = result.masses.value
    total = m.sum()
    if not total > 0:
        raise NoMassiveBodyError("the barycentre needs a body with positive mass")
    if result.masses_at_outputs is not None:
        # bodies merged away: the masses of each output, without them
        m = np.nan_to_num(result.masses_at_outputs.to_value(result.masses.unit))
        w = m / m.sum(axis=1, keepdims=True)

        def centre(a):
            return np.einsum("kn,knd->kd", w, np.nan_to_num(a.value)) << a.unit
        return _shifted(result, centre(result.positions)[:, None],
                        centre(result.velocities)[:, None], "barycentric")
    w = m / total
    return _shifted(result, (w @ result.positions)[:, None],
                    (w @ result.velocities)[:, None], "barycentric")


def in_frame(result, frame=None):
    """The same outputs in a frame given by name.

    Parameters
    ----------
    frame : str, optional
        ``"barycentric"`` (:meth:`barycentric`); ``"heliocentric"``: about
        the most massive body (the star); or a body's name
        (:meth:`relative_to`).  Default: about the most massive body when it
        holds more than :data:`DOMINANT_MASS_FRACTION` of the mass,
        otherwise barycentric.

    Returns
    -------
    Result
        With ``frame`` set to ``"barycentric"`` or the central body's name.

    Raises
    ------
    UnknownBodyError
        ``frame`` is neither a frame name nor a body's name (field ``frame``).

    Examples
    --------
    >>> planets.in_frame().frame, planets.in_frame("barycentric").frame
    ('Sun', 'barycentric')
    """
    if frame is None:
        frame = _default_frame(result)
    if frame == "barycentric":
        return result.barycentric()
    if frame == "heliocentric":
        return result.relative_to(result.names[int(np.argmax(result.masses.value))])
    if isinstance(frame, str) and frame in result.names:
        return result.relative_to(frame)
    raise UnknownBodyError(f"unknown frame; expected one of {', '.join(FRAMES)} or a "
                           f"body's name ({', '.join(result.names)})", body=frame,
                           field="frame")


def _default_frame(result):
    m = result.masses.value
    k = int(np.argmax(m))
    total = m.sum()
    if total > 0 and m[k] > DOMINANT_MASS_FRACTION * total:
        return result.names[k]
    return "barycentric"


def _shifted(result, dx, dv, frame):
    """A copy of ``result`` with ``dx`` and ``dv`` taken from its positions and
    velocities, in the frame named ``frame``."""
    new = _copy.copy(result)
    new.positions = result.positions - dx
    new.velocities = result.velocities - dv
    new.frame = frame
    return new
