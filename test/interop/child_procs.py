"""Child processes for the interop orchestrators (live_identity.py, reynard_interop.py, ...): start one
that dies with us, read its JSON ready line, stop it (SIGTERM, then SIGKILL)."""

import ctypes
import json
import os
import selectors
import signal
import subprocess
import time


class StepFailed(Exception):
    pass


def die_with_parent():
    """preexec_fn: the child gets SIGTERM if the orchestrator dies, so nothing is left running (Linux)."""
    try:
        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        libc.prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except OSError:
        pass


def start(cmd, stderr_path):
    """Starts `cmd` with stdout piped and stderr written to `stderr_path`."""
    with open(stderr_path, "wb") as errf:
        return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=errf, stdin=subprocess.DEVNULL,
                                preexec_fn=die_with_parent)


def read_json_line(proc, timeout, what):
    """Reads the first stdout line of `proc` as JSON within `timeout` seconds; StepFailed otherwise."""
    sel = selectors.DefaultSelector()
    sel.register(proc.stdout, selectors.EVENT_READ)
    buf = b""
    deadline = time.monotonic() + timeout
    try:
        while b"\n" not in buf:
            left = deadline - time.monotonic()
            if left <= 0:
                raise StepFailed("%s: no ready line within %.0f s" % (what, timeout))
            if not sel.select(left):
                continue
            chunk = os.read(proc.stdout.fileno(), 4096)
            if not chunk:
                raise StepFailed("%s exited early (status %s)" % (what, proc.wait(5)))
            buf += chunk
    finally:
        sel.close()
    try:
        return json.loads(buf.split(b"\n", 1)[0])
    except ValueError as e:
        raise StepFailed("%s: bad ready line %r: %s" % (what, buf[:200], e))


def stop(proc, wait_s=10):
    """SIGTERM, wait up to `wait_s`, then SIGKILL. Returns the exit status (None for no process)."""
    if proc is None:
        return None
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(wait_s)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(5)
    if proc.stdout:
        proc.stdout.close()
    return proc.returncode


def tail(path, n=20):
    """The last `n` lines of a log file ("" when it cannot be read)."""
    try:
        with open(path, "rb") as fh:
            return "\n".join(fh.read().decode("utf-8", "replace").splitlines()[-n:])
    except OSError:
        return ""
