#!/usr/bin/env python3
"""A device killed and restarted while OFFICIAL clients are connected through the gateway (issue 4).

rr-demo-devices (the device) and rr-gateway run as separate processes; official Python clients connect
to the gateway over rr+tcp and rr+ws and use every kind of member that keeps state across requests
(a property, a function, an event subscription, a wire connection, a callback, an objref). Then the device is
killed with SIGKILL:
  - the clients' requests fail with an RR error (not a hang), their sessions to the gateway stay up,
    /readyz says 503 and the JSON API names the device's state;
and restarted on the same port, with nothing else restarted:
  - the same client objects work again (the fresh device's DistanceTraveled is 0 again, which shows it
    is the new process); the event subscription, the wire connection and the callback set before the
    crash deliver the new device's Bump, packets and play_callback call; the objref taken before the
    crash captures frames again.

Usage: restart_test.py --gateway PATH --devices PATH
Prints a JSON summary; exit status 0 only if every check passed.
"""
import argparse
import json
import os
import sys
import tempfile
import time

import RobotRaconteur as RR

import gwproc
import official_transport  # noqa: E402  (the official client's transport, its connect timeout)
from gwproc import expect, wait_for

RRN = RR.RobotRaconteurNode.s
DRIVE_STRAIGHT = 32767


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--devices", required=True)
    a = ap.parse_args()
    checks = gwproc.Checks()
    # A port below the ephemeral range: while the device is down, no other process of a parallel test
    # run can be handed it, so the restart can take it again.
    dev_port = gwproc.fixed_port()
    dev = gwproc.start_devices(a.devices, port=dev_port, play_period=0)
    cfg = tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False)
    cfg.write("demo:\n  enabled: false\ndevices:\n"
              "  - name: create\n    url: rr+tcp://127.0.0.1:%d/?service=create\n    backoff_max_ms: 1000\n"
              "  - name: webcam\n    url: rr+tcp://127.0.0.1:%d/?service=webcam\n    backoff_max_ms: 1000\n"
              % (dev_port, dev_port))
    cfg.close()
    gw = None
    try:
        gw = gwproc.start_gateway(a.gateway, ["--config", cfg.name])
        port = gw.port
        gwproc.wait_ready(port)
        RRN.RegisterTransport(official_transport.client_tcp_transport(RR))
        RRN.RequestTimeout = 10
        c_tcp = RRN.ConnectService("rr+tcp://127.0.0.1:%d/?service=create" % port)
        c_ws = RRN.ConnectService("rr+ws://127.0.0.1:%d/?service=create" % port)
        w = RRN.ConnectService("rr+tcp://127.0.0.1:%d/?service=webcam" % port)
        bumps, packets = [], []
        c_ws.Bump += lambda: bumps.append(time.monotonic())
        conn = c_tcp.packets.Connect()
        conn.WireValueChanged += lambda c, v, ts: packets.append(v)
        cam = w.get_Webcams(0)
        plays = []

        def play(distance, angle):
            plays.append(distance)
            return [60, 16]

        c_tcp.play_callback.Function = play

        def before():
            c_tcp.Drive(200, DRIVE_STRAIGHT)
            wait_for(lambda: c_ws.DistanceTraveled > 50, 5, "distance grows while driving")
            c_tcp.Drive(0, DRIVE_STRAIGHT)
            c_tcp.StartStreaming()
            wait_for(lambda: len(packets) >= 3, 5, "packets before the crash")
            expect(len(cam.CaptureFrame().data) == 320 * 240 * 3, "frame before the crash")

        checks.run("before: property, function, wire, objref through the gateway", before)

        dev.kill()
        errors = {}

        def fails():
            for name, fn in (("tcp property", lambda: c_tcp.DistanceTraveled),
                             ("ws function", lambda: c_ws.Drive(0, DRIVE_STRAIGHT)),
                             ("objref function", lambda: cam.CaptureFrame())):
                def failed(fn=fn, name=name):
                    try:
                        fn()
                        return False
                    except RR.RobotRaconteurException as e:
                        errors[name] = "%s: %s" % (e.errorname, e.message)
                        return True
                wait_for(failed, 10, "an RR error for the %s while the device is down" % name)
            print("errors while down: %s" % json.dumps(errors), file=sys.stderr)
            for name, msg in errors.items():
                expect("create" in msg or "webcam" in msg or "device" in msg.lower(),
                       "the %s error names the device: %r" % (name, msg))

        checks.run("device killed: requests fail with an RR error naming the device", fails)

        def state():
            status, body = gwproc.http_status("http://127.0.0.1:%d/readyz" % port)
            expect(status == 503 and "create" in body, "/readyz %d %r" % (status, body))
            status, body = gwproc.http_status("http://127.0.0.1:%d/api/devices" % port)
            states = {d["name"]: d["state"] for d in json.loads(body)}
            expect(states["create"] != "connected", "create state %r" % states)

        checks.run("device down: /readyz 503, JSON API state not connected", state)

        dev = gwproc.start_devices(a.devices, port=dev_port, play_period=0)

        def back():
            gwproc.wait_ready(port, 20)
            # The same client objects; the fresh device starts at 0 mm.
            wait_for(lambda: try_get(lambda: c_tcp.DistanceTraveled) == 0, 10, "the new device's DistanceTraveled")
            expect(c_ws.Bumpers == 0, "Bumpers over rr+ws")
            expect(len(cam.CaptureFrame().data) == 320 * 240 * 3, "frame from the objref taken before the crash")

        checks.run("device restarted: the same client objects work again", back)

        def subscriptions():
            n = len(packets)
            c_ws.Drive(500, DRIVE_STRAIGHT)  # the wall is 1335 mm away: a Bump within ~3 s
            # The device asks its streaming client what to play at the bump. All clients share the
            # gateway's one session to the device, and RR says nothing when a client sets a callback,
            # so the gateway routes a device's callback to the client that made the last request:
            # StartStreaming on c_tcp comes after the Drive on c_ws.
            c_tcp.StartStreaming()
            wait_for(lambda: len(packets) >= n + 3, 10, "packets on the wire connection made before the crash")
            wait_for(lambda: bumps, 10, "Bump on the event subscription made before the crash")
            wait_for(lambda: any(d > 1000 for d in plays), 10, "play_callback at the wall on the callback set before")
            c_tcp.StopStreaming()

        checks.run("after the restart: wire, event and callback set before the crash deliver again", subscriptions)
        checks.run("gateway still running", lambda: expect(gw.alive(), "gateway exited"))
    finally:
        try:
            RRN.Shutdown()
        finally:
            status = gw.stop() if gw else None
            dev.stop()
            os.unlink(cfg.name)
    checks.run("gateway exit status 0 on SIGTERM", lambda: expect(status == 0, "exit status %r" % status))
    return checks.exit_code()


def try_get(fn):
    try:
        return fn()
    except RR.RobotRaconteurException:
        return None


if __name__ == "__main__":
    sys.exit(main())
