#!/usr/bin/env python3
"""Reynard the Robot as a real device: harness + official client, N instances side by side.

For each instance i = 1..N (concurrently):
  1. start reynard_harness.py (ephemeral RR and HTTP ports) and read its JSON ready line,
  2. for instance 1 with --capture: start recording_proxy.py in front of Reynard's RR port,
  3. run reynard_official_client.py against the URL (through the proxy if any) with --http-url;
     it must pass every check,
  4. stop proxy and harness (SIGTERM); the harness must exit 0 and Reynard's PID must be gone.
With --capture, instance 1's capture must parse (capture_summary.py) and contain the entry types
listed in REQUIRED_ENTRY_TYPES; the summary reports what it holds. With --checker (rr_capture_check,
implies --capture) our codec must decode and re-encode every captured message byte-identically.

N >= 2 shows that instances do not collide (ports, node name, local transport).

Exit status 0 only if every step of every instance passed. Everything has a time limit; children are
started with PR_SET_PDEATHSIG and stopped by PID in `finally`.

Usage: reynard_interop.py [--instances 2] [--capture] [--checker PATH] [--keep DIR] [--python PY]
"""

import argparse
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import capture_summary  # noqa: E402
from child_procs import StepFailed, die_with_parent, read_json_line, start, stop, tail  # noqa: E402

HARNESS_START_S = 40
PROXY_START_S = 10
CLIENT_S = 60
CHECKER_S = 30
STOP_S = 15

# What one client session against Reynard must put on the wire (wire.md §4): CreateConnection
# (StreamOp), ConnectClientCombined (which also carries the service definition: no GetServiceDesc),
# property get/set, function calls, the state wire (connect, packets, PeekInValue, disconnect), the
# new_message event, DisconnectClient.
REQUIRED_ENTRY_TYPES = [1, 2, 109, 110, 121, 122, 1111, 1112, 1113, 1114, 1121, 1122,
                        1131, 1161, 1163, 1164, 1165, 1166, 1181, 1182]




def pid_alive(pid):
    try:
        with open("/proc/%d/stat" % pid) as fh:
            return fh.read().split(")")[-1].split()[0] != "Z"
    except OSError:
        return False


def run_instance(i, args, workdir, result):
    python = args.python
    result.update({"instance": i, "ok": False})
    harness = proxy = None
    herr = os.path.join(workdir, "harness_%d.stderr" % i)
    t0 = time.monotonic()
    ready = None
    try:
        harness = start([python, os.path.join(HERE, "reynard_harness.py"), "--max-lifetime", "110"], herr)
        ready = read_json_line(harness, HARNESS_START_S, "reynard_harness.py")
        result["harness"] = ready
        url = ready["url"]
        capture = None
        if args.capture and i == 1:
            capture = os.path.join(workdir, "reynard.rrcap")
            proxy = start([python, os.path.join(HERE, "recording_proxy.py"), "--target", "127.0.0.1:%d" % ready["port"],
                           "--capture", capture, "--max-lifetime", "100"], os.path.join(workdir, "proxy.stderr"))
            pready = read_json_line(proxy, PROXY_START_S, "recording_proxy.py")
            url = "rr+tcp://127.0.0.1:%d/?service=reynard" % pready["port"]
            result["capture"] = capture
        cerr = os.path.join(workdir, "client_%d.stderr" % i)
        with open(cerr, "wb") as errf:
            try:
                cp = subprocess.run([python, os.path.join(HERE, "reynard_official_client.py"), url,
                                     "--http-url", ready["http_url"], "--timeout", str(CLIENT_S - 5), "--verbose"],
                                    stdout=subprocess.PIPE, stderr=errf, stdin=subprocess.DEVNULL,
                                    timeout=CLIENT_S, preexec_fn=die_with_parent)
            except subprocess.TimeoutExpired:
                raise StepFailed("reynard_official_client.py timed out after %d s\n%s" % (CLIENT_S, tail(cerr)))
        try:
            client = json.loads(cp.stdout.decode("utf-8", "replace").strip().splitlines()[-1])
        except (ValueError, IndexError):
            client = {"ok": False, "error": "no JSON summary: %r" % cp.stdout[-300:]}
        result["client"] = client
        if cp.returncode != 0 or not client.get("ok"):
            raise StepFailed("reynard_official_client.py failed (status %d)\n%s" % (cp.returncode, tail(cerr)))
    except StepFailed as e:
        result["error"] = str(e)
    finally:
        result["proxy_status"] = stop(proxy, STOP_S)
        result["harness_status"] = stop(harness, STOP_S)
        result["session_s"] = round(time.monotonic() - t0, 1)
        if ready and pid_alive(ready["pid"]):
            result.setdefault("error", "reynard pid %d still running after its harness stopped" % ready["pid"])
            try:
                os.kill(ready["pid"], signal.SIGKILL)
            except OSError:
                pass
    if "error" in result:
        result["error"] += "\n--- harness stderr ---\n" + tail(herr)
        return
    if result["harness_status"] != 0:
        result["error"] = "reynard_harness.py exited with status %s\n%s" % (result["harness_status"], tail(herr))
        return
    if result.get("capture"):
        if result["proxy_status"] != 0:
            result["error"] = "recording_proxy.py exited with status %s" % result["proxy_status"]
            return
        try:
            s = capture_summary.summarize(result["capture"])
        except (OSError, ValueError) as e:
            result["error"] = "capture unreadable: %s" % e
            return
        result["capture_summary"] = {k: s[k] for k in ("messages", "connections", "versions", "v4_without_routing",
                                                       "string_table_messages", "entry_types")}
        et = {int(k) for k in s["entry_types"]}
        missing = [t for t in REQUIRED_ENTRY_TYPES if t not in et]
        if s["parse_errors"] or s["raw_records"] or missing:
            result["error"] = "capture: parse errors %s, raw records %d, entry types missing %s" % (
                s["parse_errors"][:3], s["raw_records"],
                ["%d %s" % (t, capture_summary.ENTRY_TYPE_NAMES.get(t, "?")) for t in missing])
            return
        if args.checker:
            try:
                ck = subprocess.run([args.checker, result["capture"], "--quiet"], stdout=subprocess.PIPE,
                                    stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, timeout=CHECKER_S,
                                    preexec_fn=die_with_parent)
            except (subprocess.TimeoutExpired, OSError) as e:
                result["error"] = "checker could not run: %s" % e
                return
            out = ck.stdout.decode("utf-8", "replace").strip()
            result["checker_status"] = ck.returncode
            result["checker_output"] = out.splitlines()[-1] if out else ""
            if ck.returncode != 0:
                result["error"] = "checker reported failures (status %d):\n%s" % (ck.returncode, out[-3000:])
                return
    result["ok"] = True


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--instances", type=int, default=2, help="Reynard instances side by side (each with a client)")
    ap.add_argument("--capture", action="store_true", help="record instance 1's session through recording_proxy.py")
    ap.add_argument("--checker", help="capture checker executable (rr_capture_check); implies --capture")
    ap.add_argument("--keep", help="write logs (and the capture) to this directory and keep them")
    ap.add_argument("--python", default=sys.executable, help="Python with robotraconteur and reynard-the-robot")
    args = ap.parse_args(argv)
    if args.instances < 1:
        ap.error("--instances must be >= 1")
    if args.checker:
        if not os.access(args.checker, os.X_OK):
            ap.error("checker %s is not executable" % args.checker)
        args.capture = True

    # SIGTERM (e.g. from ctest's timeout) -> normal exit, so the finally blocks stop every child
    signal.signal(signal.SIGTERM, lambda *a: sys.exit(3))

    if args.keep:
        os.makedirs(args.keep, exist_ok=True)
        workdir = args.keep
    else:
        workdir = tempfile.mkdtemp(prefix="rr_reynard_")
    t0 = time.monotonic()
    results = [{} for _ in range(args.instances)]
    try:
        threads = [threading.Thread(target=run_instance, args=(i + 1, args, workdir, results[i]), daemon=True)
                   for i in range(args.instances)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        ok = all(r.get("ok") for r in results)
        print(json.dumps({"ok": ok, "instances": results, "total_s": round(time.monotonic() - t0, 1),
                          "workdir": workdir if args.keep else None}, indent=1), flush=True)
        for r in results:
            if not r.get("ok"):
                print("instance %s FAILED: %s" % (r.get("instance"), r.get("error")), file=sys.stderr, flush=True)
        return 0 if ok else 1
    finally:
        if not args.keep:
            shutil.rmtree(workdir, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
