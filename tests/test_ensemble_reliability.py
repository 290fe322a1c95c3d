"""Ensembles that meet trouble: a half-written index, a script without the main guard,
and the README's example run as written."""

import multiprocessing
import pathlib
import re
import subprocess
import sys

import astropy.units as u
import pandas as pd
import pytest

import orbits
from orbits.ensemble import INDEX_FILE, Ensemble, MissingMainGuard, local_cluster

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


# -- the README's example, as written --------------------------------------------------------

def _readme_ensemble_example():
    readme = (ROOT / "README.md").read_text()
    section = readme.split("## Ensembles and sweeps", 1)[1]
    return section.split("```python\n", 1)[1].split("```", 1)[0]


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

