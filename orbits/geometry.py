"""The geometry of a set of orbits: the barycentre as a primary, the angular
momentum, the invariable plane and the angle between two orbits' planes.

Plain float64 arrays in one unit system in, plain arrays out: the body set
and the result attach the units (:meth:`orbits.BodySet.to_invariable_plane`,
:meth:`orbits.BodySet.mutual_inclination`,
:meth:`orbits.Result.mutual_inclination`, and ``primary="barycentre"`` in
their ``elements``).
"""

import numpy as np

__all__ = ["BARYCENTRE", "is_barycentre", "barycentre", "angular_momentum",
           "invariable_plane_rotation", "angle_between"]

#: The words that name the barycentre where a primary is expected (both
#: spellings); a body cannot be named by them as a primary.
BARYCENTRE = ("barycentre", "barycenter")

#: ``sin`` of the tilt between the angular momentum and the z axis below which
#: the invariable plane's node is not defined and the x axis is kept instead:
#: a few units of rounding, as for a planar orbit in
#: :data:`orbits._kernels.kepler.PLANAR_TOL`.
_NODE_TOL = 8.0 * np.finfo(float).eps


def is_barycentre(primary):
    """Whether ``primary`` is one of the words in :data:`BARYCENTRE`.

    Examples
    --------
    >>> from orbits.geometry import is_barycentre
    >>> is_barycentre("barycenter"), is_barycentre("Sun"), is_barycentre(None)
    (True, False, False)
    """
    return isinstance(primary, str) and primary in BARYCENTRE


def barycentre(m, x, v):
    """Total mass, position and velocity of the centre of mass.

    Parameters
    ----------
    m : ndarray, shape (..., N)
        Masses; a body with mass 0 (massless, or merged away) adds nothing,
        and its NaN state is not read.
    x, v : ndarray, shape (..., N, 3)
        Positions and velocities.

    Returns
    -------
    mass : ndarray, shape (...)
    position, velocity : ndarray, shape (..., 3)
        NaN where ``mass`` is 0.

    Examples
    --------
    >>> from orbits.geometry import barycentre
    >>> M, X, V = barycentre(np.array([3.0, 1.0]), np.array([[0., 0, 0], [4, 0, 0]]),
    ...                      np.zeros((2, 3)))
    >>> float(M), X.tolist()
    (4.0, [1.0, 0.0, 0.0])
    """
    m = np.asarray(m, dtype=float)
    mass = m.sum(axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        pos = np.einsum("...n,...nd->...d", m, np.where(m[..., None] > 0, x, 0.0))
        vel = np.einsum("...n,...nd->...d", m, np.where(m[..., None] > 0, v, 0.0))
        return mass, pos / mass[..., None], vel / mass[..., None]


def angular_momentum(m, x, v):
    """Total angular momentum about the centre of mass, ``sum m (x - X) x (v - V)``.

    The same in every frame that moves uniformly, whatever its origin:
    the invariable plane's normal.  Positions and velocities are taken
    relative to the barycentre before the sum, which keeps the rounding of a
    set far from its origin out of the result.

    Parameters
    ----------
    m : ndarray, shape (..., N)
    x, v : ndarray, shape (..., N, 3)

    Returns
    -------
    ndarray, shape (..., 3)
        In mass x length^2 / time of the arrays' unit system.

    Examples
    --------
    >>> from orbits.geometry import angular_momentum
    >>> x = np.array([[0., 0, 0], [1, 0, 0]]) + 5.0      # any origin
    >>> v = np.array([[0., 0, 0], [0, 1, 0]]) + 2.0      # any uniform motion
    >>> angular_momentum(np.array([1.0, 1.0]), x, v).tolist()
    [0.0, 0.0, 0.5]
    """
    m = np.asarray(m, dtype=float)
    _, X, V = barycentre(m, x, v)
    dx = np.where(m[..., None] > 0, x - X[..., None, :], 0.0)
    dv = np.where(m[..., None] > 0, v - V[..., None, :], 0.0)
    return np.einsum("...n,...nd->...d", m, np.cross(dx, dv))


def invariable_plane_rotation(L):
    """The rotation to axes whose z axis is along ``L``.

    The new x axis points along the ascending node of the new x-y plane on
    the old one (the direction of ``z x L``), and y completes a right-handed
    set: REBOUND's ``Rotation.to_new_axes(newz=L)``.  Where ``L`` is along z
    to within rounding (the node is not defined), the new x axis is the old
    one with its component along ``L`` taken out, so that a second rotation
    changes nothing beyond rounding.

    Parameters
    ----------
    L : array_like, shape (3,)
        The new z direction (any length but zero).

    Returns
    -------
    ndarray, shape (3, 3)
        Rows: the new x, y and z axes in the old coordinates; ``x @ R.T``
        rotates row vectors ``x`` into the new axes.

    Raises
    ------
    ValueError
        ``L`` is zero or not finite.

    Examples
    --------
    >>> from orbits.geometry import invariable_plane_rotation
    >>> R = invariable_plane_rotation([0.0, -1.0, 1.0])   # tilted 45 deg about x
    >>> (R @ np.array([0.0, -1.0, 1.0])).round(15).tolist()
    [0.0, 0.0, 1.414213562373095]
    >>> R[0].round(15).tolist() == [1.0, 0.0, 0.0]        # the node: along +x
    True
    """
    L = np.asarray(L, dtype=float).reshape(3)
    norm = np.linalg.norm(L)
    if not (np.isfinite(norm) and norm > 0):
        raise ValueError(f"the new z axis must be a finite non-zero vector, got {L}")
    z = L / norm
    node = np.cross([0.0, 0.0, 1.0], z)
    s = np.linalg.norm(node)
    if s > _NODE_TOL:
        xa = node / s
    else:
        xa = np.array([1.0, 0.0, 0.0]) - z[0] * z
        xa /= np.linalg.norm(xa)
    ya = np.cross(z, xa)
    return np.array([xa, ya, z])


def angle_between(a, b):
    """The angle between vectors, in [0, pi].

    From ``atan2(|a x b|, a . b)``: accurate near 0 and pi, where ``acos`` of
    the normalised dot product loses half the digits; NaN where either vector
    is NaN.

    Parameters
    ----------
    a, b : ndarray, shape (..., 3)

    Returns
    -------
    ndarray, shape (...)
        Radians.

    Examples
    --------
    >>> from orbits.geometry import angle_between
    >>> float(np.degrees(angle_between(np.array([0., 0, 1]), np.array([0., 1, 1]))))
    45.0
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))
