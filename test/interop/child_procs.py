"""Child processes for the interop orchestrators (live_identity.py, reynard_interop.py, ...): start one
that dies with us, read its JSON ready line, stop it (SIGTERM, then SIGKILL)."""

import ctypes
import hashlib
import json
import os
import selectors
import signal
import subprocess
import sys
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


def proc_state(pid):
    """The kernel's view of a process that does not end: its State line and where it sleeps (wchan)."""
    try:
        state = next((l.strip() for l in open("/proc/%d/status" % pid) if l.startswith("State:")), "?")
        wchan = open("/proc/%d/wchan" % pid).read().strip() or "-"
        return "%s, wchan %s" % (state, wchan)
    except OSError as e:
        return "no /proc entry (%s)" % e


def threads_of(pid):
    """Where a live process's threads are, for a hang's report: each thread's name, wchan and CPU
    ticks, then gdb's backtraces when gdb can attach (LeakSanitizer's exit check holds ptrace then)."""
    lines = []
    try:
        for t in sorted(os.listdir("/proc/%d/task" % pid), key=int):
            try:
                comm = open("/proc/%d/task/%s/comm" % (pid, t)).read().strip()
                wchan = open("/proc/%d/task/%s/wchan" % (pid, t)).read().strip() or "-"
                f = open("/proc/%d/task/%s/stat" % (pid, t)).read().rsplit(")", 1)[1].split()
                lines.append("  %s %s %s (state %s, cpu ticks %s)" % (t, comm, wchan, f[0], int(f[11]) + int(f[12])))
            except OSError:
                pass
    except OSError as e:
        return "  (no /proc entry: %s)" % e
    try:
        gdb = subprocess.run(["gdb", "-p", str(pid), "-batch", "-nx", "-ex", "thread apply all bt 20"],
                             capture_output=True, text=True, timeout=60)
        bt = [l for l in (gdb.stdout + gdb.stderr).splitlines() if l.startswith(("Thread ", "#", "ptrace", "warning: process"))]
        lines += bt[:300]
    except (OSError, subprocess.TimeoutExpired) as e:
        lines.append("  (gdb: %s)" % e)
    return "\n".join(lines)


def stop(proc, wait_s=60):
    """SIGTERM, wait up to `wait_s`, then SIGKILL (printing where the process's threads were). Returns
    the exit status (None for no process). 60 s: ASan gateways beside a full CI run (load about 20) took
    over 10 s to end twice in one run, and one took over 20 s at load 30 in close() of its inotify
    descriptor (the kernel waits for an SRCU grace period); a real hang still fails, and names itself."""
    if proc is None:
        return None
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(wait_s)
        except subprocess.TimeoutExpired:
            # the test fails on the status; say where the process was, so a hang names itself
            sys.stderr.write("pid %d (%s) still running %s s after SIGTERM; its threads:\n%s\n"
                             % (proc.pid, os.path.basename(str(proc.args[0])), wait_s, threads_of(proc.pid)))
            proc.kill()
            try:
                proc.wait(30)  # a loaded machine has taken over 5 s to end a killed official node
            except subprocess.TimeoutExpired:
                raise StepFailed("pid %d (%s) still there 30 s after SIGKILL: %s" % (proc.pid, proc.args[:3], proc_state(proc.pid)))
    if proc.stdout:
        proc.stdout.close()
    return proc.returncode


def stop_by_stdin(proc, wait_s=30):
    """Closes the child's stdin (its sign to stop cleanly), waits up to `wait_s`, then stop(). Returns
    the exit status."""
    if proc.poll() is None:
        try:
            proc.stdin.close()
        except OSError:
            pass
        try:
            return proc.wait(wait_s)
        except subprocess.TimeoutExpired:
            return stop(proc)
    return proc.returncode


def tail(path, n=20):
    """The last `n` lines of a log file ("" when it cannot be read)."""
    try:
        with open(path, "rb") as fh:
            return "\n".join(fh.read().decode("utf-8", "replace").splitlines()[-n:])
    except OSError:
        return ""


# The official library's folder overrides (RobotRaconteurCore's NodeDirectories): pointing all of them
# into one scratch tree keeps a test's rr+local sockets, NodeID cache and config away from the machine's.
RR_DIR_VARS = (("ROBOTRACONTEUR_SYSTEM_RUN_DIR", "sysrun"), ("ROBOTRACONTEUR_SYSTEM_STATE_DIR", "sysstate"),
               ("ROBOTRACONTEUR_SYSTEM_CONFIG_DIR", "sysconfig"), ("ROBOTRACONTEUR_USER_RUN_DIR", "run"),
               ("ROBOTRACONTEUR_USER_CONFIG_DIR", "config"))


def scratch_rr_env(tree, env=None):
    """A copy of `env` (default: os.environ) whose ROBOTRACONTEUR_*_DIR folders all lie below `tree`."""
    out = dict(os.environ if env is None else env)
    for var, sub in RR_DIR_VARS:
        out[var] = os.path.join(tree, sub)
    return out


def fail(msg):
    """Prints FAIL and ends the script with status 1 (the orchestrators' way to stop at a failed step)."""
    print("FAIL: " + msg, flush=True)
    raise SystemExit(1)


def get_json(port, path, timeout=10):
    """GET http://127.0.0.1:PORT/PATH as JSON (raises OSError / urllib errors)."""
    import urllib.request
    with urllib.request.urlopen("http://127.0.0.1:%d%s" % (port, path), timeout=timeout) as r:
        return json.loads(r.read())


def wait_for(pred, timeout, what, interval=0.1):
    """Polls `pred` until it returns something true (returned); OSError counts as not yet. fail() on timeout."""
    deadline = time.monotonic() + timeout
    last = None
    while time.monotonic() < deadline:
        try:
            last = pred()
            if last:
                return last
        except OSError as e:
            last = e
        time.sleep(interval)
    fail("%s within %.0f s (last: %r)" % (what, timeout, last))


def password_line(user, password, privileges):
    """One entry of the official password file: `user md5hex(password) privileges` (comma-separated)."""
    return "%s %s %s" % (user, hashlib.md5(password.encode()).hexdigest(), privileges)


def write_password_file(path, entries, comment=True):
    """Writes the official password file from (user, password, privileges) triples or ready lines, in one
    rename (a gateway reloading it on SIGHUP never reads half a file). comment=False leaves out the
    leading `#` line, which the official library cannot read (it takes every line for a user)."""
    lines = ["# official password file format: user md5(password) privileges"] if comment else []
    lines += [e if isinstance(e, str) else password_line(*e) for e in entries]
    with open(path + ".new", "w") as f:
        f.write("".join(l + "\n" for l in lines))
    os.replace(path + ".new", path)


class Checks:
    """Named checks of an interop script: each runs, and its outcome (with the error and a short trace
    when it failed) is kept in `results` for the script's JSON summary."""

    def __init__(self):
        self.results = []

    def check(self, name, fn):
        import traceback
        try:
            fn()
            self.results.append({"check": name, "ok": True})
        except Exception as e:  # noqa: BLE001
            self.results.append({"check": name, "ok": False, "error": "%s: %s" % (type(e).__name__, e),
                                 "trace": traceback.format_exc(limit=3)})
