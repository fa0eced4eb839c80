#!/usr/bin/env python3
"""A simulated electric parallel gripper served as a standard com.robotraconteur.robotics.tool.Tool on the
official library (RobotRaconteurCompanion's standard definitions; its ToolInfo loaded by InfoFileLoader as
drivers load theirs). The PyPI robotraconteur-abstract-robot (0.2.2) has no tool base class, so the
gripper is simulated here.

The fingers travel between close_position 0 m and open_position 0.085 m at 0.1 m/s (actuation_time
0.85 s) while a motion is under way: open(), close() and setf_command(position) start one, halt() ends it
where the fingers are. An object 0.04 m wide sits between the fingers: closing stops there with the flag
`gripping` and a grip force (sensor[0], newtons) that ramps up to 40 N. enable() switches the motor on
(motion needs it; the gripper starts disabled unless --enabled), disable() stops and switches it off.
tool_state carries ts, seqno, the flags (enabled | ready, opened / closed / between, actuating,
gripping), position, command and sensor every --period.

--log-motion (for tests): one stdout line per loop step in which the fingers moved,
{"tool": <time.time()>, "position": p}, one per call {"call": name, "t": <time.time()>}, and
{"tick": <time.time()>} every 0.25 s (a test waits for a tick to know that every step before it was
logged): what a test reads to say when the gripper stopped, without a client of the tool in between.

Ready line: {"url": "rr+tcp://127.0.0.1:P/?service=tool", "port": P, "device_uuid": "..."}.

--without-member NAME (for tests): serves a Tool whose definition lacks member NAME (the standard
definition with that member's line removed, as an older or vendor release would differ): the dashboard
must fall back to the generic view.

Usage: sim_tool.py [--enabled] [--start-position 0.085] [--period 0.02] [--log-motion]
                   [--without-member tool_state] [--max-lifetime 300]
"""

import argparse
import json
import os
import sys
import threading
import time
import uuid

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import die_with_parent, free_port, node_flags, ready, wait_for_stop, log  # noqa: E402

import numpy as np  # noqa: E402
import RobotRaconteur as RR  # noqa: E402
import RobotRaconteurCompanion as RRC  # noqa: E402
from RobotRaconteurCompanion.StdRobDef import STANDARD_ROBDEF_TEXT  # noqa: E402
from RobotRaconteurCompanion.Util.InfoFileLoader import InfoFileLoader  # noqa: E402
from RobotRaconteurCompanion.Util.AttributesUtil import AttributesUtil  # noqa: E402

RRN = RR.RobotRaconteurNode.s
_stdout_lock = threading.Lock()

TOOL_INFO = """
device_info:
  device:
    name: sim_gripper
    uuid: 3c1d5e7f-9a2b-4c4d-8e6f-a1b2c3d4e5f6
  manufacturer:
    name: rr-gateway tests
    uuid: 0c6f8a3e-2d41-4b7f-9a15-3e8d2b6c4f70
  model:
    name: sim-2f85
    uuid: 5b4a3928-1706-4f5e-8d4c-3b2a19087f6e
  serial_number: SIM-2F85-0001
  user_description: Electric parallel gripper simulated in the test (85 mm stroke, 0.85 s)
  device_classes:
    - class_identifier:
        name: tool
        uuid: 00000000-0000-0000-0000-000000000000
      subclasses:
        - gripper
  implemented_types:
    - com.robotraconteur.robotics.tool.Tool
tool_type: electric_gripper
tool_capabilities:
  - open_close_command
  - continuous_command
  - homing_command
  - software_reset_errors
  - software_enable
  - sensor_feedback
tcp:
  rotation: {w: 1.0, x: 0.0, y: 0.0, z: 0.0}
  translation: {x: 0.0, y: 0.0, z: 0.15}
actuation_time: 0.85
close_position: 0.0
open_position: 0.085
command_min: 0.0
command_max: 0.085
command_close: 0.0
command_open: 0.085
sensor_type:
  - force
sensor_min: [0.0]
sensor_max: [235.0]
sensor_units:
  - display_units: N
    encoded_units: kg*m/s^2
"""

SPEED = 0.1          # m/s
OBJECT_WIDTH = 0.04  # m: the part held between the fingers
MAX_FORCE = 40.0     # N
EPS = 1e-6


def emit(value):
    with _stdout_lock:
        sys.stdout.write(json.dumps(value) + "\n")
        sys.stdout.flush()


class SimGripper:
    """The Tool object: its members as the official library calls them."""

    def __init__(self, info, period, enabled, start, log_motion):
        self.tool_info = info
        self.device_info = info.device_info
        self._period = period
        self._lock = threading.Lock()
        self._enabled = enabled
        self._position = start
        self._target = None
        self._force = 0.0
        self._seqno = 0
        self._log = log_motion
        self._flags = RRN.GetConstants("com.robotraconteur.robotics.tool")["ToolStateFlags"]
        self._state_type = RRN.GetStructureType("com.robotraconteur.robotics.tool.ToolState")
        self._ts_dtype = RRN.GetNamedArrayDType("com.robotraconteur.datetime.TimeSpec3")
        self._broadcaster = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, daemon=True)

    # wires set by the library when the object is registered
    @property
    def tool_state(self):
        return self._tool_state

    @tool_state.setter
    def tool_state(self, wire):
        self._tool_state = wire
        self._broadcaster = RR.WireBroadcaster(wire)

    def start(self):
        self._thread.start()

    def close_device(self):
        self._stop.set()
        self._thread.join(2)

    def _called(self, name):
        if self._log:
            emit({"call": name, "t": time.time()})

    def _move_to(self, name, target):
        self._called(name)
        with self._lock:
            if not self._enabled:
                raise RR.InvalidOperationException("Tool is not enabled")
            self._target = float(np.clip(target, 0.0, self.tool_info.open_position))

    def open(self):
        self._move_to("open", self.tool_info.open_position)

    def close(self):
        self._move_to("close", self.tool_info.close_position)

    def setf_command(self, command):
        if not np.isfinite(command) or command < self.tool_info.command_min or command > self.tool_info.command_max:
            raise RR.InvalidArgumentException(
                f"command {command} outside {self.tool_info.command_min} to {self.tool_info.command_max} m")
        self._move_to("setf_command", command)

    def home(self):
        self._move_to("home", self.tool_info.open_position)

    def halt(self):
        self._called("halt")
        with self._lock:
            self._target = None

    def enable(self):
        self._called("enable")
        with self._lock:
            self._enabled = True

    def disable(self):
        self._called("disable")
        with self._lock:
            self._enabled = False
            self._target = None

    def reset_errors(self):
        self._called("reset_errors")

    def _loop(self):
        last = time.monotonic()
        next_tick = 0.0
        while not self._stop.wait(self._period):
            if self._log and time.time() >= next_tick:
                next_tick = time.time() + 0.25
                emit({"tick": time.time()})
            now = time.monotonic()
            dt, last = now - last, now
            with self._lock:
                moved = False
                if self._target is not None and self._enabled:
                    lower = OBJECT_WIDTH if self._position >= OBJECT_WIDTH - EPS and self._target < OBJECT_WIDTH else 0.0
                    goal = max(self._target, lower)
                    step = float(np.clip(goal - self._position, -SPEED * dt, SPEED * dt))
                    if abs(step) > EPS:
                        self._position += step
                        moved = True
                    elif lower > 0 and self._target < lower:
                        # blocked by the part: the grip force builds while the close is held
                        self._force = min(MAX_FORCE, self._force + 100.0 * dt)
                if self._position > OBJECT_WIDTH + EPS:
                    self._force = 0.0
                gripping = self._force > 0
                pos, target, force, enabled = self._position, self._target, self._force, self._enabled
                self._seqno += 1
                seqno = self._seqno
            if moved and self._log:
                emit({"tool": time.time(), "position": pos})
            f = self._flags
            flags = 0
            if enabled:
                flags |= f["enabled"] | f["ready"]
            if pos >= self.tool_info.open_position - 1e-4:
                flags |= f["opened"]
            elif pos <= self.tool_info.close_position + 1e-4:
                flags |= f["closed"]
            else:
                flags |= f["between"]
            if moved:
                flags |= f["actuating"]
            if gripping:
                flags |= f["gripping"]
            s = self._state_type()
            ts = np.zeros((1,), dtype=self._ts_dtype)
            ts[0]["microseconds"] = int(time.time() * 1e6)
            s.ts = ts
            s.seqno = seqno
            s.tool_state_flags = flags
            s.position = pos
            s.command = target if target is not None else pos
            s.sensor = np.array([force], dtype=np.float64)
            if self._broadcaster is None:
                continue
            try:
                self._broadcaster.OutValue = s
            except Exception as e:  # noqa: BLE001  (a closing node)
                log("tool", f"tool_state: {e}")


def main():
    die_with_parent()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--enabled", action="store_true", help="motor on from the start")
    ap.add_argument("--start-position", type=float, default=0.085, help="finger opening to start at (m)")
    ap.add_argument("--period", type=float, default=0.02, help="loop period in seconds")
    ap.add_argument("--log-motion", action="store_true", help="print a JSON line per call and per step that moved")
    ap.add_argument("--without-member", default=None, help="serve a Tool definition without this member")
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    port = free_port()
    with RR.ServerNodeSetup("experimental.sim_gripper", port, argv=["sim_tool"] + node_flags(port)):
        if args.without_member:
            texts = dict(STANDARD_ROBDEF_TEXT)
            name = "com.robotraconteur.robotics.tool"
            lines = texts[name].splitlines()
            kept = [ln for ln in lines if not (ln.strip().split(" ")[:1] in (["wire"], ["pipe"], ["function"], ["property"])
                                              and len(ln.split()) > 2 and ln.split()[2].split("(")[0] == args.without_member)]
            if len(kept) == len(lines):
                raise SystemExit(f"--without-member: the Tool has no member {args.without_member}")
            texts[name] = "\n".join(kept) + "\n"
            RRN.RegisterServiceTypes(list(texts.values()))
        else:
            RRC.RegisterStdRobDefServiceTypes(RRN)
        info, _ = InfoFileLoader(RRN).LoadInfoFileFromString(TOOL_INFO, "com.robotraconteur.robotics.tool.ToolInfo", "tool")
        attributes = AttributesUtil(RRN).GetDefaultServiceAttributesFromDeviceInfo(info.device_info)
        tool = SimGripper(info, args.period, args.enabled, args.start_position, args.log_motion)
        ctx = RRN.RegisterService("tool", "com.robotraconteur.robotics.tool.Tool", tool)
        ctx.SetServiceAttributes(attributes)
        tool.start()
        device_uuid = str(uuid.UUID(bytes=bytes(info.device_info.device.uuid["uuid_bytes"].tobytes())))
        with _stdout_lock:
            ready(url=f"rr+tcp://127.0.0.1:{port}/?service=tool", port=port, device_uuid=device_uuid, pid=os.getpid())
        wait_for_stop(args.max_lifetime)
        log("tool", "stopping")
        tool.close_device()


if __name__ == "__main__":
    main()
