"""Sun, Jupiter and a massless probe for 1000 years with velocity Verlet.
=========================================================================

The README's first example as a script: a body set built from orbital
elements and a Cartesian state, a fixed-step run with 500 outputs, the run's
summary, and Jupiter's osculating elements at the end.  ::

    python examples/sun_jupiter_probe.py
"""

import astropy.units as u

import orbits


def main(until=1000 * u.yr):
    bodies = orbits.BodySet()
    bodies.add("Sun", mass=1 * u.Msun)
    bodies.add("Jupiter", mass=1 * u.Mjup, primary="Sun", a=5.2 * u.au, e=0.048,
               inc=1.3 * u.deg)
    bodies.add("probe", mass=0 * u.kg, position=[1, 0, 0] * u.au,
               velocity=[0, 30, 0] * u.km / u.s)
    bodies.move_to_com()

    sim = orbits.Simulation(bodies, integrator="verlet", dt=5 * u.day)
    result = sim.run(until=until, outputs=500)
    print(result.summary())
    el = sim.bodies.elements("Jupiter", primary="Sun")
    print(f"Jupiter at the end: a = {el['a']:.6f}, e = {el['e'].value:.6f}")
    return result


if __name__ == "__main__":
    main()
