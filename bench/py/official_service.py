#!/usr/bin/env python3
"""experimental.bench served by the official Robot Raconteur library (the reference rows).

Same members and behaviour as bench/bench_service.cpp. Prints one JSON line when ready
({"url", "port", "pid", "ws_url"?}) and runs until SIGTERM / SIGINT.

Usage: official_service.py [--port N] [--websocket] [--memory-mib M]
"""
import argparse
import json
import os
import signal
import sys
import threading
import time

import numpy as np
import RobotRaconteur as RR

RRN = RR.RobotRaconteurNode.s
ROBDEF = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "experimental.bench.robdef")


class BenchImpl:
    def __init__(self, memory_doubles):
        self.Value = 0.0
        self.Buffer = RR.ArrayMemory(np.zeros(memory_doubles, dtype=np.float64))
        self._ticks = None
        self._packets = None
        self._stop = threading.Event()
        self._senders = []

    def Nop(self):
        pass

    def Echo(self, d):
        return d

    # Ticks: a broadcaster holds the newest value for every connection and for PeekInValue.
    @property
    def Ticks(self):
        return self._ticks.Wire

    @Ticks.setter
    def Ticks(self, wire):
        self._ticks = RR.WireBroadcaster(wire)
        self._ticks.OutValue = np.array([0.0, -1.0])

    def StartTicks(self, rate_hz, count, size):
        t = threading.Thread(target=self._send_ticks, args=(rate_hz, count, max(2, size)), daemon=True)
        self._senders.append(t)
        t.start()

    def _send_ticks(self, rate_hz, count, size):
        start = time.monotonic()
        v = np.zeros(size)
        for i in range(count):
            if self._stop.is_set():
                return
            if rate_hz > 0:
                delay = start + i / rate_hz - time.monotonic()
                if delay > 0:
                    time.sleep(delay)
            v[0] = time.time() * 1e6
            v[1] = i
            self._ticks.OutValue = v.copy()

    # Packets: received and dropped; the library acknowledges packets that ask for it.
    @property
    def Packets(self):
        return self._packets

    @Packets.setter
    def Packets(self, pipe):
        self._packets = pipe
        pipe.PipeConnectCallback = self._pipe_connected

    def _pipe_connected(self, ep):
        ep.PacketReceivedEvent += self._drain

    @staticmethod
    def _drain(ep):
        while ep.Available > 0:
            ep.ReceivePacket()


def forget_local_name(name, nodeid):
    """Removes the NodeID cache and entry files a named node leaves in the node directories."""
    import glob
    d = RRN.GetNodeDirectories()
    run, config, state = d.user_run_dir.string(), d.user_config_dir.string(), d.user_state_dir.string()
    paths = glob.glob(os.path.join(run, "transport", "local", "by-nodename", name + ".*"))
    paths += glob.glob(os.path.join(run, "transport", "local", "by-nodeid", nodeid.strip("{}") + ".*"))
    paths += [os.path.join(run, "nodeids", name + ".pid"), os.path.join(config, "nodeids", name),
              os.path.join(state, "nodeids", name)]
    for p in paths:
        try:
            os.unlink(p)
        except OSError:
            pass


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--port", type=int, default=0)
    ap.add_argument("--websocket", action="store_true")
    ap.add_argument("--memory-mib", type=float, default=10)
    ap.add_argument("--local", action="store_true",
                    help="also serve rr+local under a NodeName of this process (what it leaves in the node "
                         "directories is removed at exit)")
    args = ap.parse_args(argv)

    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *a: stop.set())
    signal.signal(signal.SIGINT, lambda *a: stop.set())

    local_name = "bench.official.%d" % os.getpid()
    if args.local:
        # StartServerAsNodeID fails in the official library ("open: Already open"); by NodeName it works.
        lt = RR.LocalTransport()
        lt.StartServerAsNodeName(local_name)
        RRN.RegisterTransport(lt)
    else:
        RRN.SetNodeName("bench_official_service")
    t = RR.TcpTransport()
    t.AcceptWebSockets = args.websocket
    t.StartServer(args.port, True)
    RRN.RegisterTransport(t)
    port = t.GetListenPort()
    RRN.RegisterServiceTypeFromFile(ROBDEF)
    impl = BenchImpl(int(args.memory_mib * 1024 * 1024 / 8))
    RRN.RegisterService("bench", "experimental.bench.Bench", impl)

    ready = {"url": "rr+tcp://127.0.0.1:%d/?service=bench" % port, "port": port, "pid": os.getpid()}
    if args.websocket:
        ready["ws_url"] = "rr+ws://127.0.0.1:%d/?service=bench" % port
    if args.local:
        ready["local_url"] = "rr+local:///?nodename=%s&service=bench" % local_name
    print(json.dumps(ready), flush=True)
    while not stop.wait(0.2):
        pass
    impl._stop.set()
    if args.local:
        forget_local_name(local_name, str(RRN.NodeID))
    watchdog = threading.Timer(10.0, lambda: os._exit(3))
    watchdog.daemon = True
    watchdog.start()
    RRN.Shutdown()
    watchdog.cancel()
    return 0


if __name__ == "__main__":
    sys.exit(main())
