"""Shared by the point cloud, camera and detection test devices (point_cloud.py, multi_camera.py,
detections.py): a {generator} function's result for the official library, and the standard definitions
with members taken away (an older or trimmed release, for the dashboard's fallback tests)."""

import RobotRaconteur as RR
from RobotRaconteurCompanion.StdRobDef import STANDARD_ROBDEF_TEXT


class PartGenerator:
    """Next() gives each item in turn, then StopIteration; Close() and Abort() end it early."""

    def __init__(self, items):
        self._items = list(items)

    def Next(self):
        if not self._items:
            raise RR.StopIterationException("")
        return self._items.pop(0)

    def Close(self):
        self._items = []

    def Abort(self):
        self._items = []


def definitions_without(services, members):
    """The standard definitions with the member lines named in `members` (comma separated) removed from
    each of `services` (service names); SystemExit when none was there."""
    texts = dict(STANDARD_ROBDEF_TEXT)
    names = set(members.split(","))
    removed = 0
    for key in services:
        lines = texts[key].splitlines()
        kept = [ln for ln in lines if not (len(ln.split()) > 2 and ln.split()[0] in ("pipe", "function", "property", "wire", "objref")
                                           and ln.split()[2].split("(")[0] in names)]
        removed += len(lines) - len(kept)
        texts[key] = "\n".join(kept) + "\n"
    if not removed:
        raise SystemExit(f"--without-member: {', '.join(services)} have no member {members}")
    return list(texts.values())
