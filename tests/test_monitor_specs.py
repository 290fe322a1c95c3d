"""A monitor is declared once, by its spec (orbits._monitor_specs): every table
that lists monitors (the kernels' row, the mask, the file's series, the
result's fields, the ensemble's columns) holds exactly the specs' names."""

import astropy.units as u
import h5py
import numpy as np
import pytest

import orbits
from orbits import _monitor_specs as specs
from orbits._kernels import invariants as _inv
from orbits.ensemble import table
from orbits.monitors import (CHAOS_MONITORS, DEFAULT_MONITORS, MONITOR_SPECS, MONITORS,
                             MonitorSpec, monitor_field_names, monitor_fields)
from orbits.result import Result

CHOSEN = [s.name for s in MONITOR_SPECS if s.chosen]


def test_the_kernels_row_is_the_specs_columns():
    by_start = sorted(MONITOR_SPECS, key=lambda s: s.row_slice.start)
    assert tuple(c for s in by_start for c in s.columns) == _inv.MONITOR_COLUMNS
    for s in MONITOR_SPECS:
        assert list(_inv.MONITOR_COLUMNS[s.row_slice]) == list(s.columns)
        if s.chosen:
            assert getattr(_inv, s.name.upper()) == s.bit


def test_the_mask_and_the_named_sets_are_the_specs():
    assert list(MONITORS) == CHOSEN
    assert [MONITORS[n] for n in CHOSEN] == [s.bit for s in MONITOR_SPECS if s.chosen]
    assert CHAOS_MONITORS == tuple(s.name for s in MONITOR_SPECS if s.chaos)
    assert DEFAULT_MONITORS == tuple(s.name for s in MONITOR_SPECS if s.default)


def test_the_results_fields_are_the_specs():
    # the export order of Result.to_pandas and to_xarray
    assert specs.RESULT_FIELDS == (
        "energy", "work", "energy_error", "test_particle_energy_error", "angular_momentum",
        "angular_momentum_error", "momentum", "center_of_mass", "megno", "lyapunov", "fli")
    names = {s.name for s in MONITOR_SPECS} | {s.error_field for s in MONITOR_SPECS
                                              if s.error}
    assert set(specs.RECORDED_FIELDS) == names
    empty = Result(names=[], times=[] * u.day)
    for name in specs.RECORDED_FIELDS:
        assert getattr(empty, name) is None
    # every chosen monitor with the work, rows of the kernels' width
    rows = np.random.default_rng(1).random((2, _inv.MONITOR_WIDTH)) + 1.0
    out = monitor_fields(rows, CHOSEN, rows[0], (1.0, 1.0), orbits.UnitSystem(), work=True)
    assert set(out) == names
    assert monitor_field_names(CHOSEN, _inv.MONITOR_WIDTH, work=True) == tuple(out)
    for s in MONITOR_SPECS:
        assert np.shape(out[s.name]) == (2,) + s.shape
        assert getattr(out[s.name], "unit", u.dimensionless_unscaled) == \
            s.unit(orbits.UnitSystem())


def test_the_ensembles_columns_are_the_specs():
    U = orbits.UnitSystem()
    errors = [s.ensemble for s in MONITOR_SPECS if s.error and s.ensemble]
    assert errors == ["energy_error_max", "angular_momentum_error_max"]
    assert table._MIDDLE == ("steps", *errors)
    columns = [c for _, c, _ in table._monitor_columns(U)]
    assert columns == ["megno", "lyapunov_per_day", "fli"]
    for c in (*errors, *columns):
        assert table._is_result_column(c)
    order = table._column_order(["fli", "run", "lyapunov_per_day", "megno", *errors, "steps"],
                                [])
    assert order == ["run", "steps", *errors, "megno", "lyapunov_per_day", "fli"]


def test_the_files_series_are_the_specs(tmp_path):
    path = tmp_path / "run.h5"
    monitors = [n for n in CHOSEN if n not in CHAOS_MONITORS]
    sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day,
                            monitors=monitors)
    sim.run(until=4 * u.day, outputs=3, output=path, progress=False)
    with h5py.File(path, "r") as f:
        obs = f["observables"]
        assert sorted(k for k in obs if k != "in_loop") == sorted(monitors)
        for name in monitors:
            s = specs.BY_NAME[name]
            assert obs[name]["value"].shape == (3,) + s.shape
            assert obs[name]["value"].attrs["unit"] == s.file_unit(sim.units)
        units = f["parameters/reference"].attrs["unit"].split(", ")
        assert len(units) == _inv.MONITOR_WIDTH
        for s in MONITOR_SPECS:
            assert units[s.row_slice] == [s.file_unit(sim.units)] * len(s.columns)
    loaded = orbits.load(path)
    for name in monitors:
        assert getattr(loaded, name) is not None
    assert loaded.momentum.unit == sim.units.unit("momentum")


def test_a_new_spec_needs_its_kernel_column_and_then_fills_every_table():
    tidal = MonitorSpec("tidal", ("tidal",), "energy", bit=128, error="scalar", scale=0,
                        ensemble="tidal_error_max")
    with pytest.raises(ImportError, match="kernels' monitor row"):
        specs._check(MONITOR_SPECS + (tidal,), _inv.MONITOR_COLUMNS)
    specs._check(MONITOR_SPECS + (tidal,), _inv.MONITOR_COLUMNS + ("tidal",))
    assert specs.result_fields(tidal) == ("tidal", "tidal_error")
    with pytest.raises(ImportError, match="not distinct powers of two"):
        specs._check(MONITOR_SPECS + (MonitorSpec("twice", ("t",), "energy", bit=1),),
                     _inv.MONITOR_COLUMNS + ("t",))
    with pytest.raises(ImportError, match="not side by side"):
        split = MonitorSpec("split", ("energy", "Ly"), "energy", bit=256)
        specs._check((split,), ("energy", "Lx", "Ly"))
