#!/usr/bin/env python3
"""A gamepad served as a standard com.robotraconteur.hid.joystick.Joystick by the official library
(RobotRaconteurCompanion's standard definitions): 4 axes, 12 buttons, 1 hat, capabilities rumble |
standard_gamepad, USB id 045e:028e (an Xbox 360 pad). At 50 Hz it sends joystick_state and gamepad_state
(and the joystick_sensor_data pipe): the left stick circling once every 2 s, the right stick's x
sweeping, button (t // 0.5) % 12 pressed, the hat turning through up, right, down, left. rumble()
logs {"call": "rumble", "intensity": i, "duration": d} on stdout.

The test drives it by JSON lines on stdin, each answered by one JSON line on stdout:
  {"hold": {"axes": [4 ints], "buttons": [12 ints], "hats": [1 int]}}  the state stays there -> {"held": ...}
  {"resume": true}                                                    the pattern again -> {"resumed": true}

--without-member NAME: the joystick definition served lacks member NAME (as an older or vendor release
would differ): the dashboard must fall back to the generic view.

Ready line: {"url": "rr+tcp://127.0.0.1:P/?service=joystick", "port": P}.

Usage: joystick.py [--without-member joystick_state] [--max-lifetime 300]
"""

import argparse
import json
import math
import os
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import die_with_parent, free_port, node_flags, ready, wait_for_stop, log  # noqa: E402

import numpy as np  # noqa: E402
import RobotRaconteur as RR  # noqa: E402
import RobotRaconteurCompanion as RRC  # noqa: E402
from RobotRaconteurCompanion.StdRobDef import STANDARD_ROBDEF_TEXT  # noqa: E402
from RobotRaconteurCompanion.Util.InfoFileLoader import InfoFileLoader  # noqa: E402
from RobotRaconteurCompanion.Util.SensorDataUtil import SensorDataUtil  # noqa: E402

RRN = RR.RobotRaconteurNode.s
_stdout_lock = threading.Lock()
JOY = "com.robotraconteur.hid.joystick"
AXES, BUTTONS, HATS = 4, 12, 1
# GamepadButtons bits of buttons 0..11 in the browser's standard order (A, B, X, Y, LB, RB, LT, RT,
# back, start, left stick, right stick); the triggers are axes there, not buttons
GAMEPAD_BITS = [0x1, 0x2, 0x4, 0x8, 0x200, 0x400, 0, 0, 0x10, 0x40, 0x80, 0x100]

INFO = """
device_info:
  device:
    name: bench_gamepad
    uuid: 5b7e2f10-6c3d-4a8e-9f21-0d4c6b8a2e31
  manufacturer:
    name: rr-gateway tests
    uuid: 0c6f8a3e-2d41-4b7f-9a15-3e8d2b6c4f70
  serial_number: SIM-PAD-1
  user_description: Bench gamepad (simulated)
  device_classes:
    - class_identifier:
        name: joystick
        uuid: 00000000-0000-0000-0000-000000000000
      subclasses: []
  implemented_types:
    - com.robotraconteur.hid.joystick.Joystick
id: 0
axes_count: 4
button_count: 12
hat_count: 1
joystick_capabilities: 5
joystick_device_vendor: 1118
joystick_device_product: 654
joystick_device_version: 272
"""


def emit(value):
    with _stdout_lock:
        sys.stdout.write(json.dumps(value) + "\n")
        sys.stdout.flush()


def definitions_without(member):
    texts = dict(STANDARD_ROBDEF_TEXT)
    lines = texts[JOY].splitlines()
    kept = [ln for ln in lines if not (len(ln.split()) > 2 and ln.split()[0] in ("wire", "property", "pipe", "function") and ln.split()[2].split("(")[0] == member)]
    if len(kept) == len(lines):
        raise SystemExit(f"--without-member: the joystick has no member {member}")
    texts[JOY] = "\n".join(kept) + "\n"
    return list(texts.values())


class SimJoystick:
    def __init__(self, info):
        self.joystick_info = info
        self.device_info = info.device_info
        self._lock = threading.Lock()
        self._held = None
        self._seqno = 0
        self._sensor_data = SensorDataUtil(RRN)

    def rumble(self, intensity, duration):
        if not (0 <= intensity <= 1) or duration < 0:
            raise RR.InvalidArgumentException(f"rumble intensity {intensity} outside 0 to 1")
        emit({"call": "rumble", "intensity": intensity, "duration": duration})

    def force_feedback(self, force, duration):
        raise RR.NotImplementedException("no force feedback on this gamepad")

    def hold(self, held):
        axes, buttons, hats = held["axes"], held["buttons"], held["hats"]
        if len(axes) != AXES or len(buttons) != BUTTONS or len(hats) != HATS:
            raise ValueError(f"hold needs {AXES} axes, {BUTTONS} buttons, {HATS} hats")
        with self._lock:
            self._held = (list(axes), list(buttons), list(hats))

    def resume(self):
        with self._lock:
            self._held = None

    def pattern(self, t):
        a = 2 * math.pi * t / 2.0
        axes = [int(20000 * math.cos(a)), int(20000 * math.sin(a)), int(32767 * math.sin(a / 4)), 0]
        buttons = [0] * BUTTONS
        buttons[int(t // 0.5) % BUTTONS] = 1
        hats = [[0x01, 0x02, 0x04, 0x08][int(t // 1.0) % 4]]
        return axes, buttons, hats

    def step(self, t):
        with self._lock:
            axes, buttons, hats = self._held if self._held else self.pattern(t)
        s = RRN.NewStructure(f"{JOY}.JoystickState")
        s.axes = np.array(axes, dtype=np.int16)
        s.buttons = np.array(buttons, dtype=np.uint8)
        s.hats = np.array(hats, dtype=np.uint8)
        g = RRN.NewStructure(f"{JOY}.GamepadState")
        g.left_x, g.left_y, g.right_x, g.right_y = (int(v) for v in axes)
        g.trigger_left = 32767 if buttons[6] else 0
        g.trigger_right = 32767 if buttons[7] else 0
        bits = 0
        for i, b in enumerate(buttons):
            if b:
                bits |= GAMEPAD_BITS[i]
        for hat_bit, pad_bit in ((0x01, 0x800), (0x04, 0x1000), (0x08, 0x2000), (0x02, 0x4000)):
            if hats[0] & hat_bit:
                bits |= pad_bit
        g.buttons = bits
        self._seqno += 1
        if hasattr(self, "joystick_state"):
            self.joystick_state.OutValue = s
        if hasattr(self, "gamepad_state"):
            self.gamepad_state.OutValue = g
        if hasattr(self, "joystick_sensor_data"):
            d = RRN.NewStructure(f"{JOY}.JoystickStateSensorData")
            d.data_header = self._sensor_data.FillSensorDataHeader(self.device_info, self._seqno)
            d.joystick_state, d.gamepad_state = s, g
            self.joystick_sensor_data.AsyncSendPacket(d, lambda: None)


def main():
    die_with_parent()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--without-member", default=None)
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    port = free_port()
    with RR.ServerNodeSetup("experimental.sim_joystick", port, argv=["joystick"] + node_flags(port)):
        if args.without_member:
            RRN.RegisterServiceTypes(definitions_without(args.without_member))
        else:
            RRC.RegisterStdRobDefServiceTypes(RRN)
        info, _ = InfoFileLoader(RRN).LoadInfoFileFromString(INFO, f"{JOY}.JoystickInfo", "joystick")
        joy = SimJoystick(info)
        RRN.RegisterService("joystick", f"{JOY}.Joystick", joy)
        stop = threading.Event()

        def loop():
            start = time.monotonic()
            while not stop.wait(0.02):
                try:
                    joy.step(time.monotonic() - start)
                except Exception as e:  # a client gone mid-send: keep serving
                    log("joystick", f"step: {e}")

        def commands():
            for line in sys.stdin:
                try:
                    cmd = json.loads(line)
                    if "hold" in cmd:
                        joy.hold(cmd["hold"])
                        reply = {"held": cmd["hold"]}
                    elif cmd.get("resume"):
                        joy.resume()
                        reply = {"resumed": True}
                    else:
                        reply = {"failed": f"unknown command {line.strip()}"}
                except Exception as e:  # the test's mistake: say so, keep serving
                    reply = {"failed": f"{type(e).__name__}: {e}"}
                emit(reply)

        threading.Thread(target=loop, daemon=True).start()
        threading.Thread(target=commands, daemon=True).start()
        with _stdout_lock:
            ready(url=f"rr+tcp://127.0.0.1:{port}/?service=joystick", port=port, pid=os.getpid())
        wait_for_stop(args.max_lifetime)
        stop.set()
        log("joystick", "stopping")


if __name__ == "__main__":
    main()
