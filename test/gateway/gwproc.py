"""Starting and stopping the processes of the gateway tests: rr-gateway and rr-demo-devices.

Both print one JSON line on stdout when listening (rr-gateway: {"port": N}; rr-demo-devices: {"port": N,
"create_url": ..., "webcam_url": ...}). Processes are stopped by PID (SIGTERM, then SIGKILL).
"""
import json
import os
import random
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.request

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "interop"))
from child_procs import threads_of  # noqa: E402,F401 (where a hung gateway's threads are)


class Proc:
    """A child process whose first JSON line on stdout is `info`; later stdout lines are drained."""

    # Bounds on a hang, not expected durations: under a CI-like load (load average 20-30 on 2 vCPUs) an
    # ASan gateway has taken over 30 s to print its ready line, and over 20 s to exit after SIGTERM while
    # the kernel closed its inotify descriptor (close() waits for an SRCU grace period: 10 ms idle,
    # 1.5 s measured at load 19; docs/development.md "What a test may wait on").
    def __init__(self, argv, env=None, timeout=60.0):
        self.argv = argv
        self.p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=sys.stderr, text=True, env=env)
        self.info = None
        got = threading.Event()

        def read():
            for line in self.p.stdout:
                if self.info is None:
                    try:
                        obj = json.loads(line)
                    except ValueError:
                        continue
                    if isinstance(obj, dict) and "port" in obj:
                        self.info = obj
                        got.set()
            got.set()

        threading.Thread(target=read, daemon=True).start()
        if not got.wait(timeout) or self.info is None:
            if self.p.poll() is None:
                sys.stderr.write("%s (pid %d) printed no ready line in %.0f s; its threads:\n%s\n"
                                 % (argv[0], self.p.pid, timeout, threads_of(self.p.pid)))
            self.kill()
            raise RuntimeError("%s printed no ready line (exit %s)" % (argv[0], self.p.poll()))

    @property
    def pid(self):
        return self.p.pid

    @property
    def port(self):
        return self.info["port"]

    def alive(self):
        return self.p.poll() is None

    def stop(self, timeout=60.0):
        """SIGTERM, wait; SIGKILL when it does not end. Returns the exit status ("killed" if it hung)."""
        if self.p.poll() is not None:
            return self.p.returncode
        self.p.send_signal(signal.SIGTERM)
        try:
            return self.p.wait(timeout)
        except subprocess.TimeoutExpired:
            sys.stderr.write("gateway pid %d did not end %.0f s after SIGTERM; its threads:\n%s\n"
                             % (self.p.pid, timeout, threads_of(self.p.pid)))
            self.kill()
            return "killed"

    def kill(self):
        if self.p.poll() is None:
            self.p.kill()
        self.p.wait()


def gateway_env():
    """The environment for a gateway under ASan: a small quarantine, so that RSS shows live memory."""
    env = dict(os.environ)
    asan = env.get("ASAN_OPTIONS", "")
    env["ASAN_OPTIONS"] = (asan + ":" if asan else "") + "quarantine_size_mb=8:thread_local_quarantine_size_kb=64"
    return env


def start_gateway(exe, args, timeout=60.0):
    return Proc([exe, "--listen", "127.0.0.1", "--port", "0", "--log-level", "warning", "--no-local"] + list(args),
                env=gateway_env(), timeout=timeout)


def start_devices(exe, port=0, play_period=None):
    argv = [exe, "--port", str(port), "--max-lifetime", "600"]
    if play_period is not None:
        argv += ["--play-period", str(play_period)]
    return Proc(argv)


def http_status(url, headers=None, timeout=30.0):
    req = urllib.request.Request(url, headers=headers or {})
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            return r.status, r.read().decode("utf-8", "replace")
    except urllib.error.HTTPError as e:
        return e.code, e.read().decode("utf-8", "replace")


def wait_ready(port, timeout=60.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            if http_status("http://127.0.0.1:%d/readyz" % port, timeout=10)[0] == 200:
                return
        except OSError:
            pass
        time.sleep(0.1)
    raise RuntimeError("gateway on port %d not ready within %.0f s" % (port, timeout))


def fixed_ports(count):
    """`count` distinct free TCP ports on 127.0.0.1 below the ephemeral range: for a server that must come
    back on the same port after a restart, or one that binds some time after the port was chosen (nginx,
    a gateway): an ephemeral port could be taken meanwhile by any outgoing connection or bind to port 0."""
    low = int(open("/proc/sys/net/ipv4/ip_local_port_range").read().split()[0])
    held = []
    try:
        for _ in range(100 * count):
            if len(held) == count:
                break
            s = socket.socket()
            try:
                s.bind(("127.0.0.1", random.randrange(20000, min(low, 29000))))
                held.append(s)
            except OSError:
                s.close()
        if len(held) < count:
            raise RuntimeError("no %d free ports below the ephemeral range" % count)
        return [s.getsockname()[1] for s in held]
    finally:
        for s in held:
            s.close()


def fixed_port():
    """One port of fixed_ports()."""
    return fixed_ports(1)[0]


def vm_rss_kib(pid):
    """Resident set size of a process (/proc/PID/status VmRSS), KiB."""
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise RuntimeError("no VmRSS for %d" % pid)


class Checks:
    """Named checks; a failed one is recorded and the run goes on. exit_code() is 0 only if all passed."""

    def __init__(self):
        self.results = []

    def run(self, name, fn):
        print("... %s" % name, file=sys.stderr, flush=True)
        try:
            fn()
            self.results.append((name, None))
        except Exception as e:  # a failed check, whatever raised it
            msg = "%s: %s" % (type(e).__name__, e)
            print("FAIL %s: %s" % (name, msg), file=sys.stderr, flush=True)
            self.results.append((name, msg))

    def exit_code(self):
        failed = [(n, m) for n, m in self.results if m]
        print(json.dumps({"ok": not failed, "passed": len(self.results) - len(failed),
                          "failures": [{"check": n, "error": m} for n, m in failed]}), flush=True)
        return 1 if failed else 0


def expect(cond, what):
    if not cond:
        raise AssertionError(what)


def wait_for(pred, timeout, what):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if pred():
            return
        time.sleep(0.02)
    raise AssertionError("timed out after %.1f s waiting for %s" % (timeout, what))
