#!/usr/bin/env python3
"""Wires two objrefs below a device's root object, and events and a property one objref below,
recorded and replayed (docs/recording.md "Objects below the root", issue 44).

The device is a standard com.robotraconteur.signal.SignalDevice served by the official Python library
(signal_device.py): `signal_groups{string}` then `signals{int32}`, each signal's `signal_value_vec`
wire sending [group, signal, seq, seq/2] every 50 ms. Through rr-gateway's JSON API the test records
`signal_groups[arm].signals[0].signal_value_vec` and `signal_groups[gripper].signals[1].signal_value_vec`
(both encodings) for a few seconds, then checks:
- names that do not lead to a member get 400 naming the problem (an index missing on the string-keyed
  objref, an unknown member of the Signal, a wire used as an objref);
- the reference reader (PyPI mcap): channels `signals/signal_groups[arm].signals[0]/signal_value_vec`,
  ... with metadata `path`, `object_type` com.robotraconteur.signal.Signal, `root_type`, the
  `robotraconteur` channels' schema com.robotraconteur.signal; each channel's values are those of its
  own object (group and signal numbers), seq strictly increasing, log times in order;
- `rr-gateway --replay FILE`: an official client (rr+tcp) reaches both signals through the two objrefs,
  receives on their wires values that were recorded for that object, in the recorded order (the replay
  loops: at most one wrap); the JSON API reads the wire with `?object=`; an objref index that was not
  recorded is refused with "was not recorded".

- the device's second service "tools" (an objref `tools{int32}` to Tools with a `tick` event and a
  `number` property): `tools[1].tick` and `tools[1].number` recorded in a second recording at the same
  time; replayed, an official client gets tool 1's recorded events in the recorded order and its number,
  and tools[0] is refused as not recorded;
- with --rr: `rr record` of the device itself records a member by path on its topic (the gripper's
  values), and refuses a path without an index (exit 2); `rr replay` of that file gives an official
  client recorded values through the two objrefs and refuses the arm's group (not recorded);
- the json channels as Foxglove/Lichtblick's parser reads them (record_checks.foxglove_check).

Every step waits for what it checks (values in the file on disk, values received), bounded only against
a hang. Spacing (the recorded log times and the replayed values and events about 50 ms apart, median
within 25..150 ms) is judged with --spacing judge, the run labelled timing (the calm phase); the main
run (--spacing report) reports it.

  record_subobject_wire_test.py --gateway build/debug/server/app/rr-gateway [--rr build/debug/server/cli/rr]
                                [--spacing judge|report]
Prints a JSON summary (on a failure also the processes' logs, the work folder kept); exit 0, 1 (a check
failed) or 77 (the venv's packages are missing, or a part could not run here after the others passed).
"""
import argparse
import json
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import urllib.parse

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "interop"))
sys.path.insert(0, HERE)
from child_procs import StepFailed, die_with_parent, read_json_line, stop  # noqa: E402
import official_transport  # noqa: E402  (the official client's transport, its connect timeout)
from record_checks import (CheckFailed, exit_status, expect, foxglove_check, http, recorded_so_far, report_and_clean,  # noqa: E402
                           stop_recording, wait_for)
import record_replay_test  # noqa: E402  (its gateway launcher)

try:
    from mcap.reader import make_reader
    import numpy  # noqa: F401  (signal_device.py)
    import RobotRaconteur as RR
    import RobotRaconteurCompanion as RRC
except ImportError as e:  # pragma: no cover
    print("SKIP: %s (run ./scripts/setup.sh)" % e)
    sys.exit(77)

RRN = RR.RobotRaconteurNode.s
MEMBERS = ["signal_groups[arm].signals[0].signal_value_vec", "signal_groups[gripper].signals[1].signal_value_vec"]
TOOL_MEMBERS = ["tools[1].tick", "tools[1].number"]  # the device's second service (signal_device.py)
# (path, group number, signal number) of each recorded member
OBJECTS = [("signal_groups[arm].signals[0]", 0, 0), ("signal_groups[gripper].signals[1]", 1, 1)]


def start_gateway(exe, args, work, name):
    return record_replay_test.start_gateway(exe, ["--no-demo"] + args, os.path.join(work, name + ".log"))


def start_device(work):
    errf = open(os.path.join(work, "signal_device.log"), "wb")
    proc = subprocess.Popen([sys.executable, os.path.join(HERE, "signal_device.py"), "--period-ms", "50"],
                            stdout=subprocess.PIPE, stderr=errf, stdin=subprocess.DEVNULL, preexec_fn=die_with_parent)
    return proc, read_json_line(proc, 60, "signal_device.py")


def rr_record(rr_exe, url, work, checks):
    """`rr record` of the device itself (no gateway): a member by path is recorded on its topic with the
    object's values; a path that leads nowhere exits 2 naming it."""
    cli_dir = os.path.join(work, "cli")
    member = MEMBERS[1]
    obj, group, sig = OBJECTS[1]
    p = subprocess.Popen([rr_exe, "record", url, "--members", member, "--dir", cli_dir], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, stdin=subprocess.DEVNULL, preexec_fn=die_with_parent)
    try:
        # "rr: recording … to FILE" once the wire is connected; 5 values in the file, then SIGINT.
        line = p.stderr.readline()
        expect(line.startswith("rr: recording") and line.rstrip().endswith(".mcap"), "rr record's first line: %r" % line)
        path = line.rstrip().rsplit(" to ", 1)[1]
        wait_for("rr record: 5 values in %s" % path,
                 lambda: len(recorded_so_far(path, "signals/%s/signal_value_vec" % obj)) >= 5, timeout=90, interval=0.3)
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=120)
    finally:
        if p.poll() is None:
            stop(p)
    expect(p.returncode == 0, "rr record --members %s: exit %s, %s" % (member, p.returncode, err[-1500:]))
    status = json.loads(out.strip().splitlines()[-1])
    expect(status["members"] == [member], "rr record's members: %s" % status["members"])
    with open(status["files"][0], "rb") as f:
        values = [json.loads(m.data)["value"] for _, ch, m in make_reader(f).iter_messages()
                  if ch.topic == "signals/%s/signal_value_vec" % obj and ch.metadata.get("path") == obj
                  and ch.message_encoding == "json"]
    expect(len(values) >= 5 and all(v[0] == group and v[1] == sig for v in values),
           "rr record: %d values of %s on its topic: %s" % (len(values), obj, values[:3]))
    bad = subprocess.run([rr_exe, "record", url, "--members", "signal_groups[arm].signals.signal_value_vec", "--duration", "1",
                          "--dir", cli_dir], capture_output=True, text=True, timeout=120)
    expect(bad.returncode == 2 and "needs an index" in bad.stderr,
           "rr record of a path without an index: exit %s, %s" % (bad.returncode, bad.stderr[-800:]))
    checks["rr_record"] = {"values": len(values), "refused": bad.stderr.strip()[-300:]}
    rr_replay(rr_exe, status["files"][0], {tuple(v) for v in values}, checks)


def rr_replay(rr_exe, path, recorded, checks):
    """`rr replay` of rr record's file: an official client reaches the gripper's signal through the two
    objrefs and receives recorded values; the arm's group was not recorded."""
    proc = subprocess.Popen([rr_exe, "replay", path, "--port", "0", "--loop"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, stdin=subprocess.DEVNULL, preexec_fn=die_with_parent)
    try:
        url = proc.stdout.readline().strip()
        expect(url.startswith("rr+tcp://127.0.0.1:") and "service=signals" in url, "rr replay prints its URL: %r" % url)
        c = RRN.ConnectService(url)
        try:
            listener = WireValues(c.get_signal_groups("gripper").get_signals(1))
            try:
                wait_for("rr replay: 5 values", lambda: len(listener.snapshot()) >= 5, timeout=60, interval=0.1)
            except CheckFailed:
                pass  # said below
            got = listener.snapshot()
            listener.conn.Close()
            expect(len(got) >= 5 and all(v in recorded for _, v in got),
                   "rr replay: %d values through the objrefs, all recorded ones: %s" % (len(got), [v for _, v in got][:3]))
            try:
                c.get_signal_groups("arm").signal_info
                refused = None
            except RR.RobotRaconteurException as e:
                refused = str(e)
            expect(refused and "was not recorded" in refused, "rr replay: the arm's group refused: %s" % refused)
        finally:
            RRN.DisconnectService(c)
    finally:
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=60)
    expect(proc.returncode == 0, "rr replay ends on SIGINT with 0 (rc=%s, %s)" % (proc.returncode, err[-800:]))
    checks["rr_replay"] = {"values": len(got), "refused": refused}


def record_phase(exe, work, checks, rr_exe=None):
    dev, info = start_device(work)
    gw = None
    try:
        gw, port, base = start_gateway(exe, ["--device", "signals=" + info["url"], "--device", "tools=" + info["tools_url"],
                                             "--recordings-root", work], work, "gateway")
        for device in ("signals", "tools"):
            deadline = time.monotonic() + 30
            while time.monotonic() < deadline:
                status, d = http(base, "GET", "/api/devices/" + device)
                if status == 200 and d.get("state") == "connected":
                    break
                time.sleep(0.2)
            expect(d.get("state") == "connected", "the %s device connected: %s" % (device, d))
        bad = {}
        for name, want in (("signal_groups.signals[0].signal_value_vec", "needs an index"),
                           ("signal_groups[arm].signals[0].nope", "has no member \"nope\""),
                           ("signal_groups[arm].signals[0].signal_value_vec.x", "is a wire, not an objref")):
            status, body = http(base, "POST", "/api/recordings", {"device": "signals", "members": [name]})
            message = (body or {}).get("error", {}).get("message", "")
            bad[name] = [status, message]
            expect(status == 400 and want in message, "%s: 400 with \"%s\", got %s %s" % (name, want, status, message))
        checks["refused_names"] = bad
        status, rec = http(base, "POST", "/api/recordings", {"device": "signals", "members": MEMBERS})
        expect(status == 201, "POST /api/recordings: %s %s" % (status, rec))
        expect(rec["members"] == MEMBERS, "the status names the members with their objects: %s" % rec["members"])
        status, tools_rec = http(base, "POST", "/api/recordings", {"device": "tools", "members": TOOL_MEMBERS,
                                                                   "property_period_ms": 200})
        expect(status == 201, "POST /api/recordings (tools): %s %s" % (status, tools_rec))
        # What read_file and read_tools_file count, on disk (the writer flushes every second): 20 values of
        # each signal (10 are checked), 12 ticks (10 are checked) and the tool's number, then stop.
        for path, topic, n in [(rec["files"][0], "signals/%s/signal_value_vec" % obj, 20) for obj, _, _ in OBJECTS] + \
                [(tools_rec["files"][0], "tools/tools[1]/tick", 12), (tools_rec["files"][0], "tools/tools[1]/number", 1)]:
            wait_for("%d %s messages in %s" % (n, topic, path), lambda: len(recorded_so_far(path, topic)) >= n,
                     timeout=90, interval=0.3)
        _, done = stop_recording(base, rec["id"])
        checks["recording"] = {k: done[k] for k in ("messages", "drops", "files", "members")}
        _, tools_done = stop_recording(base, tools_rec["id"])
        checks["tools_recording"] = {k: tools_done[k] for k in ("messages", "drops", "files", "members")}
        if rr_exe:
            rr_record(rr_exe, info["url"], work, checks)
        return done["files"][-1], tools_done["files"][-1]
    finally:
        if gw:
            stop(gw)
        stop(dev)


def median_gap_ms(times_s):
    """The median interval between consecutive times (s), in ms."""
    return statistics.median([(b - a) * 1000 for a, b in zip(times_s, times_s[1:])])


def spacing(checks, judge, what, median):
    """The median interval of `what` (ms, about 50 recorded): reported, and with --spacing judge (the
    run labelled timing, in the calm phase) within 25..150 ms or a failure."""
    checks.setdefault("median_gap_ms", {})[what] = round(median, 1)
    if judge:
        expect(25 <= median <= 150, "%s: %.1f ms apart (sent every 50 ms)" % (what, median))


def in_recorded_order(what, received, recorded):
    """Replayed values (hashable) are recorded ones in the recorded order, the loop wrapping at most once:
    each later than the one before in the recording, except one wrap to an earlier one."""
    index = {v: i for i, v in enumerate(recorded)}
    unknown = [v for v in received if v not in index]
    expect(not unknown, "%s: every replayed value is a recorded one (%d of %d not: %s)" % (what, len(unknown), len(received), unknown[:3]))
    positions = [index[v] for v in received]
    wraps = sum(1 for a, b in zip(positions, positions[1:]) if b <= a)
    expect(wraps <= 1, "%s: replayed in the recorded order (recorded positions %s)" % (what, positions[:40]))


def read_file(path, checks, judge):
    """{object path: [(log_time ns, value list)]} of the json channels, after the channels' checks."""
    channels, values = {}, {}
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        for c in summary.channels.values():
            schema = summary.schemas.get(c.schema_id)
            channels[(c.topic, c.message_encoding)] = {k: c.metadata.get(k) for k in ("path", "object_type", "root_type", "member")}
            channels[(c.topic, c.message_encoding)].update(
                schema=schema.name if schema else None, messages=summary.statistics.channel_message_counts.get(c.id, 0))
        for _, ch, m in reader.iter_messages():
            if ch.message_encoding == "json":
                values.setdefault(ch.metadata["path"], []).append((m.log_time, json.loads(m.data)["value"]))
    checks["channels"] = {"%s [%s]" % k: v for k, v in sorted(channels.items())}
    expect(len(channels) == 4, "two members, two encodings: %s" % sorted(channels))
    for obj, group, sig in OBJECTS:
        topic = "signals/%s/signal_value_vec" % obj
        for enc in ("json", "robotraconteur"):
            c = channels.get((topic, enc))
            expect(c is not None, "channel %s [%s] in the file" % (topic, enc))
            expect(c["path"] == obj, "%s: metadata path %s" % (topic, c["path"]))
            expect(c["member"] == "signal_value_vec", "%s: metadata member %s" % (topic, c["member"]))
            expect(c["object_type"] == "com.robotraconteur.signal.Signal", "%s: object_type %s" % (topic, c["object_type"]))
            expect(c["root_type"] == "com.robotraconteur.signal.SignalDevice", "%s: root_type %s" % (topic, c["root_type"]))
            expect(c["messages"] >= 10, "%s [%s]: %d messages" % (topic, enc, c["messages"]))
        expect(channels[(topic, "robotraconteur")]["schema"] == "com.robotraconteur.signal",
               "%s: the robotraconteur channel's schema is the definition of Signal" % topic)
        recorded = values.get(obj, [])
        wrong = [v for _, v in recorded if v[0] != group or v[1] != sig]
        expect(not wrong, "%s: every recorded value is of that object (%d of %d are not: %s)" % (obj, len(wrong), len(recorded), wrong[:3]))
        seqs = [v[2] for _, v in recorded]
        expect(all(b > a for a, b in zip(seqs, seqs[1:])), "%s: seq strictly increasing" % obj)
        times = [t for t, _ in recorded]
        expect(times == sorted(times), "%s: log times in order" % obj)
        spacing(checks, judge, "recorded " + obj, median_gap_ms([t / 1e9 for t in times]))
    return {obj: [tuple(v) for _, v in vals] for obj, vals in values.items()}


def read_tools_file(path, checks):
    """The recorded `tools[1].tick` events as (tool, seq) tuples, after the channels' checks."""
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        topics = {(c.topic, c.message_encoding): c.metadata for c in summary.channels.values()}
        events, numbers = [], []
        for _, ch, m in reader.iter_messages():
            if ch.message_encoding != "json":
                continue
            if ch.topic == "tools/tools[1]/tick":
                args = json.loads(m.data)["args"]
                events.append((args["tool"], args["seq"]))
            elif ch.topic == "tools/tools[1]/number":
                numbers.append(json.loads(m.data)["value"])
    for topic in ("tools/tools[1]/tick", "tools/tools[1]/number"):
        for enc in ("json", "robotraconteur"):
            meta = topics.get((topic, enc))
            expect(meta is not None and meta.get("path") == "tools[1]" and meta.get("object_type") == "experimental.record_tools.Tool",
                   "channel %s [%s] with path tools[1] and its object type: %s" % (topic, enc, meta))
    expect(len(events) >= 10 and all(t == 1 for t, _ in events), "tools[1].tick events of tool 1: %s" % events[:5])
    expect(all(b[1] > a[1] for a, b in zip(events, events[1:])), "tick seq strictly increasing")
    expect(numbers and all(n == 1 for n in numbers), "tools[1].number polled: %s" % numbers[:5])
    checks["tools_file"] = {"tick": len(events), "number": len(numbers)}
    return events


def tools_replay(c, recorded, checks, judge):
    """Through the replaying gateway: tools[1]'s events arrive, recorded ones in the recorded order
    (spaced as recorded: judged in the timing run); its property answers; tools[0] was not recorded."""
    tool = c.get_tools(1)
    got, lock = [], threading.Lock()

    def on_tick(t, seq):
        with lock:
            got.append((time.monotonic(), (t, seq)))

    def snapshot():
        with lock:
            return list(got)
    tool.tick += on_tick
    try:
        wait_for("10 tools[1].tick events through the replay", lambda: len(snapshot()) >= 10, timeout=60, interval=0.1)
    except CheckFailed:
        pass  # said below
    received = snapshot()
    expect(len(received) >= 10, "tools[1].tick events through the replay: %d" % len(received))
    # The official client runs event handlers on its thread pool, so their order is not the sending
    # order under load: each event is a recorded one (the order is the wires' check, above).
    unknown = [v for _, v in received if v not in set(recorded)]
    expect(not unknown, "every replayed event is a recorded one: %s" % unknown[:3])
    median = statistics.median([(b - a) * 1000 for (a, _), (b, _) in zip(received, received[1:])])
    spacing(checks, judge, "replayed tools[1].tick", median)

    def number_read():
        try:
            box["number"] = tool.number
            return True
        except RR.RobotRaconteurException:  # ValueNotSet until the first polled value is played
            return False
    box = {"number": None}
    try:
        wait_for("tools[1].number answers", number_read, timeout=30)
    except CheckFailed:
        pass  # said below
    number = box["number"]
    expect(number == 1, "tools[1].number answers its recorded value: %s" % number)
    try:
        c.get_tools(0).number
        refused = None
    except RR.RobotRaconteurException as e:
        refused = str(e)
    expect(refused and "was not recorded" in refused, "tools[0] refused as not recorded: %s" % refused)
    checks["tools_replayed"] = {"events": len(received), "number": number}


class WireValues:
    """What an official client receives on a wire, with arrival times."""

    def __init__(self, obj):
        self.values, self.lock = [], threading.Lock()
        self.conn = obj.signal_value_vec.Connect()
        self.conn.WireValueChanged += self._on

    def _on(self, conn, value, ts):
        with self.lock:
            self.values.append((time.monotonic(), tuple(float(x) for x in value)))

    def snapshot(self):
        with self.lock:
            return list(self.values)


def replay_phase(exe, work, path, recorded, tools_path, tools_recorded, checks, judge):
    gw, port, base = start_gateway(exe, ["--replay", path, "--replay", tools_path], work, "replay")
    try:
        status, st = http(base, "POST", "/api/replays/tools", {"loop": True})
        expect(status == 200, "replay control (tools): %s %s" % (status, st))
        t = RRN.ConnectService("rr+tcp://127.0.0.1:%d/?service=tools" % port)
        try:
            tools_replay(t, tools_recorded, checks, judge)
        finally:
            RRN.DisconnectService(t)
        status, st = http(base, "POST", "/api/replays/signals", {"loop": True})
        expect(status == 200, "replay control: %s %s" % (status, st))
        expect(sorted(st["members"]) == sorted(MEMBERS), "the replay's members: %s" % st["members"])
        c = RRN.ConnectService("rr+tcp://127.0.0.1:%d/?service=signals" % port)
        try:
            listeners = {}
            for obj, group, sig in OBJECTS:
                key = obj.split("[")[1].split("]")[0]
                listeners[obj] = WireValues(c.get_signal_groups(key).get_signals(sig))
            got = {}
            for obj, group, sig in OBJECTS:
                try:
                    wait_for("%s: 10 replayed values" % obj, lambda: len(listeners[obj].snapshot()) >= 10, timeout=60, interval=0.1)
                except CheckFailed:
                    pass  # said below
                received = listeners[obj].snapshot()
                listeners[obj].conn.Close()
                expect(len(received) >= 10, "%s: values through the replayed wire: %d" % (obj, len(received)))
                # A wire's InValue on connecting may repeat the value then played: compare without repeats.
                values = [v for k, (_, v) in enumerate(received) if k == 0 or received[k - 1][1] != v]
                in_recorded_order(obj, values, recorded[obj])
                spacing(checks, judge, "replayed " + obj, median_gap_ms([t for t, _ in received]))
                got[obj] = {"received": len(received)}
            checks["replayed"] = got

            q = urllib.parse.quote(OBJECTS[0][0], safe="")
            status, body = http(base, "GET", "/api/devices/signals/wires/signal_value_vec?object=" + q)
            expect(status == 200 and tuple(float(x) for x in body["value"]) in set(recorded[OBJECTS[0][0]]),
                   "JSON API wire ?object=%s: %s %s" % (OBJECTS[0][0], status, body))
            checks["json_api_value"] = body["value"]

            refusals = {}
            for what, get in (("signals[1] of arm", lambda: c.get_signal_groups("arm").get_signals(1).signal_info),
                              ("group hand", lambda: c.get_signal_groups("hand").signal_info)):
                try:
                    get()
                    refusals[what] = None
                except RR.RobotRaconteurException as e:
                    refusals[what] = str(e)
            checks["refused"] = refusals
            for what, message in refusals.items():
                expect(message and "was not recorded" in message, "%s refused as not recorded: %s" % (what, message))
        finally:
            RRN.DisconnectService(c)
    finally:
        code = stop(gw)
    expect(code == 0, "the replaying gateway stops cleanly (%s)" % code)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--rr", help="the rr command: also record a member by path with `rr record`")
    ap.add_argument("--spacing", choices=["judge", "report"], default="judge",
                    help="report: measure the spacing but leave judging it to the run labelled timing")
    ap.add_argument("--keep", action="store_true")
    a = ap.parse_args()
    work = tempfile.mkdtemp(prefix="rr-record-subwire-")
    RRN.RegisterTransport(official_transport.client_tcp_transport(RR))
    RRC.RegisterStdRobDefServiceTypes(RRN)
    checks, ok = {}, False
    try:
        judge = a.spacing == "judge"
        path, tools_path = record_phase(a.gateway, work, checks, a.rr)
        recorded = read_file(path, checks, judge)
        tools_recorded = read_tools_file(tools_path, checks)
        foxglove_check([path, tools_path], checks)
        replay_phase(a.gateway, work, path, recorded, tools_path, tools_recorded, checks, judge)
        ok = True
    except (CheckFailed, AssertionError, RR.RobotRaconteurException, OSError, KeyError, ValueError, TypeError, IndexError,
            StepFailed, subprocess.TimeoutExpired, statistics.StatisticsError) as e:
        checks["failed"] = "%s: %s" % (type(e).__name__, str(e)[:2000])
    finally:
        report_and_clean(checks, work, a.keep, failed=not ok)
    sys.exit(exit_status(ok, checks))


if __name__ == "__main__":
    main()
