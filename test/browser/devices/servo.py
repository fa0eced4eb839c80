#!/usr/bin/env python3
"""Motion devices served by the official library with the standard definitions (RobotRaconteurCompanion):

  "servo"     a com.robotraconteur.servo.Servo: a two-axis linear stage (prismatic_electric), positions
              in metres 0 … 0.2 (start 0.1, 0.05), velocity_max 0.05 m/s per axis, capabilities
              position_command | velocity_command | trapezoidal_command. In mode velocity_command the
              axes move at the last ServoCommand received on velocity_command (a wire connection or a
              poke) and keep moving until halt(), a mode change or a limit: the stage has no command
              timeout of its own, so what stops it after a jog is the page's halt() or the gateway's.
              halt() sets mode halt. servo_state every 20 ms.
  "conveyor"  a com.robotraconteur.actuator.Actuator (ActuatorTypeCode conveyor, command units m/s): in
              actuator_mode normal or reduced_performance the belt runs at the last actuator_command;
              actuator_mode halt stops it. actuator_state every 20 ms.

Log lines on stdout (for the tests, which judge stops by them): one per call or mode write
{"call": name, "t": time.time(), "value": v}, one per loop step in which something moved
{"moved": "servo"|"conveyor", "t": time.time(), "position": [..] | "speed": v}, and {"tick": time.time()}
every 0.25 s (every step before it is logged).

--without-member NAME: the servo and actuator definitions served lack member NAME (as an older or vendor
release would differ): the dashboard must fall back to the generic view.

Ready line: {"url": "rr+tcp://127.0.0.1:P/?service=servo", "urls": {...}, "port": P}.

Usage: servo.py [--without-member servo_state] [--max-lifetime 300]
"""

import argparse
import json
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

RRN = RR.RobotRaconteurNode.s
_stdout_lock = threading.Lock()
SV, ACT = "com.robotraconteur.servo", "com.robotraconteur.actuator"
PERIOD = 0.02

DEVICE_INFO = """
device:
  name: {name}
  uuid: {uuid}
manufacturer:
  name: rr-gateway tests
  uuid: 0c6f8a3e-2d41-4b7f-9a15-3e8d2b6c4f70
serial_number: SIM-{serial}
user_description: {description}
device_classes: []
implemented_types:
  - {type}
"""


def emit(value):
    with _stdout_lock:
        sys.stdout.write(json.dumps(value) + "\n")
        sys.stdout.flush()


def definitions_without(member):
    texts = dict(STANDARD_ROBDEF_TEXT)
    changed = False
    for svc in (SV, ACT):
        lines = texts[svc].splitlines()
        kept = [ln for ln in lines if not (len(ln.split()) > 2 and ln.split()[0] in ("wire", "property", "pipe", "function") and ln.split()[2].split("(")[0] == member)]
        changed |= len(kept) != len(lines)
        texts[svc] = "\n".join(kept) + "\n"
    if not changed:
        raise SystemExit(f"--without-member: no member {member}")
    return list(texts.values())


def now_ts():
    ts = np.zeros((1,), dtype=RRN.GetNamedArrayDType("com.robotraconteur.datetime.TimeSpec3"))
    ts[0]["microseconds"] = int(time.time() * 1e6)
    return ts


def device_info(loader, name, uuid, serial, description, type_name):
    info, _ = loader.LoadInfoFileFromString(DEVICE_INFO.format(name=name, uuid=uuid, serial=serial, description=description, type=type_name),
                                            "com.robotraconteur.device.DeviceInfo", "device")
    return info


class SimServo:
    def __init__(self, dinfo):
        c = RRN.GetConstants(SV)
        self._modes = c["ServoMode"]
        jc = RRN.GetConstants("com.robotraconteur.robotics.joints")
        info = RRN.NewStructure(f"{SV}.ServoInfo")
        info.device_info = dinfo
        info.servo_type = c["ServoTypeCode"]["prismatic_electric"]
        caps = c["ServoCapabilities"]
        info.capabilities = caps["position_command"] | caps["velocity_command"] | caps["trapezoidal_command"]
        info.axis_count = 2
        info.position_units = [jc["JointPositionUnits"]["meter"]] * 2
        info.effort_units = [jc["JointEffortUnits"]["newton"]] * 2
        info.position_min, info.position_max = np.array([0.0, 0.0]), np.array([0.2, 0.2])
        info.velocity_min, info.velocity_max = np.array([-0.05, -0.05]), np.array([0.05, 0.05])
        for f in ("acceleration_min", "acceleration_max", "torque_min", "torque_max", "gear_ratio", "sensor_resolution", "effort_command_resolution"):
            setattr(info, f, np.array([]))
        info.parameter_info, info.signal_info, info.extended = [], [], {}
        self.servo_info, self.device_info = info, dinfo
        self._lock = threading.Lock()
        self._mode = self._modes["halt"]
        self._pos = np.array([0.1, 0.05])
        self._vel = np.zeros(2)
        self._seqno = 0

    def RRServiceObjectInit(self, ctx, service_path):
        if hasattr(self, "velocity_command"):
            self.velocity_command.InValueChanged += lambda value, ts, ep: self._velocity(value)

    def _velocity(self, cmd):
        v = np.asarray(cmd.command, dtype=np.float64).reshape(-1)
        with self._lock:
            if self._mode != self._modes["velocity_command"] or v.shape != (2,):
                return
            self._vel = np.clip(v, -0.05, 0.05)

    def halt(self):
        with self._lock:
            self._vel[:] = 0
            self._mode = self._modes["halt"]
        emit({"call": "halt", "t": time.time()})

    @property
    def mode(self):
        return self._mode

    @mode.setter
    def mode(self, m):
        if int(m) not in self._modes.values():
            raise RR.InvalidArgumentException(f"no servo mode {m}")
        with self._lock:
            self._mode = int(m)
            self._vel[:] = 0
        emit({"call": "mode", "t": time.time(), "value": int(m)})

    def trapezoidal_move(self, target_pos, target_vel, vel, accel):
        raise RR.NotImplementedException("trapezoidal_move is not simulated")

    def getf_signal(self, name):
        raise RR.InvalidArgumentException(f"no signal {name}")

    def setf_signal(self, name, value):
        raise RR.InvalidArgumentException(f"no signal {name}")

    def getf_param(self, name):
        raise RR.InvalidArgumentException(f"no parameter {name}")

    def setf_param(self, name, value):
        raise RR.InvalidArgumentException(f"no parameter {name}")

    def step(self):
        with self._lock:
            before = self._pos.copy()
            self._pos = np.clip(self._pos + self._vel * PERIOD, 0.0, 0.2)
            vel = self._vel.copy() if not np.array_equal(before, self._pos) else np.zeros(2)
            moved = not np.array_equal(before, self._pos)
            mode = self._mode
            self._seqno += 1
            pos = self._pos.copy()
        if moved:
            emit({"moved": "servo", "t": time.time(), "position": pos.tolist()})
        s = RRN.NewStructure(f"{SV}.ServoState")
        s.ts = now_ts()
        s.seqno = self._seqno
        flags = RRN.GetConstants(SV)["ServoStateFlags"]
        s.servo_state_flags = flags["ready"] | flags["enabled"] | flags["streaming"]
        s.mode = mode
        s.position, s.velocity = pos, vel
        s.acceleration, s.effort = np.zeros(2), np.array([1.5, -0.5])
        s.position_command, s.velocity_command, s.effort_command = pos, vel, np.zeros(2)
        if hasattr(self, "servo_state"):
            self.servo_state.OutValue = s
        if hasattr(self, "position"):
            self.position.OutValue = pos


class SimConveyor:
    def __init__(self, dinfo):
        c = RRN.GetConstants(ACT)
        self._modes = c["ActuatorMode"]
        info = RRN.NewStructure(f"{ACT}.ActuatorInfo")
        info.device_info = dinfo
        info.actuator_type = c["ActuatorTypeCode"]["conveyor"]
        u = RRN.NewStructure("com.robotraconteur.units.SIUnit")
        u.display_units, u.encoded_units = "m/s", "m/s"
        info.command_units = [u]
        info.command_resolution = np.array([0.001])
        info.analog_output = True
        info.parameter_info, info.extended = [], {}
        self.actuator_info, self.device_info = info, dinfo
        self._lock = threading.Lock()
        self._mode = self._modes["halt"]
        self._speed = 0.0
        self._seqno = 0

    def RRServiceObjectInit(self, ctx, service_path):
        if hasattr(self, "actuator_command"):
            self.actuator_command.InValueChanged += lambda value, ts, ep: self._command(value)

    def _command(self, v):
        v = np.asarray(v, dtype=np.float64).reshape(-1)
        with self._lock:
            if self._mode in (self._modes["normal"], self._modes["reduced_performance"]) and v.shape == (1,):
                self._speed = float(v[0])

    @property
    def actuator_mode(self):
        return self._mode

    @actuator_mode.setter
    def actuator_mode(self, m):
        if int(m) not in self._modes.values():
            raise RR.InvalidArgumentException(f"no actuator mode {m}")
        with self._lock:
            self._mode = int(m)
            if self._mode not in (self._modes["normal"], self._modes["reduced_performance"]):
                self._speed = 0.0
        emit({"call": "actuator_mode", "t": time.time(), "value": int(m)})

    def getf_param(self, name):
        raise RR.InvalidArgumentException(f"no parameter {name}")

    def setf_param(self, name, value):
        raise RR.InvalidArgumentException(f"no parameter {name}")

    def step(self):
        with self._lock:
            speed = self._speed
            self._seqno += 1
        if speed != 0:
            emit({"moved": "conveyor", "t": time.time(), "speed": speed})
        s = RRN.NewStructure(f"{ACT}.ActuatorState")
        s.ts = now_ts()
        s.seqno = self._seqno
        flags = RRN.GetConstants(ACT)["ActuatorStateFlags"]
        s.actuator_state_flags = flags["ready"] | flags["enabled"]
        s.actuator_command = np.array([speed])
        if hasattr(self, "actuator_state"):
            self.actuator_state.OutValue = s


def main():
    die_with_parent()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--without-member", default=None)
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    port = free_port()
    with RR.ServerNodeSetup("experimental.sim_motion", port, argv=["servo"] + node_flags(port)):
        if args.without_member:
            RRN.RegisterServiceTypes(definitions_without(args.without_member))
        else:
            RRC.RegisterStdRobDefServiceTypes(RRN)
        loader = InfoFileLoader(RRN)
        servo = SimServo(device_info(loader, "xy_stage", "6a2c4e80-1f3b-4d5c-9e7f-8a0b1c2d3e41", "XY-1", "XY stage (simulated)", f"{SV}.Servo"))
        conveyor = SimConveyor(device_info(loader, "belt", "6a2c4e80-1f3b-4d5c-9e7f-8a0b1c2d3e42", "BELT-1", "Belt conveyor (simulated)", f"{ACT}.Actuator"))
        RRN.RegisterService("servo", f"{SV}.Servo", servo)
        RRN.RegisterService("conveyor", f"{ACT}.Actuator", conveyor)
        stop = threading.Event()

        def loop():
            last_tick = 0.0
            while not stop.wait(PERIOD):
                for d in (servo, conveyor):
                    try:
                        d.step()
                    except Exception as e:  # a client gone mid-send: keep serving
                        log("servo", f"step: {e}")
                now = time.time()
                if now - last_tick >= 0.25:
                    emit({"tick": now})
                    last_tick = now

        threading.Thread(target=loop, daemon=True).start()
        urls = {n: f"rr+tcp://127.0.0.1:{port}/?service={n}" for n in ("servo", "conveyor")}
        with _stdout_lock:
            ready(url=urls["servo"], urls=urls, port=port, pid=os.getpid())
        wait_for_stop(args.max_lifetime)
        stop.set()
        log("servo", "stopping")


if __name__ == "__main__":
    main()
