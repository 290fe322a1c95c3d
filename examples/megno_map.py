"""MEGNO map: which orbits beyond Saturn are regular, and which chaotic?
=====================================================================

The Sun, Jupiter and Saturn on their J2000 orbits, and a massless test planet
whose semi-major axis (10 to 16 au) and eccentricity (0 to 0.45) run over a
48 x 24 grid.  Each run carries one random tangent vector beside the orbit
(``monitors=["megno"]``) for 24 000 years, about 2000 orbits of Jupiter and
600 of the test planet, with ``wh`` at a 216-day step (5 % of Jupiter's
period).  The map is coloured by MEGNO's running mean ``<Y>`` at the end.
The runs go to Dask workers, one process per core; the whole map took 29 s
on two cores (1152 runs of 40,583 steps)::

    python examples/megno_map.py                        # writes examples/megno_map.png
    python examples/megno_map.py --n 24 --until 6000    # a quicker, coarser map
    python examples/megno_map.py --workers 8            # more worker processes
    python examples/megno_map.py --scheduler tcp://10.0.0.5:8786   # an existing cluster

Reading the map.  ``<Y>`` (Cincotta & Simó 2000) tends to **2** on a regular,
quasi-periodic orbit (blue): the tangent vector then grows only linearly, by
the shear between neighbouring orbits.  On a chaotic orbit it grows
exponentially, ``<Y>`` grows as ``lambda t / 2`` without bound, and the map
saturates (red; the colours are clipped to [1.8, 4]).  A value means
something only after a long run.  ``<Y>`` passes 3 after about six
Lyapunov times ``1 / lambda``, so a 24 000-year run shows chaos on Lyapunov
times up to about 4000 years and calls anything slower regular.  And a
regular orbit needs hundreds of its own periods before ``<Y>`` settles at 2:
at the end of this run half of the map's regular points are within 0.05 of
2, while near resonances the value still lies anywhere from about 1.2 to 3,
depending on the random tangent vector (below 2 near a stable periodic
orbit, where ``<Y>`` tends to 0).  So read the map by its pattern, the blue
plateau, the red sea and the resonances' islands, rather than by single
points; points above 3 are counted chaotic here.

Why beyond Saturn.  Between Jupiter and Saturn (6 to 9 au) almost every
orbit is chaotic within 2000 Jupiter orbits: ``<Y>`` > 3 at 98 % of a 30 x 15
grid there (measured with this script's ``build``), as long integrations
(Gladman & Duncan 1990; Holman & Wisdom 1993) found almost no test particle
surviving in that zone; the map would have one colour.  Beyond Saturn it
has both: the chaotic zone where Saturn's resonances overlap (Wisdom 1980),
out to 11.4 au on circular orbits; the orbits that cross Saturn's (above
the dashed line: pericentre inside Saturn's aphelion) and those that come
close to it, chaotic; the regular plateau beyond; and Saturn's mean-motion
resonances (dotted), where the 3:2 at 12.5 au keeps orbits regular even
across Saturn's path, as Neptune's 3:2 keeps Pluto's.

.. image:: megno_map.png
   :alt: MEGNO's <Y> over the grid of the test planet's semi-major axis and
         eccentricity: blue (2) where regular, red where chaotic.
"""

import argparse
import pathlib
import time

import astropy.units as u
import numpy as np

import orbits

# beside this script (the current folder where there is no __file__: the docs' gallery)
HERE = pathlib.Path(globals().get("__file__", "megno_map.py")).resolve().parent

# J2000 mean elements, heliocentric ecliptic (Standish, "Keplerian elements for
# approximate positions of the major planets", JPL): a [au], e, inc, mean
# longitude L, longitude of perihelion varpi, node Omega [deg]; and the
# Sun / planet mass ratios of the IAU 2009 system
PLANETS = {"Jupiter": dict(a=5.20288700, e=0.04838624, inc=1.30439695, L=34.39644051,
                           varpi=14.72847983, Omega=100.47390909, ratio=1047.348644),
           "Saturn": dict(a=9.53667594, e=0.05386179, inc=2.48599187, L=49.95424423,
                          varpi=92.59887831, Omega=113.66242448, ratio=3497.9018)}
DT = 216 * u.day        # 5 % of Jupiter's period
CHAOTIC = 3.0           # <Y> above this: chaotic (see the module's reading guide)
RESONANCES = {"3:2": 1.5, "5:3": 5 / 3, "2:1": 2.0}    # period ratios to Saturn's


def build(a, e):
    """The Sun, Jupiter, Saturn and the test planet at (a [au], e).

    Defined at module level so that it pickles: Dask sends it to the workers.
    Every member has the same seed, so a map reproduces bit for bit.
    """
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    for name, p in PLANETS.items():
        b.add(name, mass=u.Msun / p["ratio"], primary="Sun", a=p["a"] * u.au, e=p["e"],
              inc=p["inc"] * u.deg, Omega=p["Omega"] * u.deg,
              omega=(p["varpi"] - p["Omega"]) * u.deg, M=(p["L"] - p["varpi"]) * u.deg)
    # in the ecliptic, starting at aphelion, 130 deg ahead of Saturn
    b.add("planet", mass=0 * u.kg, primary="Sun", a=a * u.au, e=e, M=180 * u.deg)
    b.move_to_com()
    return orbits.Simulation(b, integrator="wh", dt=DT, monitors=["megno"], seed=1)


def main(n=48, until=24_000 * u.yr, client=None, n_workers=None,
         png=HERE / "megno_map.png"):
    a = np.linspace(10.0, 16.0, n)
    e = np.linspace(0.0, 0.45, max(n // 2, 2))
    until = round((until / DT).to_value(u.one)) * DT    # whole steps: wh's own map
    ens = orbits.Ensemble.grid(build, e=e, a=a)
    t0 = time.perf_counter()
    df = ens.run(until=until, client=client, n_workers=n_workers, outputs=2, progress=True)
    took = time.perf_counter() - t0
    megno = df.megno.to_numpy().reshape(len(e), len(a))
    print(f"{len(df)} runs of {df.steps.iloc[0]:,} steps to {until.to(u.yr):.0f} in "
          f"{took:.1f} s ({df.steps.sum() / took / 1e6:.2g} million steps per second)")
    chaotic = ~(megno <= CHAOTIC)                   # a run that failed counts as chaotic
    print(f"chaotic (<Y> > {CHAOTIC:g}): {chaotic.mean():.0%} of the grid; regular: "
          f"{(~chaotic).mean():.0%} (within 0.05 of 2: {np.mean(abs(megno - 2) < 0.05):.0%})")
    plot(a, e, megno, until, png)
    print(f"wrote {png}")
    return df


def plot(a, e, megno, until, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 5.5), layout="constrained")
    cmap = plt.get_cmap("RdYlBu_r").with_extremes(bad="0.6")
    mesh = ax.pcolormesh(a, e, np.clip(megno, 1.8, 4.0), cmap=cmap, vmin=1.8, vmax=4.0,
                         shading="nearest")
    bar = fig.colorbar(mesh, ax=ax, extend="both")
    bar.set_label("MEGNO <Y>, clipped to [1.8, 4]: 2 regular, larger chaotic")
    saturn = PLANETS["Saturn"]
    grid_a = np.linspace(a.min(), a.max(), 200)
    ax.plot(grid_a, 1 - saturn["a"] * (1 + saturn["e"]) / grid_a, "k--", lw=1.2,
            label="pericentre at Saturn's aphelion")
    for name, ratio in RESONANCES.items():
        res = saturn["a"] * ratio ** (2 / 3)               # Kepler's third law
        ax.axvline(res, color="k", ls=":", lw=1)
        ax.text(res, e.max(), f" {name}", va="top", ha="left", fontsize=9)
    ax.set(xlim=(a.min(), a.max()), ylim=(e.min(), e.max()),
           xlabel="semi-major axis of the test planet [au]", ylabel="eccentricity",
           title=f"MEGNO beside Jupiter and Saturn ({len(a)} x {len(e)} runs, wh, "
                 f"{until.to_value(u.yr):,.0f} yr)")
    ax.legend(loc="lower right", fontsize=8, framealpha=0.8)
    fig.savefig(png, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--n", type=int, default=48,
                   help="grid points along a (half as many along e)")
    p.add_argument("--until", type=float, default=24_000, help="years")
    p.add_argument("--workers", type=int, default=None,
                   help="worker processes of the local cluster (default: one per core)")
    p.add_argument("--scheduler", default=None,
                   help="address of an existing Dask scheduler, or 'serial' for this "
                        "process alone (default: a local cluster)")
    p.add_argument("--png", default=str(HERE / "megno_map.png"))
    args = p.parse_args()
    main(args.n, args.until * u.yr, client=args.scheduler, n_workers=args.workers,
         png=args.png)
