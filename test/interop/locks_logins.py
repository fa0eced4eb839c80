"""Logins and object / monitor locks: official Python clients against OUR service (rr_interop_service
with --users, i.e. ObjectService + PasswordTable, server/service/object_locks.hpp).

The password file is in the official format (`user md5hex privileges`). Checks:
  logins   no credentials, a wrong password and an unknown user are refused (AuthenticationException);
           the right password connects and reads.
  locks    a user without the objectlock privilege cannot lock; a user lock by alice refuses bob on the
           object and on a child object (ObjectLockedException) but not alice's other session; bob
           cannot release it; alice releases it; a client lock refuses alice's other session too;
           DisconnectService releases a client lock; a client PROCESS killed with SIGKILL releases its
           user lock; objectlockoverride releases another user's lock.
  monitor  MonitorEnter by one session refuses the other's requests; the other's MonitorEnter waits
           and returns once the first calls MonitorExit.
Prints one JSON summary; exit 0 when every check passed, 1 on a failed check, 2 on setup errors,
77 when the official package is missing.

Usage: locks_logins.py --service PATH/rr_interop_service [--timeout S]
       locks_logins.py --child-lock URL USER PASSWORD   (internal: the process that gets killed)
"""

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
import traceback

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from child_procs import StepFailed, die_with_parent, read_json_line, start, stop, tail, write_password_file  # noqa: E402

try:
    import RobotRaconteur as RR
except ImportError as e:  # pragma: no cover
    print("SKIP: official RobotRaconteur package missing: %s" % e)
    sys.exit(77)

RRN = RR.RobotRaconteurNode.s

USERS = {
    "alice": ("alice-pw", "objectlock"),
    "bob": ("bob-pw", "objectlock"),
    "carol": ("carol-pw", "_"),
    "admin": ("admin-pw", "objectlockoverride"),
}


def creds(password):
    return {"password": RR.VarValue(password, "string")}


def connect(url, user, password=None):
    if password is None:
        password = USERS[user][0]
    return RRN.ConnectService(url, user, creds(password))


def register_transport():
    RRN.RegisterTransport(RR.TcpTransport())


def child_lock(url, user, password):
    """Connects, takes a user lock on the root, says so, then waits to be killed."""
    register_transport()
    c = connect(url, user, password)
    RRN.RequestObjectLock(c, RR.RobotRaconteurObjectLockFlags_USER_LOCK)
    print("locked", flush=True)
    time.sleep(120)


class Checks:
    def __init__(self):
        self.results = []

    def check(self, name, fn):
        t0 = time.monotonic()
        print("[locks_logins] %s ..." % name, file=sys.stderr, flush=True)
        try:
            fn()
            self.results.append({"check": name, "ok": True, "seconds": round(time.monotonic() - t0, 2)})
            print("[locks_logins]   ok", file=sys.stderr, flush=True)
        except Exception as e:  # noqa: BLE001 - every failure is reported
            self.results.append({"check": name, "ok": False, "error": "%s: %s" % (type(e).__name__, e),
                                 "trace": traceback.format_exc(limit=4)})
            print("[locks_logins]   FAILED: %s" % self.results[-1]["error"], file=sys.stderr, flush=True)


def expect(cond, what):
    if not cond:
        raise AssertionError(what)


def expect_raises(exc_type, fn, what, message_part=None):
    try:
        fn()
    except exc_type as e:
        if message_part is not None and message_part not in str(e):
            raise AssertionError("%s: %s raised without %r: %s" % (what, exc_type.__name__, message_part, e))
        return e
    except Exception as e:  # noqa: BLE001
        raise AssertionError("%s: expected %s, got %s: %s" % (what, exc_type.__name__, type(e).__name__, e))
    raise AssertionError("%s: expected %s, nothing raised" % (what, exc_type.__name__))


def eventually(fn, what, timeout=5.0):
    deadline = time.monotonic() + timeout
    last = None
    while time.monotonic() < deadline:
        try:
            return fn()
        except Exception as e:  # noqa: BLE001
            last = e
            time.sleep(0.1)
    raise AssertionError("%s: still failing after %.0f s: %s" % (what, timeout, last))


def run_checks(url, ck):
    # --- logins ---
    def no_credentials():
        # CORE refuses a ConnectClientCombined without a username when the service requires a login.
        expect_raises(RR.AuthenticationException, lambda: RRN.ConnectService(url), "connect without login",
                      "Username not provided")

    ck.check("login: no credentials refused", no_credentials)
    ck.check("login: wrong password refused",
             lambda: expect_raises(RR.AuthenticationException, lambda: connect(url, "alice", "wrong"), "wrong password"))
    ck.check("login: unknown user refused",
             lambda: expect_raises(RR.AuthenticationException, lambda: connect(url, "mallory", "x"), "unknown user"))

    clients = {}

    def logins_ok():
        clients["a1"] = connect(url, "alice")
        clients["a2"] = connect(url, "alice")
        clients["b"] = connect(url, "bob")
        clients["c"] = connect(url, "carol")
        for k in ("a1", "a2", "b", "c"):
            expect(isinstance(clients[k].base_name, str), "read after login (%s)" % k)

    ck.check("login: right password connects and reads", logins_ok)
    if len(clients) != 4:
        return
    a1, a2, b, c = clients["a1"], clients["a2"], clients["b"], clients["c"]

    # --- object locks ---
    ck.check("lock: user without objectlock privilege refused",
             lambda: expect_raises(RR.ObjectLockedException,
                                   lambda: RRN.RequestObjectLock(c, RR.RobotRaconteurObjectLockFlags_USER_LOCK),
                                   "carol locks", "privileges"))

    def user_lock():
        expect(RRN.RequestObjectLock(a1, RR.RobotRaconteurObjectLockFlags_USER_LOCK) == "OK", "alice locks")
        expect_raises(RR.ObjectLockedException, lambda: b.base_name, "bob reads the locked root", "alice")
        expect_raises(RR.ObjectLockedException, lambda: b.get_child().name, "bob reads a child of the locked root")
        expect(isinstance(a2.base_name, str), "alice's other session reads")
        expect(isinstance(a2.get_child().name, str), "alice's other session reads the child")
        expect_raises(RR.ObjectLockedException,
                      lambda: RRN.RequestObjectLock(b, RR.RobotRaconteurObjectLockFlags_USER_LOCK), "bob locks too")
        expect_raises(RR.ObjectLockedException, lambda: RRN.ReleaseObjectLock(b), "bob releases alice's lock")
        expect(RRN.ReleaseObjectLock(a1) == "OK", "alice releases")
        expect(isinstance(b.base_name, str), "bob reads after the release")

    ck.check("lock: user lock blocks other users on object and children, release", user_lock)

    def client_lock():
        expect(RRN.RequestObjectLock(a1, RR.RobotRaconteurObjectLockFlags_CLIENT_LOCK) == "OK", "alice client-locks")
        expect(isinstance(a1.base_name, str), "the locking session reads")
        expect_raises(RR.ObjectLockedException, lambda: a2.base_name, "alice's other session reads")
        expect_raises(RR.ObjectLockedException, lambda: b.base_name, "bob reads")
        RRN.DisconnectService(a1)
        eventually(lambda: b.base_name, "bob reads after alice's locking session disconnected")

    ck.check("lock: client lock blocks the user's other sessions; disconnect releases", client_lock)

    def killed_process_releases():
        proc = subprocess.Popen([sys.executable, os.path.abspath(__file__), "--child-lock", url, "bob", USERS["bob"][0]],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL,
                                preexec_fn=die_with_parent)
        try:
            line = proc.stdout.readline().decode().strip()
            expect(line == "locked", "child process locked (%r; %s)" % (line, proc.stderr.read1(2000) if line == "" else ""))
            expect_raises(RR.ObjectLockedException, lambda: a2.base_name, "alice reads bob's locked root")
            proc.send_signal(signal.SIGKILL)
            proc.wait(10)
            # bob has another session (b) open here: a user lock stays while its user has sessions.
            time.sleep(1.0)
            expect_raises(RR.ObjectLockedException, lambda: a2.base_name, "bob's lock while bob's other session lives")
            RRN.DisconnectService(b)
            eventually(lambda: a2.base_name, "alice reads after bob's last session ended")
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait(5)

    ck.check("lock: a killed client process releases its user lock with its user's last session", killed_process_releases)

    def override():
        b2 = connect(url, "bob")
        clients["b2"] = b2
        expect(RRN.RequestObjectLock(b2, RR.RobotRaconteurObjectLockFlags_USER_LOCK) == "OK", "bob locks")
        adm = connect(url, "admin")
        clients["adm"] = adm
        expect_raises(RR.ObjectLockedException, lambda: adm.base_name, "admin reads bob's locked root")
        expect(RRN.ReleaseObjectLock(adm) == "OK", "admin releases with objectlockoverride")
        expect(isinstance(a2.base_name, str), "alice reads after the override")

    ck.check("lock: objectlockoverride releases another user's lock", override)

    # --- monitor locks ---
    def monitor():
        b2 = clients["b2"]
        RRN.MonitorEnter(a2, -1)
        expect_raises(RR.InvalidOperationException, lambda: b2.base_name, "bob reads a monitor-locked object",
                      "monitor locked")
        expect(isinstance(a2.base_name, str), "the monitor holder reads")
        done = {}
        go_exit = threading.Event()

        def enter_then_exit():
            # The official client wants MonitorEnter and MonitorExit on the same thread (its stub mutex).
            try:
                RRN.MonitorEnter(b2, -1)
                done["t"] = time.monotonic()
                done["read"] = b2.base_name
                go_exit.wait(10)
                RRN.MonitorExit(b2)
                done["exited"] = True
            except Exception as e:  # noqa: BLE001
                done["error"] = e

        t = threading.Thread(target=enter_then_exit, daemon=True)
        t.start()
        time.sleep(0.7)
        expect(not done, "bob's MonitorEnter returned while alice holds the monitor: %r" % done)
        released = time.monotonic()
        RRN.MonitorExit(a2)
        deadline = time.monotonic() + 6
        # "read" is set after "t" on bob's thread: wait for it, not for "t" alone.
        while "read" not in done and "error" not in done and time.monotonic() < deadline:
            time.sleep(0.02)
        expect("t" in done, "bob's MonitorEnter did not return after alice's MonitorExit: %r" % done)
        expect(done["t"] - released < 3.0, "hand-over took %.1f s" % (done["t"] - released))
        expect(isinstance(done.get("read"), str), "bob reads under his monitor: %r" % done)
        expect_raises(RR.InvalidOperationException, lambda: a2.base_name, "alice reads bob's monitor-locked object")
        go_exit.set()
        t.join(10)
        expect(done.get("exited"), "bob's MonitorExit: %r" % done)
        expect(isinstance(a2.base_name, str), "alice reads after bob's MonitorExit")

    ck.check("monitor: MonitorEnter blocks other sessions; the waiter gets it on MonitorExit", monitor)

    for k in ("a2", "c", "b2", "adm"):
        try:
            RRN.DisconnectService(clients[k])
        except Exception:  # noqa: BLE001
            pass


def main():
    if len(sys.argv) >= 2 and sys.argv[1] == "--child-lock":
        child_lock(*sys.argv[2:5])
        return 0
    ap = argparse.ArgumentParser()
    ap.add_argument("--service", required=True)
    ap.add_argument("--timeout", type=float, default=150)
    args = ap.parse_args()

    tmp = tempfile.mkdtemp(prefix="rr-locks-")
    users = os.path.join(tmp, "users.txt")
    write_password_file(users, [(user, pw, priv) for user, (pw, priv) in USERS.items()])
    err = os.path.join(tmp, "service.err")
    svc = None
    ck = Checks()
    timer = threading.Timer(args.timeout, lambda: os._exit(3))
    timer.daemon = True
    timer.start()
    try:
        svc = start([args.service, "--port", "0", "--max-lifetime", str(int(args.timeout) + 30), "--users", users], err)
        ready = read_json_line(svc, 30, "rr_interop_service")
        register_transport()
        run_checks(ready["url"], ck)
    except StepFailed as e:
        print(json.dumps({"error": str(e), "service_stderr": tail(err)}))
        return 2
    finally:
        status = stop(svc)
    failed = [r for r in ck.results if not r["ok"]]
    print(json.dumps({"checks": len(ck.results), "failed": failed, "service_status": status}, indent=1))
    if failed:
        print(tail(err), file=sys.stderr)
    return 1 if failed or status not in (0, None) else 0


if __name__ == "__main__":
    sys.exit(main())
