"""The oblateness of one body, its zonal harmonics J2 and J4, acting on every
other body: conservative and of positions only, so that every integrator
takes it, the Wisdom-Holman family in its interaction step."""

import astropy.units as u
import numpy as np

from .._kernels import terms as _k
from ..errors import ForceTermError
from . import _parameters as _p
from ._base import ForceTerm
from ._binding import BoundTerm

__all__ = ["ZonalHarmonics"]


class ZonalHarmonics(ForceTerm):
    """The oblateness of one body (J2, J4) acting on every other body.

    The potential beyond the point mass, per unit mass at ``r`` from the body
    with ``u = (r . pole) / r``::

        Phi = (G m / r) [ J2 (R / r)^2 P2(u) + J4 (R / r)^4 P4(u) ]

    The oblate body takes the reaction, so momentum is conserved (its spin
    axis is held fixed: the torque on it is not followed, so only the
    component of angular momentum along ``pole`` is conserved).
    Conservative and positions only: ``wh`` takes it.

    Parameters
    ----------
    body : str
        Name of the oblate body.
    radius : Quantity (length)
        Its equatorial (reference) radius ``R``; positive.
    J2, J4 : float
        Zonal coefficients (dimensionless).
    pole : sequence of 3 floats
        Direction of its spin axis in the simulation's frame (normalised
        here); default the frame's z axis.

    Examples
    --------
    >>> J2 = orbits.forces.ZonalHarmonics("Earth", 6378.137 * u.km, J2=1.08263e-3)
    >>> J2.wisdom_holman
    True
    """

    wisdom_holman = True
    FIELDS = ("body", "radius", "J2", "J4", "pole")
    QUANTITIES = ("radius",)

    def __init__(self, body, radius, J2=0.0, J4=0.0, pole=(0.0, 0.0, 1.0)):
        name = f"ZonalHarmonics({body!r})"
        self.body = _p.body_name(body, name, "body")
        self.radius = radius
        self.J2 = _p.number(J2, name, "J2")
        self.J4 = _p.number(J4, name, "J4")
        p = np.asarray(pole, dtype=float)
        norm = float(np.linalg.norm(p)) if p.shape == (3,) else 0.0
        if not (norm > 0 and np.isfinite(norm)):
            raise ForceTermError(f"pole must be a non-zero finite 3-vector, got {pole!r}",
                                 term=name, field="pole")
        self._pole_given = [float(c) for c in p]
        self.pole = tuple(float(c) for c in p / norm)
        if isinstance(radius, u.Quantity):
            _p.positive_length(radius.value, name)

    def to_dict(self):
        # the pole as given; the attribute holds it normalised
        return {**super().to_dict(), "pole": self._pole_given}

    def bind(self, ctx):
        term = repr(self)
        b = ctx.massive_index(self.body, term, "body", "oblate body")
        R = _p.internal(self.radius, "length", ctx, "radius")
        _p.positive_length(R, term)
        gmb = float(ctx.gm[b])
        return BoundTerm(_k.TermRow(_k.ZONAL, (b,), (gmb * self.J2 * R ** 2,
                                                     gmb * self.J4 * R ** 4)
                                    + tuple(float(c) for c in self.pole)))
