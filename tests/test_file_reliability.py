"""Output files under stress: damaged files, start and mid-run checkpoints, the
writers' lock, summaries of runs written to files, checkpoint cost."""

import json
import os
import signal
import socket
import subprocess
import sys
import textwrap
import time

import astropy.units as u
import h5py
import numpy as np
import pytest

import orbits
from orbits import _driver
from orbits.io.h5md import FileInUse, FileRecorder, OrbitsFileError, safety

# A hang shows as a subprocess that outlives this many seconds: generous,
# since a child spends 2-5 s importing orbits (astropy, numba) on a loaded
# two-core machine, and every call it makes should end in well under a second.
HANG_SECONDS = 60


def outer(integrator="leapfrog", **kw):
    adaptive = orbits.integrators.get(integrator).adaptive
    return orbits.Simulation(orbits.scenes.outer_solar_system(), integrator=integrator,
                             dt=None if adaptive else 10 * u.day, **kw)


class Crash(Exception):
    pass


def python(code, *args, timeout=HANG_SECONDS):
    """Run ``code`` in a fresh interpreter; fail (not hang) if it outlives ``timeout``."""
    try:
        return subprocess.run([sys.executable, "-c", code, *map(str, args)],
                              capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired as exc:
        out = exc.stdout.decode() if isinstance(exc.stdout, bytes) else (exc.stdout or "")
        pytest.fail(f"hung for {timeout} s; the child's last lines:\n{out[-2000:]}")


# -- damaged files ---------------------------------------------------------------------

OPEN_ALL = textwrap.dedent("""
    import json, sys, orbits
    from orbits.io import h5md
    calls = {"load": orbits.load, "describe": orbits.io.describe,
             "from_file": orbits.Simulation.from_file}
    for path in sys.argv[1:]:
        for name, call in calls.items():
            print("calling", name, path, flush=True)
            try:
                call(path)
                row = {"error": None, "named": False, "message": "(no error)"}
            except Exception as exc:
                row = {"error": type(exc).__name__, "message": str(exc),
                       "named": isinstance(exc, h5md.OrbitsFileError)}
            print(json.dumps(dict(row, file=path, call=name)), flush=True)
""")


def open_all(paths):
    out = python(OPEN_ALL, *paths)
    assert out.returncode == 0, out.stderr[-3000:]
    return [json.loads(line) for line in out.stdout.splitlines() if line.startswith("{")]


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """A finished file, and a copy of one taken while its writer had it open."""
    d = tmp_path_factory.mktemp("written")
    done = d / "done.h5"
    outer().run(until=3000 * u.day, outputs=31, output=done, progress=False)
    live = d / "live.h5"
    real = FileRecorder.checkpoint

    def copying(self, finished=False):
        real(self, finished)
        if not live.exists():
            live.write_bytes(self.path.read_bytes())
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(FileRecorder, "checkpoint", copying)
        outer().run(until=3000 * u.day, outputs=31, output=d / "writing.h5", progress=False)
    return done, live


def test_the_live_copy_is_marked_as_being_written(written):
    # the second kind of file opens in SWMR mode, where HDF5 retries failed reads
    done, live = written
    assert safety._superblock(done).flags == 0
    assert safety._superblock(live).flags & safety._OPEN_FOR_SWMR_WRITE


def test_truncated_files_fail_at_once_with_a_named_error(written, tmp_path):
    # head -c N of a finished file, and of one whose writer had it open, for
    # every N up to 8 KB that hung, half, and one byte short
    paths = []
    for src in written:
        data = src.read_bytes()
        # the end its header records: a live file has space reserved past it
        end = safety._superblock(src).eof
        for n in (0, 1, 100, 1024, 4096, 8192, end // 2, end - 1):
            p = tmp_path / f"{src.stem}-{n}.h5"
            p.write_bytes(data[:n])
            paths.append(p)
    rows = open_all(paths)
    assert len(rows) == 3 * len(paths)
    for row in rows:
        assert row["named"], row
        msg = row["message"]
        assert row["file"] in msg, row
        if os.path.getsize(row["file"]) <= 1:
            assert "not a readable HDF5 file" in msg, row
        else:
            assert "truncated: it has" in msg and "rest of the file is missing" in msg, row


def test_damaged_metadata_fails_at_once(written, tmp_path):
    # zeros over the metadata after the superblock: a finished file fails in
    # HDF5 at once; one marked as being written is read in SWMR mode with
    # its retries bounded (SWMR_READ_ATTEMPTS), where HDF5's own never end.
    # Zeros inside the global heap (the attributes' strings; no checksum)
    # made HDF5 loop for ever in either mode.
    paths = []
    for src in written:
        data = src.read_bytes()
        heap = data.find(b"GCOL")
        assert 0 < heap < 1 << 20
        for name, lo, hi in (("header", 48, 4096), ("heap", heap + 64, heap + 576)):
            d = bytearray(data)
            d[lo:hi] = bytes(hi - lo)
            p = tmp_path / f"{src.stem}-zeroed-{name}.h5"
            p.write_bytes(bytes(d))
            paths.append(p)
    rows = open_all(paths)
    assert len(rows) == 3 * len(paths)
    for row in rows:
        assert row["named"] and row["file"] in row["message"], row


def test_a_missing_group_is_named_in_words(written, tmp_path):
    done, _ = written
    cases = {"restart": "missing the group /restart (the restart checkpoints)",
             "particles/bodies/velocity": "missing the group /particles/bodies/velocity "
                                          "(the velocities)",
             "parameters/reference": "missing /parameters/reference (the monitors' "
                                     "reference values)"}
    paths = {}
    for name, words in cases.items():
        p = tmp_path / f"without-{name.replace('/', '-')}.h5"
        p.write_bytes(done.read_bytes())
        with h5py.File(p, "a") as f:
            del f[name]
        paths[str(p)] = words
    rows = open_all(list(paths))
    assert len(rows) == 3 * len(paths)
    for row in rows:
        assert row["named"], row
        assert paths[row["file"]] in row["message"], row
        assert "Unable to" not in row["message"], row      # h5py's words


def test_info_and_resume_of_a_half_file_are_named_errors(written, tmp_path):
    # `orbits info` said "completed" where load failed; `orbits resume` gave a traceback
    done, _ = written
    half = tmp_path / "half.h5"
    half.write_bytes(done.read_bytes()[: done.stat().st_size // 2])
    code = textwrap.dedent("""
        import sys
        from orbits.cli import main
        print("info", main(["info", sys.argv[1]]), flush=True)
        print("resume", main(["resume", sys.argv[1], "--no-progress"]), flush=True)
    """)
    out = python(code, half)
    assert out.returncode == 0, out.stderr[-3000:]
    assert "info 4" in out.stdout and "resume 4" in out.stdout     # file errors
    assert out.stderr.count("truncated: it has") == 2 and "Traceback" not in out.stderr


def test_a_file_being_written_is_waited_for_not_called_truncated(tmp_path, monkeypatch):
    # a live writer records its new end of file a moment before the file
    # reaches it; a reader that looks then waits for it
    path = tmp_path / "run.h5"
    outer().run(until=1000 * u.day, outputs=11, output=path, progress=False)
    calls = []
    real = safety._superblock

    def lagging(p):
        sb = real(p)
        calls.append(1)
        return sb._replace(eof=sb.size + 4096) if len(calls) < 3 else sb
    monkeypatch.setattr(safety, "_superblock", lagging)
    monkeypatch.setattr(safety, "_writer", lambda p: ({"pid": 1, "host": "h"}, True))
    with pytest.raises(OrbitsFileError, match="truncated"):
        orbits.load(path)             # not marked as being written: no wait
    calls.clear()
    monkeypatch.setattr(safety, "_superblock",
                        lambda p: lagging(p)._replace(flags=safety._OPEN_FOR_SWMR_WRITE))
    monkeypatch.setattr(safety, "_open_swmr", lambda p: h5py.File(p, "r"))
    assert len(orbits.load(path)) == 11 and len(calls) == 3


# -- files with no outputs, and summaries ------------------------------------------------

def crash_at_final_output(monkeypatch):
    real = FileRecorder.output

    def output(self, sim, final=False):
        if final:
            raise Crash()
        real(self, sim, final)
    monkeypatch.setattr(FileRecorder, "output", output)


def test_plot_of_a_file_without_outputs_is_a_named_error(tmp_path, monkeypatch, capsys):
    # a run of one output stopped before it: the file holds its start
    # checkpoint and no output
    from orbits.cli import main
    path = tmp_path / "empty.h5"
    crash_at_final_output(monkeypatch)
    with pytest.raises(Crash):
        outer().run(until=1000 * u.day, outputs=1, output=path, progress=False)
    monkeypatch.undo()
    res = orbits.load(path)
    assert len(res) == 0
    assert "no outputs" in res.summary()
    assert main(["plot", str(path), "-o", str(tmp_path / "p.png")]) == 4
    err = capsys.readouterr().err
    assert "empty.h5: holds no outputs" in err and "nothing to plot" in err
    with pytest.raises(ValueError, match="no outputs"):
        orbits.plotting.plot_result(res, tmp_path / "q.png")


def test_load_gives_back_the_work_done(tmp_path):
    path = tmp_path / "run.h5"
    mem = outer().run(until=10_000 * u.day, outputs=11, progress=False)
    outer().run(until=10_000 * u.day, outputs=11, output=path, progress=False)
    back = orbits.load(path)
    assert back.steps == mem.steps == 1000
    assert back.force_evaluations == mem.force_evaluations
    assert back.wall_time > 0 and np.isfinite(back.wall_time)
    assert back.status == "completed"
    text = back.summary()
    assert "None" not in text and "nan" not in text
    assert f"({mem.force_evaluations} force evaluations)" in text


def test_a_file_from_before_the_totals_says_not_recorded(tmp_path):
    path = tmp_path / "old.h5"
    outer().run(until=10_000 * u.day, outputs=11, output=path, progress=False)
    with h5py.File(path, "a") as f:          # as files were written before
        for name in ("restart/wall", "parameters/start_clock"):
            if name in f:
                del f[name]
    back = orbits.load(path)
    assert back.force_evaluations is None and back.wall_time is None
    assert back.steps == 1000
    text = back.summary()
    assert "None" not in text and "nan" not in text
    assert "force evaluations not recorded" in text and "wall time not recorded" in text


@pytest.mark.parametrize("name", ["leapfrog", "dopri5"])
def test_the_summary_is_the_same_with_and_without_a_file(tmp_path, name):
    # the returned result holds only the last output; its largest errors and
    # time range still cover the whole run, in-loop monitor rows included
    mem = outer(name, monitor_every=7).run(until=20_000 * u.day, outputs=9, progress=False)
    res = outer(name, monitor_every=7).run(until=20_000 * u.day, outputs=9,
                                           output=tmp_path / "run.h5", progress=False)
    assert len(res) == 1
    assert res.max_energy_error() == mem.max_energy_error()
    assert res.max_angular_momentum_error() == mem.max_angular_momentum_error()
    if name == "leapfrog":
        # its energy error oscillates: the largest is not at the last output
        # (or this would test nothing); dopri5's grows, so there it is
        assert mem.max_energy_error() > mem.energy_error[-1]
    keep = lambda text: [ln for ln in text.splitlines()  # noqa: E731
                         if not ln.startswith("steps")]  # wall time differs
    assert keep(res.summary()) == keep(mem.summary())
    assert res.steps == mem.steps and res.force_evaluations == mem.force_evaluations


# -- checkpoints at the start and between chunks ---------------------------------------

KILLED_CHILD = textwrap.dedent("""
    import sys, astropy.units as u, orbits
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), integrator="leapfrog",
                            dt=10 * u.day)
    sim.run(until=6e4 * u.yr, outputs=101, output=sys.argv[1], progress=False)
""")


def checkpoints(path):
    try:
        with h5py.File(path, "r", swmr=True) as f:
            return int(f["restart/count"][()])
    except (OSError, KeyError, RuntimeError):
        return 0


def test_sigkill_before_the_first_periodic_checkpoint_resumes(tmp_path):
    # 2.2 million leapfrog steps take seconds; the periodic checkpoint comes
    # after 60 s, so only the start checkpoint is there when the run is killed
    path = tmp_path / "killed.h5"
    proc = subprocess.Popen([sys.executable, "-c", KILLED_CHILD, str(path)])
    try:
        deadline = time.monotonic() + HANG_SECONDS
        while time.monotonic() < deadline and proc.poll() is None and not checkpoints(path):
            time.sleep(0.02)
        proc.send_signal(signal.SIGKILL)
        proc.wait(HANG_SECONDS)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == -signal.SIGKILL, "the run ended before it was killed"
    assert "interrupted" in orbits.io.describe(path)     # not finished
    sim = orbits.Simulation.from_file(path)
    sim.resume(progress=False)
    ref = orbits.Simulation(orbits.scenes.outer_solar_system(), integrator="leapfrog",
                            dt=10 * u.day)
    mem = ref.run(until=6e4 * u.yr, outputs=101, progress=False)
    assert np.array_equal(sim._x, ref._x) and np.array_equal(sim._v, ref._v)
    done = orbits.load(path)
    assert done.status == "completed"
    np.testing.assert_array_equal(done.positions.value, mem.positions.value)
    np.testing.assert_array_equal(done.times.value, mem.times.value)


@pytest.mark.parametrize("name", ["leapfrog", "wh", "rk4", "ias15", "dop853"])
def test_a_checkpoint_between_chunks_resumes_bit_for_bit(tmp_path, name, monkeypatch):
    # as a signal handler does: a checkpoint where the compiled loop returns,
    # between outputs, then the process dies
    whole, cut = tmp_path / "whole.h5", tmp_path / "cut.h5"
    res_whole = outer(name).run(until=50_000 * u.day, outputs=5, output=whole,
                                progress=False)
    sim = outer(name)
    sim._chunk = 100          # several chunks between outputs
    monkeypatch.setattr(_driver, "next_chunk", lambda chunk, steps, elapsed: chunk)
    seen = []
    real = orbits.Simulation._check_wall

    def dying(self, rec, wall0):
        real(self, rec, wall0)
        seen.append(self.steps)
        if len(seen) == 3:
            rec.checkpoint()
            raise Crash()
    monkeypatch.setattr(orbits.Simulation, "_check_wall", dying)
    with pytest.raises(Crash):
        sim.run(until=50_000 * u.day, outputs=5, output=cut, progress=False)
    monkeypatch.undo()
    again = orbits.Simulation.from_file(cut)
    assert again.steps == seen[-1]
    res = again.resume(progress=False)
    a, b = orbits.load(whole), orbits.load(cut)
    np.testing.assert_array_equal(a.positions.value, b.positions.value)
    np.testing.assert_array_equal(a.velocities.value, b.velocities.value)
    np.testing.assert_array_equal(a.times.value, b.times.value)
    assert b.status == "completed" and a.steps == b.steps
    # the resumed run's largest errors include those written before the stop
    assert res.max_energy_error() == res_whole.max_energy_error()


# -- the writers' lock -----------------------------------------------------------------

LIVE_CHILD = textwrap.dedent("""
    import sys, astropy.units as u, orbits
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), integrator="leapfrog",
                            dt=1 * u.day)
    sim.run(until=1e9 * u.day, outputs=11, output=sys.argv[1], progress=False)
""")


def test_a_live_writer_keeps_its_file(tmp_path):
    path = tmp_path / "live.h5"
    proc = subprocess.Popen([sys.executable, "-c", LIVE_CHILD, str(path)])
    try:
        deadline = time.monotonic() + HANG_SECONDS
        while time.monotonic() < deadline and proc.poll() is None and not checkpoints(path):
            time.sleep(0.02)
        assert proc.poll() is None and checkpoints(path)
        assert f"process {proc.pid}" in orbits.io.describe(path)    # status: running
        sim = orbits.Simulation.from_file(path)                     # reading is fine
        with pytest.raises(FileInUse, match=f"being written by process {proc.pid}") as info:
            sim.resume(progress=False)
        assert info.value.pid == proc.pid
        with pytest.raises(FileInUse):
            outer().run(until=100 * u.day, outputs=2, output=path, overwrite=True,
                        progress=False)
        before = path.stat().st_ino
        proc.send_signal(signal.SIGKILL)
        proc.wait(HANG_SECONDS)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert path.stat().st_ino == before, "the file was replaced under its writer"
    # its writer dead, the lock it left is taken over
    lock = tmp_path / "live.h5.lock"
    assert lock.exists()
    assert "interrupted" in orbits.io.describe(path)
    outer().run(until=100 * u.day, outputs=2, output=path, overwrite=True, progress=False)
    assert not lock.exists()


def test_a_stale_lock_is_taken_over_and_a_foreign_one_is_not(tmp_path):
    path = tmp_path / "run.h5"
    lock = tmp_path / "run.h5.lock"
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)
    lock.write_text(json.dumps({"host": socket.gethostname(),
                                "pid": int(gone.stdout), "start": 1}))
    outer().run(until=100 * u.day, outputs=2, output=path, progress=False)
    assert not lock.exists()
    lock.write_text(json.dumps({"host": "elsewhere.example", "pid": 4242}))
    with pytest.raises(FileInUse, match="process 4242 on host 'elsewhere.example'.*"
                                        "delete the lock file"):
        outer().run(until=100 * u.day, outputs=2, output=path, overwrite=True,
                    progress=False)
    assert lock.exists()


# -- what checkpoints cost -------------------------------------------------------------

def test_a_checkpoint_at_every_output_does_not_grow_the_file(tmp_path):
    # Each output of 6 bodies holds 2 * 6 * 3 positions and velocities, 4
    # monitor values and 4 (step, time) pairs: 48 float64, 384 B; 700
    # outputs (more than a flush block, BUFFER_ROWS) are 269 kB.  Chunks
    # are allocated whole, and the metadata is some tens of kB, so both
    # files hold the data and under 2x overhead; rewriting a checkpoint in
    # place must not add to that: within 10 % of the file with one checkpoint
    # at the end.  (Before, every checkpoint gave the partial compressed chunks
    # new space: 5000 outputs took 657 MB.)
    sizes = {}
    for interval in (None, 0):
        path = tmp_path / f"every-{interval}.h5"
        outer().run(until=7000 * u.day, outputs=700, output=path, progress=False,
                    checkpoint_interval=interval)
        sizes[interval] = path.stat().st_size
        assert len(orbits.load(path)) == 700
    data = 700 * 48 * 8
    assert sizes[None] < 2 * data
    assert sizes[0] < 1.1 * sizes[None]


@pytest.mark.parametrize("bad", [-5, float("nan"), "often"])
def test_a_checkpoint_interval_that_is_not_seconds_is_refused(tmp_path, bad):
    path = tmp_path / "run.h5"
    with pytest.raises(ValueError, match="checkpoint_interval must be a number of seconds"):
        outer().run(until=100 * u.day, outputs=2, output=path, checkpoint_interval=bad,
                    progress=False)
    assert not path.exists() and not (tmp_path / "run.h5.lock").exists()
