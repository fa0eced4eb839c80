#!/usr/bin/env python3
"""A test service of standard images, on the official Robot Raconteur Python library: every raw
com.robotraconteur.image.ImageEncoding and compressed PNG/JPEG frames, with the RGBA picture a
correct decoder must show for each (worked out here, independently of the dashboard's decoder), and
bad frames the dashboard must refuse one by one.

Service "images", object experimental.std_images.ImageSource (definition below; the standard types
registered from the robotraconteurcompanion package, as drivers do):

    wire Image image                   the current raw frame
    wire CompressedImage compressed    the current compressed frame
    property Image still               the last raw frame
    function Image capture()           the last raw frame
    function Image{int32} capture_pair()  {0: the last raw frame, 1: the mono8 frame}

The test drives it by JSON lines on stdin; each is answered by one JSON line on stdout:

    {"case": NAME}  -> sets the wire of the case's kind to that frame:
                       {"sent": NAME, "kind": "image"|"compressed", "width", "height",
                        "reference": base64 RGBA (height x width x 4) or null, "tolerance": max
                        difference per channel, "error": the dashboard's error code or null}
    {"list": true}  -> {"cases": [names...]}

Ready line: {"url": "rr+tcp://127.0.0.1:P/?service=images", "port": P, "cases": [...]}.

Usage: image_service.py [--max-lifetime 300]
"""

import argparse
import base64
import json
import math
import os
import sys
import threading

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import die_with_parent, free_port, node_flags, ready, wait_for_stop, log  # noqa: E402

import numpy as np  # noqa: E402
import cv2  # noqa: E402
import RobotRaconteur as RR  # noqa: E402
import RobotRaconteurCompanion as RRC  # noqa: E402

RRN = RR.RobotRaconteurNode.s

ROBDEF = """\
service experimental.std_images

stdver 0.10

import com.robotraconteur.image

using com.robotraconteur.image.Image
using com.robotraconteur.image.CompressedImage

object ImageSource
    wire Image image [readonly]
    wire CompressedImage compressed [readonly]
    property Image still [readonly]
    function Image capture()
    function Image{int32} capture_pair()
end
"""

W, H = 16, 12
PAD = 2  # bytes after each row of raw frames: the decoder must honour step

# The ground truth every case shows (RGB and grey), as functions of the pixel position.
ys, xs = np.mgrid[0:H, 0:W]
TRUTH = np.stack([(xs * 16 + ys * 3) % 256, (ys * 21 + xs * 5) % 256, (xs * ys * 7 + 40) % 256], axis=-1).astype(np.uint8)
GREY = ((xs * 13 + ys * 17 + 5) % 256).astype(np.uint8)

# The depth colour map the dashboard documents ("jet": dark blue, blue, cyan, yellow, red, dark
# red): index, r, g, b of its stops; linear between them.
JET = [(0, 0, 0, 143), (32, 0, 0, 255), (96, 0, 255, 255), (160, 255, 255, 0), (224, 255, 0, 0), (255, 128, 0, 0)]


def round_half_up(x):
    return int(math.floor(x + 0.5))


def jet_colour(i):
    for (i0, *c0), (i1, *c1) in zip(JET, JET[1:]):
        if i0 <= i <= i1:
            f = (i - i0) / (i1 - i0)
            return [round_half_up(c0[c] + (c1[c] - c0[c]) * f) for c in range(3)]
    raise ValueError(i)


def rgba(rgb):
    return np.concatenate([rgb, np.full(rgb.shape[:2] + (1,), 255, np.uint8)], axis=-1)


def grey_rgba(g):
    return rgba(np.stack([g, g, g], axis=-1))


def rows(pixels, bytes_per_pixel):
    """Raw frame bytes: H rows of the pixels' bytes plus PAD filler bytes."""
    flat = np.frombuffer(np.ascontiguousarray(pixels).tobytes(), np.uint8).reshape(H, W * bytes_per_pixel)
    return np.concatenate([flat, np.full((H, PAD), 0xEE, np.uint8)], axis=1).reshape(-1), W * bytes_per_pixel + PAD


def bilinear_bayer(mosaic, pattern):
    """Reference demosaicing: each missing colour the mean of that colour's pixels in the 3x3
    neighbourhood (clipped at the borders), rounded half up; each pixel keeps its own sample."""
    colour_at = lambda x, y: "rgb".index(pattern[(y % 2) * 2 + (x % 2)])  # noqa: E731
    out = np.zeros((H, W, 4), np.uint8)
    out[..., 3] = 255
    for y in range(H):
        for x in range(W):
            sums, counts = [0, 0, 0], [0, 0, 0]
            for yy in range(max(0, y - 1), min(H, y + 2)):
                for xx in range(max(0, x - 1), min(W, x + 2)):
                    c = colour_at(xx, yy)
                    sums[c] += int(mosaic[yy, xx])
                    counts[c] += 1
            for c in range(3):
                out[y, x, c] = mosaic[y, x] if c == colour_at(x, y) else round_half_up(sums[c] / counts[c])
    return out


def depth_reference(values):
    """Reference colouring of depth values (numbers, 0/NaN/inf invalid and black) over their range."""
    flat = [float(v) for v in np.asarray(values, dtype=np.float64).reshape(-1)]
    valid = [v for v in flat if v != 0 and math.isfinite(v)]
    lo, hi = min(valid), max(valid)
    scale = 255 / (hi - lo)
    out = np.zeros((H * W, 4), np.uint8)
    out[:, 3] = 255
    for i, v in enumerate(flat):
        if v != 0 and math.isfinite(v):
            k = 0 if v <= lo else 255 if v >= hi else round_half_up((v - lo) * scale)
            out[i, :3] = jet_colour(k)
    return out.reshape(H, W, 4), (lo, hi)


def depth_values(dtype, unit=1.0, offset=0):
    d = (500 + xs * 37 + ys * 101 + offset).astype(np.float64) * unit
    d[0, 0] = 0  # no reading
    d[5, 3] = 0
    return d.astype(dtype)


class Case:
    def __init__(self, name, kind, encoding, data, step, reference, tolerance=0, error=None, width=W, height=H):
        self.name, self.kind, self.encoding, self.data, self.step = name, kind, encoding, data, step
        self.reference, self.tolerance, self.error, self.width, self.height = reference, tolerance, error, width, height


def build_cases(enc):
    cases = []

    def raw(name, pixels, bpp, reference, tolerance=0):
        data, step = rows(pixels, bpp)
        cases.append(Case(name, "image", enc[name], data, step, reference, tolerance))

    alpha8 = np.full((H, W, 1), 255, np.uint8)
    raw("rgb888", TRUTH, 3, rgba(TRUTH))
    raw("rgba8888", np.concatenate([TRUTH, alpha8], -1), 4, rgba(TRUTH))
    raw("bgr888", TRUTH[..., ::-1], 3, rgba(TRUTH))
    raw("bgra8888", np.concatenate([TRUTH[..., ::-1], alpha8], -1), 4, rgba(TRUTH))
    wide = TRUTH.astype(np.uint16) * 256 + (xs[..., None] * 7 % 256).astype(np.uint16)  # low bytes must not show
    alpha16 = np.full((H, W, 1), 0xFFFF, np.uint16)
    raw("rgba16_16_16_16", np.concatenate([wide, alpha16], -1).astype("<u2"), 8, rgba(TRUTH))
    raw("bgra16_16_16_16", np.concatenate([wide[..., ::-1], alpha16], -1).astype("<u2"), 8, rgba(TRUTH))
    raw("mono8", GREY, 1, grey_rgba(GREY))
    raw("mono16", (GREY.astype(np.uint16) * 256 + 0x37).astype("<u2"), 2, grey_rgba(GREY))
    raw("mono32", (GREY.astype(np.uint32) * (1 << 24) + 0x123456).astype("<u4"), 4, grey_rgba(GREY))
    for name, dtype, bpp in (("mono_f16", "<f2", 2), ("mono_f32", "<f4", 4), ("mono_f64", "<f8", 8)):
        samples = (GREY.astype(np.float64) / 255).astype(dtype)
        shown = np.vectorize(lambda v: min(255, max(0, round_half_up(float(v) * 255))))(samples).astype(np.uint8)
        raw(name, samples, bpp, grey_rgba(shown))
    for pattern in ("rggb", "bggr", "gbrg", "grbg"):
        mosaic = np.zeros((H, W), np.uint8)
        for y in range(H):
            for x in range(W):
                mosaic[y, x] = TRUTH[y, x, "rgb".index(pattern[(y % 2) * 2 + (x % 2)])]
        raw(f"bayer_{pattern}8888", mosaic, 1, bilinear_bayer(mosaic, pattern))
    for name, dtype, bpp, unit, offset in (
            ("depth_u16", "<u2", 2, 1, 0), ("depth_i16", "<i2", 2, 1, -1500), ("depth_u32", "<u4", 4, 1000, 0),
            ("depth_i32", "<i4", 4, 1000, -1500), ("depth_u64", "<u8", 8, 1000, 0), ("depth_i64", "<i8", 8, 1000, -1500),
            ("depth_f32", "<f4", 4, 0.001, 0), ("depth_f64", "<f8", 8, 0.001, 0)):
        values = depth_values(np.dtype(dtype), unit, offset)
        if name.startswith("depth_i"):
            values[0, 0] = 0
        if name.startswith("depth_f"):
            values[7, 9] = np.nan
            values[8, 2] = np.inf
        reference, _ = depth_reference(values)
        raw(name, values.astype(dtype), bpp, reference)

    bgr = np.ascontiguousarray(TRUTH[..., ::-1])
    ok, png = cv2.imencode(".png", bgr)
    assert ok
    cases.append(Case("png", "compressed", enc["compressed"], png.reshape(-1), 0, rgba(TRUTH)))
    ok, jpeg = cv2.imencode(".jpg", bgr, [int(cv2.IMWRITE_JPEG_QUALITY), 95])
    assert ok
    decoded = cv2.imdecode(jpeg, cv2.IMREAD_COLOR)[..., ::-1]
    cases.append(Case("jpeg", "compressed", enc["compressed"], jpeg.reshape(-1), 0, rgba(decoded), tolerance=6))

    # bad frames: what the dashboard must say is wrong (its error codes)
    good, step = rows(TRUTH, 3)
    cases.append(Case("bad_data_too_short", "image", enc["rgb888"], good[:-1], step, None, error="data_too_short"))
    cases.append(Case("bad_unknown_encoding", "image", 0x1234, good, step, None, error="unknown_encoding"))
    tight = np.frombuffer(TRUTH.tobytes(), np.uint8)
    cases.append(Case("bad_step_too_small", "image", enc["rgb888"], tight, W * 3 - 3, None, error="step_too_small"))
    cases.append(Case("bad_zero_size", "image", enc["rgb888"], good, step, None, error="zero_size", width=0))
    cases.append(Case("bad_not_raw", "image", enc["compressed"], jpeg.reshape(-1), 0, None, error="not_raw"))
    corrupt = np.concatenate([jpeg.reshape(-1)[:20], np.arange(200, dtype=np.uint8)])
    cases.append(Case("bad_corrupt_jpeg", "compressed", enc["compressed"], corrupt, 0, None, error="decode_failed"))
    cases.append(Case("bad_unknown_format", "compressed", enc["compressed"], np.arange(64, dtype=np.uint8), 0, None,
                      error="unknown_format"))
    return {c.name: c for c in cases}


class ImageSource:
    def __init__(self):
        self._image_type = RRN.GetStructureType("com.robotraconteur.image.Image")
        self._compressed_type = RRN.GetStructureType("com.robotraconteur.image.CompressedImage")
        self._info_type = RRN.GetStructureType("com.robotraconteur.image.ImageInfo")
        consts = RRN.GetConstants("com.robotraconteur.image")
        self.encodings = consts["ImageEncoding"]
        self.cases = build_cases(self.encodings)
        self._lock = threading.Lock()
        self._last = self.frame(self.cases["rgb888"])
        self._mono = self.frame(self.cases["mono8"])

    def frame(self, case):
        info = self._info_type()
        info.width, info.height, info.step, info.encoding = case.width, case.height, case.step, case.encoding
        f = (self._compressed_type if case.kind == "compressed" else self._image_type)()
        f.image_info = info
        f.data = np.ascontiguousarray(case.data, dtype=np.uint8)
        return f

    def send(self, name):
        case = self.cases[name]
        f = self.frame(case)
        if case.kind == "compressed":
            self.compressed.OutValue = f
        else:
            self.image.OutValue = f
            if case.error is None:
                with self._lock:
                    self._last = f
        ref = None if case.reference is None else base64.b64encode(np.ascontiguousarray(case.reference).tobytes()).decode()
        return {"sent": name, "kind": case.kind, "width": case.width, "height": case.height, "reference": ref,
                "tolerance": case.tolerance, "error": case.error}

    @property
    def still(self):
        with self._lock:
            return self._last

    def capture(self):
        with self._lock:
            return self._last

    def capture_pair(self):
        with self._lock:
            return {0: self._last, 1: self._mono}


def main():
    die_with_parent()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    port = free_port()
    with RR.ServerNodeSetup("experimental.std_images", port, argv=["image_service"] + node_flags(port)):
        RRC.RegisterStdRobDefServiceTypes(RRN)
        RRN.RegisterServiceType(ROBDEF)
        source = ImageSource()
        RRN.RegisterService("images", "experimental.std_images.ImageSource", source)

        def commands():
            for line in sys.stdin:
                try:
                    cmd = json.loads(line)
                    if cmd.get("list"):
                        reply = {"cases": list(source.cases)}
                    else:
                        reply = source.send(cmd["case"])
                except Exception as e:  # a wrong command is the test's mistake: say so, keep serving
                    reply = {"failed": f"{type(e).__name__}: {e}"}
                print(json.dumps(reply), flush=True)

        threading.Thread(target=commands, daemon=True).start()
        ready(url=f"rr+tcp://127.0.0.1:{port}/?service=images", port=port, cases=list(source.cases), pid=os.getpid())
        wait_for_stop(args.max_lifetime)
        log("images", "stopping")


if __name__ == "__main__":
    main()
