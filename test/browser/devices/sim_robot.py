#!/usr/bin/env python3
"""A simulated three-joint arm on the official abstract robot base (PyPI robotraconteur-abstract-robot,
pinned in test/interop/requirements.txt), served as a standard com.robotraconteur.robotics.robot.Robot.

Its RobotInfo comes from sim_robot_info.yml through RobotRaconteurCompanion's InfoFileLoader and its
service attributes from AttributesUtil, as the robot drivers do. The simulation (SimArm, a subclass
of AbstractRobot) is the "controller" the base class talks to: every loop step it reports the joint
positions, the tool pose by forward kinematics of the chain in the RobotInfo, and ready/enabled;
commands from the base class (jog, position commands) move the joints toward their targets at the
joint's velocity limit. It starts disabled; enable() (or --enabled) switches the motors on.

--joints-stdin (for tests): each line on stdin, a JSON list of joint positions, puts the joints there
at once (motors on or off), cancelling any motion; the next loop step reports them and their tool pose.

--log-joints (for tests): the robot's own joint log on stdout, one line per loop step in which a joint
moved, {"joints": <time.time()>, "q": [...]}: what a motion test reads to say when the robot stopped,
without a client of the robot in between.

The controller the sim stands for: in halt (and any mode without a command) the motors hold where they
are; halt() (the standard robot's stop, which the abstract robot base leaves out) switches to halt. In
position_command and velocity_command it follows the newest value the wire holds and keeps doing so when
the sender goes quiet: a controller without a watchdog of its own, the case the gateway's stream guard is
for (docs/security.md "Motion safety"). The base class reads velocity commands with a typo in 0.2.2
(`stat_seqno`), so the sim reads them itself.

Ready line: {"url": "rr+tcp://127.0.0.1:P/?service=robot", "port": P, "device_uuid": "...",
"joint_names": [...]}.

Usage: sim_robot.py [--info FILE] [--enabled] [--start-position Q0,Q1,...] [--joints-stdin] [--period 0.02]
                    [--log-joints] [--velocity-command] [--users FILE] [--max-lifetime 300]
"""

import argparse
import json
import os
import sys
import threading
import time
import uuid

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import die_with_parent, free_port, node_flags, ready, wait_for_stop, log  # noqa: E402

import numpy as np  # noqa: E402
import general_robotics_toolbox as rox  # noqa: E402
import RobotRaconteur as RR  # noqa: E402
import RobotRaconteurCompanion as RRC  # noqa: E402
from RobotRaconteurCompanion.Util.InfoFileLoader import InfoFileLoader  # noqa: E402
from RobotRaconteurCompanion.Util.AttributesUtil import AttributesUtil  # noqa: E402
from robotraconteur_abstract_robot import AbstractRobot  # noqa: E402

RRN = RR.RobotRaconteurNode.s
_stdout_lock = threading.Lock()


def emit(value):
    """One JSON line on stdout in one piece: the loop thread's and the RR threads' lines never interleave."""
    with _stdout_lock:
        sys.stdout.write(json.dumps(value) + "\n")
        sys.stdout.flush()


class SimArm(AbstractRobot):
    """The arm's joints follow the base class's commands at the velocity limits of the RobotInfo."""

    def __init__(self, robot_info, period, enabled, start_position=None, velocity_command=False):
        super().__init__(robot_info, 0)
        self._update_period = period
        self._base_set_controller_state = True
        self._uses_homing = False
        self._has_position_command = True
        self._has_velocity_command = velocity_command
        self._has_jog_command = True
        self._q = np.zeros(self._joint_count)
        if start_position is not None:
            given = start_position[:self._joint_count]
            self._q[:len(given)] = given
        self._q_target = None
        self._max_speed = np.array([j.joint_limits.velocity for j in robot_info.joint_info])
        self._q_min = np.array([j.joint_limits.lower for j in robot_info.joint_info])
        self._q_max = np.array([j.joint_limits.upper for j in robot_info.joint_info])
        self._sim_lock = threading.Lock()
        self._motors_on = enabled
        self._last_step = None
        self._log_jog = False
        self._log_joints = False
        self._q_velocity = None  # velocity_command: the joints move at this (rad/s)
        self._logged_q = None

    # the "controller": feedback each step, then the base class's own step
    def _run_timestep(self, now):
        with self._sim_lock:
            dt = 0.0 if self._last_step is None else now - self._last_step
            self._last_step = now
            if self._q_velocity is not None and self._motors_on:
                # at a joint limit the joint stops there (the controller's end stop)
                self._q = np.clip(self._q + np.clip(self._q_velocity, -self._max_speed, self._max_speed) * dt,
                                  self._q_min, self._q_max)
            elif self._q_target is not None and self._motors_on:
                step = np.clip(self._q_target - self._q, -self._max_speed * dt, self._max_speed * dt)
                self._q = self._q + step
            q = self._q.copy()
            on = self._motors_on
        if self._log_joints and (self._logged_q is None or np.any(q != self._logged_q)):
            self._logged_q = q
            emit({"joints": time.time(), "q": [float(x) for x in q]})
        pose = rox.fwdkin(self._rox_robots[0], q)
        with self._lock:
            self._joint_position = q
            self._joint_velocity = np.zeros(self._joint_count)
            self._joint_effort = np.zeros(self._joint_count)
            self._endpoint_pose = [self._geometry_util.rox_transform_to_pose(pose)]
            self._endpoint_vel = [np.zeros((1,), dtype=self._spatial_velocity_dtype)[0]]
            self._ready = on
            self._enabled = on
            self._last_robot_state = now
            self._last_joint_state = now
            self._last_endpoint_state = now
        super()._run_timestep(now)

    def teleport(self, q):
        """Puts the joints at q at once (a test's shortcut; no velocity limits)."""
        q = np.array(q, dtype=np.float64)
        if q.shape != (self._joint_count,):
            raise ValueError(f"{self._joint_count} joint positions expected, got {q.shape}")
        with self._sim_lock:
            self._q = q
            self._q_target = None
            self._q_velocity = None

    def async_jog_joint(self, joint_velocity, timeout, wait, handler):
        # --log-jog: one stdout line per jog call as it reaches the driver, so a test can tell a late
        # call (starved delivery) from a robot that kept moving past the call's timeout.
        if self._log_jog:
            emit({"jog_joint": time.time(), "timeout": timeout})
        return super().async_jog_joint(joint_velocity, timeout, wait, handler)

    def halt(self):
        """The standard robot's stop: command mode halt (the motors hold where they are)."""
        with self._lock:
            self._command_mode = self._robot_command_mode["halt"]

    def _fill_robot_command(self, now):
        if self._command_mode != self._robot_command_mode["velocity_command"]:
            return super()._fill_robot_command(now)
        # velocity_command: the newest value on the wire, as long as it fits (no staleness check: see above)
        res, vel_cmd, _ts, _ep = self.velocity_command.TryGetInValue()
        if not res or vel_cmd is None or len(vel_cmd.command) != self._joint_count:
            return True, None, None
        return True, None, np.array(vel_cmd.command, dtype=np.float64) * self._speed_ratio

    def _send_robot_command(self, now, joint_pos_cmd, joint_vel_cmd):
        with self._sim_lock:
            if joint_vel_cmd is not None:
                self._q_velocity = joint_vel_cmd
                self._q_target = None
            elif joint_pos_cmd is not None:
                self._q_velocity = None
                self._q_target = np.array(joint_pos_cmd, dtype=np.float64)
            else:
                self._q_velocity = None
                mode = self._command_mode
                if mode != self._robot_command_mode["position_command"]:
                    self._q_target = None  # no command: the motors hold

    def _send_enable(self, handler):
        with self._sim_lock:
            self._motors_on = True
        handler(None)

    def _send_disable(self, handler):
        with self._sim_lock:
            self._motors_on = False
        handler(None)

    def _send_reset_errors(self, handler):
        handler(None)


def teleport_from_stdin(robot):
    """--joints-stdin: every line a JSON list of joint positions; a bad line is logged and skipped."""
    for line in sys.stdin:
        if not line.strip():
            continue
        try:
            robot.teleport(json.loads(line))
        except (ValueError, TypeError) as e:
            log("robot", f"--joints-stdin: {e}: {line.strip()[:200]}")


def main():
    die_with_parent()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--info", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "sim_robot_info.yml"))
    ap.add_argument("--enabled", action="store_true", help="motors on from the start")
    ap.add_argument("--start-position", type=lambda t: [float(x) for x in t.split(",")], default=None,
                    help="joint positions to start at (joint units, comma-separated; default all 0)")
    ap.add_argument("--joints-stdin", action="store_true",
                    help="each stdin line, a JSON list of joint positions, puts the joints there at once")
    ap.add_argument("--period", type=float, default=0.02, help="loop period in seconds")
    ap.add_argument("--max-lifetime", type=float, default=300)
    ap.add_argument("--log-jog", action="store_true", help="print a JSON line as each jog_joint call arrives")
    ap.add_argument("--log-joints", action="store_true", help="print the joints each loop step in which they moved")
    ap.add_argument("--velocity-command", action="store_true", help="offer the velocity_command capability")
    ap.add_argument("--users", help="require logins: an official password file (user, MD5, privileges; objectlock "
                                    "lets a user take object locks)")
    args = ap.parse_args()
    port = free_port()
    with RR.ServerNodeSetup("experimental.sim_arm", port, argv=["sim_robot"] + node_flags(port)):
        RRC.RegisterStdRobDefServiceTypes(RRN)
        robot_info, _ = InfoFileLoader(RRN).LoadInfoFile(args.info, "com.robotraconteur.robotics.robot.RobotInfo", "robot")
        attributes = AttributesUtil(RRN).GetDefaultServiceAttributesFromDeviceInfo(robot_info.device_info)
        robot = SimArm(robot_info, args.period, args.enabled, args.start_position, args.velocity_command)
        robot._log_jog = args.log_jog
        robot._start_robot()
        security = None
        if args.users:
            with open(args.users) as f:
                security = RR.ServiceSecurityPolicy(RR.PasswordFileUserAuthenticator(f.read()),
                                                    {"requirevaliduser": "true", "allowobjectlock": "true"})
        ctx = RRN.RegisterService("robot", "com.robotraconteur.robotics.robot.Robot", robot, security)
        ctx.SetServiceAttributes(attributes)
        device_uuid = str(uuid.UUID(bytes=bytes(robot_info.device_info.device.uuid["uuid_bytes"].tobytes())))
        with _stdout_lock:
            ready(url=f"rr+tcp://127.0.0.1:{port}/?service=robot", port=port, device_uuid=device_uuid,
                  joint_names=list(robot._joint_names), pid=os.getpid())
        robot._log_joints = args.log_joints  # after the ready line, which must stay the first one
        if args.joints_stdin:
            threading.Thread(target=teleport_from_stdin, args=(robot,), daemon=True).start()
        wait_for_stop(args.max_lifetime)
        log("robot", "stopping")
        robot._close()


if __name__ == "__main__":
    main()
