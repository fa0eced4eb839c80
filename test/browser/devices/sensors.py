#!/usr/bin/env python3
"""Standard sensors on the official Robot Raconteur Python library (standard definitions registered from
the robotraconteurcompanion package, as drivers do), for the dashboard's sensor panel tests.

Services of one node:

  "wrench"   com.robotraconteur.sensor.WrenchSensor: a force/torque sensor on a wrist, 50 Hz.
             wrench_sensor_value follows a pattern of time t (s since start):
               force  = (20 sin(pi t), 10 cos(pi t), -49.05 + 5 sin(0.4 pi t)) N
               torque = (0.8 sin(pi t), -0.5 cos(pi t), 0.1 sin(0.4 pi t)) N*m
             sensor_value is the same six numbers (torque x y z, force x y z), sensor_data the same as
             SensorData; sensor_info names its units (N*m three times, then N three times) and one
             parameter, filter_cutoff (Hz, 100 at start: getf_param/setf_param; each set printed
             as {"param_set": name, "value": v}).
  "climate"  com.robotraconteur.sensor.Sensor: two named values, temperature (degC) and relative
             humidity (%), 5 Hz, drifting slowly.

  "imu"      com.robotraconteur.imu.ImuSensor: imu_state at 20 Hz, spinning about z at 0.5 rad/s (yaw
             0.5 t), level (gravity 9.81 m/s^2 on z); held still at a given yaw on command.
  "gps"      com.robotraconteur.gps.GpsSensor: gps_state at 5 Hz, walking a circle of 20 m radius at
             1 m/s around 42.7285 N, 73.6789 W, altitude 120.5 m; fix dgps_fix, 9 of 14 satellites,
             horizontal error 0.8 m, error 1.5 m.

With --old-layout the node instead serves "wrench" from a definition of com.robotraconteur.sensor
as an older or trimmed release might have it: WrenchSensor without wrench_sensor_value and
sensor_info, sensor_value only. The dashboard must fall back to its generic member view.

The test drives it by JSON lines on stdin, each answered by one JSON line on stdout:
  {"hold": {"torque": [x, y, z], "force": [x, y, z]}}  the wrench (and sensor_value) stay at these
                                                       -> {"held": {...}}
  {"resume": true}                                     the pattern again -> {"resumed": true}
  {"imu_hold": yaw_deg}                                the IMU still at that yaw -> {"imu_held": yaw_deg}

Ready line: {"url": "rr+tcp://127.0.0.1:P/?service=wrench", "climate_url": ..., "imu_url", "gps_url", "port": P,
"units": [...]}.

Usage: sensors.py [--old-layout] [--max-lifetime 300]
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

import numpy as np  # noqa: E402
import RobotRaconteur as RR  # noqa: E402
import RobotRaconteurCompanion as RRC  # noqa: E402
from RobotRaconteurCompanion.Util.IdentifierUtil import IdentifierUtil  # noqa: E402
from RobotRaconteurCompanion.Util.SensorDataUtil import SensorDataUtil  # noqa: E402

RRN = RR.RobotRaconteurNode.s
_stdout_lock = threading.Lock()

WRENCH_UNITS = ["N·m", "N·m", "N·m", "N", "N", "N"]

OLD_ROBDEF = """\
service com.robotraconteur.sensor

stdver 0.9

object WrenchSensor
    property string device_name [readonly,nolock]
    wire double[] sensor_value [readonly,nolock]
end
"""


def emit(value):
    with _stdout_lock:
        sys.stdout.write(json.dumps(value) + "\n")
        sys.stdout.flush()


def wrench_pattern(t):
    """(torque, force) at t seconds."""
    w = math.pi
    force = (20 * math.sin(w * t), 10 * math.cos(w * t), -49.05 + 5 * math.sin(0.4 * w * t))
    torque = (0.8 * math.sin(w * t), -0.5 * math.cos(w * t), 0.1 * math.sin(0.4 * w * t))
    return torque, force


def device_info(name, model):
    ident = IdentifierUtil(RRN)
    info = RRN.NewStructure("com.robotraconteur.device.DeviceInfo")
    info.device = ident.CreateIdentifierFromName(name)
    info.manufacturer = ident.CreateIdentifierFromName("rr-gateway tests")
    info.model = ident.CreateIdentifierFromName(model)
    info.serial_number = f"{model.upper()}-0001"
    info.user_description = f"test {model}"
    return info


def si_units(texts):
    out = []
    for t in texts:
        u = RRN.NewStructure("com.robotraconteur.units.SIUnit")
        u.display_units = t
        u.encoded_units = t
        out.append(u)
    return out


class Periodic:
    """Calls step(t) every period seconds on a thread of its own until stop()."""

    def __init__(self, period, step):
        self.period, self.step = period, step
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def start(self):
        self._thread.start()

    def _run(self):
        t0 = time.monotonic()
        k = 0
        while not self._stop.is_set():
            try:
                self.step(time.monotonic() - t0)
            except Exception as e:  # a send racing the node's shutdown: the next step or stop() decides
                log("sensors", f"step: {type(e).__name__}: {e}")
            k += 1
            delay = t0 + k * self.period - time.monotonic()
            if delay > 0:
                self._stop.wait(delay)

    def stop(self):
        self._stop.set()
        self._thread.join(2)


class HeldPattern:
    """The wrench of the pattern, or one held on the test's command."""

    def __init__(self):
        self._lock = threading.Lock()
        self._held = None

    def hold(self, torque, force):
        with self._lock:
            self._held = (tuple(map(float, torque)), tuple(map(float, force)))

    def resume(self):
        with self._lock:
            self._held = None

    def wrench_at(self, t):
        with self._lock:
            return self._held or wrench_pattern(t)


class WrenchSensorImpl(HeldPattern, ParamStore):
    def __init__(self):
        HeldPattern.__init__(self)
        ParamStore.__init__(self, {"filter_cutoff": 100.0}, emit)
        self.device_info = device_info("wrist_ft", "ft-6")
        info = RRN.NewStructure("com.robotraconteur.sensor.SensorInfo")
        info.device_info = self.device_info
        info.sensor_type = RRN.GetConstants("com.robotraconteur.sensor")["SensorTypeCode"]["forcetorque"]
        info.units = si_units(WRENCH_UNITS)
        info.sensor_resolution = np.array([0.001] * 3 + [0.01] * 3)
        info.analog_sensor = False
        info.update_frequency = 50.0
        param = RRN.NewStructure("com.robotraconteur.param.ParameterInfo")
        param.parameter_identifier = IdentifierUtil(RRN).CreateIdentifierFromName("filter_cutoff")
        param.description = "low-pass filter cutoff"
        param.data_units = si_units(["Hz"])
        param.default_value = RR.VarValue(np.array([100.0]), "double[]")
        info.parameter_info = [param]
        self.sensor_info = info
        self._wrench_dtype = RRN.GetNamedArrayDType("com.robotraconteur.geometry.Wrench")
        self._data = SensorDataUtil(RRN)
        self._seqno = 0

    def step(self, t):
        torque, force = self.wrench_at(t)
        w = np.zeros((1,), dtype=self._wrench_dtype)
        w[0]["torque"] = torque
        w[0]["force"] = force
        six = np.array(list(torque) + list(force), dtype=np.float64)
        self.wrench_sensor_value.OutValue = w
        self.sensor_value.OutValue = six
        self._seqno += 1
        d = RRN.NewStructure("com.robotraconteur.sensor.SensorData")
        d.data_header = self._data.FillSensorDataHeader(self.device_info, self._seqno)
        d.data_flags = 0x1 | 0x2 | 0x400
        d.data = six
        d.data_units = si_units(WRENCH_UNITS)
        self.sensor_data.SendPacket(d)


class OldWrenchSensorImpl(HeldPattern):
    device_name = "wrist_ft (older definition)"

    def step(self, t):
        torque, force = self.wrench_at(t)
        self.sensor_value.OutValue = np.array(list(torque) + list(force), dtype=np.float64)


class ClimateSensorImpl(ParamStore):
    UNITS = ["°C", "%"]

    def __init__(self):
        ParamStore.__init__(self, {}, emit)
        self.device_info = device_info("bench_climate", "climate-2")
        info = RRN.NewStructure("com.robotraconteur.sensor.SensorInfo")
        info.device_info = self.device_info
        info.sensor_type = RRN.GetConstants("com.robotraconteur.sensor")["SensorTypeCode"]["temperature"]
        info.units = si_units(self.UNITS)
        info.sensor_resolution = np.array([0.1, 0.5])
        info.analog_sensor = True
        info.update_frequency = 5.0
        self.sensor_info = info
        self._data = SensorDataUtil(RRN)
        self._seqno = 0

    def step(self, t):
        values = np.array([21.5 + 0.5 * math.sin(0.2 * t), 40.0 + 2.0 * math.cos(0.1 * t)])
        self.sensor_value.OutValue = values
        self._seqno += 1
        d = RRN.NewStructure("com.robotraconteur.sensor.SensorData")
        d.data_header = self._data.FillSensorDataHeader(self.device_info, self._seqno)
        d.data_flags = 0x1 | 0x2 | 0x400
        d.data = values
        d.data_units = si_units(self.UNITS)
        self.sensor_data.SendPacket(d)


class ImuSensorImpl(ParamStore):
    def __init__(self):
        ParamStore.__init__(self, {}, emit)
        self.device_info = device_info("base_imu", "imu-9")
        info = RRN.NewStructure("com.robotraconteur.sensor.SensorInfo")
        info.device_info = self.device_info
        info.sensor_type = RRN.GetConstants("com.robotraconteur.sensor")["SensorTypeCode"]["inertial"]
        info.update_frequency = 20.0
        self.sensor_info = info
        self._quat = RRN.GetNamedArrayDType("com.robotraconteur.geometry.Quaternion")
        self._vec = RRN.GetNamedArrayDType("com.robotraconteur.geometry.Vector3")
        self._lock = threading.Lock()
        self._held_yaw = None

    def hold(self, yaw_deg):
        with self._lock:
            self._held_yaw = math.radians(float(yaw_deg))

    def step(self, t):
        with self._lock:
            held = self._held_yaw
        yaw, rate = (held, 0.0) if held is not None else (0.5 * t, 0.5)
        st = RRN.NewStructure("com.robotraconteur.imu.ImuState")
        q = np.zeros((1,), dtype=self._quat)
        q[0]["w"], q[0]["z"] = math.cos(yaw / 2), math.sin(yaw / 2)
        st.orientation = q
        w = np.zeros((1,), dtype=self._vec)
        w[0]["z"] = rate
        st.angular_velocity = w
        a = np.zeros((1,), dtype=self._vec)
        a[0]["z"] = 9.81
        st.linear_acceleration = a
        st.orientation_covariance = np.zeros((3, 3))
        st.angular_velocity_covariance = np.zeros((3, 3))
        st.linear_acceleration_covariance = np.zeros((3, 3))
        self.imu_state.OutValue = st
        self.sensor_value.OutValue = np.array([q[0]["w"], 0, 0, q[0]["z"], 0, 0, rate, 0, 0, 9.81])


GPS_CENTRE = (42.7285, -73.6789)


class GpsSensorImpl(ParamStore):
    def __init__(self):
        ParamStore.__init__(self, {}, emit)
        self.device_info = device_info("cart_gps", "gps-1")
        info = RRN.NewStructure("com.robotraconteur.sensor.SensorInfo")
        info.device_info = self.device_info
        info.sensor_type = RRN.GetConstants("com.robotraconteur.sensor")["SensorTypeCode"]["navigation"]
        info.update_frequency = 5.0
        self.sensor_info = info

    def step(self, t):
        r, w = 20.0, 1.0 / 20.0   # 1 m/s on a circle of 20 m
        east, north = r * math.sin(w * t), r * math.cos(w * t)
        lat = GPS_CENTRE[0] + math.degrees(north / 6371008.8)
        lon = GPS_CENTRE[1] + math.degrees(east / (6371008.8 * math.cos(math.radians(GPS_CENTRE[0]))))
        st = RRN.NewStructure("com.robotraconteur.gps.GpsState")
        status = RRN.NewStructure("com.robotraconteur.gps.GpsStatus")
        status.satellites_used = 9
        status.satellites_visible = 14
        status.status_code = RRN.GetConstants("com.robotraconteur.gps")["GpsMeasurementStatusCode"]["dgps_fix"]
        st.status = status
        st.latitude_deg, st.longitude_deg, st.altitude = lat, lon, 120.5
        st.track_deg = (math.degrees(w * t) + 90.0) % 360.0
        st.speed, st.err_horz, st.err = 1.0, 0.8, 1.5
        st.position_covariance = np.zeros((3, 3))
        self.gps_state.OutValue = st
        self.sensor_value.OutValue = np.array([lat, lon, 120.5])


def main():
    die_with_parent()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--old-layout", action="store_true")
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    port = free_port()
    with RR.ServerNodeSetup("experimental.std_sensors", port, argv=["sensors"] + node_flags(port)):
        loops = []
        if args.old_layout:
            RRN.RegisterServiceType(OLD_ROBDEF)
            wrench = OldWrenchSensorImpl()
            RRN.RegisterService("wrench", "com.robotraconteur.sensor.WrenchSensor", wrench)
            climate = None
        else:
            RRC.RegisterStdRobDefServiceTypes(RRN)
            wrench = WrenchSensorImpl()
            RRN.RegisterService("wrench", "com.robotraconteur.sensor.WrenchSensor", wrench)
            climate = ClimateSensorImpl()
            RRN.RegisterService("climate", "com.robotraconteur.sensor.Sensor", climate)
            loops.append(Periodic(0.2, climate.step))
            imu, gps = ImuSensorImpl(), GpsSensorImpl()
            RRN.RegisterService("imu", "com.robotraconteur.imu.ImuSensor", imu)
            RRN.RegisterService("gps", "com.robotraconteur.gps.GpsSensor", gps)
            loops += [Periodic(0.05, imu.step), Periodic(0.2, gps.step)]
        loops.append(Periodic(0.02, wrench.step))
        for loop in loops:
            loop.start()

        def commands():
            for line in sys.stdin:
                try:
                    cmd = json.loads(line)
                    if "hold" in cmd:
                        wrench.hold(cmd["hold"]["torque"], cmd["hold"]["force"])
                        reply = {"held": cmd["hold"]}
                    elif "imu_hold" in cmd:
                        imu.hold(cmd["imu_hold"])
                        reply = {"imu_held": cmd["imu_hold"]}
                    elif cmd.get("resume"):
                        wrench.resume()
                        reply = {"resumed": True}
                    else:
                        reply = {"failed": f"unknown command {line.strip()}"}
                except Exception as e:  # a wrong command is the test's mistake: say so, keep serving
                    reply = {"failed": f"{type(e).__name__}: {e}"}
                emit(reply)

        threading.Thread(target=commands, daemon=True).start()
        ready(url=f"rr+tcp://127.0.0.1:{port}/?service=wrench",
              climate_url=None if args.old_layout else f"rr+tcp://127.0.0.1:{port}/?service=climate",
              imu_url=None if args.old_layout else f"rr+tcp://127.0.0.1:{port}/?service=imu",
              gps_url=None if args.old_layout else f"rr+tcp://127.0.0.1:{port}/?service=gps", gps_centre=GPS_CENTRE,
              port=port, units=WRENCH_UNITS, climate_units=ClimateSensorImpl.UNITS, pid=os.getpid())
        wait_for_stop(args.max_lifetime)
        for loop in loops:
            loop.stop()
        log("sensors", "stopping")


if __name__ == "__main__":
    main()
