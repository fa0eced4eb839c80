#!/usr/bin/env python3
"""Cameras beyond one on the official Robot Raconteur Python library (standard definitions from the
robotraconteurcompanion package), for the dashboard's MultiCamera and ImagePartCamera panel tests.

Each camera k sends 64 x 48 frames at 5 Hz while streaming: the whole frame in the camera's colour
(COLORS[k]) but for a white 8 x 8 square whose column is the frame number mod 8 (so a frame that moves
on shows). Previews are PNG (exact pixels), raw frames rgb888.

Services of one node:
  "rig"    com.robotraconteur.imaging.MultiCamera of three cameras, camera_names {0: "left", 1: "centre",
           2: "right"}: preview_stream_all and frame_stream_compressed_all (CompressedImage{int32}, PNG),
           frame_stream_all (Image{int32}), capture_frame_all(), trigger_all() (each call printed as
           {"triggered": n}), multicamera_info; the cameras objref gives each as a Camera (streaming with the rig).
  "parts"  com.robotraconteur.imaging.ImagePartCamera (camera 3's colour): start_streaming / stop_streaming,
           camera_state, preview_stream (PNG), capture_frame() yielding the raw frame as ImageParts of
           --part-bytes bytes (each capture printed as {"captured_parts": n, "frame": k}).
The rig streams from the start; the part camera when started.

Ready line: {"url": ".../?service=rig", "parts_url": ".../?service=parts", "port": P, "colors": [...], "size": [64, 48]}.

--without-member NAME[,NAME...] serves imaging definitions without those members (an older or trimmed release).

Usage: multi_camera.py [--part-bytes 2000] [--without-member NAME[,NAME]] [--max-lifetime 300]
"""

import argparse
import json
import os
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import die_with_parent, free_port, node_flags, ready, wait_for_stop, log  # noqa: E402
from device_parts import PartGenerator, definitions_without  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402
import RobotRaconteur as RR  # noqa: E402
import RobotRaconteurCompanion as RRC  # noqa: E402
from RobotRaconteurCompanion.Util.IdentifierUtil import IdentifierUtil  # noqa: E402

RRN = RR.RobotRaconteurNode.s
_stdout_lock = threading.Lock()
IMAGING = "com.robotraconteur.imaging"
W, H = 64, 48
COLORS = [(220, 60, 40), (40, 170, 80), (50, 90, 220), (200, 160, 30)]
NAMES = {0: "left", 1: "centre", 2: "right"}


def emit(value):
    with _stdout_lock:
        sys.stdout.write(json.dumps(value) + "\n")
        sys.stdout.flush()


def frame_rgb(k, n):
    """Camera k's frame n as an H x W x 3 uint8 RGB array."""
    a = np.empty((H, W, 3), dtype=np.uint8)
    a[:, :] = COLORS[k]
    x = (n % 8) * 8
    a[0:8, x:x + 8] = 255
    return a


def device_info(name, ident):
    d = RRN.NewStructure("com.robotraconteur.device.DeviceInfo")
    d.device = ident.CreateIdentifierFromName(name)
    d.manufacturer = ident.CreateIdentifierFromName("rr-gateway tests")
    d.model = ident.CreateIdentifierFromName("colour-camera")
    d.serial_number = f"{name.upper()}-0001"
    d.user_description = f"test camera {name}"
    return d


class Frames:
    """Makes the standard image values of one camera's frames."""

    def __init__(self, k):
        self.k = k
        self.n = 0
        enc = RRN.GetConstants("com.robotraconteur.image")["ImageEncoding"]
        self.rgb888, self.compressed = enc["rgb888"], enc["compressed"]

    def info(self, encoding, step):
        i = RRN.NewStructure("com.robotraconteur.image.ImageInfo")
        i.width, i.height, i.step, i.encoding = W, H, step, encoding
        return i

    def raw(self, n):
        f = RRN.NewStructure("com.robotraconteur.image.Image")
        f.image_info = self.info(self.rgb888, W * 3)
        f.data = np.ascontiguousarray(frame_rgb(self.k, n).reshape(-1))
        return f

    def png(self, n):
        ok, png = cv2.imencode(".png", frame_rgb(self.k, n)[..., ::-1])
        f = RRN.NewStructure("com.robotraconteur.image.CompressedImage")
        f.image_info = self.info(self.compressed, 0)
        f.data = png.reshape(-1)
        return f


class CameraInfoMaker:
    @staticmethod
    def make(name, ident):
        ci = RRN.NewStructure("com.robotraconteur.imaging.camerainfo.CameraInfo")
        ci.device_info = device_info(name, ident)
        cal = RRN.NewStructure("com.robotraconteur.imaging.camerainfo.CameraCalibration")
        size = np.zeros((1,), dtype=RRN.GetNamedArrayDType("com.robotraconteur.geometryi.Size2D"))
        size[0] = (W, H)
        cal.image_size = size
        cal.K = np.array([[60.0, 0, 32], [0, 60.0, 24], [0, 0, 1]])
        dist = RRN.NewStructure("com.robotraconteur.imaging.camerainfo.PlumbBobDistortionInfo")
        dist.k1 = dist.k2 = dist.p1 = dist.p2 = dist.k3 = 0.0
        cal.distortion_info = RR.VarValue(dist, "com.robotraconteur.imaging.camerainfo.PlumbBobDistortionInfo")
        ci.calibration = cal
        return ci


class RigCamera:
    """One camera of the rig as a standard Camera (through the rig's cameras objref)."""

    def __init__(self, rig, k, ident):
        self._rig, self._k = rig, k
        self.device_info = device_info(f"rig_{NAMES[k]}", ident)
        self.camera_info = CameraInfoMaker.make(f"rig_{NAMES[k]}", ident)

    def capture_frame(self):
        return self._rig.frames[self._k].raw(self._rig.n)

    def capture_frame_compressed(self):
        return self._rig.frames[self._k].png(self._rig.n)


class Rig:
    def __init__(self, ident):
        self.device_info = device_info("colour_rig", ident)
        info = RRN.NewStructure(f"{IMAGING}.camerainfo.MultiCameraInfo")
        info.device_info = self.device_info
        info.camera_info_all = {k: CameraInfoMaker.make(f"rig_{n}", ident) for k, n in NAMES.items()}
        self.multicamera_info = info
        self.camera_names = dict(NAMES)
        self.param_info = []
        self.frames = [Frames(k) for k in NAMES]
        self._cameras = {k: RigCamera(self, k, ident) for k in NAMES}
        self.n = 0
        self.triggers = 0

    def get_cameras(self, ind):
        k = int(ind)
        if k not in self._cameras:
            raise RR.InvalidArgumentException(f"no camera {k}")
        return self._cameras[k], f"{IMAGING}.Camera"

    def capture_frame_all(self):
        return {k: f.raw(self.n) for k, f in enumerate(self.frames)}

    def trigger_all(self):
        self.triggers += 1
        emit({"triggered": self.triggers})

    def getf_param(self, name):
        raise RR.InvalidArgumentException(f"unknown parameter {name}")

    def setf_param(self, name, value):
        raise RR.InvalidArgumentException(f"unknown parameter {name}")

    def send(self):
        self.n += 1
        for pipe, make in (("preview_stream_all", "png"), ("frame_stream_compressed_all", "png"), ("frame_stream_all", "raw")):
            p = getattr(self, pipe, None)
            if p is not None:
                p.SendPacket({k: getattr(f, make)(self.n) for k, f in enumerate(self.frames)})


class PartCamera:
    """An ImagePartCamera: capture_frame gives the raw frame in parts."""

    def __init__(self, ident, part_bytes):
        self.device_info = device_info("colour_parts", ident)
        self.camera_info = CameraInfoMaker.make("colour_parts", ident)
        self.capabilities = 0
        self.param_info = []
        self.frames = Frames(3)
        self.part_bytes = part_bytes
        self.streaming = False
        self.n = 0
        self.seqno = 0
        self._flags = RRN.GetConstants(IMAGING)["CameraStateFlags"]

    def start_streaming(self):
        if self.streaming:
            raise RR.InvalidOperationException("Already streaming")
        self.streaming = True

    def stop_streaming(self):
        if not self.streaming:
            raise RR.InvalidOperationException("Not streaming")
        self.streaming = False

    def capture_frame(self):
        raw = self.frames.raw(self.n)
        data = raw.data
        parts = []
        for off in range(0, len(data), self.part_bytes):
            p = RRN.NewStructure("com.robotraconteur.image.ImagePart")
            p.image_info = raw.image_info
            p.data_offset = off
            p.data_total_len = len(data)
            p.data_part = np.ascontiguousarray(data[off:off + self.part_bytes])
            parts.append(p)
        emit({"captured_parts": len(parts), "frame": self.n})
        return PartGenerator(parts)

    def trigger(self):
        pass

    def getf_param(self, name):
        raise RR.InvalidArgumentException(f"unknown parameter {name}")

    def setf_param(self, name, value):
        raise RR.InvalidArgumentException(f"unknown parameter {name}")

    def send(self):
        self.seqno += 1
        state = RRN.NewStructure(f"{IMAGING}.CameraState")
        state.seqno = self.seqno
        state.state_flags = self._flags["ready"] | (self._flags["streaming"] if self.streaming else 0)
        if getattr(self, "camera_state", None) is not None:
            self.camera_state.OutValue = state
        if self.streaming:
            self.n += 1
            if getattr(self, "preview_stream", None) is not None:
                self.preview_stream.SendPacket(self.frames.png(self.n))


def main():
    die_with_parent()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--part-bytes", type=int, default=2000)
    ap.add_argument("--without-member", default=None)
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    port = free_port()
    stop = threading.Event()
    with RR.ServerNodeSetup("experimental.std_multi_camera", port, argv=["multi_camera"] + node_flags(port)):
        if args.without_member:
            RRN.RegisterServiceTypes(definitions_without([IMAGING], args.without_member))
        else:
            RRC.RegisterStdRobDefServiceTypes(RRN)
        ident = IdentifierUtil(RRN)
        rig, parts = Rig(ident), PartCamera(ident, max(16, args.part_bytes))
        RRN.RegisterService("rig", f"{IMAGING}.MultiCamera", rig)
        RRN.RegisterService("parts", f"{IMAGING}.ImagePartCamera", parts)

        def loop():
            while not stop.wait(0.2):
                for dev in (rig, parts):
                    try:
                        dev.send()
                    except Exception as e:  # a send racing the node's shutdown
                        log("multi_camera", f"send: {type(e).__name__}: {e}")

        threading.Thread(target=loop, daemon=True).start()
        with _stdout_lock:
            ready(url=f"rr+tcp://127.0.0.1:{port}/?service=rig", parts_url=f"rr+tcp://127.0.0.1:{port}/?service=parts", port=port,
                  colors=COLORS, size=[W, H], pid=os.getpid())
        wait_for_stop(args.max_lifetime)
        stop.set()
        log("multi_camera", "stopping")


if __name__ == "__main__":
    main()
