#!/usr/bin/env python3
"""The gateway with rr+usb devices, through the real libusb against the emulated USB device (issue 12's
done-when): rr_usb_fixture (under umockdev-wrapper) plugs in an emulated board serving the demo devices
and example.usbtest.Bench, and starts our gateway from a configuration with

  * devices `create` (by NodeName) and `webcam` (by NodeID) at rr+usb URLs, and
  * a `discover:` entry selecting example.usbtest.Bench over rr+usb.

Then the OFFICIAL Python client, over rr+tcp to the gateway, calls every member of the demo devices
(demo_official_client.py) and the discovered device's functions; GET /api/discovered lists the USB node
with its rr+usb URL. Exit 0 when all passed, 1 on a failed check, 77 (skipped) when umockdev or the venv
is missing.

Usage: usb_gateway_test.py --fixture rr_usb_fixture --wrapper run_under_umockdev.sh
"""

import argparse
import atexit
import os
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
INTEROP = os.path.join(HERE, "..", "interop")
sys.path.insert(0, INTEROP)
import child_procs  # noqa: E402

CONFIG = """\
gateway:
  listen: 127.0.0.1
  port: 0
  local: false
  node_name: usb.gateway.test
demo:
  enabled: false
discovery:
  announce: false
devices:
  - name: create
    url: "rr+usb:///?nodename={name}&service=create"
  - name: webcam
    url: "rr+usb:///?nodeid={nodeid}&service=webcam"
discover:
  - type: example.usbtest.Bench
    transports: [rr+usb]
    name: "usb_{{service}}"
"""


fail, get_json = child_procs.fail, child_procs.get_json


def wait_for(pred, timeout, what):
    return child_procs.wait_for(pred, timeout, what, interval=0.2)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--fixture", required=True)
    ap.add_argument("--wrapper", required=True)
    args = ap.parse_args()
    try:
        import RobotRaconteur as RR  # noqa: F401
    except ImportError:
        print("SKIP: the official RobotRaconteur package is not installed (./scripts/setup.sh)")
        return 77

    tmp = tempfile.mkdtemp(prefix="rr_usb_gw_")
    atexit.register(shutil.rmtree, tmp, True)
    # The device's identity is fixed by the fixture (test/usb/usb_world.hpp).
    nodeid, name = "5a3c9d2e-7b41-4c8a-9e0f-31d2c4b5a6e7", "usb_demo"
    cfg = os.path.join(tmp, "gateway.yaml")
    with open(cfg, "w") as f:
        f.write(CONFIG.format(name=name, nodeid=nodeid))
    err_path = os.path.join(tmp, "fixture.stderr")
    with open(err_path, "wb") as errf:
        proc = subprocess.Popen([args.wrapper, args.fixture, "gateway", cfg], stdout=subprocess.PIPE, stderr=errf,
                                stdin=subprocess.PIPE, preexec_fn=child_procs.die_with_parent)
    status = None
    try:
        try:
            ready = child_procs.read_json_line(proc, 60, "rr_usb_fixture")
        except child_procs.StepFailed as e:
            if proc.poll() == 77:
                print("SKIP: " + child_procs.tail(err_path, 3) + " (rr_usb_fixture exited 77)")
                return 77
            fail("%s\n%s" % (e, child_procs.tail(err_path)))
        port = ready["port"]
        base = "rr+tcp://127.0.0.1:%d/?service=" % port

        # The configured rr+usb devices and the one discover: found come up.
        def all_connected():
            devs = {d["name"]: d for d in get_json(port, "/api/devices")}
            want = ("create", "webcam", "usb_usbtest")
            return devs if all(devs.get(n, {}).get("state") == "connected" for n in want) else None

        devs = wait_for(all_connected, 60, "create, webcam and usb_usbtest connected")
        if devs["usb_usbtest"]["url"] != "rr+usb:///?nodeid=%s&service=usbtest" % nodeid:
            fail("discovered device URL %r" % devs["usb_usbtest"]["url"])
        print("devices connected over rr+usb: %s" % sorted(devs), flush=True)

        # /api/discovered lists the USB node with its rr+usb URL and services.
        disc = get_json(port, "/api/discovered")
        node = next((n for n in disc["nodes"] if n["nodeid"] == nodeid), None)
        if node is None:
            fail("/api/discovered has no node %s: %r" % (nodeid, disc))
        want_url = "rr+usb:///?nodeid=%s&service=RobotRaconteurServiceIndex" % nodeid
        if want_url not in node["urls"] or node["source"] != "usb" or node["nodename"] != name:
            fail("/api/discovered node: %r" % node)
        services = {s["name"]: s for s in node["services"] or []}
        if services.get("usbtest", {}).get("device") != "usb_usbtest" or "create" not in services:
            fail("/api/discovered services: %r" % node["services"])
        print("/api/discovered: %s (%s) at %s" % (node["nodename"], node["source"], want_url), flush=True)

        # What a browser uses: the JSON API (REST) reads properties of devices behind rr+usb.
        name_prop = get_json(port, "/api/devices/webcam/properties/Name?object=Webcams[1]")
        if name_prop != {"value": "Right"}:
            fail("REST webcam Webcams[1].Name over rr+usb: %r" % name_prop)
        dist = get_json(port, "/api/devices/create/properties/DistanceTraveled")
        if not isinstance(dist.get("value"), int):
            fail("REST create DistanceTraveled over rr+usb: %r" % dist)
        print("JSON API -> gateway -> rr+usb: webcam Webcams[1].Name, create DistanceTraveled ok", flush=True)

        # The dashboard's path: the JSON WebSocket, a call and a wire subscription on a device behind rr+usb.
        import json
        import websocket  # websocket-client
        ws = websocket.create_connection("ws://127.0.0.1:%d/" % port, subprotocols=["rr-gateway.json.v1"], timeout=20)
        try:
            def ask(msg):
                ws.send(json.dumps(msg))
                while True:
                    r = json.loads(ws.recv())
                    if r.get("id") == msg["id"]:
                        return r
            r = ask({"id": 1, "op": "get", "device": "webcam", "member": "Name", "object": "Webcams[0]"})
            if r.get("result", {}).get("value") != "Left":
                fail("JSON WebSocket get webcam Webcams[0].Name over rr+usb: %r" % r)
            r = ask({"id": 2, "op": "call", "device": "create", "member": "Drive", "args": [100, 32767]})
            if "result" not in r:
                fail("JSON WebSocket call create.Drive over rr+usb: %r" % r)
            r = ask({"id": 3, "op": "subscribe", "device": "create", "member": "packets"})
            if "result" not in r:
                fail("JSON WebSocket subscribe create.packets over rr+usb: %r" % r)
            sub = r["result"].get("subscription")
            t_end = time.monotonic() + 15
            got = None
            while time.monotonic() < t_end and got is None:
                m = json.loads(ws.recv())
                if m.get("subscription") == sub and m.get("kind") == "wire" and "value" in m:
                    got = m
            if got is None:
                fail("no wire value from create.packets over rr+usb within 15 s")
        finally:
            ws.close()
        print("JSON WebSocket -> gateway -> rr+usb: get, call, wire subscription ok", flush=True)

        # The official client through the gateway (rr+tcp) to the discovered USB device.
        from RobotRaconteur.Client import RRN
        c = RRN.ConnectService(base + "usb_usbtest")
        try:
            c.nop()
            data = bytes(range(256)) * 64  # 16 KiB: many 512-byte bulk packets each way
            import numpy as np
            got = c.echo(np.frombuffer(data, dtype=np.uint8))
            if bytes(bytearray(got)) != data:
                fail("echo through the gateway returned other bytes")
            gen = c.count(5)
            items = []
            try:
                while True:
                    items.append(gen.Next())
            except RR.StopIterationException:
                pass
            if items != [0, 1, 2, 3, 4]:
                fail("count(5) gave %r" % items)
        finally:
            RRN.DisconnectService(c)
        print("official client -> gateway -> usb_usbtest: nop, echo (16 KiB), count generator ok", flush=True)

        # Every member of the demo devices, with the official client, through the gateway to rr+usb.
        r = subprocess.run([sys.executable, os.path.join(INTEROP, "demo_official_client.py"), "--create", base + "create",
                            "--webcam", base + "webcam", "--timeout", "150"], timeout=200)
        if r.returncode != 0:
            fail("demo_official_client.py through the gateway to rr+usb: status %d" % r.returncode)

        # Unplug: the configured rr+usb devices go down and say why, requests to them fail with an error
        # naming the device; re-plug (a new bus address): they come back by themselves and work again.
        def command(cmd, answer):
            proc.stdin.write((cmd + "\n").encode())
            proc.stdin.flush()
            line = proc.stdout.readline().decode().strip()
            if line != answer:
                fail("fixture answered %r to %s" % (line, cmd))

        prop = "/api/devices/create/properties/DistanceTraveled"
        command("unplug", "unplugged")

        def down():
            devs = {d["name"]: d for d in get_json(port, "/api/devices")}
            return devs if all(devs[n]["state"] != "connected" for n in ("create", "webcam")) else None

        devs = wait_for(down, 15, "create and webcam not connected after the unplug")
        print("after the unplug: create %s (%s)" % (devs["create"]["state"], devs["create"]["reason"]), flush=True)
        import urllib.error
        import urllib.request
        try:
            urllib.request.urlopen("http://127.0.0.1:%d%s" % (port, prop), timeout=10)
            fail("GET %s answered while the device was unplugged" % prop)
        except urllib.error.HTTPError as e:
            body = e.read().decode()
            if "create" not in body:
                fail("GET %s while unplugged: %d %s (does not name the device)" % (prop, e.code, body))
        command("plug", "plugged")
        wait_for(all_connected, 60, "create, webcam and usb_usbtest connected again after the re-plug")
        if not isinstance(get_json(port, prop).get("value"), int):
            fail("GET %s after the re-plug" % prop)
        print("unplug: devices down with a reason, requests refused naming the device; re-plug: connected again",
              flush=True)
    finally:
        status = child_procs.stop_by_stdin(proc)
    if status != 0:
        fail("rr_usb_fixture exited with %s\n%s" % (status, child_procs.tail(err_path)))
    print("PASS", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
