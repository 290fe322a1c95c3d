"""
Plotting a run: orbits, elements and an orbit sketch
====================================================

The outer solar system (:func:`orbits.scenes.outer_solar_system`: the Sun,
the four giant planets and Pluto) for 100 000 years with the Wisdom-Holman
map and a step of 100 days, drawn three ways:

* :meth:`orbits.Result.plot`: the orbits in the x-y plane, about the Sun
  (the default frame: the most massive body, which holds most of the mass),
  and the relative errors of energy and angular momentum against time;
* :meth:`orbits.Result.plot_elements`: each planet's osculating semi-major
  axis, eccentricity and inclination against time, in kyr;
* :meth:`orbits.BodySet.plot_orbits`: a sketch of the starting body set,
  each body on its osculating Keplerian ellipse.

By themselves the plotting functions return :class:`matplotlib.figure.Figure`
objects that pyplot does not manage (nothing opens a window in a script or a
test); given ``fig=plt.figure()`` (or ``ax=`` for the sketch) they draw into
pyplot's figures, which ``plt.show()`` (and this page) shows.  ::

    python examples/plotting_a_run.py                 # run and show the figures
    python examples/plotting_a_run.py --png run       # also write run_orbits.png, ...
"""

# %%
# The run and the three figures
# -----------------------------
# 1e5 years are 365 250 steps of 100 days.  300 outputs are one every 333
# years: Jupiter, Saturn and Pluto move far along their orbits between two
# outputs, so :meth:`~orbits.Result.plot` draws them as a dot per output
# rather than a mesh of chords; Uranus and Neptune, whose periods (84 and 165
# years) nearly divide 333 years, move on only a little from one output to
# the next and are drawn as lines.

import argparse

import astropy.units as u
import matplotlib.pyplot as plt

import orbits


def main(until=1e5 * u.yr, outputs=300, png_prefix=None):
    """Run the outer solar system to ``until`` and make the three figures.

    Returns the run's :class:`~orbits.Result` and a dict of the figures,
    ``"orbits"``, ``"elements"`` and ``"sketch"``, drawn into pyplot's
    figures (so that ``plt.show()`` and the gallery show them); with
    ``png_prefix``, also writes them to ``<png_prefix>_<name>.png``.
    """
    bodies = orbits.scenes.outer_solar_system()
    sim = orbits.Simulation(bodies, integrator="wh", dt=100 * u.day)
    result = sim.run(until=until, outputs=outputs, progress=False)
    print(result.summary())
    figures = {
        "orbits": result.plot(fig=plt.figure(figsize=(12, 5.5))),
        "elements": result.plot_elements(fig=plt.figure(figsize=(8, 7.5))),
        "sketch": bodies.plot_orbits(ax=plt.figure(figsize=(7, 7)).add_subplot()),
    }
    if png_prefix is not None:
        for name, fig in figures.items():
            fig.savefig(f"{png_prefix}_{name}.png", dpi=90)
    return result, figures


# %%
# Running it
# ----------
# First figure: the orbits about the Sun, left; right, the relative energy
# error, which stays below 1e-6 without growing, as a symplectic map's does,
# and the angular-momentum error, which the map would conserve exactly in
# exact arithmetic: it grows through round-off only, to about 5e-11.
# Second: the elements about the centre of mass of the bodies before each;
# Jupiter's and Saturn's eccentricities trade with a period of about 50 kyr.
# The scene is in its published frame, the Earth's equator, so the
# inclinations are near 23 degrees.  Third: the orbits at the start, Pluto's
# eccentric one crossing Neptune's.

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="The outer solar system for 1e5 years, "
                                                 "plotted three ways.")
    parser.add_argument("--years", type=float, default=1e5, help="length of the run")
    parser.add_argument("--outputs", type=int, default=300)
    parser.add_argument("--png", metavar="PREFIX", help="write PREFIX_<figure>.png")
    args = parser.parse_args()
    result, figures = main(args.years * u.yr, args.outputs, args.png)
    plt.show()
