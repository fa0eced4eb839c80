#!/usr/bin/env python3
"""String tables (wire.md §2.6) with the official library, both ways, and through the gateway.

A peer whose transport leaves the string table on (the official TcpTransport with
DisableStringTable = False) sends entry and element names as codes: standard ones and message-local
ones defined in each message's header. Every run puts a recording proxy (recording_proxy.py) between
the peer that uses codes and us, and fails unless that peer really sent codes; then:

--part direct    rr_interop_client (our C++ client) -> proxy -> official_service.py --enable-stringtable:
                 every check of official_client.py with our client session decoding the codes.
--part gateway   rr-gateway -> proxy -> official_service.py --enable-stringtable, reached through the
                 gateway by
                   * the official client (official_client.py, which offers string tables; the gateway,
                     like a stock official server, does not take them): every member kind,
                   * our client (rr_interop_client): the same checks,
                   * the JSON API: a struct property over REST, a function returning a struct, and over the
                     JSON WebSocket an event with a struct argument, a struct wire's values and a struct
                     pipe's echo,
                   * a recording (POST /api/recordings, encoding robotraconteur): every recorded RR entry
                     is free of string-table codes (the bytes stand alone for replay and other tools);
                 and the gateway must not have logged an encoding error.
--part service   official_client.py (string tables on) -> proxy -> rr_interop_service --enable-stringtable
                 (our service takes the string table): every check, with --single-connection (the official
                 1.x client cannot open a second connection to a service that uses string tables).

Prints one JSON summary; exit 0 when every check passed, 1 on a failed check, 2 on a setup error, 77
when the official package or websocket-client is missing.

Usage: string_table_interop.py --part direct|gateway|service [--gateway PATH] [--client PATH]
                               [--service PATH] [--keep DIR]
"""

import argparse
import atexit
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import urllib.request

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from child_procs import StepFailed, read_json_line, start, stop, tail  # noqa: E402
import capture_summary  # noqa: E402

START_S = 60
CLIENT_S = 170


def skip(why):
    print("SKIP: %s" % why, flush=True)
    sys.exit(77)


class Checks:
    def __init__(self):
        self.results = []

    def check(self, name, fn):
        t0 = time.monotonic()
        try:
            fn()
            self.results.append({"check": name, "ok": True, "s": round(time.monotonic() - t0, 1)})
            print("[string_table] ok   %s" % name, file=sys.stderr, flush=True)
        except Exception as e:  # noqa: BLE001  (every failure is reported by name)
            self.results.append({"check": name, "ok": False, "error": "%s: %s" % (type(e).__name__, e)})
            print("[string_table] FAIL %s: %s: %s" % (name, type(e).__name__, e), file=sys.stderr, flush=True)

    def ok(self):
        return bool(self.results) and all(r["ok"] for r in self.results)


def expect(cond, what):
    if not cond:
        raise AssertionError(what)


def http(port, method, path, body=None):
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request("http://127.0.0.1:%d%s" % (port, path), data=data, method=method,
                                 headers={"content-type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=30) as r:
            return r.status, json.loads(r.read() or b"null")
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read() or b"null")


def run(cmd, log, timeout):
    """Runs a client to its end; StepFailed with its output's tail unless it exits 0."""
    with open(log, "wb") as f:
        try:
            rc = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                timeout=timeout).returncode
        except subprocess.TimeoutExpired:
            raise StepFailed("%s did not finish within %.0f s:\n%s" % (os.path.basename(cmd[0]), timeout, tail(log, 30)))
    if rc != 0:
        raise StepFailed("%s exited with %s:\n%s" % (os.path.basename(cmd[0]), rc, tail(log, 30)))


def coded_messages(capture, kind):
    """(messages, messages with string-table codes) of direction `kind` ('C' client->server, 'S')."""
    total = coded = 0
    for k, _conn, data in capture_summary.read_records(capture):
        if k != kind:
            continue
        total += 1
        if capture_summary.parse_message(data)["string_table_codes"]:
            coded += 1
    return total, coded


def start_proxy(target_port, workdir, name):
    capture = os.path.join(workdir, name + ".rrcap")
    proc = start([sys.executable, "-u", os.path.join(HERE, "recording_proxy.py"), "--target",
                  "127.0.0.1:%d" % target_port, "--capture", capture, "--max-lifetime", "290"],
                 os.path.join(workdir, name + ".stderr"))
    ready = read_json_line(proc, START_S, "recording_proxy.py")
    return proc, ready["port"], capture


def start_official_device(workdir):
    proc = start([sys.executable, "-u", os.path.join(HERE, "official_service.py"), "--port", "0",
                  "--enable-stringtable", "--max-lifetime", "290"], os.path.join(workdir, "device.stderr"))
    return proc, read_json_line(proc, START_S, "official_service.py")


class JsonSocket:
    """The gateway's JSON WebSocket: ask() returns a request's reply, keeping pushes for wait_push()."""

    def __init__(self, port):
        import websocket  # websocket-client
        self.websocket = websocket
        self.ws = websocket.create_connection("ws://127.0.0.1:%d/" % port, subprotocols=["rr-gateway.json.v1"], timeout=30)
        self.counter = 0
        self.pushes = []

    def ask(self, msg):
        self.counter += 1
        msg = dict(msg, id=self.counter)
        self.ws.send(json.dumps(msg))
        while True:
            r = json.loads(self.ws.recv())
            if r.get("id") == msg["id"]:
                expect("result" in r, "%s: %r" % (msg["op"], r))
                return r["result"]
            if "subscription" in r:
                self.pushes.append(r)

    def wait_push(self, pred, what, timeout=30.0):
        deadline = time.monotonic() + timeout
        while True:
            for p in self.pushes:
                if pred(p):
                    self.pushes.remove(p)
                    return p
            left = deadline - time.monotonic()
            expect(left > 0, "no push: %s (last pushes %r)" % (what, self.pushes[-3:]))
            self.ws.settimeout(left)
            try:
                r = json.loads(self.ws.recv())
            except self.websocket.WebSocketTimeoutException:
                continue
            finally:
                self.ws.settimeout(30)
            if "subscription" in r:
                self.pushes.append(r)

    def close(self):
        self.ws.close()


def inner(i, label, values):
    """interop_values.inner as the JSON mapping shows it (struct -> object of its fields)."""
    return {"id": i, "label": label, "values": values}


def json_checks(ck, port):
    dev = "/api/devices/interop"

    def rest_property():
        status, body = http(port, "GET", dev + "/properties/s_inner")
        expect(status == 200, "GET s_inner: %s %r" % (status, body))
        expect(body.get("value") == inner(1, "inner 1 \u00e9", [1.0, 1.5, -1.0]), "s_inner: %r" % body)

    def rest_function():
        status, body = http(port, "POST", dev + "/functions/make_inner", {"args": [7, "seven", [0.5, 2.0]]})
        expect(status == 200, "make_inner: %s %r" % (status, body))
        expect(body.get("return") == inner(7, "seven", [0.5, 2.0]), "make_inner: %r" % body)

    def socket_members():
        s = JsonSocket(port)
        try:
            sub_e = s.ask({"op": "subscribe", "device": "interop", "member": "ev_values"})["subscription"]
            s.ask({"op": "call", "device": "interop", "member": "fire_events", "args": [2]})
            for seq in (0, 1):
                p = s.wait_push(lambda p: p.get("subscription") == sub_e and p.get("kind") == "event"
                                and (p.get("args") or {}).get("seq") == seq, "ev_values(seq=%d)" % seq)
                expect(isinstance(p["args"].get("data"), dict) and p["args"]["data"].get("id") is not None,
                       "event data is a struct: %r" % p)
            # w_state also ticks every 0.2 s, and a JSON socket gets a wire's newest value (a tick may
            # replace the asked one before it is pushed): asked again, a few times at most.
            sub_w = s.ask({"op": "subscribe", "device": "interop", "member": "w_state"})["subscription"]
            s.wait_push(lambda p: p.get("subscription") == sub_w and isinstance(p.get("value"), dict)
                        and sorted(p["value"]) == ["id", "label", "values"], "a w_state value")
            for attempt in range(5):
                s.ask({"op": "call", "device": "interop", "member": "update_state", "args": [41]})
                try:
                    s.wait_push(lambda p: p.get("subscription") == sub_w and p.get("value") == inner(41, "demand", [10.25]),
                                "w_state after update_state(41)", timeout=10.0)
                    break
                except AssertionError:
                    if attempt == 4:
                        raise
            sub_p = s.ask({"op": "subscribe", "device": "interop", "member": "p_echo"})["subscription"]
            s.ask({"op": "send", "subscription": sub_p, "value": inner(3, "echo me", [1.0])})
            s.wait_push(lambda p: p.get("subscription") == sub_p and p.get("value") == inner(3, "echo me", [1.0]),
                        "p_echo's echo")
        finally:
            s.close()

    ck.check("json: REST struct property (names from codes)", rest_property)
    ck.check("json: REST function returning a struct", rest_function)
    ck.check("json: WebSocket event, wire and pipe of structs", socket_members)


def entry_has_codes(entry):
    """Whether one recorded RR entry (message format 4, wire.md §2.4) uses string-table codes: it is
    wrapped in a one-entry v4 message (header flags 0) and read by capture_summary."""
    header_len = 12  # magic, MessageSize, version, HeaderLen (1 byte), flags
    msg = b"RRAC" + struct.pack("<IHBB", header_len + len(entry), 4, header_len, 0) + entry
    return capture_summary.parse_message(msg)["string_table_codes"]


def recording_check(ck, port, workdir):
    def record():
        # The gateway's recordings root is workdir (--recordings-root); a request names a sub-folder.
        status, st = http(port, "POST", "/api/recordings",
                          {"device": "interop", "members": ["w_state", "ev_values"], "encoding": ["robotraconteur"],
                           "directory": "rec", "compression": "none"})
        expect(status == 201, "start recording: %s %r" % (status, st))
        rid = st["id"]
        s = JsonSocket(port)
        try:
            for seq in range(3):
                s.ask({"op": "call", "device": "interop", "member": "update_state", "args": [100 + seq]})
            s.ask({"op": "call", "device": "interop", "member": "fire_events", "args": [3]})
        finally:
            s.close()
        # The recording has seen them all once its message count covers them (each wire value and event
        # is one message; the device's own periodic w_state ticks add more).
        deadline = time.monotonic() + 30
        while True:
            status, st = http(port, "GET", "/api/recordings/%d" % rid)
            if st.get("messages", 0) >= 7 or time.monotonic() > deadline:
                break
            time.sleep(0.2)
        status, st = http(port, "POST", "/api/recordings/%d/stop" % rid)
        expect(status == 200 and st.get("state") == "stopped", "stop: %s %r" % (status, st))
        expect(st.get("drops", 0) == 0, "recording dropped entries: %r" % st)
        from mcap.reader import make_reader
        topics, coded, total = {}, 0, 0
        for path in st["files"]:
            with open(path, "rb") as f:
                for _schema, channel, message in make_reader(f).iter_messages():
                    if channel.message_encoding != "robotraconteur":
                        continue
                    total += 1
                    topics[channel.topic] = topics.get(channel.topic, 0) + 1
                    if entry_has_codes(message.data):
                        coded += 1
        counts = sorted(topics.values())
        expect(len(counts) == 2 and counts[0] >= 3 and total >= 7, "recorded RR entries per topic: %r (status %r)" % (topics, st))
        expect(coded == 0, "%d of %d recorded RR entries use string-table codes" % (coded, total))

    ck.check("recording: RR entries of a string-table device are stored without codes", record)


def part_direct(args, ck, workdir, procs):
    device, ready = start_official_device(workdir)
    procs.append(device)
    proxy, pport, capture = start_proxy(ready["port"], workdir, "device")
    procs.append(proxy)
    url = "rr+tcp://127.0.0.1:%d/?service=interop" % pport
    ck.check("our client -> official service with string tables: every check",
             lambda: run([args.client, url, "--timeout", str(CLIENT_S - 20)], os.path.join(workdir, "client.log"), CLIENT_S))
    return [(capture, "S", "the official service")]


def part_gateway(args, ck, workdir, procs):
    device, ready = start_official_device(workdir)
    procs.append(device)
    proxy, pport, capture = start_proxy(ready["port"], workdir, "device")
    procs.append(proxy)
    gw_err = os.path.join(workdir, "gateway.stderr")
    gateway = start([args.gateway, "--no-demo", "--no-local", "--no-discovery", "--listen", "127.0.0.1", "--port", "0",
                     "--log-level", "warning", "--recordings-root", workdir,
                     "--device", "interop=rr+tcp://127.0.0.1:%d/?service=interop" % pport],
                    gw_err)
    procs.append(gateway)
    port = read_json_line(gateway, START_S, "rr-gateway")["port"]
    deadline = time.monotonic() + START_S
    while True:
        try:
            status, devices = http(port, "GET", "/api/devices")
            if status == 200 and devices and devices[0].get("state") == "connected":
                break
        except OSError:
            pass
        if time.monotonic() > deadline:
            raise StepFailed("the gateway did not connect the device:\n%s" % tail(gw_err, 20))
        time.sleep(0.1)
    url = "rr+tcp://127.0.0.1:%d/?service=interop" % port
    ck.check("official client -> gateway -> official service with string tables: every check",
             lambda: run([sys.executable, os.path.join(HERE, "official_client.py"), url, "--timeout", str(CLIENT_S - 20)],
                         os.path.join(workdir, "official_client.log"), CLIENT_S))
    ck.check("our client -> gateway -> official service with string tables: every check",
             lambda: run([args.client, url, "--timeout", str(CLIENT_S - 20)], os.path.join(workdir, "client.log"), CLIENT_S))
    json_checks(ck, port)
    recording_check(ck, port, workdir)

    def gateway_alive_and_quiet():
        expect(gateway.poll() is None, "the gateway exited with %s" % gateway.returncode)
        with open(gw_err, errors="replace") as f:
            bad = [l for l in f if "string table code" in l]
        expect(not bad, "the gateway logged string-table errors: %s" % bad[:3])

    ck.check("gateway: still running, no string-table error logged", gateway_alive_and_quiet)
    return [(capture, "S", "the official service")]


def part_service(args, ck, workdir, procs):
    svc = start([args.service, "--port", "0", "--enable-stringtable", "--max-lifetime", "290"],
                os.path.join(workdir, "service.stderr"))
    procs.append(svc)
    ready = read_json_line(svc, START_S, "rr_interop_service")
    expect(ready.get("stringtable") is True, "rr_interop_service ready line: %r" % ready)
    proxy, pport, capture = start_proxy(ready["port"], workdir, "service")
    procs.append(proxy)
    url = "rr+tcp://127.0.0.1:%d/?service=interop" % pport
    ck.check("official client with string tables -> our service: every check",
             lambda: run([sys.executable, os.path.join(HERE, "official_client.py"), url, "--single-connection",
                          "--timeout", str(CLIENT_S - 20)], os.path.join(workdir, "official_client.log"), CLIENT_S))
    return [(capture, "C", "the official client")]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--part", required=True, choices=["direct", "gateway", "service"])
    ap.add_argument("--gateway", help="path of rr-gateway (--part gateway)")
    ap.add_argument("--client", help="path of rr_interop_client (--part direct, gateway)")
    ap.add_argument("--service", help="path of rr_interop_service (--part service)")
    ap.add_argument("--keep", default=None, help="keep logs and captures in this directory")
    args = ap.parse_args(argv)
    try:
        import RobotRaconteur  # noqa: F401
    except ImportError as e:
        skip("official RobotRaconteur package missing: %s" % e)
    if args.part == "gateway":
        try:
            import websocket  # noqa: F401
            import mcap  # noqa: F401
        except ImportError as e:
            skip("websocket-client or mcap missing: %s (run ./scripts/setup.sh)" % e)
    need = {"direct": ["client"], "gateway": ["gateway", "client"], "service": ["service"]}[args.part]
    for n in need:
        if not getattr(args, n):
            ap.error("--part %s needs --%s" % (args.part, n))

    workdir = args.keep or tempfile.mkdtemp(prefix="rr-strtab-")
    os.makedirs(workdir, exist_ok=True)
    if not args.keep:
        atexit.register(shutil.rmtree, workdir, True)
    ck = Checks()
    procs = []
    summary = {"part": args.part}
    rc = 1
    try:
        captures = {"direct": part_direct, "gateway": part_gateway, "service": part_service}[args.part](args, ck, workdir, procs)
        # The peer must really have used codes, else the run proves nothing.
        for capture, kind, who in captures:
            def used_codes(capture=capture, kind=kind, who=who):
                total, coded = coded_messages(capture, kind)
                summary["captured_%s" % kind] = {"messages": total, "with_codes": coded}
                expect(coded > 0, "%s sent %d messages, none with string-table codes" % (who, total))
            ck.check("%s sent string-table codes" % who, used_codes)
        rc = 0 if ck.ok() else 1
    except StepFailed as e:
        summary["error"] = str(e)
        print("[string_table] setup failed: %s" % e, file=sys.stderr, flush=True)
        rc = 2
    finally:
        for p in reversed(procs):
            stop(p)
    summary["checks"] = ck.results
    summary["ok"] = rc == 0
    print(json.dumps(summary), flush=True)
    passed = sum(1 for r in ck.results if r["ok"])
    print("%d passed, %d failed" % (passed, len(ck.results) - passed), flush=True)
    return rc


if __name__ == "__main__":
    sys.exit(main())
