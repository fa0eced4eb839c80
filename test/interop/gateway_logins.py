#!/usr/bin/env python3
"""The gateway's own logins and per-member permissions (`auth: gateway`, docs/security.md), tested
with the official Python client over raw RR and with plain HTTP / WebSocket clients over the JSON API.

Starts rr_interop_service twice (the device without logins of its own, and again with the same
password file, behind `auth: passthrough`) and rr-gateway with gateway.auth: a
password file in the official format (alice: operator, bob: viewer, carol: adder), a bearer token file,
an HS256 JWT key, and roles:
  operator  every member of every device: read, write, call
  viewer    every member of `interop` and `interop_ptu`: read
  adder     `add`, `call_callbacks`, `child_by_int[*].describe`: call; `p_int32`, `child.value`: read
  writer    `w_both`, `p_unreliable`: write
Checks (each one named in the JSON summary):
  rr        official client: right password connects; wrong password, unknown user and no credentials
            are refused (AuthenticationException); the permission matrix (property get/set, function
            call, generator, event receive) per user, PermissionDenied where the role does not allow;
            wires (OutValue, PokeOutValue reaching the device or not), memory written and read back,
            pipes (a reader receives packets, its own packets are not delivered; a writer's are),
            members of objects below the root (objref) by rule; the service definition a viewer sees
            lists every member.
  json      POST /api/login (cookie: HttpOnly, SameSite=Strict; Secure only over TLS, here through a
            trusted proxy saying https, never for a client that only claims it), requests with the cookie, without it
            (401), PUT/POST refused by role (403); bearer token; JWT valid / expired / forged / wrong
            audience; the JSON WebSocket logged in by its first message and by the cookie, its `peek`
            allowed with read and refused without.
  reload    SIGHUP after the password file changed: a removed user is refused (new logins, and the
            requests of its open session), a new user logs in; a broken file is logged and changes nothing.
  limits    after 5 failed logins from this address even the right password is refused (HTTP 429,
            RR AuthenticationException "Too many failed logins"); /metrics counts the failures.
Prints one JSON summary; exit 0 when every check passed, 1 on a failed check, 2 on setup errors, 77
when the official package is missing.

Usage: gateway_logins.py --gateway PATH/rr-gateway --service PATH/rr_interop_service --rr PATH/rr
"""

import argparse
import atexit
import base64
import hashlib
import hmac
import http.cookiejar
import json
import os
import shutil
import signal
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from child_procs import Checks, StepFailed, read_json_line, start, stop, tail, write_password_file  # noqa: E402
import official_transport  # noqa: E402  (the official client's transport, its connect timeout)

try:
    import RobotRaconteur as RR
except ImportError as e:  # pragma: no cover
    print("SKIP: official RobotRaconteur package missing: %s" % e)
    sys.exit(77)

RRN = RR.RobotRaconteurNode.s

A, B = -2147483648, 2147483647  # the two p_int32 values rr_interop_service accepts (interop_values.py)
USERS = {"alice": ("alice-pw", "operator,objectlock"), "bob": ("bob-pw", "viewer"), "carol": ("carol-pw", "adder"),
         "erin": ("erin-pw", "writer")}
TOKEN = "wall-display-token-5d41402abc4b2a76"
JWT_SECRET = b"an-hs256-secret-of-at-least-32-bytes!!"


def b64url(data):
    return base64.urlsafe_b64encode(data).rstrip(b"=").decode()


def make_jwt(claims, secret=JWT_SECRET, alg="HS256"):
    header = b64url(json.dumps({"alg": alg, "typ": "JWT"}).encode())
    payload = b64url(json.dumps(claims).encode())
    sig = b64url(hmac.new(secret, (header + "." + payload).encode(), hashlib.sha256).digest())
    return header + "." + payload + "." + sig


def creds(password):
    return {"password": RR.VarValue(password, "string")}


def expect_rr_error(fn, exc_type, text=None):
    try:
        fn()
    except exc_type as e:
        if text and text not in str(e):
            raise AssertionError("expected %r in %r" % (text, str(e)))
        return str(e)
    raise AssertionError("expected %s" % exc_type.__name__)


class Http:
    def __init__(self, base):
        self.base = base
        self.jar = http.cookiejar.CookieJar()
        self.opener = urllib.request.build_opener(urllib.request.HTTPCookieProcessor(self.jar))

    def call(self, method, path, body=None, headers=None, cookies=True):
        data = json.dumps(body).encode() if body is not None else None
        req = urllib.request.Request(self.base + path, data=data, method=method, headers=dict(headers or {}))
        if data is not None:
            req.add_header("Content-Type", "application/json")
        opener = self.opener if cookies else urllib.request.build_opener()
        try:
            with opener.open(req, timeout=20) as r:
                return r.status, dict(r.headers), json.loads(r.read() or b"null")
        except urllib.error.HTTPError as e:
            raw = e.read()
            try:
                return e.code, dict(e.headers), json.loads(raw or b"null")
            except ValueError:
                return e.code, dict(e.headers), raw.decode(errors="replace")


def expect_status(got, status, name=None):
    if got[0] != status:
        raise AssertionError("expected HTTP %d, got %d %r" % (status, got[0], got[2]))
    if name and (not isinstance(got[2], dict) or got[2].get("error", {}).get("name") != name):
        raise AssertionError("expected error %s, got %r" % (name, got[2]))
    return got


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--service", required=True)
    ap.add_argument("--rr", required=True, help="our rr CLI")
    ap.add_argument("--timeout", type=float, default=60)
    args = ap.parse_args()

    work = tempfile.mkdtemp(prefix="gw_logins_")
    atexit.register(shutil.rmtree, work, True)
    write_password_file(os.path.join(work, "users.txt"), [(u, pw, roles) for u, (pw, roles) in USERS.items()])
    with open(os.path.join(work, "tokens.txt"), "w") as f:
        f.write("%s wall viewer\n" % TOKEN)
    with open(os.path.join(work, "jwt.key"), "wb") as f:
        f.write(JWT_SECRET + b"\n")

    device = device_users = gateway = None
    checks = Checks()
    try:
        device = start([args.service, "--port", "0"], os.path.join(work, "service.err"))
        dev = read_json_line(device, args.timeout, "rr_interop_service ready line")
        # The same service with logins of its own (the same password file), for passthrough with roles.
        device_users = start([args.service, "--port", "0", "--users", os.path.join(work, "users.txt")],
                             os.path.join(work, "service_users.err"))
        dev_users = read_json_line(device_users, args.timeout, "rr_interop_service --users ready line")
        config = """
gateway:
  port: 0
  listen: 127.0.0.1
  local: false
  trusted_proxies: [127.0.0.2]   # the "proxy" of the Secure-cookie check (connects from 127.0.0.2)
  auth:
    users: {work}/users.txt
    tokens: {work}/tokens.txt
    jwt:
      algorithm: HS256
      key: {work}/jwt.key
      audience: rr-gateway
    roles:
      operator:
        - allow: [read, write, call]
      viewer:
        - devices: [interop, interop_ptu]
          allow: [read]
      writer:
        - devices: [interop, interop_ptu]
          members: [w_both, p_unreliable]
          allow: [write]
      adder:
        - devices: [interop, interop_ptu]
          members: [add, call_callbacks, "child_by_int[*].describe"]
          allow: [call]
        - devices: [interop, interop_ptu]
          members: [p_int32, child.value]
          allow: [read]
    login_limit: {{max_failures: 5, window_s: 60, lockout_s: 60}}
demo:
  enabled: false
devices:
  - name: interop
    url: {url}
  - name: interop_pt
    url: {url}
    auth: passthrough
  - name: interop_ptu
    url: {url_users}
    auth: passthrough
    username: alice
    password: alice-pw
""".format(work=work, url=dev["url"], url_users=dev_users["url"])
        with open(os.path.join(work, "gateway.yaml"), "w") as f:
            f.write(config)
        gateway = start([args.gateway, "--config", os.path.join(work, "gateway.yaml")], os.path.join(work, "gateway.err"))
        gw = read_json_line(gateway, args.timeout, "rr-gateway ready line")
        port = gw["port"]
        base = "http://127.0.0.1:%d" % port
        url = "rr+tcp://127.0.0.1:%d/?service=interop" % port
        deadline = time.monotonic() + args.timeout
        while True:
            try:
                with urllib.request.urlopen(base + "/readyz", timeout=5) as r:
                    if r.status == 200:
                        break
            except Exception:  # noqa: BLE001
                pass
            if time.monotonic() > deadline:
                raise StepFailed("gateway not ready: " + tail(os.path.join(work, "gateway.err")))
            time.sleep(0.2)

        RRN.RegisterTransport(official_transport.client_tcp_transport(RR))
        conns = {}

        # ---- raw RR, the official client ----
        def rr_logins():
            for u in USERS:
                conns[u] = RRN.ConnectService(url, u, creds(USERS[u][0]))
            expect_rr_error(lambda: RRN.ConnectService(url, "alice", creds("wrong")), RR.AuthenticationException,
                            "Invalid username or password")
            expect_rr_error(lambda: RRN.ConnectService(url, "mallory", creds("x")), RR.AuthenticationException)
            expect_rr_error(lambda: RRN.ConnectService(url), RR.AuthenticationException)
        checks.check("rr: official client logs in (right / wrong password, unknown user, none)", rr_logins)

        def rr_token_login():
            # A bearer token in the credentials, with the user name the token logs in as (`<name>@token`):
            # the token's roles apply (wall: viewer); the token under another user's name, or a wrong
            # token, is refused.
            expect_rr_error(lambda: RRN.ConnectService(url, "wall@token", {"token": RR.VarValue(TOKEN + "x", "string")}),
                            RR.AuthenticationException, "Invalid token")
            expect_rr_error(lambda: RRN.ConnectService(url, "alice", {"token": RR.VarValue(TOKEN, "string")}),
                            RR.AuthenticationException, 'this token logs in as user "wall@token"')
            # (a successful login last: it clears this address's failed-login count for the later checks)
            t = RRN.ConnectService(url, "wall@token", {"token": RR.VarValue(TOKEN, "string")})
            try:
                assert t.p_int32 in (A, B)
                expect_rr_error(lambda: setattr(t, "p_int32", A), RR.PermissionDeniedException, "may not write p_int32")
            finally:
                RRN.DisconnectService(t)
        checks.check("rr: official client logs in with a bearer token (its roles; wrong name or token refused)",
                     rr_token_login)

        def cli_token_login():
            import subprocess
            run = lambda *extra: subprocess.run([args.rr, "get", url, "p_int32", "--timeout", "10"] + list(extra),
                                                capture_output=True, text=True, timeout=60)
            bad = run("--username", "wall@token", "--token", TOKEN + "x")
            assert bad.returncode == 3 and "Invalid token" in bad.stderr, (bad.returncode, bad.stderr)
            ok = run("--username", "wall@token", "--token", TOKEN)
            assert ok.returncode == 0 and ok.stdout.strip() in (str(A), str(B)), (ok.returncode, ok.stdout, ok.stderr)
        checks.check("rr CLI: --username NAME@token --token T logs in with a bearer token", cli_token_login)

        def rr_matrix():
            a, b, c = conns["alice"], conns["bob"], conns["carol"]
            # operator: everything
            a.p_int32 = B
            assert a.p_int32 == B
            assert a.add(2, 3) == 5
            assert list(a.count_up(1, 3).NextAll()) == [1, 2, 3]
            # viewer: read only
            assert b.p_int32 == B
            assert b.p_double is not None
            expect_rr_error(lambda: setattr(b, "p_int32", 9), RR.PermissionDeniedException, "may not write p_int32")
            expect_rr_error(lambda: b.add(1, 1), RR.PermissionDeniedException, "may not call add")
            expect_rr_error(lambda: b.count_up(1, 2), RR.PermissionDeniedException)
            # adder: add and p_int32 only
            assert c.add(40, 2) == 42
            assert c.p_int32 == B
            expect_rr_error(lambda: c.p_double, RR.PermissionDeniedException, "may not read p_double")
            expect_rr_error(lambda: setattr(c, "p_int32", 1), RR.PermissionDeniedException)
            expect_rr_error(lambda: c.reset(), RR.PermissionDeniedException)
            assert a.p_int32 == B  # nothing changed by the refused writes
        checks.check("rr: permission matrix (property get/set, function, generator) per role", rr_matrix)

        def rr_passthrough_roles():
            # A passthrough device with no logins of its own admits only clients that send no username
            # (it refuses a login: "Authentication not enabled"), and the gateway's roles then decide by
            # user name: anonymous may do nothing (deny by default), so the device is not open to anyone.
            pt_url = "rr+tcp://127.0.0.1:%d/?service=interop_pt" % port
            anon = RRN.ConnectService(pt_url)
            try:
                expect_rr_error(lambda: anon.p_int32, RR.PermissionDeniedException, "anonymous may not read p_int32")
                expect_rr_error(lambda: anon.add(1, 1), RR.PermissionDeniedException, "anonymous may not call add")
            finally:
                RRN.DisconnectService(anon)
            expect_rr_error(lambda: RRN.ConnectService(pt_url, "bob", creds(USERS["bob"][0])), RR.AuthenticationException,
                            "Authentication not enabled")
        checks.check("rr: auth passthrough device without logins: the gateway's roles still apply", rr_passthrough_roles)

        def rr_passthrough_packets():
            # A passthrough device with logins of its own: each client has its own upstream session, so
            # the device's wire echo, events and pipe packets arrive on that client's session alone. The
            # gateway's roles still apply to each one: a write-only user's wire echo and events are not
            # delivered (packet by packet), an operator's are.
            ptu = "rr+tcp://127.0.0.1:%d/?service=interop_ptu" % port
            s = {u: RRN.ConnectService(ptu, u, creds(USERS[u][0])) for u in ("alice", "bob", "carol", "erin")}
            try:
                wa, we = s["alice"].w_both.Connect(), s["erin"].w_both.Connect()
                try:
                    wa.OutValue = [1.0, 2.0, 3.0]
                    t_end = time.monotonic() + 10
                    while time.monotonic() < t_end and not wa.InValueValid:
                        time.sleep(0.05)
                    assert wa.InValueValid and list(wa.InValue) == [3.0, 2.0, 1.0], "the operator got no echo"
                    we.OutValue = [4.0, 5.0, 6.0]
                    t_end = time.monotonic() + 10
                    while time.monotonic() < t_end and list(s["alice"].w_both.PeekOutValue()[0]) != [4.0, 5.0, 6.0]:
                        time.sleep(0.05)
                    assert list(s["alice"].w_both.PeekOutValue()[0]) == [4.0, 5.0, 6.0], "the writer's OutValue did not reach the device"
                    time.sleep(0.5)
                    assert not we.InValueValid, "a write-only passthrough session received the device's echo (InValue)"
                finally:
                    wa.Close()
                    we.Close()
                got = {"alice": 0, "bob": 0, "carol": 0, "erin": 0}
                lock = threading.Lock()

                def handler(name):
                    def h(*_a):
                        with lock:
                            got[name] += 1
                    return h
                for u in got:
                    s[u].ev_values += handler(u)
                s["alice"].fire_events(3)
                t_end = time.monotonic() + 10
                while time.monotonic() < t_end and (got["alice"] < 3 or got["bob"] < 3):
                    time.sleep(0.05)
                time.sleep(0.5)
                assert got == {"alice": 3, "bob": 3, "carol": 0, "erin": 0}, got
            finally:
                for c in s.values():
                    RRN.DisconnectService(c)
        checks.check("rr: auth passthrough with the device's logins: roles apply to its wire packets and events",
                     rr_passthrough_packets)

        def rr_wires_memory_pipes():
            import numpy as np
            a, b, c = conns["alice"], conns["bob"], conns["carol"]
            # operator: OutValue reaches the device
            wa = a.w_sink.Connect()
            wa.OutValue = 7
            t_end = time.monotonic() + 10
            while a.w_sink_value() != 7 and time.monotonic() < t_end:
                time.sleep(0.05)
            assert a.w_sink_value() == 7
            wa.Close()
            # viewer: may connect (read), but its OutValue never reaches the device, poke is refused
            wb = b.w_sink.Connect()
            wb.OutValue = 99
            time.sleep(1.0)
            assert a.w_sink_value() == 7, "a viewer's OutValue reached the device"
            wb.Close()
            expect_rr_error(lambda: b.w_sink.PokeOutValue(5), RR.PermissionDeniedException, "may not write w_sink")
            v, _ts = b.w_state.PeekInValue()
            assert v is not None
            expect_rr_error(lambda: c.w_state.PeekInValue(), RR.PermissionDeniedException, "may not read w_state")
            expect_rr_error(lambda: c.w_both.Connect(), RR.PermissionDeniedException)
            # memory
            buf = np.zeros((4,))
            b.mem_double.Read(0, buf, 0, 4)
            assert b.mem_double.Length > 0
            expect_rr_error(lambda: b.mem_double.Write(0, np.array([1.0]), 0, 1), RR.PermissionDeniedException,
                            "may not write mem_double")
            expect_rr_error(lambda: c.mem_double.Read(0, buf, 0, 4), RR.PermissionDeniedException)
            a.mem_double.Write(0, np.array([5.0]), 0, 1)
            # pipes: a viewer may open an endpoint (to receive); carol may not
            ep = b.p_stream.Connect(-1)
            ep.Close()
            expect_rr_error(lambda: c.p_echo.Connect(-1), RR.PermissionDeniedException, "may not read p_echo")
        checks.check("rr: wires (connect, OutValue, poke, peek), memory, pipes per role", rr_wires_memory_pipes)

        def rr_write_only():
            # A write-only session may open a wire and send on it, but what the device sends back (its
            # InValue) never reaches it; an operator on the same wire gets it.
            a, e = conns["alice"], conns["erin"]
            we = e.w_both.Connect()
            wa = a.w_both.Connect()
            try:
                we.OutValue = [1.0, 2.0, 3.0]
                t_end = time.monotonic() + 10
                while time.monotonic() < t_end:
                    try:
                        if list(a.w_both.PeekOutValue()[0]) == [1.0, 2.0, 3.0]:
                            break
                    except RR.RobotRaconteurException:
                        pass
                    time.sleep(0.05)
                assert list(a.w_both.PeekOutValue()[0]) == [1.0, 2.0, 3.0], "the writer's OutValue did not reach the device"
                t_end = time.monotonic() + 10
                while time.monotonic() < t_end and not wa.InValueValid:
                    time.sleep(0.05)
                assert wa.InValueValid, "the operator got no InValue (the device's echo)"
                time.sleep(0.5)
                assert not we.InValueValid, "a write-only session received the device's InValue"
                expect_rr_error(lambda: e.w_both.PeekInValue(), RR.PermissionDeniedException, "may not read w_both")
            finally:
                we.Close()
                wa.Close()
        checks.check("rr: a write-only session sends on a wire but receives nothing on it", rr_write_only)

        def metric(prefix):
            with urllib.request.urlopen(base + "/metrics", timeout=10) as r:
                for line in r.read().decode().splitlines():
                    if line.startswith(prefix):
                        return float(line.rsplit(" ", 1)[1])
            raise AssertionError("no %s in /metrics" % prefix.strip())

        def pipe_packets_forwarded():
            return metric('rr_gateway_device_pipe_packets_total{device="interop"}')

        def rr_write_only_pipe():
            # The device echoes every p_unreliable packet to the endpoint that sent it. An operator gets
            # its echo; a write-only session's packet reaches the device (the gateway forwards it: the
            # pipe packet counter grows) but the echo is not delivered to it.
            # (AsyncSendPacket: the official library never completes a synchronous SendPacket on an
            # unreliable pipe; official_client.py "unreliable pipe echo".)
            a, e = conns["alice"], conns["erin"]
            pa = a.p_unreliable.Connect(-1)
            pe = e.p_unreliable.Connect(-1)
            try:
                pa.AsyncSendPacket("from alice", lambda *_a: None)
                t_end = time.monotonic() + 10
                while time.monotonic() < t_end and pa.Available == 0:
                    time.sleep(0.05)
                assert pa.Available > 0 and pa.ReceivePacket() == "from alice", "the operator got no echo"
                before = pipe_packets_forwarded()
                pe.AsyncSendPacket("from erin", lambda *_a: None)
                t_end = time.monotonic() + 10
                while time.monotonic() < t_end and pipe_packets_forwarded() < before + 1:
                    time.sleep(0.05)
                assert pipe_packets_forwarded() >= before + 1, "the writer's packet was not forwarded"
                time.sleep(1.0)
                assert pe.Available == 0, "a write-only session received the device's pipe echo"
                assert pa.Available == 0, "the writer's echo went to another session's endpoint"
            finally:
                pa.Close()
                pe.Close()
        checks.check("rr: a write-only session sends pipe packets but receives none", rr_write_only_pipe)

        def denied_total():
            return metric("rr_gateway_permission_denied_total ")

        def rr_read_only_pipes():
            # A viewer (read only) receives what the device sends on a pipe; a packet it sends itself is
            # dropped by the gateway (p_echo would send it straight back to that endpoint, which may read,
            # so an echo here means the device got it). An operator's packet on the same pipe is echoed.
            a, b = conns["alice"], conns["bob"]
            stream = b.p_stream.Connect(-1)
            try:
                a.send_stream(3)
                t_end = time.monotonic() + 10
                while time.monotonic() < t_end and stream.Available < 3:
                    time.sleep(0.05)
                got = [list(stream.ReceivePacket()) for _ in range(stream.Available)]
                assert got == [[0.0, 0.0], [1.0, 0.5], [2.0, 1.0]], got
            finally:
                stream.Close()
            pa, pb = a.p_echo.Connect(-1), b.p_echo.Connect(-1)
            try:
                def inner(i, label):
                    v = RRN.NewStructure("experimental.interop_test.Inner", a)
                    v.id, v.label, v.values = i, label, [float(i)]
                    return v
                pa.AsyncSendPacket(inner(1, "from alice"), lambda *_a: None)
                t_end = time.monotonic() + 10
                while time.monotonic() < t_end and pa.Available == 0:
                    time.sleep(0.05)
                assert pa.Available == 1 and pa.ReceivePacket().label == "from alice", "the operator got no echo"
                forwarded, denied = pipe_packets_forwarded(), denied_total()
                pb.AsyncSendPacket(inner(2, "from bob"), lambda *_a: None)
                t_end = time.monotonic() + 10
                while time.monotonic() < t_end and denied_total() == denied:
                    time.sleep(0.05)
                assert denied_total() > denied, "the viewer's packet was not refused"
                time.sleep(1.0)
                assert pb.Available == 0, "a read-only session's pipe packet reached the device (its echo came back)"
                assert pipe_packets_forwarded() == forwarded, "a read-only session's pipe packet was forwarded"
            finally:
                pa.Close()
                pb.Close()
        checks.check("rr: a read-only session receives pipe packets; the packets it sends are not delivered",
                     rr_read_only_pipes)

        def rr_poke_and_memory_allowed():
            import numpy as np
            a, b, e = conns["alice"], conns["bob"], conns["erin"]
            # erin (writer on w_both) pokes; the device has the value (its PeekOutValue, read by alice).
            e.w_both.PokeOutValue([7.0, 8.0, 9.0])
            assert list(a.w_both.PeekOutValue()[0]) == [7.0, 8.0, 9.0], "the writer's poke did not reach the device"
            expect_rr_error(lambda: b.w_both.PokeOutValue([1.0]), RR.PermissionDeniedException, "may not write w_both")
            assert list(a.w_both.PeekOutValue()[0]) == [7.0, 8.0, 9.0], "a refused poke changed the device's value"
            # alice (operator) writes memory; alice and bob (viewer) read the same values back.
            a.mem_double.Write(2, np.array([6.5, -1.25]), 0, 2)
            for who in (a, b):
                buf = np.zeros((2,))
                who.mem_double.Read(2, buf, 0, 2)
                assert list(buf) == [6.5, -1.25], list(buf)
            expect_rr_error(lambda: b.mem_double.Write(2, np.array([99.0]), 0, 1), RR.PermissionDeniedException)
            buf = np.zeros((1,))
            a.mem_double.Read(2, buf, 0, 1)
            assert buf[0] == 6.5, "a refused memory write changed the device's memory"
        checks.check("rr: PokeOutValue and memory writes allowed by role reach the device (read back)",
                     rr_poke_and_memory_allowed)

        def rr_child_objects():
            # Members below the root are named child.value, child_by_int[7].describe, child.leaf.x: rules
            # match those names, so carol (adder) gets exactly her two and nothing else down there.
            a, b, c = conns["alice"], conns["bob"], conns["carol"]
            cc, c7 = c.get_child(), c.get_child_by_int(7)
            assert cc.value == 1
            expect_rr_error(lambda: cc.name, RR.PermissionDeniedException, "may not read child.name of interop")
            expect_rr_error(lambda: cc.describe(), RR.PermissionDeniedException, "may not call child.describe")
            expect_rr_error(lambda: setattr(cc, "value", 5), RR.PermissionDeniedException, "may not write child.value")
            expect_rr_error(lambda: cc.get_leaf().x, RR.PermissionDeniedException, "may not read child.leaf.x")
            assert c7.describe() == "child[7] value=107"
            expect_rr_error(lambda: c7.value, RR.PermissionDeniedException, "may not read child_by_int[7].value")
            expect_rr_error(lambda: c.get_child_by_int(0).name, RR.PermissionDeniedException,
                            "may not read child_by_int[0].name")
            # bob (viewer) reads at every depth and writes nowhere; alice (operator) writes below the root.
            bc = b.get_child()
            assert bc.name == "child[plain]" and bc.get_leaf().x == 1.5
            expect_rr_error(lambda: setattr(bc, "value", 5), RR.PermissionDeniedException, "may not write child.value")
            expect_rr_error(lambda: bc.describe(), RR.PermissionDeniedException, "may not call child.describe")
            a.get_child().value = 42
            assert cc.value == 42 and bc.value == 42
            assert a.get_child().describe() == "child[plain] value=42"
            a.get_child().value = 1
        checks.check("rr: members of objects below the root (objref) allowed and refused by rule", rr_child_objects)

        def rr_callbacks():
            a, c = conns["alice"], conns["carol"]
            called = {"alice": 0, "carol": 0}

            def compute(who):
                def f(x, label):
                    called[who] += 1
                    return x * 2.0
                return f

            def notify(who):
                def f(info):
                    called[who] += 1
                return f
            a.cb_compute.Function = compute("alice")
            a.cb_notify.Function = notify("alice")
            c.cb_compute.Function = compute("carol")
            c.cb_notify.Function = notify("carol")
            assert a.call_callbacks(3.0) == 7.0
            assert called["alice"] == 2, called
            # carol may call call_callbacks but not be called back (no `call` on cb_*): the device's
            # callbacks go to a session that may take them (alice), never to carol.
            c.call_callbacks(3.0)
            assert called["carol"] == 0, called
            assert called["alice"] == 4, called
            expect_rr_error(lambda: conns["bob"].call_callbacks(1.0), RR.PermissionDeniedException)
        checks.check("rr: callbacks reach only sessions allowed to call them", rr_callbacks)

        def rr_definition():
            # The viewer's proxy is built from the service definition the gateway sent: every member is
            # there, also the ones bob may not use (permissions are not hidden in the definition).
            b = conns["bob"]
            for m in ("add", "reset", "count_up", "ev_values", "p_int32", "p_echo", "get_child"):
                assert m in dir(b), m
        checks.check("rr: a viewer's service definition lists every member", rr_definition)

        def rr_events():
            got = {"bob": 0, "carol": 0}
            lock = threading.Lock()

            def handler(name):
                def h(*_a):
                    with lock:
                        got[name] += 1
                return h
            conns["bob"].ev_values += handler("bob")
            conns["carol"].ev_values += handler("carol")
            conns["alice"].fire_events(3)
            t_end = time.monotonic() + 10
            while time.monotonic() < t_end and got["bob"] < 3:
                time.sleep(0.05)
            time.sleep(0.5)
            assert got["bob"] == 3, got
            assert got["carol"] == 0, got  # no read on ev_values: the event does not reach carol
        checks.check("rr: events reach only sessions allowed to read them", rr_events)

        def json_cookie_secure():
            # The cookie is Secure when the client reached the gateway over TLS: directly (HTTPS), or
            # through a trusted proxy that says so (X-Forwarded-Proto: https); a client that only claims
            # it gets no Secure cookie.
            import http.client

            def login_cookie(source, headers):
                c = http.client.HTTPConnection("127.0.0.1", port, timeout=20, source_address=(source, 0))
                try:
                    c.request("POST", "/api/login", json.dumps({"username": "bob", "password": "bob-pw"}),
                              dict(headers, **{"Content-Type": "application/json"}))
                    r = c.getresponse()
                    r.read()
                    assert r.status == 200, (source, r.status)
                    return r.getheader("Set-Cookie", "")
                finally:
                    c.close()

            proxied = login_cookie("127.0.0.2", {"X-Forwarded-Proto": "https", "X-Forwarded-For": "10.9.8.7"})
            assert "Secure" in proxied and "HttpOnly" in proxied, proxied
            forged = login_cookie("127.0.0.1", {"X-Forwarded-Proto": "https"})
            assert "rrgw_session=" in forged and "Secure" not in forged, forged
        checks.check("json: Secure cookie behind a trusted proxy saying https; not for a client only claiming it",
                     json_cookie_secure)

        # ---- JSON API ----
        prop = "/api/devices/interop/properties/p_int32"

        def json_cookie():
            h = Http(base)
            expect_status(h.call("GET", prop), 401, "RobotRaconteur.AuthenticationError")
            expect_status(h.call("GET", "/api/devices"), 401)
            expect_status(h.call("POST", "/api/login", {"username": "bob", "password": "nope"}), 401)
            st, hdrs, body = expect_status(h.call("POST", "/api/login", {"username": "bob", "password": "bob-pw"}), 200)
            assert body["user"] == "bob" and body["roles"] == ["viewer"], body
            cookie = hdrs.get("Set-Cookie", "")
            for part in ("rrgw_session=", "HttpOnly", "SameSite=Strict", "Path=/"):
                assert part in cookie, cookie
            assert "Secure" not in cookie, cookie  # plain HTTP
            assert expect_status(h.call("GET", prop), 200)[2]["value"] == B
            assert expect_status(h.call("GET", "/api/whoami"), 200)[2]["user"] == "bob"
            expect_status(h.call("PUT", prop, {"value": 1}), 403, "RobotRaconteur.PermissionDenied")
            expect_status(h.call("POST", "/api/devices/interop/functions/add", {"args": [1, 2]}), 403)
            expect_status(h.call("POST", "/api/devices/interop/functions/count_up", {"args": [1, 3]}), 403)  # generator
            expect_status(h.call("GET", "/api/devices/interop/wires/w_state"), 200)
            expect_status(h.call("GET", "/api/devices/interop/properties/name?object=child"), 200)  # below the root
            expect_status(h.call("POST", "/api/logout", {}), 200)
            expect_status(h.call("GET", prop), 401)
            # alice: all three
            h2 = Http(base)
            expect_status(h2.call("POST", "/api/login", {"username": "alice", "password": "alice-pw"}), 200)
            expect_status(h2.call("PUT", prop, {"value": A}), 200)
            assert expect_status(h2.call("POST", "/api/devices/interop/functions/add", {"args": [1, 2]}), 200)[2]["return"] == 3
            assert expect_status(h2.call("POST", "/api/devices/interop/functions/count_up", {"args": [1, 3]}),
                                 200)[2]["items"] == [1, 2, 3]
            # carol: add yes, p_double no
            h3 = Http(base)
            expect_status(h3.call("POST", "/api/login", {"username": "carol", "password": "carol-pw"}), 200)
            expect_status(h3.call("POST", "/api/devices/interop/functions/add", {"args": [1, 2]}), 200)
            expect_status(h3.call("GET", "/api/devices/interop/properties/p_double"), 403)
            expect_status(h3.call("PUT", prop, {"value": 9}), 403)
            expect_status(h3.call("GET", "/api/devices/interop/wires/w_state"), 403)
            expect_status(h3.call("GET", "/api/devices/interop/properties/name?object=child"), 403)
            # Adding a discovered device takes read, write and call everywhere (alice: operator). The role
            # check passes into 404: no node has this NodeID (NodeNotFound).
            add = {"nodeid": "00000000-0000-0000-0000-000000000001", "service": "x"}
            expect_status(Http(base).call("POST", "/api/discovered/add", add), 401)
            expect_status(h3.call("POST", "/api/discovered/add", add), 403, "RobotRaconteur.PermissionDenied")
            expect_status(h2.call("POST", "/api/discovered/add", add), 404)
        checks.check("json: cookie login, 401 without, 403 by role", json_cookie)

        def json_tokens():
            h = Http(base)
            auth = lambda t: {"Authorization": "Bearer " + t}  # noqa: E731
            assert expect_status(h.call("GET", prop, headers=auth(TOKEN), cookies=False), 200)[2]["value"] == A
            expect_status(h.call("PUT", prop, {"value": 1}, headers=auth(TOKEN), cookies=False), 403)
            expect_status(h.call("GET", prop, headers=auth(TOKEN + "x"), cookies=False), 401)
            now = int(time.time())
            good = make_jwt({"sub": "dave", "aud": "rr-gateway", "exp": now + 300, "roles": ["operator"]})
            expect_status(h.call("PUT", prop, {"value": A}, headers=auth(good), cookies=False), 200)
            expired = make_jwt({"sub": "dave", "aud": "rr-gateway", "exp": now - 600, "roles": ["operator"]})
            expect_status(h.call("GET", prop, headers=auth(expired), cookies=False), 401)
            forged = make_jwt({"sub": "dave", "aud": "rr-gateway", "exp": now + 300, "roles": ["operator"]},
                              secret=b"not-the-secret-not-the-secret-not-the-secret")
            expect_status(h.call("GET", prop, headers=auth(forged), cookies=False), 401)
            wrong_aud = make_jwt({"sub": "dave", "aud": "elsewhere", "exp": now + 300, "roles": ["operator"]})
            expect_status(h.call("GET", prop, headers=auth(wrong_aud), cookies=False), 401)
            future = make_jwt({"sub": "dave", "aud": "rr-gateway", "exp": now + 900, "nbf": now + 600})
            expect_status(h.call("GET", prop, headers=auth(future), cookies=False), 401)
            viewer_jwt = make_jwt({"sub": "erin", "aud": ["x", "rr-gateway"], "exp": now + 300, "roles": "viewer"})
            expect_status(h.call("PUT", prop, {"value": 1}, headers=auth(viewer_jwt), cookies=False), 403)
            # A login with the token gives a cookie session too.
            h2 = Http(base)
            expect_status(h2.call("POST", "/api/login", {"token": good}), 200)
            expect_status(h2.call("PUT", prop, {"value": A}), 200)
        checks.check("json: bearer token, JWT valid / expired / forged / wrong audience / not yet valid", json_tokens)

        def json_websocket():
            import websocket  # websocket-client
            ws = websocket.create_connection("ws://127.0.0.1:%d/" % port, subprotocols=["rr-gateway.json.v1"], timeout=20)

            def ask(msg):
                ws.send(json.dumps(msg))
                while True:
                    r = json.loads(ws.recv())
                    if r.get("id") == msg["id"]:
                        return r
            r = ask({"id": 1, "op": "get", "device": "interop", "member": "p_int32"})
            assert r["error"]["name"] == "RobotRaconteur.AuthenticationError", r
            r = ask({"id": 2, "op": "login", "username": "bob", "password": "wrong"})
            assert "error" in r, r
            r = ask({"id": 3, "op": "login", "username": "bob", "password": "bob-pw"})
            assert r["result"]["user"] == "bob", r
            assert ask({"id": 4, "op": "get", "device": "interop", "member": "p_int32"})["result"]["value"] == A
            r = ask({"id": 5, "op": "set", "device": "interop", "member": "p_int32", "value": 1})
            assert r["error"]["name"] == "RobotRaconteur.PermissionDenied", r
            # bob may subscribe to a wire (read) but not set its OutValue (write)
            r = ask({"id": 6, "op": "subscribe", "device": "interop", "member": "w_both"})
            assert "result" in r, r
            sub = r["result"]["subscription"]
            r = ask({"id": 7, "op": "set_out_value", "subscription": sub, "value": [1.0]})
            assert r["error"]["name"] == "RobotRaconteur.PermissionDenied", r
            r = ask({"id": 8, "op": "call", "device": "interop", "member": "add", "args": [1, 1]})
            assert r["error"]["name"] == "RobotRaconteur.PermissionDenied", r
            # a pipe: bob may open an endpoint (read) but not send on it (write)
            r = ask({"id": 9, "op": "subscribe", "device": "interop", "member": "p_unreliable"})
            assert r.get("result", {}).get("kind") == "pipe", r
            r = ask({"id": 10, "op": "send", "subscription": r["result"]["subscription"], "value": "hello"})
            assert r["error"]["name"] == "RobotRaconteur.PermissionDenied", r
            ws.close()
            # Logged in by the dashboard's cookie.
            h = Http(base)
            st, hdrs, _ = expect_status(h.call("POST", "/api/login", {"username": "carol", "password": "carol-pw"}), 200)
            sid = hdrs["Set-Cookie"].split(";")[0]
            ws = websocket.create_connection("ws://127.0.0.1:%d/" % port, subprotocols=["rr-gateway.json.v1"],
                                             header=["Cookie: " + sid], timeout=20)
            assert ask({"id": 1, "op": "call", "device": "interop", "member": "add", "args": [2, 2]})["result"]["return"] == 4
            r = ask({"id": 2, "op": "get", "device": "interop", "member": "p_double"})
            assert r["error"]["name"] == "RobotRaconteur.PermissionDenied", r
            r = ask({"id": 3, "op": "subscribe", "device": "interop", "member": "ev_values"})
            assert r["error"]["name"] == "RobotRaconteur.PermissionDenied", r
            ws.close()
            # The same cookie on an upgrade from a page of another site (cross-site WebSocket): refused
            # by the Origin check before any login is looked at, for both subprotocols.
            for proto in ("rr-gateway.json.v1", "robotraconteur.robotraconteur.com"):
                try:
                    websocket.create_connection("ws://127.0.0.1:%d/" % port, subprotocols=[proto], timeout=20,
                                                header=["Cookie: " + sid], origin="https://evil.example")
                    raise AssertionError("a cross-site %s upgrade with the cookie was accepted" % proto)
                except websocket.WebSocketBadStatusException as e:
                    assert e.status_code == 403, (proto, e.status_code)
            # A token in the URL is not a login.
            ws = websocket.create_connection("ws://127.0.0.1:%d/?access_token=%s" % (port, TOKEN),
                                             subprotocols=["rr-gateway.json.v1"], timeout=20)
            r = ask({"id": 1, "op": "get", "device": "interop", "member": "p_int32"})
            assert r["error"]["name"] == "RobotRaconteur.AuthenticationError", r
            ws.close()
        checks.check("json: WebSocket login by first message and by cookie, never by URL token; cross-site upgrades "
                     "with the cookie refused", json_websocket)

        def json_websocket_peek():
            import websocket  # websocket-client
            # peek is a read: bob (viewer) gets the wire's value, carol (no read on w_state) and erin
            # (write only on w_both) are refused; erin's refusal is not for want of a value (bob reads it).
            results = {}
            for user, member in (("bob", "w_state"), ("carol", "w_state"), ("bob", "w_both"), ("erin", "w_both")):
                ws = websocket.create_connection("ws://127.0.0.1:%d/" % port, subprotocols=["rr-gateway.json.v1"],
                                                 timeout=20)
                try:
                    def ask(msg):
                        ws.send(json.dumps(msg))
                        while True:
                            r = json.loads(ws.recv())
                            if r.get("id") == msg["id"]:
                                return r
                    assert "result" in ask({"id": 1, "op": "login", "username": user, "password": USERS[user][0]})
                    results[(user, member)] = ask({"id": 2, "op": "peek", "device": "interop", "member": member})
                finally:
                    ws.close()
            r = results[("bob", "w_state")]
            assert isinstance(r.get("result", {}).get("value"), dict) and "time" in r["result"], r
            assert "value" in results[("bob", "w_both")].get("result", {}), results
            for key in (("carol", "w_state"), ("erin", "w_both")):
                err = results[key].get("error", {})
                assert err.get("name") == "RobotRaconteur.PermissionDenied", (key, results[key])
                assert "may not read %s" % key[1] in err.get("message", ""), (key, err)
        checks.check("json: WebSocket peek needs read (viewer yes; no-read and write-only roles refused)",
                     json_websocket_peek)

        # ---- brute force (last: it locks this address out) ----
        def wait_log(text, after):
            deadline = time.monotonic() + 15
            while True:
                with open(os.path.join(work, "gateway.err")) as f:
                    log = f.read()[after:]
                if text in log:
                    return log
                if time.monotonic() > deadline:
                    raise AssertionError("no %r in the gateway's log after SIGHUP: %s" % (text, log[-800:]))
                time.sleep(0.1)

        def write_users(entries):
            write_password_file(os.path.join(work, "users.txt"), entries)

        def reload_users():
            # bob leaves, dave (operator) joins; alice stays as she was.
            write_users([("alice", *USERS["alice"]), ("dave", "dave-pw", "operator")])
            mark = os.path.getsize(os.path.join(work, "gateway.err"))
            os.kill(gateway.pid, signal.SIGHUP)
            wait_log("SIGHUP: logins reloaded: 2 user(s), 1 token(s), JWT HS256, 4 role(s)", mark)
            expect_rr_error(lambda: RRN.ConnectService(url, "bob", creds("bob-pw")), RR.AuthenticationException,
                            "Invalid username or password")
            # bob's session from before: its requests are refused from now on (no user, no roles).
            expect_rr_error(lambda: conns["bob"].p_int32, RR.PermissionDeniedException, "may not read p_int32")
            d = RRN.ConnectService(url, "dave", creds("dave-pw"))
            assert d.add(20, 22) == 42
            RRN.DisconnectService(d)
            h = Http(base)
            expect_status(h.call("POST", "/api/login", {"username": "dave", "password": "dave-pw"}), 200)
            # A broken file on the next SIGHUP is logged and changes nothing.
            write_users([("alice", *USERS["alice"]), "dave not-an-md5-digest operator"])
            mark = os.path.getsize(os.path.join(work, "gateway.err"))
            os.kill(gateway.pid, signal.SIGHUP)
            wait_log("SIGHUP: logins not reloaded, the previous ones stay in force: gateway.auth.users", mark)
            d = RRN.ConnectService(url, "dave", creds("dave-pw"))
            assert d.add(1, 2) == 3
            RRN.DisconnectService(d)
            assert conns["alice"].add(2, 2) == 4
        checks.check("reload: SIGHUP reads the users again (one leaves, one joins; a broken file changes nothing)",
                     reload_users)

        def limits():
            h = Http(base)
            for i in range(5):
                expect_status(h.call("POST", "/api/login", {"username": "alice", "password": "guess%d" % i}), 401)
            st, hdrs, body = expect_status(h.call("POST", "/api/login", {"username": "alice", "password": "alice-pw"}), 429)
            assert "Too many failed logins" in body["error"]["message"], body
            assert int(hdrs.get("Retry-After", "0")) > 0, hdrs
            expect_rr_error(lambda: RRN.ConnectService(url, "alice", creds("alice-pw")), RR.AuthenticationException,
                            "Too many failed logins")
            with urllib.request.urlopen(base + "/metrics", timeout=10) as r:
                text = r.read().decode()
            vals = {}
            for line in text.splitlines():
                if line.startswith("rr_gateway_login"):
                    k, v = line.rsplit(" ", 1)
                    vals[k] = float(v)
            assert vals.get('rr_gateway_login_failures_total{channel="http"}', 0) >= 6, vals
            assert vals.get('rr_gateway_login_failures_total{channel="rr"}', 0) >= 2, vals
            assert vals.get("rr_gateway_login_lockouts_total", 0) >= 1, vals
            assert vals.get("rr_gateway_login_rate_limited_total", 0) >= 2, vals
            # Sessions opened before the lockout carry on.
            assert conns["alice"].p_int32 == A
        checks.check("limits: brute force locked out (HTTP 429, RR), /metrics counts", limits)

        for c in conns.values():
            try:
                RRN.DisconnectService(c)
            except Exception:  # noqa: BLE001
                pass
    except StepFailed as e:
        print(json.dumps({"setup_error": str(e)}))
        return 2
    finally:
        stop(gateway)
        stop(device)
        stop(device_users)
        try:
            RRN.Shutdown()
        except Exception:  # noqa: BLE001
            pass
    ok = all(r["ok"] for r in checks.results)
    print(json.dumps({"ok": ok, "checks": checks.results}, indent=1))
    if not ok:
        print(tail(os.path.join(work, "gateway.err")), file=sys.stderr)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
