#!/usr/bin/env python3
"""A fiducial sensor and an object recognition sensor on the official Robot Raconteur Python library
(standard definitions from the robotraconteurcompanion package), for the dashboard's detections panel
tests. Both send their detections at 5 Hz in the frame "camera_link" (metres, quaternion w first):

  "tags"     com.robotraconteur.fiducial.FiducialSensor: ArUco markers "aruco_4x4:7" at (0.4, 0.1, 1.2)
             turned 90 degrees about z, confidence 0.98, and "aruco_4x4:12" at (-0.25, 0, 0.8), confidence
             0.9 (x moves by 0.05 sin t unless --hold); fiducial_sensor_info lists the dictionary.
  "objects"  com.robotraconteur.objectrecognition.ObjectRecognitionSensor: "mug" (class "cup") at
             (0.3, -0.1, 0.75), confidence 0.87, and "gearbox" (class "part") at (0, 0.2, 0.9), 0.61.

Both: capture_* gives the current detections; parameter "threshold" through getf_param / setf_param
(each set printed as {"param_set": name, "value": v}).

Ready line: {"url": ".../?service=tags", "objects_url": ".../?service=objects", "port": P}.

Usage: detections.py [--hold] [--without-member NAME] [--max-lifetime 300]
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
from device_parts import definitions_without  # noqa: E402

import numpy as np  # noqa: E402
import RobotRaconteur as RR  # noqa: E402
import RobotRaconteurCompanion as RRC  # noqa: E402
from RobotRaconteurCompanion.Util.IdentifierUtil import IdentifierUtil  # noqa: E402
from RobotRaconteurCompanion.Util.SensorDataUtil import SensorDataUtil  # noqa: E402

RRN = RR.RobotRaconteurNode.s
_stdout_lock = threading.Lock()
FID = "com.robotraconteur.fiducial"
OBJ = "com.robotraconteur.objectrecognition"
TAGS = [("aruco_4x4:7", (0.4, 0.1, 1.2), 90.0, 0.98), ("aruco_4x4:12", (-0.25, 0.0, 0.8), 0.0, 0.9)]
OBJECTS = [("mug", "cup", (0.3, -0.1, 0.75), 0.87), ("gearbox", "part", (0.0, 0.2, 0.9), 0.61)]


def emit(value):
    with _stdout_lock:
        sys.stdout.write(json.dumps(value) + "\n")
        sys.stdout.flush()


def pose_with_covariance(ident, position, yaw_deg):
    p = RRN.NewStructure("com.robotraconteur.geometry.NamedPoseWithCovariance")
    named = RRN.NewStructure("com.robotraconteur.geometry.NamedPose")
    named.parent_frame = ident.CreateIdentifierFromName("camera_link")
    pose = np.zeros((1,), dtype=RRN.GetNamedArrayDType("com.robotraconteur.geometry.Pose"))
    half = math.radians(yaw_deg) / 2
    pose[0]["orientation"] = (math.cos(half), 0.0, 0.0, math.sin(half))
    pose[0]["position"] = position
    named.pose = pose
    p.pose = named
    p.covariance = np.zeros((6, 6))
    return p


def device_info(name, ident):
    d = RRN.NewStructure("com.robotraconteur.device.DeviceInfo")
    d.device = ident.CreateIdentifierFromName(name)
    d.manufacturer = ident.CreateIdentifierFromName("rr-gateway tests")
    d.model = ident.CreateIdentifierFromName("detector")
    d.serial_number = f"{name.upper()}-0001"
    d.user_description = f"test {name}"
    return d


def range_box():
    b = RRN.NewStructure("com.robotraconteur.geometry.BoundingBox")
    c = RRN.NewStructure("com.robotraconteur.geometry.NamedPose")
    pose = np.zeros((1,), dtype=RRN.GetNamedArrayDType("com.robotraconteur.geometry.Pose"))
    pose[0]["orientation"]["w"] = 1.0
    pose[0]["position"]["z"] = 1.5
    c.pose = pose
    b.center = c
    size = np.zeros((1,), dtype=RRN.GetNamedArrayDType("com.robotraconteur.geometry.Size"))
    size[0] = (2.0, 1.5, 3.0)
    b.size = size
    return b


def resolution():
    r = np.zeros((1,), dtype=RRN.GetNamedArrayDType("com.robotraconteur.geometry.Vector3"))
    r[0] = (0.002, 0.002, 0.002)
    return r


def param_info(ident):
    p = RRN.NewStructure("com.robotraconteur.param.ParameterInfo")
    p.parameter_identifier = ident.CreateIdentifierFromName("threshold")
    p.description = "detection threshold"
    return [p]


class Detector(ParamStore):
    def __init__(self, ident, hold):
        ParamStore.__init__(self, {"threshold": 0.5}, emit)
        self.ident, self.hold = ident, hold
        self._data = SensorDataUtil(RRN)
        self.seqno = 0
        self.t = 0.0

    def header(self):
        self.seqno += 1
        return self._data.FillSensorDataHeader(self.device_info, self.seqno)

    def dx(self):
        return 0.0 if self.hold else 0.05 * math.sin(self.t)


class Tags(Detector):
    def __init__(self, ident, hold):
        Detector.__init__(self, ident, hold)
        self.device_info = device_info("tag_camera", ident)
        info = RRN.NewStructure(f"{FID}.FiducialSensorInfo")
        info.device_info = self.device_info
        info.range = range_box()
        info.resolution = resolution()
        info.param_info = param_info(ident)
        fi = RRN.NewStructure(f"{FID}.FiducialInfo")
        fi.fiducial_marker_class = ident.CreateIdentifierFromName("aruco_4x4_50")
        fi.fiducial_marker_range = "0-49"
        info.fiducial_info = [fi]
        self.fiducial_sensor_info = info

    def capture_fiducials(self):
        out = RRN.NewStructure(f"{FID}.RecognizedFiducials")
        out.recognized_fiducials = []
        for k, (marker, (x, y, z), yaw, conf) in enumerate(TAGS):
            f = RRN.NewStructure(f"{FID}.RecognizedFiducial")
            f.fiducial_marker_class = self.ident.CreateIdentifierFromName("aruco_4x4_50")
            f.fiducial_marker = marker
            f.pose = pose_with_covariance(self.ident, (x + (self.dx() if k == 0 else 0.0), y, z), yaw)
            f.confidence = conf
            out.recognized_fiducials.append(f)
        return out

    def send(self):
        d = RRN.NewStructure(f"{FID}.FiducialSensorData")
        d.sensor_data = self.header()
        d.fiducials = self.capture_fiducials()
        p = getattr(self, "fiducials_sensor_data", None)
        if p is not None:
            p.SendPacket(d)


class Objects(Detector):
    def __init__(self, ident, hold):
        Detector.__init__(self, ident, hold)
        self.device_info = device_info("object_camera", ident)
        info = RRN.NewStructure(f"{OBJ}.ObjectRecognitionSensorInfo")
        info.device_info = self.device_info
        info.range = range_box()
        info.resolution = resolution()
        info.param_info = param_info(ident)
        info.object_template_identifiers = [ident.CreateIdentifierFromName(n) for n, *_ in OBJECTS]
        self.object_recognition_sensor_info = info

    def capture_recognized_objects(self):
        out = RRN.NewStructure(f"{OBJ}.RecognizedObjects")
        out.recognized_objects = []
        for name, cls, pos, conf in OBJECTS:
            o = RRN.NewStructure(f"{OBJ}.RecognizedObject")
            o.recognized_object = self.ident.CreateIdentifierFromName(name)
            c = RRN.NewStructure("com.robotraconteur.device.DeviceClass")
            c.class_identifier = self.ident.CreateIdentifierFromName(cls)
            c.subclasses = []
            o.recognized_object_class = c
            o.pose = pose_with_covariance(self.ident, pos, 0.0)
            o.confidence = conf
            out.recognized_objects.append(o)
        return out

    def send(self):
        d = RRN.NewStructure(f"{OBJ}.ObjectRecognitionSensorData")
        d.sensor_data = self.header()
        d.recognized_objects = self.capture_recognized_objects()
        p = getattr(self, "object_recognition_sensor_data", None)
        if p is not None:
            p.SendPacket(d)


def main():
    die_with_parent()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hold", action="store_true")
    ap.add_argument("--without-member", default=None)
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    port = free_port()
    stop = threading.Event()
    with RR.ServerNodeSetup("experimental.std_detections", port, argv=["detections"] + node_flags(port)):
        if args.without_member:
            RRN.RegisterServiceTypes(definitions_without([FID, OBJ], args.without_member))
        else:
            RRC.RegisterStdRobDefServiceTypes(RRN)
        ident = IdentifierUtil(RRN)
        tags, objects = Tags(ident, args.hold), Objects(ident, args.hold)
        RRN.RegisterService("tags", f"{FID}.FiducialSensor", tags)
        RRN.RegisterService("objects", f"{OBJ}.ObjectRecognitionSensor", objects)

        def loop():
            while not stop.wait(0.2):
                for dev in (tags, objects):
                    dev.t += 0.2
                    try:
                        dev.send()
                    except Exception as e:  # a send racing the node's shutdown
                        log("detections", f"send: {type(e).__name__}: {e}")

        threading.Thread(target=loop, daemon=True).start()
        with _stdout_lock:
            ready(url=f"rr+tcp://127.0.0.1:{port}/?service=tags", objects_url=f"rr+tcp://127.0.0.1:{port}/?service=objects",
                  port=port, pid=os.getpid())
        wait_for_stop(args.max_lifetime)
        stop.set()
        log("detections", "stopping")


if __name__ == "__main__":
    main()
