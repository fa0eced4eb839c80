#!/usr/bin/env python3
"""The official Robot Raconteur library's side of the discovery tests (discovery_netns.py).

    discovery_official.py serve --name NODENAME --port N
        ServerNodeSetup(NODENAME, N) (official defaults: TCP server, IPv6 link-local announce and listen)
        serving "thing" (experimental.discovery_test.Thing, implements Base, attribute tags="fox,arm").
        Prints {"port": N, "nodeid": "..."} when ready; runs until SIGTERM. --ipv4-only: announce and
        listen on IPv4 broadcast only (IPNodeDiscoveryFlags_IPV4_BROADCAST), not IPv6.
    discovery_official.py find --type T --name NODENAME --wait S
        ClientNodeSetup(), waits S seconds for announces, then RRN.AsyncFindServiceByType(T, ["rr+tcp"])
        and RRN.FindNodeByName(NODENAME, ["rr+tcp"]); prints {"services": [...], "nodes": [...]}. The
        search's timeout and the transport's connect timeout are FIND_TIMEOUT_S and 60 s, not the
        official 5 s: a node's services are read by connecting to its service index, which a loaded
        machine did not finish in 5 s (the node was listed, its services not).
        --ipv4-only: listens on IPv4 broadcast only. --also-name NAME2: FindNodeByName(NAME2) too
        ("nodes2"). --call: connects to the first service found on node NODENAME with the URLs the
        search gave and, for an experimental.create.Create, reads DistanceTraveled and calls Drive(0, 0)
        ("call": {"urls", "DistanceTraveled"} or {"error"}).
    discovery_official.py call --url URL
        ClientNodeSetup() (connect timeout 60 s), ConnectService(URL) of an experimental.create.Create, reads DistanceTraveled and
        calls Drive(0, 0); prints {"DistanceTraveled": N} or {"error": "..."}.
    discovery_official.py hostile --iface IF --flood N
        Sends hostile datagrams to FF02::BA86%IF port 48653: truncated, oversized, a bad UUID, a lying
        URL, a global address, then N announces of distinct NodeIDs. Prints {"sent": count}.
"""

import argparse
import json
import os
import signal
import socket
import sys
import threading
import time
import uuid

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import official_transport  # noqa: E402  (the test's connect timeout)

# AsyncFindServiceByType's timeout: a quarter of it listens for nodes, then each node's service index
# is read within it. A bound on a hang; the search ends as soon as every node answered.
FIND_TIMEOUT_S = 30

ROBDEF = """service experimental.discovery_test

object Base
    property int32 x
end

object Thing
    implements Base
    property int32 x
    property string label
end
"""


class Thing:
    def __init__(self):
        self.x = 7
        self.label = "official thing"


def ipv4_only_flags(flags):
    """A node setup's `flags` with discovery (announce and listening) on IPv4 broadcast instead of IPv6."""
    import RobotRaconteur as RR
    return ((flags & ~RR.RobotRaconteurNodeSetupFlags_TCP_TRANSPORT_IPV6_DISCOVERY)
            | RR.RobotRaconteurNodeSetupFlags_TCP_TRANSPORT_IPV4_DISCOVERY)


def serve(args):
    import RobotRaconteur as RR
    RRN = RR.RobotRaconteurNode.s
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *a: stop.set())
    signal.signal(signal.SIGINT, lambda *a: stop.set())
    if args.ipv4_only:
        # Announce and listen on IPv4 broadcast only (the official IPV4_BROADCAST flag), chosen by the node
        # setup's flags: turning the IPv6 default off after the start (DisableNodeDiscoveryListening) threw
        # "shutdown: Transport endpoint is not connected" now and then in the official library.
        node_setup = RR.RobotRaconteurNodeSetup(args.name, args.port, ipv4_only_flags(RR.RobotRaconteurNodeSetupFlags_SERVER_DEFAULT))
    else:
        node_setup = RR.ServerNodeSetup(args.name, args.port)
    with node_setup as setup:
        if args.ipv4_only:
            # Announce every second (the default is 55 s): a listener that sends no IPv4 requests, such as
            # rr discover with default settings, hears it within its timeout.
            setup.tcp_transport.NodeAnnouncePeriod = 1000
        RRN.RegisterServiceType(ROBDEF)
        ctx = RRN.RegisterService("thing", "experimental.discovery_test.Thing", Thing())
        ctx.SetServiceAttributes({"tags": RR.VarValue("fox,arm", "string")})
        print(json.dumps({"port": args.port, "nodeid": str(RRN.NodeID)}), flush=True)
        while not stop.wait(0.2):
            pass


def find(args):
    import RobotRaconteur as RR
    RRN = RR.RobotRaconteurNode.s
    if args.ipv4_only:  # listen on IPv4 broadcast only, by the setup's flags (see serve)
        node_setup = RR.RobotRaconteurNodeSetup(None, 0, ipv4_only_flags(RR.RobotRaconteurNodeSetupFlags_CLIENT_DEFAULT))
    else:
        node_setup = RR.ClientNodeSetup()
    with node_setup as setup:
        official_transport.set_connect_timeout(setup.tcp_transport)
        time.sleep(args.wait)
        found = []
        done = threading.Event()

        def handler(result):
            found.extend(result or [])
            done.set()
        RRN.AsyncFindServiceByType(args.type, ["rr+tcp"], handler, FIND_TIMEOUT_S)
        if not done.wait(FIND_TIMEOUT_S * 2):
            raise RuntimeError("AsyncFindServiceByType did not return within %d s" % (FIND_TIMEOUT_S * 2))
        services = []
        for s in found:
            services.append({"name": s.Name, "nodename": s.NodeName, "nodeid": str(s.NodeID),
                             "root_object_type": s.RootObjectType,
                             "implements": list(s.RootObjectImplements), "urls": list(s.ConnectionURL)})
        def by_name(name):
            return [{"nodename": n.NodeName, "nodeid": str(n.NodeID), "urls": list(n.ConnectionURL)}
                    for n in RRN.FindNodeByName(name, ["rr+tcp"])]
        out = {"services": services, "nodes": by_name(args.name)}
        if args.also_name:
            out["nodes2"] = by_name(args.also_name)
        if args.call:
            mine = [s for s in services if s["nodename"] == args.name]
            if not mine:
                out["call"] = {"error": "no service of node %s found" % args.name}
            else:
                try:
                    c = RRN.ConnectService(mine[0]["urls"])
                    try:
                        distance = c.DistanceTraveled
                        c.Drive(0, 0)
                        out["call"] = {"urls": mine[0]["urls"], "DistanceTraveled": int(distance)}
                    finally:
                        RRN.DisconnectService(c)
                except Exception as e:  # noqa: BLE001 (reported to the orchestrator)
                    out["call"] = {"error": "%s: %s" % (type(e).__name__, e)}
        print(json.dumps(out), flush=True)


def call(args):
    import RobotRaconteur as RR
    RRN = RR.RobotRaconteurNode.s
    with RR.ClientNodeSetup() as setup:
        official_transport.set_connect_timeout(setup.tcp_transport)
        try:
            c = RRN.ConnectService(args.url)
            try:
                distance = c.DistanceTraveled
                c.Drive(0, 0)
                out = {"DistanceTraveled": int(distance)}
            finally:
                RRN.DisconnectService(c)
        except Exception as e:  # noqa: BLE001 (reported to the orchestrator)
            out = {"error": "%s: %s" % (type(e).__name__, e)}
        print(json.dumps(out), flush=True)


def hostile(args):
    s = socket.socket(socket.AF_INET6, socket.SOCK_DGRAM)
    ifindex = socket.if_nametoindex(args.iface)
    s.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_MULTICAST_IF, ifindex)
    dest = ("ff02::ba86", 48653, 0, ifindex)
    magic = "Robot Raconteur Node Discovery Packet\n"
    nid = str(uuid.uuid4())
    url = "rr+tcp://[fe80::99]:1/?nodeid=%s&service=RobotRaconteurServiceIndex" % nid
    packets = [
        magic + "{%s}" % nid,                                                   # truncated
        magic + "{%s}\n" % nid + url + "\n" + "X" * 9000,                       # oversized
        magic + "{not-a-uuid}\n" + url + "\n",                                   # bad UUID
        magic + "{%s}\n" % uuid.uuid4() + url + "\n",                            # lying URL (another NodeID)
        magic + "{%s}\n" % nid + url.replace("fe80::99", "2001:db8::1") + "\n",  # global address
        magic + "{%s}\n" % nid + url.replace("[fe80::99]", "evil.example.org") + "\n",  # not an IP
    ]
    sent = 0
    for p in packets:
        s.sendto(p.encode(), dest)
        sent += 1
    for i in range(args.flood):
        n = str(uuid.uuid4())
        p = magic + "{%s},flood%d\nrr+tcp://[fe80::99]:1/?nodeid=%s&service=RobotRaconteurServiceIndex\n" % (n, i, n)
        s.sendto(p.encode(), dest)
        sent += 1
        if i % 100 == 99:
            time.sleep(0.01)  # let the receiver keep up; UDP would drop the rest
    print(json.dumps({"sent": sent}), flush=True)


def main():
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="cmd", required=True)
    a = sub.add_parser("serve")
    a.add_argument("--name", required=True)
    a.add_argument("--port", type=int, default=29321)
    a.add_argument("--ipv4-only", action="store_true")
    a = sub.add_parser("find")
    a.add_argument("--type", required=True)
    a.add_argument("--name", required=True)
    a.add_argument("--wait", type=float, default=5)
    a.add_argument("--ipv4-only", action="store_true")
    a.add_argument("--also-name")
    a.add_argument("--call", action="store_true")
    a = sub.add_parser("call")
    a.add_argument("--url", required=True)
    a = sub.add_parser("hostile")
    a.add_argument("--iface", required=True)
    a.add_argument("--flood", type=int, default=2000)
    args = ap.parse_args()
    {"serve": serve, "find": find, "call": call, "hostile": hostile}[args.cmd](args)


if __name__ == "__main__":
    sys.exit(main())
