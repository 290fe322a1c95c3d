"""The dissipative terms, which take energy out of an orbit (or put it in):
migration and damping on prescribed time scales (:class:`Migration`), the
constant-time-lag tide (:class:`TidesConstantTimeLag`), radiation pressure
and Poynting-Robertson drag (:class:`RadiationPressure`).

Each reads velocities and adds nothing to the conserved energy: the loops
integrate its work (:attr:`orbits.Simulation.work`), and the Wisdom-Holman
family does not take it.
"""

import math

import astropy.units as u
import numpy as np

from .._kernels import terms as _k
from ..errors import ForceTermError
from . import _parameters as _p
from ._base import ForceTerm
from ._binding import BoundTerm

__all__ = ["Migration", "TidesConstantTimeLag", "RadiationPressure"]


class _Dissipative(ForceTerm):
    """A term that reads velocities and does work: its energy kernel is zero."""

    velocity_dependent = True
    conservative = False
    why_not_wisdom_holman = "it is dissipative and depends on velocities"


class Migration(_Dissipative):
    """Orbital migration and eccentricity and inclination damping of one body on
    prescribed time scales (Papaloizou & Larwood 2000), the forces of REBOUNDx's
    ``modify_orbits_forces``.

    The body's acceleration relative to its ``primary`` is ::

        a = -u / (2 tau_a) - 2 (r . u) r / (r^2 tau_e) - 2 u_z z_hat / tau_inc

    with ``r``, ``u`` the body's position and velocity relative to the primary
    and ``z_hat`` the frame's z axis (the reference plane is the xy plane).
    Orbit-averaged, ``a`` decays as ``exp(-t / tau_a)``, and a low ``e`` as
    ``exp(-t / tau_e)`` (at constant angular momentum, so that damping ``e``
    also moves ``a`` a little), a low inclination as ``exp(-t / tau_inc)``.
    The pair shares the acceleration in inverse proportion to the masses, the
    body taking ``m_p / (m_p + m_b)`` of it and the primary the rest with the
    opposite sign, so the relative acceleration is ``a`` and momentum is
    conserved.  For the innermost body about the central one this is REBOUNDx's
    default (Jacobi) choice exactly.  Give one term per body.

    A positive time scale damps (inward migration), a negative one grows
    (outward migration): REBOUNDx's ``tau_a`` is minus this one.
    Dissipative and velocity-dependent: not for the Wisdom-Holman family.  Its
    energy kernel is zero.

    Parameters
    ----------
    body : str
        Name of the migrating body.
    tau_a, tau_e, tau_inc : Quantity (time) or None
        E-folding times of the semi-major axis, the eccentricity and the
        inclination; non-zero and finite; None leaves that part out (give at
        least one).
    primary : str, optional
        Name of the body the orbit is relative to; default the most massive
        other body.

    Raises
    ------
    ForceTermError
        A time scale that is zero or not finite, or none given; when bound, a
        primary without mass or the body as its own primary.
    UnknownBodyError
        When bound, ``body`` or ``primary`` is not in the body set.

    References
    ----------
    Papaloizou, J. C. B. & Larwood, J. D. 2000, MNRAS 315, 823.  Kostov, V. B. et
    al. 2016, ApJ 832, 183 (the form REBOUNDx implements).

    Examples
    --------
    >>> term = orbits.forces.Migration("Planet", tau_a=1e4 * u.yr, tau_e=1e3 * u.yr)
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "ias15", forces=[term])
    >>> term.velocity_dependent, term.conservative, term.wisdom_holman
    (True, False, False)
    """

    FIELDS = ("body", "tau_a", "tau_e", "tau_inc", "primary")
    QUANTITIES = ("tau_a", "tau_e", "tau_inc")

    def __init__(self, body, tau_a=None, tau_e=None, tau_inc=None, primary=None):
        name = f"Migration({body!r})"
        self.body = _p.body_name(body, name, "body")
        self.primary = _p.body_name(primary, name, "primary", optional=True, body=body)
        self.tau_a = tau_a
        self.tau_e = tau_e
        self.tau_inc = tau_inc
        if tau_a is None and tau_e is None and tau_inc is None:
            raise ForceTermError("give at least one of tau_a, tau_e, tau_inc (a time "
                                 "scale, Quantity)", term=name, field="tau_a", body=body)
        for field in self.QUANTITIES:
            value = getattr(self, field)
            if isinstance(value, u.Quantity):
                self._check_scale(np.asarray(value.value, dtype=float), name, field)

    def _check_scale(self, value, term, field):
        if value.shape != () or not (math.isfinite(value) and value != 0):
            raise ForceTermError(
                f"expected a non-zero finite time scale (positive damps, negative grows) "
                f"or None, got {value}", term=term, field=field, body=self.body)

    def bind(self, ctx):
        term = repr(self)
        b = ctx.index(self.body, term, "body")
        if self.primary is None:
            others = [i for i in range(len(ctx.m)) if i != b]
            if not others or not ctx.m[others].max() > 0:
                raise ForceTermError("no other body has mass to be the primary", term=term,
                                     field="primary", body=self.body)
            p = others[int(np.argmax(ctx.m[others]))]
        else:
            p = ctx.massive_index(self.primary, term, "primary", "primary")
        if p == b:
            raise ForceTermError("the body cannot be its own primary", term=term,
                                 field="primary", body=self.body)
        inv = []
        for field in self.QUANTITIES:
            value = getattr(self, field)
            if value is None:
                inv.append(0.0)
                continue
            tau = np.asarray(_p.internal(value, "time", ctx, field))
            self._check_scale(tau, term, field)
            inv.append(1.0 / float(tau))
        gb = float(ctx.gm[b])
        gp = float(ctx.gm[p])
        return BoundTerm(_k.TermRow(_k.MIGRATION, (b, p), (gp / (gp + gb), gb / (gp + gb),
                                                           inv[0], inv[1], inv[2])))


class TidesConstantTimeLag(_Dissipative):
    """The constant-time-lag tide raised on one body by every other massive
    body (Hut 1981; Eggleton, Kiseleva & Hut 1998), the force of REBOUNDx's
    ``tides_constant_time_lag`` (Baronett et al. 2022).

    The body (mass ``m``, radius ``R``, Love number ``k2``, time lag ``tau``,
    fixed spin ``Omega``) is distorted by each other massive body ``j``; the
    bulge, lagging by ``tau``, pulls on ``j`` with ::

        F_j = -3 k2 G m_j^2 R^5 / r^8 [ r + tau (2 (r . u) r / r^2 + u + r x Omega) ]

    where ``r``, ``u`` are ``j``'s position and velocity relative to the body; the
    body takes ``-F_j``, so momentum is conserved.  The first term is the
    conservative tidal distortion (potential ``-k2 G m_j^2 R^5 / (2 r^6)``), the
    rest the lag's dissipation; ``time_lag = 0`` leaves the conservative part
    alone, as REBOUNDx does.  This is Hut's (1981) force with his ``k``
    written ``k2``.  Orbit-averaged, a low eccentricity decays at Hut's
    rate (his eq. 10), with the spin along the orbit's normal ::

        de/dt = -27 k2 tau n^2 (m_j / m) (R / a)^5 e [1 - (11/18) Omega / n]

    The spin is held fixed (the torque on it is not followed): zero by default,
    as REBOUNDx's default; REBOUNDx's ``OmegaMag`` is a spin along the frame's
    z axis, ``spin=[0, 0, OmegaMag]`` here.  REBOUNDx lets only its primary
    raise a tide on a body other than the primary; here every massive body
    does (the same for two bodies, or for the tide on the central body).
    Dissipative and velocity-dependent: not for the Wisdom-Holman family.  Its
    energy kernel is zero (the conservative part's potential included).

    Parameters
    ----------
    body : str
        Name of the tidally distorted body; it must have mass.
    k2 : float
        Its potential Love number of degree 2, twice the apsidal motion constant;
        finite and not negative.
    time_lag : Quantity (time)
        The constant time lag ``tau``; finite and not negative.
    radius : Quantity (length)
        Its physical radius ``R``; positive and finite.
    spin : Quantity (angular velocity), shape (3,), optional
        Its fixed spin vector ``Omega`` (``rad / day`` or ``1 / day``); default zero.

    Raises
    ------
    ForceTermError
        A negative or non-finite ``k2``, ``time_lag`` or ``radius`` (or a zero
        radius), a spin that is not a finite 3-vector; when bound, a body
        without mass.
    UnknownBodyError
        When bound, ``body`` is not in the body set.

    References
    ----------
    Hut, P. 1981, A&A 99, 126.  Eggleton, P. P., Kiseleva, L. G. & Hut, P. 1998,
    ApJ 499, 853.  Baronett, S. A., Ferich, N., Tamayo, D. & Steffen, J. H. 2022,
    MNRAS 510, 6001 (arXiv:2101.12277).

    Examples
    --------
    >>> tide = orbits.forces.TidesConstantTimeLag("Planet", k2=0.3, time_lag=600 * u.s,
    ...                                           radius=1 * u.Rjup)
    >>> sim = orbits.Simulation(orbits.scenes.kepler(), "ias15", forces=[tide])
    >>> tide.velocity_dependent, tide.wisdom_holman
    (True, False)
    """

    FIELDS = ("body", "k2", "time_lag", "radius", "spin")
    QUANTITIES = ("time_lag", "radius", "spin")

    def __init__(self, body, k2, time_lag, radius, spin=None):
        name = f"TidesConstantTimeLag({body!r})"
        self.body = _p.body_name(body, name, "body")
        self.k2 = _p.number(k2, name, "k2", body)
        if self.k2 < 0:
            raise ForceTermError(f"expected a Love number k2 >= 0, got {self.k2}", term=name,
                                 field="k2", body=body)
        self.time_lag = time_lag
        self.radius = radius
        self.spin = spin
        if isinstance(time_lag, u.Quantity):
            self._check_lag(time_lag.value, name)
        if isinstance(radius, u.Quantity):
            _p.positive_length(radius.value, name, body)
        if isinstance(spin, u.Quantity):
            _p.check_spin(spin.value, name)

    def _check_lag(self, value, term):
        value = np.asarray(value, dtype=float)
        if value.shape != () or not (value >= 0 and math.isfinite(value)):
            raise ForceTermError(f"expected a finite time lag >= 0, got {value}", term=term,
                                 field="time_lag", body=self.body)

    def bind(self, ctx):
        term = repr(self)
        b = ctx.massive_index(self.body, term, "body", "tidally distorted body")
        R = _p.internal(self.radius, "length", ctx, "radius")
        _p.positive_length(R, term, self.body)
        tau = _p.internal(self.time_lag, "time", ctx, "time_lag")
        self._check_lag(tau, term)
        spin = _p.angular_velocity(self.spin, ctx, term)
        return BoundTerm(_k.TermRow(_k.TIDES, (b,), (3.0 * self.k2 * R ** 5, tau)
                                    + tuple(float(c) for c in spin)))


class RadiationPressure(_Dissipative):
    """Radiation pressure and Poynting-Robertson drag from one source (Burns,
    Lamy & Soter 1979), the force of REBOUNDx's ``radiation_forces``.

    A body with ``beta`` (radiation pressure over the source's gravity) feels ::

        a = beta G m_s / r^2 [ (1 - rdot / c) r_hat - u / c ]

    with ``r``, ``u`` its position and velocity relative to the source and
    ``rdot = r_hat . u``: the pressure cancels ``beta`` of the source's pull, the
    velocity terms are the drag.  The source takes no reaction (it radiates
    isotropically), so momentum is not conserved, as in REBOUNDx.  A circular
    orbit spirals in as ``r^2 = r0^2 - 4 beta G m_s t / c`` (Wyatt & Whipple
    1950), reaching the source after ``c r0^2 / (4 beta G m_s)``.
    Dissipative and velocity-dependent: not for the Wisdom-Holman family.  Its
    energy kernel is zero.

    Parameters
    ----------
    source : str
        Name of the radiating body (the Sun); it must have mass.
    beta : float, dict or sequence of float
        One ``beta`` for every body but the source; a dict ``{name: beta}`` (the
        others feel nothing); or one value per body in the body set's order, 0
        for the source.  Finite and not negative; below 1 for a body on a bound
        orbit about the source.
    c : Quantity (speed), optional
        Speed of light; default astropy's ``c``.

    Raises
    ------
    ForceTermError
        A negative or non-finite ``beta``; when bound, ``beta >= 1`` for a body
        bound to the source, a ``beta`` for the source itself, a sequence of the
        wrong length, a source without mass.
    UnknownBodyError
        When bound, the source or a name in ``beta`` is not in the body set.

    References
    ----------
    Burns, J. A., Lamy, P. L. & Soter, S. 1979, Icarus 40, 1.  Wyatt, S. P. &
    Whipple, F. L. 1950, ApJ 111, 134.

    Examples
    --------
    >>> b = orbits.scenes.kepler()
    >>> b.add("dust", mass=0 * u.kg, primary="Star", a=2 * u.au)
    >>> rad = orbits.forces.RadiationPressure("Star", beta={"dust": 0.1})
    >>> sim = orbits.Simulation(b, "ias15", forces=[rad])
    >>> sim.forces
    (RadiationPressure(source='Star', beta={'dust': 0.1}),)
    """

    FIELDS = ("source", "beta", "c")
    QUANTITIES = ("c",)

    def __init__(self, source, beta, *, c=None):
        name = f"RadiationPressure({source!r})"
        self.source = _p.body_name(source, name, "source")
        self.c = c
        if isinstance(beta, dict):
            self.beta = {}
            for key, value in beta.items():
                if not isinstance(key, str):
                    raise ForceTermError(f"beta's keys must be body names, got {key!r}",
                                         term=name, field="beta")
                self.beta[key] = self._check_beta(value, name, key)
        elif np.ndim(beta) == 1:
            self.beta = [self._check_beta(value, name, k) for k, value in enumerate(beta)]
        else:
            self.beta = self._check_beta(beta, name, None)

    @staticmethod
    def _check_beta(value, term, body):
        out = _p.number(value, term, "beta", body)
        if out < 0:
            raise ForceTermError(f"expected beta >= 0 (radiation pushes outward), got {out}",
                                 term=term, field="beta", body=body)
        return out

    def bind(self, ctx):
        term = repr(self)
        s = ctx.massive_index(self.source, term, "source", "source")
        n = len(ctx.m)
        beta = np.zeros(n)
        if isinstance(self.beta, dict):
            for name, value in self.beta.items():
                i = ctx.index(name, term, "beta")
                if i == s:
                    raise ForceTermError("the source feels no radiation of its own; leave "
                                         "it out of beta", term=term, field="beta", body=name)
                beta[i] = value
        elif isinstance(self.beta, list):
            if len(self.beta) != n:
                raise ForceTermError(f"expected {n} values of beta, one per body in the body "
                                     f"set's order, got {len(self.beta)}", term=term,
                                     field="beta")
            beta[:] = np.asarray(self.beta)[ctx.order]
            if beta[s] != 0:
                raise ForceTermError(f"the source feels no radiation of its own; expected "
                                     f"beta = 0 for it, got {beta[s]}", term=term,
                                     field="beta", body=self.source)
        else:
            beta[:] = self.beta
            beta[s] = 0.0
        self._check_bound(ctx, s, beta, term)
        ic = 1.0 / _p.speed_of_light(self, ctx)
        return BoundTerm(_k.TermRow(_k.RADIATION, (s,), (float(ctx.gm[s]), ic), beta))

    def _check_bound(self, ctx, s, beta, term):
        # beta >= 1 cancels the source's pull or more: a bound body would be flung out
        us = ctx.order[s]
        for i in np.flatnonzero(beta >= 1.0):
            k = ctx.order[i]
            r = float(np.linalg.norm(ctx.x_user[k] - ctx.x_user[us]))
            v2 = float(np.sum((ctx.v_user[k] - ctx.v_user[us]) ** 2))
            if 0.5 * v2 - (ctx.gm[s] + ctx.gm[i]) / r < 0:
                raise ForceTermError(
                    f"beta = {beta[i]} >= 1 for a body on a bound orbit about "
                    f"{self.source!r}: radiation would cancel the source's gravity or more; "
                    f"expected beta < 1 for a bound body", term=term, field="beta",
                    body=ctx.names[i])
