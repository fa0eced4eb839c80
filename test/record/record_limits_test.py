#!/usr/bin/env python3
"""Recordings stay in their place, and recording and replay memory is bounded (issue 52; docs/recording.md
"Where recordings go" and "Limits"), against rr-gateway with its demo devices:

  place    with no logins (as ./scripts/run.sh runs it): the issue's request (`directory` /tmp-like,
           `prefix` "victim.txt\\u0000") is refused with 400 and the victim file keeps its contents; an
           absolute and a `..` directory get 400; a folder link planted in the root gets 507 naming it
           and nothing is written behind it; file links planted where this second's files would go are
           not opened (the file gets another name, the victim is untouched); queue_bytes 10^12 gets 400.
  burst    50 recordings of one prefix requested at once: at most recordings.max_active (8) are
           accepted, the rest get 429; every file is read whole by the reference reader (PyPI mcap) and
           no two recordings share a file.
  rights   with logins (bearer tokens): a user with `write` but not `record` gets 403 starting or
           stopping and sees the list without files, directory or prefix; a user with `record` starts
           one (201) and sees its files; recordings.keep_ended bounds the ended statuses listed; a start
           that would pass recordings.max_total_bytes gets 507.
  replay   crafted MCAP files (crafted_mcap.py): 16 Chunk Index records naming one 500 MiB chunk and a
           chunk over the memory limit make `rr-gateway --replay` exit with a clear error at once; an
           index understating its chunk makes the replayed device fail with the reason, logged; the
           gateway's peak memory stays far below the 500 MiB the chunk holds.

  record_limits_test.py --gateway build/debug/server/app/rr-gateway
Prints a JSON summary; exit 0, 1 (a check failed) or 77 (the venv's packages are missing).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "interop"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from child_procs import die_with_parent, stop  # noqa: E402
from record_checks import CheckFailed, expect, report_and_clean, wait_for  # noqa: E402
from record_replay_test import start_gateway  # noqa: E402

try:
    from mcap.reader import make_reader
    import crafted_mcap
except ImportError as e:  # pragma: no cover
    print("SKIP: %s (run ./scripts/setup.sh)" % e)
    sys.exit(77)

MiB = 1024 * 1024


def http(base, method, path, body=None, token=None, timeout=60):
    data = None if body is None else json.dumps(body).encode()
    headers = {"Content-Type": "application/json"}
    if token:
        headers["Authorization"] = "Bearer " + token
    req = urllib.request.Request(base + path, data=data, method=method, headers=headers)
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            return r.status, json.loads(r.read() or b"null")
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read() or b"null")


def wait_connected(base, device, token=None, seconds=60):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        status, devices = http(base, "GET", "/api/devices", token=token)
        if status == 200 and any(d["name"] == device and d["state"] == "connected" for d in devices or []):
            return
        time.sleep(0.2)
    raise CheckFailed("device %s not connected" % device)


def read_whole(path):
    """Every message of a file, read by the reference reader; raises on a file it cannot read."""
    with open(path, "rb") as f:
        return sum(1 for _ in make_reader(f).iter_messages())


def error_of(body):
    return ((body or {}).get("error") or {}).get("message", "")


def place_phase(exe, work, checks):
    root, outside = os.path.join(work, "root"), os.path.join(work, "outside")
    os.makedirs(outside)
    victim = os.path.join(outside, "victim.txt")
    with open(victim, "w") as f:
        f.write("precious")
    proc, _, base = start_gateway(exe, ["--recordings-root", root], os.path.join(work, "place.log"))
    try:
        wait_connected(base, "create")
        got = {}
        issue = {"device": "create", "directory": outside, "prefix": "victim.txt\u0000", "encoding": "robotraconteur",
                 "compression": "none", "duration_s": 2}
        for name, body, want in (
                ("issue request", issue, "is an absolute path"),
                ("NUL prefix", {"device": "create", "prefix": "victim.txt\u0000", "duration_s": 2}, "\\u0000"),
                ("absolute directory", {"device": "create", "directory": "/tmp"}, "is an absolute path"),
                ("up directory", {"device": "create", "directory": "../outside"}, "starting with a dot"),
                ("queue_bytes", {"device": "create", "queue_bytes": 10 ** 12}, "recordings.max_queue_bytes")):
            status, reply = http(base, "POST", "/api/recordings", body)
            got[name] = status
            expect(status == 400 and want in error_of(reply), "%s: %s %s" % (name, status, reply))
        checks["refused_400"] = got
        # A folder link planted in the root: not followed.
        os.makedirs(root, exist_ok=True)
        os.symlink(outside, os.path.join(root, "lab"))
        status, reply = http(base, "POST", "/api/recordings", {"device": "create", "directory": "lab/run", "duration_s": 2})
        expect(status == 507 and "is a symbolic link" in error_of(reply), "folder link: %s %s" % (status, reply))
        # File links where the next half minute's first files go: the file gets another name.
        os.makedirs(os.path.join(root, "cams"))
        now = int(time.time())
        for s in range(30):  # a busy machine may start the recording seconds later
            stamp = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime(now + s))
            os.symlink(victim, os.path.join(root, "cams", "cam-%s-001.mcap" % stamp))
        status, rec = http(base, "POST", "/api/recordings",
                           {"device": "create", "directory": "cams", "prefix": "cam", "members": ["packets"]})
        expect(status == 201, "recording beside planted links: %s %s" % (status, rec))
        time.sleep(0.5)
        status, done = http(base, "POST", "/api/recordings/%d/stop" % rec["id"])
        expect(status == 200 and len(done["files"]) == 1, "stopped: %s %s" % (status, done))
        path = done["files"][0]
        expect(path.endswith("-001-2.mcap") and not os.path.islink(path), "the file is a new one: %s" % path)
        read_whole(path)
        with open(victim) as f:
            expect(f.read() == "precious", "the victim file keeps its contents")
        expect(sorted(os.listdir(outside)) == ["victim.txt"], "nothing written outside the root: %s" % os.listdir(outside))
        checks["links"] = {"folder": 507, "file": os.path.basename(path)}
    finally:
        stop(proc)


def burst_phase(exe, work, checks):
    root = os.path.join(work, "burst")
    proc, _, base = start_gateway(exe, ["--recordings-root", root], os.path.join(work, "burst.log"))
    try:
        wait_connected(base, "create")
        replies, lock = [], threading.Lock()
        gate = threading.Barrier(50)

        def one():
            gate.wait()
            r = http(base, "POST", "/api/recordings", {"device": "create", "prefix": "same", "members": ["packets"]})
            with lock:
                replies.append(r)
        threads = [threading.Thread(target=one) for _ in range(50)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        accepted = [r for s, r in replies if s == 201]
        refused = [r for s, r in replies if s == 429]
        expect(len(accepted) + len(refused) == 50, "every answer 201 or 429: %s" % sorted(s for s, _ in replies))
        expect(0 < len(accepted) <= 8, "at most recordings.max_active (8) accepted: %d" % len(accepted))
        expect(all("recordings.max_active" in error_of(r) for r in refused), "429 names the limit")
        # Each accepted recording has written messages before it is stopped (waited for, not slept: on a
        # busy machine a recording's subscription can take seconds to open).
        ids = {r["id"] for r in accepted}

        def all_wrote():
            status, listing = http(base, "GET", "/api/recordings")
            got = {x["id"]: x.get("messages", 0) for x in listing.get("recordings", [])} if status == 200 else {}
            return all(got.get(i, 0) > 0 for i in ids)
        wait_for("every accepted recording wrote messages", all_wrote, timeout=60, interval=0.3)
        files = []
        for r in accepted:
            status, done = http(base, "POST", "/api/recordings/%d/stop" % r["id"])
            expect(status == 200 and done["state"] == "stopped" and len(done["files"]) == 1, "stop %s: %s" % (r["id"], done))
            files.append(done["files"][0])
        expect(len(set(files)) == len(files), "no two recordings share a file: %s" % files)
        counts = [read_whole(f) for f in files]
        expect(all(c > 0 for c in counts), "every file read whole with its messages: %s" % counts)
        checks["burst"] = {"accepted": len(accepted), "refused_429": len(refused), "messages": counts}
    finally:
        stop(proc)


def rights_phase(exe, work, checks):
    root = os.path.join(work, "rights")
    os.makedirs(root)
    tokens = os.path.join(work, "tokens.txt")
    with open(tokens, "w") as f:
        f.write("writer-token-0123456789abcdef writer operator\nrecorder-token-0123456789abcdef rec recorder\n")
    config = os.path.join(work, "rights.yaml")
    with open(config, "w") as f:
        f.write("gateway:\n  auth:\n    tokens: %s\n    roles:\n"
                "      operator:\n        - allow: [read, write, call]\n"
                "      recorder:\n        - allow: [read, record]\n"
                "recordings:\n  root: %s\n  keep_ended: 2\n  max_total_bytes: 3145728\n" % (tokens, root))
    writer, recorder = "writer-token-0123456789abcdef", "recorder-token-0123456789abcdef"
    proc, _, base = start_gateway(exe, ["--config", config], os.path.join(work, "rights.log"))
    try:
        wait_connected(base, "create", token=recorder)
        status, reply = http(base, "POST", "/api/recordings", {"device": "create", "members": ["packets"]}, token=writer)
        expect(status == 403 and "may not record" in error_of(reply), "write without record: %s %s" % (status, reply))
        ids = []
        for _ in range(3):
            status, rec = http(base, "POST", "/api/recordings", {"device": "create", "members": ["packets"], "directory": "r"},
                               token=recorder)
            expect(status == 201 and rec["files"], "record right: %s %s" % (status, rec))
            ids.append(rec["id"])
            status, _ = http(base, "POST", "/api/recordings/%d/stop" % rec["id"], token=writer)
            expect(status == 403, "stopping needs record too: %s" % status)
            status, done = http(base, "POST", "/api/recordings/%d/stop" % rec["id"], token=recorder)
            expect(status == 200, "stop: %s %s" % (status, done))
        # keep_ended: 2 (the ended listener runs just after the stop answer: wait for the list, bounded)
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline:
            status, listed = http(base, "GET", "/api/recordings", token=recorder)
            if [r["id"] for r in listed["recordings"]] == ids[1:]:
                break
            time.sleep(0.1)
        expect([r["id"] for r in listed["recordings"]] == ids[1:], "the last 2 ended kept: %s" % listed)
        expect(all(r["files"] for r in listed["recordings"]), "a user with record sees the files")
        status, seen = http(base, "GET", "/api/recordings", token=writer)
        expect(status == 200 and len(seen["recordings"]) == 2, "a user without record lists: %s %s" % (status, seen))
        for r in seen["recordings"]:
            expect("files" not in r and "directory" not in r["spec"] and "prefix" not in r["spec"], "no paths: %s" % r)
        status, one = http(base, "GET", "/api/recordings/%d" % ids[-1], token=writer)
        expect(status == 200 and "files" not in one, "GET one without paths: %s" % one)
        # The root's budget: 3 MiB, of which a file of 2.5 MiB is used.
        with open(os.path.join(root, "old.mcap"), "wb") as f:
            f.write(b"x" * (5 * MiB // 2))
        status, reply = http(base, "POST", "/api/recordings", {"device": "create", "members": ["packets"]}, token=recorder)
        expect(status == 507 and "recordings.max_total_bytes" in error_of(reply), "over the root's budget: %s %s" % (status, reply))
        checks["rights"] = {"writer": 403, "recorder": 201, "listed": len(seen["recordings"]), "budget": status}
    finally:
        stop(proc)


def vm_hwm(pid):
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) * 1024
    return None


def replay_phase(exe, work, checks):
    files = {name: os.path.join(work, "crafted_%s.mcap" % name) for name in crafted_mcap.FILES}
    for name, path in files.items():
        with open(path, "wb") as f:
            f.write(crafted_mcap.FILES[name]())
    got = {}
    for name, want in (("duplicate_chunk_index", "a second index of the chunk"),
                       ("huge_chunk", "can never be read within the reader's memory limit"),
                       ("announced_chunk", "uncompressed_size says 209715200")):
        cmd = [exe, "--listen", "127.0.0.1", "--port", "0", "--no-local", "--no-discovery", "--no-demo", "--replay", files[name]]
        # Popen's own wait would reap it: run it with os.wait4 to read its rusage.
        with open(os.path.join(work, name + ".log"), "wb") as errf:
            p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=errf, stdin=subprocess.DEVNULL, preexec_fn=die_with_parent)
        timer = threading.Timer(120, p.kill)
        timer.start()
        _, status, usage = os.wait4(p.pid, 0)
        timer.cancel()
        p.returncode = os.waitstatus_to_exitcode(status)
        with open(os.path.join(work, name + ".log"), errors="replace") as f:
            err = f.read()
        peak = usage.ru_maxrss * 1024
        expect(p.returncode not in (0, -9) and want in err, "%s: exit %s, %s" % (name, p.returncode, err[-800:]))
        expect(peak < 400 * MiB, "%s: peak RSS %d MiB (the chunk holds 500 MiB)" % (name, peak // MiB))
        got[name] = {"exit": p.returncode, "peak_rss_mib": peak // MiB}
    # An index understating its chunk: the replay starts, then fails reading it, logged; memory bounded.
    config = os.path.join(work, "lying.yaml")
    with open(config, "w") as f:
        f.write("devices:\n  - name: crafted\n    replay: %s\nrecordings:\n  replay_memory_bytes: 67108864\n" % files["lying_chunk_index"])
    log = os.path.join(work, "lying.log")
    proc, _, base = start_gateway(exe, ["--no-demo", "--config", config], log)
    try:
        deadline = time.monotonic() + 60
        st = None
        while time.monotonic() < deadline:
            status, st = http(base, "GET", "/api/replays/crafted")
            if status == 200 and st.get("state") == "failed":
                break
            time.sleep(0.2)
        expect(st and st.get("state") == "failed" and "would take the reader over its memory limit of 67108864" in st.get("error", ""),
               "the understated chunk fails the replay: %s" % st)
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and "replay of crafted failed" not in open(log, errors="replace").read():
            time.sleep(0.1)
        expect("replay of crafted failed" in open(log, errors="replace").read(), "the failure is logged")
        peak = vm_hwm(proc.pid)
        expect(peak is not None and peak < 400 * MiB, "peak RSS %s MiB" % (peak and peak // MiB))
        status, _ = http(base, "GET", "/api/devices")
        expect(status == 200, "the gateway goes on serving")
        got["lying_chunk_index"] = {"state": st["state"], "peak_rss_mib": peak // MiB}
    finally:
        stop(proc)
    checks["crafted_replays"] = got


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--keep", action="store_true")
    a = ap.parse_args()
    work = tempfile.mkdtemp(prefix="rr-record-limits-")
    checks = {}
    try:
        replay_phase(a.gateway, work, checks)  # first: this process's children's peak memory is fresh
        place_phase(a.gateway, work, checks)
        burst_phase(a.gateway, work, checks)
        rights_phase(a.gateway, work, checks)
    except CheckFailed as e:
        checks["failed"] = str(e)
        report_and_clean(checks, work, True)
        return 1
    report_and_clean(checks, work, a.keep)
    return 0


if __name__ == "__main__":
    sys.exit(main())
