#!/usr/bin/env python3
"""experimental.thenable (members named `then`) served by the official Python library over rr+tcp and
rr+ws on one port, for thenable_test.mjs.

Ready line: {"url": "rr+tcp://127.0.0.1:P/?service=thenable", "ws_url": "rr+ws://…", "port": P}.
Runs until SIGTERM/SIGINT or --max-lifetime seconds.

Usage: then_service.py [--max-lifetime S] [--string-table]
"""

import argparse
import json
import os
import signal
import threading

import RobotRaconteur as RR

RRN = RR.RobotRaconteurNode.s
HERE = os.path.dirname(os.path.abspath(__file__))


class Child:
    def __init__(self):
        self.then = "child then"


class Root:
    def __init__(self):
        self.value = 7
        self._child = Child()

    def then(self, x):
        return x + 1

    def get_child(self):
        return self._child, "experimental.thenable.Child"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--max-lifetime", type=float, default=300)
    ap.add_argument("--string-table", action="store_true", help="leave the library's string table on (TcpTransport's default)")
    args = ap.parse_args()
    stop = threading.Event()
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda *_: stop.set())
    t = RR.TcpTransport()
    t.AcceptWebSockets = True
    t.DisableStringTable = not args.string_table  # as ServerNodeSetup's defaults and official_service.py
    t.StartServer(0, True)
    RRN.RegisterTransport(t)
    RRN.RegisterServiceTypeFromFile(os.path.join(HERE, "experimental.thenable.robdef"))
    RRN.RegisterService("thenable", "experimental.thenable.Root", Root())
    port = t.GetListenPort()
    print(json.dumps({"url": "rr+tcp://127.0.0.1:%d/?service=thenable" % port,
                      "ws_url": "rr+ws://127.0.0.1:%d/?service=thenable" % port, "port": port}), flush=True)
    stop.wait(args.max_lifetime if args.max_lifetime > 0 else None)
    RRN.Shutdown()


if __name__ == "__main__":
    main()
