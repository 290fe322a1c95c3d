"""Files written before a change of the file code still load and resume bit for bit.

The files in tests/data/before_split/ were written by orbits at commit e5f7d5b
(tests/data/make_before_split.py says how, and how ias15's file follows the
corrector's later arithmetic): runs stopped after the fifth of eleven
outputs.  Each is read, resumed, and compared with the same run made
now without a stop, value for value.
"""

import pathlib
import shutil

import astropy.units as u
import numpy as np
import pytest

import orbits

DATA = pathlib.Path(__file__).parent / "data" / "before_split"
#: integrator -> the options the file's simulation was made with (as in
#: tests/data/make_before_split.py)
CASES = {"ias15": dict(monitors=("energy", "angular_momentum"), monitor_every=50),
         "leapfrog": dict(monitors=("energy", "megno"))}


def simulation(name, **kw):
    adaptive = orbits.integrators.get(name).adaptive
    return orbits.Simulation(orbits.scenes.outer_solar_system(), integrator=name,
                             dt=None if adaptive else 10 * u.day, **kw)


@pytest.mark.parametrize("name", sorted(CASES))
def test_a_file_written_before_loads_and_resumes_bit_for_bit(tmp_path, name):
    path = tmp_path / "run.h5"
    shutil.copyfile(DATA / f"{name}-interrupted.h5", path)
    assert "interrupted" in orbits.io.describe(path)
    cut = orbits.load(path)
    assert len(cut.times) == 5
    whole = tmp_path / "whole.h5"
    # the same random tangent vector as the file's (its recorded seed)
    simulation(name, seed=cut.seed, **CASES[name]).run(
        until=5_000 * u.day, outputs=11, output=whole, progress=False, checkpoint_interval=0)
    now = orbits.load(whole)
    # the rows the file held before resuming are those of the run made now
    np.testing.assert_array_equal(cut.positions.value, now.positions.value[:5])
    np.testing.assert_array_equal(cut.velocities.value, now.velocities.value[:5])
    sim = orbits.Simulation.from_file(path)
    sim.resume(progress=False)
    back = orbits.load(path)
    assert back.status == "completed" and len(back.times) == 11
    for field in ("times", "positions", "velocities"):
        np.testing.assert_array_equal(getattr(back, field).value, getattr(now, field).value)
    np.testing.assert_array_equal(back.energy_error, now.energy_error)
    for name_ in CASES[name]["monitors"]:
        if name_ in ("megno", "angular_momentum"):
            np.testing.assert_array_equal(np.asarray(getattr(back, name_)),
                                          np.asarray(getattr(now, name_)))
    assert back.steps == now.steps
