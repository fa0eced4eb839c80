#!/usr/bin/env python3
"""Three lights served on one node by the official library with RobotRaconteurCompanion's standard
definitions (com.robotraconteur.lighting): "light" a Light (a bench lamp, on/off), "dimmer" a
DimmableLight (a ring light, intensity 0 to 1) and "lamp" a ColorTunableLight (an RGB panel, intensity
and ColorRGBA). Each logs every write on stdout, {"light": service, "member": name, "value": v}, so a
test can tell what reached the device.

--without-member NAME (for tests): the lighting definition served lacks member NAME in every light
(its line removed from the standard text, as an older or vendor release would differ).

Ready line: {"url": "rr+tcp://127.0.0.1:P/?service=lamp", "port": P, "urls": {service: url}}.

Usage: sim_lights.py [--without-member on_off] [--max-lifetime 300]
"""

import argparse
import json
import os
import sys
import threading

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import die_with_parent, free_port, node_flags, ready, wait_for_stop, log  # noqa: E402

import numpy as np  # noqa: E402
import RobotRaconteur as RR  # noqa: E402
import RobotRaconteurCompanion as RRC  # noqa: E402
from RobotRaconteurCompanion.StdRobDef import STANDARD_ROBDEF_TEXT  # noqa: E402
from RobotRaconteurCompanion.Util.InfoFileLoader import InfoFileLoader  # noqa: E402
from RobotRaconteurCompanion.Util.AttributesUtil import AttributesUtil  # noqa: E402

RRN = RR.RobotRaconteurNode.s
_stdout_lock = threading.Lock()
LIGHTING = "com.robotraconteur.lighting"

# fixed UUIDs: with the zero UUID the companion's loader would lock a per-name identifier file, and a
# second instance (the tests run two) would fail
LIGHTS = {
    "light": ("Light", "bench_lamp", "7a1e0c52-3b4d-4e6f-8a9b-0c1d2e3f4a51", "Bench lamp (on/off)", 800.0),
    "dimmer": ("DimmableLight", "ring_light", "7a1e0c52-3b4d-4e6f-8a9b-0c1d2e3f4a52", "Microscope ring light (dimmable)", 1200.0),
    "lamp": ("ColorTunableLight", "rgb_panel", "7a1e0c52-3b4d-4e6f-8a9b-0c1d2e3f4a53", "RGB panel light (colour tunable)", 2500.0),
}

INFO = """
device_info:
  device:
    name: {name}
    uuid: {uuid}
  manufacturer:
    name: rr-gateway tests
    uuid: 0c6f8a3e-2d41-4b7f-9a15-3e8d2b6c4f70
  serial_number: {serial}
  user_description: {description}
  device_classes:
    - class_identifier:
        name: light
        uuid: 00000000-0000-0000-0000-000000000000
      subclasses: []
  implemented_types:
    - com.robotraconteur.lighting.{type}
max_lumens: {lumens}
"""


def emit(value):
    with _stdout_lock:
        sys.stdout.write(json.dumps(value) + "\n")
        sys.stdout.flush()


def definitions_without(member):
    """The standard definitions with `member`'s line removed from the lighting service."""
    texts = dict(STANDARD_ROBDEF_TEXT)
    lines = texts[LIGHTING].splitlines()
    kept = [ln for ln in lines if not (ln.strip().startswith("property ") and len(ln.split()) > 2 and ln.split()[2] == member)]
    if len(kept) == len(lines):
        raise SystemExit(f"--without-member: the lights have no property {member}")
    texts[LIGHTING] = "\n".join(kept) + "\n"
    return list(texts.values())


class SimLight:
    """A light's properties as the official library reads and writes them; every write is logged."""

    def __init__(self, service, info):
        self._service = service
        self.light_info = info
        self.device_info = info.device_info
        self._on = False
        self._intensity = 0.5
        self._color = np.zeros((1,), dtype=RRN.GetNamedArrayDType("com.robotraconteur.color.ColorRGBA"))
        self._color[0] = (1.0, 0.75, 0.3, 1.0)  # warm white

    def _logged(self, member, value):
        emit({"light": self._service, "member": member, "value": value})

    @property
    def on_off(self):
        return self._on

    @on_off.setter
    def on_off(self, v):
        self._on = bool(v)
        self._logged("on_off", self._on)

    @property
    def intensity(self):
        return self._intensity

    @intensity.setter
    def intensity(self, v):
        if not np.isfinite(v) or v < 0 or v > 1:
            raise RR.InvalidArgumentException(f"intensity {v} outside 0 to 1")
        self._intensity = float(v)
        self._logged("intensity", self._intensity)

    @property
    def color(self):
        return self._color

    @color.setter
    def color(self, v):
        c = v.reshape(-1)[0] if hasattr(v, "reshape") else v
        values = [float(c[k]) for k in ("r", "g", "b", "a")]
        if not all(0 <= x <= 1 for x in values):
            raise RR.InvalidArgumentException(f"colour {values} outside 0 to 1")
        self._color[0] = tuple(values)
        self._logged("color", values)


def main():
    die_with_parent()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--without-member", default=None, help="serve lights whose definition lacks this property")
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    port = free_port()
    with RR.ServerNodeSetup("experimental.sim_lights", port, argv=["sim_lights"] + node_flags(port)):
        if args.without_member:
            RRN.RegisterServiceTypes(definitions_without(args.without_member))
        else:
            RRC.RegisterStdRobDefServiceTypes(RRN)
        loader, attributes_util = InfoFileLoader(RRN), AttributesUtil(RRN)
        urls = {}
        for service, (type_name, name, device_uuid, description, lumens) in LIGHTS.items():
            info, _ = loader.LoadInfoFileFromString(
                INFO.format(name=name, uuid=device_uuid, serial=f"SIM-{name.upper()}-1", description=description, type=type_name, lumens=lumens),
                f"{LIGHTING}.LightInfo", "light")
            ctx = RRN.RegisterService(service, f"{LIGHTING}.{type_name}", SimLight(service, info))
            ctx.SetServiceAttributes(attributes_util.GetDefaultServiceAttributesFromDeviceInfo(info.device_info))
            urls[service] = f"rr+tcp://127.0.0.1:{port}/?service={service}"
        with _stdout_lock:
            ready(url=urls["lamp"], port=port, urls=urls, pid=os.getpid())
        wait_for_stop(args.max_lifetime)
        log("lights", "stopping")


if __name__ == "__main__":
    main()
