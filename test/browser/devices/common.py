"""Shared by the devices the dashboard's standard-type browser tests start (test/browser/std_*.test.mjs):
each runs as a child of the test, prints one JSON ready line on stdout and runs until SIGTERM/SIGINT or
its --max-lifetime. None of them uses the local transport or discovery (no files in /run, no UDP)."""

import ctypes
import json
import signal
import socket
import sys
import threading
import time


def die_with_parent():
    """This process gets SIGTERM when the test that started it dies (Linux PR_SET_PDEATHSIG)."""
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGTERM)
    except OSError:
        pass


# The official library refuses to listen on 48653 ("reserved for Robot Raconteur port sharer"), which is
# in Linux's ephemeral range: a flaky.sh run drew it once and the device exited at start.
RR_PORT_SHARER_PORT = 48653


def free_port():
    """A TCP port free on 127.0.0.1 now (the RR node's options take a port, not a socket), never the
    port sharer's 48653."""
    while True:
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        if port != RR_PORT_SHARER_PORT:
            return port


def node_flags(port):
    """The official library's --robotraconteur-* options for a test node: TCP on 127.0.0.1:port only."""
    return [
        f"--robotraconteur-tcp-port={port}",
        "--robotraconteur-tcp-listen-localhost=true",
        "--robotraconteur-local-enable=false",
        "--robotraconteur-tcp-ipv4-discovery=false",
        "--robotraconteur-tcp-ipv6-discovery=false",
    ]


def ready(**info):
    """The ready line: one JSON object on stdout."""
    print(json.dumps(info), flush=True)


def log(name, *args):
    print(f"[{name}]", *args, file=sys.stderr, flush=True)


def wait_for_stop(max_lifetime):
    """Blocks until SIGTERM or SIGINT, or max_lifetime seconds (0: no limit)."""
    stop = threading.Event()
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda *_: stop.set())
    end = time.monotonic() + max_lifetime if max_lifetime > 0 else None
    while not stop.wait(0.5):
        if end is not None and time.monotonic() >= end:
            break
