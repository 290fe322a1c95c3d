"""Stability map: where can a second planet live next to a Jupiter?
=================================================================

The Sun, a Jupiter analogue (a = 5.2 au, e = 0.048) and a 10-Earth-mass planet
whose semi-major axis and eccentricity run over a 40 x 40 grid.  Each run
stops at a close encounter (the planets within 3 mutual Hill radii) or an
escape (beyond 100 au); the map is coloured by the time that took, white where
the planet survived the whole run.  The runs go to Dask workers, one process per
core, and the whole sweep takes a few minutes on two cores::

    python examples/stability_map.py                      # writes examples/stability_map.png
    python examples/stability_map.py --n 20 --until 2000  # a quicker, coarser map
    python examples/stability_map.py --scheduler tcp://10.0.0.5:8786   # an existing cluster

The dashed line is where the planet's pericentre reaches Jupiter's aphelion;
the dotted one is Gladman's (1993) Hill-stability limit for two circular
orbits, a separation of 2 sqrt(3) mutual Hill radii.  Inside the band between
them almost nothing survives; well outside it on the right almost everything.

.. image:: stability_map.png
   :alt: Time to a close encounter or escape over the grid of semi-major axis
         and eccentricity, white where the planet survived.
"""

import argparse
import pathlib
import time

import astropy.units as u
import numpy as np

import orbits

# beside this script (the current folder where there is no __file__: the docs' gallery)
HERE = pathlib.Path(globals().get("__file__", "stability_map.py")).resolve().parent
A_J, E_J = 5.2, 0.048              # au; Jupiter's orbit
M_PLANET = 10 * u.Mearth
HILL_K = 3.0                       # close encounter: within this many mutual Hill radii
ESCAPE = 100 * u.au


def build(a, e):
    """The three bodies with the second planet at (a [au], e).

    Defined at module level so that it pickles: Dask sends it to the workers.
    """
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    b.add("Jupiter", mass=1 * u.Mjup, primary="Sun", a=A_J * u.au, e=E_J)
    # a quarter turn from Jupiter: not already at conjunction
    b.add("planet", mass=M_PLANET, primary="Sun", a=a * u.au, e=e, M=90 * u.deg)
    b.move_to_com()
    return orbits.Simulation(b, integrator="leapfrog", dt=30 * u.day,
                             encounter_hill=HILL_K, escape_distance=ESCAPE)


def main(n=40, until=50_000 * u.yr, client=None, png=HERE / "stability_map.png",
         out_dir=None):
    ens = orbits.Ensemble.grid(build, a=np.linspace(5.9, 9.9, n), e=np.linspace(0, 0.5, n))
    t0 = time.perf_counter()
    df = ens.run(until=until, client=client, out_dir=out_dir, progress=True)
    took = time.perf_counter() - t0
    print(f"{len(df)} runs to {until:g} in {took:.1f} s "
          f"({df.steps.sum() / took / 1e6:.1f} million steps per second)")
    print(df.outcome.value_counts().to_string())
    plot(df, n, until, png)
    print(f"wrote {png}")
    return df


def plot(df, n, until, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    a = df.a.to_numpy().reshape(n, n)
    e = df.e.to_numpy().reshape(n, n)
    years = (df.t_stop_day.to_numpy() * u.day).to_value(u.yr).reshape(n, n)
    survived = (df.outcome == "completed").to_numpy().reshape(n, n)
    top = np.log10(until.to_value(u.yr))
    shown = np.where(survived, np.inf, np.log10(np.maximum(years, 1e-3)))

    fig, ax = plt.subplots(figsize=(7.5, 5.5), layout="constrained")
    cmap = plt.get_cmap("magma").with_extremes(over="white")
    mesh = ax.pcolormesh(a, e, shown, cmap=cmap, vmin=min(1.0, top - 1), vmax=top - 1e-9,
                         shading="nearest")
    bar = fig.colorbar(mesh, ax=ax, extend="max")
    bar.set_label(f"log10 time to close encounter or escape [yr]  (white: survived "
                  f"{until.to_value(u.yr):g} yr)")
    grid_a = np.linspace(a.min(), a.max(), 200)
    ax.plot(grid_a, 1 - A_J * (1 + E_J) / grid_a, "c--", lw=1.2,
            label="pericentre at Jupiter's aphelion")
    mu = ((1 * u.Mjup + M_PLANET) / (3 * u.Msun)).decompose().value ** (1 / 3)
    gladman = A_J * (1 + mu * np.sqrt(3)) / (1 - mu * np.sqrt(3))   # (a2-a1) = 2sqrt3 R_H
    ax.axvline(gladman, color="c", ls=":", lw=1.2, label="Hill stable beyond (circular)")
    ax.set(xlim=(a.min(), a.max()), ylim=(e.min(), e.max()),
           xlabel="semi-major axis of the second planet [au]", ylabel="eccentricity",
           title=f"A {M_PLANET.value:g} Earth-mass planet beside a Jupiter "
                 f"({n} x {n} runs, leapfrog, 30-day step)")
    ax.legend(loc="lower right", fontsize=8, framealpha=0.8)
    fig.savefig(png, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--n", type=int, default=40, help="grid points per axis")
    p.add_argument("--until", type=float, default=50_000, help="years")
    p.add_argument("--scheduler", default=None,
                   help="address of an existing Dask scheduler (default: a local cluster)")
    p.add_argument("--out-dir", default=None, help="write each run's HDF5 file here")
    p.add_argument("--png", default=str(HERE / "stability_map.png"))
    args = p.parse_args()
    main(args.n, args.until * u.yr, client=args.scheduler, png=args.png, out_dir=args.out_dir)
