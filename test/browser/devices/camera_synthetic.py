#!/usr/bin/env python3
"""The official OpenCV camera driver (PyPI robotraconteur-camera-driver, pinned in
test/interop/requirements.txt) with a synthetic frame source in place of a camera.

The driver opens its camera with cv2.VideoCapture(device_id) and reads frames with read(); this
launcher replaces cv2.VideoCapture, before the driver's own main() runs, with SyntheticCapture: frames
of the size the driver asks for (--width/--height), paced at --fps, each a function of its number k
(counted from 0 by read()) that the browser test recomputes to compare pixels:

  * blocks of BLOCK x BLOCK pixels; the top row of blocks spells k mod 2^cols in binary, bit i in
    block column i: white (255, 255, 255) when set, black when not;
  * every other block (bx, by) is PALETTE[(bx + 3 * by + k) mod 8] (RGB);
  * with --mono the frame is one channel: white/black as above, other blocks 32 * ((bx + 3*by + k) mod 8) + 16.

The frame is given to the driver in OpenCV's BGR order, so the driver sends bgr888 (mono8 with
--mono) Images, and JPEG CompressedImages (quality 100 on frame_stream_compressed, 70 on
preview_stream) as it does for a real camera. Nothing else of the driver is changed: its
argument parsing, info file loading (RobotRaconteurCompanion's InfoFileLoader), service
registration and streaming thread all run as shipped.

The driver's main() ends with drekar_launch_process.wait_exit(), called once the service is
registered: this launcher takes that moment to print its ready line

    {"url": "rr+tcp://127.0.0.1:P/?service=camera", "port": P, "width": W, "height": H, "block": B,
     "palette": [...], "mono": false}

and then waits for SIGTERM/SIGINT (or --max-lifetime); the driver then closes its camera and node.

Usage: camera_synthetic.py --camera-info FILE [--width 320] [--height 240] [--fps 15] [--mono]
                           [--max-lifetime 300]
"""

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import die_with_parent, free_port, node_flags, ready, wait_for_stop, log  # noqa: E402

import numpy as np  # noqa: E402
import cv2  # noqa: E402
import drekar_launch_process  # noqa: E402
import robotraconteur_camera_driver as driver  # noqa: E402

BLOCK = 40
PALETTE = [(230, 25, 75), (60, 180, 75), (255, 225, 25), (0, 130, 200),
           (245, 130, 48), (145, 30, 180), (70, 240, 240), (240, 50, 230)]


def synthetic_frame(k, width, height, mono):
    """Frame number k as an OpenCV mat (BGR, or one channel with mono)."""
    cols, rows = (width + BLOCK - 1) // BLOCK, (height + BLOCK - 1) // BLOCK
    if mono:
        mat = np.zeros((height, width), dtype=np.uint8)
    else:
        mat = np.zeros((height, width, 3), dtype=np.uint8)
    for by in range(rows):
        for bx in range(cols):
            if by == 0:
                on = (k >> bx) & 1
                rgb = (255, 255, 255) if on else (0, 0, 0)
                grey = 255 if on else 0
            else:
                i = (bx + 3 * by + k) % 8
                rgb = PALETTE[i]
                grey = 32 * i + 16
            block = (slice(by * BLOCK, min(height, (by + 1) * BLOCK)), slice(bx * BLOCK, min(width, (bx + 1) * BLOCK)))
            if mono:
                mat[block] = grey
            else:
                mat[block] = (rgb[2], rgb[1], rgb[0])  # BGR, as OpenCV's captures give
    return mat


class SyntheticCapture:
    """What the driver uses of cv2.VideoCapture: isOpened, set, get, read, release."""

    settings = {"fps": 15.0, "mono": False}

    def __init__(self, device_id, *_):
        self.device_id = device_id
        self.width, self.height = 640, 480
        self.fps = float(self.settings["fps"])
        self.k = 0
        self.next_time = None
        self.frames = {}

    def isOpened(self):
        return True

    def set(self, prop, value):
        if prop == cv2.CAP_PROP_FRAME_WIDTH:
            self.width = int(value)
        elif prop == cv2.CAP_PROP_FRAME_HEIGHT:
            self.height = int(value)
        elif prop == cv2.CAP_PROP_FPS:
            self.fps = float(value) or self.fps
        return True

    def get(self, prop):
        return {cv2.CAP_PROP_FRAME_WIDTH: float(self.width), cv2.CAP_PROP_FRAME_HEIGHT: float(self.height),
                cv2.CAP_PROP_FPS: self.fps}.get(prop, 0.0)

    def read(self):
        now = time.monotonic()
        if self.next_time is None or self.next_time < now - 1:
            self.next_time = now
        if self.next_time > now:
            time.sleep(self.next_time - now)
        self.next_time += 1.0 / self.fps
        frame = synthetic_frame(self.k, self.width, self.height, self.settings["mono"])
        self.k += 1
        return True, frame

    def release(self):
        pass


def main():
    die_with_parent()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--camera-info", required=True, help="the camera info YAML file (CameraInfo)")
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    ap.add_argument("--fps", type=float, default=15)
    ap.add_argument("--mono", action="store_true", help="one-channel frames (the driver sends mono8)")
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()

    SyntheticCapture.settings = {"fps": args.fps, "mono": args.mono}
    cv2.VideoCapture = SyntheticCapture
    port = free_port()

    def registered_then_wait():
        ready(url=f"rr+tcp://127.0.0.1:{port}/?service=camera", port=port, width=args.width, height=args.height,
              block=BLOCK, palette=PALETTE, mono=args.mono, pid=os.getpid())
        wait_for_stop(args.max_lifetime)
        log("camera", "stopping")

    drekar_launch_process.wait_exit = registered_then_wait
    sys.argv = ["robotraconteur-camera-driver", "--camera-info-file", args.camera_info,
                "--width", str(args.width), "--height", str(args.height), "--fps", str(int(args.fps))] + node_flags(port)
    driver.main()


if __name__ == "__main__":
    main()
