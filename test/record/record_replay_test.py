#!/usr/bin/env python3
"""Recording and replay end to end (docs/recording.md), with the official Robot Raconteur Python client
and the reference MCAP reader (PyPI `mcap`):

  record   rr-gateway with its demo devices; an official client streams the `create` device's `packets`
           wire through the gateway and keeps what it receives (SensorPacket sequence numbers); a
           recording of packets, Bump and DistanceTraveled (polled) is made through the JSON API for
           --seconds; the reference reader lists its channels, schemas and counts, every `json` message
           validates against its channel's JSON Schema, and the recorded packets are the ones the
           official client received live (same bytes for each sequence number it received, most received).
  killed   a second recording, the gateway killed with SIGKILL mid-recording: the reference reader
           still reads the file up to its last chunk.
  replay   `rr-gateway --no-demo --replay FILE`: an official client through the gateway receives the
           recorded packets in order with the recorded spacing (each interval within +-5 ms, see
           --tolerance-ms); a seek lands on the right wire and property value; a function is refused
           with a clear error; the replay's JSON API status moves.
  failures a sub-folder that cannot be created: 507 and a failed recording with the reason; a full disk
           (a small tmpfs, mounted here as root; the test exits 77 when it cannot be mounted): the
           recording fails with "No space left on device" while the gateway goes on serving; corrupt
           files handed to --replay: a clear error and exit status 2 (a start error), no crash.

Every step waits for the event it checks (a count on disk, a value received), bounded only against a
hang. The replay's spacing is judged with --spacing judge (the run labelled timing, in the calm phase):
a miss fails there. Prints one JSON summary (and, on a failure, the gateways' logs; the work folder is
kept); exit 0 when every check passed, 1 when one failed, 77 (SKIP) without the venv's packages or when
the tmpfs cannot be mounted (not root, no CAP_SYS_ADMIN) after every other check passed.
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
import urllib.error
import urllib.request

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "interop"))
from child_procs import die_with_parent, read_json_line, stop  # noqa: E402
import official_transport  # noqa: E402  (the official client's transport, its connect timeout)
from record_checks import (CheckFailed, exit_status, expect, foxglove_check, http, recorded_so_far, report_and_clean,  # noqa: E402
                           stop_recording, wait_for)

try:
    import jsonschema
    from mcap.reader import make_reader
    from mcap.records import Message
    from mcap.stream_reader import StreamReader
    from mcap.exceptions import McapError
    import RobotRaconteur as RR
except ImportError as e:  # pragma: no cover
    print("SKIP: %s (run ./scripts/setup.sh)" % e)
    sys.exit(77)

RRN = RR.RobotRaconteurNode.s


def start_gateway(exe, args, log_path):
    with open(log_path, "wb") as errf:
        proc = subprocess.Popen([exe, "--listen", "127.0.0.1", "--port", "0", "--no-local", "--no-discovery"] + args,
                                stdout=subprocess.PIPE, stderr=errf, stdin=subprocess.DEVNULL, preexec_fn=die_with_parent)
    ready = read_json_line(proc, 60, "rr-gateway")
    base = "http://127.0.0.1:%d" % ready["port"]
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        try:
            with urllib.request.urlopen(base + "/readyz", timeout=5) as r:
                if r.status == 200:
                    return proc, ready["port"], base
        except (urllib.error.URLError, OSError):
            pass
        time.sleep(0.1)
    raise CheckFailed("rr-gateway not ready: " + open(log_path, errors="replace").read()[-2000:])


def seq_of(packet):
    data = bytes(bytearray(packet.Data))
    return data[2] | (data[3] << 8), data


class WireListener:
    """The values an official client receives on a wire, with their arrival times (monotonic s) and
    the times their sender stamped on them (the packet's TimeSpec, wall clock s)."""

    def __init__(self, obj, member):
        self.values = []
        self.sent = []
        self.lock = threading.Lock()
        self.conn = getattr(obj, member).Connect()
        self.conn.WireValueChanged += self._on

    def _on(self, conn, value, ts):
        t = time.monotonic()
        with self.lock:
            self.values.append((t, value))
            self.sent.append(ts.seconds + ts.nanoseconds * 1e-9)

    def snapshot(self):
        with self.lock:
            return list(self.values)

    def snapshot_with_sent(self):
        """(arrival, value, sent) of each value."""
        with self.lock:
            return [(t, v, s) for (t, v), s in zip(self.values, self.sent)]


def read_stream(path):
    """Messages the reference reader's streaming mode reads from a file cut off by a crash, and the
    error its end gives (None for a complete file)."""
    n, end = 0, None
    with open(path, "rb") as f:
        try:
            for r in StreamReader(f, validate_crcs=True).records:
                n += isinstance(r, Message)
        except McapError as e:  # a cut-off file ends in an error after its complete records
            end = "%s: %s" % (type(e).__name__, e)
    return n, end


def read_channels(path):
    """{topic+encoding: (channel, schema, [messages])} with the reference reader."""
    out = {}
    with open(path, "rb") as f:
        reader = make_reader(f)
        for schema, channel, message in reader.iter_messages():
            key = (channel.topic, channel.message_encoding)
            out.setdefault(key, (channel, schema, []))[2].append(message)
    return out


def check_recording(path, listener, checks):
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    expect(summary is not None, "recording has a summary (closed file)")
    topics = sorted({(c.topic, c.message_encoding) for c in summary.channels.values()})
    checks["channels"] = ["%s [%s]" % t for t in topics]
    for member in ("packets", "Bump", "DistanceTraveled"):
        for enc in ("json", "robotraconteur"):
            expect(("create/" + member, enc) in topics, "channel create/%s [%s] listed" % (member, enc))
    schemas = {s.id: s for s in summary.schemas.values()}
    rr_schema = [s for s in schemas.values() if s.encoding == "robotraconteur_servicedef"]
    expect(rr_schema and rr_schema[0].name == "experimental.create", "the service definition is a schema")
    expect(b"object Create" in rr_schema[0].data, "the schema holds the definition text")
    channels = read_channels(path)
    counts = {"%s [%s]" % k: len(v[2]) for k, v in channels.items()}
    checks["counts"] = counts
    json_packets = channels[("create/packets", "json")]
    rr_packets = channels[("create/packets", "robotraconteur")]
    expect(len(json_packets[2]) == len(rr_packets[2]) and len(rr_packets[2]) > 20, "packets recorded in both encodings")
    expect(len(channels[("create/DistanceTraveled", "json")][2]) >= 3, "the polled property is recorded")
    # Every json message validates against its channel's JSON Schema.
    validated = 0
    for (topic, enc), (channel, schema, messages) in channels.items():
        if enc != "json":
            continue
        expect(schema.encoding == "jsonschema", topic + ": schema encoding jsonschema")
        validator = jsonschema.Draft202012Validator(json.loads(schema.data))
        for m in messages:
            validator.validate(json.loads(m.data))
            validated += 1
    checks["json_messages_validated"] = validated
    foxglove_check([path], checks)
    # The recorded packets are those the official client received live: same sequence, same bytes.
    recorded = {}
    for m in json_packets[2]:
        v = json.loads(m.data)["value"]
        data = bytes(v["Data"])
        recorded[data[2] | (data[3] << 8)] = data
    # The official client's callbacks run on its own threads, behind the recorder on a busy machine: wait
    # until it has received the last recorded packet or a later one (the stream goes on).
    last = max(recorded)
    live = wait_for("the official client received packet %d live" % last,
                    lambda: (lambda got: got if any(seq_of(v)[0] >= last for _, v in got) else None)(listener.snapshot()))
    live_seqs = {seq_of(v)[0]: seq_of(v)[1] for _, v in live}
    common = set(recorded) & set(live_seqs)
    checks["live_packets"] = len(live_seqs)
    checks["recorded_packets_seen_live"] = len(common)
    # A wire keeps only the newest value for a client that is behind: the live client may have skipped
    # some recorded packets beside a CI run. Each it received has the recorded bytes; most were received.
    expect(all(recorded[s] == live_seqs[s] for s in common), "recorded packet bytes equal the live ones")
    expect(len(common) >= len(recorded) // 2, "most recorded packets were received live (%d of %d)" % (len(common), len(recorded)))
    # log_time spacing and publish_time (the device's packettime) present.
    times = [m.log_time for m in rr_packets[2]]
    expect(times == sorted(times), "log times increase")
    expect(all(m.publish_time > 0 for m in rr_packets[2]), "publish_time set")
    return rr_packets[2], channels[("create/DistanceTraveled", "json")][2], json_packets[2]


def record_phase(exe, work, seconds, checks):
    log = os.path.join(work, "gateway1.log")
    proc, port, base = start_gateway(exe, ["--recordings-root", work], log)  # requests name sub-folders of it
    try:
        client = RRN.ConnectService("rr+tcp://127.0.0.1:%d/?service=create" % port)
        listener = WireListener(client, "packets")
        client.play_callback.Function = lambda distance, angle: [60, 32]  # the robot asks what to play
        client.StartStreaming()
        client.Drive(200, 32767)  # DistanceTraveled changes while recorded
        status, rec = http(base, "POST", "/api/recordings",
                           {"device": "create", "members": ["packets", "Bump", "DistanceTraveled"],
                            "property_period_ms": 200, "directory": "rec", "chunk_bytes": 16384})
        expect(status == 201, "POST /api/recordings: %s %s" % (status, rec))
        expect(rec["state"] == "recording", "state recording")
        wait_for("GET /api/recordings counts messages", lambda: http(base, "GET", "/api/recordings")[1]["recordings"][0]["messages"] > 0)
        # The recording spans `seconds` (the replay below seeks to its middle packet) and holds, on
        # disk, what check_recording counts: more than 20 packets, 3 polled values.
        time.sleep(seconds)
        path = rec["files"][0]
        wait_for("21 packets recorded", lambda: len(recorded_so_far(path, "create/packets")) > 20, interval=0.5)
        wait_for("3 DistanceTraveled values recorded", lambda: len(recorded_so_far(path, "create/DistanceTraveled")) >= 3, interval=0.5)
        took, done = stop_recording(base, rec["id"])
        checks["recording"] = {k: done[k] for k in ("bytes", "messages", "drops", "duration_s", "files")}
        checks["stop_answered_s"] = round(took, 2)
        expect(done["drops"] == 0, "no drops")
        expect(done["files"] == [path], "one file: %s" % done["files"])
        rr_packets, props, json_packets = check_recording(path, listener, checks)

        # A sub-folder that cannot be made (a file in its way): a clear error, listed as failed; the gateway goes on.
        open(os.path.join(work, "blocked"), "w").close()
        status, err = http(base, "POST", "/api/recordings", {"device": "create", "directory": "blocked/dir"})
        expect(status == 507 and "blocked is not a folder" in err["error"]["message"], "unwritable directory: %s %s" % (status, err))
        status, listed = http(base, "GET", "/api/recordings")
        expect(any(r["state"] == "failed" and r["error"] for r in listed["recordings"]), "the failed recording is listed")

        # Disk full on a small tmpfs.
        checks["disk_full"] = disk_full(base, work)
        status, _ = http(base, "GET", "/api/devices")
        expect(status == 200, "the gateway serves after the failures")

        # Killed mid-recording: the file reads up to its last chunk.
        status, rec2 = http(base, "POST", "/api/recordings",
                            {"device": "create", "members": ["packets"], "directory": "killed",
                             "chunk_bytes": 4096})
        expect(status == 201, "second recording")
        killed = rec2["files"][0]
        wait_for("11 packets of the second recording on disk", lambda: len(recorded_so_far(killed, "create/packets")) > 10, interval=0.3)
        client.StopStreaming()
        RRN.DisconnectService(client)
        proc.send_signal(signal.SIGKILL)
        proc.wait(30)
        n, end = read_stream(killed)
        checks["killed_file"] = {"messages": n, "end": end}
        expect(n > 10, "a killed gateway's file reads up to its last chunk (%d messages)" % n)
        return path, rr_packets, props
    finally:
        stop(proc)


def disk_full(base, work):
    mnt = os.path.join(work, "tiny")
    os.makedirs(mnt)
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", mnt], capture_output=True, text=True)
    if r.returncode != 0:
        # Not root, or no CAP_SYS_ADMIN (a container): main() reports the test skipped (77) with this
        # reason once every other check passed.
        return "SKIP: cannot mount a tmpfs (%s)" % (r.stderr.strip() or "mount exit status %d" % r.returncode)
    try:
        # Leave about 24 KiB free, so that the recording fills it within a few seconds.
        with open(os.path.join(mnt, "filler"), "wb") as f:
            try:
                f.write(b"\0" * (1024 * 1024 - 24 * 1024))
            except OSError:
                pass
        status, rec = http(base, "POST", "/api/recordings",
                           {"device": "create", "members": ["packets"], "directory": "tiny", "chunk_bytes": 4096,
                            "compression": "none"})
        expect(status == 201, "recording on the small tmpfs starts: %s %s" % (status, rec))
        s = wait_for("the recording on the full tmpfs ends",
                     lambda: (lambda st: st if st["state"] in ("failed", "stopped") else None)(http(base, "GET", "/api/recordings/%d" % rec["id"])[1]))
        expect(s["state"] == "failed", "a full disk fails the recording (state %s)" % s["state"])
        expect("No space left on device" in s.get("error", ""), "the error says the disk is full: %r" % s.get("error"))
        return s["error"]
    finally:
        subprocess.run(["umount", "-l", mnt], capture_output=True)


def replay_phase(exe, work, path, rr_packets, props, tolerance_ms, checks):
    log = os.path.join(work, "gateway2.log")
    proc, port, base = start_gateway(exe, ["--no-demo", "--replay", path], log)
    try:
        status, st = http(base, "GET", "/api/replays/create")
        expect(status == 200 and st["state"] == "playing", "replay status: %s %s" % (status, st))
        recorded_seq = []
        # The recorded order (by sequence number, from the json channel of the same file).
        with open(path, "rb") as f:
            for _, ch, m in make_reader(f).iter_messages(topics=["create/packets"]):
                if ch.message_encoding == "json":
                    d = bytes(json.loads(m.data)["value"]["Data"])
                    recorded_seq.append((m.log_time, d[2] | (d[3] << 8)))
        # Start over with the listener connected, so every packet is seen.
        status, st = http(base, "POST", "/api/replays/create", {"state": "paused", "position_s": 0})
        expect(status == 200 and st["state"] == "paused", "pause at 0: %s %s" % (status, st))

        def gateway_wire_seq():
            status, w = http(base, "GET", "/api/devices/create/wires/packets")
            d = bytes(w["value"]["Data"]) if status == 200 else b"\0\0\0\0"
            return d[2] | (d[3] << 8)
        # The seek is applied by the replay's own thread after the reply: wait until the wire holds the
        # first recorded packet, so a packet played before the pause cannot reach the listener after it.
        wait_for("pause at 0: the wire holds the first recorded packet %d" % recorded_seq[0][1],
                 lambda: gateway_wire_seq() == recorded_seq[0][1], timeout=30)
        client = RRN.ConnectService("rr+tcp://127.0.0.1:%d/?service=create" % port)
        listener = WireListener(client, "packets")
        played_at = time.monotonic()
        status, st = http(base, "POST", "/api/replays/create", {"state": "playing"})
        expect(status == 200 and st["state"] == "playing", "play: %s %s" % (status, st))
        # Played up to the packet recorded min(span, 4) s after the first one (or a later one): the
        # packets received since play are judged (a value from the pause at 0 that arrives late is the
        # first recorded one, in order too).
        first_ns = recorded_seq[0][0]
        upto = max(i for i, (t, _) in enumerate(recorded_seq) if t - first_ns <= 4e9)
        later = {s for _, s in recorded_seq[upto:]}
        wait_for("the replay played the packet recorded %.1f s in, and more than 10 packets reached the client"
                 % ((recorded_seq[upto][0] - first_ns) / 1e9),
                 lambda: any(seq_of(v)[0] in later for t, v in listener.snapshot() if t >= played_at)
                 and len([t for t, _ in listener.snapshot() if t >= played_at]) > 10, timeout=90)
        got = [(t, v, sent) for t, v, sent in listener.snapshot_with_sent() if t >= played_at]
        expect(len(got) > 10, "replayed packets received (%d)" % len(got))
        # A wire keeps only the newest value for a client that is behind (docs/json-api.md), so the
        # received packets are the recorded ones in order, possibly with some skipped.
        seqs = [s for _, s in recorded_seq]
        index, pos, kept = [], 0, []
        for t, v, sent in got:
            s = seq_of(v)[0]
            # The pause at 0 left the first recorded packet on the wire; a listener that got it late (after
            # played_at) then gets it again when play starts at 0: once, at the start, it is not disorder
            # (and the later copy is the one whose spacing counts).
            if index == [0] and s == seqs[0]:
                kept[0] = (t, v, sent)
                continue
            while pos < len(seqs) and seqs[pos] != s:
                pos += 1
            expect(pos < len(seqs), "replayed packet %d is a recorded one, in the recorded order" % s)
            index.append(pos)
            kept.append((t, v, sent))
            pos += 1
        got = kept
        skipped = index[-1] - index[0] + 1 - len(index)
        checks["replayed_packets"] = {"received": len(got), "skipped": skipped}
        if tolerance_ms is not None:
            # The timing run: a client that keeps up (a calm machine) gets nearly every packet. Beside a CI
            # run the official client falls behind and its wire skips more: the order alone is judged there.
            expect(skipped <= len(got) // 10, "at most 10%% of the packets skipped by the wire (%d)" % skipped)
        # Spacing: each interval between received packets against the recorded one, by the times the
        # replay stamped on them as it sent them (its timer: what the replay keeps) and, reported, by
        # their arrival at this client (the official client's own thread and this process's scheduling
        # besides).
        def spacing_errors(when):
            e = sorted(abs((when(got[i]) - when(got[i - 1])) - (recorded_seq[index[i]][0] - recorded_seq[index[i - 1]][0]) / 1e9)
                       * 1000 for i in range(1, len(got)))
            return e, {"median": e[len(e) // 2], "p95": e[int(len(e) * 0.95)], "max": e[-1], "intervals": len(e)}
        errors, checks["spacing_error_ms"] = spacing_errors(lambda g: g[2])
        _, checks["arrival_spacing_error_ms"] = spacing_errors(lambda g: g[0])
        if tolerance_ms is None:
            checks["spacing_judged"] = "no (--spacing report): judged by the test labelled timing"
        else:
            # The run labelled timing: the calm phase of scripts/test.sh (nothing built or tested beside
            # it), so a miss is the replay's and fails.
            within = sum(1 for e in errors if e <= tolerance_ms)
            checks["spacing_judged"] = "load average %.1f on %d CPUs" % (os.getloadavg()[0], os.cpu_count() or 1)
            expect(within >= 0.95 * len(errors), "95%% of intervals within %.0f ms as sent: %s (at arrival: %s) (%s)"
                   % (tolerance_ms, checks["spacing_error_ms"], checks["arrival_spacing_error_ms"], checks["spacing_judged"]))

        # Seek lands on the right value: the wire and the property just after the middle packet (on a
        # busy machine the device's first packets can come seconds after the recording started, so a
        # fixed position could precede them all).
        position_s = seek_position(recorded_seq, [m.log_time for m in props], st["start_ns"])
        status, st = http(base, "POST", "/api/replays/create", {"state": "paused", "position_s": position_s})
        expect(status == 200, "seek: %s %s" % (status, st))
        target = st["start_ns"] + round(position_s * 1e9)
        want_seq = [s for t, s in recorded_seq if t <= target][-1]

        wire_seq = gateway_wire_seq
        # The seek's values reach the gateway's wire and the client's InValue as messages: waited for.
        wait_for("seek: wire value %d" % want_seq, lambda: wire_seq() == want_seq, timeout=30)
        wait_for("seek: official client's PeekInValue %d" % want_seq,
                 lambda: seq_of(client.packets.PeekInValue()[0])[0] == want_seq, timeout=30)
        want_prop = [json.loads(m.data)["value"] for m in props if m.log_time <= target][-1]
        status, p = http(base, "GET", "/api/devices/create/properties/DistanceTraveled")
        expect(status == 200 and p["value"] == want_prop, "seek: property %s, want %s" % (p, want_prop))
        checks["seek"] = {"position_s": position_s, "wire_seq": want_seq, "property": want_prop}

        # Functions are refused with a clear error.
        try:
            client.Drive(100, 32767)
            raise CheckFailed("Drive on a replayed device did not fail")
        except RR.InvalidOperationException as e:
            expect("recording" in str(e), "function refusal names the recording: %s" % e)
        status, err = http(base, "POST", "/api/devices/create/functions/Drive", {"args": [100, 32767]})
        expect(status >= 400 and "recording" in err["error"]["message"], "JSON API function refused: %s" % err)
        status, bad = http(base, "POST", "/api/replays/create", {"speed": 0})
        expect(status == 400, "speed 0 refused")
        RRN.DisconnectService(client)
    finally:
        code = stop(proc)
        checks["replay_gateway_exit"] = code


def seek_position(packets, other_times, start_ns):
    """A replay position (seconds from `start_ns`) 1 ms after the middle one of `packets` ([(log time
    ns, seq)]) and after the first of `other_times` (ns), so that a value of each precedes it."""
    expect(len(packets) > 0, "packets recorded")
    at = max([packets[len(packets) // 2][0]] + ([min(other_times)] if other_times else [])) + 1_000_000
    return (at - start_ns) / 1e9


def mcap_core_phase(exe, work, path, checks):
    """The recording rewritten by the TypeScript reference writer (@mcap/core) replays: its wire value
    after a seek is the recorded one."""
    node = shutil.which("node")
    script = os.path.join(os.path.dirname(__file__), "rewrite_with_mcap_core.mjs")
    if not node or not os.path.isdir(os.path.join(os.path.dirname(__file__), "..", "mcap", "node_modules", "@mcap")):
        checks["mcap_core_file"] = "SKIP: node or test/mcap/node_modules missing (run ./scripts/setup.sh)"
        return
    rewritten = os.path.join(work, "mcap_core.mcap")
    r = subprocess.run([node, script, path, rewritten], capture_output=True, text=True, timeout=60)
    expect(r.returncode == 0, "@mcap/core rewrite: %s" % r.stderr[-500:])
    proc, port, base = start_gateway(exe, ["--no-demo", "--replay", "ts_create=" + rewritten], os.path.join(work, "gateway3.log"))
    try:
        recorded = []
        with open(path, "rb") as f:
            for _, ch, m in make_reader(f).iter_messages(topics=["create/packets"]):
                if ch.message_encoding == "json":
                    d = bytes(json.loads(m.data)["value"]["Data"])
                    recorded.append((m.log_time, d[2] | (d[3] << 8)))
        status, st = http(base, "GET", "/api/replays/ts_create")
        expect(status == 200, "status of the @mcap/core file's replay: %s %s" % (status, st))
        position_s = seek_position(recorded, [], st["start_ns"])
        status, st = http(base, "POST", "/api/replays/ts_create", {"state": "paused", "position_s": position_s})
        expect(status == 200, "seek in the @mcap/core file: %s %s" % (status, st))
        target = st["start_ns"] + round(position_s * 1e9)
        want = [s for t, s in recorded if t <= target][-1]

        def wire_seq():
            status, w = http(base, "GET", "/api/devices/ts_create/wires/packets")
            expect(status == 200, "wire of the @mcap/core file's device: %s %s" % (status, w))
            d = bytes(w["value"]["Data"])
            return d[2] | (d[3] << 8)
        wait_for("the @mcap/core file replays the recorded value %d" % want, lambda: wire_seq() == want, timeout=30)
        checks["mcap_core_file"] = {"rewrite": json.loads(r.stdout), "position_s": position_s, "wire_seq": want}
    finally:
        stop(proc)


def chunk_records_middle(path, data):
    """Offset and length of bytes in the middle of the largest chunk's records (the part its CRC covers).

    The middle of the whole file can fall between chunks, in message index records that a reader
    following the summary's chunk indexes never reads: flipping those proves nothing."""
    with open(path, "rb") as f:
        chunks = make_reader(f).get_summary().chunk_indexes
    expect(chunks, "the recording has chunk indexes")
    c = max(chunks, key=lambda c: c.chunk_length)
    # chunk record: opcode u8, length u64, start u64, end u64, uncompressed size u64, crc u32,
    # compression string (u32 length + bytes), records length u64, records
    at = c.chunk_start_offset + 1 + 8 + 8 + 8 + 8 + 4
    at += 4 + int.from_bytes(data[at:at + 4], "little")
    records = int.from_bytes(data[at:at + 8], "little")
    at += 8
    expect(records >= 8, "the largest chunk holds records (%d bytes)" % records)
    span = min(64, records // 2)
    return at + (records - span) // 2, span


def corrupt_phase(exe, work, path, checks):
    cases = {}
    garbage = os.path.join(work, "garbage.mcap")
    with open(garbage, "wb") as f:
        f.write(os.urandom(4096))
    cut = os.path.join(work, "cut.mcap")
    with open(path, "rb") as f:
        data = f.read()
    with open(cut, "wb") as f:
        f.write(data[:40])  # magic and part of the header
    flipped = os.path.join(work, "flipped.mcap")
    mid, span = chunk_records_middle(path, data)
    with open(flipped, "wb") as f:
        f.write(data[:mid] + bytes(b ^ 0x5A for b in data[mid:mid + span]) + data[mid + span:])
    for name, p in (("garbage", garbage), ("cut", cut), ("missing", os.path.join(work, "none.mcap"))):
        r = subprocess.run([exe, "--listen", "127.0.0.1", "--port", "0", "--no-local", "--no-discovery", "--no-demo",
                            "--replay", p], capture_output=True, text=True, timeout=60)
        cases[name] = {"exit": r.returncode, "stderr": r.stderr.strip()[-300:]}
        expect(r.returncode == 2, "%s: exit status 2 (a start error), not a crash (%s)" % (name, r.returncode))
        expect(p in r.stderr, "%s: the error names the file" % name)
    # Bytes flipped inside a chunk: the file opens (its summary is intact); the chunk's CRC fails when
    # it is played, which ends the replay in state failed while the gateway goes on serving.
    proc, port, base = start_gateway(exe, ["--no-demo", "--replay", flipped], os.path.join(work, "gateway4.log"))
    try:
        http(base, "POST", "/api/replays/create", {"speed": 20})
        st = wait_for("the replay of the flipped file ends",
                      lambda: (lambda st: st if st["state"] in ("failed", "ended") else None)(http(base, "GET", "/api/replays/create")[1]))
        cases["flipped"] = {"state": st["state"], "error": st.get("error", "")}
        expect(st["state"] == "failed" and flipped in st.get("error", ""), "flipped chunk: replay failed naming the file: %s" % st)
        status, _ = http(base, "GET", "/api/devices")
        expect(status == 200, "the gateway serves after a failed replay")
    finally:
        code = stop(proc)
    expect(code == 0, "the gateway with a failed replay stops cleanly (%s)" % code)
    checks["corrupt"] = cases


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--tolerance-ms", type=float, default=5.0)
    ap.add_argument("--keep", action="store_true")
    ap.add_argument("--spacing", choices=["judge", "report"], default="judge",
                    help="report: measure the replay's spacing but leave judging it to a run on a quieter CPU")
    a = ap.parse_args()
    work = tempfile.mkdtemp(prefix="rr-record-test-")
    RRN.RegisterTransport(official_transport.client_tcp_transport(RR))
    checks = {}
    ok = False
    try:
        path, rr_packets, props = record_phase(a.gateway, work, a.seconds, checks)
        replay_phase(a.gateway, work, path, rr_packets, props, a.tolerance_ms if a.spacing == "judge" else None, checks)
        mcap_core_phase(a.gateway, work, path, checks)
        corrupt_phase(a.gateway, work, path, checks)
        ok = True
    except (CheckFailed, AssertionError, jsonschema.ValidationError, McapError, RR.RobotRaconteurException,
            OSError, KeyError, ValueError, IndexError) as e:
        checks["failed"] = "%s: %s" % (type(e).__name__, str(e)[:2000])
    finally:
        subprocess.run(["umount", "-l", os.path.join(work, "tiny")], capture_output=True)
        report_and_clean(checks, work, a.keep, failed=not ok)
    sys.exit(exit_status(ok, checks))


if __name__ == "__main__":
    main()
