#!/usr/bin/env python3
"""A device with a command wire, a command pipe and a clock, on the official Robot Raconteur Python
library, for the Foxglove WebSocket test of a client publish reaching a wire or a pipe and of `time`
from a device's clock (docs/foxglove.md "How it is tested").

Service "sink", object experimental.foxglove_sink.Sink: `wire double[] command [writeonly]` (what a
Foxglove Publish panel sends goes to the device's InValue), `property double[] last_command [readonly]`
(the newest InValue received, empty before any), `property int32 commands [readonly]` (how many),
`pipe double[] command_packets [writeonly]` with `property double[] last_packet [readonly]` and
`property int32 packets [readonly]` (the same for pipe packets), `property string label` (read and
written: a parameter to set), and the standard DeviceClock's `wire DeviceTime device_clock_now`, whose
`device_utc` runs from 2001-01-01T00:00:00Z (978307200 s) at the device's start, ticking at 20 Hz: a
time no gateway's wall clock has, so a test tells the device's clock from the gateway's.

Ready line: {"url": "rr+tcp://127.0.0.1:P/?service=sink", "port": P}.
Usage: command_sink.py [--port P] [--max-lifetime 300]
"""

import argparse
import os
import sys
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "browser", "devices"))
from common import die_with_parent, free_port, node_flags, ready, wait_for_stop  # noqa: E402

import numpy as np  # noqa: E402
import RobotRaconteur as RR  # noqa: E402
import RobotRaconteurCompanion as RRC  # noqa: E402

RRN = RR.RobotRaconteurNode.s

ROBDEF = """service experimental.foxglove_sink

import com.robotraconteur.device.clock
using com.robotraconteur.device.clock.DeviceTime

object Sink
    wire double[] command [writeonly]
    property double[] last_command [readonly]
    property int32 commands [readonly]
    pipe double[] command_packets [writeonly]
    property double[] last_packet [readonly]
    property int32 packets [readonly]
    property string label
    wire DeviceTime device_clock_now [readonly,nolock]
end
"""

CLOCK_EPOCH = 978307200  # 2001-01-01T00:00:00Z


class Sink:
    def __init__(self):
        self._lock = threading.Lock()
        self._last = []
        self._count = 0
        self._wire = None
        self._receiver = None
        self._pipe = None
        self._last_packet = []
        self._packets = 0
        self._clock_wire = None
        self._clock = None
        self._start = time.monotonic()
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

    @property
    def command_packets(self):
        return self._pipe

    @command_packets.setter
    def command_packets(self, pipe):
        self._pipe = pipe
        pipe.PipeConnectCallback = self._pipe_connected

    def _pipe_connected(self, ep):
        ep.PacketReceivedEvent += self._packet_received

    def _packet_received(self, ep):
        while ep.Available > 0:
            value = ep.ReceivePacket()
            with self._lock:
                self._last_packet = [float(x) for x in value]
                self._packets += 1

    @property
    def last_packet(self):
        with self._lock:
            return list(self._last_packet)

    @property
    def packets(self):
        with self._lock:
            return self._packets

    @property
    def device_clock_now(self):
        return self._clock_wire

    @device_clock_now.setter
    def device_clock_now(self, wire):
        self._clock_wire = wire
        self._clock = RR.WireBroadcaster(wire)

    def tick(self, seqno):
        """device_clock_now's value now: device_ts from the start, device_utc from CLOCK_EPOCH."""
        elapsed = time.monotonic() - self._start
        v = np.zeros((1,), dtype=RRN.GetPodDType("com.robotraconteur.device.clock.DeviceTime"))
        v[0]["device_seqno"] = seqno
        v[0]["device_ts"]["seconds"] = int(elapsed)
        v[0]["device_ts"]["nanoseconds"] = int((elapsed % 1.0) * 1e9)
        v[0]["device_utc"]["seconds"] = CLOCK_EPOCH + int(elapsed)
        v[0]["device_utc"]["nanoseconds"] = int((elapsed % 1.0) * 1e9)
        if self._clock is not None:
            self._clock.OutValue = v


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--port", type=int, default=0)
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    die_with_parent()
    port = args.port or free_port()
    with RR.ServerNodeSetup("experimental.foxglove_sink", port, argv=["command_sink"] + node_flags(port)):
        RRC.RegisterStdRobDefServiceTypes(RRN)
        RRN.RegisterServiceType(ROBDEF)
        sink = Sink()
        RRN.RegisterService("sink", "experimental.foxglove_sink.Sink", sink)
        stop = threading.Event()

        def clock():
            seqno = 0
            while not stop.wait(0.05):
                seqno += 1
                sink.tick(seqno)

        threading.Thread(target=clock, daemon=True).start()
        ready(url=f"rr+tcp://127.0.0.1:{port}/?service=sink", port=port, pid=os.getpid())
        wait_for_stop(args.max_lifetime)
        stop.set()


if __name__ == "__main__":
    main()
