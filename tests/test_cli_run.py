"""``orbits run``: body-set files, integrator options, stopping conditions, --com."""

import re

import numpy as np
import pytest

import orbits
from orbits import cli
from orbits.cli import main

SYSTEM = '''\
[[body]]
name = "Sun"
mass = "1 Msun"

[[body]]
name = "Jupiter"
mass = "1 Mjup"
primary = "Sun"
a = "5.2 au"
e = 0.048
inc = "1.3 deg"

[[body]]
name = "probe"
mass = 0
position = ["1 au", "0 au", "0 au"]
velocity = ["0 km/s", "30 km/s", "0 km/s"]
'''


@pytest.fixture
def system(tmp_path):
    path = tmp_path / "system.toml"
    path.write_text(SYSTEM)
    return path


def test_runs_a_toml_file(system, capsys):
    assert main(["run", str(system), "-i", "leapfrog", "--dt", "5d", "--until", "1yr",
                 "--outputs", "5", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "bodies          3: Sun, Jupiter, probe" in out
    assert re.search(r"steps\s+74 ", out)  # 365.25 d / 5 d: 73 steps and a last short one


def test_runs_a_csv_file(tmp_path, capsys):
    path = tmp_path / "system.csv"
    orbits.systemfile.write(orbits.scenes.kepler(), path)
    assert main(["run", str(path), "-i", "rk4", "--dt", "1d", "--until", "100d",
                 "--outputs", "5", "--no-progress"]) == 0
    assert "bodies          2: Star, Planet" in capsys.readouterr().out


def test_run_table_gives_defaults_and_options_override_them(system, capsys):
    system.write_text(SYSTEM + '\n[run]\nintegrator = "dop853"\nuntil = "1 yr"\n'
                               'outputs = 3\n[run.options]\nrtol = 1e-8\n')
    assert main(["run", str(system), "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "dop853" in out and "rtol=1e-08" in out and "-> 1 yr" in out
    assert main(["run", str(system), "--rtol", "1e-6", "--until", "10d", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "rtol=1e-06" in out and "-> 10 d" in out


def test_rtol_reaches_the_integrator(tmp_path, capsys):
    out = tmp_path / "run.h5"
    assert main(["run", "kepler", "-i", "dopri5", "--rtol", "1e-6", "--atol", "1e-9",
                 "--until", "100d", "--outputs", "3", "--out", str(out),
                 "--no-progress"]) == 0
    result = orbits.load(str(out))
    assert result.integrator["name"] == "dopri5"
    assert result.integrator["option.rtol"] == 1e-6
    assert result.integrator["option.atol"] == 1e-9


@pytest.mark.parametrize("argv, shown", [
    (["-i", "ias15", "--epsilon", "1e-7"], "epsilon=1e-07"),
    (["-i", "taylor", "--tol", "1e-12"], "tol=1e-12"),
    (["-i", "wh", "--dt", "50d", "--corrector", "17", "--coordinates",
      "democratic-heliocentric"], "coordinates='democratic-heliocentric', corrector=17"),
])
def test_options_reach_other_integrators(argv, shown, capsys):
    assert main(["run", "outer-solar-system", *argv, "--until", "1000d", "--outputs", "3",
                 "--no-progress"]) == 0
    out = capsys.readouterr().out
    summary = re.search(r"integrator .*", out).group(0)
    for part in shown.split(", "):
        assert part.replace("'", "") in summary


@pytest.mark.parametrize("argv, words", [
    (["-i", "verlet", "--dt", "10d", "--rtol", "1e-6"], ["'verlet' has no option 'rtol'"]),
    (["-i", "ias15", "--rtol", "1e-6"], ["'ias15' has no option 'rtol'", "epsilon"]),
    (["-i", "wh", "--dt", "10d", "--coordinates", "helio"], ["unknown coordinates 'helio'"]),
    (["-i", "saba2", "--dt", "10d", "--corrector", "5"], ["corrector"]),
    (["-i", "dop853", "--rtol", "-1e-6"], ["'rtol' must be a positive"]),
    (["-i", "taylor", "--tol", "0"], ["'tol' must be a positive"]),
    (["-i", "verlet", "--dt", "10d", "--escape-distance", "-3au"], ["escape_distance"]),
])
def test_option_errors_are_clear(argv, words, capsys):
    assert main(["run", "outer-solar-system", *argv, "--until", "100d",
                 "--no-progress"]) == 3
    err = capsys.readouterr().err
    for word in words:
        assert word in err


def test_distances_need_lengths(capsys):
    with pytest.raises(SystemExit):
        main(["run", "kepler", "-i", "ias15", "--until", "1d", "--encounter-distance", "3d"])
    assert "'3d' is not a length" in capsys.readouterr().err


def test_option_help_names_the_integrators_that_take_each_option():
    # the help lists them from the declarations read without importing the
    # integrators: every integrator listed takes the option, every other one
    # refuses it, and a non-default value is taken by the listed ones but those
    # whose own check refuses it (saba's corrector, which the help says)
    values = {"epsilon": 1e-8, "tol": 1e-12, "rtol": 1e-6, "atol": 1e-10, "corrector": 17,
              "coordinates": "democratic-heliocentric", "min_dt": 1e-6,
              "adaptive_mode": "prs24", "order": 12, "hill": 2.0, "speed": 2.0,
              "pericentre": 1.0, "lanes": "off"}
    refused = {"corrector": {"saba2", "saba3", "saba4"}}
    taken_by = {option: {name for _, names in takers for name in names}
                for option, takers in cli.integrator_options().items()}
    assert set(values) == set(taken_by)
    for option, value in values.items():
        takers = set()
        for info in orbits.integrators.available():
            try:
                orbits.integrators.get(info.name, **{option: value})
            except orbits.IntegratorOptionError:
                continue
            takers.add(info.name)
        assert takers == taken_by[option] - refused.get(option, set()), option
    assert "SABA: 0 only" in cli._option_help(cli.integrator_options()["corrector"])


def test_help_shows_a_worked_example(capsys):
    with pytest.raises(SystemExit) as info:
        main(["run", "--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    assert "examples:" in out and "orbits run system.toml" in out
    assert '[[body]]\n  name = "Sun"' in out  # raw formatting keeps the file's lines
    for option in ("--epsilon", "--rtol", "--atol", "--corrector", "--coordinates",
                   "--encounter-distance", "--escape-distance", "--com"):
        assert option in out
    # the example file in the help reads
    toml = out.split("system.toml (numbers with units; angles in deg or rad):", 1)[1]
    toml = toml.split("then:", 1)[0]
    sf = orbits.systemfile.loads("\n".join(line[2:] for line in toml.splitlines()))
    assert sf.bodies.names == ["Sun", "Jupiter", "probe"]


def com_position(path):
    result = orbits.load(str(path))
    m = result.masses.value
    return np.linalg.norm(m @ result.positions[0].value / m.sum())


def test_com_moves_the_scene_to_its_centre_of_mass_frame(tmp_path):
    args = ["run", "outer-solar-system", "-i", "leapfrog", "--dt", "10d", "--until", "20d",
            "--outputs", "2", "--no-progress"]
    assert main([*args, "--out", str(tmp_path / "a.h5")]) == 0
    assert main([*args, "--com", "--out", str(tmp_path / "b.h5")]) == 0
    # the published frame has its centre of mass ~1e-3 au from the origin
    assert com_position(tmp_path / "a.h5") > 1e-4
    assert com_position(tmp_path / "b.h5") < 1e-14


def test_com_from_the_run_table(system, tmp_path):
    system.write_text(SYSTEM + "\n[run]\ncom = true\n")
    assert main(["run", str(system), "-i", "leapfrog", "--dt", "5d", "--until", "10d",
                 "--outputs", "2", "--out", str(tmp_path / "c.h5"), "--no-progress"]) == 0
    assert com_position(tmp_path / "c.h5") < 1e-14


@pytest.mark.parametrize("argv, words", [
    (["--escape-distance", "25au"], ["status          escape", "'Neptune' escaped"]),
    (["--encounter-distance", "1000au"], ["close encounter of"]),
])
def test_stopping_conditions_stop_with_status_1(argv, words, capsys):
    code = main(["run", "outer-solar-system", "-i", "leapfrog", "--dt", "100d", "--until",
                 "1000d", "--outputs", "3", "--no-progress", *argv])
    assert code == 1
    out = capsys.readouterr().out
    assert "integrator      leapfrog" in out  # the summary of what was done
    for word in words:
        assert word in out


def test_file_and_scene_errors(tmp_path, capsys):
    assert main(["run", str(tmp_path / "none.toml"), "--until", "1yr"]) == 3
    assert "no such file" in capsys.readouterr().err
    bad = tmp_path / "bad.toml"
    bad.write_text(SYSTEM.replace('"1.3 deg"', "1.3"))
    assert main(["run", str(bad), "--until", "1yr"]) == 3
    assert f"{bad}, line 11: body 'Jupiter', field 'inc'" in capsys.readouterr().err
    assert main(["run", "no-such-scene", "--until", "1yr"]) == 3
    assert ".toml or .csv" in capsys.readouterr().err
    assert main(["run", "kepler", "-i", "ias15"]) == 3
    assert "--until is needed" in capsys.readouterr().err


# -- the default number of outputs ------------------------------------------------------------

def test_the_default_outputs_are_the_librarys():
    from orbits import simulation
    assert cli.DEFAULT_OUTPUTS == simulation.DEFAULT_OUTPUTS


@pytest.mark.parametrize("steps, outputs", [
    (365250.0, 488),       # 1e5 yr at 100 d = 2 3 5^3 487: 487 intervals of 750 steps
    (3652.5, 333),         # 100 yr at 10 d: 3652 = 4 11 83 steps and a half; 332 of 11
    (36525.0, 488),        # 1000 yr at 10 d = 3 5^2 487
    (10000.0, 501),        # 500 intervals of 20 steps: the default itself where it fits
    (499.0, 500),          # one per step up to the default
    (73.05, 74),           # and a shortened last step
    (600.0, 601),          # 600 is a divisor of itself, nearer 499 than 300
    (1009.0, None),        # a prime: the library's default, at the nearest steps
    (2 * 2609.0, None),    # divisors 2 and 2609 only: outside 100 to 1000
    (0.3, None),           # less than a step
])
def test_default_outputs_fall_a_whole_number_of_steps_apart(steps, outputs):
    chosen = cli.default_outputs(steps)
    assert chosen == outputs
    if chosen is not None:
        assert round(steps) % (chosen - 1) == 0
        assert cli.OUTPUT_INTERVALS[0] <= chosen - 1 <= cli.OUTPUT_INTERVALS[1] or steps < 500


@pytest.mark.parametrize("until, end, count, apart", [
    ("3652.5d", 3652.5, 333, 11),    # 3652 steps and a half one
    ("3651.7d", 3651.7, 333, 11),    # 3651 and most of one: 3652 in all
    ("3652.3d", 3652.3, 333, 11),
    ("1yr", 365.25, 366, 1),         # one per step
])
def test_run_outputs_fall_whole_steps_apart(tmp_path, until, end, count, apart, capsys):
    path = tmp_path / "run.h5"
    assert main(["run", "kepler", "-i", "leapfrog", "--dt", "1d", "--until", until,
                 "--out", str(path), "--no-progress"]) == 0
    times = orbits.load(path).times.to_value("day")
    assert len(times) == count
    # every output but the last (at until, after a shortened step) a whole number
    # of steps after the one before; the times are sums of whole steps of 1 d, exact
    assert np.all(np.diff(times[:-1]) == apart)
    assert times[-1] == pytest.approx(end, rel=1e-15)      # float64 rounding of until


def test_adaptive_runs_keep_the_default(capsys, tmp_path):
    path = tmp_path / "run.h5"
    assert main(["run", "kepler", "-i", "ias15", "--until", "1000d", "--out", str(path),
                 "--no-progress"]) == 0
    assert len(orbits.load(path).times) == cli.DEFAULT_OUTPUTS


def test_help_says_how_the_outputs_are_chosen(capsys):
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "a whole number of steps apart" in out and "488 outputs 750 steps apart" in out
