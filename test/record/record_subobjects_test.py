#!/usr/bin/env python3
"""Members of objects below a device's root object, recorded and replayed (docs/recording.md "Objects
below the root", issue 44).

rr-gateway with its demo devices: the `webcam` device (experimental.createwebcam.WebcamHost) has its
cameras behind the objref `Webcams{int32}`. Recorded through the JSON API: `Webcams[0].FrameStream`
(a pipe, streaming) and the `Name` property of `Webcams[0]` and `Webcams[1]`, both encodings. Checked:
- names that do not lead to a member get 400 naming the problem (no index, no such objref or member,
  a property used as an objref);
- the status's `connecting` turns 0 once the pipe is connected; 3 frames and the names are waited for
  in the file on disk, then the stop answers `stopped` (its time is reported: it took over 60 s under a
  CI load while each frame's JSON was a tree of numbers);
- the reference reader (PyPI mcap) lists channels `webcam/Webcams[0]/FrameStream`, ... with metadata
  `path`, `object_type` experimental.createwebcam.Webcam and `root_type`, and the frames;
- `rr-gateway --replay FILE`: an official client (rr+tcp) gets `Webcams[0]` and `Webcams[1]` through
  the objref, reads their recorded names, receives on `Webcams[0].FrameStream` frames that were
  recorded, is refused a function and an object that was not recorded; the JSON API reads
  `Name?object=Webcams[1]`.

  record_subobjects_test.py --gateway build/debug/server/app/rr-gateway
Prints a JSON summary (on a failure also the gateways' logs, the work folder kept); exit 0, 1 (a check
failed) or 77 (the venv's packages are missing).
"""
import argparse
import hashlib
import json
import os
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "interop"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from child_procs import stop  # noqa: E402
import official_transport  # noqa: E402  (the official client's transport, its connect timeout)
from record_checks import CheckFailed, expect, http, recorded_so_far, report_and_clean, stop_recording, wait_for  # noqa: E402
from record_replay_test import start_gateway  # noqa: E402

try:
    from mcap.reader import make_reader
    import RobotRaconteur as RR
except ImportError as e:  # pragma: no cover
    print("SKIP: %s (run ./scripts/setup.sh)" % e)
    sys.exit(77)

RRN = RR.RobotRaconteurNode.s


def frame_digest(width, height, data):
    return hashlib.sha256(b"%d,%d," % (width, height) + bytes(bytearray(data))).hexdigest()


def record_phase(exe, work, checks):
    proc, port, base = start_gateway(exe, ["--recordings-root", work], os.path.join(work, "gateway.log"))
    try:
        wait_for("the webcam device connected",
                 lambda: any(d["name"] == "webcam" and d["state"] == "connected" for d in http(base, "GET", "/api/devices")[1] or []))
        bad = {}
        for name, want in (("Webcams.FrameStream", "needs an index"), ("Webcams[0].Nope", "has no member \"Nope\""),
                           ("Nothing[0].Name", "has no member \"Nothing\""),
                           ("WebcamNames.Name", "is a property, not an objref"), ("Webcams[0.Name", "without ']'")):
            status, body = http(base, "POST", "/api/recordings", {"device": "webcam", "members": [name]})
            message = (body or {}).get("error", {}).get("message", "")
            bad[name] = [status, message]
            expect(status == 400 and want in message, "%s: 400 with \"%s\", got %s %s" % (name, want, status, message))
        checks["refused_names"] = bad
        status, body = http(base, "POST", "/api/devices/webcam/functions/StartStreaming?object=Webcams%5B0%5D", {})
        expect(status == 200, "StartStreaming on Webcams[0]: %s %s" % (status, body))
        members = ["Webcams[0].FrameStream", "Webcams[0].Name", "Webcams[1].Name"]
        status, rec = http(base, "POST", "/api/recordings",
                           {"device": "webcam", "members": members, "property_period_ms": 200})
        expect(status == 201, "POST /api/recordings: %s %s" % (status, rec))
        expect(rec["members"] == members, "the status names the members with their objects: %s" % rec["members"])
        live_names = {}
        for i in (0, 1):
            status, body = http(base, "GET", "/api/devices/webcam/properties/Name?object=Webcams%%5B%d%%5D" % i)
            live_names[i] = body["value"]
        # "connecting": the pipe's connection not answered yet, then 0 (docs/recording.md "JSON API").
        expect(isinstance(rec.get("connecting"), int) and 0 <= rec["connecting"] <= 1, "connecting in the status: %s" % rec)
        wait_for("the recording's pipe connected (connecting 0)",
                 lambda: http(base, "GET", "/api/recordings/%d" % rec["id"])[1]["connecting"] == 0)
        # Recorded on disk (the writer flushes a chunk at least every second): 3 frames and each name.
        path = rec["files"][-1]
        for topic, n in (("webcam/Webcams[0]/FrameStream", 3), ("webcam/Webcams[0]/Name", 1), ("webcam/Webcams[1]/Name", 1)):
            wait_for("%d %s messages in %s" % (n, topic, path), lambda: len(recorded_so_far(path, topic)) >= n, timeout=90, interval=0.5)
        took, done = stop_recording(base, rec["id"])
        checks["recording"] = {k: done[k] for k in ("messages", "drops", "files", "members")}
        checks["stop_answered_s"] = round(took, 2)
        return done["files"][-1], live_names
    finally:
        stop(proc)


def read_file(path, checks):
    channels, frames = {}, []
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        for c in summary.channels.values():
            schema = summary.schemas.get(c.schema_id)
            channels[(c.topic, c.message_encoding)] = {"path": c.metadata.get("path"), "object_type": c.metadata.get("object_type"),
                                                       "root_type": c.metadata.get("root_type"), "schema": schema.name if schema else None,
                                                       "messages": summary.statistics.channel_message_counts.get(c.id, 0)}
        for _, ch, m in reader.iter_messages(topics=["webcam/Webcams[0]/FrameStream"]):
            if ch.message_encoding == "json":
                v = json.loads(m.data)["value"]
                frames.append(frame_digest(v["width"], v["height"], v["data"]))
    checks["channels"] = {"%s [%s]" % k: v for k, v in sorted(channels.items())}
    for topic in ("webcam/Webcams[0]/FrameStream", "webcam/Webcams[0]/Name", "webcam/Webcams[1]/Name"):
        for enc in ("json", "robotraconteur"):
            c = channels.get((topic, enc))
            expect(c is not None, "channel %s [%s] in the file" % (topic, enc))
            expect(c["path"] == topic.split("/")[1], "%s: metadata path %s" % (topic, c["path"]))
            expect(c["object_type"] == "experimental.createwebcam.Webcam", "%s: object_type %s" % (topic, c["object_type"]))
            expect(c["root_type"] == "experimental.createwebcam.WebcamHost", "%s: root_type %s" % (topic, c["root_type"]))
            expect(c["messages"] > 0, "%s [%s]: messages recorded" % (topic, enc))
        expect(channels[(topic, "robotraconteur")]["schema"] == "experimental.createwebcam",
               "%s: the robotraconteur channel's schema is the definition of its object" % topic)
    expect(len(frames) >= 3, "frames recorded: %d" % len(frames))
    return set(frames)


def replay_phase(exe, work, path, recorded_frames, live_names, checks):
    proc, port, base = start_gateway(exe, ["--no-demo", "--replay", path], os.path.join(work, "replay.log"))
    try:
        status, st = http(base, "POST", "/api/replays/webcam", {"loop": True})
        expect(status == 200, "replay control: %s %s" % (status, st))
        expect(sorted(st["members"]) == sorted(["Webcams[0].FrameStream", "Webcams[0].Name", "Webcams[1].Name"]),
               "the replay's members: %s" % st["members"])
        c = RRN.ConnectService("rr+tcp://127.0.0.1:%d/?service=webcam" % port)
        try:
            cams = [c.get_Webcams(0), c.get_Webcams(1)]
            got = {}

            def names_read():
                try:
                    got.update({i: cams[i].Name for i in (0, 1)})
                    return True
                except RR.RobotRaconteurException:  # ValueNotSet until the first polled value is played
                    return False
            wait_for("the recorded names played", names_read, timeout=60)
            expect(got == live_names, "recorded names through the objref: %s, live %s" % (got, live_names))
            status, body = http(base, "GET", "/api/devices/webcam/properties/Name?object=Webcams%5B1%5D")
            expect(status == 200 and body["value"] == live_names[1], "JSON API Name?object=Webcams[1]: %s %s" % (status, body))

            received, lock, arrived = [], threading.Lock(), threading.Event()
            ep = cams[0].FrameStream.Connect(-1)

            def on_packet(e):
                while e.Available > 0:
                    p = e.ReceivePacket()
                    with lock:
                        received.append(frame_digest(p.width, p.height, p.data))
                        if len(received) >= 3:
                            arrived.set()
            ep.PacketReceivedEvent += on_packet
            expect(arrived.wait(60), "frames through Webcams[0].FrameStream: %d" % len(received))
            ep.Close()
            with lock:
                unknown = [d for d in received if d not in recorded_frames]
            expect(not unknown, "every replayed frame is a recorded one (%d of %d not)" % (len(unknown), len(received)))
            checks["replayed_frames"] = len(received)

            refusals = {}
            try:
                cams[0].CaptureFrame()
                refusals["function"] = None
            except RR.RobotRaconteurException as e:
                refusals["function"] = str(e)
            try:
                c.get_Webcams(5).Name
                refusals["object"] = None
            except RR.RobotRaconteurException as e:
                refusals["object"] = str(e)
            checks["refused"] = refusals
            expect(refusals["function"] and "functions are not replayed" in refusals["function"], "a function is refused: %s" % refusals)
            expect(refusals["object"] and "was not recorded" in refusals["object"], "an object not recorded: %s" % refusals)
        finally:
            RRN.DisconnectService(c)
    finally:
        code = stop(proc)
    expect(code == 0, "the replaying gateway stops cleanly (%s)" % code)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--keep", action="store_true")
    a = ap.parse_args()
    work = tempfile.mkdtemp(prefix="rr-record-sub-")
    RRN.RegisterTransport(official_transport.client_tcp_transport(RR))
    checks = {}
    ok = False
    try:
        path, live_names = record_phase(a.gateway, work, checks)
        frames = read_file(path, checks)
        replay_phase(a.gateway, work, path, frames, live_names, checks)
        ok = True
    except (CheckFailed, AssertionError, RR.RobotRaconteurException, OSError, KeyError, ValueError, TypeError) as e:
        checks["failed"] = "%s: %s" % (type(e).__name__, str(e)[:2000])
    finally:
        report_and_clean(checks, work, a.keep, failed=not ok)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
