#!/usr/bin/env python3
"""A replayed device served to every kind of client (docs/recording.md "Replay", "Which clients were
tested against a replay"):

  record   `rr record` of rr_interop_service: its w_state wire (a tick every 200 ms), the p_stream pipe
           (5 packets asked for by an official client), the ev_values event (3 fired) and the p_int32
           property (polled every second; the official client sets it from A to B halfway). Each step
           waits for the previous one's messages in the file on disk; SIGINT ends the recording once B
           is recorded. The reference reader (PyPI `mcap`) gives what was recorded.
  replay   `rr-gateway --no-demo --replay interop=FILE`, paused at 0 while four clients connect:
             rr+tcp  the official Python client to the gateway's TCP port,
             rr+ws   the official Python client over WebSocket to the same port,
             wasm    the wasm client (wasm-client/dist) in node over rr+ws (replay_clients_wasm.mjs),
             json    the JSON API WebSocket (subprotocol rr-gateway.json.v1), subscribed to the members.
           Then played to its end. Each client must have received: w_state values that are recorded ones
           in the recorded order (a wire may skip a value for a slow client, at most a third here) ending
           with the last recorded one; the 5 recorded pipe packets; the 3 recorded events; p_int32 =
           its last recorded value; add(1, 2) refused with InvalidOperation "… functions are not replayed".
  seek     POST /api/replays/interop {"position_s": T, "state": "paused"} with T just after the last
           p_int32 poll that read A: each client then sees the w_state value recorded at T (its wire's
           InValue, or the JSON push) and p_int32 = A again.

Prints one JSON summary; exit 0 when every check passed, 1 when one failed, 77 (SKIP, with the reason)
without the venv's packages, or when every other check passed but the wasm client could not run (node
or wasm-client/dist missing).
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
from child_procs import StepFailed, die_with_parent, read_json_line, stop  # noqa: E402
import official_transport  # noqa: E402  (the official client's transport, its connect timeout)
from record_checks import CheckFailed, expect, http, recorded_so_far, report_and_clean, wait_for  # noqa: E402

try:
    import websocket
    from mcap.reader import make_reader
    import RobotRaconteur as RR
except ImportError as e:  # pragma: no cover
    print("SKIP: %s (run ./scripts/setup.sh)" % e)
    sys.exit(77)

RRN = RR.RobotRaconteurNode.s
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
P_INT32_A, P_INT32_B = -2147483648, 2147483647  # the two values rr_interop_service accepts
REFUSAL = "functions are not replayed"


def inner_id(v):
    return v["id"] if isinstance(v, dict) else int(v.id)


# ---- record ----------------------------------------------------------------------------------------

def record(rr, service_exe, work, checks):
    """Records rr_interop_service with `rr record`; returns the file's path."""
    service = subprocess.Popen([service_exe, "--port", "0"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                               stdin=subprocess.DEVNULL, preexec_fn=die_with_parent)
    proc = None
    try:
        url = read_json_line(service, 60, "rr_interop_service")["url"]
        client = RRN.ConnectService(url)
        proc = subprocess.Popen([rr, "record", url, "--dir", os.path.join(work, "rec"),
                                 "--members", "w_state,p_stream,ev_values,p_int32"],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, stdin=subprocess.DEVNULL,
                                preexec_fn=die_with_parent)
        # The recorder says what it records (and its file) once its wire, pipe and event are connected.
        seen = []
        for line in proc.stderr:
            seen.append(line)
            if line.startswith("rr: recording"):
                break
        expect(seen and seen[-1].startswith("rr: recording") and seen[-1].rstrip().endswith(".mcap"),
               "rr record started: %r" % seen[-5:])
        path = seen[-1].rstrip().rsplit(" to ", 1)[1]

        def on_disk(topic, n):
            wait_for("%d %s messages in %s" % (n, topic, path), lambda: len(recorded_so_far(path, "interop/" + topic)) >= n,
                     timeout=90, interval=0.3)
        # Each step after the previous one is in the file, so the recording holds them in this order.
        on_disk("w_state", 5)
        on_disk("p_int32", 1)  # A
        client.send_stream(5)
        on_disk("p_stream", 5)
        client.fire_events(3)
        on_disk("ev_values", 3)
        on_disk("w_state", len(recorded_so_far(path, "interop/w_state")) + 3)
        client.p_int32 = P_INT32_B
        wait_for("p_int32 = B recorded", lambda: any(json.loads(d)["value"] == P_INT32_B
                                                       for d in recorded_so_far(path, "interop/p_int32")), timeout=90, interval=0.3)
        on_disk("w_state", len(recorded_so_far(path, "interop/w_state")) + 3)
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=120)
        expect(proc.returncode == 0, "rr record ends on SIGINT with 0 (rc=%s, %s)" % (proc.returncode, err[-1000:]))
        status = json.loads(out.strip().splitlines()[-1])
        RRN.DisconnectService(client)
        expect(status["drops"] == 0 and status["files"] == [path], "one file, no drops: %r" % status)
        checks["recording"] = {k: status[k] for k in ("messages", "bytes", "members")}
        return path
    finally:
        if proc is not None and proc.poll() is None:
            stop(proc)
        stop(service)


def recorded(path):
    """What the file holds (its json channels), each message as (log_time ns, value)."""
    out = {}
    with open(path, "rb") as f:
        for _, channel, m in make_reader(f).iter_messages():
            if channel.message_encoding == "json":
                out.setdefault(channel.topic.split("/", 1)[1], []).append((m.log_time, json.loads(m.data)))
    wire = [(t, inner_id(v["value"])) for t, v in out.get("w_state", [])]
    pipe = [[float(x) for x in v["value"]] for _, v in out.get("p_stream", [])]
    events = [[a["args"]["seq"], a["args"]["text"], a["args"]["data"]["id"]] for _, a in out.get("ev_values", [])]
    prop = [(t, v["value"]) for t, v in out.get("p_int32", [])]
    expect(len(wire) >= 5, "w_state recorded (%d values)" % len(wire))
    expect(pipe == [[float(i), i * 0.5] for i in range(5)], "the 5 pipe packets recorded: %r" % pipe)
    expect([e[0] for e in events] == [0, 1, 2], "the 3 events recorded: %r" % events)
    expect(prop and prop[0][1] == P_INT32_A and prop[-1][1] == P_INT32_B, "p_int32 recorded as A, then B: %r" % prop)
    return {"wire": wire, "pipe": pipe, "events": events, "property": prop}


# ---- clients ---------------------------------------------------------------------------------------

class OfficialClient:
    """The official Python client on one URL (rr+tcp or rr+ws), connected to w_state, p_stream, ev_values."""

    def __init__(self, url):
        self.lock = threading.Lock()
        self.wire, self.pipe, self.events = [], [], []
        self.c = RRN.ConnectService(url)
        self.w = self.c.w_state.Connect()
        self.w.WireValueChanged += self._on_value
        self.ep = self.c.p_stream.Connect(-1)
        self.ep.PacketReceivedEvent += self._on_packet
        self.c.ev_values += self._on_event

    def _on_value(self, conn, value, ts):
        with self.lock:
            self.wire.append(int(value.id))

    def _on_packet(self, ep):
        while ep.Available > 0:
            p = [float(x) for x in ep.ReceivePacket()]
            with self.lock:
                self.pipe.append(p)

    def _on_event(self, seq, text, data):
        with self.lock:
            self.events.append([int(seq), str(text), int(data.id)])

    def report(self):
        try:
            self.c.add(1, 2)
            refusal = None
        except RR.RobotRaconteurException as e:
            refusal = {"errorName": e.errorname, "message": str(e.message)}
        try:
            prop = self.c.p_int32
        except RR.RobotRaconteurException as e:
            prop = {"errorName": e.errorname, "message": str(e.message)}
        try:
            in_value = int(self.w.InValue.id)
        except RR.RobotRaconteurException:
            in_value = None
        with self.lock:
            return {"wire": list(self.wire), "in_value": in_value, "pipe": list(self.pipe), "events": list(self.events),
                    "property": prop, "function_error": refusal}

    def close(self):
        try:
            RRN.DisconnectService(self.c)
        except RR.RobotRaconteurException:
            pass


class JsonClient:
    """The JSON API WebSocket, subscribed to w_state, p_stream and ev_values of `device`."""

    def __init__(self, port, device):
        self.device = device
        self.ws = websocket.create_connection("ws://127.0.0.1:%d/" % port, subprotocols=["rr-gateway.json.v1"],
                                              timeout=30)
        self.lock = threading.Lock()
        self.replies = {}
        self.cond = threading.Condition(self.lock)
        self.pushes = {}
        self.next_id = 0
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()
        self.subs = {}
        for member in ("w_state", "p_stream", "ev_values"):
            r = self.request({"op": "subscribe", "device": device, "member": member})
            expect("result" in r, "json: subscribe %s: %r" % (member, r))
            self.subs[member] = r["result"]["subscription"]

    def _read(self):
        while True:
            try:
                msg = json.loads(self.ws.recv())
            except (websocket.WebSocketException, OSError, ValueError):
                return
            with self.cond:
                if "id" in msg:
                    self.replies[msg["id"]] = msg
                    self.cond.notify_all()
                elif "subscription" in msg:
                    self.pushes.setdefault(msg["subscription"], []).append(msg)

    def request(self, body, timeout=30):
        with self.cond:
            self.next_id += 1
            rid = self.next_id
        self.ws.send(json.dumps(dict(body, id=rid)))
        with self.cond:
            expect(self.cond.wait_for(lambda: rid in self.replies, timeout), "json: no answer to %r" % body)
            return self.replies.pop(rid)

    def report(self):
        call = self.request({"op": "call", "device": self.device, "member": "add", "args": [1, 2]})
        get = self.request({"op": "get", "device": self.device, "member": "p_int32"})
        with self.cond:
            wire = [p["value"]["id"] for p in self.pushes.get(self.subs["w_state"], []) if "value" in p]
            pipe = [[float(x) for x in p["value"]] for p in self.pushes.get(self.subs["p_stream"], []) if "value" in p]
            events = [[p["args"]["seq"], p["args"]["text"], p["args"]["data"]["id"]]
                      for p in self.pushes.get(self.subs["ev_values"], []) if "args" in p]
        return {"wire": wire, "in_value": wire[-1] if wire else None, "pipe": pipe, "events": events,
                "property": get["result"]["value"] if "result" in get else get.get("error"),
                "function_error": call.get("error")}

    def close(self):
        self.ws.close()


class WasmClient:
    """replay_clients_wasm.mjs in node: the wasm client over rr+ws."""

    def __init__(self, node, url, log):
        with open(log, "wb") as errf:
            self.proc = subprocess.Popen([node, os.path.join(HERE, "replay_clients_wasm.mjs"), url], stdin=subprocess.PIPE,
                                         stdout=subprocess.PIPE, stderr=errf, preexec_fn=die_with_parent)
        try:
            ready = read_json_line(self.proc, 60, "replay_clients_wasm.mjs")
        except StepFailed as e:
            raise CheckFailed("wasm client: %s: %s" % (e, open(log, errors="replace").read()[-800:]))
        expect(ready.get("ready"), "wasm client ready: %r" % ready)

    def report(self):
        self.proc.stdin.write(b"report\n")
        self.proc.stdin.flush()
        return read_json_line(self.proc, 30, "wasm client report")

    def close(self):
        try:
            self.proc.stdin.write(b"quit\n")
            self.proc.stdin.flush()
        except OSError:
            pass
        stop(self.proc)


def wasm_prerequisite():
    """None when the wasm client can run here, else the reason it cannot."""
    node = shutil.which("node")
    if not node:
        return None, "node is not installed"
    if not os.path.exists(os.path.join(ROOT, "wasm-client", "dist", "robotraconteur.mjs")):
        return None, "wasm-client/dist missing (run wasm-client/build.sh)"
    if not os.path.isdir(os.path.join(ROOT, "wasm-client", "node_modules", "ws")):
        return None, "wasm-client/node_modules/ws missing (run ./scripts/setup.sh)"
    return node, None


# ---- checks ----------------------------------------------------------------------------------------

def check_played(name, got, rec):
    """A client's report after the replay played to its end, against the recording."""
    ids = [i for _, i in rec["wire"]]
    # A client may get a value twice (the value at the paused position, then the same one played):
    # compare the sequence without repeats.
    received = [i for k, i in enumerate(got["wire"]) if k == 0 or got["wire"][k - 1] != i]
    pos, index = 0, []
    for i in received:
        while pos < len(ids) and ids[pos] != i:
            pos += 1
        expect(pos < len(ids), "%s: w_state %d received is a recorded value in the recorded order (received %r, "
               "recorded %r)" % (name, i, got["wire"], ids))
        index.append(pos)
        pos += 1
    # Values from the seek to 0 before playing are recorded ones too; those played are the rest.
    played = sorted(set(index))
    expect(len(played) >= len(ids) * 2 // 3, "%s: most recorded w_state values received (%d of %d)"
           % (name, len(played), len(ids)))
    expect(got["wire"] and got["wire"][-1] == ids[-1], "%s: the last w_state value is the last recorded one" % name)
    expect(got["pipe"] == rec["pipe"], "%s: the recorded pipe packets: %r" % (name, got["pipe"]))
    events = got["events"]
    if name.startswith("rr+"):
        # The official client runs event handlers on its thread pool: events sent microseconds apart (the
        # service fired them back to back) may reach the handlers in any order. The others keep the order.
        events = sorted(events)
    expect(events == rec["events"], "%s: the recorded events: %r, want %r" % (name, got["events"], rec["events"]))
    want_prop = rec["property"][-1][1]
    expect(got["property"] == want_prop, "%s: p_int32 at the end is %r, want %r" % (name, got["property"], want_prop))
    err = got["function_error"] or {}
    expect(err.get("errorName", err.get("name")) == "RobotRaconteur.InvalidOperation" and REFUSAL in err.get("message", ""),
           "%s: add() refused with InvalidOperation '%s': %r" % (name, REFUSAL, got["function_error"]))
    return {"wire_received": len(got["wire"]), "pipe": len(got["pipe"]), "events": len(got["events"]),
            "property": got["property"], "refusal": err.get("message")}


def replay(gateway, path, rec, work, checks):
    log = os.path.join(work, "gateway.log")
    with open(log, "wb") as errf:
        proc = subprocess.Popen([gateway, "--listen", "127.0.0.1", "--port", "0", "--no-local", "--no-discovery",
                                 "--no-demo", "--replay", "interop=" + path],
                                stdout=subprocess.PIPE, stderr=errf, stdin=subprocess.DEVNULL, preexec_fn=die_with_parent)
    clients = {}
    wasm_skip = None
    try:
        port = read_json_line(proc, 60, "rr-gateway")["port"]
        base = "http://127.0.0.1:%d" % port
        deadline = time.monotonic() + 30
        while True:
            try:
                with urllib.request.urlopen(base + "/readyz", timeout=5) as r:
                    if r.status == 200:
                        break
            except (urllib.error.URLError, OSError):
                pass
            expect(time.monotonic() < deadline, "rr-gateway ready: " + open(log, errors="replace").read()[-1500:])
            time.sleep(0.1)
        status, st = http(base, "POST", "/api/replays/interop", {"state": "paused", "position_s": 0})
        expect(status == 200 and st["state"] == "paused", "pause at 0: %s %r" % (status, st))
        start_ns, duration_s = st["start_ns"], st["duration_s"]
        clients["rr+tcp"] = OfficialClient("rr+tcp://127.0.0.1:%d/?service=interop" % port)
        clients["rr+ws"] = OfficialClient("rr+ws://127.0.0.1:%d/?service=interop" % port)
        node, wasm_skip = wasm_prerequisite()
        if node:
            clients["wasm"] = WasmClient(node, "rr+ws://127.0.0.1:%d/?service=interop" % port, os.path.join(work, "wasm.log"))
        clients["json"] = JsonClient(port, "interop")
        status, st = http(base, "POST", "/api/replays/interop", {"state": "playing"})
        expect(status == 200 and st["state"] == "playing", "play: %s %r" % (status, st))
        deadline = time.monotonic() + 2 * duration_s + 60  # a bound on a hang
        while st["state"] == "playing" and time.monotonic() < deadline:
            time.sleep(0.2)
            _, st = http(base, "GET", "/api/replays/interop")
        expect(st["state"] == "ended", "the replay ends (state %s after %.1f s)" % (st["state"], duration_s))
        played = {}
        last_id, n_events = rec["wire"][-1][1], len(rec["events"])
        for name, c in clients.items():
            # The last values may still be on their way to a client: wait (bounded) for the last recorded
            # w_state value, the pipe packets and the events, then judge that report.
            box = {}

            def arrived():
                box["got"] = c.report()
                got = box["got"]
                return got["wire"] and got["wire"][-1] == last_id and len(got["pipe"]) >= len(rec["pipe"]) and len(got["events"]) >= n_events
            try:
                wait_for("%s: the last recorded values arrive" % name, arrived, timeout=30, interval=0.3)
            except CheckFailed:
                pass  # check_played says what is missing
            played[name] = check_played(name, box["got"], rec)
        checks["played"] = played

        # Seek back to just after the last p_int32 poll that read A (before the set to B), paused: every
        # client sees the wire value and the property of that position.
        t_ns = [t for t, v in rec["property"] if v == P_INT32_A][-1] + 50_000_000
        want_wire = [i for t, i in rec["wire"] if t <= t_ns]
        if not want_wire:
            t_ns = rec["wire"][0][0] + 50_000_000
            want_wire = [rec["wire"][0][1]]
        want_prop = [v for t, v in rec["property"] if t <= t_ns]
        expect(want_prop and want_prop[-1] == P_INT32_A, "the seek's position precedes the set to B")
        position_s = (t_ns - start_ns) / 1e9
        status, st = http(base, "POST", "/api/replays/interop", {"position_s": position_s, "state": "paused"})
        expect(status == 200, "seek: %s %r" % (status, st))
        seek = {"position_s": round(position_s, 3), "w_state": want_wire[-1]}
        deadline = time.monotonic() + 30
        for name, c in clients.items():
            while True:
                got = c.report()
                if got["in_value"] == want_wire[-1] or time.monotonic() > deadline:
                    break
                time.sleep(0.2)
            expect(got["in_value"] == want_wire[-1], "%s after the seek: w_state %r, want %r"
                   % (name, got["in_value"], want_wire[-1]))
            expect(got["property"] == P_INT32_A, "%s after the seek: p_int32 %r, want A" % (name, got["property"]))
            seek[name] = "w_state %d, p_int32 A" % got["in_value"]
        checks["seek"] = seek
    finally:
        for c in clients.values():
            c.close()
        checks["gateway_exit"] = stop(proc)
    return wasm_skip


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--rr", required=True)
    ap.add_argument("--service", required=True, help="rr_interop_service")
    ap.add_argument("--keep", action="store_true")
    a = ap.parse_args()
    work = tempfile.mkdtemp(prefix="rr-replay-clients-")
    RRN.RegisterTransport(official_transport.client_tcp_transport(RR))
    checks = {}
    ok, wasm_skip = False, None
    try:
        path = record(a.rr, a.service, work, checks)
        rec = recorded(path)
        checks["recorded"] = {"w_state": len(rec["wire"]), "pipe": len(rec["pipe"]), "events": len(rec["events"]),
                              "p_int32": [v for _, v in rec["property"]]}
        wasm_skip = replay(a.gateway, path, rec, work, checks)
        ok = True
    except (CheckFailed, StepFailed, AssertionError, RR.RobotRaconteurException, OSError, KeyError, ValueError,
            IndexError, TypeError, subprocess.TimeoutExpired, websocket.WebSocketException) as e:
        checks["failed"] = "%s: %s" % (type(e).__name__, str(e)[:2000])
    finally:
        report_and_clean(checks, work, a.keep, failed=not ok)
    if ok and wasm_skip:
        print("SKIP: every other client passed; the wasm client was not run: %s" % wasm_skip)
        sys.exit(77)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
