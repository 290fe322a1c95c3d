"""Ensembles that meet trouble: a half-written index, a script without the main guard,
and the README's example run as written."""

import multiprocessing
import pathlib
import re
import subprocess
import sys
import textwrap

import astropy.units as u
import pandas as pd
import pytest

import orbits
from orbits.ensemble import (INDEX_FILE, SWEEP_FILE, Ensemble, EnsembleOptionError,
                             MissingMainGuard, local_cluster)

ROOT = pathlib.Path(__file__).resolve().parents[1]

# columns that say where and how fast a run went, not what it computed
WHERE = ["wall_time_s", "worker", "kernels_compiled", "kernels_loaded"]

BUILT = []      # the parameters build() was called with, in order


def build(e):
    """A Kepler orbit; e < 0 is refused by ``build`` itself with a message of two
    lines, which the index must quote."""
    BUILT.append(e)
    if e < 0:
        raise orbits.ElementsError(f"e = {e} describes no orbit\nwanted: 0 <= e < 1",
                                   body="Planet", field="e")
    return orbits.Simulation(orbits.scenes.kepler(e=e), integrator="leapfrog", dt=1 * u.day)


# the last run is refused, so that the last row of the index holds a quoted newline
PARAMS = [{"e": 0.1}, {"e": 0.3}, {"e": -0.5}]
UNTIL = 0.5 * u.yr       # 183 steps a run (more than the 100 outputs): a sweep takes < 1 s


def _cut_mid_line(text):
    last = text[:-1].rfind("\n") + 1          # start of the last row
    return text[:last + (len(text) - last) // 2]


def _cut_inside_quotes(text):
    # just after the newline inside the last row's quoted message: every line that
    # is there ends with "\n", but the row is not complete
    return text[:text.index("\nwanted:") + 1]


def _cut_header(text):
    return text[:10]


@pytest.mark.parametrize("cut, rerun", [(_cut_mid_line, [-0.5]),
                                        (_cut_inside_quotes, [-0.5]),
                                        (_cut_header, [0.1, 0.3, -0.5])])
def test_a_row_cut_off_in_the_index_is_run_again(tmp_path, cut, rerun):
    whole = Ensemble(build, PARAMS).run(UNTIL, client="serial", progress=False,
                                        out_dir=tmp_path / "whole")
    assert list(whole.outcome) == ["completed", "completed", "invalid"]
    out = tmp_path / "cut"
    Ensemble(build, PARAMS).run(UNTIL, client="serial", progress=False, out_dir=out)
    index = out / INDEX_FILE
    assert index.read_text().count("\n") == 5      # header, 2 rows, one row of 2 lines
    index.write_text(cut(index.read_text()))        # what a crash in mid-write leaves
    BUILT.clear()
    with pytest.warns(UserWarning, match="run again"):
        resumed = Ensemble(build, PARAMS).run(UNTIL, client="serial", progress=False,
                                              out_dir=out)
    assert BUILT == rerun                           # only the cut-off rows were redone
    assert resumed.drop(columns=WHERE).equals(whole.drop(columns=WHERE))
    # the file now holds every row whole, once, and reads back as it was written
    text = index.read_text()
    assert text.endswith("\n") and text.count("\n") == 5
    BUILT.clear()
    again = Ensemble(build, PARAMS).run(UNTIL, client="serial", progress=False, out_dir=out)
    assert BUILT == [] and again.equals(resumed)


def test_rows_of_an_intact_index_are_all_kept(tmp_path, recwarn):
    Ensemble(build, PARAMS).run(UNTIL, client="serial", progress=False, out_dir=tmp_path)
    BUILT.clear()
    Ensemble(build, PARAMS).run(UNTIL, client="serial", progress=False, out_dir=tmp_path)
    assert BUILT == [] and not [w for w in recwarn if "index" in str(w.message)]


def test_an_index_row_with_an_unknown_outcome_or_a_bad_number_is_run_again(tmp_path):
    Ensemble(build, PARAMS[:2]).run(UNTIL, client="serial", progress=False, out_dir=tmp_path)
    index = tmp_path / INDEX_FILE
    header, row0, row1 = index.read_text().splitlines(keepends=True)
    # a row that parses into the right number of fields is still not complete when
    # its outcome is a fragment ("compl") or a number column holds text
    row0 = row0.replace(",completed,", ",compl,")
    row1 = re.sub(r",183,", ",18x,", row1)          # the steps column (183 steps)
    index.write_text(header + row0 + row1)
    BUILT.clear()
    with pytest.warns(UserWarning, match="dropped 2"):
        df = Ensemble(build, PARAMS[:2]).run(UNTIL, client="serial", progress=False,
                                             out_dir=tmp_path)
    assert BUILT == [0.1, 0.3]
    assert list(df.outcome) == ["completed", "completed"] and list(df.steps) == [183, 183]


# -- parameters and rows of another sweep ------------------------------------------------

def build_with(e, **extra):
    """``build`` that takes (and ignores) other parameters."""
    return build(e)


@pytest.mark.parametrize("name", ["outcome", "steps", "file", "message", "run",
                                  "stop_bodies", "t_stop"])
def test_a_parameter_named_as_a_result_column_is_refused_by_name(name):
    # the result would overwrite it without a word (and "run", the rows'
    # numbering, would end the sweep in KeyError: 0)
    with pytest.raises(EnsembleOptionError, match=f"parameter '{name}'.*name of a column"):
        Ensemble(build_with, [{"e": 0.1}, {"e": 0.3, name: 7}])
    # a Quantity's column has its unit: t_stop in days would be t_stop_day
    with pytest.raises(EnsembleOptionError, match="'t_stop_day'"):
        Ensemble(build_with, [{"e": 0.1, "t_stop": 3 * u.day}])


def test_a_parameter_named_as_a_bodys_final_element_stops_the_sweep():
    # "Planet_e" is the column of the planet's final eccentricity: a column
    # that only the bodies of a run name, so the first run stops the sweep
    BUILT.clear()
    with pytest.raises(EnsembleOptionError, match="parameter 'Planet_e'.*run 0"):
        Ensemble(build_with, [{"e": 0.1, "Planet_e": 0.5}, {"e": 0.3, "Planet_e": 0.6}]).run(
            UNTIL, client="serial", progress=False)
    assert BUILT == [0.1]
    # with its elements not asked for, the name is free
    df = Ensemble(build_with, [{"e": 0.1, "Planet_e": 0.5}]).run(
        UNTIL, client="serial", progress=False, elements=[])
    assert df.Planet_e.tolist() == [0.5]


def test_without_sweep_json_the_rows_of_another_sweep_are_refused(tmp_path):
    Ensemble(build, PARAMS[:2]).run(UNTIL, client="serial", progress=False, out_dir=tmp_path)
    (tmp_path / SWEEP_FILE).unlink()
    # another grid in the same folder: its run 1 would be the old run 1's row
    with pytest.raises(EnsembleOptionError, match=r"another sweep.*run 0 has e = 0\.1, where "
                                                  r"this sweep's run 0 has e = 0\.2"):
        Ensemble(build, [{"e": 0.2}, {"e": 0.3}]).run(UNTIL, client="serial", progress=False,
                                                      out_dir=tmp_path)
    # a parameter the index has and this sweep lacks
    with pytest.raises(EnsembleOptionError, match=r"run 0 has tag = 'x', where this sweep's "
                                                  r"run 0 has tag = \(none\)"):
        Ensemble(build_with, PARAMS[:2]).run(UNTIL, client="serial", progress=False,
                                             out_dir=_copy_index(tmp_path, "tag", "x"))
    assert not (tmp_path / SWEEP_FILE).exists()     # nothing was written for a refusal
    # the same sweep resumes from its rows, and records itself again
    BUILT.clear()
    df = Ensemble(build, PARAMS[:2]).run(UNTIL, client="serial", progress=False,
                                         out_dir=tmp_path)
    assert BUILT == [] and list(df.e) == [0.1, 0.3] and (tmp_path / SWEEP_FILE).exists()


def _copy_index(out, column, value):
    """A new out_dir whose index has one more parameter column."""
    import csv
    new = out.parent / (out.name + "-" + column)
    new.mkdir()
    rows = list(csv.reader((out / INDEX_FILE).read_text().splitlines()))
    rows = [rows[0][:1] + [column] + rows[0][1:]] + [r[:1] + [value] + r[1:] for r in rows[1:]]
    (new / INDEX_FILE).write_text("".join(",".join(r) + "\n" for r in rows))
    return new


def test_a_sweep_json_that_records_no_sweep_is_refused_by_name(tmp_path):
    (tmp_path / SWEEP_FILE).write_bytes(b"\xff[]")
    with pytest.raises(EnsembleOptionError, match="sweep.json does not record a sweep"):
        Ensemble(build, PARAMS[:1]).run(UNTIL, client="serial", progress=False,
                                        out_dir=tmp_path)


# -- text cells of the index in a spreadsheet ------------------------------------------------

LINK = '=HYPERLINK("http://example.com","x")'


def linked(e, tag, shift):
    """A massless planet named as a spreadsheet formula, escaping beyond 1.5 au
    when its apocentre is beyond (e > 0.5)."""
    b = orbits.BodySet()
    b.add("Star", mass=1 * u.Msun)
    b.add(LINK, mass=0 * u.kg, primary="Star", a=1 * u.au, e=e)
    return orbits.Simulation(b, integrator="leapfrog", dt=1 * u.day,
                             escape_distance=1.5 * u.au)


def test_text_cells_of_the_index_are_safe_in_a_spreadsheet_and_read_back(tmp_path):
    import csv
    params = [{"e": 0.1, "tag": "-x", "shift": -1.5}, {"e": 0.9, "tag": "'=y", "shift": 2.0}]
    df = Ensemble(linked, params).run(UNTIL, client="serial", progress=False, out_dir=tmp_path)
    assert df.loc[1].outcome == "escape" and df.loc[1].stop_bodies == LINK
    assert f"{LINK}_e" in df.columns and list(df.tag) == ["-x", "'=y"]
    rows = list(csv.reader((tmp_path / INDEX_FILE).read_text().splitlines()))
    cells = [c for row in rows for c in row]
    for cell in cells:
        try:
            float(cell)
        except ValueError:      # text: never the start of a formula (OWASP)
            assert not cell.startswith(("=", "+", "-", "@", "\t", "\r")), cell
    assert f"'{LINK}_e" in rows[0] and "-1.5" in cells        # numbers stay numbers
    assert "'-x" in cells and "''=y" in cells
    # and every text reads back as it was
    again = Ensemble(linked, params).run(UNTIL, client="serial", progress=False,
                                         out_dir=tmp_path)
    assert again.equals(df)


# -- a script without the main guard -------------------------------------------------------

UNGUARDED = """\
import astropy.units as u
import orbits

def build(e):
    return orbits.Simulation(orbits.scenes.kepler(e=e), integrator="leapfrog", dt=1 * u.day)

df = orbits.Ensemble(build, [{"e": 0.1}, {"e": 0.2}]).run(1 * u.yr, n_workers=1, progress=False)
"""


def test_a_script_without_the_main_guard_gets_an_error_that_names_the_guard(tmp_path):
    script = tmp_path / "sweep.py"
    script.write_text(UNGUARDED)
    # the generous timeout: a scheduler and a spawned worker process have to start
    # (and the worker to fail) on a machine shared with other test processes; a
    # few seconds when idle
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                         cwd=tmp_path, timeout=180)
    assert out.returncode != 0
    last = out.stderr.strip().splitlines()[-1]
    assert last.startswith("orbits.ensemble.MissingMainGuard: "), out.stderr[-3000:]
    assert 'if __name__ == "__main__":' in last
    assert f"line 7 of {script}" in last             # the line that starts the sweep


def test_local_cluster_refuses_to_start_while_a_worker_imports_the_main_script(monkeypatch):
    # the state of a spawned worker that is importing the main script again, in
    # which multiprocessing cannot start processes: the error must come before any
    # attempt (no scheduler, no processes)
    monkeypatch.setattr(multiprocessing.current_process(), "_inheriting", True, raising=False)
    with pytest.raises(MissingMainGuard, match=r'if __name__ == "__main__":'):
        local_cluster(1)
    assert issubclass(MissingMainGuard, orbits.OrbitsError)


# -- Ctrl-C --------------------------------------------------------------------------------

INTERRUPTED = """\
import sys
import time

import astropy.units as u
import orbits

def build(e):
    while e > 0.3:       # the runs after the first two go on until Ctrl-C
        time.sleep(0.05)
    return orbits.Simulation(orbits.scenes.kepler(e=e), integrator="leapfrog", dt=1 * u.day)

if __name__ == "__main__":
    try:
        orbits.Ensemble(build, [{"e": e} for e in (0.1, 0.3, 0.5, 0.7)]).run(
            0.5 * u.yr, n_workers=1, progress=False, out_dir=sys.argv[1])
    except KeyboardInterrupt:
        sys.exit(130)
"""


def test_ctrl_c_on_a_local_cluster_prints_one_line_and_the_same_call_continues(tmp_path):
    import os
    import signal
    import time

    script, out = tmp_path / "sweep.py", tmp_path / "sweep"
    script.write_text(INTERRUPTED)
    # a session of its own: Ctrl-C in a terminal signals the whole foreground
    # group, the worker processes too
    proc = subprocess.Popen([sys.executable, str(script), str(out)], cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    try:
        # generous: a scheduler and a spawned worker start on a shared machine
        # (a few seconds when idle); the two runs that can finish take 183
        # steps each
        deadline = time.monotonic() + 180
        index = out / INDEX_FILE
        while not (index.exists() and index.read_text().count("\n") == 3):
            assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
            time.sleep(0.1)
        os.killpg(proc.pid, signal.SIGINT)
        stdout, stderr = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
    assert proc.returncode == 130
    assert stdout == ""
    assert stderr.splitlines() == [
        f"orbits ensemble: interrupted; 2 of 4 runs are saved in {out}, and the same call "
        f"(with this out_dir) continues with the other 2"], stderr[-3000:]
    # the same call goes on from there (build is this module's, under the same name)
    params = [{"e": e} for e in (0.1, 0.3, 0.5, 0.7)]
    BUILT.clear()
    resumed = Ensemble(build, params).run(UNTIL, client="serial", progress=False, out_dir=out)
    assert BUILT == [0.5, 0.7]
    whole = Ensemble(build, params).run(UNTIL, client="serial", progress=False,
                                        out_dir=tmp_path / "whole")
    assert resumed.drop(columns=WHERE).equals(whole.drop(columns=WHERE))


# -- the ensembles guide's example, as written ------------------------------------------------

def _readme_ensemble_example():
    guide = (ROOT / "docs" / "guides" / "ensembles.rst").read_text()
    block = guide.split(".. code-block:: python\n\n", 1)[1]
    return textwrap.dedent(block.split("\n\n:meth:", 1)[0])


@pytest.mark.slow     # about 10 s: two Python start-ups and a local cluster
def test_the_readme_ensemble_example_runs_as_written(tmp_path):
    script = tmp_path / "readme_sweep.py"
    script.write_text(_readme_ensemble_example())
    # generous timeout: a local cluster of one process per core starts, and 2 x 15
    # runs of up to 12 175 steps; about 10 s on a 2-core machine
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                         cwd=tmp_path, timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    index = pd.read_csv(tmp_path / "sweep" / INDEX_FILE)
    assert len(index) == 15 and (tmp_path / "sweep" / "run-00007.h5").exists()
    # the phase keeps every planet off Jupiter at the start: no run ends at its
    # first step (at f = 0, 6 of the 15 do)
    assert (index.steps > 1).all(), index[["a", "e", "outcome", "steps"]]
    assert set(index.outcome) == {"completed", "close-encounter"}
    assert "close-encounter" in out.stdout

