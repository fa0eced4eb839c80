#!/usr/bin/env python3
"""The other standard device types of a bench, served on one node by the official library with
RobotRaconteurCompanion's standard definitions:

  "clock"      a com.robotraconteur.datetime.clock.Clock whose time runs --clock-offset seconds (2.5) ahead
               of this computer's: time_utc and time_local (UTC+02:00, Europe/Berlin) every 0.1 s;
               clock_info with that zone.
  "log"        a com.robotraconteur.eventlog.EventLogDevice holding 50 messages (numbers 1 to 50; every
               tenth an error "conveyor jam at station N", the rest info/warning), then one new message a
               second (number 51, 52, ...: "heartbeat N", info) stored and sent on eventlog_message_stream.
  "billboard"  a com.robotraconteur.device.BillboardDevice whose user_description is BILLBOARD_TEXT.
  "storage"    a com.robotraconteur.resource.device.ResourceStorageDevice with the bucket "programs"
               (pick_place.txt: 3,000 bytes of text, sent by resource_get in parts of 1,024 bytes;
               calibration.yml) and the bucket "empty".
  "planner"    an experimental.planner.Planner (PLANNER_DEF below: not a standard object, a device whose
               members carry standard structures): last_plan, a JointTrajectory of 3 joints (radians) and
               11 waypoints over 2 s; plan(duration) the same motion over `duration` s with twice the
               swing; gains, a PIDParam.

Ready line: {"url": ".../?service=clock", "urls": {service: url}, "port": P, "clock_offset": s,
"billboard": text, "resources": {key: sha256 hex}}.

--without-member NAME: the definitions served lack member NAME in those services (as an older or vendor
release would differ): the dashboard must fall back to the generic view.

Usage: misc_devices.py [--clock-offset 2.5] [--without-member NAME] [--max-lifetime 300]
"""

import argparse
import hashlib
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
BILLBOARD_TEXT = "Cell 3: robot maintenance until 14:00. Do not enter the cell."
PICK_PLACE = ("; pick and place, station 3\n" + "".join(f"MOVE P{i} SPEED 50\nGRIP {'CLOSE' if i % 2 else 'OPEN'}\n" for i in range(200)))[:3000].encode()
CALIBRATION = b"camera:\n  fx: 612.3\n  fy: 611.9\n  cx: 320.5\n  cy: 240.1\n"
SERVICES = ["com.robotraconteur.datetime.clock", "com.robotraconteur.eventlog", "com.robotraconteur.device", "com.robotraconteur.resource.device"]

PLANNER_DEF = """service experimental.planner

stdver 0.10

import com.robotraconteur.robotics.trajectory
import com.robotraconteur.pid

using com.robotraconteur.robotics.trajectory.JointTrajectory
using com.robotraconteur.pid.PIDParam

object Planner
    property JointTrajectory last_plan [readonly]
    property PIDParam gains [readonly]
    function JointTrajectory plan(double duration)
end
"""

DEVICE_INFO = """
device:
  name: {name}
  uuid: {uuid}
manufacturer:
  name: rr-gateway tests
  uuid: 0c6f8a3e-2d41-4b7f-9a15-3e8d2b6c4f70
serial_number: SIM-{name}
user_description: {description}
device_classes: []
implemented_types:
  - {type}
"""


def definitions_without(member):
    texts = dict(STANDARD_ROBDEF_TEXT)
    changed = False
    for svc in SERVICES:
        lines = texts[svc].splitlines()
        kept = [ln for ln in lines if not (len(ln.split()) > 2 and ln.split()[0] in ("wire", "property", "pipe", "function")
                                           and ln.split()[2].split("(")[0] == member)]
        changed |= len(kept) != len(lines)
        texts[svc] = "\n".join(kept) + "\n"
    if not changed:
        raise SystemExit(f"--without-member: no member {member}")
    return list(texts.values())


def identifier(name):
    i = RRN.NewStructure("com.robotraconteur.identifier.Identifier")
    i.name = name
    i.uuid = np.zeros((1,), dtype=RRN.GetNamedArrayDType("com.robotraconteur.uuid.UUID"))
    return i


def utc(seconds):
    t = np.zeros((1,), dtype=RRN.GetPodDType("com.robotraconteur.datetime.DateTimeUTC"))
    t[0]["seconds"] = int(seconds)
    t[0]["nanoseconds"] = int((seconds - int(seconds)) * 1e9)
    t[0]["clock_info"]["clock_type"] = RRN.GetConstants("com.robotraconteur.datetime")["ClockTypeCode"]["system_rtc_clock"]
    return t


class SimClock:
    def __init__(self, dinfo, offset):
        self.device_info, self._offset = dinfo, offset
        info = RRN.NewStructure("com.robotraconteur.datetime.clock.ClockDeviceInfo")
        info.device_info = dinfo
        info.clock_type = RRN.GetConstants("com.robotraconteur.datetime")["ClockTypeCode"]["system_rtc_clock"]
        info.timezone_utc_offset_seconds, info.timezone_name, info.extended = 7200, "Europe/Berlin", {}
        self.clock_info = info

    def step(self):
        now = time.time() + self._offset
        if hasattr(self, "time_utc"):
            self.time_utc.OutValue = utc(now)
        if hasattr(self, "time_local"):
            loc = RRN.NewStructure("com.robotraconteur.datetime.DateTimeLocal")
            loc.clock_info = utc(now)["clock_info"].copy()
            loc.seconds, loc.nanoseconds = int(now), int((now - int(now)) * 1e9)
            loc.utc_offset_seconds, loc.timezone_name = 7200, "Europe/Berlin"
            self.time_local.OutValue = loc


class SimEventLog:
    def __init__(self, dinfo):
        self.device_info = dinfo
        c = RRN.GetConstants("com.robotraconteur.eventlog")["EventLogLevel"]
        self._levels = c
        self._lock = threading.Lock()
        self._messages = []
        for n in range(1, 51):
            if n % 10 == 0:
                self._add(n, "error", f"conveyor jam at station {n // 10}", "belt stopped: part stuck at the transfer")
            elif n % 3 == 0:
                self._add(n, "warning", "air pressure low", f"{5.2 + n / 100:.2f} bar, below 5.5 bar")
            else:
                self._add(n, "info", "cycle done", f"cycle {n} in {12 + n % 4}.{n % 10} s")
        self._heartbeats = 0

    def _add(self, n, level, title, message):
        m = RRN.NewStructure("com.robotraconteur.eventlog.EventLogMessage")
        h = RRN.NewStructure("com.robotraconteur.eventlog.EventLogMessageHeader")
        t = RRN.NewStructure("com.robotraconteur.eventlog.EventLogType")
        t.event_category, t.event_type = identifier("cell"), "status"
        h.type, h.level = t, self._levels[level]
        h.source_device, h.source_component, h.source_object = identifier("cell3_plc"), "line", f"station{1 + n % 4}"
        h.message_number = n
        h.timestamp = utc(time.time() - (60 - n))
        m.header, m.title, m.message, m.extended = h, title, message, {}
        with self._lock:
            self._messages.append(m)
        return m

    @property
    def eventlog_info(self):
        info = RRN.NewStructure("com.robotraconteur.eventlog.EventLogInfo")
        info.device_info, info.logged_device, info.extended = self.device_info, identifier("cell3_plc"), {}
        with self._lock:
            info.min_message_number = self._messages[0].header.message_number
            info.max_message_number = self._messages[-1].header.message_number
        return info

    def getf_eventlog_messages(self, start, count):
        if count > 1000:
            raise RR.InvalidArgumentException("at most 1000 messages per request")
        with self._lock:
            return [m for m in self._messages if start <= m.header.message_number < start + count]

    def eventlog_clear_messages(self, offset, count):
        raise RR.InvalidOperationException("this log keeps its messages")

    def eventlog_clear_all_messages(self):
        raise RR.InvalidOperationException("this log keeps its messages")

    def step(self):
        self._heartbeats += 1
        with self._lock:
            n = self._messages[-1].header.message_number + 1
        m = self._add(n, "info", f"heartbeat {self._heartbeats}", "the cell controller is alive")
        if hasattr(self, "eventlog_message_stream"):
            self.eventlog_message_stream.AsyncSendPacket(m, lambda: None)


class Billboard:
    def __init__(self, dinfo):
        self.device_info = dinfo


class Planner:
    def __init__(self):
        self.last_plan = self._plan(2.0, 1.0)
        g = RRN.NewStructure("com.robotraconteur.pid.PIDParam")
        g.p, g.i, g.d, g.imax, g.imin, g.cmd_max, g.cmd_min = 2.5, 0.1, 0.02, 5.0, -5.0, 10.0, -10.0
        self.gains = g

    def _plan(self, duration, swing):
        T = "com.robotraconteur.robotics.trajectory"
        units = RRN.GetConstants("com.robotraconteur.robotics.joints")["JointPositionUnits"]
        t = RRN.NewStructure(f"{T}.JointTrajectory")
        t.joint_names, t.joint_units, t.extended = ["shoulder", "elbow", "wrist"], [units["radian"]] * 3, {}
        wps = []
        for k in range(11):
            w = RRN.NewStructure(f"{T}.JointTrajectoryWaypoint")
            s = k / 10
            w.joint_position = np.array([swing * 0.8 * s, swing * 0.5 * np.sin(np.pi * s), -swing * 0.3 * s])
            w.joint_velocity = np.zeros(3)
            w.position_tolerance, w.velocity_tolerance = np.zeros(3), np.zeros(3)
            w.interpolation_mode, w.waypoint_type = 0, 0
            w.time_from_start = duration * s
            wps.append(w)
        t.waypoints = wps
        return t

    def plan(self, duration):
        if not (0 < duration <= 60):
            raise RR.InvalidArgumentException("duration must be in (0, 60] s")
        return self._plan(duration, 2.0)


class PartGenerator:
    def __init__(self, parts):
        self._parts = list(parts)

    def Next(self):
        if not self._parts:
            raise RR.StopIterationException("")
        return self._parts.pop(0)

    def Close(self):
        self._parts = []

    def Abort(self):
        self._parts = []


class Storage:
    def __init__(self, dinfo):
        self.device_info = dinfo
        self._buckets = {"programs": ("robot programs", {"pick_place.txt": PICK_PLACE, "calibration.yml": CALIBRATION}),
                         "empty": ("nothing yet", {})}
        infos = []
        for name, (description, items) in self._buckets.items():
            b = RRN.NewStructure("com.robotraconteur.resource.BucketInfo")
            b.identifier, b.keys, b.description, b.extended = identifier(name), list(items), description, {}
            infos.append(b)
        self.resource_bucket_info = infos

    def _find(self, identifier):
        bucket = self._buckets.get(identifier.bucket.name)
        if bucket is None or identifier.key not in bucket[1]:
            raise RR.InvalidArgumentException(f"no resource {identifier.bucket.name}/{identifier.key}")
        return bucket[1][identifier.key]

    def resource_get_info(self, identifier):
        data = self._find(identifier)
        i = RRN.NewStructure("com.robotraconteur.resource.ResourceInfo")
        i.identifier, i.key, i.total_size = identifier, identifier.key, len(data)
        i.created = utc(1_700_000_000)
        i.modified = utc(1_790_000_000)
        i.description, i.extended = f"{identifier.key} ({len(data)} bytes)", {}
        return i

    def resource_get(self, identifier):
        data, info = self._find(identifier), self.resource_get_info(identifier)
        parts = []
        for off in range(0, len(data), 1024):
            p = RRN.NewStructure("com.robotraconteur.resource.ResourcePart")
            p.info, p.data_offset, p.data = info, off, np.frombuffer(data[off:off + 1024], dtype=np.uint8)
            parts.append(p)
        return PartGenerator(parts)

    def resource_get_all(self, bucket_identifier):
        raise RR.NotImplementedException("not simulated")

    def resource_bucket_add(self, bucket_identifier):
        raise RR.InvalidOperationException("read-only storage")

    def resource_bucket_delete(self, bucket_identifier):
        raise RR.InvalidOperationException("read-only storage")

    def resource_set(self, identifier, overwrite, resource):
        raise RR.InvalidOperationException("read-only storage")

    def resource_delete(self, identifier):
        raise RR.InvalidOperationException("read-only storage")

    def resource_copy(self, identifier, new_identifier, copy):
        raise RR.InvalidOperationException("read-only storage")


def main():
    die_with_parent()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clock-offset", type=float, default=2.5)
    ap.add_argument("--without-member", default=None)
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    port = free_port()
    with RR.ServerNodeSetup("experimental.sim_misc", port, argv=["misc"] + node_flags(port)):
        if args.without_member:
            RRN.RegisterServiceTypes(definitions_without(args.without_member))
        else:
            RRC.RegisterStdRobDefServiceTypes(RRN)
        RRN.RegisterServiceType(PLANNER_DEF)  # imports only the standard services it names
        loader = InfoFileLoader(RRN)

        def dinfo(name, uuid_tail, description, type_name):
            info, _ = loader.LoadInfoFileFromString(DEVICE_INFO.format(name=name, uuid=f"7c3e5a90-2b4d-4e6f-8a1b-{uuid_tail}", description=json.dumps(description), type=type_name),
                                                    "com.robotraconteur.device.DeviceInfo", "device")
            return info

        clock = SimClock(dinfo("wall_clock", "000000000001", "Cell clock", "com.robotraconteur.datetime.clock.Clock"), args.clock_offset)
        eventlog = SimEventLog(dinfo("cell_log", "000000000002", "Cell 3 event log", "com.robotraconteur.eventlog.EventLogDevice"))
        billboard = Billboard(dinfo("cell_sign", "000000000003", BILLBOARD_TEXT, "com.robotraconteur.device.BillboardDevice"))
        storage = Storage(dinfo("program_store", "000000000004", "Robot program store", "com.robotraconteur.resource.device.ResourceStorageDevice"))
        RRN.RegisterService("clock", "com.robotraconteur.datetime.clock.Clock", clock)
        RRN.RegisterService("log", "com.robotraconteur.eventlog.EventLogDevice", eventlog)
        RRN.RegisterService("billboard", "com.robotraconteur.device.BillboardDevice", billboard)
        RRN.RegisterService("storage", "com.robotraconteur.resource.device.ResourceStorageDevice", storage)
        RRN.RegisterService("planner", "experimental.planner.Planner", Planner())
        stop = threading.Event()

        def loop():
            k = 0
            while not stop.wait(0.1):
                k += 1
                try:
                    clock.step()
                    if k % 10 == 0:
                        eventlog.step()
                except Exception as e:  # a client gone mid-send: keep serving
                    log("misc", f"step: {e}")

        threading.Thread(target=loop, daemon=True).start()
        urls = {n: f"rr+tcp://127.0.0.1:{port}/?service={n}" for n in ("clock", "log", "billboard", "storage", "planner")}
        ready(url=urls["clock"], urls=urls, port=port, clock_offset=args.clock_offset, billboard=BILLBOARD_TEXT,
              resources={"pick_place.txt": hashlib.sha256(PICK_PLACE).hexdigest(), "calibration.yml": hashlib.sha256(CALIBRATION).hexdigest()},
              pid=os.getpid())
        wait_for_stop(args.max_lifetime)
        stop.set()
        log("misc", "stopping")


if __name__ == "__main__":
    main()
