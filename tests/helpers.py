"""Small systems with known exact behaviour, shared by the tests."""

import math

import numpy as np

import orbits
from orbits._kernels import stepping
from orbits._kernels.gravity import gravity_args

#: an orbit started well away from an apsis, so that errors in position and
#: velocity both show (at an apsis some error terms vanish by symmetry)
KEPLER_F0 = 1.0


def kepler_bodies(e=0.5, f=KEPLER_F0, m_orbiter=0.0):
    """A test particle on an orbit with a = 1 about a unit mass, G = 1: period 2 pi."""
    b = orbits.BodySet(units=orbits.UnitSystem.nbody())
    b.add("star", mass=1.0)
    b.add("planet", mass=m_orbiter, primary="star", a=1.0, e=e, f=f)
    return b


def adaptive_fixed_steps_error(name, n, e=0.2):
    """Global error of an adaptive integrator over one Kepler orbit taken in n
    equal steps: tolerances so loose that every step is accepted and the
    controller only ever proposes longer ones, so each call to ``advance_to``
    ends in one step shortened to exactly 2 pi / n."""
    integ = orbits.integrators.get(name, rtol=1e6, atol=1e6)
    b = kepler_bodies(e=e)
    x, v = b.positions.value.copy(), b.velocities.value.copy()
    x0, v0 = x.copy(), v.copy()
    m = b.masses.value
    ws = integ.workspace(2, 2 * math.pi / n)
    fargs = gravity_args(1.0, m, 1, 0.0)
    force = stepping.gravity_force("small")
    mon = (0, 0, m, 1.0, 1, 0.0)
    t = 0.0
    for k in range(n):
        status, t, acc, rej, fev, _ = integ.advance_to(
            ws, x, v, t, (k + 1) * 2 * math.pi / n, force, fargs, mon, k, np.empty(0),
            np.zeros((0, 11)), None, 10)
        assert status == 0 and acc == 1 and rej == 0
    return np.abs(x - x0).max() + np.abs(v - v0).max()


def jupiter_saturn(a_saturn, e_saturn=0.05):
    """The Sun, Jupiter and a Saturn at ``a_saturn`` au (au, Msun, day): regular at
    9.5 au, chaotic at 6.6 au (period ratio 1.37)."""
    import astropy.units as u
    b = orbits.BodySet()
    b.add("Sun", 1 * u.Msun)
    b.add("Jupiter", 9.55e-4 * u.Msun, primary="Sun", a=5.2 * u.au, e=0.05, f=0.3 * u.rad)
    b.add("Saturn", 2.86e-4 * u.Msun, primary="Sun", a=a_saturn * u.au, e=e_saturn,
          inc=0.01 * u.rad, f=2.1 * u.rad)
    return b
