#!/usr/bin/env python3
"""Live identity test: capture a real official<->official session and check our codec against it.

For each message-format mode (default: v4, v4st, v2):
  1. start official_service.py (ephemeral port),
  2. start recording_proxy.py in front of it,
  3. run official_client.py through the proxy (rr+tcp://127.0.0.1:PROXYPORT/?service=interop);
     the client must pass all its checks,
  4. stop proxy and service,
  5. sanity-check the capture (capture_summary.py): expected member entry types present, message
     versions as negotiated, string-table codes only when negotiated,
  6. run the checker executable (--checker, e.g. build/.../rr_capture_check) on the capture: it decodes
     and re-encodes every message and must reproduce the bytes exactly.

Modes:
  v4    stock setup: the service disables string tables (as ServerNodeSetup does), the client offers
        everything -> message format 4 without string tables.
  v4st  the service allows string tables -> message format 4 with standard and message-local codes.
  v2    both sides disable message 4 -> message format 2 only.

Exit status 0 only if every step of every mode passed. Everything has a time limit (whole run < 2
minutes); child processes are always terminated.

Usage: live_identity.py [--checker PATH] [--modes v4,v4st,v2] [--keep DIR] [--verbose]
"""

import argparse
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import capture_summary  # noqa: E402
from child_procs import StepFailed, die_with_parent, read_json_line, start, stop, tail  # noqa: E402

MODES = {
    "v4": {"service": [], "client": [], "version": 4, "string_table": False},
    # One connection only: the official library fails a second connection from the client's node to a
    # service that uses string tables (official_client.py --single-connection).
    "v4st": {"service": ["--enable-stringtable"], "client": ["--single-connection"], "version": 4, "string_table": True},
    "v2": {"service": ["--disable-message4"], "client": ["--disable-message4"], "version": 2,
           "string_table": False},
}

# Heartbeats every 0.5 s plus an idle pause make ConnectionTest 111/112 appear in every session.
HEARTBEAT_S = "0.5"
IDLE_S = "1.5"

# Entry types the client session must produce (wire.md §4). 1174 MemoryWriteRet is deliberately
# absent: CORE answers MemoryWrite (1173) with EntryType 1172 (MemoryReadRet), see README.md.
REQUIRED_ENTRY_TYPES = [
    1, 2, 103, 104, 109, 110, 111, 112, 121, 122, 1107, 1108, 1109,
    1111, 1112, 1113, 1114, 1121, 1122, 1123, 1124, 1131, 1141, 1142, 1143, 1144, 1145, 1146, 1147,
    1151, 1152, 1161, 1163, 1164, 1165, 1166, 1171, 1172, 1173, 1175, 1176,
    1181, 1182, 1183, 1184, 1185, 1186,
]
MIN_MESSAGES = 500  # a full client session is ~860 messages

SERVICE_START_S = 20
PROXY_START_S = 10
CLIENT_S = 60
CHECKER_S = 60
STOP_S = 10


def check_capture(summary, mode):
    """Sanity checks of one capture. Returns a list of problems."""
    problems = []
    m = MODES[mode]
    if summary["parse_errors"]:
        problems.append("unparseable messages: %s" % summary["parse_errors"][:3])
    if summary["raw_records"]:
        problems.append("%d raw (unframed) records" % summary["raw_records"])
    if summary["messages"] < MIN_MESSAGES:
        problems.append("only %d messages captured (expected at least %d)" % (summary["messages"], MIN_MESSAGES))
    et = {int(k): v for k, v in summary["entry_types"].items()}
    missing = [t for t in REQUIRED_ENTRY_TYPES if t not in et]
    if missing:
        problems.append("entry types missing: %s" % ", ".join(
            "%d %s" % (t, capture_summary.ENTRY_TYPE_NAMES.get(t, "?")) for t in missing))
    if et.get(1172, 0) != et.get(1171, 0) + et.get(1173, 0):
        problems.append("MemoryRead/Write replies do not add up: 1171=%d 1173=%d 1172=%d 1174=%d"
                        % (et.get(1171, 0), et.get(1173, 0), et.get(1172, 0), et.get(1174, 0)))
    versions = {int(k): v for k, v in summary["versions"].items()}
    connections = max(summary["connections"], 1)
    if m["version"] == 2:
        if set(versions) != {2}:
            problems.append("v2 session carried versions %s" % versions)
    else:
        # CreateConnection request and reply are always v2 (wire.md §2.1); everything else is v4
        if versions.get(2, 0) != 2 * connections:
            problems.append("v4 session: %d v2 messages (expected %d, the CreateConnection exchange)"
                            % (versions.get(2, 0), 2 * connections))
        if not versions.get(4):
            problems.append("v4 session carried no v4 message")
        if summary["v4_without_routing"] == 0:
            problems.append("no v4 message omitted routing info (expected after negotiation)")
    if m["string_table"] and summary["string_table_messages"] == 0:
        problems.append("string tables negotiated but no message used a code")
    if not m["string_table"] and summary["string_table_messages"]:
        problems.append("%d messages used string-table codes although not negotiated"
                        % summary["string_table_messages"])
    return problems


def run_mode(mode, args, workdir, python):
    m = MODES[mode]
    capture = os.path.join(workdir, "interop_%s.rrcap" % mode)
    result = {"mode": mode, "capture": capture, "ok": False}
    svc = proxy = None
    t0 = time.monotonic()
    try:
        svc = start([python, os.path.join(HERE, "official_service.py"), "--port", "0",
                     "--heartbeat", HEARTBEAT_S, "--max-lifetime", "160"] + m["service"],
                    os.path.join(workdir, "service_%s.stderr" % mode))
        ready = read_json_line(svc, SERVICE_START_S, "official_service.py")
        proxy = start([python, os.path.join(HERE, "recording_proxy.py"), "--target", "127.0.0.1:%d" % ready["port"],
                       "--capture", capture, "--max-lifetime", "160"],
                      os.path.join(workdir, "proxy_%s.stderr" % mode))
        pready = read_json_line(proxy, PROXY_START_S, "recording_proxy.py")
        url = "rr+tcp://127.0.0.1:%d/?service=interop" % pready["port"]
        client_err = os.path.join(workdir, "client_%s.stderr" % mode)
        with open(client_err, "wb") as errf:
            try:
                cp = subprocess.run([python, os.path.join(HERE, "official_client.py"), url, "--heartbeat", HEARTBEAT_S,
                                     "--idle", IDLE_S, "--timeout", str(CLIENT_S - 5)] + m["client"],
                                    stdout=subprocess.PIPE, stderr=errf, stdin=subprocess.DEVNULL,
                                    timeout=CLIENT_S, preexec_fn=die_with_parent)
            except subprocess.TimeoutExpired:
                raise StepFailed("official_client.py timed out after %d s\n%s" % (CLIENT_S, tail(client_err)))
        try:
            client = json.loads(cp.stdout.decode("utf-8", "replace").strip().splitlines()[-1])
        except (ValueError, IndexError):
            client = {"ok": False, "error": "no JSON summary: %r" % cp.stdout[-300:]}
        result["client"] = {k: client.get(k) for k in ("ok", "passed", "failed", "failures", "error")}
        if cp.returncode != 0 or not client.get("ok"):
            raise StepFailed("official_client.py failed (status %d): %s\n%s"
                             % (cp.returncode, json.dumps(result["client"])[:2000], tail(client_err)))
    except StepFailed as e:
        result["error"] = str(e)
        return result
    finally:
        result["proxy_status"] = stop(proxy, STOP_S)
        result["service_status"] = stop(svc, STOP_S)
        result["session_s"] = round(time.monotonic() - t0, 1)

    if result["service_status"] != 0:
        result["error"] = "official_service.py exited with status %s\n%s" % (
            result["service_status"], tail(os.path.join(workdir, "service_%s.stderr" % mode)))
        return result
    if result["proxy_status"] != 0:
        result["error"] = "recording_proxy.py exited with status %s\n%s" % (
            result["proxy_status"], tail(os.path.join(workdir, "proxy_%s.stderr" % mode)))
        return result

    try:
        summary = capture_summary.summarize(capture)
    except (OSError, ValueError) as e:
        result["error"] = "capture unreadable: %s" % e
        return result
    result["capture_summary"] = {k: summary[k] for k in ("messages", "connections", "versions",
                                                         "v4_without_routing", "string_table_messages")}
    result["entry_types"] = summary["entry_types"]
    problems = check_capture(summary, mode)
    if problems:
        result["error"] = "capture sanity: " + "; ".join(problems)
        return result

    if args.checker:
        try:
            ck = subprocess.run([args.checker, capture], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                stdin=subprocess.DEVNULL, timeout=CHECKER_S, preexec_fn=die_with_parent)
        except subprocess.TimeoutExpired:
            result["error"] = "checker timed out after %d s" % CHECKER_S
            return result
        except OSError as e:
            result["error"] = "checker could not run: %s" % e
            return result
        out = ck.stdout.decode("utf-8", "replace")
        result["checker_status"] = ck.returncode
        result["checker_output"] = out
        if ck.returncode != 0:
            result["error"] = "checker reported failures (status %d)" % ck.returncode
            return result
    result["ok"] = True
    return result


def checker_selftest(checker, capture, workdir):
    """Shows the checker can fail: two mutated copies of a v2 capture must be reported.

    1. the reserved uint16 of one v2 entry set to 1 (decodes fine, CORE writes 0, so the re-encoded
       bytes differ: a MISMATCH);
    2. the magic of one message broken (a DECODE ERROR).
    Returns a list of problems (empty = the checker caught both)."""
    records = list(capture_summary.read_records(capture))
    target = None
    for i, (kind, conn, data) in enumerate(records):
        if kind == "C" and data[8:10] == b"\x02\x00":
            header_size = struct.unpack_from("<H", data, 10)[0]
            if struct.unpack_from("<H", data, header_size + 4)[0] == 1111:
                target = (i, header_size)
                break
    if target is None:
        return ["self-test: no v2 PropertyGetReq in %s" % capture]
    problems = []
    for name, mutate, expect_text in [
        ("reserved", lambda b, h: b[:h + 6] + b"\x01\x00" + b[h + 8:], "MISMATCH"),
        ("magic", lambda b, h: b"XRAC" + b[4:], "DECODE ERROR"),
    ]:
        path = os.path.join(workdir, "selftest_%s.rrcap" % name)
        with open(path, "wb") as fh:
            fh.write(capture_summary.MAGIC)
            for i, (kind, conn, data) in enumerate(records):
                if i == target[0]:
                    data = mutate(data, target[1])
                fh.write(struct.pack("<BII", ord(kind), conn, len(data)) + data)
        try:
            ck = subprocess.run([checker, path, "--quiet"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                stdin=subprocess.DEVNULL, timeout=CHECKER_S, preexec_fn=die_with_parent)
        except subprocess.TimeoutExpired:
            problems.append("self-test %s: checker timed out" % name)
            continue
        out = ck.stdout.decode("utf-8", "replace")
        if ck.returncode != 1 or expect_text not in out:
            problems.append("self-test %s: checker status %d, expected 1 and %r in its output"
                            % (name, ck.returncode, expect_text))
    return problems


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--checker", help="capture checker executable (rr_capture_check); omitted = capture only")
    ap.add_argument("--modes", default="v4,v4st,v2", help="comma-separated: " + ",".join(MODES))
    ap.add_argument("--keep", help="write captures and logs to this directory and keep them")
    ap.add_argument("--verbose", action="store_true", help="print the checker's full output")
    ap.add_argument("--no-selftest", action="store_true", help="skip the checker self-test on mutated captures")
    ap.add_argument("--python", default=sys.executable, help="Python with the robotraconteur package")
    args = ap.parse_args(argv)
    modes = [x for x in args.modes.split(",") if x]
    for x in modes:
        if x not in MODES:
            ap.error("unknown mode %r" % x)
    if args.checker and not os.access(args.checker, os.X_OK):
        ap.error("checker %s is not executable" % args.checker)

    if args.keep:
        os.makedirs(args.keep, exist_ok=True)
        workdir = args.keep
    else:
        workdir = tempfile.mkdtemp(prefix="rr_live_identity_")
    t0 = time.monotonic()
    results = []
    try:
        for mode in modes:
            r = run_mode(mode, args, workdir, args.python)
            results.append(r)
            status = "ok" if r["ok"] else "FAILED"
            cs = r.get("capture_summary", {})
            print("== mode %-4s %s  (%.1f s, %s messages, versions %s, string-table messages %s)"
                  % (mode, status, r.get("session_s", 0), cs.get("messages"), cs.get("versions"),
                     cs.get("string_table_messages")), flush=True)
            if "checker_output" in r:
                out = r["checker_output"].rstrip()
                lines = out.splitlines()
                print("\n".join(lines if (args.verbose or not r["ok"]) else lines[-40:]), flush=True)
            if not r["ok"]:
                print("   error: %s" % r.get("error"), flush=True)
            if mode == "v2" and r["ok"] and args.checker and not args.no_selftest:
                problems = checker_selftest(args.checker, r["capture"], workdir)
                results.append({"mode": "checker-selftest", "ok": not problems, "error": "; ".join(problems)})
                print("== checker self-test %s%s" % ("ok" if not problems else "FAILED: ", "; ".join(problems)),
                      flush=True)
    finally:
        if not args.keep:
            shutil.rmtree(workdir, ignore_errors=True)

    ok = bool(results) and all(r["ok"] for r in results)
    print(json.dumps({
        "ok": ok,
        "seconds": round(time.monotonic() - t0, 1),
        "checker": args.checker,
        "modes": {r["mode"]: {"ok": r["ok"], "error": r.get("error", "").split("\n")[0] or None,
                              "client_checks_passed": (r.get("client") or {}).get("passed"),
                              "capture": r.get("capture_summary"),
                              "checker_status": r.get("checker_status")} for r in results},
        "captures_kept_in": args.keep,
    }), flush=True)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
