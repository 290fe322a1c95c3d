"""Ensembles on Dask: rows, outcomes, perturbations, resuming, and serial == cluster."""

import pathlib
import runpy
import subprocess
import sys

import astropy.units as u
import cloudpickle
import h5py
import numba
import numpy as np
import pytest

import orbits
from orbits.ensemble import INDEX_FILE, Ensemble, local_cluster

# builds defined here travel to the workers by value (the workers cannot import
# this test module by name)
cloudpickle.register_pickle_by_value(sys.modules[__name__])

# columns that say where and how fast a run went, not what it computed
WHERE = ["wall_time_s", "worker", "kernels_compiled", "kernels_loaded"]


def planet(a, e):
    """Sun, a Jupiter and a 10-Earth-mass planet at (a, e), with both stopping conditions."""
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    b.add("Jupiter", mass=1 * u.Mjup, primary="Sun", a=5.2 * u.au)
    b.add("planet", mass=10 * u.Mearth, primary="Sun", a=a * u.au, e=e, f=2 * u.rad)
    b.move_to_com()
    return orbits.Simulation(b, integrator="leapfrog", dt=30 * u.day, encounter_hill=3.0,
                             escape_distance=100 * u.au)


def collision(speed):
    # two near-massless bodies flying head on: a step lands both on the origin
    # (the same set-up as test_simulation's collision_course)
    b = orbits.BodySet(units=orbits.UnitSystem.nbody())
    b.add("a", mass=1e-300, position=[5, 0, 0], velocity=[-speed, 0, 0])
    b.add("b", mass=1e-300, position=[-5, 0, 0], velocity=[speed, 0, 0])
    return orbits.Simulation(b, integrator="leapfrog", dt=1.0)


# a sweep with every outcome a planet can have: stable (a = 8-9 au, e = 0),
# Jupiter encounters (near 6 au, or eccentric), escape (apocentre 108 au > 100
# au), and parameters that describe no orbit (e < 0)
SWEEP = [{"a": a, "e": e} for a in (6.0, 6.5, 8.0, 9.0) for e in (0.0, 0.2, 0.5)] + \
        [{"a": 60.0, "e": 0.8}, {"a": 7.0, "e": -0.1}]
UNTIL = 3000 * u.yr


@pytest.fixture(scope="module")
def serial():
    return Ensemble(planet, SWEEP).run(UNTIL, client="serial", progress=False)


def test_grid_varies_the_first_axis_slowest():
    ens = Ensemble.grid(planet, a=[6.0, 7.0], e=np.array([0.0, 0.1, 0.2]))
    assert len(ens) == 6
    assert ens.parameters[0] == {"a": 6.0, "e": 0.0}
    assert ens.parameters[2] == {"a": 6.0, "e": 0.2}
    assert ens.parameters[3] == {"a": 7.0, "e": 0.0}
    assert type(ens.parameters[1]["e"]) is float      # numpy scalars become plain numbers


def test_parameters_must_be_keywords():
    with pytest.raises(ValueError, match="identifiers"):
        Ensemble(planet, [{"a": 6.0, "not a name": 1}])


def test_rows_agree_with_running_each_simulation_alone(serial):
    assert list(serial.index) == list(range(len(SWEEP)))
    assert set(serial.outcome) == {"completed", "close-encounter", "escape", "invalid"}
    for i, p in enumerate(SWEEP):
        row = serial.loc[i]
        assert (row.a, row.e) == (p["a"], p["e"])
        try:
            sim = planet(**p)
        except orbits.ElementsError as exc:
            assert row.outcome == "invalid" and row.message == str(exc)
            continue
        try:
            result = sim.run(UNTIL, outputs=100, progress=False)
            outcome, t, bodies = "completed", sim.time.to_value(u.day), ""
        except (orbits.CloseEncounter, orbits.Escape) as exc:
            outcome, t, bodies = ("escape" if isinstance(exc, orbits.Escape)
                                  else "close-encounter"), exc.time.to_value(u.day), \
                ",".join(exc.bodies)
            result = exc.result
        assert row.outcome == outcome
        assert row.stop_bodies == bodies
        assert row.t_stop_day == t
        assert row.steps == sim.steps
        assert row.energy_error_max == result.max_energy_error()
        assert row.angular_momentum_error_max == result.max_angular_momentum_error()
        el = sim.bodies.elements("planet", primary="Sun")
        assert row.planet_a_au == el["a"].to_value(u.au)
        assert row.planet_e == el["e"].value
        assert row.planet_inc_rad == el["inc"].to_value(u.rad)
        assert not np.isnan(row.Jupiter_a_au) and "Sun_a_au" not in serial.columns


def test_non_finite_state_is_an_outcome():
    df = Ensemble(collision, [{"speed": 2.0}, {"speed": 10.0}, {"speed": 2.5}]).run(
        10.0, client="serial", outputs=2, progress=False)
    # leapfrog takes forces after half a drift, at x = 5 - speed (k + 1/2): speed 2
    # puts both bodies on the origin in step 3 (k = 2), speed 10 in step 1, and
    # speed 2.5 never (they pass each other)
    assert df.loc[0].outcome == "non-finite-state" and df.loc[0].steps == 2
    assert df.loc[0].t_stop == 2.0            # the last good state (N-body units: no suffix)
    assert "non-finite" in df.loc[0].message
    assert df.loc[1].outcome == "non-finite-state" and df.loc[1].steps == 0
    assert df.loc[2].outcome == "completed" and df.loc[2].t_stop == 10.0


def test_a_build_error_that_is_not_about_the_parameters_stops_the_sweep():
    def broken(a):
        raise ZeroDivisionError("a bug in build")
    with pytest.raises(ZeroDivisionError):
        Ensemble(broken, [{"a": 1}]).run(UNTIL, client="serial", progress=False)


def test_progress_bar_counts_finished_runs(capsys):
    Ensemble(planet, SWEEP[:3]).run(100 * u.yr, client="serial", progress=True)
    assert "3/3" in capsys.readouterr().err


# -- perturbed copies -----------------------------------------------------------------

def test_perturbed_shifts_positions_by_the_relative_amount_reproducibly():
    sim = planet(7.0, 0.1)
    base = sim.bodies
    ens = Ensemble.perturbed(sim, n=5, scale=1e-6, seed=3)
    again = Ensemble.perturbed(sim, n=50, scale=1e-6, seed=3)
    other = Ensemble.perturbed(sim, n=5, scale=1e-6, seed=4)
    x0 = base.positions.to_value(u.au)
    r = np.linalg.norm(x0 - base.center_of_mass()[0].to_value(u.au), axis=1)
    shifts = []
    for k in range(5):
        x = ens.simulation(k).bodies.positions.to_value(u.au)
        d = np.linalg.norm(x - x0, axis=1)
        # |shift| = scale * r up to the rounding of x + shift (1 ulp of x ~ 1e-15 au)
        np.testing.assert_allclose(d, 1e-6 * r, rtol=1e-8)
        # same seed and member: the same bits, whatever n is
        np.testing.assert_array_equal(x, again.simulation(k).bodies.positions.to_value(u.au))
        assert not np.array_equal(x, other.simulation(k).bodies.positions.to_value(u.au))
        np.testing.assert_array_equal(ens.simulation(k).bodies.velocities, base.velocities)
        shifts.append(x - x0)
    assert len({s.tobytes() for s in shifts}) == 5


@pytest.mark.parametrize("a, e, stop", [(6.5, 0.2, orbits.CloseEncounter),
                                        (60.0, 0.8, orbits.Escape)])
def test_perturbed_copies_keep_the_simulation_options(a, e, stop):
    # scale 0: each copy must run exactly as the original, stopping conditions included
    sim = planet(a, e)
    df = Ensemble.perturbed(sim, n=2, scale=0.0).run(UNTIL, client="serial", progress=False)
    with pytest.raises(stop) as exc:
        sim.run(UNTIL, outputs=100, progress=False)
    for k in range(2):
        assert df.loc[k].outcome == ("escape" if stop is orbits.Escape else "close-encounter")
        assert df.loc[k].t_stop_day == exc.value.time.to_value(u.day)
        assert df.loc[k].planet_a_au == sim.bodies.elements("planet", "Sun")["a"].value
    assert df.loc[0].member == 0 and df.loc[1].member == 1


# -- files and resuming ---------------------------------------------------------------

class Interruptible:
    """``planet`` that counts its calls and can be told to stop the sweep at a run."""

    calls = []
    stop_at = None

    def __call__(self, a, e):
        if (a, e) == Interruptible.stop_at:
            raise KeyboardInterrupt
        Interruptible.calls.append((a, e))
        return planet(a, e)


def test_an_interrupted_sweep_resumes_where_it_stopped(tmp_path):
    build = Interruptible()
    whole = Ensemble(build, SWEEP).run(UNTIL, client="serial", progress=False,
                                       out_dir=tmp_path / "whole")
    out = tmp_path / "cut"
    Interruptible.calls, Interruptible.stop_at = [], (SWEEP[5]["a"], SWEEP[5]["e"])
    with pytest.raises(KeyboardInterrupt):
        Ensemble(build, SWEEP).run(UNTIL, client="serial", progress=False, out_dir=out)
    assert len(Interruptible.calls) == 5
    (out / "run-00005.h5").write_bytes(b"a run cut off while writing")
    Interruptible.calls, Interruptible.stop_at = [], None
    resumed = Ensemble(build, SWEEP).run(UNTIL, client="serial", progress=False,
                                         out_dir=out)
    assert Interruptible.calls == [(p["a"], p["e"]) for p in SWEEP[5:]]
    assert resumed.drop(columns=WHERE).equals(whole.drop(columns=WHERE))
    # the rows read back from the index are the rows that were written
    again = Ensemble(build, SWEEP).run(UNTIL, client="serial", progress=False, out_dir=out)
    assert len(Interruptible.calls) == len(SWEEP) - 5
    assert again.equals(resumed)
    # every run that made a simulation has its file, which ends where the row says
    for i, row in resumed.iterrows():
        if row.outcome == "invalid":
            assert row.file == ""
            continue
        result = orbits.load(out / row.file)
        assert result.times[-1].to_value(u.day) == row.t_stop_day
    assert (out / INDEX_FILE).read_text().count("\n") == len(SWEEP) + 1


def test_another_sweep_is_not_resumed_into_an_out_dir(tmp_path):
    Ensemble(planet, SWEEP[:2]).run(100 * u.yr, client="serial", progress=False,
                                    out_dir=tmp_path)
    with pytest.raises(ValueError, match="another sweep"):
        Ensemble(planet, SWEEP[:3]).run(100 * u.yr, client="serial", progress=False,
                                        out_dir=tmp_path)


# -- on a cluster -----------------------------------------------------------------------

def test_two_worker_cluster_is_bit_identical_to_serial_and_compiles_once(serial, tmp_path):
    to_file = Ensemble(planet, SWEEP).run(UNTIL, client="serial", progress=False,
                                          out_dir=tmp_path / "serial")
    df = Ensemble(planet, SWEEP).run(UNTIL, client=None, n_workers=2, progress=False,
                                     out_dir=tmp_path / "dask")
    assert df.drop(columns=WHERE).equals(to_file.drop(columns=WHERE))
    # and a run kept in memory tabulates the same numbers as one written to a file
    assert df.drop(columns=WHERE + ["file"]).equals(serial.drop(columns=WHERE + ["file"]))
    for row in df.itertuples():
        if row.file:
            with h5py.File(tmp_path / "serial" / row.file) as a, \
                    h5py.File(tmp_path / "dask" / row.file) as b:
                for name in ("position", "velocity"):
                    va = a[f"particles/bodies/{name}/value"][()]
                    vb = b[f"particles/bodies/{name}/value"][()]
                    assert va.tobytes() == vb.tobytes()
    workers = df.groupby("worker")
    assert workers.ngroups == 2
    # a fresh worker gets its kernels in one task (loaded from the disk cache the
    # serial run above left, or compiled if a kernel source changed since) and
    # never again
    for _, rows in workers:
        busy = rows.kernels_compiled + rows.kernels_loaded > 0
        assert busy.sum() == 1, rows[WHERE]


def test_an_existing_cluster_by_client_or_address(serial):
    client = local_cluster(1)
    try:
        for how in (client, client.scheduler.address):
            df = Ensemble(planet, SWEEP[:4]).run(UNTIL, client=how, progress=False)
            assert df.drop(columns=WHERE).equals(serial.iloc[:4].drop(columns=WHERE))
        assert client.status == "running"      # a cluster it was given, it leaves open
        assert set(client.run(numba.get_num_threads).values()) == {1}   # one per process
        # the workers run without the statistical profiler (its sampling thread
        # shares the run's core); a worker takes its nanny's configuration, so
        # an environment variable alone would not do this
        from orbits.ensemble import WORKER_DASK_CONFIG

        def settings(dask_worker):
            import dask
            return tuple(dask.config.get(k) for k in WORKER_DASK_CONFIG)
        assert set(client.run(settings).values()) == {tuple(WORKER_DASK_CONFIG.values())}
        assert not any("profile" in name for name in
                       client.run(lambda dask_worker: list(dask_worker.periodic_callbacks))
                       .popitem()[1])
        # nothing listens beyond the loopback interface
        info = client.scheduler_info()
        assert all(a.startswith("tcp://127.0.0.1:") for a in
                   [client.scheduler.address, *info["workers"]])
    finally:
        client.close()
        client.cluster.close()


WORKER_SCRIPT = """
import astropy.units as u
import numba
import orbits                       # imported by each worker before its environment is set
from orbits.ensemble import local_cluster

def build(e):
    return orbits.Simulation(orbits.scenes.kepler(e=e), integrator="leapfrog", dt=1 * u.day)

def compile_something():
    return numba.njit(lambda x: x + 1)(1)

if __name__ == "__main__":
    client = local_cluster(1)
    try:
        orbits.Ensemble(build, [{"e": 0.1}, {"e": 0.2}]).run(1 * u.yr, client=client,
                                                              progress=False)
        print(client.submit(numba.get_num_threads, pure=False).result(),
              client.submit(compile_something, pure=False).result())
    finally:
        client.close()
        client.cluster.close()
"""


def test_workers_use_one_numba_thread_even_if_the_script_imported_numba_first(tmp_path):
    # the worker's task thread uses one numba thread, and compiling after the
    # pool started still works (numba refuses a thread count changed under it)
    script = tmp_path / "sweep.py"
    script.write_text(WORKER_SCRIPT)
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                         cwd=tmp_path, timeout=120)
    assert out.returncode == 0, out.stderr[-3000:]
    assert out.stdout.strip().splitlines()[-1] == "1 2"


def test_import_orbits_imports_neither_dask_nor_pandas():
    code = ("import sys, orbits; assert orbits.Ensemble.__name__ == 'Ensemble'; "
            "import orbits.ensemble; "
            "print(sorted(m for m in ('dask', 'distributed', 'pandas') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "[]"


@pytest.mark.slow
def test_with_a_cold_cache_each_worker_compiles_in_its_first_task_only(tmp_path, monkeypatch):
    # workers inherit this process's environment when they are spawned: an empty
    # numba cache of their own makes the first task of each compile (~7 s)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    df = Ensemble(planet, SWEEP).run(UNTIL, client=None, n_workers=2, progress=False)
    assert df.groupby("worker").ngroups == 2
    for _, rows in df.groupby("worker"):
        assert (rows.kernels_compiled > 0).sum() == 1
    assert list(tmp_path.rglob("*.nbi")), "the workers wrote no cache"


@pytest.mark.slow
def test_the_readme_commands_for_an_existing_cluster(serial, tmp_path):
    # the commands of the ensembles guide for an existing cluster, on loopback
    import os
    import time

    env = dict(os.environ, NUMBA_NUM_THREADS="1",
               DASK_DISTRIBUTED__WORKER__PROFILE__ENABLED="False")
    procs = [subprocess.Popen(["dask", "scheduler", "--host", "127.0.0.1", "--port", "8786",
                               "--no-dashboard"], env=env, cwd=tmp_path,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        time.sleep(2)
        procs.append(subprocess.Popen(["dask", "worker", "tcp://127.0.0.1:8786", "--nworkers",
                                       "-1", "--nthreads", "1", "--no-dashboard"], env=env,
                                      cwd=tmp_path, stdout=subprocess.DEVNULL,
                                      stderr=subprocess.DEVNULL))
        from distributed import Client
        with Client("tcp://127.0.0.1:8786", timeout=30) as client:
            client.wait_for_workers(os.cpu_count(), timeout=60)   # one per core
        df = Ensemble(planet, SWEEP).run(UNTIL, client="tcp://127.0.0.1:8786",
                                         progress=False)
        assert df.drop(columns=WHERE).equals(serial.drop(columns=WHERE))
        assert df.groupby("worker").ngroups == min(2, os.cpu_count())
    finally:
        for p in reversed(procs):
            p.terminate()
            p.wait(timeout=30)


def test_stability_map_example(tmp_path, capsys):
    example = pathlib.Path(__file__).resolve().parents[1] / "examples" / "stability_map.py"
    mod = runpy.run_path(str(example))
    df = mod["main"](n=3, until=300 * u.yr, client="serial", png=tmp_path / "map.png")
    assert len(df) == 9 and (tmp_path / "map.png").stat().st_size > 10_000
    # a = 5.9 au with e = 0.5 crosses Jupiter's orbit: an encounter within 300 yr
    assert df.loc[2].outcome == "close-encounter"
    assert "9 runs to 300 yr" in capsys.readouterr().out
