"""Body-set files (orbits.systemfile): exact round trips, and errors with lines."""

import pathlib
import re
import textwrap

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits import systemfile
from orbits.errors import BodyError, SystemFileError
from orbits.systemfile import _csv, _writer

ROOT = pathlib.Path(__file__).resolve().parents[1]


def python_set():
    bodies = orbits.BodySet()
    bodies.add("Sun", mass=1 * u.Msun)
    bodies.add("Jupiter", mass=9.547919e-4 * u.Msun, primary="Sun", a=5.2026 * u.au,
               e=0.0484, inc=1.30 * u.deg, Omega=100.5 * u.deg, omega=273.9 * u.deg,
               M=20 * u.deg)
    bodies.add("Saturn", mass=95.16 * u.Mearth, a=9.537 * u.au, e=0.0539, inc=2.49 * u.deg,
               f=120 * u.deg)
    bodies.add("probe", mass=0 * u.kg, position=[1, 0, 0] * u.au,
               velocity=[0, 30, 0] * u.km / u.s)
    bodies.move_to_com()
    return bodies


def run(bodies):
    sim = orbits.Simulation(bodies, integrator="leapfrog", dt=20 * u.day)
    return sim.run(until=2000 * u.day, outputs=11, progress=False)


def same_set(a, b):
    return (a.names == b.names and a.units == b.units
            and np.array_equal(a.masses, b.masses) and np.array_equal(a.positions, b.positions)
            and np.array_equal(a.velocities, b.velocities))


@pytest.mark.parametrize("ext", ["toml", "csv"])
def test_written_set_reads_back_and_runs_bit_for_bit(tmp_path, ext):
    bodies = python_set()
    path = tmp_path / f"system.{ext}"
    bodies.write(path)
    back = orbits.BodySet.read(path)
    assert same_set(back, bodies)
    a, b = run(bodies), run(back)
    assert np.array_equal(a.positions, b.positions)
    assert np.array_equal(a.velocities, b.velocities)
    # writing again gives the same text: nothing is lost or rounded on the way
    back.write(tmp_path / f"again.{ext}")
    assert (tmp_path / f"again.{ext}").read_text() == path.read_text()


@pytest.mark.parametrize("scene", ["outer-solar-system", "figure-eight", "earth-moon"])
def test_scenes_in_their_own_units_round_trip(scene):
    # hlw's own G, N-body units, and km/kg/s: the unit system travels with the numbers
    bodies = orbits.scenes.get(scene)
    for kind in ("toml", "csv"):
        back = systemfile.loads(systemfile.dumps(bodies, kind), kind).bodies
        assert same_set(back, bodies), kind
        assert back.units.G == bodies.units.G


def test_hand_written_file_equals_the_same_set_built_in_python():
    text = '''
    [[body]]
    name = "Sun"
    mass = "1 Msun"

    [[body]]
    name = "Jupiter"
    mass = "9.547919e-4 Msun"
    primary = "Sun"
    a = "5.2026 au"
    e = 0.0484
    inc = "1.30 deg"
    Omega = "100.5 deg"
    omega = "273.9 deg"
    M = "20 deg"

    [[body]]
    name = "Saturn"
    mass = "95.16 Mearth"
    a = "9.537 au"
    e = "0.0539"
    inc = "2.49 deg"
    f = "120 deg"

    [[body]]
    name = "probe"
    mass = 0
    position = ["1 au", "0 au", "0 au"]
    velocity = ["0 km/s", "30 km/s", "0 km/s"]
    '''
    got = systemfile.loads(text).bodies
    got.move_to_com()
    assert same_set(got, python_set())


def test_units_table_makes_plain_numbers_and_run_defaults():
    text = '''
    [units]
    length = "km"
    mass = "kg"
    time = "s"

    [[body]]
    name = "Earth"
    mass = 5.972e24
    [[body]]
    name = "sat"
    mass = 0
    primary = "Earth"
    a = 7000
    e = 0.001

    [run]
    integrator = "dop853"
    dt = 10
    until = "1 day"
    outputs = 5
    com = true
    escape_distance = "1e6 km"
    [run.options]
    rtol = 1e-10
    '''
    sf = systemfile.loads(text)
    assert sf.bodies.units.length == u.km
    el = sf.bodies.elements("sat", primary="Earth")
    assert el["a"].to_value(u.km) == pytest.approx(7000, rel=1e-12)
    assert sf.run["dt"] == 10 * u.s and sf.run["until"] == 1 * u.day
    assert sf.run["options"] == {"rtol": 1e-10} and sf.run["com"] is True
    assert sf.run["escape_distance"] == 1e6 * u.km


def test_csv_by_elements_and_state_with_comment_lines():
    text = ("# my system\n"
            "name,mass [Msun],x [au],y [au],z [au],vx [km/s],vy [km/s],vz [km/s],"
            "primary,a [au],e,inc [deg]\n"
            "# the star\n"
            "Sun,1,0,0,0,0,0,0,,,,\n"
            "Jupiter,9.547919e-4,,,,,,,Sun,5.2026,0.0484,1.30\n")
    got = systemfile.loads(text, "csv").bodies
    ref = orbits.BodySet()
    ref.add("Sun", mass=1 * u.Msun)
    ref.add("Jupiter", mass=9.547919e-4 * u.Msun, primary="Sun", a=5.2026 * u.au,
            e=0.0484, inc=1.30 * u.deg)
    assert same_set(got, ref)


def test_tutorial_example_reads():
    # the tutorial's system file, as a reader copies it from the page
    page = (ROOT / "docs" / "tutorial.rst").read_text()
    block = page.split(".. code-block:: toml\n\n", 1)[1]
    toml = textwrap.dedent(block.split("\n\n``", 1)[0])
    sf = systemfile.loads(toml)
    assert sf.bodies.names == ["Sun", "Jupiter", "probe"]
    assert sf.run["integrator"] == "ias15"


# -- malformed files: a named error with the file and the line ------------------------
GOOD = '''\
[[body]]
name = "Sun"
mass = "1 Msun"

[[body]]
name = "Jupiter"
mass = "9.55e-4 Msun"
primary = "Sun"
a = "5.2 au"
e = 0.048
inc = "1.3 deg"
'''
PROBE = '\n[[body]]\nname = "probe"\nmass = 0\n'  # lines 13-15 after GOOD

TOML_CASES = {
    # case: (text, line, body, words in the message)
    "missing unit": (GOOD.replace('"9.55e-4 Msun"', "9.55e-4"), 7, "Jupiter",
                     ["has no unit", "[units]"]),
    "unit-less string": (GOOD.replace('"5.2 au"', '"5.2"'), 9, "Jupiter", ["has no unit"]),
    "angle without unit": (GOOD.replace('"1.3 deg"', "1.3"), 11, "Jupiter",
                           ["angle needs a unit"]),
    "unknown field": (GOOD.replace("e = 0.048", "ecc = 0.048"), 10, "Jupiter",
                      ["unknown field 'ecc'"]),
    "misspelt field": (GOOD.replace("inc =", "incl ="), 11, "Jupiter", ["did you mean 'inc'"]),
    "wrong length": (GOOD + PROBE + 'position = ["1 au", "0 au"]\n', 16, "probe",
                     ["3 components", "got 2"]),
    "wrong length, array over lines": (GOOD + PROBE + 'velocity = [\n  "1 km/s",\n]\n', 16,
                                       "probe", ["3 components", "got 1"]),
    "duplicate name": (GOOD + '\n[[body]]\nname = "Jupiter"\nmass = 0\n', 14, "Jupiter",
                       ["already given on line 5"]),
    "wrong physical type": (GOOD.replace('"5.2 au"', '"5.2 kg"'), 9, "Jupiter",
                            ["expected a length"]),
    "unreadable unit": (GOOD.replace('"5.2 au"', '"5.2 furlongz"'), 9, "Jupiter",
                        ["cannot read"]),
    "unknown primary": (GOOD.replace('"Sun"\na', '"Sol"\na'), 8, "Jupiter",
                        ["unknown primary 'Sol'"]),
    "no mass": (GOOD + PROBE.replace("mass = 0\n", ""), 13, "probe", ["needs a mass"]),
    "state and elements": (GOOD + PROBE + 'position = ["1 au", "0 au", "0 au"]\n'
                           'a = "1 au"\n', 16, "probe", ["not both"]),
    "impossible orbit": (GOOD.replace("e = 0.048", "e = 1.5"), 10, "Jupiter", ["e = 1.5"]),
    "TOML syntax": (GOOD.replace("e = 0.048", "e = 0.048 0.1"), 10, None, ["not valid TOML"]),
    "unknown table": (GOOD + "\n[bodies]\nx = 1\n", 13, None, ["unknown table 'bodies'"]),
    "unknown unit key": ('[units]\nlength = "au"\nlenght = "km"\n' + GOOD, 3, None,
                         ["did you mean 'length'"]),
    "unit of the wrong kind": ('[units]\nlength = "kg"\n' + GOOD, 2, None, ["not a length"]),
    "run option the integrator lacks": (GOOD + '\n[run]\nintegrator = "verlet"\n'
                                        '[run.options]\nrtol = 1e-6\n', 16, None,
                                        ["no option 'rtol'"]),
    "unknown run key": (GOOD + '\n[run]\nintegrater = "wh"\n', 14, None,
                        ["did you mean 'integrator'"]),
    "run time without unit": (GOOD + '\n[run]\nuntil = 100\n', 14, None, ["has no unit"]),
}


@pytest.mark.parametrize("case", list(TOML_CASES))
def test_malformed_toml_names_the_line(case):
    text, line, body, words = TOML_CASES[case]
    with pytest.raises(SystemFileError) as info:
        systemfile.loads(text, source="system.toml")
    exc = info.value
    assert isinstance(exc, BodyError)
    assert exc.line == line, str(exc)
    message = str(exc)
    assert message.startswith(f"system.toml, line {line}: "), message
    if body is not None:
        assert exc.body == body and f"body {body!r}" in message
    for word in words:
        assert word in message


HEADER = "name,mass [Msun],x [au],y [au],z [au],vx [km/s],vy [km/s],vz [km/s]\n"
ROWS = "Sun,1,0,0,0,0,0,0\nprobe,0,1,0,0,0,30,0\n"
CSV_CASES = {
    "missing unit": ("# c\n" + HEADER.replace("mass [Msun]", "mass") + ROWS, 2, None,
                     ["column 'mass' has no unit"]),
    "unknown column": (HEADER.replace("vz", "vw") + ROWS, 1, None, ["unknown column 'vw'"]),
    "angle column without unit": (HEADER.strip() + ",inc\n" + "Sun,1,0,0,0,0,0,0,\n", 1,
                                  None, ["angle column 'inc' needs a unit"]),
    "wrong length (columns)": (HEADER.replace(",z [au]", "") + "Sun,1,0,0,0,0,0\n", 1, None,
                               ["3 columns"]),
    "wrong length (cells)": (HEADER + ROWS + "moon,0,1\n", 4, None, ["expected 8 cells"]),
    "empty component": (HEADER + "Sun,1,0,0,0,0,0,0\nprobe,0,1,,0,0,30,0\n", 3, "probe",
                        ["y empty"]),
    "duplicate name": (HEADER + ROWS + "# again\nSun,1,5,0,0,0,0,0\n", 5, "Sun",
                       ["already given on line 2"]),
    "not a number": (HEADER + "Sun,1,0,0,0,0,0,0\nprobe,zero,1,0,0,0,30,0\n", 3, "probe",
                     ["cannot read 'zero'"]),
    "wrong physical type": (HEADER.replace("x [au]", "x [kg]") + ROWS, 1, None,
                            ["column 'x' is in kg, which is not a length"]),
    "unit on a text column": (HEADER.replace("name", "name [au]") + ROWS, 1, None,
                              ["column 'name'"]),
}


@pytest.mark.parametrize("case", list(CSV_CASES))
def test_malformed_csv_names_the_line(case):
    text, line, body, words = CSV_CASES[case]
    with pytest.raises(SystemFileError) as info:
        systemfile.loads(text, "csv", source="system.csv")
    exc = info.value
    assert exc.line == line, str(exc)
    assert str(exc).startswith(f"system.csv, line {line}: "), str(exc)
    if body is not None:
        assert exc.body == body
    for word in words:
        assert word in str(exc)


def test_file_errors_name_the_file(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(GOOD.replace("e = 0.048", "e = -1"))
    with pytest.raises(SystemFileError, match=re.escape(f"{path}, line 10: body 'Jupiter', "
                                                        f"field 'e'")):
        orbits.BodySet.read(path)
    with pytest.raises(SystemFileError, match="ends in .toml or .csv"):
        orbits.BodySet.read(tmp_path / "system.json")
    with pytest.raises(FileNotFoundError):
        orbits.BodySet.read(tmp_path / "missing.toml")
    with pytest.raises(SystemFileError, match="no bodies"):
        systemfile.loads('[units]\nlength = "au"\n')


def test_run_table_round_trips():
    run = {"integrator": "wh", "dt": 10.5 * u.day, "until": 1e4 * u.yr, "outputs": 200,
           "com": True, "options": {"corrector": 17, "coordinates": "jacobi"}}
    text = systemfile.dumps(orbits.scenes.kepler(), run=run)
    assert "[run.options]" in text
    assert systemfile.loads(text).run == run
    with pytest.raises(ValueError, match="no \\[run\\] table"):
        systemfile.dumps(orbits.scenes.kepler(), "csv", run=run)


def test_radii_round_trip_and_a_set_without_them_is_written_as_before():
    bodies = python_set()
    plain = {kind: systemfile.dumps(bodies, kind) for kind in ("toml", "csv")}
    assert "radius" not in plain["toml"] and "radius" not in plain["csv"]
    bodies.add("moon", mass=0 * u.kg, position=[2, 0, 0] * u.au, radius=1737.4 * u.km)
    for kind in ("toml", "csv"):
        text = systemfile.dumps(bodies, kind)
        assert "radius" in text, kind
        back = systemfile.loads(text, kind).bodies
        assert np.array_equal(back.radii.value, bodies.radii.value), kind
        assert back.radii[:-1].value.tolist() == [0.0] * 4


def one_body(line):
    return f'[[body]]\nname = "Sun"\nmass = "1 Msun"\n{line}\n'


def test_radius_field_is_read_with_its_unit_and_checked():
    text = one_body('radius = "1 Rsun"')
    b = systemfile.loads(text).bodies
    assert b.radii[0].to(u.Rsun).value == pytest.approx(1.0, rel=1e-15)
    with pytest.raises(SystemFileError, match="line 4: body 'Sun', field 'radius'"):
        systemfile.loads(one_body('radius = "-1 km"'))
    csv_text = "name,mass [Msun],radius [km],x [au],y [au],z [au]\nSun,1,696000,0,0,0\n"
    assert systemfile.loads(csv_text, "csv").bodies.radii[0].to_value(u.km) \
        == pytest.approx(696000, rel=1e-15)


def test_names_with_quotes_commas_and_accents_round_trip():
    bodies = orbits.BodySet()
    for k, name in enumerate(['Béta "B", the second', "back\\slash", "tab\there"]):
        bodies.add(name, mass=(k + 1) * u.Msun, position=[k, 0, 0] * u.au)
    for kind in ("toml", "csv"):
        assert systemfile.loads(systemfile.dumps(bodies, kind), kind).bodies.names \
            == bodies.names, kind


# -- what used to escape as another exception, and spreadsheets ------------------------

def test_a_file_that_is_not_utf8_names_its_line(tmp_path):
    for ext, data in (("toml", GOOD.encode() + b'\n[[body]]\nname = "Ab\xe9"\nmass = 0\n'),
                      ("csv", (HEADER + ROWS).encode() + b"Ab\xe9,0,2,0,0,0,30,0\n")):
        path = tmp_path / f"latin1.{ext}"
        path.write_bytes(data)       # "Abé" in Latin-1, as an old editor saves it
        line = data.count(b"\n", 0, data.index(b"\xe9")) + 1
        with pytest.raises(SystemFileError, match=re.escape(
                f"{path}, line {line}: not UTF-8 text: the byte 0xe9 at column ")) as exc:
            systemfile.read(path)
        assert exc.value.path == str(path) and exc.value.line == line


@pytest.mark.parametrize("text, line, field", [
    # whole numbers of 400 digits: TOML takes them, a float cannot
    (one_body("") + '[[body]]\nname = "b"\nmass = ' + "9" * 400 + "\n", 7, "mass"),
    (one_body("") + '[[body]]\nname = "b"\nmass = 0\na = "1 au"\ne = ' + "9" * 400 + "\n", 9,
     "e"),
    ("[units]\nG = " + "9" * 400 + "\n" + one_body(""), 2, "G"),
    (one_body("") + '[run]\nintegrator = "ias15"\n[run.options]\nepsilon = ' + "9" * 400
     + "\n", 8, "epsilon"),
], ids=["mass", "e", "G", "run option"])
def test_a_whole_number_too_large_for_a_float_names_its_line(text, line, field):
    with pytest.raises(SystemFileError, match="too large for a 64-bit float") as exc:
        systemfile.loads(text, source="system.toml")
    assert exc.value.line == line and exc.value.field == field
    assert str(exc.value).startswith(f"system.toml, line {line}: ")


def test_arrays_nested_too_deeply_and_values_python_cannot_hold_name_their_line():
    # the parser recurses once for each level: 5000 levels pass Python's limit
    deep = one_body("") + "x = 1\ny = " + "[" * 5000 + "]" * 5000 + "\n"
    with pytest.raises(SystemFileError, match=r"system.toml, line 6: .*nested too deeply"):
        systemfile.loads(deep, source="system.toml")
    # valid TOML that Python's int() refuses: more than 4300 digits
    digits = one_body("") + '[[body]]\nname = "b"\nmass = ' + "1" * 5000 + "\n"
    with pytest.raises(SystemFileError, match=r"system.toml, line 7: not valid TOML here: "
                                              r".*4300 digits"):
        systemfile.loads(digits, source="system.toml")


def test_a_utf8_byte_order_mark_as_a_spreadsheet_writes_it_is_read_past(tmp_path):
    bodies = python_set()
    for ext in ("csv", "toml"):
        path = tmp_path / f"marked.{ext}"
        path.write_bytes(b"\xef\xbb\xbf" + systemfile.dumps(bodies, ext).encode())
        assert same_set(systemfile.read(path).bodies, bodies), ext


def test_long_runs_of_spaces_and_digits_are_read_in_linear_time():
    # patterns with two adjacent runs that match spaces (or digits) take time
    # quadratic (or worse) in the run's length: minutes for 80 000; a test that
    # hangs shows as the suite's timeout
    from orbits.systemfile._toml import _TomlLines
    spaces = " " * 80_000
    text = f'[[body{spaces}]]\nname = "Sun"\nmass = "1 Msun"\n[[body]]\nname = "b"\n' \
           f'mass = 0\n'
    assert systemfile.loads(text).bodies.names == ["Sun", "b"]
    # lines the line finder sees, but that no header: a multi-line string's text
    lines = _TomlLines(f'[[body]]\nnote = """\n[a{spaces}\n[{spaces}\n"""\nname = "S"\n')
    assert lines.find(("body", 0, "name")) == 6
    with pytest.raises(SystemFileError, match="line 3: body 'Sun', field 'mass': cannot read"):
        systemfile.loads(one_body("").replace('"1 Msun"', '"' + "1" * 80_000 + 'x"'))
    with pytest.raises(SystemFileError, match="line 1: cannot read the column"):
        systemfile.loads(f"name{spaces}x,mass [Msun]\nSun,1\n", "csv")


def test_a_table_of_states_reads_as_row_by_row_bit_for_bit():
    # the columns converted at once, as the cells one by one: km/s and Rsun to
    # the set's au/day and au, plain numbers in the file's units, empty cells
    rng = np.random.default_rng(7)
    n = 300
    rows = [f"b{k},{m!r},{r!r},{x!r},{y!r},{z!r},{vx!r},{vy!r},{vz!r}"
            for k, (m, r, x, y, z, vx, vy, vz) in enumerate(
                (rng.lognormal(size=(n, 8)) * np.array([1, 1, 1, -1, 1, 1, -1, 1])).tolist())]
    rows[5] = "b5,0,,,,,,,"                      # at rest at the origin, no radius
    text = ("name,mass [Mearth],radius [Rsun],x [au],y [km],z [pc],vx [km/s],vy [au/d],"
            "vz [m/s]\n" + "\n".join(rows) + "\n")
    reader = _csv._CsvReader(text, "<string>")
    table = reader.read_table()
    assert table is not None
    one_by_one = _csv._CsvReader(text, "<string>").read_rows()
    assert table.names == one_by_one.names
    for a, b in ((table._m, one_by_one._m), (table._r, one_by_one._r),
                 (table._x, one_by_one._x), (table._v, one_by_one._v)):
        assert a.tobytes() == b.tobytes()
    units = "# units: length = km; mass = kg; time = s\n"
    plain = units + "name,mass,x,y,z,vx,vy,vz\nEarth,5.972e24,0,0,0,0,0,0\nsat,0,7000,0,0,0,7.5,0\n"
    assert same_set(_csv._CsvReader(plain, "").read_table(),
                    _csv._CsvReader(plain, "").read_rows())


def test_a_table_of_states_is_read_as_one_piece():
    # 2000 bodies by columns: the set's history records the table once; a
    # body at a time records 2000 entries (and takes seconds, 1e5 bodies
    # minutes)
    n = 2000
    bodies = orbits.BodySet.from_arrays(np.full(n, 1e-3) * u.Msun,
                                        np.arange(3.0 * n).reshape(n, 3) * u.au,
                                        np.zeros((n, 3)) * u.au / u.day,
                                        names=[f"b{k}" for k in range(n)])
    back = systemfile.loads(systemfile.dumps(bodies, "csv"), "csv").bodies
    assert same_set(back, bodies)
    assert back.history == [{"from": "arrays", "n": n}, {"from": "file", "path": "<string>"}]


def test_an_error_in_a_table_still_names_its_line_body_and_field():
    rows = "".join(f"b{k},1e-9,{k},0,0,0,1,0\n" for k in range(1, 50))
    bad = HEADER + "Sun,1,0,0,0,0,0,0\n" + rows.replace("b30,1e-9,", "b30,-1e-9,")
    with pytest.raises(SystemFileError, match=r"system.csv, line 32: body 'b30', field 'mass'"):
        systemfile.loads(bad, "csv", source="system.csv")
    nul = HEADER + "Sun,1,0,0,0,0,0,0\n" + rows.replace("b30,", "b\x0030,")
    with pytest.raises(SystemFileError, match=r"system.csv, line 32: body 'b\\x0030', "
                                              r"field 'name'.*NUL"):
        systemfile.loads(nul, "csv", source="system.csv")


def test_names_a_spreadsheet_would_run_as_formulas_are_written_as_text():
    names = ['=HYPERLINK("http://example.com","x")', "+1", "-x", "@SUM(A1)", "\tx",
             "'quoted", "Sun"]
    bodies = orbits.BodySet(units=orbits.UnitSystem(name="mine, with a comma"))
    for k, name in enumerate(names):
        bodies.add(name, mass=1.0, position=[k, 0, 0])
    text = systemfile.dumps(bodies, "csv")
    import csv
    import io
    rows = list(csv.reader(io.StringIO(text)))
    assert [r[0] for r in rows[3:]] == ["'" + n for n in names[:-1]] + ["Sun"]
    assert len(rows[1]) == 1 and rows[1][0].startswith("# units:")   # one cell
    back = systemfile.loads(text, "csv").bodies
    assert back.names == names and back.units.name == "mine, with a comma"


ELEMENT_TABLE = (
    "name,mass [Msun],radius [km],x [au],y [au],z [au],vx [km/s],vy [km/s],vz [km/s],"
    "primary,a [au],e,inc [deg],Omega [rad],omega [deg],f [deg],M [deg]\n"
    "Sun,1,695700,0,0,0,0,0,0,,,,,,,,\n"
    "Jupiter,9.547919e-4,71492,,,,,,,Sun,5.2026,0.0484,1.30,1.754,273.9,,20\n"
    "Io,4.7e-8,,,,,,,,Jupiter,0.002819,0.0041,0.05,,,,\n"               # angles' defaults
    "Saturn,2.858e-4,,,,,,,,,9.537,0.0539,2.49,,,120,\n"                # about the COM above
    "probe,0,,1.5,-0.25,0.01,3,28,-0.5,,,,,,,,\n"                       # a state
    "comet,1e-12,,,,,,,,Sun,-2.5,1.7,-0.0,0.3,12.5,-40,\n"              # hyperbolic, f
    "flyby,0,,,,,,,,Jupiter,-0.01,3.2,150,-2.1,,,0.5\n"                 # hyperbolic, M
    "moonlet,0,1.5,,,,,,,Io,1e-5,0,,,,359,\n"                           # about a moon
    "Trojan,1e-13,,,,,,,,Sun,5.2026,0.1,10,2,60,,80\n"
    "far,0,,,,,,,,,40,0.25,,,,,-170\n"                                  # COM of all above
)


def test_a_table_of_elements_reads_as_row_by_row_bit_for_bit():
    # the element rows by columns: several primaries (named, and the centre of
    # mass of the rows above), elliptic and hyperbolic, f and M, angles left
    # to their defaults, a state among them; every attribute as BodySet.add
    # makes it, the history included
    table = _csv._CsvReader(ELEMENT_TABLE, "<string>").read_table()
    assert table is not None
    one_by_one = _csv._CsvReader(ELEMENT_TABLE, "<string>").read_rows()
    assert vars(table).keys() == vars(one_by_one).keys()
    for key, value in vars(one_by_one).items():
        if isinstance(value, np.ndarray):
            assert getattr(table, key).tobytes() == value.tobytes(), key
        else:
            assert getattr(table, key) == value, key
    assert [_writer._elements_note(table, i) for i in range(len(table))] == \
        [_writer._elements_note(one_by_one, i) for i in range(len(table))]
    assert systemfile.dumps(table, "toml") == systemfile.dumps(one_by_one, "toml")
    # plain numbers in the file's units, e without a unit
    plain = ("# units: length = km; mass = kg; time = s\n"
             "name,mass,primary,a,e,inc [rad],f [deg]\n"
             "Earth,5.972e24,,,,,\nsat,0,Earth,7000,0.001,0.9,33\nsat2,0,,-9000,1.5,,-10\n")
    table = _csv._CsvReader(plain, "").read_table()
    assert table is not None
    one_by_one = _csv._CsvReader(plain, "").read_rows()
    assert same_set(table, one_by_one) and table.history == one_by_one.history



@pytest.mark.parametrize("old, new, line, body, field", [
    ("Jupiter,0.002819,0.0041,", "Jupiter,0.002819,1.5,", 4, "Io", "e"),     # e >= 1, a > 0
    (",Io,1e-5,", ",Titan,1e-5,", 9, "moonlet", "primary"),                  # no such body
    (",Jupiter,0.002819,", ",moonlet,0.002819,", 4, "Io", "primary"),       # given below
    ("28,-0.5,,,", "28,-0.5,,1.2,", 6, "probe", "position"),                # state and a
    ("Sun,5.2026,0.1,", "Sun,,0.1,", 10, "Trojan", "a"),                     # no a
    ("Sun,-2.5,1.7,-0.0,0.3,12.5,-40,", "Sun,-2.5,1.7,-0.0,0.3,12.5,-40,3", 7, "comet", "f"),
])
def test_an_error_in_a_table_of_elements_names_its_line_body_and_field(old, new, line, body,
                                                                       field):
    assert ELEMENT_TABLE.count(old) == 1
    with pytest.raises(SystemFileError, match=rf"system.csv, line {line}: body '{body}', "
                                              rf"field '{field}'"):
        systemfile.loads(ELEMENT_TABLE.replace(old, new), "csv", source="system.csv")


@pytest.mark.parametrize("old, new, line, body, field", [
    ("Saturn,2.858e-4,", "Saturn,-2.858e-4,", 5, "Saturn", "mass"),
    ("Jupiter,9.547919e-4,", "Jupiter,nan,", 3, "Jupiter", "mass"),
    ("probe,0,,1.5,", "probe,0,,inf,", 6, "probe", "position"),
])
def test_a_bad_mass_or_state_among_elements_names_its_row(old, new, line, body, field):
    with pytest.raises(SystemFileError, match=rf"system.csv, line {line}: body '{body}', "
                                              rf"field '{field}'"):
        systemfile.loads(ELEMENT_TABLE.replace(old, new), "csv", source="system.csv")
