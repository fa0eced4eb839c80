#!/usr/bin/env python3
"""A device with a command wire, on the official Robot Raconteur Python library, for the Foxglove
WebSocket test of a client publish reaching a wire (docs/foxglove.md "How it is tested").

Service "sink", object experimental.foxglove_sink.Sink: `wire double[] command [writeonly]` (what a
Foxglove Publish panel sends goes to the device's InValue), `property double[] last_command [readonly]`
(the newest InValue received, empty before any), `property int32 commands [readonly]` (how many), and
`property string label` (read and written: a parameter to set).

Ready line: {"url": "rr+tcp://127.0.0.1:P/?service=sink", "port": P}.
Usage: command_sink.py [--port P] [--max-lifetime 300]
"""

import argparse
import os
import sys
import threading

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "browser", "devices"))
from common import die_with_parent, free_port, node_flags, ready, wait_for_stop  # noqa: E402

import RobotRaconteur as RR  # noqa: E402

RRN = RR.RobotRaconteurNode.s

ROBDEF = """service experimental.foxglove_sink

object Sink
    wire double[] command [writeonly]
    property double[] last_command [readonly]
    property int32 commands [readonly]
    property string label
end
"""


class Sink:
    def __init__(self):
        self._lock = threading.Lock()
        self._last = []
        self._count = 0
        self._wire = None
        self._receiver = None
        self.label = "sink"

    @property
    def command(self):
        return self._wire

    @command.setter
    def command(self, wire):
        self._wire = wire
        self._receiver = RR.WireUnicastReceiver(wire)
        self._receiver.InValueChanged += self._received

    def _received(self, value, ts, ep):
        with self._lock:
            self._last = [float(x) for x in value]
            self._count += 1

    @property
    def last_command(self):
        with self._lock:
            return list(self._last)

    @property
    def commands(self):
        with self._lock:
            return self._count


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--port", type=int, default=0)
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    die_with_parent()
    port = args.port or free_port()
    with RR.ServerNodeSetup("experimental.foxglove_sink", port, argv=["command_sink"] + node_flags(port)):
        RRN.RegisterServiceType(ROBDEF)
        RRN.RegisterService("sink", "experimental.foxglove_sink.Sink", Sink())
        ready(url=f"rr+tcp://127.0.0.1:{port}/?service=sink", port=port, pid=os.getpid())
        wait_for_stop(args.max_lifetime)


if __name__ == "__main__":
    main()
