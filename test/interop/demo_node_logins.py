#!/usr/bin/env python3
"""rr-gateway's embedded demo node behind the gateway's logins (docs/security.md "The demo node"),
tested with the official Python client.

Starts rr-gateway with gateway.auth (a password file: alice with role operator, bob with role
webcam_viewer) and the demo devices on, with rr+local on and the official library's node folders in a
scratch tree (ROBOTRACONTEUR_*_DIR, for the gateway and for this client alike). The demo node listens
on 127.0.0.1 (its port is the demo devices' `url` in GET /api/devices) and on rr+local as
`<node_name>.demo`. Checks (each named in the JSON summary):
  direct    a connect straight to the demo node's `create` and `webcam` services, over rr+tcp and over
            rr+local by NodeName, is refused (AuthenticationException) without credentials, with the
            demo node's user name and a made-up password, and with a gateway user's own password.
  gateway   through the gateway (rr+tcp, and rr+local by the gateway's NodeName) a gateway user reads
            the demo devices' properties; the roles still apply (bob may read `webcam` only:
            PermissionDenied on `create`); /readyz is ready (the gateway's own sessions logged in).
  json      the JSON API with alice's cookie: both demo devices connected, a property read; the JSON
            WebSocket (the dashboard's way) streams create's `packets` wire and a webcam's FrameStream pipe.
  secret    no 64-hex-digit run (the form of the demo node's password) in the gateway's debug log, in
            the /api device answers or in /metrics.
Prints one JSON summary; exit 0 when every check passed, 1 on a failed check, 2 on setup errors, 77
when the official package is missing.

Usage: demo_node_logins.py --gateway PATH/rr-gateway
"""

import argparse
import http.cookiejar
import json
import os
import re
import secrets
import shutil
import sys
import tempfile
import time
import urllib.error
import urllib.parse
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from child_procs import Checks, StepFailed, read_json_line, scratch_rr_env, start, stop, tail, write_password_file  # noqa: E402
import official_transport  # noqa: E402  (the official client's transport, its connect timeout)

# The official library reads its node folders from the environment: point this process (the client)
# and the gateway (started with this environment) at one scratch tree before the library loads.
WORK = tempfile.mkdtemp(prefix="gw_demo_logins_")
os.environ.update(scratch_rr_env(os.path.join(WORK, "rr")))

try:
    import RobotRaconteur as RR
except ImportError as e:  # pragma: no cover
    print("SKIP: official RobotRaconteur package missing: %s" % e)
    sys.exit(77)

RRN = RR.RobotRaconteurNode.s

USERS = {"alice": ("alice-pw", "operator"), "bob": ("bob-pw", "webcam_viewer")}
DEMO_USER = "rr-gateway-demo"  # the demo node's one user (server/app/gateway.cpp)
HEX64 = re.compile(r"[0-9a-fA-F]{64}")


def creds(password):
    return {"password": RR.VarValue(password, "string")}


def expect_refused(what, connect):
    """`connect` must raise AuthenticationException; a connection it opens is closed and reported."""
    try:
        c = connect()
    except RR.AuthenticationException:
        return
    except Exception as e:  # noqa: BLE001
        raise AssertionError("%s: expected AuthenticationException, got %s: %s" % (what, type(e).__name__, e))
    try:
        RRN.DisconnectService(c)
    except Exception:  # noqa: BLE001
        pass
    raise AssertionError("%s: connected without the demo node's login" % what)


def http_call(opener, method, url, body=None):
    data = json.dumps(body).encode() if body is not None else None
    req = urllib.request.Request(url, data=data, method=method)
    if data is not None:
        req.add_header("Content-Type", "application/json")
    try:
        with opener.open(req, timeout=20) as r:
            return r.status, r.read().decode("utf-8", "replace")
    except urllib.error.HTTPError as e:
        return e.code, e.read().decode("utf-8", "replace")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--timeout", type=float, default=60)
    args = ap.parse_args()

    users_path = os.path.join(WORK, "users.txt")
    write_password_file(users_path, [(u, pw, roles) for u, (pw, roles) in USERS.items()])
    node_name = "rrgwtest.demologin.%d.%s" % (os.getpid(), secrets.token_hex(3))
    config = """
gateway:
  port: 0
  listen: 127.0.0.1
  local: true
  node_name: {name}
  log_level: debug
  auth:
    users: {users}
    roles:
      operator:
        - allow: [read, write, call]
      webcam_viewer:
        - devices: [webcam]
          allow: [read]
demo:
  enabled: true
  port: 0
""".format(name=node_name, users=users_path)
    with open(os.path.join(WORK, "gateway.yaml"), "w") as f:
        f.write(config)

    gateway = None
    checks = Checks()
    summary = {"ok": False}
    log_path = os.path.join(WORK, "gateway.err")
    try:
        gateway = start([args.gateway, "--config", os.path.join(WORK, "gateway.yaml")], log_path)
        gw = read_json_line(gateway, args.timeout, "rr-gateway ready line")
        base = "http://127.0.0.1:%d" % gw["port"]
        deadline = time.monotonic() + args.timeout
        while True:
            # /readyz waits for the required devices, the demo devices among them: ready means the
            # gateway's own sessions logged in to the demo node.
            try:
                with urllib.request.urlopen(base + "/readyz", timeout=5) as r:
                    if r.status == 200:
                        break
            except Exception:  # noqa: BLE001
                pass
            if time.monotonic() > deadline:
                raise StepFailed("gateway not ready (demo devices not connected?): " + tail(log_path))
            time.sleep(0.2)

        jar = http.cookiejar.CookieJar()
        opener = urllib.request.build_opener(urllib.request.HTTPCookieProcessor(jar))
        status, body = http_call(opener, "POST", base + "/api/login", {"username": "alice", "password": "alice-pw"})
        if status != 200:
            raise StepFailed("POST /api/login as alice: %d %s" % (status, body))
        status, body = http_call(opener, "GET", base + "/api/devices")
        if status != 200:
            raise StepFailed("GET /api/devices: %d %s" % (status, body))
        devices = {d["name"]: d for d in json.loads(body)}
        if "create" not in devices or "webcam" not in devices:
            raise StepFailed("the demo devices are not listed: %s" % body)
        demo_urls = {n: devices[n]["url"] for n in ("create", "webcam")}
        demo_port = urllib.parse.urlsplit(demo_urls["create"]).port
        summary["demo_port"] = demo_port
        summary["demo_nodename"] = node_name + ".demo"
        api_answers = [body]

        RRN.RegisterTransport(official_transport.client_tcp_transport(RR))
        RRN.RegisterTransport(RR.LocalTransport())

        def direct(scheme):
            for service in ("create", "webcam"):
                url = (demo_urls[service] if scheme == "tcp"
                       else "rr+local:///?nodename=%s.demo&service=%s" % (node_name, service))
                expect_refused(url + " without credentials", lambda: RRN.ConnectService(url))
                expect_refused(url + " as %s with a made-up password" % DEMO_USER,
                               lambda: RRN.ConnectService(url, DEMO_USER, creds(secrets.token_hex(32))))
                expect_refused(url + " as alice with her gateway password",
                               lambda: RRN.ConnectService(url, "alice", creds("alice-pw")))
        checks.check("direct: rr+tcp to the demo node's port is refused without its login", lambda: direct("tcp"))
        checks.check("direct: rr+local to NAME.demo is refused without its login", lambda: direct("local"))

        def through_gateway(url_of):
            a = RRN.ConnectService(url_of("create"), "alice", creds("alice-pw"))
            try:
                if not isinstance(a.DistanceTraveled, int):
                    raise AssertionError("DistanceTraveled: %r" % (a.DistanceTraveled,))
                a.Drive(0, 0)  # operator may call
            finally:
                RRN.DisconnectService(a)
            w = RRN.ConnectService(url_of("webcam"), "bob", creds("bob-pw"))
            try:
                names = w.WebcamNames
                if not names:
                    raise AssertionError("WebcamNames empty")
            finally:
                RRN.DisconnectService(w)
            b = RRN.ConnectService(url_of("create"), "bob", creds("bob-pw"))
            try:
                try:
                    b.DistanceTraveled
                except RR.PermissionDeniedException:
                    pass
                else:
                    raise AssertionError("bob (webcam_viewer) read create.DistanceTraveled")
            finally:
                RRN.DisconnectService(b)
        checks.check("gateway: users reach the demo devices over rr+tcp with their roles",
                     lambda: through_gateway(lambda s: "rr+tcp://127.0.0.1:%d/?service=%s" % (gw["port"], s)))
        checks.check("gateway: users reach the demo devices over rr+local (the gateway's NodeName) with their roles",
                     lambda: through_gateway(lambda s: "rr+local:///?nodename=%s&service=%s" % (node_name, s)))

        def json_api():
            for name in ("create", "webcam"):
                status, body = http_call(opener, "GET", base + "/api/devices/" + name)
                api_answers.append(body)
                d = json.loads(body)
                if status != 200 or d.get("state") != "connected":
                    raise AssertionError("GET /api/devices/%s: %d %s" % (name, status, body[:300]))
            status, body = http_call(opener, "GET", base + "/api/devices/create/properties/DistanceTraveled")
            api_answers.append(body)
            if status != 200 or not isinstance(json.loads(body).get("value"), int):
                raise AssertionError("GET …/create/properties/DistanceTraveled: %d %s" % (status, body))
        checks.check("json: the demo devices are connected and readable through the JSON API", json_api)

        def json_websocket():
            # What the dashboard does on the demo devices: a wire and a pipe streamed over the JSON
            # WebSocket (logged in by the cookie), on the gateway's own sessions to the demo node.
            import websocket  # websocket-client
            cookie = "; ".join("%s=%s" % (c.name, c.value) for c in jar)
            ws = websocket.create_connection("ws://127.0.0.1:%d/" % gw["port"], subprotocols=["rr-gateway.json.v1"],
                                             header=["Cookie: " + cookie], timeout=20)
            pushes = []

            def ask(msg):
                ws.send(json.dumps(msg))
                while True:
                    r = json.loads(ws.recv())
                    if r.get("id") == msg["id"]:
                        return r
                    pushes.append(r)

            def wait_push(sub, kind):
                deadline = time.monotonic() + 15
                while time.monotonic() < deadline:
                    for p in pushes:
                        if p.get("subscription") == sub and p.get("kind") == kind and "value" in p:
                            return p
                    pushes.append(json.loads(ws.recv()))
                raise AssertionError("no %s push on subscription %s within 15 s" % (kind, sub))
            try:
                r = ask({"id": 1, "op": "subscribe", "device": "create", "member": "packets"})
                assert r.get("result", {}).get("kind") == "wire", r
                wire = r["result"]["subscription"]
                r = ask({"id": 2, "op": "call", "device": "create", "member": "StartStreaming"})
                assert "result" in r, r
                wait_push(wire, "wire")
                ask({"id": 3, "op": "call", "device": "create", "member": "StopStreaming"})
                r = ask({"id": 4, "op": "subscribe", "device": "webcam", "object": "Webcams[0]", "member": "FrameStream"})
                assert r.get("result", {}).get("kind") == "pipe", r
                pipe = r["result"]["subscription"]
                r = ask({"id": 5, "op": "call", "device": "webcam", "object": "Webcams[0]", "member": "StartStreaming"})
                assert "result" in r, r
                frame = wait_push(pipe, "pipe")["value"]
                assert frame.get("width", 0) > 0, str(frame)[:200]
                ask({"id": 6, "op": "call", "device": "webcam", "object": "Webcams[0]", "member": "StopStreaming"})
            finally:
                ws.close()
        checks.check("json: the JSON WebSocket streams a demo wire and pipe (the dashboard's way)", json_websocket)

        def secret():
            with urllib.request.urlopen(base + "/metrics", timeout=10) as r:
                api_answers.append(r.read().decode("utf-8", "replace"))
            for text in api_answers:
                m = HEX64.search(text)
                if m:
                    raise AssertionError("a 64-hex-digit run in an /api or /metrics answer: …%s…"
                                         % text[max(0, m.start() - 60):m.end() + 20])
            with open(log_path, encoding="utf-8", errors="replace") as f:
                log = f.read()
            if "HTTP 200" not in log:
                raise AssertionError("the gateway's log has no debug lines (access log) to check")
            m = HEX64.search(log)
            if m:
                raise AssertionError("a 64-hex-digit run in the gateway's log: …%s…" % log[max(0, m.start() - 80):m.end()])
        checks.check("secret: the demo node's password is in no log line, /api answer or /metrics", secret)

        failed = [c for c in checks.results if not c["ok"]]
        summary.update({"ok": not failed, "checks": checks.results})
        print(json.dumps(summary, indent=1))
        return 0 if not failed else 1
    except StepFailed as e:
        summary.update({"error": str(e), "checks": checks.results, "log": tail(log_path)})
        print(json.dumps(summary, indent=1))
        return 2
    finally:
        stop(gateway)
        if summary.get("ok"):
            shutil.rmtree(WORK, ignore_errors=True)
        else:
            print("kept for inspection: " + WORK, file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main())
