#!/usr/bin/env python3
"""The official Python client (the venv's RobotRaconteur) against rr-test-service: every member of each
test service, with the values computed here (testsvc_values.py: the LFSR and the TestService3 recipes),
not taken from the service. Checks of our own, written from the definitions; docs/native-service.md.

    .venv/bin/python test/testsvc/testsvc_checks.py --service build/debug/test/testsvc/rr-test-service \\
        [--robdef-dir DIR] [--only testroot,auth,testroot3,async,transports] [--gateway RR_GATEWAY] [--verbose]

Starts rr-test-service (port 0, rr+local with a NodeName of its own), waits for its `ready` line, runs the
checks, stops it with SIGTERM and expects a clean exit. With --gateway the checks go through rr-gateway
in front of it (gateway_front.py: the four services as `auth: passthrough` devices of the same names;
the transports check then uses the gateway's rr+ws), and the gateway must stop cleanly too. Exit 0: all passed; 1: a check failed (each
failure and the service's log tail are printed); 77: skipped (no definitions, no venv packages).
Deadlines are bounds on a hang (tens of seconds), never expected durations.
"""

import argparse
import glob
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
import traceback
import uuid

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

BOUND = 30.0  # seconds: how long any awaited event may take before the check fails (a hang)


def skip(why):
    print("SKIP: " + why)
    sys.exit(77)


try:
    import numpy as np
    import RobotRaconteur as RR
    from RobotRaconteur.Client import RRN
except ImportError as e:  # not the project's venv
    skip("the official Python package and numpy are needed (%s)" % e)

import gateway_front  # noqa: E402
import testsvc_values as tv  # noqa: E402
from testsvc_values import Lfsr, SEED, lfsr_json, to_json, from_json  # noqa: E402

SERVICE_PATH_RELEASED = 5  # ClientServiceListenerEventType_ServicePathReleased
TS1, TS2, TS3, TS5 = ("com.robotraconteur.testing.TestService%d" % i for i in (1, 2, 3, 5))


class Failed(Exception):
    pass


def check(cond, what):
    if not cond:
        raise Failed(what)


def equal(got, expected, what):
    if got != expected:
        g, e = json.dumps(got, default=str)[:300], json.dumps(expected, default=str)[:300]
        raise Failed("%s: got %s, expected %s" % (what, g, e))


def raises(exc, fn, what):
    """fn() must raise `exc` (a class, or a tuple of them)."""
    try:
        fn()
    except exc as e:
        return e
    except Exception as e:
        raise Failed("%s: raised %s (%s), expected %s" % (what, type(e).__name__, e, exc))
    raise Failed("%s: no error, expected %s" % (what, exc))


def wait(event, what):
    if not event.wait(BOUND):
        raise Failed("%s: nothing within %.0f s" % (what, BOUND))


# --------------------------------------------------------------------------------------------------
# Properties drawn from the LFSR: get, set of the expected value, set of another value refused


def check_table_properties(types, c, object_type, specials, log):
    n = 0
    for kind, name, t, _, mods in types.members(object_type):
        if kind != "property" or name in specials:
            continue
        readonly, writeonly = "readonly" in mods, "writeonly" in mods
        expected = lfsr_json(types, t, Lfsr(SEED, name + "_get"))
        if writeonly:
            raises(RR.WriteOnlyMemberException, lambda: getattr(c, name), name + " get (writeonly)")
        else:
            equal(to_json(types, getattr(c, name), t), expected, name + " get")
        to_set = lfsr_json(types, t, Lfsr(SEED, name + "_set"))
        if readonly:
            raises(RR.ReadOnlyMemberException, lambda: setattr(c, name, from_json(types, to_set, t, c)), name + " set (readonly)")
        else:
            setattr(c, name, from_json(types, to_set, t, c))
            if expected != to_set:
                raises(RR.InvalidArgumentException, lambda: setattr(c, name, from_json(types, expected, t, c)),
                       name + " set of another value")
        n += 1
    log("%s: %d table properties" % (object_type, n))
    check(n > 0, "no table properties")


# --------------------------------------------------------------------------------------------------
# RobotRaconteurTestService: TestService1.testroot


def check_testroot(types, urls, log):
    url = urls["url"] + "?service=RobotRaconteurTestService"
    # The official client starts its next receive before it handles a message, so a
    # ServicePathReleasedReq and the function reply sent after it can be handled on two threads in
    # either order: o6_op() may return while get_o6() still finds the released proxy. Its listener
    # reports the release once the proxy is gone; the o6 checks wait for that event.
    released = []
    released_cv = threading.Condition()

    def on_client_event(_client, event, param):
        if event == SERVICE_PATH_RELEASED:
            with released_cv:
                released.append(str(param))
                released_cv.notify_all()

    def o6_op(op, replaces_proxy=True):
        with released_cv:
            before = len(released)
        c.o6_op(op)
        if not replaces_proxy:
            return
        with released_cv:
            if not released_cv.wait_for(lambda: any(p.endswith(".o6") for p in released[before:]), BOUND):
                raise Failed("o6_op(%d): no ServicePathReleased for o6 within %.0f s" % (op, BOUND))

    c = RRN.ConnectService(url, None, None, on_client_event)
    try:
        attrs = RRN.GetServiceAttributes(c)
        equal(attrs["test"].data, "This is a test attribute", "attribute test")
        equal(int(attrs["test2"].data[0]), 42, "attribute test2")

        check_table_properties(types, c, TS1 + ".testroot", {"i32_huge", "errtest", "nulltest"}, log)
        huge = c.i32_huge
        check(len(huge) == 2621440 and huge[0] == 0 and huge[-1] == 2621439 and huge[123456] == 123456, "i32_huge get")
        c.i32_huge = -np.arange(2621440, dtype=np.int32)
        raises(RR.InvalidArgumentException, lambda: setattr(c, "i32_huge", np.arange(3, dtype=np.int32)), "i32_huge wrong set")
        raises(RR.OperationFailedException, lambda: c.errtest, "errtest get")
        raises(RR.OperationFailedException, lambda: setattr(c, "errtest", 1.0), "errtest set")
        check(c.nulltest is None, "nulltest get")
        c.nulltest = None
        raises(RR.InvalidArgumentException,
               lambda: setattr(c, "nulltest", from_json(types, lfsr_json(types, types.parse("teststruct1", TS1), Lfsr(SEED, "x")),
                                                        types.parse("teststruct1", TS1), c)), "nulltest non-null set")
        log("testroot: properties")

        # functions and events
        ev1, ev2 = threading.Event(), threading.Event()
        got2 = []
        c.ev1 += lambda: ev1.set()

        def on_ev2(d, s):
            got2.append((d, list(s.mydat)))
            ev2.set()
        c.ev2 += on_ev2
        c.func1()
        c.func2(27.3, 98.23)
        wait(ev1, "ev1 after func1")
        wait(ev2, "ev2 after func2")
        equal(got2[0], (27.3, [98.23]), "ev2 arguments")
        equal(c.func3(2, 3.45), 5.45, "func3")
        equal(c.meaning_of_life(), 42, "meaning_of_life")
        e = raises(RR.OperationFailedException, c.func_errtest, "func_errtest")
        equal(e.message, "This is a test", "func_errtest message")
        raises(RR.DataTypeException, c.func_errtest1, "func_errtest1")
        e1 = RRN.GetExceptionType(TS1 + ".testexception1", c)
        e3 = RRN.GetExceptionType(TS2 + ".testexception3", c)
        equal(raises(e1, c.func_errtest2, "func_errtest2").message, "This is a test 2", "func_errtest2")
        equal(raises(e3, c.func_errtest3, "func_errtest3").message, "This is a test 3", "func_errtest3")
        log("testroot: functions, events, errors")

        # objrefs
        o1 = c.get_o1()
        o1.d1 = [1.5, -2.5]
        equal(list(o1.d1), [1.5, -2.5], "o1.d1")
        equal((o1.s_ind, o1.i_ind), ("", 0), "o1 indexes")
        equal(c.get_o2(10).i_ind, 10, "o2[10].i_ind")
        equal(c.get_o3(1).i_ind, 1, "o3[1].i_ind")
        special = "ind!@#$%^&*().<>     "
        equal(c.get_o4(special).s_ind, special, "o4[special].s_ind")
        o2_2 = c.get_o2(10).get_o2_2(32)
        equal(o2_2.i_ind, 32, "o2[10].o2_2[32].i_ind")
        o2_2.data = "Hello world!"
        equal(c.get_o2(10).get_o2_2(32).data, "Hello world!", "the same object on a second request")
        o3 = o2_2.get_o3_1("ind1")
        equal(o3.ind, "ind1", "o3_1[ind1].ind")
        equal(o3.add(1.5), 43.5, "sub3.add")
        equal(o1.get_o2_3("x").s_ind, "x", "o2_3[x].s_ind")
        equal(c.get_o5().add_val(2), 3, "o5.add_val")
        o6_op(0, replaces_proxy=False)  # no o6 proxy yet: maybe nothing to release
        o6 = c.get_o6()
        o6.d1 = [0.0]
        o6.get_o2_1().data = "Hello world!"
        o6_op(1)
        raises(Exception, lambda: setattr(o6, "d1", [0.0]), "released o6 (sub1)")
        o6b = c.get_o6()
        o6b.data = "now a sub2"
        o6_op(2)
        raises(Exception, lambda: setattr(o6b, "data", "x"), "released o6 (sub2)")
        equal(c.get_o6().add_val(2), 3, "o6 as subobj")
        raises(RR.InvalidArgumentException, lambda: c.o6_op(7), "o6_op(7)")
        log("testroot: objrefs")

        # pipes
        received = {k: [] for k in ("e1", "e2", "e3", "bp")}
        events = {k: threading.Event() for k in received}

        def collect(key, n):
            def cb(ep):
                while ep.Available > 0:
                    received[key].append(ep.ReceivePacket())
                if len(received[key]) >= n:
                    events[key].set()
            return cb
        e1 = c.p1.Connect(-1)
        e2 = c.p1.Connect(3432)
        e3 = c.p2.Connect(-1)
        e1.RequestPacketAck = True
        e1.PacketReceivedEvent += collect("e1", 3)
        e2.PacketReceivedEvent += collect("e2", 2)
        e3.PacketReceivedEvent += collect("e3", 1)
        acks, ack_seen = set(), threading.Condition()

        def on_ack(ep, n):
            with ack_seen:
                acks.add(n)
                ack_seen.notify_all()
        e1.PacketAckReceivedEvent += on_ack  # before the send: its ack may come before SendPacket returns
        sent = e1.SendPacket([1, 2, 3, 4])
        e1.SendPacket([5, 6, 7, 8])
        e1.SendPacket([-1, -2, -3, -5.32])
        e2.SendPacket([3.21])
        e2.SendPacket([4.72])
        s = RRN.NewStructure(TS1 + ".teststruct2", c)
        s.mydat = [738.29]
        e3.SendPacket(s)
        for k in ("e1", "e2", "e3"):
            wait(events[k], "pipe echo " + k)
        equal([list(x) for x in received["e1"]], [[1, 2, 3, 4], [5, 6, 7, 8], [-1, -2, -3, -5.32]], "p1 echo")
        equal([list(x) for x in received["e2"]], [[3.21], [4.72]], "p1 echo (second endpoint)")
        equal(list(received["e3"][0].mydat), [738.29], "p2 echo")
        with ack_seen:
            check(ack_seen.wait_for(lambda: sent in acks, BOUND), "ack of the first packet sent on p1: nothing within %.0f s" % BOUND)
        # the service's ack request: the client acks the first echo, pipe_check_error sees it
        deadline = time.time() + BOUND
        while True:
            try:
                c.pipe_check_error()
                break
            except RR.InvalidOperationException:
                if time.time() > deadline:
                    raise Failed("pipe_check_error: the first echo's ack never reached the service")
                time.sleep(0.05)
        bp = c.broadcastpipe.Connect(-1)
        bp.PacketReceivedEvent += collect("bp", 3)
        wait(events["bp"], "broadcastpipe packets")
        check(all(0 <= x <= 99 for x in received["bp"]), "broadcastpipe values")
        for ep in (e1, e2, e3, bp):
            ep.Close()
        log("testroot: pipes")

        # callbacks
        calls = []
        c.cb1.Function = lambda: calls.append("cb1")
        c.cb2.Function = lambda d1, d2: calls.append(("cb2", d1, d2))
        c.cb3.Function = lambda d1, d2: d1 + d2 + 3.14
        c.cb_meaning_of_life.Function = lambda: 42

        def cb_err():
            raise Exception("This is a test")
        c.cb_errtest.Function = cb_err
        c.test_callbacks()
        equal(calls, ["cb1", ("cb2", 739.2, 0.392)], "callbacks called")
        c.cb3.Function = lambda d1, d2: d1 + d2
        raises(RR.InvalidArgumentException, c.test_callbacks, "test_callbacks with a wrong cb3")
        log("testroot: callbacks")

        # wires
        for name, value in (("w1", [1.5, -2.0]), ("w3", np.array([[1, 2], [3, 4]], dtype=np.int32))):
            w = getattr(c, name).Connect()
            changed = threading.Event()
            w.WireValueChanged += lambda conn, v, t: changed.set()
            w.OutValue = value
            wait(changed, name + " echo")
            equal(np.asarray(w.InValue).tolist(), np.asarray(value).tolist(), name + " echo")
            w.Close()
        w2 = c.w2.Connect()
        changed = threading.Event()
        w2.WireValueChanged += lambda conn, v, t: changed.set()
        s = RRN.NewStructure(TS1 + ".teststruct2", c)
        s.mydat = [0.25]
        w2.OutValue = s
        wait(changed, "w2 echo")
        equal(list(w2.InValue.mydat), [0.25], "w2 echo")
        w2.Close()
        bw = c.broadcastwire.Connect()
        deadline = time.time() + BOUND
        while not bw.InValueValid:
            check(time.time() < deadline, "broadcastwire: no value")
            time.sleep(0.05)
        check(0 <= bw.InValue <= 99, "broadcastwire value")
        bw.Close()
        log("testroot: wires")

        # memories
        m1 = c.m1
        equal(m1.Length, 100, "m1 length")
        buf = np.zeros(100)
        m1.Read(0, buf, 0, 100)
        equal(to_json(types, buf, types.parse("double[]", TS1)),
              lfsr_json(types, types.parse("double[100]", TS1), Lfsr(SEED, "m1_init")), "m1 contents")
        m1.Write(20, np.array([1.0, 2.0, 3.0]), 1, 2)
        part = np.zeros(4)
        m1.Read(19, part, 0, 4)
        equal(part[1:3].tolist(), [2.0, 3.0], "m1 write then read")
        equal(list(c.m2.Dimensions), [10, 10, 10, 10, 10], "m2 dims")
        g = Lfsr(1234, "multidimarray_test_double")
        block = np.array([g.next_double() for _ in range(2 * 3 * 1 * 2 * 1)]).reshape([2, 3, 1, 2, 1], order="F")
        c.m2.Write([1, 2, 3, 4, 5], block, [0, 0, 0, 0, 0], [2, 3, 1, 2, 1])
        back = np.zeros([2, 3, 1, 2, 1])
        c.m2.Read([1, 2, 3, 4, 5], back, [0, 0, 0, 0, 0], [2, 3, 1, 2, 1])
        equal(to_json(types, back, types.parse("double[*]", TS1)), to_json(types, block, types.parse("double[*]", TS1)), "m2 block")
        bytes_ = np.arange(200 * 300, dtype=np.uint32).astype(np.uint8).reshape([200, 300], order="F")
        c.m3.Write([500, 600], bytes_, [0, 0], [200, 300])
        back = np.zeros([200, 300], dtype=np.uint8)
        c.m3.Read([500, 600], back, [0, 0], [200, 300])
        check((back == bytes_).all(), "m3 block")
        raises(Exception, lambda: c.m1.Read(95, np.zeros(10), 0, 10), "m1 read past the end")
        log("testroot: memories")

        # monitor lock: another client's request to the object waits out the monitor
        c2 = RRN.ConnectService(url)
        try:
            o1b = c2.get_o1()
            RRN.MonitorEnter(o1)
            raises(RR.InvalidOperationException, lambda: setattr(o1b, "d1", [2.0]), "request to a monitor-locked object")
            RRN.MonitorExit(o1)
            o1b.d1 = [2.0]
        finally:
            RRN.DisconnectService(c2)
        log("testroot: monitor lock")
    finally:
        RRN.DisconnectService(c)


# --------------------------------------------------------------------------------------------------
# RobotRaconteurTestService_auth: logins and object locks


def check_auth(types, urls, log):
    url = urls["url"] + "?service=RobotRaconteurTestService_auth"

    def cred(p):
        return {"password": RR.VarValue(p, "string")}
    def anonymous():
        r = RRN.ConnectService(url)
        try:
            r.func3(1, 2)
        finally:
            RRN.DisconnectService(r)
    raises(Exception, anonymous, "no login")
    raises(RR.AuthenticationException, lambda: RRN.ConnectService(url, "testuser2", cred("testpass1")), "wrong password")
    r1 = RRN.ConnectService(url, "testuser1", cred("testpass1"))
    r1b = RRN.ConnectService(url, "testuser1", cred("testpass1"))
    r2 = RRN.ConnectService(url, "testuser2", cred("testpass2"))
    try:
        equal(r1.func3(2.2, 3.3), 2.2 + 3.3, "logged-in call")
        o1, o1b, o2 = r1.get_o1(), r1b.get_o1(), r2.get_o1()
        sub2 = r2.get_o1().get_o2_1()
        RRN.RequestObjectLock(o1, RR.RobotRaconteurObjectLockFlags_USER_LOCK)
        o1.d1 = [1.0]
        o1b.d1 = [1.0]  # the same user, another session
        raises(RR.ObjectLockedException, lambda: setattr(o2, "d1", [1.0]), "other user, locked object")
        raises(RR.ObjectLockedException, lambda: setattr(sub2, "data", "x"), "other user, object below")
        r2.func3(1, 2)  # the root is not locked
        RRN.ReleaseObjectLock(o1)
        o2.d1 = [1.0]
        RRN.RequestObjectLock(o1, RR.RobotRaconteurObjectLockFlags_CLIENT_LOCK)
        raises(RR.ObjectLockedException, lambda: setattr(o1b, "d1", [1.0]), "same user, other session, client lock")
        su = RRN.ConnectService(url, "testsuperuser", cred("superpass1"))
        try:
            RRN.ReleaseObjectLock(su.get_o1())
        finally:
            RRN.DisconnectService(su)
        o1b.d1 = [1.0]
        o2.d1 = [1.0]
        RRN.RequestObjectLock(o1, RR.RobotRaconteurObjectLockFlags_USER_LOCK)
        RRN.DisconnectService(r1b)
        raises(RR.ObjectLockedException, lambda: setattr(o2, "d1", [1.0]), "lock kept while the user has a session")
        RRN.DisconnectService(r1)
        r1 = None
        deadline = time.time() + BOUND
        while True:  # the lock goes with the user's last session, as soon as the service sees it close
            try:
                o2.d1 = [1.0]
                break
            except RR.ObjectLockedException:
                check(time.time() < deadline, "lock not released with the user's last session")
                time.sleep(0.05)
        log("auth: logins, user and client locks, override, release with the last session")
    finally:
        for r in (r1, r2):
            if r is not None:
                try:
                    RRN.DisconnectService(r)
                except Exception:
                    pass


# --------------------------------------------------------------------------------------------------
# RobotRaconteurTestService2: TestService3.testroot3


def check_testroot3(types, urls, log):
    url = urls["url"] + "?service=RobotRaconteurTestService2"
    c = RRN.ConnectService(url)
    ts3 = tv.Ts3(types, tv.SequenceTables.lfsr(SEED))
    P = lambda text: types.parse(text, TS3)  # noqa: E731
    try:
        recipes = {"testenum1_prop", "testpod1_prop", "teststruct3_prop", "testnamedarray1", "testnamedarray2",
                   "testnamedarray3", "testnamedarray4", "testnamedarray5"}
        check_table_properties(types, c, TS3 + ".testroot3", recipes, log)

        consts = RRN.GetConstants(TS3, c)
        equal(c.testenum1_prop, consts["testenum1"]["anothervalue"], "testenum1_prop get")
        c.testenum1_prop = consts["testenum1"]["hexval1"]
        raises(RR.InvalidArgumentException, lambda: setattr(c, "testenum1_prop", 0), "testenum1_prop other set")

        def recipe(name, t, get, to_set, wrong):
            equal(to_json(types, getattr(c, name), t), get, name + " get")
            setattr(c, name, from_json(types, to_set, t, c))
            raises(RR.InvalidArgumentException, lambda: setattr(c, name, from_json(types, wrong, t, c)), name + " other set")
        recipe("testpod1_prop", P("testpod1"), ts3.testpod1(563921043), ts3.testpod1(85932659), ts3.testpod1(1))
        recipe("teststruct3_prop", P("teststruct3"), ts3.teststruct3(16483675), ts3.teststruct3(858362), ts3.teststruct3(1))
        recipe("testnamedarray1", P("vector3"), ts3.vector3_of_transform(74637), ts3.vector3_of_transform(3956378),
               ts3.vector3_of_transform(1))
        recipe("testnamedarray2", P("transform"), ts3.transform(1294), ts3.transform(827635), ts3.transform(1))
        recipe("testnamedarray3", P("transform[10-]"), ts3.transform_array(8, 837512), ts3.transform_array(6, 19274),
               ts3.transform_array(6, 1))
        recipe("testnamedarray4", P("transform[*]"), ts3.transform_multidim(7, 2, 66134), ts3.transform_multidim(5, 2, 6385),
               ts3.transform_multidim(5, 2, 1))
        recipe("testnamedarray5", P("transform[3,2]"), ts3.transform_multidim(3, 2, 773142),
               ts3.transform_multidim(3, 2, 7732), ts3.transform_multidim(3, 2, 1))
        equal(to_json(types, c.testpod1_func2(), P("testpod1")), ts3.testpod1(95836295), "testpod1_func2")
        c.testpod1_func1(from_json(types, ts3.testpod1(29546592), P("testpod1"), c))
        raises(RR.InvalidArgumentException, lambda: c.testpod1_func1(from_json(types, ts3.testpod1(2), P("testpod1"), c)),
               "testpod1_func1 other value")
        log("testroot3: properties, recipes")

        # generators
        equal(list(c.gen_func1().NextAll()), list(range(16)), "gen_func1")
        equal([list(x) for x in c.gen_func2("gen_func2_a_param").NextAll()], [[i] for i in range(16)], "gen_func2")
        raises(RR.InvalidArgumentException, lambda: c.gen_func2("other"), "gen_func2 other name")
        g = c.gen_func3("name")
        for i in range(3):
            g.Next(np.array([i], dtype=np.uint8))
        g.Close()
        g = c.gen_func4()
        for j in range(3):
            equal(list(g.Next(np.array([2, 3, 4], dtype=np.uint8))), [2 + j, 3 + j, 4 + j], "gen_func4 call %d" % j)
        g.Abort()
        raises(RR.OperationAbortedException, lambda: g.Next(np.array([1], dtype=np.uint8)), "gen_func4 after abort")
        g = c.gen_func4()
        g.Next(np.array([1], dtype=np.uint8))
        g.Close()
        raises(RR.StopIterationException, lambda: g.Next(np.array([1], dtype=np.uint8)), "gen_func4 after close")
        g = c.gen_func5()
        s = RRN.NewStructure(TS1 + ".teststruct2", c)
        s.mydat = [1.25, 2.5]
        equal(list(g.Next(s).mydat), [1.25, 2.5], "gen_func5 echo")
        g.Close()
        equal(list(c.enum_generator1().NextAll()), [v for _, v in types.enums[TS3 + ".testenum1"]], "enum_generator1")
        g = c.enum_generator2(1, 2)
        equal(g.Next(consts["testenum1"]["hexval2"]), consts["testenum1"]["hexval2"], "enum_generator2 echo")
        g.Close()
        log("testroot3: generators")

        # objrefs, the service's own lock on nolock_test
        o4 = c.get_o4()
        o4.data = "obj4 data"
        equal(o4.data, "obj4 data", "o4.data")
        equal(o4.get_o3_1("k").add(1), 43, "o4.o3_1[k].add")
        o5 = c.get_nolock_test()
        raises(RR.ObjectLockedException, lambda: o5.p1, "nolock_test.p1 (locked)")
        o5.p2 = 1.0
        equal(o5.p2, 1.0, "p2 [nolock]")
        equal(o5.p3, 0.0, "p3 [nolockread] read")
        raises(RR.ObjectLockedException, lambda: setattr(o5, "p3", 1.0), "p3 write")
        raises(RR.ObjectLockedException, o5.f1, "f1")
        equal(o5.f2(), 11, "f2 [nolock]")
        raises(RR.ObjectLockedException, lambda: o5.q1.Connect(-1), "q1")
        o5.q2.Connect(-1).Close()
        raises(RR.ObjectLockedException, lambda: o5.w1.Connect(), "w1")
        o5.w2.Connect().Close()
        raises(RR.ObjectLockedException, lambda: o5.m1.Length, "m1")
        b = np.zeros(10, dtype=np.int32)
        o5.m2.Write(0, b, 0, 10)
        o5.m3.Read(0, b, 0, 10)
        raises(RR.ObjectLockedException, lambda: o5.m3.Write(0, b, 0, 10), "m3 write")
        log("testroot3: objrefs, nolock_test")

        # errors with a sub-name and a parameter
        e = raises(RR.InvalidOperationException, c.test_exception_params1, "test_exception_params1")
        equal((e.message, e.errorsubname), ("test error", "my_error"), "test_exception_params1")
        equal((int(e.errorparam.data["param1"].data[0]), e.errorparam.data["param2"].data), (10, "20"), "params 1")
        e4 = RRN.GetExceptionType(TS3 + ".test_exception4", c)
        e = raises(e4, c.test_exception_params2, "test_exception_params2")
        equal((e.message, e.errorsubname), ("test error2", "my_error2"), "test_exception_params2")
        equal((int(e.errorparam.data["param1"].data[0]), e.errorparam.data["param2"].data), (30, "40"), "params 2")
        log("testroot3: errors with parameters")

        # pipes and wires
        for name, value in (("p1", [1, 2, 3]), ("p2", [4, 5]), ("p3", np.array([[1, 2], [3, 4]], dtype=np.int32))):
            ep = getattr(c, name).Connect(-1)
            got = threading.Event()
            ep.PacketReceivedEvent += lambda e: got.set()
            ep.SendPacket(np.asarray(value, dtype=np.int32))
            wait(got, name + " echo")
            equal(np.asarray(ep.ReceivePacket()).tolist(), np.asarray(value).tolist(), name + " echo")
            ep.Close()
        u = c.unreliable1.Connect(-1)
        u.Close()
        for name, value in (("w1", np.arange(6, dtype=np.int32)), ("w2", np.arange(3, dtype=np.int32)),
                            ("w3", np.arange(6, dtype=np.int32).reshape([3, 2], order="F"))):
            w = getattr(c, name).Connect()
            changed = threading.Event()
            w.WireValueChanged += lambda conn, v, t: changed.set()
            w.OutValue = value
            wait(changed, name + " echo")
            equal(np.asarray(w.InValue).tolist(), value.tolist(), name + " echo")
            w.Close()
        equal(c.peekwire.PeekInValue()[0], 56295674, "peekwire")
        raises(RR.ReadOnlyMemberException, lambda: c.peekwire.PokeOutValue(1), "peekwire poke")
        c.pokewire.PokeOutValue(75738265)
        equal(c.pokewire.PeekOutValue()[0], 75738265, "pokewire poke then peek")
        w = c.pokewire.Connect()
        w.OutValue = 8638356
        deadline = time.time() + BOUND
        while c.pokewire.PeekOutValue()[0] != 8638356:
            check(time.time() < deadline, "pokewire value sent on the connection")
            time.sleep(0.05)
        w.Close()
        log("testroot3: pipes, wires, peek and poke")

        # memories
        equal(c.readmem.Length, 100, "readmem length")
        buf = np.zeros(100)
        c.readmem.Read(0, buf, 0, 100)
        equal(to_json(types, buf, P("double[]")), lfsr_json(types, P("double[100]"), Lfsr(SEED, "readmem_init")), "readmem")
        raises(RR.ReadOnlyMemberException, lambda: c.readmem.Write(0, buf, 0, 1), "readmem write")
        pods = from_json(types, [ts3.testpod2(59174 + i) for i in range(20)], P("testpod2[]"), c)
        equal(c.pod_m1.Length, 1024, "pod_m1 length")
        c.pod_m1.Write(52, pods, 3, 17)
        back = np.zeros(16, dtype=pods.dtype)
        c.pod_m1.Read(53, back, 2, 14)
        equal(to_json(types, back[2:16], P("testpod2[]")), [ts3.testpod2(59174 + i + 4) for i in range(14)], "pod_m1")
        grid = from_json(types, {"dims": [3, 3], "array": [ts3.testpod2(75721 + i) for i in range(9)]}, P("testpod2[*]"), c)
        c.pod_m2.Write([0, 0], grid, [0, 0], [3, 3])
        back = np.zeros([3, 3], dtype=grid.dtype)
        c.pod_m2.Read([0, 0], back, [0, 0], [3, 3])
        equal(to_json(types, back, P("testpod2[*]")), to_json(types, grid, P("testpod2[*]")), "pod_m2")
        trs = from_json(types, ts3.transform_array(21, 79174), P("transform[]"), c)
        equal(c.namedarray_m1.Length, 512, "namedarray_m1 length")
        c.namedarray_m1.Write(23, trs, 3, 18)
        back = np.zeros(18, dtype=trs.dtype)
        c.namedarray_m1.Read(23, back, 0, 18)
        equal(to_json(types, back, P("transform[]")), to_json(types, trs[3:21], P("transform[]")), "namedarray_m1")
        trs = from_json(types, ts3.transform_multidim(3, 3, 15721), P("transform[*]"), c)
        c.namedarray_m2.Write([1, 2], trs, [0, 0], [3, 3])
        back = np.zeros([3, 3], dtype=trs.dtype)
        c.namedarray_m2.Read([1, 2], back, [0, 0], [3, 3])
        equal(to_json(types, back, P("transform[*]")), to_json(types, trs, P("transform[*]")), "namedarray_m2")
        g = Lfsr(SEED, "complex")
        cx = np.array([g.next_cdouble() for _ in range(8)])
        for name in ("c_m1", "c_m3"):
            getattr(c, name).Write(10, cx, 0, 8)
            back = np.zeros(8, dtype=np.complex128)
            getattr(c, name).Read(10, back, 0, 8)
            equal(to_json(types, back, P("cdouble[]")), to_json(types, cx, P("cdouble[]")), name)
        for name in ("c_m2", "c_m4"):
            block = cx[:6].reshape([3, 2], order="F")
            getattr(c, name).Write([0, 1], block, [0, 0], [3, 2])
            back = np.zeros([3, 2], dtype=np.complex128)
            getattr(c, name).Read([0, 1], back, [0, 0], [3, 2])
            equal(to_json(types, back, P("cdouble[*]")), to_json(types, block, P("cdouble[*]")), name)
        bits = np.array([True, False, False, True, True, False, False, False, True, True])
        c.c_m5.Write(100, bits, 1, 8)
        back = np.zeros(10, dtype=np.bool_)
        c.c_m5.Read(99, back, 0, 10)
        equal(back[1:9].tolist(), bits[1:9].tolist(), "c_m5")
        c.c_m6.Write([0, 0], bits.reshape([2, 5], order="F"), [0, 0], [2, 5])
        back = np.zeros([2, 5], dtype=np.bool_)
        c.c_m6.Read([0, 0], back, [0, 0], [2, 5])
        equal(back.tolist(), bits.reshape([2, 5], order="F").tolist(), "c_m6")
        log("testroot3: memories")
    finally:
        RRN.DisconnectService(c)


# --------------------------------------------------------------------------------------------------
# RobotRaconteurTestService3: TestService5.asynctestroot


def check_async(types, urls, log):
    c = RRN.ConnectService(urls["url"] + "?service=RobotRaconteurTestService3")
    try:
        check_table_properties(types, c, TS5 + ".asynctestroot", {"d1", "err"}, log)
        equal(c.d1, 8.5515, "d1 get")
        c.d1 = 3.0819
        raises(RR.InvalidArgumentException, lambda: setattr(c, "d1", 1.0), "d1 other set")
        equal(raises(RR.InvalidArgumentException, lambda: c.err, "err get").message, "Test message 1", "err get message")
        raises(RR.InvalidOperationException, lambda: setattr(c, "err", 1.0), "err set")
        c.f1()
        c.f2(247)
        raises(RR.InvalidArgumentException, lambda: c.f2(1), "f2(1)")
        equal(c.f3(1, 2), 3, "f3")
        raises(RR.OutOfRangeException, lambda: c.f3(1e10, 1), "f3 past int32")
        raises(RR.InvalidOperationException, c.err_func, "err_func")
        raises(RRN.GetExceptionType(TS5 + ".asynctestexp", c), c.err_func2, "err_func2")
        raises(RR.InvalidOperationException, c.err_func3, "err_func3")
        equal(list(c.f4().NextAll()), [float(i) for i in range(16)], "f4")
        g = c.f5(1.0)
        g.Next(2.0)
        g.Next(3.0)
        g.Close()
        g = c.f6(1.5)
        s = RRN.NewStructure(TS5 + ".teststruct5", c)
        s.a = "four"
        equal(g.Next(s).a, 5.5, "f6")
        g.Close()
        # asynchronous calls from this side too
        done = threading.Event()
        result = []
        c.async_f3(20, 22, lambda r, err: (result.append((r, err)), done.set()))
        wait(done, "async_f3")
        equal(result[0], (42, None), "async_f3")
        log("async: properties, functions, generators")
    finally:
        RRN.DisconnectService(c)


# --------------------------------------------------------------------------------------------------
# The same services over rr+ws and rr+local


def check_transports(types, urls, log):
    for key in ("ws_url", "local_url"):
        base = urls.get(key)
        if base is None:  # through the gateway: no rr+local
            continue
        sep = "&" if "?" in base else "?"
        c = RRN.ConnectService(base + sep + "service=RobotRaconteurTestService")
        try:
            equal(c.func3(1, 2), 3, key + " func3")
            equal(to_json(types, c.d2, types.parse("double[]", TS1)),
                  lfsr_json(types, types.parse("double[]", TS1), Lfsr(SEED, "d2_get")), key + " d2")
        finally:
            RRN.DisconnectService(c)
        c = RRN.ConnectService(base + sep + "service=RobotRaconteurTestService3")
        try:
            equal(c.d1, 8.5515, key + " async d1")
        finally:
            RRN.DisconnectService(c)
        log("transports: " + key)


def start_gateway(program, logdir, device_url, log):
    """rr-gateway in front of the service (gateway_front.py); (process, its URLs) once every device is
    connected, (None, None) when it does not get there within the bound."""
    cfg = os.path.join(logdir, "gateway.yaml")
    with open(cfg, "w") as f:
        f.write(gateway_front.config_text(device_url))
    gw = subprocess.Popen(gateway_front.argv(program, cfg), stdout=subprocess.PIPE, stderr=log, text=True)
    first = []

    def read():
        for line in gw.stdout:
            if not first and gateway_front.is_ready_line(line):
                first.append(line)  # then keep draining, so the gateway never blocks on stdout
    threading.Thread(target=read, daemon=True).start()
    deadline = time.time() + 60  # bound: an ASan start at load 15 takes seconds
    while not first and gw.poll() is None and time.time() < deadline:
        time.sleep(0.05)
    if not first or not gateway_front.wait_until_ready(gateway_front.port_of(first[0]), 60, lambda: gw.poll() is None):
        gw.kill()
        gw.wait()
        return None, None
    port = gateway_front.port_of(first[0])
    return gw, {"url": "rr+tcp://127.0.0.1:%d/" % port, "ws_url": "rr+ws://127.0.0.1:%d/" % port}


CHECKS = {"testroot": check_testroot, "auth": check_auth, "testroot3": check_testroot3, "async": check_async,
          "transports": check_transports}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--service", required=True, help="the rr-test-service program")
    ap.add_argument("--robdef-dir", default=None, help="default: $RR_SHARED_DIR/robdef-testing, else SHARED/robdef-testing")
    ap.add_argument("--shared-default", default=os.path.join(HERE, "..", "..", "..", "shared"), metavar="SHARED",
                    help="the shared test data folder when RR_SHARED_DIR is not set (CMake passes its RR_SHARED_DIR)")
    ap.add_argument("--only", default=",".join(CHECKS))
    ap.add_argument("--gateway", default=None, help="the rr-gateway program: the checks go through it")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args()

    shared = os.environ.get("RR_SHARED_DIR") or args.shared_default
    robdef_dir = args.robdef_dir or os.path.join(shared, "robdef-testing")
    files = sorted(glob.glob(os.path.join(robdef_dir, "com.robotraconteur.testing.TestService*.robdef")))
    if len(files) < 5:
        skip("no test definitions in %s (RR_SHARED_DIR/robdef-testing)" % robdef_dir)
    types = tv.Types([open(f).read() for f in files])
    only = [x for x in args.only.split(",") if x]
    for name in only:
        if name not in CHECKS:
            ap.error("unknown check " + name)

    logdir = tempfile.mkdtemp(prefix="testsvc-")
    errlog = open(os.path.join(logdir, "service.stderr"), "w+")
    nodename = "testsvc_" + uuid.uuid4().hex[:12]
    proc = subprocess.Popen([args.service, "--port", "0", "--robdef-dir", robdef_dir, "--nodename", nodename,
                             "--max-lifetime", "900"], stdout=subprocess.PIPE, stderr=errlog, text=True)
    failures = []
    gateway = None
    gwlog = open(os.path.join(logdir, "gateway.stderr"), "w+")

    def tail(log=errlog):
        log.flush()
        log.seek(0)
        lines = log.read().splitlines()
        return "\n".join(lines[-40:])

    try:
        ready = []
        reader = threading.Thread(target=lambda: ready.append(proc.stdout.readline()), daemon=True)
        reader.start()
        reader.join(60)  # bound: an ASan start at load 15 takes seconds
        if not ready or not ready[0].startswith("ready "):
            print("rr-test-service did not print its ready line (%r); its log:\n%s" % (ready[:1], tail()))
            return 1
        urls = json.loads(ready[0][len("ready "):])
        if args.gateway:
            gateway, urls = start_gateway(args.gateway, logdir, urls["url"], gwlog)
            if gateway is None:
                print("rr-gateway did not get ready; its log:\n%s" % tail(gwlog))
                return 1
        for name in only:
            t0 = time.time()
            try:
                CHECKS[name](types, urls, (lambda m: print("  ok: " + m)) if args.verbose else (lambda m: None))
                print("PASS %s (%.1f s)" % (name, time.time() - t0))
            except Exception as e:
                failures.append(name)
                print("FAIL %s: %s" % (name, e))
                traceback.print_exc()
    finally:
        if gateway is not None:
            gateway.send_signal(signal.SIGTERM)
            try:
                if gateway.wait(60) != 0:
                    failures.append("gateway exit status %d" % gateway.returncode)
            except subprocess.TimeoutExpired:
                gateway.kill()
                gateway.wait()
                failures.append("gateway exit (did not stop within 60 s of SIGTERM)")
        proc.send_signal(signal.SIGTERM)
        try:
            code = proc.wait(60)
        except subprocess.TimeoutExpired:
            proc.kill()
            code = proc.wait()
            failures.append("exit (did not stop within 60 s of SIGTERM)")
        if code != 0 and "exit (" not in " ".join(failures):
            failures.append("exit status %d" % code)
    if failures:
        print("FAILED: %s\nrr-test-service log (tail):\n%s" % (", ".join(failures), tail()))
        if args.gateway:
            print("rr-gateway log (tail):\n%s" % tail(gwlog))
        return 1
    print("all %d checks passed" % len(only))
    return 0


if __name__ == "__main__":
    sys.exit(main())
