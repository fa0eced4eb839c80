"""Object and monitor locks held AT THE GATEWAY for a device in the default `auth: shared` mode
(docs/security.md "auth: shared"): official Python clients -> rr-gateway (gateway.auth: its own users,
whose privilege column holds their roles and objectlock / objectlockoverride) -> rr_interop_service
without logins of its own (every gateway client shares the gateway's one session to it).

Every check of locks_logins.py runs against the shared device through the gateway, the users being
gateway users, and must give the same answers as our ObjectService gives directly: a user without
objectlock refused; a user lock blocking the other user on the object and a child, not the user's
other session; a client lock blocking the user's other session, released by DisconnectService; a
user lock of a client process killed with SIGKILL released with its user's last session;
objectlockoverride; a monitor handed from one client to the other. Then:
  nolock    a [nolock] member passes another user's lock.
  json      /api/devices lists the locks held at the gateway (user, client, monitor) with their holders,
            and forgets them on release and disconnect.
  json api  REST and WebSocket requests act as their gateway user without a session of their own:
            alice's pass her user lock, bob's get 409 ObjectLockedError "Object locked by alice"
            (a wire subscription too), alice's are refused by her own client lock and by a monitor.
  direct    the device's own (direct) clients are not bound by locks held at the gateway.
  anonymous a second gateway without gateway.auth: object locks need a login (PermissionDenied),
            a monitor taken by an anonymous client refuses another.
Prints one JSON summary; exit 0 when every check passed, 1 on a failed check, 2 on setup errors, 77
when the official package is missing.

Usage: shared_locks_gateway.py --gateway PATH/rr-gateway --service PATH/rr_interop_service [--timeout S]
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
from child_procs import StepFailed, get_json, read_json_line, start, stop, tail, write_password_file  # noqa: E402

try:
    import RobotRaconteur as RR
except ImportError as e:  # pragma: no cover
    print("SKIP: official RobotRaconteur package missing: %s" % e)
    sys.exit(77)

import locks_logins as ll  # noqa: E402  (the same checks, through the gateway's shared device)
from gateway_logins import Http  # noqa: E402
from passthrough_gateway import JsonSocket  # noqa: E402

RRN = ll.RRN
# The gateway's users: locks_logins' users and privileges, each with the role that may do everything
# (locks too: `lock` lets a lock request reach the lock rules, where objectlock then decides).
GATEWAY_USERS = {user: (pw, "operator" if priv == "_" else "operator," + priv) for user, (pw, priv) in ll.USERS.items()}


def login(base, user):
    http = Http(base)
    status, _, body = http.call("POST", "/api/login", {"username": user, "password": ll.USERS[user][0]})
    ll.expect(status == 200, "%s logs in over HTTP: %s %r" % (user, status, body))
    return http


def device_status(http, name):
    status, _, body = http.call("GET", "/api/devices")
    ll.expect(status == 200, "GET /api/devices: %s %r" % (status, body))
    for d in body:
        if d["name"] == name:
            return d
    raise AssertionError("device %s not in /api/devices" % name)


def expect_locks(http, expected, what, timeout=5.0):
    """Waits until /api/devices shows exactly `expected` ([(path, user, kind)]) for the shared device."""
    deadline = time.monotonic() + timeout
    got = None
    while time.monotonic() < deadline:
        got = sorted((l["path"], l["user"], l["kind"]) for l in device_status(http, "interop")["locks"])
        if got == sorted(expected):
            return
        time.sleep(0.05)
    raise AssertionError("%s: /api/devices locks %r, expected %r" % (what, got, sorted(expected)))


def disconnect(*clients):
    for c in clients:
        if c is not None:
            try:
                RRN.DisconnectService(c)
            except Exception:  # noqa: BLE001
                pass


def run_extra_checks(port, device_url, ck):
    url = "rr+tcp://127.0.0.1:%d/?service=interop" % port
    base = "http://127.0.0.1:%d" % port

    def nolock_member():
        a, b = ll.connect(url, "alice"), ll.connect(url, "bob")
        try:
            ll.expect(RRN.RequestObjectLock(a, RR.RobotRaconteurObjectLockFlags_USER_LOCK) == "OK", "alice locks")
            ll.expect_raises(RR.ObjectLockedException, lambda: b.base_name, "bob reads base_name", "alice")
            ll.expect(b.nolock_value in (11, 12), "bob reads the [nolock] member under alice's lock")
            ll.expect(RRN.ReleaseObjectLock(a) == "OK", "alice releases")
        finally:
            disconnect(a, b)

    ck.check("nolock: a [nolock] member passes another user's lock held at the gateway", nolock_member)

    def json_shows_holders():
        http = login(base, "carol")
        d = device_status(http, "interop")
        ll.expect(d.get("auth") == "shared" and d.get("locks") == [], "a shared device's fields: %r" % d)
        ll.expect("passthrough_sessions" not in d, "no passthrough fields on a shared device: %r" % d)
        a, b = ll.connect(url, "alice"), ll.connect(url, "bob")
        try:
            ll.expect(RRN.RequestObjectLock(a, RR.RobotRaconteurObjectLockFlags_USER_LOCK) == "OK", "alice locks")
            expect_locks(http, [("interop", "alice", "user")], "alice's user lock")
            ll.expect(RRN.ReleaseObjectLock(a) == "OK", "alice releases")
            expect_locks(http, [], "after the release")
            child = b.get_child()
            ll.expect(RRN.RequestObjectLock(child, RR.RobotRaconteurObjectLockFlags_CLIENT_LOCK) == "OK", "bob locks the child")
            RRN.MonitorEnter(a, -1)
            expect_locks(http, [("interop.child", "bob", "client"), ("interop", "alice", "monitor")],
                         "bob's client lock and alice's monitor")
            RRN.MonitorExit(a)
            expect_locks(http, [("interop.child", "bob", "client")], "after alice's MonitorExit")
            RRN.DisconnectService(b)
            b = None
            expect_locks(http, [], "bob's client lock went with his session")
        finally:
            disconnect(a, b)

    ck.check("json: /api/devices lists the locks held at the gateway and their holders", json_shows_holders)

    def json_requests_act_as_their_user():
        rest_a, rest_b = login(base, "alice"), login(base, "bob")
        prop = "/api/devices/interop/properties/base_name"
        ws_b = JsonSocket(port)
        a = ll.connect(url, "alice")
        try:
            r = ws_b.ask({"op": "login", "username": "bob", "password": ll.USERS["bob"][0]})
            ll.expect("result" in r, "bob's WebSocket login: %r" % r)
            ll.expect(RRN.RequestObjectLock(a, RR.RobotRaconteurObjectLockFlags_USER_LOCK) == "OK", "alice locks")
            status, _, body = rest_a.call("GET", prop)
            ll.expect(status == 200 and "value" in body, "alice's REST read under her user lock: %s %r" % (status, body))
            status, _, body = rest_b.call("GET", prop)
            ll.expect(status == 409 and body["error"]["name"] == "RobotRaconteur.ObjectLockedError"
                      and body["error"]["message"] == "Object locked by alice", "bob's REST read: %s %r" % (status, body))
            status, _, body = rest_b.call("GET", "/api/devices/interop/properties/nolock_value")
            ll.expect(status == 200, "bob's REST read of the [nolock] member: %s %r" % (status, body))
            status, _, body = rest_b.call("POST", "/api/devices/interop/functions/add", {"args": [1, 2]})
            ll.expect(status == 409, "bob's REST call: %s %r" % (status, body))
            for msg in ({"op": "get", "device": "interop", "member": "base_name"},
                        {"op": "subscribe", "device": "interop", "member": "w_both"}):
                r = ws_b.ask(msg)
                ll.expect(r.get("error", {}).get("name") == "RobotRaconteur.ObjectLockedError",
                          "bob's WebSocket %s under alice's lock: %r" % (msg["op"], r))
            r = ws_b.ask({"op": "subscribe", "device": "interop", "member": "ev_values"})
            ll.expect(r.get("result", {}).get("kind") == "event", "events are not lock-checked: %r" % r)
            ll.expect(RRN.ReleaseObjectLock(a) == "OK", "alice releases")

            # A client lock is the locking session's only: alice's REST requests have no session.
            ll.expect(RRN.RequestObjectLock(a, RR.RobotRaconteurObjectLockFlags_CLIENT_LOCK) == "OK", "alice client-locks")
            status, _, body = rest_a.call("GET", prop)
            ll.expect(status == 409 and body["error"]["name"] == "RobotRaconteur.ObjectLockedError",
                      "alice's REST read under her client lock: %s %r" % (status, body))
            ll.expect(RRN.ReleaseObjectLock(a) == "OK", "alice releases her client lock")
            RRN.MonitorEnter(a, -1)
            try:
                status, _, body = rest_a.call("GET", prop)
                ll.expect(status == 409 and body["error"]["name"] == "RobotRaconteur.InvalidOperation"
                          and "monitor locked" in body["error"]["message"], "REST read under a monitor: %s %r" % (status, body))
            finally:
                RRN.MonitorExit(a)
            status, _, body = rest_b.call("GET", prop)
            ll.expect(status == 200, "bob's REST read once nothing is held: %s %r" % (status, body))
        finally:
            ws_b.close()
            disconnect(a)

    ck.check("json api: REST and WebSocket requests act as their gateway user, without a session of their own",
             json_requests_act_as_their_user)

    def direct_clients_not_bound():
        a = ll.connect(url, "alice")
        direct = None
        try:
            ll.expect(RRN.RequestObjectLock(a, RR.RobotRaconteurObjectLockFlags_USER_LOCK) == "OK", "alice locks")
            direct = RRN.ConnectService(device_url)  # the device itself, not through the gateway
            ll.expect(isinstance(direct.base_name, str), "a direct client of the device reads")
            ll.expect(RRN.ReleaseObjectLock(a) == "OK", "alice releases")
        finally:
            disconnect(a, direct)

    ck.check("direct: the device's own clients are not bound by locks held at the gateway", direct_clients_not_bound)


def anonymous_checks(port, ck):
    url = "rr+tcp://127.0.0.1:%d/?service=interop" % port

    def anonymous():
        a, b = RRN.ConnectService(url), RRN.ConnectService(url)
        try:
            ll.expect_raises(RR.PermissionDeniedException,
                             lambda: RRN.RequestObjectLock(a, RR.RobotRaconteurObjectLockFlags_USER_LOCK),
                             "an anonymous object lock", "User must be authenticated to lock object")
            RRN.MonitorEnter(a, -1)
            try:
                ll.expect_raises(RR.InvalidOperationException, lambda: b.base_name, "b reads a's monitor-locked object",
                                 "monitor locked")
                ll.expect(isinstance(a.base_name, str), "the monitor holder reads")
                d = [d for d in get_json(port, "/api/devices") if d["name"] == "interop"][0]
                ll.expect([(l["path"], l["user"], l["kind"]) for l in d["locks"]] == [("interop", None, "monitor")],
                          "an anonymous monitor in /api/devices: %r" % d["locks"])
            finally:
                RRN.MonitorExit(a)
            ll.expect(isinstance(b.base_name, str), "b reads after a's MonitorExit")
        finally:
            disconnect(a, b)

    ck.check("anonymous: without gateway users object locks need a login, monitors work", anonymous)


def write_config(path, device_url, users=None):
    with open(path, "w") as fh:
        fh.write("gateway:\n  listen: 127.0.0.1\n  port: 0\n  local: false\n")
        if users:
            fh.write("  auth:\n    users: %s\n    roles:\n      operator:\n        - allow: [read, write, call, lock]\n" % users)
            fh.write("    login_limit: {max_failures: 100, window_s: 60, lockout_s: 1}\n")
        fh.write("demo:\n  enabled: false\ndevices:\n  - name: interop\n    url: %s\n" % json.dumps(device_url))


def wait_connected(port, gw_err, http=None):
    deadline = time.monotonic() + 30
    while True:
        try:
            d = device_status(http, "interop") if http else next(d for d in get_json(port, "/api/devices") if d["name"] == "interop")
            if d["state"] == "connected":
                return
        except (OSError, AssertionError):
            pass
        if time.monotonic() > deadline:
            raise StepFailed("gateway device not connected: %s" % tail(gw_err))
        time.sleep(0.1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--service", required=True)
    ap.add_argument("--timeout", type=float, default=240)
    args = ap.parse_args()

    tmp = tempfile.mkdtemp(prefix="rr-shared-locks-")
    atexit.register(shutil.rmtree, tmp, True)  # logs are printed before exit; os._exit on timeout keeps them
    users = os.path.join(tmp, "users.txt")
    write_password_file(users, [(user, pw, roles) for user, (pw, roles) in GATEWAY_USERS.items()])
    svc_err, gw_err, gw2_err = (os.path.join(tmp, n) for n in ("service.err", "gateway.err", "gateway2.err"))
    svc = gw = gw2 = None
    ck = ll.Checks()
    timer = threading.Timer(args.timeout, lambda: os._exit(3))
    timer.daemon = True
    timer.start()
    try:
        svc = start([args.service, "--port", "0", "--max-lifetime", str(int(args.timeout) + 30)], svc_err)
        dev = read_json_line(svc, 30, "rr_interop_service")["url"]
        config = os.path.join(tmp, "gateway.yaml")
        write_config(config, dev, users)
        gw = start([args.gateway, "--config", config, "--no-local", "--log-level", "warning"], gw_err)
        port = read_json_line(gw, 30, "rr-gateway")["port"]
        wait_connected(port, gw_err, login("http://127.0.0.1:%d" % port, "carol"))
        ll.register_transport()
        ll.run_checks("rr+tcp://127.0.0.1:%d/?service=interop" % port, ck)
        run_extra_checks(port, dev, ck)

        config2 = os.path.join(tmp, "gateway2.yaml")
        write_config(config2, dev)
        gw2 = start([args.gateway, "--config", config2, "--no-local", "--log-level", "warning"], gw2_err)
        port2 = read_json_line(gw2, 30, "rr-gateway (no users)")["port"]
        wait_connected(port2, gw2_err)
        anonymous_checks(port2, ck)
    except StepFailed as e:
        print(json.dumps({"error": str(e), "service_stderr": tail(svc_err), "gateway_stderr": tail(gw_err)}))
        return 2
    finally:
        gw2_status = stop(gw2)
        gw_status = stop(gw)
        svc_status = stop(svc)
    failed = [r for r in ck.results if not r["ok"]]
    print(json.dumps({"checks": len(ck.results), "failed": failed, "gateway_status": gw_status,
                      "gateway2_status": gw2_status, "service_status": svc_status}, indent=1))
    if failed:
        print("--- gateway\n" + tail(gw_err) + "\n--- service\n" + tail(svc_err), file=sys.stderr)
    ok_status = (0, None)
    return 1 if failed or gw_status not in ok_status or gw2_status not in ok_status or svc_status not in ok_status else 0


if __name__ == "__main__":
    sys.exit(main())
