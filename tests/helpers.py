"""Small systems with known exact behaviour, shared by the tests."""

import orbits

#: an orbit started well away from an apsis, so that errors in position and
#: velocity both show (at an apsis some error terms vanish by symmetry)
KEPLER_F0 = 1.0


def kepler_bodies(e=0.5, f=KEPLER_F0, m_orbiter=0.0):
    """A test particle on an orbit with a = 1 about a unit mass, G = 1: period 2 pi."""
    b = orbits.BodySet(units=orbits.UnitSystem.nbody())
    b.add("star", mass=1.0)
    b.add("planet", mass=m_orbiter, primary="star", a=1.0, e=e, f=f)
    return b
