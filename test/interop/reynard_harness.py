#!/usr/bin/env python3
"""Runs Reynard the Robot (PyPI `reynard-the-robot`, pinned in requirements.txt) headless, as a test device.

Reynard ships no console script in this venv (its wheel has no entry points), so it is started as a
module: `python -u -m reynard_the_robot ...`. Without `--gui` it is headless already: it serves its
web UI (aiohttp + socket.io, no browser needed), an optional ASCII socket, and its Robot Raconteur
service "reynard" through a stock `ServerNodeSetup` that reads the standard `--robotraconteur-*`
command-line options. This harness passes:

    --robotraconteur-tcp-port=P              RR TCP port (0 = ephemeral; 29200 when omitted)
    --robotraconteur-tcp-listen-localhost=true   (unless --public)
    --robotraconteur-local-enable=false      the local transport claims the node name
                                             "experimental.reynard_the_robot" system-wide: a second
                                             instance would die with "Identifier UUID or Name already
                                             in use", and a killed one leaves files in /run/robotraconteur
    --robotraconteur-tcp-ipv4-discovery=false --robotraconteur-tcp-ipv6-discovery=false   (no UDP broadcasts)
    --http-port=H                            web UI / REST / socket.io (0 = ephemeral; 29201 when omitted)
    --disable-ascii-socket                   (or --ascii-socket-port=A with --ascii-port A)

Ephemeral ports are found out, not guessed: the RR port from the candidate URLs Reynard prints, the
HTTP port from the child's own listening sockets (/proc/PID/fd + /proc/PID/net/tcp{,6}).

Readiness: the harness connects to the RR URL with the official client on a private node, reads
`robot_position`, disconnects; and GETs http://127.0.0.1:H/api/state. Then it prints exactly one JSON
line on stdout:

    {"url": "rr+tcp://127.0.0.1:P/?service=reynard", "port": P, "service": "reynard",
     "nodeid": "...", "nodename": "experimental.reynard_the_robot",
     "root_type": "experimental.reynard_the_robot.Reynard",
     "http_url": "http://127.0.0.1:H/", "http_port": H, "ascii_port": null,
     "pid": REYNARD_PID, "harness_pid": ..., "startup_s": ...}

and runs until SIGTERM/SIGINT, --max-lifetime, or Reynard's unexpected exit. Stopping: SIGINT to
Reynard (its `finally` closes the RR node, ~0.3 s), then SIGTERM, then SIGKILL - by PID only, each
with a time limit. Reynard gets PR_SET_PDEATHSIG, so it also dies if this harness is killed.
Reynard's own stdout/stderr go to this harness's stderr, prefixed "[reynard]".

Exit status: 0 = stopped on request / lifetime reached; 1 = Reynard failed to start or died;
2 = not ready within --start-timeout.

Usage:
    reynard_harness.py [--rr-port 0] [--http-port 0] [--ascii-port A] [--public]
                       [--start-timeout 30] [--max-lifetime 0] [--python PY]
"""

import argparse
import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from child_procs import die_with_parent  # noqa: E402

RR_NODENAME = "experimental.reynard_the_robot"
RR_SERVICE = "reynard"
RR_ROOT_TYPE = "experimental.reynard_the_robot.Reynard"

STOP_INT_S = 5.0   # after SIGINT
STOP_TERM_S = 3.0  # after SIGTERM
STOP_KILL_S = 3.0  # after SIGKILL
PROBE_TIMEOUT_MS = 3000

# "    rr+tcp://127.0.0.1:41234?nodeid=9176fabe-...&service=reynard"
URL_RE = re.compile(r"rr\+tcp://127\.0\.0\.1:(\d+)\?nodeid=([0-9a-fA-F-]{36})&service=" + RR_SERVICE)
READY_MARK = "Reynard the Robot started in headless mode"
# Start-up failures show up as a traceback (e.g. the web server thread cannot bind its port: Reynard's
# main thread then waits forever) or as an RR log line at error level.
FAILURE_RE = re.compile(r"^(Traceback \(most recent call last\)|Exception in thread)|\] \[error\] ")


def log(*args):
    print("[reynard_harness]", *args, file=sys.stderr, flush=True)


def listening_ports(pid):
    """TCP ports in LISTEN state on sockets owned by process `pid` (Linux /proc). {port: [addr hex]}"""
    inodes = set()
    fd_dir = "/proc/%d/fd" % pid
    try:
        for fd in os.listdir(fd_dir):
            try:
                target = os.readlink(os.path.join(fd_dir, fd))
            except OSError:
                continue
            if target.startswith("socket:["):
                inodes.add(target[8:-1])
    except OSError:
        return {}
    ports = {}
    for table in ("tcp", "tcp6"):
        try:
            with open("/proc/%d/net/%s" % (pid, table)) as fh:
                next(fh)
                for line in fh:
                    f = line.split()
                    if len(f) < 10 or f[3] != "0A" or f[9] not in inodes:  # 0A = TCP_LISTEN
                        continue
                    addr, port_hex = f[1].rsplit(":", 1)
                    ports.setdefault(int(port_hex, 16), []).append(addr)
        except OSError:
            continue
    return ports


class Reynard:
    """The child process and a thread that forwards (and scans) its output."""

    def __init__(self, cmd):
        self.lines = []
        self.cond = threading.Condition()
        self.eof = False
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     stdin=subprocess.DEVNULL, preexec_fn=die_with_parent,
                                     env=dict(os.environ, PYTHONUNBUFFERED="1"))
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        for raw in iter(self.proc.stdout.readline, b""):
            line = raw.decode("utf-8", "replace").rstrip("\n")
            print("[reynard]", line, file=sys.stderr, flush=True)
            with self.cond:
                self.lines.append(line)
                self.cond.notify_all()
        with self.cond:
            self.eof = True
            self.cond.notify_all()

    def failure_text(self):
        """The first failure line and the last output line, if Reynard reported a failure."""
        with self.cond:
            bad = [l for l in self.lines if FAILURE_RE.search(l)]
            return "%s ... %s" % (bad[0], self.lines[-1]) if bad else ""

    def wait_line(self, pred, deadline):
        """First output line satisfying pred, or None at EOF / deadline."""
        i = 0
        with self.cond:
            while True:
                while i < len(self.lines):
                    if pred(self.lines[i]):
                        return self.lines[i]
                    i += 1
                left = deadline - time.monotonic()
                if self.eof or left <= 0:
                    return None
                self.cond.wait(min(left, 0.5))

    def stop(self):
        """SIGINT, SIGTERM, SIGKILL - each only if still running, each with a time limit."""
        p = self.proc
        for sig, wait_s in ((signal.SIGINT, STOP_INT_S), (signal.SIGTERM, STOP_TERM_S),
                            (signal.SIGKILL, STOP_KILL_S)):
            if p.poll() is not None:
                break
            try:
                os.kill(p.pid, sig)
            except ProcessLookupError:
                break
            try:
                p.wait(wait_s)
            except subprocess.TimeoutExpired:
                log("reynard (pid %d) still running %.0f s after %s" % (p.pid, wait_s, signal.Signals(sig).name))
        self.reader.join(2.0)
        try:
            p.stdout.close()
        except OSError:
            pass
        return p.poll()


def probe_rr(url, deadline):
    """Connects with the official client on a private node, reads robot_position. Returns the root
    object type, or raises the last error at the deadline."""
    import RobotRaconteur as RR
    last = None
    while time.monotonic() < deadline:
        node = RR.RobotRaconteurNode()
        node.Init()
        try:
            t = RR.TcpTransport(node)
            node.RegisterTransport(t)
            node._SetRequestTimeout(PROBE_TIMEOUT_MS)  # the RequestTimeout property passes a float
            c = node.ConnectService(url)
            try:
                pos = c.robot_position
                if len(pos) != 2:
                    raise RuntimeError("robot_position has %d elements" % len(pos))
                return node.GetObjectType(c)
            finally:
                try:
                    node.DisconnectService(c)
                except Exception:
                    pass
        except Exception as e:  # not answering yet
            last = e
        finally:
            node.Shutdown()
        time.sleep(0.2)
    raise RuntimeError("RR service not answering at %s: %s" % (url, last))


def probe_http(http_url, deadline):
    last = None
    while time.monotonic() < deadline:
        try:
            with urllib.request.urlopen(http_url + "api/state", timeout=3) as r:
                state = json.loads(r.read())
                if "x" in state:
                    return
        except Exception as e:
            last = e
        time.sleep(0.2)
    raise RuntimeError("web UI not answering at %s: %s" % (http_url, last))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rr-port", type=int, default=0, help="Robot Raconteur TCP port (0 = ephemeral)")
    ap.add_argument("--http-port", type=int, default=0, help="web UI port (0 = ephemeral; never use 8080)")
    ap.add_argument("--ascii-port", type=int, default=None, help="enable the ASCII socket on this port (> 0)")
    ap.add_argument("--public", action="store_true", help="listen on all interfaces (default: localhost only)")
    ap.add_argument("--start-timeout", type=float, default=30.0, help="seconds until ready, else exit 2")
    ap.add_argument("--max-lifetime", type=float, default=0.0, help="stop after this many seconds (0 = never)")
    ap.add_argument("--python", default=sys.executable, help="Python with reynard-the-robot installed")
    args = ap.parse_args(argv)
    if args.ascii_port is not None and args.ascii_port <= 0:
        ap.error("--ascii-port needs a fixed port > 0 (an ephemeral one could not be told from the HTTP port)")

    stop_evt = threading.Event()
    ready = [False]

    def on_signal(signum, frame):
        stop_evt.set()
        if not ready[0]:  # still starting: abandon the start-up, the finally block stops Reynard
            raise KeyboardInterrupt("signal %d during start-up" % signum)

    signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGINT, on_signal)

    cmd = [args.python, "-u", "-m", "reynard_the_robot",
           "--robotraconteur-tcp-port=%d" % args.rr_port,
           "--robotraconteur-local-enable=false",
           "--robotraconteur-tcp-ipv4-discovery=false",
           "--robotraconteur-tcp-ipv6-discovery=false",
           "--http-port=%d" % args.http_port]
    if args.public:
        cmd += ["--http-public"]
    else:
        cmd += ["--robotraconteur-tcp-listen-localhost=true"]
    if args.ascii_port is None:
        cmd += ["--disable-ascii-socket"]
    else:
        cmd += ["--ascii-socket-port=%d" % args.ascii_port] + (["--ascii-socket-public"] if args.public else [])

    t0 = time.monotonic()
    deadline = t0 + args.start_timeout
    rey = None
    rc = 1
    try:
        log("starting:", " ".join(cmd))
        rey = Reynard(cmd)
        url_line = rey.wait_line(lambda l: URL_RE.search(l) is not None or FAILURE_RE.search(l), deadline)
        if url_line is None or not URL_RE.search(url_line):
            raise RuntimeError("no rr+tcp://127.0.0.1 candidate URL printed (status %s): %s"
                               % (rey.proc.poll(), rey.failure_text()))
        m = URL_RE.search(url_line)
        rr_port, nodeid = int(m.group(1)), m.group(2)
        if not rey.wait_line(lambda l: READY_MARK in l or FAILURE_RE.search(l), deadline) or rey.failure_text():
            raise RuntimeError("no %r line (status %s): %s" % (READY_MARK, rey.proc.poll(), rey.failure_text()))

        http_port = args.http_port
        if http_port == 0:
            ports = listening_ports(rey.proc.pid)
            others = sorted(p for p in ports if p != rr_port and p != args.ascii_port
                            and any(len(a) == 8 for a in ports[p]))  # IPv4 listeners only
            # the RR transport listens on IPv4 and IPv6 with separate ephemeral ports; the IPv6 one
            # is not in the IPv4 table, so what is left is the web server
            if len(others) != 1:
                raise RuntimeError("cannot tell the HTTP port from listening ports %s (RR %d)" % (ports, rr_port))
            http_port = others[0]
        url = "rr+tcp://127.0.0.1:%d/?service=%s" % (rr_port, RR_SERVICE)
        http_url = "http://127.0.0.1:%d/" % http_port

        probe_http(http_url, deadline)
        root_type = probe_rr(url, deadline)
        if rey.proc.poll() is not None:
            raise RuntimeError("reynard exited during the readiness probe (status %s)" % rey.proc.poll())

        ready[0] = True  # from here on a signal means "stop", not "abandon the start-up"
        print(json.dumps({
            "url": url, "port": rr_port, "service": RR_SERVICE, "nodeid": nodeid, "nodename": RR_NODENAME,
            "root_type": root_type, "http_url": http_url, "http_port": http_port,
            "ascii_port": args.ascii_port, "pid": rey.proc.pid, "harness_pid": os.getpid(),
            "startup_s": round(time.monotonic() - t0, 2),
        }), flush=True)

        end = t0 + args.max_lifetime if args.max_lifetime > 0 else None
        while not stop_evt.is_set():
            if rey.proc.poll() is not None:
                raise RuntimeError("reynard exited unexpectedly (status %s)" % rey.proc.returncode)
            if end is not None and time.monotonic() >= end:
                log("max lifetime %.0f s reached" % args.max_lifetime)
                break
            stop_evt.wait(0.2)
        rc = 0
    except RuntimeError as e:
        log("error:", e)
        rc = 2 if time.monotonic() >= deadline and rey is not None and rey.proc.poll() is None else 1
    except KeyboardInterrupt as e:
        log("stopped during start-up:", e)
        rc = 1
    except Exception as e:  # report and still stop the child
        log("error: %s: %s" % (type(e).__name__, e))
        rc = 1
    finally:
        if rey is not None:
            status = rey.stop()
            log("reynard (pid %d) stopped, status %s" % (rey.proc.pid, status))
    return rc


if __name__ == "__main__":
    sys.exit(main())
