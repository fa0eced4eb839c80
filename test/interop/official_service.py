#!/usr/bin/env python3
"""The interop test service, implemented with the official Robot Raconteur Python package.

Serves robdef/experimental.interop_test.robdef as service "interop" with the deterministic values of
interop_values.py. Every member behaves observably (see the robdef comments): properties check what
they are set to, functions push events / pipe packets / callbacks / wire values on request, generators
yield known sequences, memories are readable and writable, reset() restores the initial state.

Usage:
    official_service.py [--port N] [--websocket] [--disable-message4] [--enable-stringtable]
                        [--heartbeat SECONDS] [--max-lifetime SECONDS] [--node-setup NAME]
                        [--nodeid ID] [--load-tls] [--users FILE]

--node-setup NAME starts the node with the library's default server setup,
RobotRaconteur.ServerNodeSetup(NAME, port): NodeName NAME with the NodeID of its NodeID cache, the
local transport (rr+local) serving NAME, TCP on the port (loopback and every other interface), and the
setup's own defaults for message formats; the transport options above are then ignored. The ready line
adds "local_url" (by NodeName) and "local_id_url" (by NodeID). A NodeName already in use exits with
status 3 and the library's message on stderr.

--nodeid ID fixes the NodeID; --load-tls loads the node's TLS certificate for rrs+tcp as the library
does (TcpTransport.LoadTlsNodeCertificate: <config dir>/certificates/{NodeID}.p12, the config dir
from ROBOTRACONTEUR_SYSTEM_CONFIG_DIR when root, else ROBOTRACONTEUR_USER_CONFIG_DIR); the ready line
then says "tls": true or false.

--users FILE requires logins: the file (the official password file format, `user md5hex privileges`
per line) is handed unchanged to the library's PasswordFileUserAuthenticator, and the service is
registered with a ServiceSecurityPolicy of {"requirevaliduser": "true", "allowobjectlock": "true"}, as
the official docs and examples do. Object locks, monitor locks and their release are then the
library's own (ServerContext in RobotRaconteurCore/src/Service.cpp): this is the reference that
locks_logins.py compares our service with. The ready line then says "users": true. The library reads
every non-empty line as a user, `#` lines too (as a user named "#"); a line with fewer than three
fields, or with a fourth that is not a list of NodeIDs, makes the whole file fail to load (exit 3).

When ready it prints exactly one JSON line on stdout, e.g.
    {"url": "rr+tcp://127.0.0.1:PORT/?service=interop", "port": PORT, "nodeid": "...", ...}
and then runs until SIGTERM/SIGINT (or --max-lifetime), shutting the node down cleanly.
"""

import argparse
import json
import os
import signal
import sys
import threading
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import interop_values as iv  # noqa: E402

import RobotRaconteur as RR  # noqa: E402

RRN = RR.RobotRaconteurNode.s

ROBDEF = os.path.join(os.path.dirname(os.path.abspath(__file__)), "robdef", "experimental.interop_test.robdef")


def log(*args):
    print("[official_service]", *args, file=sys.stderr, flush=True)


# ---------------------------------------------------------------------------------------------------
# Generators


class CountUp:
    """count_up(start, count): yields start .. start+count-1, then StopIteration."""

    def __init__(self, owner, start, count):
        self.owner, self.next_value, self.end = owner, start, start + count
        self.closed = self.aborted = False

    def Next(self):
        if self.aborted:
            raise RR.OperationAbortedException("count_up aborted")
        if self.closed or self.next_value >= self.end:
            raise RR.StopIterationException("count_up done")
        v = self.next_value
        self.next_value += 1
        return v

    def Close(self):
        self.closed = True
        self.owner._log_generator("count_up:close")

    def Abort(self):
        self.aborted = True
        self.owner._log_generator("count_up:abort")


class RunningSum:
    """running_sum(values{generator}): Next(x) returns the sum of all x so far."""

    def __init__(self, owner):
        self.owner, self.total, self.done = owner, 0.0, False

    def Next(self, x):
        if self.done:
            raise RR.StopIterationException("running_sum closed")
        self.total += x
        return self.total

    def Close(self):
        self.done = True
        self.owner._log_generator("running_sum:close")

    def Abort(self):
        self.done = True
        self.owner._log_generator("running_sum:abort")


class Collect:
    """collect(items{generator}): Next(s) appends s to Root.collected."""

    def __init__(self, owner):
        self.owner, self.done = owner, False

    def Next(self, s):
        if self.done:
            raise RR.StopIterationException("collect closed")
        with self.owner._lock:
            self.owner._collected.append(s)

    def Close(self):
        self.done = True
        self.owner._log_generator("collect:close")

    def Abort(self):
        self.done = True
        self.owner._log_generator("collect:abort")


# ---------------------------------------------------------------------------------------------------
# Sub-objects


class LeafImpl:
    def __init__(self, x):
        self._x0 = x
        self.x = x

    def scaled(self, k):
        return self.x * k


class ChildImpl:
    def __init__(self, key, value):
        self._name = iv.child_name(key)
        self._value0 = value
        self.value = value
        self.service_path = None
        self._leaf = LeafImpl(float(value) + 0.5)

    @property
    def name(self):
        return self._name

    def describe(self):
        return "%s value=%d" % (self._name, self.value)

    def get_leaf(self):
        return self._leaf, iv.qn("Leaf")

    def RRServiceObjectInit(self, context, service_path):
        self.service_path = service_path


# ---------------------------------------------------------------------------------------------------
# Root object


class RootImpl:
    def __init__(self):
        self._lock = threading.RLock()
        self._monitor = threading.RLock()
        self.f = iv.Factory(RR, RRN)
        self._ab = iv.property_values(self.f)  # name -> (A, B); reference copies, never handed out
        self.ev_values = RR.EventHook()
        self.ev_empty = RR.EventHook()
        self._stream_eps = []
        self._w_state = None
        self._w_both = None
        self._w_sink = None
        self._tick = 0
        self.mem_double = RR.ArrayMemory(iv.mem_double_initial())
        self.mem_md = RR.MultiDimArrayMemory(iv.mem_md_initial())
        self.mem_pod = RR.ArrayMemory(iv.mem_pod_initial(self.f))
        self.mem_pod_md = RR.MultiDimArrayMemory(iv.mem_pod_md_initial(self.f))
        self.mem_na = RR.ArrayMemory(iv.mem_na_initial(self.f))
        self.mem_na_md = RR.MultiDimArrayMemory(iv.mem_na_md_initial(self.f))
        self.mem_ro = RR.ArrayMemory(iv.mem_ro_initial())
        self._child = ChildImpl("plain", 1)
        self._children_int = {k: ChildImpl(k, 100 + k) for k in iv.CHILD_INT_KEYS}
        self._children_str = {k: ChildImpl(k, 200 + i) for i, k in enumerate(iv.CHILD_STR_KEYS)}
        self._any_leaf = LeafImpl(-3.5)
        self._reset_state()

    def _reset_state(self):
        with self._lock:
            self._props = {k: v[0] for k, v in iv.property_values(self.f).items()}
            self._wo_value = 0
            self._collected = []
            self._generator_log = []
            self._both_in = None
            self._both_out = np.array([0.0])
            self._sink_value = -1
            self.mem_double.memory[:] = iv.mem_double_initial()
            self.mem_md.memory[:] = iv.mem_md_initial()
            self.mem_pod.memory[:] = iv.mem_pod_initial(self.f)
            self.mem_pod_md.memory[:] = iv.mem_pod_md_initial(self.f)
            self.mem_na.memory[:] = iv.mem_na_initial(self.f)
            self.mem_na_md.memory[:] = iv.mem_na_md_initial(self.f)
            self.mem_ro.memory[:] = iv.mem_ro_initial()
            for c in [self._child] + list(self._children_int.values()) + list(self._children_str.values()):
                c.value = c._value0
                c._leaf.x = c._leaf._x0
            self._any_leaf.x = self._any_leaf._x0

    def _log_generator(self, what):
        with self._lock:
            self._generator_log.append(what)

    # --- properties (the read/write ones are generated below the class) ---
    @property
    def base_name(self):
        return iv.BASE_NAME

    @property
    def ro_value(self):
        return iv.RO_VALUE

    @property
    def wo_value(self):
        raise RR.WriteOnlyMemberException("wo_value is write-only")

    @wo_value.setter
    def wo_value(self, v):
        with self._lock:
            self._wo_value = v

    @property
    def collected(self):
        with self._lock:
            return list(self._collected)

    # --- functions ---
    def reset(self):
        self._reset_state()

    def add(self, a, b):
        r = a + b
        if not -2 ** 31 <= r < 2 ** 31:
            raise RR.OutOfRangeException("add overflows int32")
        return r

    def mix(self, a, b, c, d, e, f_, g, h):
        return iv.mix_result(self.f, a, b, c, d, e, f_, g, h)

    def make_inner(self, id_, label, values):
        return iv.inner(self.f, id_, label=label, values=values)

    def echo(self, v):
        return v

    def catalog(self, kind):
        cat = iv.varvalue_catalog(self.f)
        if kind not in cat:
            raise RR.InvalidArgumentException("unknown varvalue kind %r" % kind)
        return cat[kind][0]

    def throw_user(self, message):
        raise RRN.GetExceptionType(iv.qn("InteropError"))(message)

    def throw_standard(self):
        raise RR.InvalidArgumentException("standard error from throw_standard")

    def wo_value_last(self):
        with self._lock:
            return self._wo_value

    # --- generators ---
    def count_up(self, start, count):
        return CountUp(self, start, count)

    def running_sum(self):
        return RunningSum(self)

    def collect(self):
        return Collect(self)

    def generator_log(self):
        with self._lock:
            return list(self._generator_log)

    # --- events ---
    def fire_events(self, count):
        for seq in range(count):
            self.ev_values.fire(seq, iv.event_text(seq), iv.event_data(self.f, seq))
        self.ev_empty.fire()

    # --- objrefs ---
    def get_child(self):
        return self._child, iv.qn("Child")

    def get_child_by_int(self, ind):
        k = int(ind)  # the Python skeleton hands int32 indexes over as text
        if k not in self._children_int:
            raise RR.ObjectNotFoundException("no child_by_int[%d]" % k)
        return self._children_int[k], iv.qn("Child")

    def get_child_by_name(self, ind):
        if ind not in self._children_str:
            raise RR.ObjectNotFoundException("no child_by_name[%s]" % ind)
        return self._children_str[ind], iv.qn("Child")

    def get_any_obj(self):
        return self._any_leaf, iv.qn("Leaf")

    def release_child(self, index):
        c = self._children_int.get(index)
        if c is None:
            raise RR.InvalidArgumentException("no child_by_int[%d]" % index)
        if c.service_path is None:
            raise RR.InvalidOperationException("child_by_int[%d] was never requested" % index)
        RR.ServerContext.GetCurrentServerContext().ReleaseServicePath(c.service_path)
        c.service_path = None

    # --- pipes ---
    @property
    def p_echo(self):
        return self._p_echo

    @p_echo.setter
    def p_echo(self, pipe):
        self._p_echo = pipe
        pipe.PipeConnectCallback = self._echo_connected

    @property
    def p_unreliable(self):
        return self._p_unreliable

    @p_unreliable.setter
    def p_unreliable(self, pipe):
        self._p_unreliable = pipe
        pipe.PipeConnectCallback = self._echo_connected

    def _echo_connected(self, ep):
        ep.PacketReceivedEvent += self._echo_received

    def _echo_received(self, ep):
        while ep.Available > 0:
            ep.AsyncSendPacket(ep.ReceivePacket(), lambda *a: None)

    @property
    def p_stream(self):
        return self._p_stream

    @p_stream.setter
    def p_stream(self, pipe):
        self._p_stream = pipe
        pipe.PipeConnectCallback = self._stream_connected

    def _stream_connected(self, ep):
        with self._lock:
            self._stream_eps.append(ep)
        ep.PipeEndpointClosedCallback = self._stream_closed

    def _stream_closed(self, ep):
        with self._lock:
            if ep in self._stream_eps:
                self._stream_eps.remove(ep)

    def send_stream(self, count):
        with self._lock:
            eps = list(self._stream_eps)
        for ep in eps:
            for i in range(count):
                ep.SendPacket(iv.stream_packet(i))

    def close_stream(self):
        with self._lock:
            eps, self._stream_eps = self._stream_eps, []
        for ep in eps:
            ep.Close()

    # --- callbacks (cb_compute / cb_notify are set by the skeleton) ---
    def call_callbacks(self, x):
        ep = RR.ServerEndpoint.GetCurrentEndpoint()
        self.cb_notify.GetClientFunction(ep)(iv.inner(self.f, 77, label="notify"))
        r = self.cb_compute.GetClientFunction(ep)(x, iv.CALLBACK_LABEL)
        return r + 1.0

    # --- wires ---
    @property
    def w_state(self):
        return self._w_state_wire

    @w_state.setter
    def w_state(self, wire):
        self._w_state_wire = wire
        self._w_state = RR.WireBroadcaster(wire)
        self._w_state.OutValue = iv.state_value(self.f, 0, "initial")

    def update_state(self, seq):
        self._w_state.OutValue = iv.state_value(self.f, seq, "demand")

    def _tick_state(self):
        with self._lock:
            self._tick += 1
            t = self._tick
        if self._w_state is not None:
            self._w_state.OutValue = iv.state_value(self.f, t, "tick")

    @property
    def w_both(self):
        return self._w_both

    @w_both.setter
    def w_both(self, wire):
        self._w_both = wire
        wire.WireConnectCallback = self._both_connected
        wire.PeekInValueCallback = self._both_peek_in
        wire.PeekOutValueCallback = self._both_peek_out
        wire.PokeOutValueCallback = self._both_poke

    def _both_connected(self, conn):
        conn.WireValueChanged += self._both_changed

    def _both_changed(self, conn, value, ts):
        rev = np.ascontiguousarray(value[::-1])
        with self._lock:
            self._both_in = value
            self._both_out = rev
        conn.OutValue = rev

    def _both_peek_in(self, ep):
        # what a client's PeekInValue sees: the service's out value
        with self._lock:
            return self._both_out

    def _both_peek_out(self, ep):
        # what a client's PeekOutValue sees: the value the service last received
        with self._lock:
            if self._both_in is None:
                raise RR.ValueNotSetException("w_both has no value from a client yet")
            return self._both_in

    def _both_poke(self, value, ts, ep):
        with self._lock:
            self._both_in = value

    @property
    def w_sink(self):
        return self._w_sink

    @w_sink.setter
    def w_sink(self, wire):
        self._w_sink_wire = wire
        self._w_sink = RR.WireUnicastReceiver(wire)
        self._w_sink.InValueChanged += self._sink_changed

    def _sink_changed(self, value, ts, ep):
        with self._lock:
            self._sink_value = value

    def w_sink_value(self):
        with self._lock:
            return self._sink_value

    # --- monitor lock (ClientSessionOp MonitorEnter / MonitorExit) ---
    def RobotRaconteurMonitorEnter(self, timeout=-1):
        if not self._monitor.acquire(timeout=(timeout / 1000.0 if timeout >= 0 else -1)):
            raise RR.RequestTimeoutException("monitor busy")

    def RobotRaconteurMonitorExit(self):
        self._monitor.release()


def _make_property(name):
    def getter(self):
        with self._lock:
            return self._props[name]

    def setter(self, value):
        a, b = self._ab[name]
        da = iv.deep_equal(value, a, name)
        if da is not None and iv.deep_equal(value, b, name) is not None:
            raise RR.InvalidArgumentException("set %s: value is neither A nor B (%s)" % (name, da))
        with self._lock:
            self._props[name] = value

    return property(getter, setter)


def install_properties():
    # property names are known only once the service type is registered (pods need type info)
    for name in iv.property_values(iv.Factory(RR, RRN)):
        setattr(RootImpl, name, _make_property(name))


# ---------------------------------------------------------------------------------------------------


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--port", type=int, default=0, help="TCP port (0 = ephemeral)")
    ap.add_argument("--websocket", action="store_true", help="also accept WebSocket (rr+ws) on the same port")
    ap.add_argument("--disable-message4", action="store_true", help="negotiate message format v2 only")
    ap.add_argument("--enable-stringtable", action="store_true",
                    help="allow v4 string tables (a stock ServerNodeSetup disables them)")
    ap.add_argument("--heartbeat", type=float, default=None, help="TCP heartbeat period in seconds")
    ap.add_argument("--listen-all", action="store_true", help="listen on all interfaces, not only loopback")
    ap.add_argument("--max-lifetime", type=float, default=0, help="exit after this many seconds (0 = never)")
    ap.add_argument("--nodeid", default=None, help="fix the NodeID (UUID)")
    ap.add_argument("--load-tls", action="store_true", help="load the node's TLS certificate (rrs+tcp)")
    ap.add_argument("--node-setup", default=None, metavar="NAME",
                    help="use RobotRaconteur.ServerNodeSetup(NAME, port) (rr+local + TCP, library defaults)")
    ap.add_argument("--users", default=None, metavar="FILE",
                    help="require logins: PasswordFileUserAuthenticator from FILE (official format), "
                         "policies requirevaliduser and allowobjectlock")
    args = ap.parse_args(argv)

    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *a: stop.set())
    signal.signal(signal.SIGINT, lambda *a: stop.set())

    RRN.SetLogLevelFromEnvVariable()
    setup = None
    tls_loaded = None
    if args.node_setup:
        try:
            setup = RR.ServerNodeSetup(args.node_setup, args.port)
        except Exception as e:
            log("ServerNodeSetup(%r) failed: %s: %s" % (args.node_setup, type(e).__name__, e))
            return 3
        port = setup.tcp_transport.GetListenPort()
    else:
        if args.nodeid:
            RRN.SetNodeID(RR.NodeID(args.nodeid))
        RRN.SetNodeName("interop_service")
        t = RR.TcpTransport()
        t.DisableMessage4 = args.disable_message4
        t.DisableStringTable = not args.enable_stringtable
        t.AcceptWebSockets = args.websocket
        if args.heartbeat is not None:
            t._SetDefaultHeartbeatPeriod(int(args.heartbeat * 1000))  # the property setter passes a float
        t.StartServer(args.port, not args.listen_all)
        if args.load_tls:
            t.LoadTlsNodeCertificate()  # logs a warning and leaves TLS off when the file is missing
            tls_loaded = bool(t.IsTlsNodeCertificateLoaded)
        RRN.RegisterTransport(t)
        port = t.GetListenPort()

    RRN.RegisterServiceTypeFromFile(ROBDEF)
    install_properties()
    root = RootImpl()
    security = None
    if args.users:
        with open(args.users) as fh:
            users_text = fh.read()
        try:
            authenticator = RR.PasswordFileUserAuthenticator(users_text)
        except Exception as e:  # the library refuses the whole file on one bad line
            log("PasswordFileUserAuthenticator(%s) failed: %s: %s" % (args.users, type(e).__name__, e))
            RRN.Shutdown()
            return 3
        security = RR.ServiceSecurityPolicy(authenticator, {"requirevaliduser": "true", "allowobjectlock": "true"})
    ctx = RRN.RegisterService(iv.SERVICE_NAME, iv.qn("Root"), root, security)
    ctx.SetServiceAttributes({
        "purpose": RR.VarValue("interop test \u2713", "string"),
        "version": RR.VarValue(np.array([1, 0], dtype=np.int32), "int32[]"),
    })

    def ticker():
        while not stop.wait(iv.STATE_PERIOD_S):
            try:
                root._tick_state()
            except Exception as e:  # the node may be shutting down
                log("tick failed:", e)

    th = threading.Thread(target=ticker, daemon=True)
    th.start()

    ready = {
        "url": "rr+tcp://127.0.0.1:%d/?service=%s" % (port, iv.SERVICE_NAME),
        "port": port,
        "nodeid": str(RRN.NodeID),
        "nodename": RRN.NodeName,
        "message4": not args.disable_message4,
        "stringtable": bool(args.enable_stringtable),
    }
    if args.users:
        ready["users"] = True
    if args.load_tls:
        ready["tls"] = tls_loaded
    if args.websocket:
        ready["ws_url"] = "rr+ws://127.0.0.1:%d/?service=%s" % (port, iv.SERVICE_NAME)
    if setup is not None:
        ready["local_url"] = "rr+local:///?nodename=%s&service=%s" % (args.node_setup, iv.SERVICE_NAME)
        ready["local_id_url"] = "rr+local:///?nodeid=%s&service=%s" % (str(RRN.NodeID).strip("{}"), iv.SERVICE_NAME)
    print(json.dumps(ready), flush=True)

    deadline = time.monotonic() + args.max_lifetime if args.max_lifetime > 0 else None
    while not stop.wait(0.2):
        if deadline is not None and time.monotonic() > deadline:
            log("max lifetime reached")
            break

    # Shutdown: never hang. A watchdog ends the process if the node does not stop in time: 50 s, a bound
    # on a hang (under load the node's shutdown took over 10 s: closing its rr+local transport's inotify
    # descriptor waits for the kernel, docs/development.md), below the 60 s the tests' stop() waits.
    watchdog = threading.Timer(50.0, lambda: os._exit(3))
    watchdog.daemon = True
    watchdog.start()
    stop.set()
    th.join(2.0)
    RRN.Shutdown()
    watchdog.cancel()
    return 0


if __name__ == "__main__":
    sys.exit(main())
