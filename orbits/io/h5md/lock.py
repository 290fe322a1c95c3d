"""The writers' lock: one process writes a file at a time.

A writer holds ``<file>.lock`` (made atomically; it names the host, process
id and its start time) while the file is open, and removes it on closing.
A second writer, or a resume, of a file whose lock names a live process is
refused with :class:`FileInUse`; a lock left by a process that has died (on
this host) is taken over.
"""

import datetime
import json
import os
import pathlib
import socket
import stat
import time as _time
import uuid

from .errors import FileInUse, OrbitsFileError, _write_error

__all__ = []

#: a writer's lock this many seconds old that cannot be read is taken to be
#: left over (a lock is written whole before it appears, see _acquire)
_LOCK_UNREADABLE_SECONDS = 5.0
_HELD = {}      # lock path -> token, for the locks this process holds


def _lock_path(path):
    return pathlib.Path(os.path.abspath(path) + ".lock")


def _process_start(pid):
    """(state, start time in clock ticks) of a process on this host, from /proc; or None."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            text = fh.read()
    except OSError:
        return None
    fields = text[text.rindex(")") + 2:].split()
    return fields[0], int(fields[19])           # stat(5) fields 3 and 22


#: the most bytes of a writers' lock read (one holds about 150)
_LOCK_BYTES = 4096


def _read_lock(lock):
    """The lock's record; None if there is no lock, {} if it cannot be read.

    Read without following a link, and only from a regular file, the kind a
    writer makes (a link to a named pipe would block the read for ever).
    """
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
    try:
        fd = os.open(lock, flags)
    except FileNotFoundError:
        return None
    except OSError:
        return {}
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return {}
        text = os.read(fd, _LOCK_BYTES).decode("utf-8", "replace")
    except OSError:
        return {}
    finally:
        os.close(fd)
    try:
        rec = json.loads(text)
    except ValueError:
        return {}
    return rec if isinstance(rec, dict) else {}


def _alive(rec):
    """Whether the lock's process runs: True, False, or None where it cannot be told."""
    if rec.get("host") != socket.gethostname():
        return None
    pid = rec.get("pid")
    if not isinstance(pid, int) or pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass
    found = _process_start(pid)
    if found is not None:
        state, start = found
        if state in ("Z", "X"):                 # exited, not yet reaped
            return False
        if rec.get("start") is not None and rec["start"] != start:
            return False                        # the pid was reused
    return True


def _writer(path):
    """``(record, alive)`` of the lock on ``path``; ``(None, False)`` if there is none."""
    rec = _read_lock(_lock_path(path))
    if rec is None:
        return None, False
    if not rec:
        return rec, None
    return rec, _alive(rec)


def _acquire(path):
    """Take the writers' lock of ``path`` (or keep it, if this process holds it)."""
    lock = _lock_path(path)
    key = str(lock)
    if key in _HELD and (_read_lock(lock) or {}).get("token") == _HELD[key]:
        return
    started = _process_start(os.getpid())
    token = uuid.uuid4().hex
    me = {"host": socket.gethostname(), "pid": os.getpid(),
          "start": started[1] if started else None, "token": token,
          "since": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}
    tmp = lock.with_name(f"{lock.name}.{token}")
    made = False
    try:
        with open(tmp, "x") as fh:              # a new file, never one a link names
            made = True
            fh.write(json.dumps(me))
    except OSError as exc:
        if made:
            tmp.unlink(missing_ok=True)
        raise _write_error(path, exc, f"when making its writers' lock {lock}") from None
    try:
        for _ in range(5):
            if _link(tmp, lock):
                _HELD[key] = token
                return
            rec = _read_lock(lock)
            if rec is None:
                continue                        # released meanwhile
            alive = _alive(rec) if rec else None
            if not rec:
                try:
                    info = lock.lstat()
                except FileNotFoundError:
                    continue
                # a writer's lock is a regular file: anything else there (a
                # link, a pipe) is not one, and is taken over at once
                if not stat.S_ISREG(info.st_mode) or \
                        _time.time() - info.st_mtime > _LOCK_UNREADABLE_SECONDS:
                    alive = False
            if alive is False:
                _remove_stale(lock, rec)
                continue
            raise _in_use(path, lock, rec)
        raise FileInUse(f"{path}: could not take its lock {lock} (other writers keep "
                        f"taking it)")
    except OrbitsFileError:
        raise
    except OSError as exc:
        raise _write_error(path, exc, f"when taking its writers' lock {lock}") from None
    finally:
        tmp.unlink(missing_ok=True)


def _link(tmp, lock):
    # the lock appears whole: a hard link made only if nothing has the name
    try:
        os.link(tmp, lock)
        return True
    except FileExistsError:
        return False
    except OSError:                             # a file system without hard links
        try:
            fd = os.open(lock, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
        except FileExistsError:
            return False
        with os.fdopen(fd, "w") as fh:
            fh.write(tmp.read_text())
        return True


def _remove_stale(lock, rec):
    # renamed away first, so that of two processes taking it over only one
    # removes it, and a lock taken meanwhile by a live writer is put back
    grave = lock.with_name(f"{lock.name}.stale.{uuid.uuid4().hex}")
    try:
        os.rename(lock, grave)
    except FileNotFoundError:
        return
    if _read_lock(grave) != rec:
        _link(grave, lock)
    grave.unlink(missing_ok=True)


def _in_use(path, lock, rec):
    pid, host = rec.get("pid"), rec.get("host")
    if not rec:
        who = "another process (its lock cannot be read yet)"
    elif host == socket.gethostname():
        who = f"process {pid}"
    else:
        who = f"process {pid} on host {host!r}"
    since = f" since {rec['since']}" if rec.get("since") else ""
    return FileInUse(f"{path}: being written by {who}{since} (lock {lock}); wait for it "
                     f"to finish or stop it first"
                     + ("; if that process is gone, delete the lock file"
                        if rec and host != socket.gethostname() else ""),
                     pid=pid, host=host)


def _release(path):
    lock = _lock_path(path)
    token = _HELD.pop(str(lock), None)
    if token is not None and (_read_lock(lock) or {}).get("token") == token:
        lock.unlink(missing_ok=True)
