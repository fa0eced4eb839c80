#!/usr/bin/env python3
"""Interop test client, implemented with the official Robot Raconteur Python package.

Connects to a service implementing robdef/experimental.interop_test.robdef (official_service.py, or
later our own C++ service) and exercises every member kind and every value type, ASSERTING the
results against interop_values.py. Prints one JSON summary on stdout; exit status 0 only if every
check passed (1 = a check failed, 2 = could not connect / setup error, 3 = overall timeout).

Usage:
    official_client.py URL [--disable-message4] [--disable-stringtable] [--heartbeat S] [--idle S] [--single-connection]
                           [--timeout S] [--only SECTION,...]
URL example: rr+tcp://127.0.0.1:PORT/?service=interop   (rr+ws://... also works with --websocket)
"""

import argparse
import json
import os
import sys
import threading
import time
import traceback

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import interop_values as iv  # noqa: E402

import RobotRaconteur as RR  # noqa: E402
import official_transport  # noqa: E402  (the official client's transport, its connect timeout)

RRN = RR.RobotRaconteurNode.s

WAIT_S = 5.0  # how long to wait for asynchronous traffic (events, packets, wire values)


class CheckFailed(Exception):
    pass


def expect_equal(got, want, what):
    d = iv.deep_equal(got, want, what)
    if d is not None:
        raise CheckFailed(d)


def expect(cond, what):
    if not cond:
        raise CheckFailed(what)


def expect_raises(exc_types, fn, what):
    try:
        fn()
    except exc_types as e:
        return e
    except Exception as e:
        raise CheckFailed("%s: expected %s, got %s: %s" % (what, exc_types, type(e).__name__, e))
    raise CheckFailed("%s: expected %s, nothing raised" % (what, exc_types))


def wait_for(pred, timeout=WAIT_S, what="condition"):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if pred():
            return
        time.sleep(0.01)
    raise CheckFailed("timed out after %.1f s waiting for %s" % (timeout, what))


class Runner:
    def __init__(self, c, url=None):
        self.c = c
        self.url = url
        self.f = iv.Factory(RR, RRN, c)
        self.results = []  # (section, name, ok, error)
        self.section = ""
        self.verbose = False

    def check(self, name, fn):
        if self.verbose:
            print("... %s/%s" % (self.section, name), file=sys.stderr, flush=True)
        try:
            fn()
            self.results.append((self.section, name, True, None))
        except Exception as e:
            if isinstance(e, CheckFailed):
                msg = str(e)
            else:
                msg = "%s: %s" % (type(e).__name__, e)
                traceback.print_exc(file=sys.stderr)
            print("FAIL %s/%s: %s" % (self.section, name, msg), file=sys.stderr, flush=True)
            self.results.append((self.section, name, False, msg))

    # -------------------------------------------------------------------------------------------
    def connection(self):
        c = self.c

        def attributes():
            a = RRN.GetServiceAttributes(c)
            expect_equal(a.get("purpose").data if a.get("purpose") else None, "interop test \u2713", "attr purpose")
            expect_equal(a["version"].data, np.array([1, 0], dtype=np.int32), "attr version")

        self.check("service attributes", attributes)
        self.check("object type", lambda: expect_equal(RRN.GetObjectType(c), iv.qn("Root"), "root type"))
        self.check("reset", lambda: c.reset())

    def properties(self):
        c, f = self.c, self.f
        for name, (a, b) in iv.property_values(f).items():
            def get_a(name=name, a=a):
                expect_equal(getattr(c, name), a, name + " (A)")

            def set_b(name=name, b=b):
                setattr(c, name, b)
                expect_equal(getattr(c, name), b, name + " (B after set)")

            self.check(name + " get", get_a)
            self.check(name + " set/get", set_b)

        self.check("set rejected by service", lambda: expect_raises(
            RR.InvalidArgumentException, lambda: setattr(c, "p_int32", 5), "set p_int32 = 5"))
        self.check("base_name [readonly]", lambda: expect_equal(c.base_name, iv.BASE_NAME, "base_name"))
        self.check("ro_value [readonly] get", lambda: expect_equal(c.ro_value, iv.RO_VALUE, "ro_value"))
        self.check("ro_value [readonly] set fails", lambda: expect_raises(
            (RR.ReadOnlyMemberException, AttributeError, RR.RobotRaconteurException),
            lambda: setattr(c, "ro_value", 1), "set ro_value"))

        def writeonly():
            c.wo_value = 1234
            expect_equal(c.wo_value_last(), 1234, "wo_value_last")

        self.check("wo_value [writeonly] set", writeonly)
        self.check("wo_value [writeonly] get fails", lambda: expect_raises(
            (RR.WriteOnlyMemberException, AttributeError, RR.RobotRaconteurException),
            lambda: c.wo_value, "get wo_value"))

    def functions(self):
        c, f = self.c, self.f
        self.check("add", lambda: expect_equal(c.add(2, -5), -3, "add"))
        self.check("add overflow -> OutOfRange", lambda: expect_raises(
            RR.OutOfRangeException, lambda: c.add(2 ** 31 - 1, 1), "add overflow"))
        self.check("void function", lambda: expect_equal(c.reset(), None, "reset() return"))
        self.check("make_inner", lambda: expect_equal(
            c.make_inner(-4, iv.UTF8_TEXT, np.array([1.0, -2.0])),
            iv.inner(f, -4, label=iv.UTF8_TEXT, values=[1.0, -2.0]), "make_inner"))

        def mix():
            args = (2.5, "mix \u00e9", iv.inner(f, 8), iv.test_pods(f, 1, seed=6), iv.vec3s(f, 1, seed=2),
                    f.var(np.array([1, 2], dtype=np.uint16), "uint16[]"), iv.COLOR["minus"], [3, -1, 0])
            expect_equal(c.mix(*args), iv.mix_result(f, *args), "mix")

        self.check("mix (8 parameters)", mix)

        def user_error():
            exc_type = RRN.GetExceptionType(iv.qn("InteropError"), c)
            e = expect_raises(exc_type, lambda: c.throw_user("boom \u00fc"), "throw_user")
            expect(isinstance(e, RR.RobotRaconteurRemoteException), "user error is a RemoteException")
            expect_equal(e.errorname, iv.qn("InteropError"), "errorname")
            expect_equal(e.message, "boom \u00fc", "error message")

        self.check("user exception", user_error)

        def standard_error():
            e = expect_raises(RR.InvalidArgumentException, lambda: c.throw_standard(), "throw_standard")
            expect_equal(e.errorname, "RobotRaconteur.InvalidArgument", "errorname")
            expect_equal(e.message, "standard error from throw_standard", "error message")

        self.check("standard exception", standard_error)

        cat = iv.varvalue_catalog(f)
        for kind in iv.VARVALUE_KINDS:
            sent, back = cat[kind]
            self.check("echo varvalue " + kind, lambda s=sent, b=back, k=kind: expect_equal(c.echo(s), b, k))
            self.check("catalog varvalue " + kind, lambda b=back, k=kind: expect_equal(c.catalog(k), b, k))
        self.check("catalog unknown -> InvalidArgument", lambda: expect_raises(
            RR.InvalidArgumentException, lambda: c.catalog("no such kind"), "catalog"))

    def generators(self):
        c = self.c

        def count_up():
            g = c.count_up(5, 3)
            expect_equal([g.Next(), g.Next(), g.Next()], [5, 6, 7], "count_up values")
            expect_raises(RR.StopIterationException, lambda: g.Next(), "count_up end")

        self.check("return generator to the end", count_up)
        self.check("return generator NextAll", lambda: expect_equal(c.count_up(-2, 4).NextAll(), [-2, -1, 0, 1],
                                                                   "NextAll"))

        def close_abort():
            g = c.count_up(0, 10)
            expect_equal(g.Next(), 0, "first")
            g.Close()
            g2 = c.count_up(0, 10)
            expect_equal(g2.Next(), 0, "first")
            g2.Abort()

        self.check("return generator Close/Abort", close_abort)

        def running_sum():
            g = c.running_sum()
            expect_equal([g.Next(1.0), g.Next(2.5), g.Next(-0.5)], [1.0, 3.5, 3.0], "running sums")
            g.Close()

        self.check("parameter+return generator", running_sum)

        def collect():
            g = c.collect()
            expect_equal(g.Next("a"), None, "void Next")
            g.Next(iv.UTF8_TEXT)
            g.Next("")
            g.Close()
            expect_equal(c.collected, ["a", iv.UTF8_TEXT, ""], "collected")

        self.check("parameter generator (void return)", collect)

        def log():
            got = c.generator_log()
            for what in ["count_up:close", "count_up:abort", "running_sum:close", "collect:close"]:
                expect(what in got, "generator_log lacks %r: %r" % (what, got))

        self.check("service saw close/abort", log)

    def events(self):
        c, f = self.c, self.f
        got, empty = [], []
        lock = threading.Lock()

        def on_values(seq, text, data):
            with lock:
                got.append((seq, text, data))

        def on_empty():
            with lock:
                empty.append(True)

        c.ev_values += on_values
        c.ev_empty += on_empty

        def fire():
            c.fire_events(3)
            wait_for(lambda: len(got) >= 3 and empty, what="3 ev_values and 1 ev_empty")
            with lock:
                expect_equal(len(got), 3, "ev_values count")
                # the library dispatches events on a thread pool: arrival order is not guaranteed
                for i, (seq, text, data) in enumerate(sorted(got, key=lambda x: x[0])):
                    expect_equal(seq, i, "ev_values seq")
                    expect_equal(text, iv.event_text(i), "ev_values text")
                    expect_equal(data, iv.event_data(f, i), "ev_values data")
                expect_equal(len(empty), 1, "ev_empty count")

        self.check("events fired on request", fire)
        c.ev_values -= on_values
        c.ev_empty -= on_empty

    def objrefs(self):
        c = self.c

        def plain():
            ch = c.get_child()
            expect_equal(RRN.GetObjectType(ch), iv.qn("Child"), "child type")
            expect_equal(RRN.GetObjectServicePath(ch), "interop.child", "child path")
            expect_equal(ch.name, iv.child_name("plain"), "child name")
            expect_equal(ch.value, 1, "child value")
            ch.value = -9
            expect_equal(ch.value, -9, "child value after set")
            expect_equal(ch.describe(), "child[plain] value=-9", "describe")
            leaf = ch.get_leaf()
            expect_equal(RRN.GetObjectServicePath(leaf), "interop.child.leaf", "leaf path")
            expect_equal(leaf.x, 1.5, "leaf x")
            expect_equal(leaf.scaled(2.0), 3.0, "leaf scaled")

        self.check("objref plain + nested", plain)

        def by_int():
            for k in iv.CHILD_INT_KEYS:
                ch = c.get_child_by_int(k)
                expect_equal(ch.name, iv.child_name(k), "child_by_int name")
                expect_equal(ch.value, 100 + k, "child_by_int value")
            ch = c.get_child_by_int(-1)
            expect_equal(RRN.GetObjectServicePath(ch), "interop.child_by_int[%2d1]", "encoded int index")

        self.check("objref indexed by int32", by_int)

        def by_name():
            for i, k in enumerate(iv.CHILD_STR_KEYS):
                ch = c.get_child_by_name(k)
                expect_equal(ch.name, iv.child_name(k), "child_by_name name")
                expect_equal(ch.value, 200 + i, "child_by_name value")
            ch = c.get_child_by_name("with space_and-dash")
            expect_equal(RRN.GetObjectServicePath(ch), "interop.child_by_name[with%20space%5fand%2ddash]",
                         "encoded string index")
            expect_equal(ch.get_leaf().x, 200.5 + 1, "leaf below an indexed objref")

        self.check("objref indexed by string", by_name)
        self.check("objref unknown index -> ObjectNotFound", lambda: expect_raises(
            RR.ObjectNotFoundException, lambda: c.get_child_by_int(12345), "child_by_int[12345]"))

        def varobject():
            o = c.get_any_obj()
            expect_equal(RRN.GetObjectType(o), iv.qn("Leaf"), "varobject type")
            expect_equal(o.x, -3.5, "varobject x")

        self.check("objref varobject", varobject)

        def release():
            ch = c.get_child_by_int(0)
            expect_equal(ch.value, 100, "before release")
            c.release_child(0)
            ch2 = c.get_child_by_int(0)
            expect_equal(ch2.value, 100, "after release, requested again")

        self.check("service path released", release)

    def pipes(self):
        c, f = self.c, self.f

        def echo():
            ep = c.p_echo.Connect(-1)
            acks = []
            ep.PacketAckReceivedEvent += lambda ep_, n: acks.append(n)
            ep.RequestPacketAck = True
            sent = [iv.inner(f, i, label="pipe %d" % i) for i in range(3)]
            for p in sent:
                ep.SendPacket(p)
            for i, p in enumerate(sent):
                expect_equal(ep.ReceivePacketWait(WAIT_S), p, "echoed packet %d" % i)
            wait_for(lambda: len(acks) >= 3, what="3 packet acks")
            ep.Close()

        self.check("pipe echo with acks", echo)

        def fixed_index():
            ep = c.p_echo.Connect(3)
            expect_equal(ep.Index, 3, "pipe index")
            ep.SendPacket(iv.inner(f, 3))
            expect_equal(ep.ReceivePacketWait(WAIT_S), iv.inner(f, 3), "echo on index 3")
            ep.Close()

        self.check("pipe connect with fixed index", fixed_index)

        def unreliable():
            ep = c.p_unreliable.Connect(-1)
            expect(ep.IsUnreliable, "endpoint is unreliable")
            for s in ["u1", iv.UTF8_TEXT]:
                # The official 1.2.9 library never completes a synchronous SendPacket on an unreliable
                # pipe (its send handler is not called), so send asynchronously.
                ep.AsyncSendPacket(s, lambda *a: None)
                expect_equal(ep.ReceivePacketWait(WAIT_S), s, "unreliable echo")
            ep.Close()

        self.check("unreliable pipe echo", unreliable)

        def stream():
            ep = c.p_stream.Connect(-1)
            closed = threading.Event()
            ep.PipeEndpointClosedCallback = lambda ep_: closed.set()
            c.send_stream(4)
            for i in range(4):
                expect_equal(ep.ReceivePacketWait(WAIT_S), iv.stream_packet(i), "stream packet %d" % i)
            c.close_stream()
            expect(closed.wait(WAIT_S), "service closed the pipe endpoint")

        self.check("readonly pipe stream + closed by service", stream)

    def callbacks(self):
        c, f = self.c, self.f
        labels, infos = [], []

        def compute(x, label):
            labels.append(label)
            return x * 2.0

        def notify(info):
            infos.append(info)

        c.cb_compute.Function = compute
        c.cb_notify.Function = notify

        def call():
            expect_equal(c.call_callbacks(3.0), 7.0, "call_callbacks result")
            expect_equal(labels, [iv.CALLBACK_LABEL], "callback label")
            expect_equal(infos, [iv.inner(f, 77, label="notify")], "callback struct")

        self.check("callbacks invoked by the service", call)

    def wires(self):
        c, f = self.c, self.f

        def state():
            conn = c.w_state.Connect()
            seen = []
            conn.WireValueChanged += lambda conn_, v, ts: seen.append(v)
            wait_for(lambda: len({v.id for v in seen if v.label == "tick"}) >= 2, timeout=10 * iv.STATE_PERIOD_S + 2,
                     what="two periodic w_state updates")
            c.update_state(1234)
            wait_for(lambda: any(v.id == 1234 and v.label == "demand" for v in seen), what="w_state on demand")
            expect_equal([v for v in seen if v.label == "demand"][0], iv.state_value(f, 1234, "demand"), "w_state")
            expect(conn.InValueValid, "InValue valid")
            v, ts = c.w_state.PeekInValue()
            expect(v.label in ("tick", "demand"), "peeked w_state label %r" % v.label)
            expect(ts.seconds > 1500000000, "packet time stamp is recent: %r" % ts.seconds)
            conn.Close()

        self.check("readonly wire periodic + on demand + peek", state)

        def two_clients():
            # The service sends one value to several clients (encoded once, copied into each message):
            # every client gets the same value, and so does each client's event handler.
            c2 = RRN.ConnectService(self.url)
            try:
                conns = [c.w_state.Connect(), c2.w_state.Connect()]
                seen = [[], []]
                for k, conn in enumerate(conns):
                    conn.WireValueChanged += lambda conn_, v, ts, k=k: seen[k].append(v)
                got = [[], []]
                handlers = [lambda seq, text, data, k=k: got[k].append((seq, text, data)) for k in range(2)]
                c.ev_values += handlers[0]
                c2.ev_values += handlers[1]
                c.update_state(4321)
                for k in range(2):
                    wait_for(lambda k=k: any(v.id == 4321 and v.label == "demand" for v in seen[k]),
                             what="w_state on demand at client %d" % (k + 1))
                    expect_equal([v for v in seen[k] if v.id == 4321][0], iv.state_value(f, 4321, "demand"),
                                 "w_state at client %d" % (k + 1))
                c.fire_events(2)
                for k in range(2):
                    wait_for(lambda k=k: len(got[k]) >= 2, what="2 ev_values at client %d" % (k + 1))
                    for i, (seq, text, data) in enumerate(sorted(got[k], key=lambda x: x[0])):
                        expect_equal((seq, text), (i, iv.event_text(i)), "ev_values at client %d" % (k + 1))
                        expect_equal(data, iv.event_data(f, i), "ev_values data at client %d" % (k + 1))
                c.ev_values -= handlers[0]
                c2.ev_values -= handlers[1]
                for conn in conns:
                    conn.Close()
            finally:
                RRN.DisconnectService(c2)

        if self.url:
            self.check("one wire value and event to two clients", two_clients)
        else:
            print("skipped wires/one wire value and event to two clients: --single-connection", file=sys.stderr)

        def both():
            conn = c.w_both.Connect()
            conn.OutValue = np.array([1.0, 2.0, 3.0])
            wait_for(lambda: conn.InValueValid, what="w_both echo")
            wait_for(lambda: iv.deep_equal(conn.InValue, np.array([3.0, 2.0, 1.0])) is None, what="reversed echo")
            expect_equal(c.w_both.PeekInValue()[0], np.array([3.0, 2.0, 1.0]), "PeekInValue")
            expect_equal(c.w_both.PeekOutValue()[0], np.array([1.0, 2.0, 3.0]), "PeekOutValue")
            c.w_both.PokeOutValue(np.array([9.0, -0.0]))
            expect_equal(c.w_both.PeekOutValue()[0], np.array([9.0, -0.0]), "PeekOutValue after poke")
            conn.Close()

        self.check("two-way wire + peek/poke", both)

        def sink():
            conn = c.w_sink.Connect()
            conn.OutValue = 42
            wait_for(lambda: c.w_sink_value() == 42, what="w_sink value 42")
            conn.Close()
            c.w_sink.PokeOutValue(-43)
            expect_equal(c.w_sink_value(), -43, "w_sink after poke")
            expect_equal(c.w_sink.PeekOutValue()[0], -43, "w_sink PeekOutValue")

        self.check("writeonly wire + poke", sink)

    def memories(self):
        c, f = self.c, self.f

        def mem_double():
            m = c.mem_double
            expect_equal(m.Length, iv.MEM_DOUBLE_LEN, "Length")
            buf = np.zeros((10,))
            m.Read(10, buf, 0, 10)
            expect_equal(buf, iv.mem_double_initial()[10:20], "read")
            m.Write(5, np.array([-1.0, -2.0, -3.0]), 0, 3)
            buf = np.zeros((5,))
            m.Read(4, buf, 0, 5)
            expect_equal(buf, np.array([2.0, -1.0, -2.0, -3.0, 4.0]), "read after write")

        self.check("memory double[]", mem_double)

        def mem_md():
            m = c.mem_md
            expect_equal([int(d) for d in m.Dimensions], list(iv.MEM_MD_SHAPE), "Dimensions")
            expect_equal(int(m.DimCount), 2, "DimCount")
            buf = np.zeros((2, 3), dtype=np.int32)
            m.Read([1, 1], buf, [0, 0], [2, 3])
            expect_equal(buf, iv.mem_md_initial()[1:3, 1:4], "read block")
            m.Write([0, 0], np.array([[7, 8], [9, 10]], dtype=np.int32), [0, 0], [2, 2])
            buf = np.zeros(iv.MEM_MD_SHAPE, dtype=np.int32)
            m.Read([0, 0], buf, [0, 0], list(iv.MEM_MD_SHAPE))
            want = iv.mem_md_initial()
            want[0:2, 0:2] = [[7, 8], [9, 10]]
            expect_equal(buf, want, "read after write")

        self.check("memory int32[*]", mem_md)

        def mem_pod():
            m = c.mem_pod
            expect_equal(m.Length, iv.MEM_POD_LEN, "Length")
            buf = np.zeros((2,), dtype=f.pod_dtype("TestPod"))
            m.Read(1, buf, 0, 2)
            expect_equal(buf, iv.mem_pod_initial(f)[1:3], "read")
            m.Write(0, iv.test_pods(f, 1, seed=99), 0, 1)
            buf = np.zeros((iv.MEM_POD_LEN,), dtype=f.pod_dtype("TestPod"))
            m.Read(0, buf, 0, iv.MEM_POD_LEN)
            want = iv.mem_pod_initial(f)
            want[0] = iv.test_pods(f, 1, seed=99)[0]
            expect_equal(buf, want, "read after write")

        self.check("memory pod[]", mem_pod)

        def mem_pod_md():
            m = c.mem_pod_md
            expect_equal([int(d) for d in m.Dimensions], [2, 3], "Dimensions")
            buf = np.zeros((2, 3), dtype=f.pod_dtype("TestPod"))
            m.Read([0, 0], buf, [0, 0], [2, 3])
            expect_equal(buf, iv.mem_pod_md_initial(f), "read")
            w = iv.test_pods(f, 2, seed=7).reshape((1, 2), order="F")
            m.Write([1, 1], w, [0, 0], [1, 2])
            m.Read([0, 0], buf, [0, 0], [2, 3])
            want = iv.mem_pod_md_initial(f)
            want[1:2, 1:3] = w
            expect_equal(buf, want, "read after write")

        self.check("memory pod[*]", mem_pod_md)

        def mem_na():
            m = c.mem_na
            expect_equal(m.Length, iv.MEM_NA_LEN, "Length")
            buf = np.zeros((3,), dtype=f.na_dtype("Vec3"))
            m.Read(2, buf, 0, 3)
            expect_equal(buf, iv.mem_na_initial(f)[2:5], "read")
            m.Write(4, iv.vec3s(f, 1, seed=70), 0, 1)
            m.Read(2, buf, 0, 3)
            want = iv.mem_na_initial(f)[2:5].copy()
            want[2] = iv.vec3s(f, 1, seed=70)[0]
            expect_equal(buf, want, "read after write")

        self.check("memory namedarray[]", mem_na)

        def mem_na_md():
            m = c.mem_na_md
            expect_equal([int(d) for d in m.Dimensions], [3, 2], "Dimensions")
            buf = np.zeros((3, 2), dtype=f.na_dtype("Vec3"))
            m.Read([0, 0], buf, [0, 0], [3, 2])
            expect_equal(buf, iv.mem_na_md_initial(f), "read")

        self.check("memory namedarray[*]", mem_na_md)

        def mem_ro():
            m = c.mem_ro
            buf = np.zeros((iv.MEM_RO_LEN,), dtype=np.uint8)
            m.Read(0, buf, 0, iv.MEM_RO_LEN)
            expect_equal(buf, iv.mem_ro_initial(), "read")
            expect_raises((RR.ReadOnlyMemberException, RR.RobotRaconteurException),
                          lambda: m.Write(0, np.array([1], dtype=np.uint8), 0, 1), "write to readonly memory")

        self.check("memory [readonly]", mem_ro)

    def session(self):
        c = self.c

        def monitor():
            RRN.MonitorEnter(c, 5)
            try:
                expect_equal(c.ro_value, iv.RO_VALUE, "read under monitor lock")
            finally:
                RRN.MonitorExit(c)

        self.check("monitor lock", monitor)
        self.check("final reset", lambda: c.reset())

    SECTIONS = ["connection", "properties", "functions", "generators", "events", "objrefs", "pipes",
                "callbacks", "wires", "memories", "session"]

    def run(self, sections):
        for s in sections:
            self.section = s
            getattr(self, s)()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("url")
    ap.add_argument("--disable-message4", action="store_true", help="offer message format v2 only")
    ap.add_argument("--disable-stringtable", action="store_true", help="do not offer v4 string tables")
    ap.add_argument("--heartbeat", type=float, default=None, help="TCP heartbeat period in seconds")
    ap.add_argument("--idle", type=float, default=0.0, help="stay connected and idle this long at the end (s)")
    ap.add_argument("--timeout", type=float, default=90.0, help="overall time limit (s)")
    ap.add_argument("--single-connection", action="store_true",
                    help="open no second connection to the service (the official 1.x library fails one to a service "
                         "that uses string tables: 'Transport connection to remote host not found')")
    ap.add_argument("--verbose", action="store_true", help="print each check's name on stderr")
    ap.add_argument("--only", default="", help="comma-separated sections (default: all): " +
                    ",".join(Runner.SECTIONS))
    args = ap.parse_args(argv)
    sections = [s for s in args.only.split(",") if s] or Runner.SECTIONS
    for s in sections:
        if s not in Runner.SECTIONS:
            ap.error("unknown section %r" % s)

    def overall_timeout():
        print(json.dumps({"ok": False, "url": args.url, "error": "overall timeout %.0f s" % args.timeout}),
              flush=True)
        os._exit(3)

    watchdog = threading.Timer(args.timeout, overall_timeout)
    watchdog.daemon = True
    watchdog.start()

    RRN.SetLogLevelFromEnvVariable()
    t = official_transport.client_tcp_transport(RR)
    t.DisableMessage4 = args.disable_message4
    t.DisableStringTable = args.disable_stringtable
    if args.heartbeat is not None:
        t._SetDefaultHeartbeatPeriod(int(args.heartbeat * 1000))  # the property setter passes a float
    RRN.RegisterTransport(t)
    if args.url.startswith("rr+local:"):
        lt = RR.LocalTransport()
        lt.DisableMessage4 = args.disable_message4
        lt.DisableStringTable = args.disable_stringtable
        RRN.RegisterTransport(lt)

    summary = {"ok": False, "url": args.url, "sections": sections}
    rc = 2
    try:
        try:
            c = RRN.ConnectService(args.url)
        except Exception as e:
            summary["error"] = "connect failed: %s: %s" % (type(e).__name__, e)
            print(json.dumps(summary), flush=True)
            return 2
        r = Runner(c, None if args.single_connection else args.url)
        r.verbose = args.verbose
        r.run(sections)
        if args.idle > 0:
            time.sleep(args.idle)
        try:
            RRN.DisconnectService(c)
        except Exception as e:
            r.results.append(("session", "disconnect", False, str(e)))
        failures = [{"check": "%s/%s" % (s, n), "error": e} for s, n, ok, e in r.results if not ok]
        summary.update({
            "ok": not failures,
            "passed": sum(1 for x in r.results if x[2]),
            "failed": len(failures),
            "failures": failures,
            "per_section": {s: [sum(1 for x in r.results if x[0] == s and x[2]),
                                sum(1 for x in r.results if x[0] == s)] for s in sections},
        })
        print(json.dumps(summary), flush=True)
        rc = 0 if not failures else 1
        return rc
    finally:
        watchdog2 = threading.Timer(50.0, lambda: os._exit(rc if rc else 4))  # bounds Shutdown's hang (official_service.py)
        watchdog2.daemon = True
        watchdog2.start()
        RRN.Shutdown()
        watchdog.cancel()
        watchdog2.cancel()


if __name__ == "__main__":
    sys.exit(main())
