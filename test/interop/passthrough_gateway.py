"""Logins, object locks, monitor locks and callbacks THROUGH the gateway with `auth: passthrough`
(docs/security.md "Logins and locks through the gateway"): official Python clients -> rr-gateway ->
rr_interop_service --users (official password file format), or with --official -> the official
library's own service (official_service.py --users), so that the forwarding is proven against an
official device: every answer must then be the one the official library gives (locks_logins.Expected).

Every check of locks_logins.py runs against the gateway's mirror of the device instead of the device
itself, and must give the same answers (the device's own users, privileges, object locks, monitor
locks, release on disconnect and on a killed client process). Then:
  json     the JSON API (/api/devices) shows who holds a lock / a monitor taken through the gateway,
           and forgets it when released;
  callback two clients calling call_callbacks() at the same time each get their own callback
           (each has its own upstream session);
  limit    a device with max_passthrough_sessions: 2 refuses a third client with a clear error and
           admits it once one of the two has gone;
  shared   a device in the default shared mode holds locks at the gateway: an anonymous client's
           RequestObjectLock is refused with PermissionDenied (this gateway has no users), its
           MonitorEnter is held at the gateway and listed in /api/devices (shared_locks_gateway.py
           has the rest);
  device_login  a JSON WebSocket logs in to the device as one of its users (`device_login`): a wrong
           password gets the device's own error; while alice holds a user lock, the socket logged in
           as alice reads the locked object and subscribes to a wire, a pipe and an event on her own
           session (the wire's answer, the pipe's echo and the events arrive), one logged in as bob
           (and one without a device login, on the gateway's shared session) get ObjectLockedError
           for both; device_logout ends alice's subscriptions with a "closed" push and goes back to
           the shared session; a shared device refuses device_login.
  strict   a device with json_api_requires_device_login refuses REST requests and WebSocket requests
           without a device_login (AuthenticationError naming device_login) and serves them after one.
Prints one JSON summary; exit 0 when every check passed, 1 on a failed check, 2 on setup errors, 77
when the official package is missing.

Usage: passthrough_gateway.py --gateway PATH/rr-gateway (--service PATH/rr_interop_service | --official) [--timeout S]
"""

import argparse
import atexit
import json
import os
import shutil
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from child_procs import StepFailed, get_json, read_json_line, start, stop, tail  # noqa: E402

try:
    import RobotRaconteur as RR
except ImportError as e:  # pragma: no cover
    print("SKIP: official RobotRaconteur package missing: %s" % e)
    sys.exit(77)

import locks_logins as ll  # noqa: E402  (the same checks, through the gateway)

RRN = ll.RRN
GATEWAY_USER = ("gateway", "gateway-pw")  # the gateway's own (shared) session: JSON API, definitions


class JsonSocket:
    """A JSON WebSocket to the gateway: ask() sends a request and returns its reply, keeping the pushes
    that arrive meanwhile for wait_push()."""

    def __init__(self, port):
        import websocket  # websocket-client
        self.ws = websocket.create_connection("ws://127.0.0.1:%d/" % port, subprotocols=["rr-gateway.json.v1"], timeout=20)
        self.counter = 0
        self.pushes = []

    def ask(self, msg):
        self.counter += 1
        msg = dict(msg, id=self.counter)
        self.ws.send(json.dumps(msg))
        while True:
            r = json.loads(self.ws.recv())
            if r.get("id") == msg["id"]:
                return r
            if "subscription" in r:
                self.pushes.append(r)

    def wait_push(self, pred, what, timeout=10.0):
        """The first push (kept or new) with pred(push); removed from the kept ones."""
        import websocket  # websocket-client
        deadline = time.monotonic() + timeout
        while True:
            for p in self.pushes:
                if pred(p):
                    self.pushes.remove(p)
                    return p
            left = deadline - time.monotonic()
            ll.expect(left > 0, "no push: %s (have %r)" % (what, self.pushes[-5:]))
            self.ws.settimeout(left)
            try:
                r = json.loads(self.ws.recv())
            except websocket.WebSocketTimeoutException:
                continue
            finally:
                self.ws.settimeout(20)
            if "subscription" in r:
                self.pushes.append(r)

    def close(self):
        self.ws.close()


def device_status(port, name):
    for d in get_json(port, "/api/devices"):
        if d["name"] == name:
            return d
    raise AssertionError("device %s not in /api/devices" % name)


def expect_locks(port, name, expected, what, timeout=5.0):
    """Waits until /api/devices shows exactly `expected` ([(path, user, kind)]) for `name`."""
    deadline = time.monotonic() + timeout
    got = None
    while time.monotonic() < deadline:
        got = sorted((l["path"], l["user"], l["kind"]) for l in device_status(port, name).get("locks", []))
        if got == sorted(expected):
            return
        time.sleep(0.05)
    raise AssertionError("%s: /api/devices locks %r, expected %r" % (what, got, sorted(expected)))


def run_extra_checks(port, ck, exp):
    url = "rr+tcp://127.0.0.1:%d/?service=interop" % port
    url_small = "rr+tcp://127.0.0.1:%d/?service=small" % port
    url_shared = "rr+tcp://127.0.0.1:%d/?service=shared" % port

    def json_shows_holders():
        d = device_status(port, "interop")
        ll.expect(d.get("auth") == "passthrough", "auth in /api/devices: %r" % d)
        a = ll.connect(url, "alice")
        b = ll.connect(url, "bob")
        try:
            ll.expect(device_status(port, "interop")["passthrough_sessions"] >= 2, "two passthrough sessions")
            ll.expect(RRN.RequestObjectLock(a, RR.RobotRaconteurObjectLockFlags_USER_LOCK) == "OK", "alice locks")
            expect_locks(port, "interop", [("interop", "alice", "user")], "alice's user lock")
            ll.expect_raises(RR.ObjectLockedException, lambda: b.base_name, "bob reads the locked root", "alice")
            ll.expect(RRN.ReleaseObjectLock(a) == "OK", "alice releases")
            expect_locks(port, "interop", [], "after the release")
            child = b.get_child()
            ll.expect(RRN.RequestObjectLock(child, RR.RobotRaconteurObjectLockFlags_CLIENT_LOCK) == "OK", "bob locks the child")
            expect_locks(port, "interop", [("interop.child", "bob", "client")], "bob's client lock on the child")
            RRN.MonitorEnter(a, -1)
            expect_locks(port, "interop", [("interop.child", "bob", "client"), ("interop", "alice", "monitor")],
                         "alice's monitor beside bob's lock")
            RRN.MonitorExit(a)
            RRN.DisconnectService(b)
            b = None
            expect_locks(port, "interop", [], "bob's client lock went with his session")
        finally:
            for c in (a, b):
                if c is not None:
                    try:
                        RRN.DisconnectService(c)
                    except Exception:  # noqa: BLE001
                        pass

    ck.check("json: /api/devices shows lock and monitor holders through the gateway", json_shows_holders)

    def callbacks_to_the_right_client():
        a = ll.connect(url, "alice")
        b = ll.connect(url, "bob")
        calls = {"a": [], "b": []}
        try:
            a.cb_compute.Function = lambda x, label: (calls["a"].append(x), x * 2.0)[1]
            b.cb_compute.Function = lambda x, label: (calls["b"].append(x), x * 3.0)[1]
            a.cb_notify.Function = lambda info: None
            b.cb_notify.Function = lambda info: None
            errors = []

            def loop(c, factor, base):
                try:
                    for i in range(15):
                        x = float(base + i)
                        r = c.call_callbacks(x)
                        if r != x * factor + 1.0:
                            errors.append("call_callbacks(%s) = %s, expected %s" % (x, r, x * factor + 1.0))
                except Exception as e:  # noqa: BLE001
                    errors.append("%s: %s" % (type(e).__name__, e))

            ta = threading.Thread(target=loop, args=(a, 2.0, 100))
            tb = threading.Thread(target=loop, args=(b, 3.0, 200))
            ta.start()
            tb.start()
            ta.join(60)
            tb.join(60)
            ll.expect(not errors, "; ".join(errors[:5]))
            ll.expect(sorted(calls["a"]) == [float(100 + i) for i in range(15)], "alice's callbacks: %r" % calls["a"])
            ll.expect(sorted(calls["b"]) == [float(200 + i) for i in range(15)], "bob's callbacks: %r" % calls["b"])
        finally:
            for c in (a, b):
                try:
                    RRN.DisconnectService(c)
                except Exception:  # noqa: BLE001
                    pass

    ck.check("callback: each client's callback reaches that client (concurrent calls)", callbacks_to_the_right_client)

    def session_limit():
        c1 = ll.connect(url_small, "alice")
        c2 = ll.connect(url_small, "bob")
        c3 = None
        try:
            e = ll.expect_raises(RR.RobotRaconteurException, lambda: ll.connect(url_small, "carol"), "a third client",
                                 "passthrough session limit (2 upstream sessions) reached")
            RRN.DisconnectService(c1)
            c1 = None
            c3 = ll.eventually(lambda: ll.connect(url_small, "carol"), "a third client after one left")
            ll.expect(isinstance(c3.base_name, str), "the third client reads")
            ll.expect(device_status(port, "small")["passthrough_sessions"] == 2, "two upstream sessions")
            import urllib.request
            with urllib.request.urlopen("http://127.0.0.1:%d/metrics" % port, timeout=10) as r:
                metrics = r.read().decode()
            for line in ('rr_gateway_device_passthrough_sessions{device="small"} 2',
                         'rr_gateway_device_clients{device="small"} 2',
                         'rr_gateway_device_passthrough_sessions{device="shared"} 0'):
                ll.expect(line in metrics.splitlines(), "/metrics has %r" % line)
            del e
        finally:
            for c in (c1, c2, c3):
                if c is not None:
                    try:
                        RRN.DisconnectService(c)
                    except Exception:  # noqa: BLE001
                        pass

    ck.check("limit: max_passthrough_sessions refuses a client with a clear error", session_limit)

    def shared_holds_locks():
        c = RRN.ConnectService(url_shared)  # the shared mode: the gateway's own login to the device
        try:
            ll.expect(isinstance(c.base_name, str), "reads on the shared session")
            ll.expect_raises(RR.PermissionDeniedException,
                             lambda: RRN.RequestObjectLock(c, RR.RobotRaconteurObjectLockFlags_USER_LOCK),
                             "an anonymous object lock on a shared device", "User must be authenticated to lock object")
            RRN.MonitorEnter(c, 1000)
            try:
                expect_locks(port, "shared", [("shared", None, "monitor")], "the monitor held at the gateway")
            finally:
                RRN.MonitorExit(c)
            expect_locks(port, "shared", [], "after MonitorExit")
        finally:
            RRN.DisconnectService(c)

    ck.check("shared: locks held at the gateway (anonymous: no object lock, a monitor)", shared_holds_locks)

    def no_login_refused_with_device_error():
        ll.expect_raises(RR.AuthenticationException, lambda: RRN.ConnectService(url_small), "no login (small)",
                         exp.login_refused("Username not provided"))

    ck.check("login: the device's own error for a client without a login", no_login_refused_with_device_error)

    def json_device_login():
        def error_of(r):
            return (r.get("error") or {}).get("name", ""), (r.get("error") or {}).get("message", "")

        get_root = {"op": "get", "device": "interop", "member": "base_name"}
        ws_a, ws_b, ws_n = JsonSocket(port), JsonSocket(port), JsonSocket(port)
        ask_a, ask_b, ask_n = ws_a.ask, ws_b.ask, ws_n.ask
        holder = None
        try:
            sessions_before = device_status(port, "interop")["passthrough_sessions"]
            name, msg = error_of(ask_a({"op": "device_login", "device": "interop", "username": "alice", "password": "wrong"}))
            ll.expect(name == "RobotRaconteur.AuthenticationError", "wrong password: %s %s" % (name, msg))
            r = ask_a({"op": "device_login", "device": "interop", "username": "alice", "password": ll.USERS["alice"][0]})
            ll.expect(r.get("result") == {"device": "interop", "username": "alice"}, "alice's device_login: %r" % r)
            r = ask_b({"op": "device_login", "device": "interop", "username": "bob", "password": ll.USERS["bob"][0]})
            ll.expect("result" in r, "bob's device_login: %r" % r)
            ll.expect(device_status(port, "interop")["passthrough_sessions"] == sessions_before + 2,
                      "two more passthrough sessions")
            name, msg = error_of(ask_n({"op": "device_login", "device": "shared", "username": "alice", "password": "x"}))
            ll.expect(name == "RobotRaconteur.InvalidOperation" and "passthrough" in msg, "shared device: %s %s" % (name, msg))

            holder = ll.connect(url, "alice")  # a native RR client of alice's locks the root object
            ll.expect(RRN.RequestObjectLock(holder, RR.RobotRaconteurObjectLockFlags_USER_LOCK) == "OK", "alice locks")
            r = ask_a(get_root)
            ll.expect("result" in r, "alice's socket reads the object alice locked: %r" % r)
            for who, ask in (("bob's socket", ask_b), ("a socket without device_login", ask_n)):
                name, msg = error_of(ask(get_root))
                ll.expect(name == "RobotRaconteur.ObjectLockedError" and "alice" in msg,
                          "%s under alice's lock: %s %s" % (who, name, msg))
            # Subscriptions follow the device_login too: alice's socket connects the wire, pipe and
            # event on her own session (the device lets her past her lock), bob's and the gateway's
            # shared session are refused by the device.
            subscribe_w = {"op": "subscribe", "device": "interop", "member": "w_both"}
            r = ask_a(subscribe_w)
            ll.expect(r.get("result", {}).get("kind") == "wire", "alice subscribes to w_both under her lock: %r" % r)
            sub_w = r["result"]["subscription"]
            for who, ask in (("bob's socket", ask_b), ("a socket without device_login", ask_n)):
                name, msg = error_of(ask(subscribe_w))
                ll.expect(name == "RobotRaconteur.ObjectLockedError" and "alice" in msg,
                          "%s subscribes under alice's lock: %s %s" % (who, name, msg))
            # w_both answers a client's OutValue on that client's connection only, reversed.
            r = ask_a({"op": "set_out_value", "subscription": sub_w, "value": [1.0, 2.0, 3.0]})
            ll.expect(r.get("result") == {}, "alice sets w_both's OutValue: %r" % r)
            ws_a.wait_push(lambda p: p.get("subscription") == sub_w and p.get("value") == [3.0, 2.0, 1.0],
                      "the device's answer on alice's wire connection")
            r = ask_a({"op": "subscribe", "device": "interop", "member": "p_unreliable"})
            ll.expect(r.get("result", {}).get("kind") == "pipe", "alice opens p_unreliable: %r" % r)
            sub_p = r["result"]["subscription"]
            r = ask_a({"op": "send", "subscription": sub_p, "value": "on alice's session"})
            ll.expect("result" in r, "alice sends on p_unreliable: %r" % r)
            ws_a.wait_push(lambda p: p.get("subscription") == sub_p and p.get("value") == "on alice's session",
                      "the echo on alice's pipe endpoint")
            r = ask_a({"op": "subscribe", "device": "interop", "member": "ev_values"})
            ll.expect(r.get("result", {}).get("kind") == "event", "alice subscribes to ev_values: %r" % r)
            sub_e = r["result"]["subscription"]
            r = ask_a({"op": "call", "device": "interop", "member": "fire_events", "args": [2]})
            ll.expect("result" in r, "alice fires two events: %r" % r)
            for n in (1, 2):
                ws_a.wait_push(lambda p: p.get("subscription") == sub_e and p.get("kind") == "event",
                          "event %d on alice's session" % n)
            r = ask_a({"op": "device_logout", "device": "interop"})
            ll.expect(r.get("result") == {}, "device_logout: %r" % r)
            for sub in (sub_w, sub_p, sub_e):
                p = ws_a.wait_push(lambda p, sub=sub: p.get("subscription") == sub and p.get("kind") == "closed",
                              "subscription %d closed by device_logout" % sub)
                ll.expect(p["error"]["name"] == "RobotRaconteur.OperationAborted" and "device_logout" in p["error"]["message"],
                          "closed by device_logout: %r" % p)
            name, msg = error_of(ask_a(get_root))
            ll.expect(name == "RobotRaconteur.ObjectLockedError", "after device_logout: shared session: %s %s" % (name, msg))
            ll.expect(RRN.ReleaseObjectLock(holder) == "OK", "alice releases")
            ll.expect("result" in ask_b(get_root), "bob's socket reads after the release")
        finally:
            for ws in (ws_a, ws_b, ws_n):
                ws.close()
            if holder is not None:
                try:
                    RRN.DisconnectService(holder)
                except Exception:  # noqa: BLE001
                    pass
        ll.eventually(lambda: ll.expect(device_status(port, "interop")["passthrough_sessions"] == sessions_before,
                                        "closed sockets close their device sessions"), "sessions closed")

    ck.check("json: device_login gives a WebSocket the device's own user, locks apply", json_device_login)

    def json_requires_device_login():
        import urllib.error
        import urllib.request
        ll.expect(device_status(port, "strict").get("json_api_requires_device_login") is True,
                  "/api/devices names the requirement")
        ll.expect(device_status(port, "interop").get("json_api_requires_device_login") is False,
                  "and its absence on the other passthrough device")
        # REST has no device session: refused, not served by the gateway's own login to the device.
        try:
            urllib.request.urlopen("http://127.0.0.1:%d/api/devices/strict/properties/base_name" % port, timeout=10)
            raise AssertionError("REST read of a device that requires a device login was served")
        except urllib.error.HTTPError as e:
            body = json.loads(e.read())
            ll.expect(e.code == 401 and body["error"]["name"] == "RobotRaconteur.AuthenticationError"
                      and "device_login" in body["error"]["message"], "REST refused: %s %r" % (e.code, body))
        ll.expect("value" in get_json(port, "/api/devices/interop/properties/base_name"),
                  "REST on a passthrough device without the requirement still reads")
        ws = JsonSocket(port)
        ask = ws.ask
        try:
            for op in ({"op": "get", "member": "base_name"}, {"op": "subscribe", "member": "ev_values"},
                       {"op": "call", "member": "add", "args": [1, 2]}):
                r = ask(dict(op, device="strict"))
                ll.expect(r.get("error", {}).get("name") == "RobotRaconteur.AuthenticationError",
                          "%s without device_login refused: %r" % (op["op"], r))
            r = ask({"op": "device_login", "device": "strict", "username": "bob", "password": ll.USERS["bob"][0]})
            ll.expect("result" in r, "bob's device_login: %r" % r)
            ll.expect("value" in ask({"op": "get", "device": "strict", "member": "base_name"}).get("result", {}),
                      "bob reads after his device_login")
            r = ask({"op": "subscribe", "device": "strict", "member": "ev_values"})
            ll.expect(r.get("result", {}).get("kind") == "event", "bob subscribes after his device_login: %r" % r)
            ll.expect(ask({"op": "device_logout", "device": "strict"}).get("result") == {}, "device_logout")
            r = ask({"op": "get", "device": "strict", "member": "base_name"})
            ll.expect(r.get("error", {}).get("name") == "RobotRaconteur.AuthenticationError",
                      "refused again after device_logout: %r" % r)
        finally:
            ws.close()

    ck.check("json: json_api_requires_device_login refuses REST and sockets without a device_login", json_requires_device_login)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gateway", required=True)
    target = ap.add_mutually_exclusive_group(required=True)
    target.add_argument("--service", help="our rr_interop_service as the device")
    target.add_argument("--official", action="store_true", help="the official library's service as the device")
    ap.add_argument("--timeout", type=float, default=240)
    args = ap.parse_args()

    tmp = tempfile.mkdtemp(prefix="rr-passthrough-")
    atexit.register(shutil.rmtree, tmp, True)  # logs are printed before exit; os._exit on timeout keeps them
    users = os.path.join(tmp, "users.txt")
    exp = ll.Expected("official" if args.official else "ours", gateway=True)
    svc_err = os.path.join(tmp, "service.err")
    gw_err = os.path.join(tmp, "gateway.err")
    svc = gw = None
    ck = ll.Checks()
    timer = threading.Timer(args.timeout, lambda: os._exit(3))
    timer.daemon = True
    timer.start()
    try:
        svc, ready = ll.start_device(args.service, users, {GATEWAY_USER[0]: (GATEWAY_USER[1], "_")}, svc_err,
                                     args.timeout + 30)
        dev = ready["url"]
        config = os.path.join(tmp, "gateway.yaml")
        with open(config, "w") as fh:
            common = "    url: %s\n    username: %s\n    password: %s\n" % (json.dumps(dev), GATEWAY_USER[0], GATEWAY_USER[1])
            fh.write("gateway:\n  listen: 127.0.0.1\n  port: 0\ndemo:\n  enabled: false\ndevices:\n")
            fh.write("  - name: interop\n" + common + "    auth: passthrough\n")
            fh.write("  - name: small\n" + common + "    auth: passthrough\n    max_passthrough_sessions: 2\n")
            fh.write("  - name: shared\n" + common)
            fh.write("  - name: strict\n" + common + "    auth: passthrough\n    json_api_requires_device_login: true\n")
        gw = start([args.gateway, "--config", config, "--no-local", "--log-level", "warning"], gw_err)
        port = read_json_line(gw, 30, "rr-gateway")["port"]
        deadline = time.monotonic() + 30
        while True:
            try:
                if all(d["state"] == "connected" for d in get_json(port, "/api/devices")):
                    break
            except OSError:
                pass
            if time.monotonic() > deadline:
                raise StepFailed("gateway devices not connected: %s" % tail(gw_err))
            time.sleep(0.1)
        ll.register_transport()
        ll.run_checks("rr+tcp://127.0.0.1:%d/?service=interop" % port, ck, exp)
        run_extra_checks(port, ck, exp)
    except StepFailed as e:
        print(json.dumps({"error": str(e), "service_stderr": tail(svc_err), "gateway_stderr": tail(gw_err)}))
        return 2
    finally:
        gw_status = stop(gw)
        svc_status = stop(svc)
    failed = [r for r in ck.results if not r["ok"]]
    print(json.dumps({"service": exp.device, "checks": len(ck.results), "failed": failed,
                      "differences_from_reference": exp.differences_from_reference(), "gateway_status": gw_status,
                      "service_status": svc_status}, indent=1))
    if failed:
        print("--- gateway\n" + tail(gw_err) + "\n--- service\n" + tail(svc_err), file=sys.stderr)
    return 1 if failed or gw_status not in (0, None) or svc_status not in (0, None) else 0


if __name__ == "__main__":
    sys.exit(main())
