#!/usr/bin/env python3
"""A work cell's I/O served by the official library with the standard com.robotraconteur.signal
definitions (RobotRaconteurCompanion):

  "io"      a SignalDevice with two groups (signal_group_info; signal_groups[name], signal i of a group at
            signals[i]):
              inputs   door_closed (digital, readonly, on), part_present (digital, readonly, on for 1 s
                       of every 2), air_pressure (analog, bar, readonly, 6.0 + 0.2 sin t),
                       cell_temperature (analog, °C, readonly, 21.5)
              outputs  valve_a (digital, all, off), beacon (digital, all, off), conveyor_speed (analog,
                       m/s, all, 0 to 0.5, 0), safety_relay (digital, restricted, on)
  "lamps"   a SignalGroup: lamp_green, lamp_red (digital, all, off)
  "gauge"   a lone Signal: line_pressure (analog, bar, readonly, 4.25)

Values go out every 0.1 s on signal_value (varvalue: bool[] for digital signals, double[] otherwise)
and signal_value_vec (double[]). A command on signal_command_vec or signal_command (poked or sent on a
connection) sets a writable signal's value and is logged {"signal": name, "command": [values]}; one
for a signal that is not writable, or outside its range, is logged {"signal": name, "refused": ...}
and ignored.

--without-member NAME: the signal definition served lacks member NAME (as an older or vendor release
would differ): the dashboard must fall back to the generic view.

Ready line: {"url": "rr+tcp://127.0.0.1:P/?service=io", "urls": {service: url}, "port": P}.

Usage: signals.py [--without-member signal_groups] [--max-lifetime 300]
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

RRN = RR.RobotRaconteurNode.s
_stdout_lock = threading.Lock()
SIG = "com.robotraconteur.signal"

DEVICE_INFO = """
device:
  name: cell_io
  uuid: 2f4e6a80-1b3c-4d5e-8f70-9a1b2c3d4e5f
manufacturer:
  name: rr-gateway tests
  uuid: 0c6f8a3e-2d41-4b7f-9a15-3e8d2b6c4f70
serial_number: SIM-IO-1
user_description: Work cell I/O (simulated)
device_classes:
  - class_identifier:
      name: io
      uuid: 00000000-0000-0000-0000-000000000000
    subclasses: []
implemented_types:
  - com.robotraconteur.signal.SignalDevice
"""

# name, type, access, units, min, max, start value (None: a pattern of t)
INPUTS = [
    ("door_closed", "digital", "readonly", None, None, None, 1.0),
    ("part_present", "digital", "readonly", None, None, None, None),
    ("air_pressure", "analog", "readonly", "bar", None, None, None),
    ("cell_temperature", "analog", "readonly", "°C", None, None, 21.5),
]
OUTPUTS = [
    ("valve_a", "digital", "all", None, None, None, 0.0),
    ("beacon", "digital", "all", None, None, None, 0.0),
    ("conveyor_speed", "analog", "all", "m/s", 0.0, 0.5, 0.0),
    ("safety_relay", "digital", "restricted", None, None, None, 1.0),
]
LAMPS = [
    ("lamp_green", "digital", "all", None, None, None, 0.0),
    ("lamp_red", "digital", "all", None, None, None, 0.0),
]
GAUGE = ("line_pressure", "analog", "readonly", "bar", None, None, 4.25)


def emit(value):
    with _stdout_lock:
        sys.stdout.write(json.dumps(value) + "\n")
        sys.stdout.flush()


def definitions_without(member):
    texts = dict(STANDARD_ROBDEF_TEXT)
    lines = texts[SIG].splitlines()
    kept = [ln for ln in lines if not (len(ln.split()) > 2 and ln.split()[0] in ("wire", "property", "objref") and ln.split()[2] == member)]
    if len(kept) == len(lines):
        raise SystemExit(f"--without-member: the signal definition has no member {member}")
    texts[SIG] = "\n".join(kept) + "\n"
    return list(texts.values())


def consts(name):
    return RRN.GetConstants(SIG)[name]


def var(type_text, value):
    return RR.VarValue(value, type_text)


class SignalImpl:
    """One signal: signal_info, its value on signal_value / signal_value_vec, commands taken when writable."""

    def __init__(self, spec, start):
        name, kind, access, units, lo, hi, value = spec
        self.name, self.digital, self.writable = name, kind == "digital", access == "all"
        self.lo, self.hi = lo, hi
        self._start = start
        self._value = value
        self._pattern = value is None
        info = RRN.NewStructure(f"{SIG}.SignalInfo")
        ident = RRN.NewStructure("com.robotraconteur.identifier.Identifier")
        ident.name = name
        ident.uuid = np.zeros((1,), dtype=RRN.GetNamedArrayDType("com.robotraconteur.uuid.UUID"))
        info.signal_identifier = ident
        unit_list = []
        if units:
            u = RRN.NewStructure("com.robotraconteur.units.SIUnit")
            u.display_units, u.encoded_units = units, units
            unit_list.append(u)
        info.units = unit_list
        info.signal_type = consts("SignalType")[kind]
        info.access_level = consts("SignalAccessLevel")[access]
        info.address = np.array([], dtype=np.uint32)
        info.user_description = f"{name.replace('_', ' ')} ({kind}, {access})"
        info.min_value = var("double[]", np.array([lo], dtype=np.float64)) if lo is not None else None
        info.max_value = var("double[]", np.array([hi], dtype=np.float64)) if hi is not None else None
        info.extended = {}
        self.signal_info = info

    def RRServiceObjectInit(self, ctx, service_path):
        for wire in ("signal_command_vec", "signal_command"):
            if hasattr(self, wire):
                getattr(self, wire).InValueChanged += (lambda w: lambda value, ts, ep: self.command(w, value))(wire)

    def command(self, wire, value):
        v = value.data if isinstance(value, RR.VarValue) else value
        values = [float(x) for x in np.asarray(v).reshape(-1)]
        if not self.writable:
            emit({"signal": self.name, "refused": values, "why": "not writable"})
            return
        if len(values) != 1 or (self.lo is not None and values[0] < self.lo) or (self.hi is not None and values[0] > self.hi):
            emit({"signal": self.name, "refused": values, "why": "outside its range"})
            return
        self._value = (1.0 if values[0] != 0 else 0.0) if self.digital else values[0]
        emit({"signal": self.name, "command": values, "wire": wire})

    def value(self, t):
        if not self._pattern:
            return self._value
        if self.name == "part_present":
            return 1.0 if int(t) % 2 == 0 else 0.0
        return 6.0 + 0.2 * math.sin(t)

    def step(self, t):
        v = self.value(t)
        if hasattr(self, "signal_value"):
            self.signal_value.OutValue = var("bool[]", np.array([v != 0], dtype=bool)) if self.digital else var("double[]", np.array([v]))
        if hasattr(self, "signal_value_vec"):
            self.signal_value_vec.OutValue = np.array([v], dtype=np.float64)


class SignalGroupImpl:
    def __init__(self, specs, start):
        self.signal_list = [SignalImpl(s, start) for s in specs]
        self.signal_info = [s.signal_info for s in self.signal_list]

    def get_signals(self, ind):
        i = int(ind)
        if not 0 <= i < len(self.signal_list):
            raise RR.InvalidArgumentException(f"no signal {ind}")
        return self.signal_list[i], f"{SIG}.Signal"


class SignalDeviceImpl:
    def __init__(self, groups, device_info):
        self.device_info = device_info
        self._groups = groups  # name -> (description, SignalGroupImpl)
        infos = []
        for name, (description, _) in groups.items():
            g = RRN.NewStructure(f"{SIG}.SignalGroupInfo")
            ident = RRN.NewStructure("com.robotraconteur.identifier.Identifier")
            ident.name = name
            ident.uuid = np.zeros((1,), dtype=RRN.GetNamedArrayDType("com.robotraconteur.uuid.UUID"))
            g.signal_group_identifier, g.description = ident, description
            infos.append(g)
        self.signal_group_info = infos

    def get_signal_groups(self, ind):
        if ind not in self._groups:
            raise RR.InvalidArgumentException(f"no signal group {ind}")
        return self._groups[ind][1], f"{SIG}.SignalGroup"


def main():
    die_with_parent()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--without-member", default=None)
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    port = free_port()
    with RR.ServerNodeSetup("experimental.sim_signals", port, argv=["signals"] + node_flags(port)):
        if args.without_member:
            RRN.RegisterServiceTypes(definitions_without(args.without_member))
        else:
            RRC.RegisterStdRobDefServiceTypes(RRN)
        start = time.monotonic()
        device_info, _ = InfoFileLoader(RRN).LoadInfoFileFromString(DEVICE_INFO, "com.robotraconteur.device.DeviceInfo", "device")
        inputs, outputs = SignalGroupImpl(INPUTS, start), SignalGroupImpl(OUTPUTS, start)
        io = SignalDeviceImpl({"inputs": ("Cell inputs", inputs), "outputs": ("Cell outputs", outputs)}, device_info)
        lamps = SignalGroupImpl(LAMPS, start)
        gauge = SignalImpl(GAUGE, start)
        RRN.RegisterService("io", f"{SIG}.SignalDevice", io)
        RRN.RegisterService("lamps", f"{SIG}.SignalGroup", lamps)
        RRN.RegisterService("gauge", f"{SIG}.Signal", gauge)
        every = inputs.signal_list + outputs.signal_list + lamps.signal_list + [gauge]
        stop = threading.Event()

        def loop():
            while not stop.wait(0.1):
                t = time.monotonic() - start
                for s in every:
                    try:
                        s.step(t)
                    except Exception as e:  # a signal nobody opened yet has no wires: skip it
                        log("signals", f"{s.name}: {e}")

        threading.Thread(target=loop, daemon=True).start()
        urls = {n: f"rr+tcp://127.0.0.1:{port}/?service={n}" for n in ("io", "lamps", "gauge")}
        with _stdout_lock:
            ready(url=urls["io"], urls=urls, port=port, pid=os.getpid())
        wait_for_stop(args.max_lifetime)
        stop.set()
        log("signals", "stopping")


if __name__ == "__main__":
    main()
