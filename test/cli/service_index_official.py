#!/usr/bin/env python3
"""The official Python client against OUR node's built-in RobotRaconteurServiceIndex
(server/node/service_index.hpp, wire.md §11.2): starts rr_interop_service, connects to
`service=RobotRaconteurServiceIndex` as discovery's interrogation does, calls GetLocalNodeServices(),
checks every ServiceInfo, then follows the reported ConnectionURL to the interop service.

Exit status: 0 = all checks passed, 1 = a check failed.

Usage: service_index_official.py --service PATH/rr_interop_service
"""

import argparse
import json
import re
import signal
import subprocess
import sys

import RobotRaconteur as RR

RRN = RR.RobotRaconteurNode.s

failures = []


def check(cond, what, detail=""):
    if not cond:
        failures.append(what)
        print(f"FAIL: {what}" + (f"\n      {detail}" if detail else ""), flush=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--service", required=True)
    args = ap.parse_args()

    svc = subprocess.Popen([args.service, "--port", "0", "--max-lifetime", "120", "--websocket"], stdout=subprocess.PIPE,
                           text=True)
    try:
        ready = json.loads(svc.stdout.readline())
        port, nodeid = ready["port"], ready["nodeid"].strip("{}")
        t = RR.TcpTransport()
        RRN.RegisterTransport(t)
        try:
            index_url = f"rr+tcp://127.0.0.1:{port}/?service=RobotRaconteurServiceIndex"
            c = RRN.ConnectService(index_url)
            check(RRN.GetObjectType(c) == "RobotRaconteurServiceIndex.ServiceIndex", "index root type",
                  RRN.GetObjectType(c))
            services = c.GetLocalNodeServices()
            check(sorted(services.keys()) == [0, 1], "two services: the index and interop", repr(services))
            by_name = {s.Name: s for s in services.values()}
            check(set(by_name) == {"RobotRaconteurServiceIndex", "interop"}, "service names", repr(list(by_name)))
            info = by_name.get("interop")
            if info is not None:
                check(info.RootObjectType == "experimental.interop_test.Root", "interop root type", info.RootObjectType)
                check(list(info.RootObjectImplements.values()) == ["experimental.interop_test.Base"],
                      "interop implements Base", repr(info.RootObjectImplements))
                urls = dict(info.ConnectionURL)
                want = f"rr+tcp://127.0.0.1:{port}/?nodeid={nodeid}&service=interop"
                check(urls == {1: want}, "ConnectionURL {1: url with nodeid}", f"{urls!r} != {want!r}")
                check(isinstance(info.Attributes, dict), "Attributes is a map", repr(info.Attributes))
                # the URL the index gave leads to the service
                if urls.get(1):
                    c2 = RRN.ConnectService(urls[1])
                    check(c2.add(2, 3) == 5, "service reached through the reported URL")
                    RRN.DisconnectService(c2)
            check(len(c.GetRoutedNodes()) == 0, "GetRoutedNodes is empty")
            RRN.DisconnectService(c)

            # Over rr+ws on the same port: the listener's address is reported (the WebSocket stream
            # does not expose its socket), which reaches the same node.
            ws_index = ready["ws_url"].replace("service=interop", "service=RobotRaconteurServiceIndex")
            w = RRN.ConnectService(ws_index)
            names = {s.Name: dict(s.ConnectionURL) for s in w.GetLocalNodeServices().values()}
            check(names.get("interop") == {1: f"rr+tcp://127.0.0.1:{port}/?nodeid={nodeid}&service=interop"},
                  "index over rr+ws reports the TCP listener URL", repr(names))
            RRN.DisconnectService(w)
            check(re.fullmatch(r"[0-9a-f-]{36}", nodeid) is not None, "nodeid form", nodeid)

            # An unknown service: the official client gets its ServiceNotFoundException (our node sends
            # CORE's wire name) and the message names the service (issue 15).
            try:
                RRN.ConnectService(f"rr+tcp://127.0.0.1:{port}/?nodeid={nodeid}&service=nosuch")
                check(False, "connecting to an unknown service fails")
            except RR.ServiceNotFoundException as e:
                check('"nosuch"' in str(e), "ServiceNotFoundException names the service", str(e))
            except Exception as e:  # noqa: BLE001 (any other type is the failure to report)
                check(False, "unknown service: ServiceNotFoundException", f"{type(e).__name__}: {e}")
        finally:
            RRN.Shutdown()
    finally:
        svc.send_signal(signal.SIGTERM)
        svc.wait(20)
    print(json.dumps({"failures": len(failures)}))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
