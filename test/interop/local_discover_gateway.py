#!/usr/bin/env python3
"""A gateway `discover:` entry over rr+local (docs/discovery.md, docs/gateway-config.md): rr-gateway is
started with an entry selecting experimental.interop_test.Root by NodeName with `transports: [rr+local]`;
then an OFFICIAL service is started with ServerNodeSetup (rr+local and TCP). The gateway must pick it up
from the node directories (no configuration naming it), serve it over rr+tcp to the official client,
list it in GET /api/discovered with its rr+local URL, and drop the device when the service stops (its
entry is closed: no 60 s expiry wait), telling every JSON WebSocket (`device_removed`); the device comes
back when the service starts again. A second entry without a NodeName and with `max: 1` takes one of
two further official services, not both, and the other once the first one stops. Everything runs in
a temporary tree of node directories (the official ROBOTRACONTEUR_*_DIR overrides). Exit 0 when all
passed, 1 on failure, 77 without the venv.

Usage: local_discover_gateway.py --gateway rr-gateway
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import child_procs  # noqa: E402


fail, get_json = child_procs.fail, child_procs.get_json


wait_for = child_procs.wait_for


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gateway", required=True)
    args = ap.parse_args()
    try:
        from RobotRaconteur.Client import RRN
    except ImportError:
        print("SKIP: the official RobotRaconteur package is not installed (./scripts/setup.sh)")
        return 77

    tree = tempfile.mkdtemp(prefix="rr_local_discover_")
    env = child_procs.scratch_rr_env(tree)
    name = "official.gwdiscover.%d" % os.getpid()
    cfg = os.path.join(tree, "gateway.yaml")
    with open(cfg, "w") as f:
        f.write("""\
gateway: {listen: 127.0.0.1, port: 0, node_name: gw.discover.%d}
demo: {enabled: false}
discovery: {announce: false}
discover:
  - type: experimental.interop_test.Root
    nodename: %s
    transports: [rr+local]
    name: "local_{service}"
  - type: experimental.interop_test.Root
    transports: [rr+local]
    max: 1
    name: "one_{service}"
""" % (os.getpid(), name))

    procs = []

    def start(cmd, what):
        err = os.path.join(tree, what + ".stderr")
        with open(err, "wb") as errf:
            p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=errf, stdin=subprocess.DEVNULL, env=env,
                                 preexec_fn=child_procs.die_with_parent)
        procs.append((p, err))
        try:
            return p, child_procs.read_json_line(p, 60, what)
        except child_procs.StepFailed as e:
            fail("%s\n%s" % (e, child_procs.tail(err)))

    try:
        gw, ready = start([args.gateway, "--config", cfg], "gateway")
        port = ready["port"]
        devices = get_json(port, "/api/devices")
        if devices:
            fail("devices before the service started: %r" % devices)

        # Every JSON WebSocket hears of devices that go away (device_removed).
        import websocket  # websocket-client
        ws = websocket.create_connection("ws://127.0.0.1:%d/" % port, subprotocols=["rr-gateway.json.v1"], timeout=60)
        pushes = []

        def read_pushes():
            try:
                while True:
                    pushes.append(json.loads(ws.recv()))
            except Exception:  # closed at the end
                pass

        threading.Thread(target=read_pushes, daemon=True).start()

        def official(node_name, what):
            return start([sys.executable, os.path.join(HERE, "official_service.py"), "--port", "0",
                          "--node-setup", node_name, "--max-lifetime", "120"], what)

        # The official service starts after the gateway.
        t0 = time.monotonic()
        svc, sready = official(name, "official")
        nodeid = sready["nodeid"].strip("{}")

        def device():
            for d in get_json(port, "/api/devices"):
                if d["name"] == "local_interop" and d["state"] == "connected":
                    return d
            return None

        d = wait_for(device, 60, "device local_interop connected")
        print("gateway picked up %s over rr+local in %.1f s: %s" % (name, time.monotonic() - t0, d["url"]), flush=True)
        if d["url"] != "rr+local:///?nodeid=%s&service=interop" % nodeid:
            fail("device URL %r" % d["url"])

        disc = get_json(port, "/api/discovered")
        node = next((n for n in disc["nodes"] if n["nodeid"] == nodeid), None)
        want = "rr+local:///?nodeid=%s&service=RobotRaconteurServiceIndex" % nodeid
        if node is None or want not in node["urls"] or node["nodename"] != name:
            fail("/api/discovered: %r" % disc)
        if not any(s["name"] == "interop" and s["device"] == "local_interop" for s in node["services"] or []):
            fail("/api/discovered services: %r" % node["services"])

        # The official client through the gateway (rr+tcp) to the discovered rr+local device.
        c = RRN.ConnectService("rr+tcp://127.0.0.1:%d/?service=local_interop" % port)
        try:
            if not isinstance(c.base_name, str) or not c.base_name:
                fail("base_name through the gateway: %r" % c.base_name)
            # The interop service accepts only its test values for p_double (-DBL_MAX is one).
            c.p_double = -1.7976931348623157e308
            if not isinstance(c.p_double, float):
                fail("p_double through the gateway: %r" % c.p_double)
        finally:
            RRN.DisconnectService(c)
        print("official client -> gateway (rr+tcp) -> rr+local device: get/set ok", flush=True)

        # The service stops: its entry is closed, the device goes (long before the 60 s expiry).
        t1 = time.monotonic()
        child_procs.stop(svc)
        wait_for(lambda: all(x["name"] != "local_interop" for x in get_json(port, "/api/devices")), 45,
                 "device local_interop removed after the service stopped")
        print("device removed %.1f s after the service stopped" % (time.monotonic() - t1), flush=True)
        wait_for(lambda: any(m.get("kind") == "device_removed" and m["device"]["name"] == "local_interop"
                             for m in pushes), 30, "device_removed for local_interop on the JSON WebSocket")
        print("JSON WebSocket told: device_removed local_interop", flush=True)

        # The service comes back (same NodeName; the official node keeps its NodeID): so does the device.
        svc, sready = official(name, "official-again")
        d = wait_for(device, 60, "device local_interop connected again after the service restarted")
        if d["url"] != "rr+local:///?nodeid=%s&service=interop" % sready["nodeid"].strip("{}"):
            fail("device URL after the restart %r" % d["url"])
        print("device back after the service restarted: %s" % d["url"], flush=True)
        child_procs.stop(svc)

        # max: 1 -> one of two matching services is a device; the other takes its place when it stops.
        def one_devices():
            return [x for x in get_json(port, "/api/devices") if x["name"].startswith("one_")]

        others = {}
        for i in (1, 2):
            p, r = official("%s.other%d" % (name, i), "other%d" % i)
            others[r["nodeid"].strip("{}")] = p
        wait_for(lambda: one_devices() or None, 60, "a one_ device for the max: 1 entry")
        time.sleep(3)  # both nodes are in the node directories by now; the second must not be added
        held = one_devices()
        if len(held) != 1:
            fail("max: 1 entry holds %d devices: %r" % (len(held), held))
        first_id = next((k for k in others if k in held[0]["url"]), None)
        if first_id is None:
            fail("one_ device URL %r names neither service" % held[0]["url"])
        print("max: 1 holds one of two matching services: %s" % held[0]["url"], flush=True)
        child_procs.stop(others.pop(first_id))
        (second_id,) = others
        wait_for(lambda: [x for x in one_devices() if second_id in x["url"] and x["state"] == "connected"] or None, 60,
                 "the max: 1 entry taking the other service after the first stopped")
        if len(one_devices()) != 1:
            fail("max: 1 entry after the switch: %r" % one_devices())
        print("max: 1 took the other service when the first stopped", flush=True)
        ws.close()
        status = child_procs.stop(gw)
        if status != 0:
            fail("rr-gateway exited with %s\n%s" % (status, child_procs.tail(procs[0][1])))
    except SystemExit:
        for p, err in procs:
            print("--- %s (exit %s):\n%s" % (err, p.poll(), child_procs.tail(err, 40)), flush=True)
        raise
    finally:
        for p, _ in procs:
            child_procs.stop(p)
        shutil.rmtree(tree, ignore_errors=True)
    print("PASS", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
