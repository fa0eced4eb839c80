#!/usr/bin/env python3
"""`rr record` and `rr replay` (docs/recording.md "From the command line") against rr_interop_service,
with the official Robot Raconteur Python client and the reference MCAP reader (PyPI `mcap`):

  record   an official client connects to the service's w_state wire (a tick every 200 ms) and keeps
           every value it receives; `rr record URL --members w_state,p_stream,ev_values` says
           "rr: recording" once its wire, pipe and event are connected; then the client asks for 5 pipe
           packets and 3 events, and once the file on disk holds them (and 10 w_state values) SIGINT
           ends rr record (status 0, a complete file); the reference reader lists the channels (json
           and robotraconteur per member), schemas and counts, every json message is valid against its
           JSON Schema, and the recorded w_state values are in order and equal to those the official
           client received live (same id, label and values); one it did not get must have been
           superseded there by a newer one (a wire keeps the newest), and most must have reached it.
  duration `rr record --duration 1.5 --encoding json` ends by itself with status 0, a complete file
           of json channels only, and a status whose duration is at least 1.5 s.
  replay   `rr replay FILE --port 0 --loop` prints its URL; an official client connected to it receives
           w_state values that are recorded ones and the 5 recorded pipe packets; SIGINT ends it (status 0,
           a final status line with played > 0).
  errors   a member the object lacks (status 2), an unreachable service (status 3), an unwritable
           directory and a file that is not MCAP (status 1, messages naming the member / path).
  login    (with --gateway) the service behind rr-gateway with logins on (gateway.auth, a bearer token):
           `rr record` through the gateway is refused without a login and with a wrong token (status 3,
           the gateway's reason), and records with `--username rec@token --token T`.

Exit 0 when every check passed, 1 when one failed, 77 (SKIP) without the venv's packages.
"""

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "interop"))
from child_procs import StepFailed, die_with_parent, read_json_line, stop  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "record"))
from record_checks import CheckFailed, expect, recorded_so_far, report_and_clean, wait_for  # noqa: E402

try:
    import jsonschema
    from mcap.reader import make_reader
    import RobotRaconteur as RR
except ImportError as e:  # pragma: no cover
    print("SKIP: %s (run ./scripts/setup.sh)" % e)
    sys.exit(77)

RRN = RR.RobotRaconteurNode.s


def inner_tuple(v):
    """An Inner struct (official client value or JSON mapping) as (id, label, values)."""
    if isinstance(v, dict):
        return (v["id"], v["label"], tuple(float(x) for x in v["values"]))
    return (int(v.id), str(v.label), tuple(float(x) for x in v.values))


def read_channels(path):
    """{(topic, encoding): (channel, schema, [messages])} with the reference reader, and its summary."""
    out = {}
    with open(path, "rb") as f:
        reader = make_reader(f)
        for schema, channel, message in reader.iter_messages():
            out.setdefault((channel.topic, channel.message_encoding), (channel, schema, []))[2].append(message)
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    return out, summary


def start_rr(exe, args):
    return subprocess.Popen([exe] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            stdin=subprocess.DEVNULL, preexec_fn=die_with_parent)


def wait_stderr_line(proc, prefix, timeout):
    """Reads proc's stderr until a line starting with prefix (returns it) or timeout/EOF (raises)."""
    box = {}

    def reader():
        for line in proc.stderr:
            if line.startswith(prefix):
                box["line"] = line
                return
            box.setdefault("other", []).append(line)

    t = threading.Thread(target=reader, daemon=True)
    t.start()
    t.join(timeout)
    expect("line" in box, "rr printed %r within %d s (got %r)" % (prefix, timeout, box.get("other")))
    return box["line"]


def recording_path(line):
    """The file named by rr record's "rr: recording NAME (MEMBERS) to PATH" line."""
    path = line.rsplit(" to ", 1)[-1].strip()
    expect(path.endswith(".mcap") and " not connected yet" not in line, "rr record's line names its file, all connected: %r" % line)
    return path


def record_phase(rr, url, work, checks):
    client = RRN.ConnectService(url)
    live = []
    lock = threading.Lock()
    wire = client.w_state.Connect()

    def on_value(conn, value, ts):
        with lock:
            live.append(inner_tuple(value))

    wire.WireValueChanged += on_value
    proc = start_rr(rr, ["record", url, "--dir", work, "--members", "w_state,p_stream,ev_values"])
    try:
        # The line comes once the recorder's wire, pipe and event are connected: what the service sends
        # from now on is recorded.
        path = recording_path(wait_stderr_line(proc, "rr: recording", 60))
        client.send_stream(5)
        client.fire_events(3)
        for topic, n in (("interop/p_stream", 5), ("interop/ev_values", 3), ("interop/w_state", 10)):
            wait_for("%d %s messages in %s" % (n, topic, path), lambda: len(recorded_so_far(path, topic)) >= n, timeout=90, interval=0.3)
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=120)
        return check_recording(out, err, proc, checks, live, lock)
    finally:
        if proc.poll() is None:
            stop(proc)
        wire.Close()
        RRN.DisconnectService(client)


def check_recording(out, err, proc, checks, live, lock):
    expect(proc.returncode == 0, "rr record ends on SIGINT with 0 (rc=%s, stderr=%s)" % (proc.returncode, err[-1500:]))
    status = json.loads(out.strip().splitlines()[-1])
    checks["record_status"] = {k: status[k] for k in ("state", "messages", "drops", "files", "members")}
    expect(status["state"] == "stopped" and status["drops"] == 0, "the recording stopped without drops")
    expect(len(status["files"]) == 1, "one file")
    path = status["files"][0]

    channels, summary = read_channels(path)
    topics = sorted("%s %s %d" % (t, e, len(m[2])) for (t, e), m in channels.items())
    checks["channels"] = topics
    for member in ("w_state", "p_stream", "ev_values"):
        for enc in ("json", "robotraconteur"):
            expect(("interop/" + member, enc) in channels, "channel interop/%s (%s)" % (member, enc))
    expect(len(channels[("interop/p_stream", "json")][2]) == 5, "5 pipe packets recorded")
    expect(len(channels[("interop/ev_values", "json")][2]) == 3, "3 events recorded")
    n_state = len(channels[("interop/w_state", "json")][2])
    expect(n_state >= 10, "w_state values recorded (%d)" % n_state)
    expect(summary.statistics.message_count == status["messages"], "the file's summary counts what the status says")
    expect(n_state == len(channels[("interop/w_state", "robotraconteur")][2]), "both encodings hold every w_state value")
    rr_schema = [s for s in summary.schemas.values() if s.encoding == "robotraconteur_servicedef"]
    expect(rr_schema and rr_schema[0].name == "experimental.interop_test", "the service definition is a schema")
    for (topic, enc), (channel, schema, messages) in channels.items():
        if enc != "json":
            continue
        expect(schema.encoding == "jsonschema", topic + ": jsonschema")
        validator = jsonschema.Draft202012Validator(json.loads(schema.data))
        for m in messages:
            validator.validate(json.loads(m.data))
    packets = [json.loads(m.data)["value"] for m in channels[("interop/p_stream", "json")][2]]
    expect(packets == [[i, i * 0.5] for i in range(5)], "pipe packets as sent: %r" % packets)
    recorded = [inner_tuple(json.loads(m.data)["value"]) for m in channels[("interop/w_state", "json")][2]]
    # The official client's callbacks run on its own threads: on a busy machine the last values the recorder
    # saw may still be on their way to it. Wait for them (bounded) before comparing.
    deadline = time.monotonic() + 10
    while True:
        with lock:
            live_set = list(live)
        by_id = {v[0]: v for v in live_set}
        newest = max(by_id, default=None)
        # A wire keeps only the newest value: a packet still waiting to be written to the live client is
        # replaced by a newer one (server_connection.cpp), and a tick during its connect supersedes the
        # value current at the connect. So a recorded value the live client never got is fine when it got
        # a newer one; one it got must be identical.
        unseen = [r for r in recorded if r[0] not in by_id]
        pending = [r for r in unseen if newest is None or r[0] > newest]
        if not pending or time.monotonic() > deadline:
            break
        time.sleep(0.1)
    live_ids = [v[0] for v in live_set]
    about = "(live ids %s..%s, %d values)" % (live_ids[:1], live_ids[-1:], len(live_ids))
    mismatched = [(r, by_id[r[0]]) for r in recorded if r[0] in by_id and by_id[r[0]] != r]
    expect(not mismatched, "recorded w_state values equal what the official client received live: %r %s" % (mismatched[:3], about))
    expect(not pending, "every recorded w_state value reached the official client or was superseded there by a newer one "
           "(%d not, first %r) %s" % (len(pending), pending[:3], about))
    expect(2 * len(unseen) <= len(recorded), "most recorded w_state values were received live (%d of %d not, first %r) %s"
           % (len(unseen), len(recorded), unseen[:3], about))
    ids = [r[0] for r in recorded]
    expect(ids == sorted(ids) and len(set(ids)) == len(ids), "recorded w_state values in order")
    checks["w_state"] = {"recorded": len(recorded), "live": len(live_set), "superseded_live": len(unseen), "first_id": ids[0], "last_id": ids[-1]}
    return path, recorded


def duration_phase(rr, url, work, checks):
    d = os.path.join(work, "duration")
    proc = start_rr(rr, ["record", url, "--dir", d, "--members", "w_state", "--encoding", "json", "--duration", "1.5"])
    try:
        wait_stderr_line(proc, "rr: recording", 60)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            stop(proc)
    expect(proc.returncode == 0, "rr record --duration ends by itself with 0 (rc=%s, %s)" % (proc.returncode, err[-800:]))
    status = json.loads(out.strip().splitlines()[-1])
    expect(status["state"] == "stopped" and status["duration_s"] >= 1.5, "--duration 1.5: stopped after %s s" % status["duration_s"])
    with open(status["files"][0], "rb") as f:
        summary = make_reader(f).get_summary()
    # The wire's value when the recorder connected comes with the connection: at least one is recorded.
    expect(summary is not None and summary.statistics.message_count >= 1, "the --duration file is complete, with values")
    expect(all(c.message_encoding == "json" for c in summary.channels.values()), "--encoding json: json channels only")
    checks["duration"] = {"messages": summary.statistics.message_count, "duration_s": status["duration_s"]}


def replay_phase(rr, path, recorded, checks):
    proc = start_rr(rr, ["replay", path, "--port", "0", "--loop"])
    line = proc.stdout.readline().strip()
    expect(line.startswith("rr+tcp://127.0.0.1:") and "service=interop" in line, "rr replay prints its URL: %r" % line)
    try:
        client = RRN.ConnectService(line)
        got, pipe_got = [], []
        lock = threading.Lock()
        wire = client.w_state.Connect()

        def on_value(conn, value, ts):
            with lock:
                got.append(inner_tuple(value))

        wire.WireValueChanged += on_value
        ep = client.p_stream.Connect(-1)

        def on_packet(e):
            while e.Available > 0:
                with lock:
                    pipe_got.append([float(x) for x in e.ReceivePacket()])

        ep.PacketReceivedEvent += on_packet
        # Looped: the 5 packets come once per pass. The bound is against a hang (several passes).
        duration = (recorded and len(recorded) * 0.2) or 3
        deadline = time.monotonic() + 3 * duration + 60
        want = [[float(i), i * 0.5] for i in range(5)]
        while time.monotonic() < deadline:
            time.sleep(0.2)
            with lock:
                if len(got) >= 5 and any(pipe_got[i:i + 5] == want for i in range(len(pipe_got))):
                    break
        with lock:
            got_c, pipe_c = list(got), list(pipe_got)
        ep.Close()
        wire.Close()
        RRN.DisconnectService(client)
        checks["replay"] = {"w_state_received": len(got_c), "pipe_packets": len(pipe_c)}
        expect(len(got_c) >= 5, "the official client receives replayed w_state values")
        expect(all(g in recorded for g in got_c), "every replayed w_state value is a recorded one")
        expect(any(pipe_c[i:i + 5] == want for i in range(len(pipe_c))), "the 5 recorded pipe packets are replayed: %r" % pipe_c[:10])
    finally:
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=60)
    expect(proc.returncode == 0, "rr replay ends on SIGINT with 0 (rc=%s, %s)" % (proc.returncode, err[-800:]))
    final = json.loads(out.strip().splitlines()[-1])
    expect(final["played"] > 0 and final["loop"] is True, "final replay status: %r" % final)


def errors_phase(rr, url, work, checks):
    def run(args, timeout=90):
        p = subprocess.run([rr] + args, capture_output=True, text=True, timeout=timeout)
        return p.returncode, p.stderr

    rc, err = run(["record", url, "--members", "no_such_member", "--dir", work])
    expect(rc == 2 and "no_such_member" in err, "an unknown member: status 2 naming it (rc=%s, %s)" % (rc, err))
    rc, err = run(["record", "rr+tcp://127.0.0.1:9/?service=interop", "--timeout", "2", "--dir", work])
    expect(rc == 3 and "not connected" in err, "an unreachable service: status 3 (rc=%s, %s)" % (rc, err))
    rc, err = run(["record", url, "--dir", "/proc/rr-no-such-dir"])
    expect(rc == 1 and "/proc/rr-no-such-dir" in err, "an unwritable directory: status 1 naming it (rc=%s, %s)" % (rc, err))
    bad = os.path.join(work, "not-mcap.mcap")
    with open(bad, "w") as f:
        f.write("this is not an MCAP file\n")
    rc, err = run(["replay", bad])
    expect(rc == 1 and "not-mcap.mcap" in err, "a file that is not MCAP: status 1 naming it (rc=%s, %s)" % (rc, err))
    rc, err = run(["replay", bad, "--duration", "3"])
    expect(rc == 2, "record options refused by replay (rc=%s)" % rc)
    checks["errors"] = "ok"


GATEWAY_TOKEN = "recorder-token-8f14e45fceea167a"


def gateway_login_phase(rr, gateway, url, work, checks):
    """`rr record` of a device behind a gateway with logins on (gateway.auth): refused without
    credentials or with a wrong token (status 3, the gateway's reason), recorded with
    `--username rec@token --token T` (the credentials every rr command takes)."""
    d = os.path.join(work, "gw")
    os.makedirs(d)
    with open(os.path.join(d, "tokens.txt"), "w") as f:
        f.write("%s rec viewer\n" % GATEWAY_TOKEN)
    with open(os.path.join(d, "gateway.yaml"), "w") as f:
        f.write("""gateway:
  port: 0
  listen: 127.0.0.1
  local: false
  auth:
    tokens: {d}/tokens.txt
    roles:
      viewer:
        - allow: [read]
    # the recorder retries a refused login until --timeout: no lockout for this test's address
    login_limit: {{max_failures: 1000, window_s: 60, lockout_s: 1}}
demo:
  enabled: false
devices:
  - name: interop
    url: {url}
""".format(d=d, url=url))
    with open(os.path.join(d, "gateway.err"), "wb") as errf:
        gw = subprocess.Popen([gateway, "--config", os.path.join(d, "gateway.yaml"), "--no-discovery"],
                              stdout=subprocess.PIPE, stderr=errf, stdin=subprocess.DEVNULL, preexec_fn=die_with_parent)
    try:
        port = read_json_line(gw, 60, "rr-gateway")["port"]
        gw_url = "rr+tcp://127.0.0.1:%d/?service=interop" % port

        def run(extra):
            p = subprocess.run([rr, "record", gw_url, "--members", "w_state", "--duration", "2", "--timeout", "8",
                                "--dir", os.path.join(d, "rec")] + extra, capture_output=True, text=True, timeout=120)
            return p.returncode, p.stdout, p.stderr

        rc, _, err = run([])
        expect(rc == 3 and "not connected" in err,
               "without a login: status 3 with the gateway's reason (rc=%s, %s)" % (rc, err.strip()[-600:]))
        refused = err.strip().splitlines()[-1]
        rc, _, err = run(["--username", "rec@token", "--token", GATEWAY_TOKEN + "x"])
        expect(rc == 3 and "Invalid token" in err, "a wrong token: status 3, 'Invalid token' (rc=%s, %s)"
               % (rc, err.strip()[-600:]))
        rc, out, err = run(["--username", "rec@token", "--token", GATEWAY_TOKEN])
        expect(rc == 0, "with --token: rr record exits 0 (rc=%s, %s)" % (rc, err.strip()[-800:]))
        status = json.loads(out.strip().splitlines()[-1])
        channels, _ = read_channels(status["files"][0])
        n = len(channels.get(("interop/w_state", "json"), (None, None, []))[2])
        expect(n >= 1, "with --token: w_state values recorded through the gateway (%d)" % n)
        checks["gateway_login"] = {"refused": refused[-300:], "recorded_w_state": n}
    finally:
        stop(gw)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rr", required=True)
    ap.add_argument("--service", required=True, help="rr_interop_service")
    ap.add_argument("--gateway", help="rr-gateway: also record a device behind its logins with --token")
    ap.add_argument("--keep", action="store_true")
    a = ap.parse_args()
    work = tempfile.mkdtemp(prefix="rr-record-cli-")
    RRN.RegisterTransport(RR.TcpTransport())
    checks, ok = {}, False
    svc = subprocess.Popen([a.service, "--port", "0", "--max-lifetime", "280"], stdout=subprocess.PIPE,
                           stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL, preexec_fn=die_with_parent)
    try:
        url = read_json_line(svc, 60, "rr_interop_service")["url"]
        path, recorded = record_phase(a.rr, url, work, checks)
        duration_phase(a.rr, url, work, checks)
        replay_phase(a.rr, path, recorded, checks)
        errors_phase(a.rr, url, work, checks)
        if a.gateway:
            gateway_login_phase(a.rr, a.gateway, url, work, checks)
        else:
            checks["gateway_login"] = "not run (no --gateway)"
        ok = True
    except (CheckFailed, AssertionError, jsonschema.ValidationError, RR.RobotRaconteurException, OSError, KeyError,
            ValueError, IndexError, subprocess.TimeoutExpired, StepFailed) as e:
        checks["failed"] = "%s: %s" % (type(e).__name__, str(e)[:2000])
    finally:
        stop(svc)
        report_and_clean(checks, work, a.keep, failed=not ok)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
