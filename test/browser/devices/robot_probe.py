#!/usr/bin/env python3
"""The official Python client watching a robot for the jog tests (std_robot_jog.test.mjs): connects
straight to the robot (not through the gateway), follows its robot_state wire and prints one JSON line
per state received: {"t": <time.time() of receipt, s>, "sent": <the robot's clock when it sent the state,
s>, "q": [joint positions], "mode": command_mode}.
The test compares these times with its own clock (same machine) to say when the robot stopped.

Ready line: {"url": "<robot url>", "probe": true}. Runs until SIGTERM or --max-lifetime.

Usage: robot_probe.py --url rr+tcp://127.0.0.1:P/?service=robot [--max-lifetime 300]
"""

import argparse
import json
import os
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import die_with_parent, log, ready, wait_for_stop  # noqa: E402

import RobotRaconteur as RR  # noqa: E402
import RobotRaconteurCompanion as RRC  # noqa: E402

RRN = RR.RobotRaconteurNode.s


def main():
    die_with_parent()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--url", required=True)
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    out = threading.Lock()
    flags = ["robot_probe", "--robotraconteur-local-enable=false", "--robotraconteur-tcp-ipv4-discovery=false",
             "--robotraconteur-tcp-ipv6-discovery=false"]
    with RR.ClientNodeSetup(argv=flags):
        # each step on stderr: a probe that never gets ready (once, under a load average of 10) says where it stuck
        log("probe", "registering the standard types")
        RRC.RegisterStdRobDefServiceTypes(RRN)
        log("probe", f"connecting to {args.url}")
        robot = RRN.ConnectService(args.url)
        log("probe", "connected; connecting the robot_state wire")
        wire = robot.robot_state.Connect()
        log("probe", "wire connected")

        def on_state(_wc, value, ts):
            # ts: the robot's node's clock when it sent this state (same machine, same clock as t)
            line = json.dumps({"t": time.time(), "sent": ts.seconds + ts.nanoseconds * 1e-9,
                               "q": [float(x) for x in value.joint_position], "mode": int(value.command_mode)})
            with out:
                print(line, flush=True)

        wire.WireValueChanged += on_state
        ready(url=args.url, probe=True)
        wait_for_stop(args.max_lifetime)
        wire.Close()


if __name__ == "__main__":
    main()
