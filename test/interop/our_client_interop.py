#!/usr/bin/env python3
"""Our C++ client (rr_interop_client) against the official implementation.

--target official   start official_service.py (with --disable-message4 when asked), run
                    `rr_interop_client URL [--disable-message4]`; it must pass every check.
--target reynard    start reynard_harness.py, connect a socket.io client to Reynard's web UI (what
                    reynard_official_client.py does to trigger `new_message`), run
                    `rr_interop_client --reynard URL --chat`; whenever the client prints
                    `CHAT <json string>`, send that text as a web-UI chat message.

Prints the client's JSON summary (plus what this script saw) on stdout; exit status 0 only if the
client passed every check and the service/harness stopped cleanly. Everything has a time limit;
children are started with PR_SET_PDEATHSIG and stopped by PID in `finally`.

Usage: our_client_interop.py --client PATH [--target official|reynard] [--disable-message4]
                             [--keep DIR] [--verbose]
"""

import argparse
import atexit
import json
import os
import selectors
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from child_procs import StepFailed, die_with_parent, read_json_line, start, stop, tail  # noqa: E402

SERVICE_START_S = 40
CLIENT_S = 150


def run_client(cmd, stderr_path, on_line, timeout):
    """Runs the client, handing each stdout line to on_line; returns (exit status, last JSON line)."""
    with open(stderr_path, "wb") as errf:
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=errf, stdin=subprocess.DEVNULL,
                                preexec_fn=die_with_parent)
    sel = selectors.DefaultSelector()
    sel.register(proc.stdout, selectors.EVENT_READ)
    buf = b""
    last = None
    deadline = time.monotonic() + timeout
    try:
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                raise StepFailed("client did not finish within %.0f s" % timeout)
            if not sel.select(min(left, 1.0)):
                continue
            chunk = os.read(proc.stdout.fileno(), 65536)
            if not chunk:
                break
            buf += chunk
            while b"\n" in buf:
                line, buf = buf.split(b"\n", 1)
                text = line.decode("utf-8", "replace").strip()
                if not text:
                    continue
                if text.startswith("CHAT "):
                    on_line(json.loads(text[5:]))
                else:
                    last = text
        status = proc.wait(30)
    finally:
        sel.close()
        if proc.poll() is None:
            proc.kill()
            proc.wait(5)
        proc.stdout.close()
    return status, last


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--client", required=True, help="path of rr_interop_client")
    ap.add_argument("--target", choices=["official", "reynard"], default="official")
    ap.add_argument("--disable-message4", action="store_true")
    ap.add_argument("--keep", default=None, help="keep stderr logs in this directory")
    ap.add_argument("--verbose", action="store_true")
    ap.add_argument("--python", default=sys.executable)
    args = ap.parse_args(argv)

    workdir = args.keep or tempfile.mkdtemp(prefix="our_client_")
    os.makedirs(workdir, exist_ok=True)
    if not args.keep:
        atexit.register(shutil.rmtree, workdir, True)
    result = {"ok": False, "target": args.target, "message4": not args.disable_message4}
    service = None
    sio = None
    rc = 1
    try:
        if args.target == "official":
            cmd = [args.python, "-u", os.path.join(HERE, "official_service.py"), "--port", "0", "--max-lifetime", "300"]
            if args.disable_message4:
                cmd.append("--disable-message4")
            service = start(cmd, os.path.join(workdir, "service.stderr"))
            ready = read_json_line(service, SERVICE_START_S, "official_service.py")
            client_cmd = [args.client, ready["url"], "--timeout", str(CLIENT_S - 10)]
            if args.disable_message4:
                client_cmd.append("--disable-message4")
        else:
            cmd = [args.python, "-u", os.path.join(HERE, "reynard_harness.py"), "--max-lifetime", "300"]
            service = start(cmd, os.path.join(workdir, "harness.stderr"))
            ready = read_json_line(service, SERVICE_START_S, "reynard_harness.py")
            import socketio  # python-socketio, a dependency of reynard-the-robot

            sio = socketio.Client()
            # polling transport: websocket-client is not installed in the venv
            sio.connect(ready["http_url"].rstrip("/"), transports=["polling"], wait_timeout=10)
            client_cmd = [args.client, "--reynard", ready["url"], "--chat", "--timeout", str(CLIENT_S - 10)]
        if args.verbose:
            client_cmd.append("--verbose")
        result["url"] = ready["url"]
        chats = []

        def on_chat(text):
            chats.append(text)
            sio.emit("new_message", text)

        status, last = run_client(client_cmd, os.path.join(workdir, "client.stderr"), on_chat, CLIENT_S)
        result["client_status"] = status
        result["chats_sent"] = len(chats)
        try:
            result["client"] = json.loads(last) if last else None
        except ValueError:
            result["client"] = last
        if status != 0:
            raise StepFailed("rr_interop_client exited with %s; stderr:\n%s" % (status, tail(os.path.join(workdir, "client.stderr"), 40)))
        if args.target == "reynard" and not chats:
            raise StepFailed("the client never asked for a chat message")
        result["ok"] = True
        rc = 0
    except StepFailed as e:
        result["error"] = str(e)
        print("[our_client_interop] FAIL: %s" % e, file=sys.stderr, flush=True)
    finally:
        if sio is not None:
            try:
                sio.eio.disconnect(abort=True)  # a graceful disconnect waits for the long poll
            except Exception:
                pass
        status = stop(service, 15)
        result["service_status"] = status
        if service is not None and status not in (0, None):
            print("[our_client_interop] service/harness exited with %s:\n%s" % (
                status, tail(os.path.join(workdir, "service.stderr" if args.target == "official" else "harness.stderr"))),
                file=sys.stderr, flush=True)
    print(json.dumps(result), flush=True)
    return rc


if __name__ == "__main__":
    sys.exit(main())
