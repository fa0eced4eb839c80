#!/usr/bin/env python3
"""Standard laser scanners on the official Robot Raconteur Python library (standard definitions from the
robotraconteurcompanion package), for the dashboard's laser scanner panel tests: a scanner on a cart in a
room, scanning 270 degrees by 0.5 degrees (541 ranges) at 10 Hz.

The room, in the scanner's frame (x forward, y left, metres): walls at x = -2 and x = 4, y = -2.5 and
y = 2.5 (intensity 100); a round pillar of radius 0.3 at (2, 1) (intensity 200); a person, a circle of
radius 0.25, walking along y at x = 1.5: y = -1.2 + 0.6 sin(t) (intensity 50; never on the ray
straight ahead). Ranges beyond range_max
(10 m) or hidden are not returned (inf).

Services of one node:
  "scanner"  com.robotraconteur.laserscanner.LaserScanner: each scan as one LaserScanf packet
  "parts"    com.robotraconteur.laserscanner.LaserScanPartScanner: each scan as three LaserScanPartf
             packets (data_offset 0, 181, 362 of 541)
Both: scanner_info (LaserScannerInfo: the scan's angles and ranges, scan_rate 10) and one parameter,
"motor_speed" (Hz), through getf_param / setf_param (each set printed as {"param_set": name, "value": v}).

With --hold the person stands still at y = -1.2 (scans differ only in their header); stdin {"walk": true}
or {"hold": true} switches, answered by {"walking": bool}.

Ready line: {"url": ".../?service=scanner", "parts_url": ".../?service=parts", "port": P,
"angle_min", "angle_increment", "count", "range_max"}.

Usage: laser_scanner.py [--hold] [--max-lifetime 300]
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
from param_store import ParamStore  # noqa: E402

import numpy as np  # noqa: E402
import RobotRaconteur as RR  # noqa: E402
import RobotRaconteurCompanion as RRC  # noqa: E402
from RobotRaconteurCompanion.Util.IdentifierUtil import IdentifierUtil  # noqa: E402
from RobotRaconteurCompanion.Util.SensorDataUtil import SensorDataUtil  # noqa: E402

RRN = RR.RobotRaconteurNode.s
_stdout_lock = threading.Lock()

ANGLE_MIN = -0.75 * math.pi
INCREMENT = math.radians(0.5)
COUNT = 541
RANGE_MIN, RANGE_MAX = 0.05, 10.0
WALLS = (-2.0, 4.0, -2.5, 2.5)   # x min, x max, y min, y max
PILLAR = (2.0, 1.0, 0.3)
PERSON_X, PERSON_R = 1.5, 0.25


def emit(value):
    with _stdout_lock:
        sys.stdout.write(json.dumps(value) + "\n")
        sys.stdout.flush()


def ray_circle(c, s, cx, cy, r):
    """Distance along the unit ray (c, s) from the origin to the circle, or inf."""
    b = c * cx + s * cy
    d = b * b - (cx * cx + cy * cy - r * r)
    if d < 0:
        return math.inf
    t = b - math.sqrt(d)
    return t if t > 0 else math.inf


def room_scan(person_y):
    """(ranges, intensities) as float32 arrays of COUNT."""
    ranges = np.full(COUNT, np.inf, dtype=np.float32)
    intensities = np.zeros(COUNT, dtype=np.float32)
    x0, x1, y0, y1 = WALLS
    for i in range(COUNT):
        a = ANGLE_MIN + i * INCREMENT
        c, s = math.cos(a), math.sin(a)
        wall = min(t for t in ((x1 / c) if c > 1e-12 else math.inf, (x0 / c) if c < -1e-12 else math.inf,
                               (y1 / s) if s > 1e-12 else math.inf, (y0 / s) if s < -1e-12 else math.inf) if t > 0)
        hits = [(wall, 100.0), (ray_circle(c, s, *PILLAR), 200.0), (ray_circle(c, s, PERSON_X, person_y, PERSON_R), 50.0)]
        r, inten = min(hits)
        if RANGE_MIN <= r <= RANGE_MAX:
            ranges[i] = r
            intensities[i] = inten
    return ranges, intensities


class ScannerBase(ParamStore):
    def __init__(self, name):
        ParamStore.__init__(self, {"motor_speed": 10.0}, emit)
        ident = IdentifierUtil(RRN)
        self.device_info = RRN.NewStructure("com.robotraconteur.device.DeviceInfo")
        self.device_info.device = ident.CreateIdentifierFromName(name)
        self.device_info.manufacturer = ident.CreateIdentifierFromName("rr-gateway tests")
        self.device_info.model = ident.CreateIdentifierFromName("room-scan-270")
        self.device_info.serial_number = f"{name.upper()}-0001"
        self.device_info.user_description = "test laser scanner in a room"
        info = RRN.NewStructure("com.robotraconteur.laserscanner.LaserScannerInfo")
        info.device_info = self.device_info
        info.scanner_info = self.scan_info(None)
        info.scan_rate = 10.0
        param = RRN.NewStructure("com.robotraconteur.param.ParameterInfo")
        param.parameter_identifier = ident.CreateIdentifierFromName("motor_speed")
        param.description = "mirror motor speed"
        info.param_info = [param]
        self.scanner_info = info
        self._data = SensorDataUtil(RRN)
        self.seqno = 0

    def scan_info(self, header):
        i = RRN.NewStructure("com.robotraconteur.laserscan.LaserScanInfof")
        if header is not None:
            i.data_header = header
        i.angle_min = ANGLE_MIN
        i.angle_max = ANGLE_MIN + (COUNT - 1) * INCREMENT
        i.angle_increment = INCREMENT
        i.angle_count = COUNT
        i.vertical_angle_count = 1
        i.scan_time = 0.1
        i.time_increment = 0.1 / COUNT
        i.range_min = RANGE_MIN
        i.range_max = RANGE_MAX
        i.range_resolution = 0.001
        return i

    def next_info(self):
        self.seqno += 1
        return self.scan_info(self._data.FillSensorDataHeader(self.device_info, self.seqno))


class Scanner(ScannerBase):
    def send(self, ranges, intensities):
        s = RRN.NewStructure("com.robotraconteur.laserscan.LaserScanf")
        s.scan_info = self.next_info()
        s.ranges = ranges
        s.intensities = intensities
        self.laser_scan_sensor_data.SendPacket(s)


class PartScanner(ScannerBase):
    def send(self, ranges, intensities):
        info = self.next_info()
        for start in range(0, COUNT, 181):
            p = RRN.NewStructure("com.robotraconteur.laserscan.LaserScanPartf")
            p.scan_info = info
            p.data_offset = start
            p.data_total_len = COUNT
            p.ranges = np.ascontiguousarray(ranges[start:start + 181])
            p.intensities = np.ascontiguousarray(intensities[start:start + 181])
            self.laser_scan_sensor_data.SendPacket(p)


def main():
    die_with_parent()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hold", action="store_true")
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    port = free_port()
    walking = threading.Event()
    if not args.hold:
        walking.set()
    stop = threading.Event()
    with RR.ServerNodeSetup("experimental.std_laser_scanner", port, argv=["laser_scanner"] + node_flags(port)):
        RRC.RegisterStdRobDefServiceTypes(RRN)
        scanner, parts = Scanner("room_scanner"), PartScanner("room_scanner_parts")
        RRN.RegisterService("scanner", "com.robotraconteur.laserscanner.LaserScanner", scanner)
        RRN.RegisterService("parts", "com.robotraconteur.laserscanner.LaserScanPartScanner", parts)

        def loop():
            t0 = time.monotonic()
            k, t_walk = 0, 0.0
            while not stop.is_set():
                if walking.is_set():
                    t_walk += 0.1
                ranges, intensities = room_scan(-1.2 + 0.6 * math.sin(t_walk))
                for dev in (scanner, parts):
                    try:
                        dev.send(ranges, intensities)
                    except Exception as e:  # a send racing the node's shutdown
                        log("laser_scanner", f"send: {type(e).__name__}: {e}")
                k += 1
                delay = t0 + k * 0.1 - time.monotonic()
                if delay > 0:
                    stop.wait(delay)

        threading.Thread(target=loop, daemon=True).start()

        def commands():
            for line in sys.stdin:
                try:
                    cmd = json.loads(line)
                    if cmd.get("walk"):
                        walking.set()
                    elif cmd.get("hold"):
                        walking.clear()
                    reply = {"walking": walking.is_set()}
                except Exception as e:
                    reply = {"failed": f"{type(e).__name__}: {e}"}
                emit(reply)

        threading.Thread(target=commands, daemon=True).start()
        ready(url=f"rr+tcp://127.0.0.1:{port}/?service=scanner", parts_url=f"rr+tcp://127.0.0.1:{port}/?service=parts",
              port=port, angle_min=ANGLE_MIN, angle_increment=INCREMENT, count=COUNT, range_max=RANGE_MAX, pid=os.getpid())
        wait_for_stop(args.max_lifetime)
        stop.set()
        log("laser_scanner", "stopping")


if __name__ == "__main__":
    main()
