#!/usr/bin/env python3
"""The gateway's per-address connection limit (gateway.limits.connections_per_address,
docs/security.md "Connection limits"), tested with plain sockets.

Starts rr-gateway (no devices, demo off) with connections_per_address: 2 on 0.0.0.0 and checks:
  refused   two JSON WebSockets from 127.0.0.1 stay open; a third connection from 127.0.0.1 is
            refused: an HTTP request gets 429 with the reason in the body, a raw RR connection
            (`RRAC` …) is closed without an answer.
  others    meanwhile 127.0.0.2 (Linux routes 127/8 to lo; the client socket is bound to it) still
            gets /metrics (200), and both WebSockets from 127.0.0.1 still answer.
  released  after one WebSocket from 127.0.0.1 closes, a new request from 127.0.0.1 is served.
  counted   /metrics reports rr_gateway_limited_total{limit="connections_per_address"} >= the
            refusals made, and the gateway's log has a warning naming the address.
Then restarts it with messages_per_second: 20 (burst_s: 1) and, with the official Python client
(skipped when missing), checks:
  throttled a client calling the gateway's service index as fast as it can gets about 20 calls/s
            over 4 s (at most the rate plus its one-second burst, and at least half the rate: slowed,
            not cut off), and rr_gateway_limited_total{limit="rate"} counts the pauses.
  unharmed  meanwhile a second client's calls on its own connection return promptly, and the
            flooding client is still connected afterwards.
  rr+ws     the same flood over RR inside a WebSocket (rr+ws) gets the same pace and stays connected.
  JSON/HTTP a JSON WebSocket and an HTTP keep-alive connection sending requests back to back are
            paced to about the same rate, and the WebSocket stays open.
Then restarts it with bytes_per_second: 256 KiB (burst_s: 1) in front of rr_interop_service (when
--service is given) and checks:
  bytes     an official client that queues 80 pipe packets of 16 KiB at once on p_echo (which echoes
            each one) gets its echoes at about the limit: no faster than the rate allows (the burst plus
            the rate, plus one 64 KiB read), and no slower than half of it.
  unharmed  meanwhile a second client's calls on its own connection return promptly, and the
            flooding client is still connected afterwards.
Prints one JSON summary; exit 0 when every check passed, 1 on a failed check, 2 on setup errors, 77
when websocket-client is missing or 127.0.0.2 cannot be bound.

Usage: gateway_limits.py --gateway PATH/rr-gateway [--service PATH/rr_interop_service]
"""

import argparse
import json
import os
import re
import socket
import sys
import tempfile
import time
import traceback

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from child_procs import StepFailed, read_json_line, start, stop, tail  # noqa: E402
import official_transport  # noqa: E402  (the official client's transport, its connect timeout)

try:
    import websocket  # websocket-client
except ImportError as e:  # pragma: no cover
    print("SKIP: websocket-client missing: %s" % e)
    sys.exit(77)

JSON_PROTOCOL = "rr-gateway.json.v1"
METRIC = 'rr_gateway_limited_total{limit="connections_per_address"}'
RATE_METRIC = 'rr_gateway_limited_total{limit="rate"}'
RATE = 20
BYTE_RATE = 256 * 1024  # bytes/s in the bytes_per_second phase
PACKET = 16 * 1024      # bytes of text per pipe packet there
PACKETS = 80
READ_CHUNK = 64 * 1024  # the most one read takes before it is charged (StreamPump's buffer)


def http_get(port, path, source="127.0.0.1", timeout=10):
    """One HTTP/1.1 GET over a fresh socket bound to `source`; returns (status, body) or (None, why)."""
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.settimeout(timeout)
    try:
        s.bind((source, 0))
        s.connect(("127.0.0.1", port))
        s.sendall(("GET %s HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nConnection: close\r\n\r\n" % (path, port)).encode())
        data = b""
        while True:
            chunk = s.recv(65536)
            if not chunk:
                break
            data += chunk
    except OSError as e:
        return None, "%s: %s" % (type(e).__name__, e)
    finally:
        s.close()
    head, _, body = data.partition(b"\r\n\r\n")
    m = re.match(rb"HTTP/1\.1 (\d+)", head)
    if not m:
        return None, "no HTTP answer: %r" % data[:200]
    return int(m.group(1)), body.decode("utf-8", "replace")


def raw_rr_refused(port, timeout=10):
    """A raw RR connection from 127.0.0.1 that sends `RRAC` and a few more bytes: True when the gateway
    closes it without sending anything."""
    s = socket.create_connection(("127.0.0.1", port), timeout=timeout)
    try:
        s.sendall(b"RRAC" + b"\x00" * 12)
        try:
            return s.recv(4096) == b""
        except ConnectionResetError:
            return True
    finally:
        s.close()


def json_ws(port):
    ws = websocket.create_connection("ws://127.0.0.1:%d/" % port, subprotocols=[JSON_PROTOCOL], timeout=20)
    return ws


def ws_alive(ws):
    """The JSON WebSocket answers a request (any well-formed answer counts: the connection works)."""
    ws.send(json.dumps({"id": 1, "op": "devices"}))
    return bool(json.loads(ws.recv()))


def metric(port, source="127.0.0.2", name=METRIC):
    status, body = http_get(port, "/metrics", source)
    if status != 200:
        raise StepFailed("/metrics from %s: %s %s" % (source, status, body[:200] if body else ""))
    for line in body.splitlines():
        if line.startswith(name + " "):
            return int(float(line.split()[-1]))
    raise StepFailed("/metrics has no %s" % name)


_official = []


def official_node():
    """The official library's node with its TCP transport (rr+tcp, rr+ws), set up once: the node
    cannot start again after Shutdown, so main() shuts it down at the end. None when not installed."""
    if not _official:
        try:
            import RobotRaconteur as RR
        except ImportError as e:
            _official.append((None, str(e)))
        else:
            RR.RobotRaconteurNode.s.RegisterTransport(official_transport.client_tcp_transport(RR))
            _official.append((RR.RobotRaconteurNode.s, None))
    return _official[0]


def rate_checks(c, args, work):
    """The messages_per_second phase (official client); returns False when it had to be skipped."""
    import threading

    rrn, missing = official_node()
    if rrn is None:
        c.results.append({"check": "throttled", "ok": True, "skipped": "official package missing: %s" % missing})
        return False
    gateway = None
    try:
        with open(os.path.join(work, "rate.yaml"), "w") as f:
            f.write("gateway:\n  listen: 127.0.0.1\n  port: 0\n  local: false\n"
                    "  limits:\n    messages_per_second: %d\n    burst_s: 1\n"
                    "demo:\n  enabled: false\n" % RATE)
        gateway = start([args.gateway, "--config", os.path.join(work, "rate.yaml")], os.path.join(work, "rate.err"))
        port = read_json_line(gateway, args.timeout, "rr-gateway ready line (rate)")["port"]
        url = "rr+tcp://127.0.0.1:%d/?service=RobotRaconteurServiceIndex" % port
        flood = rrn.ConnectService(url)
        other = rrn.ConnectService(url)
        time.sleep(1.5)  # both buckets full again after the connection handshakes
        calls = [0]
        stop_at = time.monotonic() + 4.0
        err = []

        def flooder():
            try:
                while time.monotonic() < stop_at:
                    flood.GetLocalNodeServices()
                    calls[0] += 1
            except Exception as e:  # noqa: BLE001
                err.append(repr(e))

        t0 = time.monotonic()
        th = threading.Thread(target=flooder)
        th.start()
        time.sleep(1.5)  # the flood is in its paced phase now
        worst = 0.0
        for _ in range(5):
            s0 = time.monotonic()
            other.GetLocalNodeServices()
            worst = max(worst, time.monotonic() - s0)
            time.sleep(0.1)
        th.join(30)
        elapsed = time.monotonic() - t0
        rate = calls[0] / elapsed
        # Requests are RR messages from the client; the burst is RATE messages; heartbeats are rare.
        c.check("throttled: a flooding client gets about messages_per_second calls/s",
                not err and calls[0] <= RATE * (elapsed + 1) + 5 and rate >= RATE / 2,
                "%d calls in %.2f s = %.1f/s (limit %d/s, burst %d) %s" % (calls[0], elapsed, rate, RATE, RATE, err))
        c.check("unharmed: a second client's calls return promptly during the flood", worst < 0.5,
                "slowest of 5 calls: %.3f s" % worst)
        try:
            flood.GetLocalNodeServices()
            still = True
        except Exception as e:  # noqa: BLE001
            still = repr(e)
        c.check("unharmed: the flooding client is slowed, not disconnected", still is True, str(still))
        paused = metric(port, source="127.0.0.1", name=RATE_METRIC)
        c.check("throttled: /metrics counts the pauses", paused > 0, "%s = %d" % (RATE_METRIC, paused))
        time.sleep(0.2)
        log = tail(os.path.join(work, "rate.err"), 200)
        c.check("throttled: the log says reads were paused", "over its rate" in log and "reads paused" in log, log[-600:])
        # RR inside a WebSocket (rr+ws): the upgraded connection is paced by the same rate.
        ws_client = rrn.ConnectService(url.replace("rr+tcp://", "rr+ws://"))
        time.sleep(1.5)
        calls_ws, elapsed_ws, err_ws = flood_for(4.0, ws_client.GetLocalNodeServices)
        rate_ws = calls_ws / elapsed_ws
        c.check("rr+ws: a flooding RR-over-WebSocket client gets about messages_per_second calls/s",
                not err_ws and calls_ws <= RATE * (elapsed_ws + 1) + 5 and rate_ws >= RATE / 2,
                "%d calls in %.2f s = %.1f/s (limit %d/s, burst %d) %s" % (calls_ws, elapsed_ws, rate_ws, RATE, RATE, err_ws))
        try:
            ws_client.GetLocalNodeServices()
            still = True
        except Exception as e:  # noqa: BLE001
            still = repr(e)
        c.check("rr+ws: the flooding client is slowed, not disconnected", still is True, str(still))
        json_http_rate_checks(c, port)
        for client in (flood, other, ws_client):
            rrn.DisconnectService(client)
    finally:
        stop(gateway)
    return True


def bytes_checks(c, args, work):
    """The bytes_per_second phase: official client -> gateway -> rr_interop_service's p_echo pipe."""
    import threading

    rrn, missing = official_node()
    if rrn is None:
        c.results.append({"check": "bytes", "ok": True, "skipped": "official package missing: %s" % missing})
        return
    if not args.service:
        c.results.append({"check": "bytes", "ok": True, "skipped": "no --service (rr_interop_service)"})
        return
    device = gateway = None
    try:
        device = start([args.service, "--port", "0"], os.path.join(work, "service.err"))
        dev = read_json_line(device, args.timeout, "rr_interop_service ready line")
        with open(os.path.join(work, "bytes.yaml"), "w") as f:
            f.write("gateway:\n  listen: 127.0.0.1\n  port: 0\n  local: false\n"
                    "  limits:\n    bytes_per_second: %d\n    burst_s: 1\n"
                    "demo:\n  enabled: false\n"
                    "devices:\n  - name: interop\n    url: %s\n" % (BYTE_RATE, json.dumps(dev["url"])))
        gateway = start([args.gateway, "--config", os.path.join(work, "bytes.yaml")], os.path.join(work, "bytes.err"))
        port = read_json_line(gateway, args.timeout, "rr-gateway ready line (bytes)")["port"]
        deadline = time.monotonic() + args.timeout
        while http_get(port, "/readyz")[0] != 200:  # the device is connected
            if time.monotonic() > deadline:
                raise StepFailed("gateway not ready: " + tail(os.path.join(work, "bytes.err")))
            time.sleep(0.2)
        url = "rr+tcp://127.0.0.1:%d/?service=interop" % port
        flood = rrn.ConnectService(url)
        other = rrn.ConnectService(url)
        ep = flood.p_echo.Connect(-1)
        packet = rrn.NewStructure("experimental.interop_test.Inner", flood)
        packet.id, packet.label, packet.values = 1, "x" * PACKET, [0.0]
        time.sleep(1.5)  # the bucket full again after the handshake and the definitions
        t0 = time.monotonic()
        for _ in range(PACKETS):
            ep.AsyncSendPacket(packet, lambda *_a: None)
        echoes = []  # arrival time of each echo
        done = threading.Event()

        def drain():
            end = time.monotonic() + 60
            while len(echoes) < PACKETS and time.monotonic() < end:
                while ep.Available:
                    ep.ReceivePacket()
                    echoes.append(time.monotonic())
                time.sleep(0.005)
            done.set()

        th = threading.Thread(target=drain)
        th.start()
        time.sleep(1.5)  # the burst is spent: the flood is paced now
        worst = 0.0
        for _ in range(5):
            s0 = time.monotonic()
            other.add(1, 2)
            worst = max(worst, time.monotonic() - s0)
            time.sleep(0.1)
        done.wait(70)
        th.join(5)
        sent = PACKETS * PACKET  # what the gateway had to read at least (the text alone)
        fastest = (sent - BYTE_RATE - READ_CHUNK) / BYTE_RATE  # burst + rate + one read, no faster
        expected = (sent - BYTE_RATE) / BYTE_RATE
        elapsed = echoes[-1] - t0 if echoes else float("inf")
        # The steady part, from the 20th echo on: its bytes over its time, against the limit.
        steady = (len(echoes) - 20) * PACKET / (echoes[-1] - echoes[19]) if len(echoes) > 21 else 0.0
        c.check("bytes: a client pushing faster than bytes_per_second is paced to about the limit",
                len(echoes) == PACKETS and elapsed >= fastest and elapsed <= 2 * expected + 2
                and BYTE_RATE / 2 <= steady <= BYTE_RATE * 1.3,
                "%d/%d echoes of %d B in %.2f s (no faster than %.2f s, about %.2f s expected); steady %.0f B/s "
                "(limit %d B/s)" % (len(echoes), PACKETS, PACKET, elapsed, fastest, expected, steady, BYTE_RATE))
        c.check("bytes: a second client's calls return promptly meanwhile", worst < 0.5, "slowest of 5 calls: %.3f s" % worst)
        try:
            still = flood.add(2, 3) == 5
        except Exception as e:  # noqa: BLE001
            still = repr(e)
        c.check("bytes: the flooding client is slowed, not disconnected", still is True, str(still))
        paused = metric(port, source="127.0.0.1", name=RATE_METRIC)
        c.check("bytes: /metrics counts the pauses", paused > 0, "%s = %d" % (RATE_METRIC, paused))
        ep.Close()
        for client in (flood, other):
            rrn.DisconnectService(client)
    finally:
        stop(gateway)
        stop(device)


def flood_for(seconds, one_request):
    """Calls one_request() back to back for `seconds`; returns (calls, elapsed, errors)."""
    calls, err = 0, []
    t0 = time.monotonic()
    try:
        while time.monotonic() - t0 < seconds:
            one_request()
            calls += 1
    except Exception as e:  # noqa: BLE001
        err.append(repr(e))
    return calls, time.monotonic() - t0, err


def json_http_rate_checks(c, port):
    """messages_per_second on the JSON WebSocket (one JSON message = one message) and on an HTTP
    keep-alive connection (one request = one message), each on a fresh connection (a full bucket)."""
    import http.client

    ws = json_ws(port)
    counter = [0]

    def ws_request():
        counter[0] += 1
        ws.send(json.dumps({"id": counter[0], "op": "devices"}))
        while json.loads(ws.recv()).get("id") != counter[0]:
            pass

    calls, elapsed, err = flood_for(3.0, ws_request)
    rate = calls / elapsed
    c.check("throttled: a JSON WebSocket sending requests back to back gets about messages_per_second",
            not err and calls <= RATE * (elapsed + 1) + 5 and rate >= RATE / 2,
            "%d requests in %.2f s = %.1f/s (limit %d/s, burst %d) %s" % (calls, elapsed, rate, RATE, RATE, err))
    c.check("unharmed: the flooding JSON WebSocket is slowed, not closed", not err and ws_alive(ws), str(err))
    ws.close()

    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=10)

    def http_request():
        conn.request("GET", "/api/devices")
        r = conn.getresponse()
        r.read()
        if r.status != 200:
            raise StepFailed("GET /api/devices: %d" % r.status)

    calls, elapsed, err = flood_for(3.0, http_request)
    rate = calls / elapsed
    c.check("throttled: HTTP requests back to back on one keep-alive connection get about messages_per_second",
            not err and calls <= RATE * (elapsed + 1) + 5 and rate >= RATE / 2,
            "%d requests in %.2f s = %.1f/s (limit %d/s, burst %d) %s" % (calls, elapsed, rate, RATE, RATE, err))
    conn.close()


class Checks:
    def __init__(self):
        self.results = []

    def check(self, name, ok, detail=""):
        self.results.append({"check": name, "ok": bool(ok), "detail": detail})
        return ok


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--service", help="rr_interop_service, the device of the bytes_per_second phase")
    ap.add_argument("--timeout", type=float, default=30)
    args = ap.parse_args()

    probe = socket.socket()
    try:
        probe.bind(("127.0.0.2", 0))
    except OSError as e:
        print("SKIP: cannot bind 127.0.0.2 (%s)" % e)
        return 77
    finally:
        probe.close()

    c = Checks()
    gateway = None
    opened = []
    with tempfile.TemporaryDirectory(prefix="rr-limits-") as work:
        try:
            with open(os.path.join(work, "gateway.yaml"), "w") as f:
                f.write("gateway:\n  listen: 0.0.0.0\n  port: 0\n  local: false\n"
                        "  limits:\n    connections_per_address: 2\n"
                        "demo:\n  enabled: false\n")
            gateway = start([args.gateway, "--config", os.path.join(work, "gateway.yaml")], os.path.join(work, "gateway.err"))
            port = read_json_line(gateway, args.timeout, "rr-gateway ready line")["port"]

            opened = [json_ws(port), json_ws(port)]
            c.check("refused: two WebSockets from 127.0.0.1 open", all(ws_alive(w) for w in opened))

            status, body = http_get(port, "/metrics")
            c.check("refused: third connection from 127.0.0.1 (HTTP) gets 429 with the reason",
                    status == 429 and "too many connections from 127.0.0.1" in body and "at most 2" in body,
                    "%s %r" % (status, body))
            c.check("refused: third connection from 127.0.0.1 (raw RR) is closed", raw_rr_refused(port))

            status, body = http_get(port, "/metrics", source="127.0.0.2")
            c.check("others: 127.0.0.2 is served meanwhile", status == 200, "%s" % status)
            c.check("others: the two WebSockets from 127.0.0.1 still work", all(ws_alive(w) for w in opened))

            count = metric(port)
            c.check("counted: /metrics counts the refusals", count >= 2, "%s = %d" % (METRIC, count))

            opened.pop().close()
            served = None
            for _ in range(50):  # the gateway notices the close asynchronously
                served, body = http_get(port, "/metrics")
                if served == 200:
                    break
                time.sleep(0.1)
            c.check("released: after a WebSocket closes, 127.0.0.1 is served again", served == 200, "%s" % served)

            time.sleep(0.2)
            log = tail(os.path.join(work, "gateway.err"), 200)
            c.check("counted: the log warns naming the address",
                    "connection refused: too many connections from 127.0.0.1" in log, log[-600:])
            for w in opened:
                w.close()
            opened = []
            stop(gateway)
            gateway = None

            rate_checks(c, args, work)
            bytes_checks(c, args, work)
        except StepFailed as e:
            c.results.append({"check": "setup", "ok": False, "detail": str(e)})
            print(json.dumps({"results": c.results, "gateway_log": tail(os.path.join(work, "gateway.err"))}, indent=1))
            return 2
        except Exception:  # noqa: BLE001
            c.results.append({"check": "setup", "ok": False, "detail": traceback.format_exc()})
            print(json.dumps({"results": c.results, "gateway_log": tail(os.path.join(work, "gateway.err"))}, indent=1))
            return 2
        finally:
            for w in opened:
                try:
                    w.close()
                except Exception:  # noqa: BLE001
                    pass
            stop(gateway)
            if _official and _official[0][0] is not None:
                try:
                    _official[0][0].Shutdown()
                except Exception:  # noqa: BLE001
                    pass
    ok = all(r["ok"] for r in c.results)
    print(json.dumps({"ok": ok, "results": c.results}, indent=1))
    skipped = ["%s: %s" % (r["check"], r["skipped"]) for r in c.results if "skipped" in r]
    if ok and skipped:
        # a part that could not run is not a pass: ctest reports the test skipped, with the reasons
        print("SKIP: every check that ran passed; not run: %s" % "; ".join(skipped))
        return 77
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
