#!/usr/bin/env python3
"""A standard signal device on the official Robot Raconteur Python library, for the recording tests of
members below the root object (record_subobject_wire_test.py, docs/recording.md "Objects below the root").

Service "signals", root object com.robotraconteur.signal.SignalDevice (the standard definitions as the
robotraconteurcompanion package registers them, as drivers do). Its signals sit two objrefs below the
root: `signal_groups{string}` ("arm", "gripper"), then `signals{int32}` (0 and 1 in each group). Every
signal's `signal_value_vec` wire (double[]) sends, every --period-ms, the value

    [group number, signal number, seq, seq * 0.5]

(group number: 0 arm, 1 gripper; seq counts from 0 per signal), so a value names the object it came
from and its place in the stream. Other groups or signals: ObjectNotFound.

A second service on the same node, "tools" (experimental.record_tools.ToolHost, defined below), has
events below its root: `tools{int32}` (0 and 1), each Tool firing `tick(int32 tool, int32 seq)` every
--period-ms (seq counts from 0 per tool). Other tools: ObjectNotFound.

Ready line: {"url": "rr+tcp://127.0.0.1:P/?service=signals", "tools_url": ".../?service=tools", "port": P,
"groups": {...}}.

Usage: signal_device.py [--period-ms 50] [--max-lifetime 300]
"""

import argparse
import os
import sys
import threading

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "browser", "devices"))
from common import die_with_parent, free_port, node_flags, ready, wait_for_stop  # noqa: E402

import numpy as np  # noqa: E402
import RobotRaconteur as RR  # noqa: E402
import RobotRaconteurCompanion as RRC  # noqa: E402

RRN = RR.RobotRaconteurNode.s
GROUPS = {"arm": 0, "gripper": 1}
SIGNALS_PER_GROUP = 2


class Signal:
    """com.robotraconteur.signal.Signal: the node sets the wire attributes when the object is served."""

    def __init__(self, group, index):
        self.group, self.index, self.seq = group, index, 0
        self._lock = threading.Lock()
        self._vec = None
        self.signal_info = None
        self.isoch_info = None
        self.isoch_downsample = 0

    @property
    def signal_value_vec(self):
        return self._vec_wire

    @signal_value_vec.setter
    def signal_value_vec(self, wire):
        self._vec_wire = wire
        with self._lock:
            self._vec = RR.WireBroadcaster(wire)

    def tick(self):
        with self._lock:
            if self._vec is None:
                return
            self._vec.OutValue = np.array([self.group, self.index, self.seq, self.seq * 0.5], dtype=np.float64)
            self.seq += 1


class SignalGroup:
    def __init__(self, group):
        self.signal_info = []
        self.signals_by_index = [Signal(group, i) for i in range(SIGNALS_PER_GROUP)]

    def get_signals(self, ind):
        k = int(ind)  # the Python skeleton hands int32 indexes over as text
        if not 0 <= k < len(self.signals_by_index):
            raise RR.ObjectNotFoundException("no signals[%d]" % k)
        return self.signals_by_index[k], "com.robotraconteur.signal.Signal"


TOOLS_ROBDEF = """service experimental.record_tools

stdver 0.10

object Tool
    property int32 number [readonly]
    event tick(int32 tool, int32 seq)
end

object ToolHost
    objref Tool{int32} tools
end
"""


class Tool:
    def __init__(self, number):
        self.number, self.seq = number, 0
        self.tick = RR.EventHook()

    def fire(self):
        self.tick.fire(self.number, self.seq)
        self.seq += 1


class ToolHost:
    def __init__(self):
        self.tools_by_index = [Tool(i) for i in range(2)]

    def get_tools(self, ind):
        k = int(ind)  # the Python skeleton hands int32 indexes over as text
        if not 0 <= k < len(self.tools_by_index):
            raise RR.ObjectNotFoundException("no tools[%d]" % k)
        return self.tools_by_index[k], "experimental.record_tools.Tool"


class SignalDevice:
    def __init__(self):
        self.device_info = None
        self.signal_group_info = []
        self.groups = {name: SignalGroup(number) for name, number in GROUPS.items()}

    def get_signal_groups(self, ind):
        if ind not in self.groups:
            raise RR.ObjectNotFoundException("no signal_groups[%s]" % ind)
        return self.groups[ind], "com.robotraconteur.signal.SignalGroup"

    def all_signals(self):
        return [s for g in self.groups.values() for s in g.signals_by_index]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--period-ms", type=float, default=50)
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    die_with_parent()
    port = free_port()
    device = SignalDevice()
    with RR.ServerNodeSetup("experimental.signal_device", port, argv=["signal_device"] + node_flags(port)):
        RRC.RegisterStdRobDefServiceTypes(RRN)
        RRN.RegisterService("signals", "com.robotraconteur.signal.SignalDevice", device)
        RRN.RegisterServiceType(TOOLS_ROBDEF)
        tools = ToolHost()
        RRN.RegisterService("tools", "experimental.record_tools.ToolHost", tools)
        stop = threading.Event()

        def ticker():
            while not stop.wait(args.period_ms / 1000.0):
                for s in device.all_signals():
                    s.tick()
                for t in tools.tools_by_index:
                    t.fire()
        t = threading.Thread(target=ticker, daemon=True)
        t.start()
        ready(url=f"rr+tcp://127.0.0.1:{port}/?service=signals", tools_url=f"rr+tcp://127.0.0.1:{port}/?service=tools",
              port=port, groups=GROUPS, pid=os.getpid())
        wait_for_stop(args.max_lifetime)
        stop.set()
        t.join(2)


if __name__ == "__main__":
    main()
