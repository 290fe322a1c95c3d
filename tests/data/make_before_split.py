"""The files in before_split/: runs of ``outer_solar_system()`` stopped after the
fifth of their eleven outputs, written by orbits at commit e5f7d5b, before
``orbits/io/hdf5.py`` became the package ``orbits.io.h5md``.
tests/test_files_before.py reads and resumes them.

Run from the repository root (at that commit the recorder is
``orbits.io.hdf5.FileRecorder``)::

    python tests/data/make_before_split.py tests/data/before_split

``ias15-interrupted.h5`` was written again on 2026-11-30 by that commit with
the corrector's arithmetic of 182f0fc (each factor ``1 / (h_n - h_j)`` as
``R + R_low`` with a fused multiply-add: the lines of the corrector and of
``_tables`` in ``orbits/_kernels/ias15.py`` as they are now), so that its rows
are those of a run made now; the file code is e5f7d5b's.
``leapfrog-interrupted.h5`` is e5f7d5b's (written again the same way, its
positions are equal to the bit).
"""

import pathlib
import sys

import astropy.units as u

import orbits
from orbits.io.hdf5 import FileRecorder

#: integrator -> the simulation's options: an adaptive integrator whose
#: workspace and in-loop monitor series are written, and a fixed-step one
#: with a chaos indicator (tangent vectors in the checkpoints)
CASES = {"ias15": dict(monitors=("energy", "angular_momentum"), monitor_every=50),
         "leapfrog": dict(monitors=("energy", "megno"))}


def simulation(name, **kw):
    adaptive = orbits.integrators.get(name).adaptive
    return orbits.Simulation(orbits.scenes.outer_solar_system(), integrator=name,
                             dt=None if adaptive else 10 * u.day, **kw)


class Crash(Exception):
    pass


def main(out):
    out.mkdir(parents=True, exist_ok=True)
    real = FileRecorder.output
    for name, kw in CASES.items():
        seen = []

        def crashing(self, sim, final=False):
            real(self, sim, final)
            seen.append(1)
            if len(seen) == 5:
                raise Crash()
        FileRecorder.output = crashing
        try:
            simulation(name, **kw).run(until=5_000 * u.day, outputs=11,
                                       output=out / f"{name}-interrupted.h5",
                                       progress=False, checkpoint_interval=0)
        except Crash:
            pass
        finally:
            FileRecorder.output = real


if __name__ == "__main__":
    main(pathlib.Path(sys.argv[1]))
