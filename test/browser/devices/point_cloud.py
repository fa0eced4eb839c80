#!/usr/bin/env python3
"""Standard point cloud sensors on the official Robot Raconteur Python library (standard definitions from
the robotraconteurcompanion package), for the dashboard's point cloud panel tests and bench: a depth
sensor above a table with a few objects on it, at --rate Hz (default 10).

The scene, in the sensor's frame (metres, z up): a table top of 1.2 x 0.8 m at z = 0 (grey, intensity
40), a red box of 0.3 m at (0.3, 0.15, 0.15) (intensity 200), a green ball of radius 0.12 rolling on a
circle of 0.25 m around (-0.25, -0.05) (intensity 120; with --hold it stays at its start, angle 0), a
blue post of radius 0.05 and 0.4 m high at (-0.45, 0.3) (intensity 80). --points N (default 20000)
points spread over the surfaces by area, the same every frame but for the ball's. Bounds: the table's
box (x -0.6..0.6, y -0.4..0.4, z 0..0.4).

Services of one node (all: point_sensor_info with bounds, resolution 0.005 m, one parameter
"exposure" (ms) through getf_param / setf_param, each set printed as {"param_set": name, "value": v}):
  "cloud"   com.robotraconteur.pointcloud.sensor.PointCloudSensor: point_cloud_sensor_data (PointCloudf:
            positions only) and capture_point_cloud()
  "cloud2"  PointCloud2Sensor: also point_cloud2_sensor_data (PointCloud2f: each point's intensity, its
            colour as PixelRGBFloatPackedf (the float's bits are 0x00RRGGBB, as PCL packs rgb), normal)
  "parts"   PointCloudPartSensor: each cloud as --parts packets (points_offset, points_total_len)
  "parts2"  PointCloud2PartSensor: the same for PointCloud2Partf

stdin {"hold": true} / {"roll": true} stops or starts the ball, answered by {"rolling": bool}.
--without-member NAME serves definitions whose point cloud sensors lack member NAME (an older or trimmed
release), for the fallback tests.

Ready line: {"url": ".../?service=cloud", "urls": {service: url}, "port": P, "points": N, "ball": [x, y, z]}.

Usage: point_cloud.py [--points 20000] [--rate 10] [--parts 3] [--hold] [--without-member NAME] [--max-lifetime 300]
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
from device_parts import PartGenerator, definitions_without  # noqa: E402

import numpy as np  # noqa: E402
import RobotRaconteur as RR  # noqa: E402
import RobotRaconteurCompanion as RRC  # noqa: E402
from RobotRaconteurCompanion.Util.IdentifierUtil import IdentifierUtil  # noqa: E402
from RobotRaconteurCompanion.Util.SensorDataUtil import SensorDataUtil  # noqa: E402

RRN = RR.RobotRaconteurNode.s
_stdout_lock = threading.Lock()
PC = "com.robotraconteur.pointcloud"
SENSOR = "com.robotraconteur.pointcloud.sensor"

TABLE = (1.2, 0.8)
BOX = ((0.3, 0.15, 0.15), 0.3, (230, 40, 40), 200.0)           # centre, edge, colour, intensity
BALL = ((-0.25, -0.05), 0.25, 0.12, (40, 200, 60), 120.0)      # circle centre, circle radius, radius, ...
POST = ((-0.45, 0.3), 0.05, 0.4, (50, 90, 230), 80.0)          # centre, radius, height, ...
TABLE_LOOK = ((150, 150, 150), 40.0)


def emit(value):
    with _stdout_lock:
        sys.stdout.write(json.dumps(value) + "\n")
        sys.stdout.flush()


def packed_rgb(rgb):
    """PCL's packed colour: the float32 whose bits are 0x00RRGGBB."""
    r, g, b = rgb
    return np.array([(r << 16) | (g << 8) | b], dtype=np.uint32).view(np.float32)[0]


class Scene:
    """The static points (table, box, post) made once and the ball's, moved each frame."""

    def __init__(self, n):
        rng = np.random.default_rng(54)
        areas = {"table": TABLE[0] * TABLE[1], "box": 5 * BOX[1] ** 2, "ball": 2 * math.pi * BALL[2] ** 2,
                 "post": 2 * math.pi * POST[1] * POST[2] + math.pi * POST[1] ** 2}
        total = sum(areas.values())
        counts = {k: int(n * a / total) for k, a in areas.items()}
        counts["table"] += n - sum(counts.values())
        parts = []  # (xyz, normal, rgb, intensity)
        # table top: uniform on the rectangle, less where the box and post stand (kept: a sensor sees around)
        k = counts["table"]
        xyz = np.stack([rng.uniform(-TABLE[0] / 2, TABLE[0] / 2, k), rng.uniform(-TABLE[1] / 2, TABLE[1] / 2, k), np.zeros(k)], 1)
        parts.append((xyz, np.tile([0.0, 0.0, 1.0], (k, 1)), TABLE_LOOK[0], TABLE_LOOK[1]))
        # box: the top and four sides
        (bx, by, bz), e, rgb, inten = BOX
        k = counts["box"]
        face = rng.integers(0, 5, k)
        u, v = rng.uniform(-e / 2, e / 2, k), rng.uniform(-e / 2, e / 2, k)
        xyz, nrm = np.zeros((k, 3)), np.zeros((k, 3))
        for f, (axis, sign) in enumerate([(2, 1), (0, 1), (0, -1), (1, 1), (1, -1)]):
            m = face == f
            other = [a for a in range(3) if a != axis]
            xyz[m, axis] = sign * e / 2
            xyz[m, other[0]], xyz[m, other[1]] = u[m], v[m]
            nrm[m, axis] = sign
        parts.append((xyz + [bx, by, bz], nrm, rgb, inten))
        # post: the side and the top
        (px, py), r, hgt, rgb, inten = POST
        k = counts["post"]
        a = rng.uniform(0, 2 * math.pi, k)
        top = rng.uniform(0, 1, k) < (math.pi * r * r) / areas["post"]
        rr = np.where(top, r * np.sqrt(rng.uniform(0, 1, k)), r)
        xyz = np.stack([px + rr * np.cos(a), py + rr * np.sin(a), np.where(top, hgt, rng.uniform(0, hgt, k))], 1)
        nrm = np.where(top[:, None], [0.0, 0.0, 1.0], np.stack([np.cos(a), np.sin(a), np.zeros(k)], 1))
        parts.append((xyz, nrm, rgb, inten))
        self.static = parts
        # ball: the upper half of a sphere (what a sensor above sees), relative to its centre
        k = counts["ball"]
        d = rng.normal(size=(k, 3))
        d /= np.linalg.norm(d, axis=1)[:, None]
        d[:, 2] = np.abs(d[:, 2])
        self.ball_dirs = d
        self.n = n

    def ball_centre(self, angle):
        (cx, cy), orbit, r, _, _ = BALL
        return (cx + orbit * math.cos(angle), cy + orbit * math.sin(angle), r)

    def frame(self, angle):
        """(xyz float32 [n,3], normals float32 [n,3], packed rgb float32 [n], intensity float32 [n])."""
        c = np.array(self.ball_centre(angle))
        parts = self.static + [(c + BALL[2] * self.ball_dirs, self.ball_dirs, BALL[3], BALL[4])]
        xyz = np.concatenate([p[0] for p in parts]).astype(np.float32)
        nrm = np.concatenate([p[1] for p in parts]).astype(np.float32)
        rgb = np.concatenate([np.full(len(p[0]), packed_rgb(p[2]), dtype=np.float32) for p in parts])
        inten = np.concatenate([np.full(len(p[0]), p[3], dtype=np.float32) for p in parts])
        return xyz, nrm, rgb, inten


def bounds(geometry="com.robotraconteur.geometry"):
    """The table's box as a BoundingBox (centre pose and size) of `geometry` (geometry or geometryf)."""
    b = RRN.NewStructure(f"{geometry}.BoundingBox")
    centre = RRN.NewStructure(f"{geometry}.NamedPose")
    pose = np.zeros((1,), dtype=RRN.GetNamedArrayDType(f"{geometry}.Pose"))
    pose[0]["orientation"]["w"] = 1.0
    pose[0]["position"]["z"] = 0.2
    centre.pose = pose
    b.center = centre
    size = np.zeros((1,), dtype=RRN.GetNamedArrayDType(f"{geometry}.Size"))
    size[0] = (TABLE[0], TABLE[1], 0.4)
    b.size = size
    return b


def boundsf():
    return bounds("com.robotraconteur.geometryf")


class CloudSensor(ParamStore):
    """One of the four services; `kind` is "cloud", "cloud2", "parts" or "parts2"."""

    def __init__(self, kind, parts):
        ParamStore.__init__(self, {"exposure": 8.0}, emit)
        self.kind, self.parts = kind, parts
        ident = IdentifierUtil(RRN)
        self.device_info = RRN.NewStructure("com.robotraconteur.device.DeviceInfo")
        self.device_info.device = ident.CreateIdentifierFromName(f"table_depth_{kind}")
        self.device_info.manufacturer = ident.CreateIdentifierFromName("rr-gateway tests")
        self.device_info.model = ident.CreateIdentifierFromName("table-depth-sensor")
        self.device_info.serial_number = f"DEPTH-{kind.upper()}-0001"
        self.device_info.user_description = "test depth sensor above a table"
        info = RRN.NewStructure(f"{SENSOR}.PointCloudSensorInfo")
        info.device_info = self.device_info
        info.bounds = bounds()
        res = np.zeros((1,), dtype=RRN.GetNamedArrayDType("com.robotraconteur.geometry.Vector3"))
        res[0] = (0.005, 0.005, 0.005)
        info.resolution = res
        param = RRN.NewStructure("com.robotraconteur.param.ParameterInfo")
        param.parameter_identifier = ident.CreateIdentifierFromName("exposure")
        param.description = "exposure time (ms)"
        info.param_info = [param]
        self.point_sensor_info = info
        self._data = SensorDataUtil(RRN)
        self.seqno = 0
        self.latest = None
        self._lock = threading.Lock()
        self._pointf = RRN.GetNamedArrayDType(f"com.robotraconteur.geometryf.Point")
        self._point2f = RRN.GetNamedArrayDType(f"{PC}.PointCloud2Pointf")

    # the values the official library sends
    def cloud(self, xyz, part=None):
        name = "PointCloudPartf" if part else "PointCloudf"
        c = RRN.NewStructure(f"{PC}.{name}")
        c.bounds = boundsf()
        c.is_dense = True
        pts = np.zeros((len(xyz),), dtype=self._pointf)
        pts["x"], pts["y"], pts["z"] = xyz[:, 0], xyz[:, 1], xyz[:, 2]
        c.points = pts
        c.extended = {}
        if part:
            c.points_offset, c.points_total_len = part
        return c

    def cloud2(self, frame, part=None, sl=slice(None)):
        xyz, nrm, rgb, inten = (a[sl] for a in frame)
        name = "PointCloud2Partf" if part else "PointCloud2f"
        c = RRN.NewStructure(f"{PC}.{name}")
        c.bounds = boundsf()
        c.is_dense = True
        pts = np.zeros((len(xyz),), dtype=self._point2f)
        for i, k in enumerate("xyz"):
            pts["point"][k] = xyz[:, i]
            pts["normal"][k] = nrm[:, i]
        pts["intensity"] = inten
        pts["rgb"]["rgb"] = rgb
        c.points = pts
        c.extended = {}
        if part:
            c.points_offset, c.points_total_len = part
        return c

    def capture_point_cloud(self):
        with self._lock:
            frame = self.latest
        if frame is None:
            raise RR.InvalidOperationException("no frame yet")
        if self.kind in ("parts", "parts2"):
            return PartGenerator([self.cloud(frame[0][s], (s.start, len(frame[0]))) for s in self.slices(len(frame[0]))])
        return self.cloud(frame[0])

    def capture_point_cloud2(self):
        with self._lock:
            frame = self.latest
        if frame is None:
            raise RR.InvalidOperationException("no frame yet")
        if self.kind == "parts2":
            return PartGenerator([self.cloud2(frame, (s.start, len(frame[0])), s) for s in self.slices(len(frame[0]))])
        return self.cloud2(frame)

    def slices(self, n):
        step = -(-n // self.parts)
        return [slice(a, min(n, a + step)) for a in range(0, n, step)]

    def header(self):
        """The pipes' sensor_data: a SensorData holding the header (no samples of its own)."""
        self.seqno += 1
        d = RRN.NewStructure("com.robotraconteur.sensor.SensorData")
        d.data_header = self._data.FillSensorDataHeader(self.device_info, self.seqno)
        d.data_flags = 0
        d.data = np.zeros((0,), dtype=np.float64)
        return d

    def send(self, frame):
        with self._lock:
            self.latest = frame
        header = self.header()
        n = len(frame[0])
        # the pipes the definitions served have (--without-member takes one away)
        pipe1 = getattr(self, "point_cloud_sensor_data", None)
        pipe2 = getattr(self, "point_cloud2_sensor_data", None) if self.kind in ("cloud2", "parts2") else None
        if self.kind in ("cloud", "cloud2"):
            if pipe1 is not None:
                d = RRN.NewStructure(f"{SENSOR}.PointCloudSensorData")
                d.sensor_data, d.point_cloud = header, self.cloud(frame[0])
                pipe1.SendPacket(d)
            if pipe2 is not None:
                d2 = RRN.NewStructure(f"{SENSOR}.PointCloud2SensorData")
                d2.sensor_data, d2.point_cloud = header, self.cloud2(frame)
                pipe2.SendPacket(d2)
            return
        for s in self.slices(n):
            if pipe1 is not None:
                d = RRN.NewStructure(f"{SENSOR}.PointCloudPartSensorData")
                d.sensor_data, d.point_cloud = header, self.cloud(frame[0][s], (s.start, n))
                pipe1.SendPacket(d)
            if pipe2 is not None:
                d2 = RRN.NewStructure(f"{SENSOR}.PointCloud2PartSensorData")
                d2.sensor_data, d2.point_cloud = header, self.cloud2(frame, (s.start, n), s)
                pipe2.SendPacket(d2)


def main():
    die_with_parent()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=20000)
    ap.add_argument("--rate", type=float, default=10.0)
    ap.add_argument("--parts", type=int, default=3)
    ap.add_argument("--hold", action="store_true")
    ap.add_argument("--services", default="cloud,cloud2,parts,parts2", help="which services to serve")
    ap.add_argument("--without-member", default=None)
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    port = free_port()
    rolling = threading.Event()
    if not args.hold:
        rolling.set()
    stop = threading.Event()
    scene = Scene(args.points)
    types = {"cloud": "PointCloudSensor", "cloud2": "PointCloud2Sensor", "parts": "PointCloudPartSensor", "parts2": "PointCloud2PartSensor"}
    with RR.ServerNodeSetup("experimental.std_point_cloud", port, argv=["point_cloud"] + node_flags(port)):
        if args.without_member:
            RRN.RegisterServiceTypes(definitions_without([SENSOR], args.without_member))
        else:
            RRC.RegisterStdRobDefServiceTypes(RRN)
        sensors, urls = {}, {}
        for service in args.services.split(","):
            sensors[service] = CloudSensor(service, max(1, args.parts))
            RRN.RegisterService(service, f"{SENSOR}.{types[service]}", sensors[service])
            urls[service] = f"rr+tcp://127.0.0.1:{port}/?service={service}"

        def loop():
            t0 = time.monotonic()
            k, angle = 0, 0.0
            period = 1.0 / args.rate
            while not stop.is_set():
                if rolling.is_set():
                    angle += 2 * math.pi * period / 6  # one turn in 6 s
                frame = scene.frame(angle)
                for dev in sensors.values():
                    try:
                        dev.send(frame)
                    except Exception as e:  # a send racing the node's shutdown, or no client yet
                        log("point_cloud", f"send: {type(e).__name__}: {e}")
                k += 1
                delay = t0 + k * period - time.monotonic()
                if delay > 0:
                    stop.wait(delay)
                elif delay < -1:
                    t0, k = time.monotonic(), 0  # fell behind (a slow machine): no burst to catch up

        threading.Thread(target=loop, daemon=True).start()

        def commands():
            for line in sys.stdin:
                try:
                    cmd = json.loads(line)
                    if cmd.get("roll"):
                        rolling.set()
                    elif cmd.get("hold"):
                        rolling.clear()
                    reply = {"rolling": rolling.is_set()}
                except Exception as e:
                    reply = {"failed": f"{type(e).__name__}: {e}"}
                emit(reply)

        threading.Thread(target=commands, daemon=True).start()
        first = next(iter(urls.values()))
        with _stdout_lock:
            ready(url=first, urls=urls, port=port, points=args.points, ball=list(scene.ball_centre(0.0)), pid=os.getpid())
        wait_for_stop(args.max_lifetime)
        stop.set()
        log("point_cloud", "stopping")


if __name__ == "__main__":
    main()
