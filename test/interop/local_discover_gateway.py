#!/usr/bin/env python3
"""A gateway `discover:` entry over rr+local (docs/discovery.md, docs/gateway-config.md): rr-gateway is
started with an entry selecting experimental.interop_test.Root by NodeName with `transports: [rr+local]`;
then an OFFICIAL service is started with ServerNodeSetup (rr+local and TCP). The gateway must pick it up
from the node directories (no configuration naming it), serve it over rr+tcp to the official client,
list it in GET /api/discovered with its rr+local URL, and drop the device when the service stops (its
entry is closed: no 60 s expiry wait). Everything runs in a temporary tree of node directories (the
official ROBOTRACONTEUR_*_DIR overrides). Exit 0 when all passed, 1 on failure, 77 without the venv.

Usage: local_discover_gateway.py --gateway rr-gateway
"""

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
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

        # The official service starts after the gateway.
        t0 = time.monotonic()
        svc, sready = start([sys.executable, os.path.join(HERE, "official_service.py"), "--port", "0",
                             "--node-setup", name, "--max-lifetime", "120"], "official")
        nodeid = sready["nodeid"].strip("{}")

        def device():
            for d in get_json(port, "/api/devices"):
                if d["name"] == "local_interop" and d["state"] == "connected":
                    return d
            return None

        d = wait_for(device, 30, "device local_interop connected")
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
        wait_for(lambda: all(x["name"] != "local_interop" for x in get_json(port, "/api/devices")), 20,
                 "device local_interop removed after the service stopped")
        print("device removed %.1f s after the service stopped" % (time.monotonic() - t1), flush=True)
        status = child_procs.stop(gw)
        if status != 0:
            fail("rr-gateway exited with %s\n%s" % (status, child_procs.tail(procs[0][1])))
    finally:
        for p, _ in procs:
            child_procs.stop(p)
        shutil.rmtree(tree, ignore_errors=True)
    print("PASS", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
