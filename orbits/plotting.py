"""Plots a person would rather look at than read (needs matplotlib)."""

import pathlib

import numpy as np

__all__ = ["plot_result", "plot_file"]


def plot_result(result, path):
    """Orbits in the x-y plane, and the relative energy and angular-momentum
    errors against time on log axes, side by side in one PNG."""
    if not len(result.times):
        raise ValueError("the result holds no outputs: nothing to plot")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_orbit, ax_err) = plt.subplots(1, 2, figsize=(12, 5.5))
    x = result.positions
    for i, name in enumerate(result.names[:50]):
        ax_orbit.plot(x[:, i, 0].value, x[:, i, 1].value, lw=0.8, label=name)
        ax_orbit.plot(x[-1, i, 0].value, x[-1, i, 1].value, "o", ms=3, color="k")
    ax_orbit.set_aspect("equal", adjustable="datalim")
    ax_orbit.set_xlabel(f"x [{x.unit}]")
    ax_orbit.set_ylabel(f"y [{x.unit}]")
    ax_orbit.set_title("orbits (x-y plane)")
    if len(result.names) <= 12:
        ax_orbit.legend(fontsize=8, loc="upper right")
    t = result.times
    t0 = t - t[0]
    keep = t0.value > 0
    drawn = False
    for label, err in (("energy", result.energy_error),
                       ("angular momentum", result.angular_momentum_error)):
        if err is not None:
            e = np.asarray(err)[keep]
            ax_err.loglog(t0.value[keep], np.where(e > 0, e, np.nan), lw=1,
                          label=f"|{label} error| (relative)")
            drawn = True
    ax_err.set_xlabel(f"time since start [{t.unit}]")
    ax_err.set_ylabel("relative error")
    ax_err.set_title(f"{result.integrator['name']}: conservation")
    if drawn:
        ax_err.legend(fontsize=8)
    else:
        ax_err.text(0.5, 0.5, "no monitors recorded", ha="center", transform=ax_err.transAxes)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return pathlib.Path(path)


def plot_file(path, out=None):
    """Plot an output file (see :func:`plot_result`); returns the PNG's path."""
    from .io.hdf5 import OrbitsFileError, load
    out = pathlib.Path(out) if out else pathlib.Path(path).with_suffix(".png")
    result = load(path)
    if not len(result.times):
        raise OrbitsFileError(f"{path}: holds no outputs ({result.status}): nothing to plot")
    return plot_result(result, out)
