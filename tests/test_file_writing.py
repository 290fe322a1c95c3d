"""Writing output files: temporaries and links, a full disk, resuming a damaged
file, runs continued into their file, and the unit system results carry."""

import os
import subprocess
import sys
import textwrap

import astropy.units as u
import h5py
import numpy as np
import pytest

import orbits
from orbits import cli
from orbits.analysis import frequencies, secular_frequencies
from orbits.io.h5md import FileRecorder, OrbitsFileError, safety

# A child that hangs fails the test rather than the suite: it spends 2-5 s
# importing orbits (astropy, numba) on a loaded two-core machine.
CHILD_SECONDS = 120

RUN = ["run", "kepler", "-i", "leapfrog", "--dt", "1d", "--no-progress"]


def kepler(**kw):
    return orbits.Simulation(orbits.scenes.kepler(**kw), "leapfrog", dt=1 * u.day)


class Crash(Exception):
    pass


def interrupted(path, monkeypatch):
    """A file whose run stopped before its last output: its start checkpoint
    and the outputs recorded in the loop after it are there."""
    real = FileRecorder.output

    def output(self, sim, final=False):
        if final:
            raise Crash()
        real(self, sim, final)
    with monkeypatch.context() as mp:
        mp.setattr(FileRecorder, "output", output)
        with pytest.raises(Crash):
            kepler().run(until=100 * u.day, outputs=11, output=path, progress=False)
    assert "interrupted" in orbits.io.describe(path)


def child(code, *args):
    try:
        return subprocess.run([sys.executable, "-c", code, *map(str, args)],
                              capture_output=True, text=True, timeout=CHILD_SECONDS)
    except subprocess.TimeoutExpired as exc:
        out = exc.stderr.decode() if isinstance(exc.stderr, bytes) else (exc.stderr or "")
        pytest.fail(f"hung for {CHILD_SECONDS} s; the child's last lines:\n{out[-2000:]}")


# -- temporaries and links ---------------------------------------------------------------

def test_a_link_at_the_name_of_a_temporary_is_not_written_through(tmp_path, monkeypatch):
    # run.h5.creating (a new file) and run.h5.resume (the copy resume makes)
    # made beforehand as links to another file: that file is left alone, and
    # run.h5 is a file of its own
    path = tmp_path / "run.h5"
    target = tmp_path / "precious.txt"
    target.write_text("precious")
    (tmp_path / "run.h5.creating").symlink_to(target)
    assert cli.main([*RUN, "--until", "10d", "--outputs", "3", "--out", str(path)]) == 0
    assert target.read_text() == "precious"
    assert not path.is_symlink() and len(orbits.load(path)) == 3
    assert not (tmp_path / "run.h5.creating").exists()

    path.unlink()
    interrupted(path, monkeypatch)
    (tmp_path / "run.h5.resume").symlink_to(target)
    assert cli.main(["resume", str(path), "--no-progress"]) == 0
    assert target.read_text() == "precious"
    assert not path.is_symlink() and orbits.load(path).status == "completed"
    assert not os.path.lexists(tmp_path / "run.h5.resume")


def test_a_destination_that_is_a_link_is_replaced_only_with_force(tmp_path, capsys):
    path = tmp_path / "run.h5"
    target = tmp_path / "elsewhere.h5"
    target.write_text("not an output")
    path.symlink_to(target)
    args = [*RUN, "--until", "10d", "--outputs", "3", "--out", str(path)]
    assert cli.main(args) == cli.EXIT_FILE
    err = capsys.readouterr().err
    assert f"{path}: a symbolic link" in err and "--force" in err
    assert path.is_symlink() and target.read_text() == "not an output"
    # --force replaces the link with a file; what it pointed to is not touched
    assert cli.main([*args, "--force"]) == 0
    assert not path.is_symlink() and len(orbits.load(path)) == 3
    assert target.read_text() == "not an output"
    # closed, the file holds no more than its end: the space reserved is given back
    assert path.stat().st_size == safety._superblock(path).eof


def test_resume_refuses_a_link(tmp_path, monkeypatch):
    real = tmp_path / "real.h5"
    interrupted(real, monkeypatch)
    link = tmp_path / "link.h5"
    link.symlink_to(real)
    with pytest.raises(OrbitsFileError, match="link.h5: a symbolic link .*real.h5"):
        orbits.Simulation.from_file(link).resume(progress=False)
    assert link.is_symlink() and "interrupted" in orbits.io.describe(real)
    assert not (tmp_path / "link.h5.lock").exists()


# -- a full disk -------------------------------------------------------------------------

# The run writes 40001 outputs of 2 bodies (about 9 MB); its file may grow to
# RUN_LIMIT bytes, which holds the new file (about 0.25 MB) and its start
# checkpoint with the space reserved ahead of it, but not the outputs.  Resume
# then copies the file, which RESUME_LIMIT does not let it finish.
RUN_LIMIT = 1_500_000
RESUME_LIMIT = 300_000
FULL_DISK = textwrap.dedent("""
    import resource, signal, sys
    from orbits.cli import main
    # past the limit a write fails with EFBIG instead of ending the process
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    path, warm, run_limit, resume_limit = sys.argv[1], sys.argv[2], *map(int, sys.argv[3:])
    run = ["run", "kepler", "-i", "leapfrog", "--dt", "1d", "--no-progress", "--out"]
    # compiled (or read from numba's cache) before the limit applies
    assert main([*run, warm, "--until", "100d", "--outputs", "101"]) == 0
    hard = resource.getrlimit(resource.RLIMIT_FSIZE)[1]
    resource.setrlimit(resource.RLIMIT_FSIZE, (run_limit, hard))
    print("run", main([*run, path, "--until", "40000d", "--outputs", "40001"]), flush=True)
    resource.setrlimit(resource.RLIMIT_FSIZE, (resume_limit, hard))
    print("resume", main(["resume", path, "--no-progress"]), flush=True)
""")


def test_a_full_disk_is_a_file_error_and_the_file_resumes(tmp_path):
    # a file-size limit (ulimit -f) stands in for a full disk: writes past it
    # fail as on a full one.  Before, the run raised HDF5's RuntimeError and
    # the interpreter crashed at exit (status 139), and resume left its copy
    # and the lock behind.
    path = tmp_path / "run.h5"
    out = child(FULL_DISK, path, tmp_path / "warm.h5", RUN_LIMIT, RESUME_LIMIT)
    assert out.returncode == 0, out.stderr[-3000:]
    assert f"run {cli.EXIT_FILE}" in out.stdout and f"resume {cli.EXIT_FILE}" in out.stdout
    assert "Traceback" not in out.stderr
    assert out.stderr.count(f"{path}: the disk is full (File too large)") == 2, out.stderr
    assert "orbits resume" in out.stderr
    for left in ("run.h5.lock", "run.h5.resume", "run.h5.creating"):
        assert not os.path.lexists(tmp_path / left), left
    # the space reserved past the file's end was given back
    assert path.stat().st_size == safety._superblock(path).eof
    # what was written resumes, and ends as a run that had room
    assert "interrupted" in orbits.io.describe(path)
    assert cli.main(["resume", str(path), "--no-progress"]) == 0
    mem = kepler().run(until=40000 * u.day, outputs=40001, progress=False)
    back = orbits.load(path)
    assert back.status == "completed"
    np.testing.assert_array_equal(back.times.value, mem.times.value)
    np.testing.assert_array_equal(back.positions.value, mem.positions.value)
    np.testing.assert_array_equal(back.velocities.value, mem.velocities.value)


UNRESERVED = textwrap.dedent("""
    import errno, os, resource, signal, sys
    import astropy.units as u, orbits
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)

    def unsupported(fd, offset, length):
        raise OSError(errno.EOPNOTSUPP, os.strerror(errno.EOPNOTSUPP))
    os.posix_fallocate = unsupported     # no space reserved: HDF5's own writes fail
    path, limit = sys.argv[1], int(sys.argv[2])
    sim = lambda: orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    sim().run(until=100 * u.day, outputs=101, output=path + ".warm", progress=False)
    hard = resource.getrlimit(resource.RLIMIT_FSIZE)[1]
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, hard))
    try:
        sim().run(until=40000 * u.day, outputs=40001, output=path, progress=False)
    except orbits.io.OrbitsFileError as exc:
        print("raised", type(exc).__name__, exc.errno, exc, flush=True)
""")


def test_a_write_that_fails_in_hdf5_ends_the_session_cleanly(tmp_path):
    # where no space can be reserved ahead (a file system without
    # fallocate), the write that fails is HDF5's own: the run still raises
    # OrbitsFileError, and the session ends normally (it crashed at exit
    # with status 139: HDF5 freed the datasets whose close failed and closed
    # them again at exit)
    import errno
    path = tmp_path / "run.h5"
    out = child(UNRESERVED, path, RUN_LIMIT)
    assert out.returncode == 0, out.stderr[-3000:]
    assert f"raised OrbitsFileError {errno.EFBIG} {path}: the disk is full" in out.stdout
    assert not (tmp_path / "run.h5.lock").exists()


# -- resuming a damaged file ---------------------------------------------------------------

def test_a_copy_that_fails_in_resume_is_a_file_error_and_leaves_nothing(tmp_path,
                                                                        monkeypatch, capsys):
    # HDF5 failing to read a block of the file while resume copies it (a
    # checksum that does not match): before, a raw RuntimeError, exit status
    # 1, and run.h5.resume and run.h5.lock left behind
    path = tmp_path / "run.h5"
    interrupted(path, monkeypatch)
    before = path.read_bytes()
    real = h5py.Group.copy
    calls = []

    def damaged(self, source, dest, *args, **kwargs):
        calls.append(source)
        if len(calls) == 3:
            raise RuntimeError("Unable to copy object (incorrect metadata checksum after all "
                               "read attempts)")
        return real(self, source, dest, *args, **kwargs)
    with monkeypatch.context() as mp:
        mp.setattr(h5py.Group, "copy", damaged)
        assert cli.main(["resume", str(path), "--no-progress"]) == cli.EXIT_FILE
    err = capsys.readouterr().err
    assert f"{path}: damaged" in err and "incorrect metadata checksum" in err
    assert "Traceback" not in err
    assert not os.path.lexists(tmp_path / "run.h5.resume")
    assert not (tmp_path / "run.h5.lock").exists()
    assert path.read_bytes() == before
    assert cli.main(["resume", str(path), "--no-progress"]) == 0


# -- runs continued into their file --------------------------------------------------------

def test_a_run_continued_into_its_file_does_not_repeat_its_first_output(tmp_path):
    path = tmp_path / "run.h5"
    tilted = dict(e=0.1, inc=0.1 * u.rad)      # so that both secular signals are there
    kepler(**tilted).run(until=100 * u.day, outputs=11, output=path, progress=False)
    orbits.Simulation.from_file(path).run(until=200 * u.day, outputs=11, output=path,
                                          progress=False)
    sim = kepler(**tilted)
    sim.run(until=100 * u.day, outputs=11, output=tmp_path / "same.h5", progress=False)
    sim.run(until=200 * u.day, outputs=11, output=tmp_path / "same.h5", progress=False)
    for p in (path, tmp_path / "same.h5"):
        back = orbits.load(p)
        np.testing.assert_array_equal(back.times.to_value(u.day), np.arange(0, 201, 10.0))
        # the second run's outputs start after the first run's last
        sf = secular_frequencies(back, "Planet", n=1, plane="run")
        assert len(sf.g) == len(sf.s) == 1
    # and the continued run resumes as any other
    again = orbits.Simulation.from_file(path)
    assert again.resume_point.finished and again.resume_point.rows == 21


# -- readers that hold HDF5's lock ---------------------------------------------------------

HOLD = textwrap.dedent("""
    import sys, h5py
    f = h5py.File(sys.argv[1], "r", swmr=sys.argv[2] == "swmr")
    print(f["particles/bodies/names"].shape[0], flush=True)
    sys.stdin.readline()
""")


class Holder:
    """Another process that opens ``path`` with plain h5py and holds it (and
    HDF5's lock, where it takes one) until :meth:`close`."""

    def __init__(self, path, mode):
        self.proc = subprocess.Popen([sys.executable, "-c", HOLD, str(path), mode],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     text=True)
        self.bodies = self.proc.stdout.readline().strip()

    def close(self):
        if self.proc.poll() is None:
            self.proc.stdin.close()
        self.proc.wait(CHILD_SECONDS)


def test_a_reader_that_opens_a_new_file_as_it_appears_does_not_stop_its_writer(
        tmp_path, monkeypatch):
    # a script polling for the file opens it the moment it takes its name (as
    # test_file_reliability's live-writer test did, once in CI): the writer
    # must not need a lock that reader holds
    from orbits.io.h5md import layout
    path, readers = tmp_path / "run.h5", []
    real = os.replace

    def replace(src, dst):
        real(src, dst)
        if os.fspath(dst) == os.fspath(path):
            readers.append(Holder(path, "swmr"))
    monkeypatch.setattr(layout.os, "replace", replace)
    try:
        kepler().run(until=100 * u.day, outputs=11, output=path, progress=False)
    finally:
        for r in readers:
            r.close()
    assert [r.bodies for r in readers] == ["2"]
    np.testing.assert_array_equal(orbits.load(path).times.to_value(u.day),
                                  np.arange(0, 101, 10.0))


def test_an_append_waits_for_a_reader_and_then_says_what_holds_the_file(tmp_path,
                                                                        monkeypatch):
    import threading

    from orbits.io.h5md import writer
    path = tmp_path / "run.h5"
    sim = kepler()
    sim.run(until=100 * u.day, outputs=11, output=path, progress=False)
    # a reader that closes the file within the wait: the run goes on
    reader = Holder(path, "plain")
    timer = threading.Timer(0.5, reader.close)
    timer.start()
    sim.run(until=200 * u.day, outputs=11, output=path, progress=False)
    timer.join()
    assert reader.proc.returncode == 0
    np.testing.assert_array_equal(orbits.load(path).times.to_value(u.day),
                                  np.arange(0, 201, 10.0))
    # one that keeps it: a named error, and the file as it was
    before = path.read_bytes()
    monkeypatch.setattr(writer, "READER_WAIT_SECONDS", 0.2)
    reader = Holder(path, "plain")
    try:
        with pytest.raises(OrbitsFileError, match="open in another program, which holds "
                                                  "HDF5's lock"):
            sim.run(until=300 * u.day, outputs=11, output=path, progress=False)
    finally:
        reader.close()
    assert path.read_bytes() == before
    assert sim.time.to_value(u.day) == 200


def test_repeated_times_are_named_without_advice_about_dt():
    t = np.array([0.0, 10, 20, 20, 30, 40, 50, 60, 70]) * u.day
    with pytest.raises(ValueError, match=r"times\[3\] = 20 is not after times\[2\] = 20") as info:
        frequencies(t, np.ones(9))
    assert "dt" not in str(info.value)


# -- the unit system a result carries ------------------------------------------------------

def hlw_kepler():
    # Hairer, Lubich & Wanner's G (au, Msun, day), not astropy's
    units = orbits.UnitSystem(G=2.95912208286e-4, name="HLW")
    return orbits.scenes.kepler(units=units), units


def test_results_carry_their_unit_system_and_files_give_it_back(tmp_path):
    bodies, units = hlw_kepler()
    sim = orbits.Simulation(bodies, "leapfrog", dt=1 * u.day)
    mem = sim.run(until=10 * u.day, outputs=3, progress=False)
    sim.run(until=20 * u.day, outputs=3, output=tmp_path / "run.h5", progress=False)
    back = orbits.load(tmp_path / "run.h5")
    for r in (mem, back):
        assert isinstance(r.units, orbits.UnitSystem)
        assert r.units == units and r.units.G == 2.95912208286e-4 and r.units.name == "HLW"
        assert r.units["G"] == r.units.G          # the keys results used to have
        again = orbits.BodySet.from_arrays(r.masses, r.positions[-1], r.velocities[-1],
                                           names=r.names, units=r.units)
        assert again.units.G == 2.95912208286e-4
    assert "units           HLW, G = 0.000295912208286" in back.summary()


def test_a_lock_that_is_not_a_file_is_not_read_through(tmp_path, capsys):
    # run.h5.lock made beforehand as a link to a named pipe: reading it blocked
    # for ever (open waits for a writer).  A lock orbits makes is a regular
    # file, so this one is not a writer's and is taken over.
    import signal
    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    (tmp_path / "run.h5.lock").symlink_to(pipe)

    def hung(signum, frame):
        raise Crash("reading the lock blocked")     # not an OSError, which the reader catches
    previous = signal.signal(signal.SIGALRM, hung)
    signal.alarm(60)        # the run takes a few seconds
    try:
        code = cli.main([*RUN, "--until", "10d", "--outputs", "3",
                         "--out", str(tmp_path / "run.h5")])
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    assert code == 0, capsys.readouterr().err
    assert pipe.exists() and not os.path.lexists(tmp_path / "run.h5.lock")
