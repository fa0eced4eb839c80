#!/usr/bin/env python3
"""The gateway as the dead-man for motion (issue 52; docs/security.md "Motion safety"), end to end: a
standard robot (test/browser/devices/sim_robot.py, the official robotraconteur-abstract-robot) behind
rr-gateway, clients that start a motion and then vanish, and the robot's own joint log (sim_robot.py
--log-joints, read from the driver's stdout, never through a client) to say when it stopped.

Each client runs as a child process of this script (--client KIND) and is taken away two ways: killed
(SIGKILL: its connection closes) or cut (a TCP relay between it and the gateway stops forwarding both
ways and keeps both connections open, as a black-holed proxy or a pulled cable does). The robot must
stop within the bound (safety.hold_to_run_max_s, 0.5 s by default) plus MARGIN_S after the event.

Cases (--case, one ctest each):
  rest       POST jog_joint with timeout 60 (clamped), client killed and cut; jog_freespace with wait false
             refused (409); jog_freespace with wait true, client killed mid-move
  ws         the JSON WebSocket: jog_joint 60 s killed and cut; jog_freespace (wait false) killed and cut
             (the gateway's pings); a second socket's jog refused naming the holder
  rr         an official RR client through the gateway: jog_joint 60 s killed and cut; jog_freespace (wait
             false) killed and cut (the gateway's ConnectionTest probe); execute_trajectory killed; a
             second client refused naming the holder, then allowed once the first one's hold ended
  stream     velocity_command streamed by an official client, which then goes silent (cut) or is killed;
             another sender's packets are dropped and its wire connect refused while the first streams
  locks      gateway users: alice (objectlock) holds the robot's object lock and a monitor through the
             gateway while jogging; bob's halt() (RR) and command_mode = halt (REST) still stop it; a
             passthrough device: a client's monitor lock on the device, another client's halt still
             reaches it

Exit 0 when every check passed, 1 when one failed, 77 (SKIP) without the venv's packages.
"""

import argparse
import http.client
import json
import os
import select
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import traceback
import urllib.error
import urllib.request

HERE = os.path.dirname(os.path.abspath(__file__))
DEVICES = os.path.join(HERE, "..", "browser", "devices")
sys.path.insert(0, os.path.join(HERE, "..", "interop"))
from child_procs import die_with_parent, read_json_line  # noqa: E402

try:
    import numpy as np
    import RobotRaconteur as RR
    import RobotRaconteurCompanion as RRC
    import robotraconteur_abstract_robot  # noqa: F401
    import websocket
except ImportError as e:  # pragma: no cover
    print("SKIP: %s (run ./scripts/setup.sh)" % e)
    sys.exit(77)

RRN = RR.RobotRaconteurNode.s
BOUND_S = 0.5
# What a loaded CI machine may add to the bound: the stop's way to the driver and one of its loop steps
# (the ASan gateway beside other tests: a second is generous, the figure measured is printed).
MARGIN_S = 1.5
# The robot counts as stopped when its joints did not move for this long (its loop runs every 20 ms).
QUIET_S = 2.0
MODE = {"halt": 0, "jog": 1, "trajectory": 2, "position_command": 3, "velocity_command": 4}  # RobotCommandMode
RR_FLAGS = ["--robotraconteur-local-enable=false", "--robotraconteur-tcp-ipv4-discovery=false",
            "--robotraconteur-tcp-ipv6-discovery=false"]


class CheckFailed(Exception):
    pass


def expect(cond, what):
    if not cond:
        raise CheckFailed(what)
    print("ok: " + what, flush=True)


# --- the robot and its own joint log -------------------------------------------------------------

class Robot:
    def __init__(self, work, extra=(), login=None):
        self.errf = open(os.path.join(work, "robot.log"), "ab")
        self.proc = subprocess.Popen([sys.executable, os.path.join(DEVICES, "sim_robot.py"), "--enabled", "--log-joints",
                                      "--max-lifetime", "600"] + list(extra),
                                     stdout=subprocess.PIPE, stderr=self.errf, stdin=subprocess.DEVNULL,
                                     preexec_fn=die_with_parent)
        self.lock = threading.Lock()
        self.cond = threading.Condition(self.lock)
        self.moves = []  # (time.time(), q) of each step in which a joint moved
        self.info = None
        threading.Thread(target=self._read, daemon=True).start()
        end = time.monotonic() + 120
        with self.cond:  # the joint log may begin before the ready line
            while self.info is None:
                if time.monotonic() > end or self.proc.poll() is not None:
                    raise CheckFailed("sim_robot.py: no ready line after %.0f s (exit %s)" % (120 - (end - time.monotonic()), self.proc.poll()))
                self.cond.wait(0.5)
        self.url = self.info["url"]
        # the test's own session, straight to the robot
        if login:
            self.direct = RRN.ConnectService(self.url, login[0], {"password": RR.VarValue(login[1], "string")})
        else:
            self.direct = RRN.ConnectService(self.url)

    def _read(self):
        for line in self.proc.stdout:
            try:
                v = json.loads(line)
            except ValueError:
                continue
            if isinstance(v, dict) and "joints" in v:
                with self.cond:
                    self.moves.append((v["joints"], v["q"]))
                    self.cond.notify_all()
            elif isinstance(v, dict) and "url" in v:
                with self.cond:
                    self.info = v
                    self.cond.notify_all()

    def mode(self, name):
        """Sets the command mode straight on the robot (halt first: the abstract robot switches only from it)."""
        self.direct.command_mode = MODE["halt"]
        if name != "halt":
            self.direct.command_mode = MODE[name]

    def position(self):
        return [float(x) for x in self.direct.robot_state.PeekInValue()[0].joint_position]

    def teleport_home(self):
        """Back to a known place for the next scenario (halt, then wait until it stands still)."""
        self.mode("halt")
        self.wait_stopped(time.time(), "reset", limit=20)

    def wait_moving(self, since, what, limit=30):
        """Waits until the joints move after `since` (the motion this scenario started)."""
        end = time.monotonic() + limit
        with self.cond:
            while not any(t > since for t, _ in self.moves):
                left = end - time.monotonic()
                if left <= 0:
                    raise CheckFailed("%s: the robot did not start moving within %d s" % (what, limit))
                self.cond.wait(left)

    def wait_stopped(self, since, what, limit=25):
        """Waits until no joint moved for QUIET_S; returns the time of the last motion (>= since or since)."""
        end = time.monotonic() + limit
        with self.cond:
            while True:
                last = max([t for t, _ in self.moves] + [since])
                if time.time() - last >= QUIET_S:
                    return last
                left = end - time.monotonic()
                if left <= 0:
                    raise CheckFailed("%s: the robot still moves %.1f s after the event (last motion %.2f s after it)"
                                      % (what, time.time() - since, last - since))
                self.cond.wait(min(left, 0.2))

    def stop(self):
        try:
            self.proc.send_signal(signal.SIGTERM)
            self.proc.wait(20)
        except subprocess.TimeoutExpired:
            self.proc.kill()


def stopped_within_bound(robot, event, what, bound=BOUND_S):
    last = robot.wait_stopped(event, what)
    took = last - event
    print("# %s: last motion %.3f s after the event (bound %.2f s + margin %.2f s)" % (what, took, bound, MARGIN_S),
          flush=True)
    expect(took <= bound + MARGIN_S, "%s: the robot stopped within the bound (%.3f s)" % (what, took))


# --- the gateway ---------------------------------------------------------------------------------

class Gateway:
    def __init__(self, exe, work, config_text, name="gateway"):
        path = os.path.join(work, name + ".yaml")
        with open(path, "w") as f:
            f.write(config_text)
        self.errf = open(os.path.join(work, name + ".log"), "ab")
        self.proc = subprocess.Popen([exe, "--config", path, "--listen", "127.0.0.1", "--port", "0", "--no-local",
                                      "--no-discovery", "--no-demo"],
                                     stdout=subprocess.PIPE, stderr=self.errf, stdin=subprocess.DEVNULL,
                                     preexec_fn=die_with_parent)
        self.port = read_json_line(self.proc, 60, "rr-gateway")["port"]
        self.base = "http://127.0.0.1:%d" % self.port
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            try:
                with urllib.request.urlopen(self.base + "/readyz", timeout=5) as r:
                    if r.status == 200:
                        return
            except (urllib.error.URLError, OSError):
                pass
            time.sleep(0.2)
        raise CheckFailed("rr-gateway not ready")

    def stop(self):
        self.proc.send_signal(signal.SIGTERM)
        try:
            status = self.proc.wait(30)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            status = "hung"
        expect(status == 0, "rr-gateway exits 0 (status %s)" % status)


def rest(base, method, path, body=None, headers=None, timeout=30):
    data = json.dumps(body).encode() if body is not None else None
    h = {"Content-Type": "application/json"}
    h.update(headers or {})
    req = urllib.request.Request(base + path, data=data, method=method, headers=h)
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            return r.status, json.loads(r.read() or b"null")
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read() or b"null")


# --- a TCP relay that can stop forwarding ----------------------------------------------------------

class Relay:
    """Forwards 127.0.0.1:port to the gateway. cut(): both directions stop being forwarded while the
    connections stay open (nothing more is read, so nothing more arrives anywhere)."""

    def __init__(self, target_port):
        self.target = target_port
        self.listener = socket.socket()
        self.listener.bind(("127.0.0.1", 0))
        self.listener.listen(16)
        self.port = self.listener.getsockname()[1]
        self.cut_flag = threading.Event()
        self.sockets = []
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self):
        while True:
            try:
                c, _ = self.listener.accept()
            except OSError:
                return
            u = socket.create_connection(("127.0.0.1", self.target))
            self.sockets += [c, u]
            threading.Thread(target=self._pump, args=(c, u), daemon=True).start()

    def _pump(self, a, b):
        peers = {a: b, b: a}
        while not self.cut_flag.is_set():
            try:
                ready, _, _ = select.select([a, b], [], [], 0.05)
            except (OSError, ValueError):
                return
            for s in ready:
                if self.cut_flag.is_set():
                    return
                try:
                    data = s.recv(65536)
                except OSError:
                    data = b""
                if not data:
                    for x in (a, b):
                        try:
                            x.close()
                        except OSError:
                            pass
                    return
                peers[s].sendall(data)

    def cut(self):
        self.cut_flag.set()

    def close(self):
        self.cut_flag.set()
        for s in self.sockets + [self.listener]:
            try:
                s.close()
            except OSError:
                pass


# --- clients (each a child process: --client KIND) -------------------------------------------------

def client_main(args):
    """One client: starts a motion, prints {"started": …} (or the refusal), then keeps its connection
    (reading, so that it answers pings and ConnectionTests) until killed."""
    die_with_parent()
    kind = args.client
    out = lambda **v: print(json.dumps(v), flush=True)  # noqa: E731
    if kind.startswith("rest-"):
        conn = http.client.HTTPConnection("127.0.0.1", args.port, timeout=600)
        body = {"jog": {"args": {"joint_velocity": [0.1, 0, 0], "timeout": 60, "wait": False}},
                "freespace": {"args": {"joint_position": args.target, "max_velocity": [0.015, 0.015, 0.015], "wait": True}},
                }[kind[5:]]
        member = {"jog": "jog_joint", "freespace": "jog_freespace"}[kind[5:]]
        out(sending=time.time())
        conn.request("POST", "/api/devices/robot/functions/" + member, json.dumps(body), {"Content-Type": "application/json"})
        r = conn.getresponse()
        out(started=time.time(), status=r.status, body=json.loads(r.read() or b"null"))
        while True:
            time.sleep(1)
    if kind.startswith("ws-"):
        ws = websocket.create_connection("ws://127.0.0.1:%d/" % args.port, subprotocols=["rr-gateway.json.v1"])
        if args.user:
            ws.send(json.dumps({"id": "login", "op": "login", "username": args.user, "password": args.user + "-pw"}))
        call = {"jog": ("jog_joint", {"joint_velocity": [0.1, 0, 0], "timeout": 60, "wait": False}),
                "jog-short": ("jog_joint", {"joint_velocity": [0.1, 0, 0], "timeout": 0.15, "wait": False}),
                "freespace": ("jog_freespace", {"joint_position": args.target, "max_velocity": [0.015, 0.015, 0.015],
                                                "wait": False})}[kind[3:]]
        ws.send(json.dumps({"id": 1, "op": "call", "device": "robot", "member": call[0], "args": call[1]}))
        while True:
            m = json.loads(ws.recv())
            if m.get("id") == 1:
                out(started=time.time(), reply=m)
                break
        while True:
            ws.recv()  # pushes; websocket-client answers pings while it reads
    # rr-*: the official client through the gateway
    flags = ["motion_client"] + RR_FLAGS
    with RR.ClientNodeSetup(argv=flags):
        RRC.RegisterStdRobDefServiceTypes(RRN)
        if args.user:
            robot = RRN.ConnectService(args.url, args.user, {"password": RR.VarValue(args.user + "-pw", "string")})
        else:
            robot = RRN.ConnectService(args.url)
        try:
            if kind == "rr-jog":
                robot.jog_joint(np.array([0.1, 0, 0]), 60.0, False)
            elif kind == "rr-freespace":
                robot.jog_freespace(np.array(args.target), np.array([0.015, 0.015, 0.015]), False)
            elif kind == "rr-trajectory":
                gen = robot.execute_trajectory(trajectory(robot, args.start, args.target, 20.0))
                gen_thread = threading.Thread(target=lambda: [gen.Next() for _ in range(100000)], daemon=True)
                gen_thread.start()
            elif kind == "rr-stream":
                wire = robot.velocity_command.Connect()
                cmd_type = RRN.GetStructureType("com.robotraconteur.robotics.robot.RobotJointCommand", robot)
                out(started=time.time())
                seqno = 0
                while True:  # a command every 50 ms, as a joystick would
                    seqno += 1
                    c = cmd_type()
                    c.seqno = seqno
                    c.state_seqno = 0
                    c.command = np.array([0.2, 0, 0])
                    c.units = np.zeros((0,), dtype=np.uint8)
                    wire.OutValue = c
                    time.sleep(0.05)
        except RR.RobotRaconteurException as e:
            out(refused=time.time(), error=str(e), name=type(e).__name__)
            return
        out(started=time.time())
        while True:
            time.sleep(1)


def trajectory(robot, start, target, duration):
    """A JointTrajectory from `start` to `target` in `duration` s (one waypoint every 50 ms)."""
    traj_t = RRN.GetStructureType("com.robotraconteur.robotics.trajectory.JointTrajectory", robot)
    wp_t = RRN.GetStructureType("com.robotraconteur.robotics.trajectory.JointTrajectoryWaypoint", robot)
    waypoints = []
    n = int(duration / 0.05)  # the interpolator wants waypoints at most 100 ms apart
    points = [(duration * i / n, [a + (b - a) * i / n for a, b in zip(start, target)]) for i in range(n + 1)]
    for t, q in points:
        wp = wp_t()
        wp.joint_position = np.array(q, dtype=np.float64)
        wp.joint_velocity = np.zeros((3,))
        wp.position_tolerance = np.zeros((3,))
        wp.velocity_tolerance = np.zeros((3,))
        wp.interpolation_mode = 0
        wp.waypoint_type = 0
        wp.time_from_start = t
        waypoints.append(wp)
    traj = traj_t()
    traj.joint_names = ["shoulder", "elbow", "wrist"]
    traj.waypoints = waypoints
    return traj


class Client:
    def __init__(self, work, kind, port=None, url=None, target=None, start=None, user=None):
        argv = [sys.executable, os.path.abspath(__file__), "--client", kind]
        if port:
            argv += ["--port", str(port)]
        if url:
            argv += ["--url", url]
        if target:
            argv += ["--target=" + ",".join(str(x) for x in target)]
        if start:
            argv += ["--start=" + ",".join(str(x) for x in start)]
        if user:
            argv += ["--user", user]
        self.errf = open(os.path.join(work, "client-%s.log" % kind), "ab")
        self.proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=self.errf, stdin=subprocess.DEVNULL,
                                     preexec_fn=die_with_parent, text=True)
        self.lines = []
        self.cond = threading.Condition()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.proc.stdout:
            try:
                v = json.loads(line)
            except ValueError:
                continue
            with self.cond:
                self.lines.append(v)
                self.cond.notify_all()

    def wait_line(self, key, limit=60):
        end = time.monotonic() + limit
        with self.cond:
            while True:
                for v in self.lines:
                    if key in v:
                        return v
                left = end - time.monotonic()
                if left <= 0 or self.proc.poll() is not None and not any(key in v for v in self.lines):
                    if left > 0:
                        self.cond.wait(0.5)
                        if any(key in v for v in self.lines):
                            continue
                    raise CheckFailed("client %s: no %r line (lines %s, exit %s)" % (self.proc.args[3], key, self.lines,
                                                                                      self.proc.poll()))
                self.cond.wait(min(left, 0.5))

    def kill(self):
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()


def take_away(client, relay, how):
    """Kills the client or cuts its relay; returns the time of the event."""
    t = time.time()
    if how == "kill":
        client.kill()
    else:
        relay.cut()
    return t


# --- the cases -------------------------------------------------------------------------------------

def robot_config(robot, extra=""):
    return "devices:\n  - name: robot\n    url: %s\n%s" % (robot.url, extra)


def case_rest(exe, work):
    robot = Robot(work)
    gw = Gateway(exe, work, robot_config(robot))
    try:
        for how in ("kill", "cut"):
            robot.mode("jog")
            relay = Relay(gw.port)
            c = Client(work, "rest-jog", port=relay.port)
            started = c.wait_line("started")
            expect(started["status"] == 200, "REST jog_joint timeout 60 answered 200 (%s)" % started["body"])
            robot.wait_moving(started["started"] - 1, "REST jog")
            event = take_away(c, relay, how)
            stopped_within_bound(robot, event, "REST jog_joint 60 s, client %s" % how)
            c.kill()
            relay.close()
        robot.mode("jog")
        q = robot.position()
        status, body = rest(gw.base, "POST", "/api/devices/robot/functions/jog_freespace",
                            {"args": {"joint_position": [q[0] + 0.25, q[1], q[2]], "max_velocity": [0.05] * 3, "wait": False}})
        expect(status == 409 and "wait true" in body["error"]["message"],
               "REST jog_freespace with wait false refused (409, names wait true): %s %s" % (status, body))
        robot.mode("jog")
        q = robot.position()
        c = Client(work, "rest-freespace", port=gw.port, target=[q[0] + 0.25, q[1], q[2]])
        sending = c.wait_line("sending")
        robot.wait_moving(sending["sending"], "REST jog_freespace wait true")
        event = take_away(c, None, "kill")
        stopped_within_bound(robot, event, "REST jog_freespace (wait true, a 17 s move), client killed")
        expect(robot.position()[0] < q[0] + 0.24, "the move did not reach its target (%.3f of %.3f)" % (robot.position()[0], q[0] + 0.25))
    finally:
        gw.stop()
        robot.stop()


def ws_case(robot, gw, work, kind, how, what, target=None):
    robot.mode("jog")
    relay = Relay(gw.port)
    c = Client(work, kind, port=relay.port, target=target)
    started = c.wait_line("started")
    expect("result" in started["reply"], "%s answered: %s" % (what, started["reply"]))
    robot.wait_moving(started["started"] - 1, what)
    event = take_away(c, relay, how)
    stopped_within_bound(robot, event, "%s, client %s" % (what, how))
    c.kill()
    relay.close()


def case_ws(exe, work):
    robot = Robot(work)
    gw = Gateway(exe, work, robot_config(robot))
    try:
        for how in ("kill", "cut"):
            ws_case(robot, gw, work, "ws-jog", how, "JSON WebSocket jog_joint 60 s")
        for how in ("kill", "cut"):
            q = robot.position()
            ws_case(robot, gw, work, "ws-freespace", how, "JSON WebSocket jog_freespace (wait false, a 17 s move)",
                    target=[q[0] - 0.25, q[1], q[2]])
        # two sockets: the second one's jog is refused naming the first while it holds
        robot.mode("jog")
        q = robot.position()
        first = Client(work, "ws-freespace", port=gw.port, target=[q[0] + 0.25, q[1], q[2]])
        started = first.wait_line("started")
        expect("result" in started["reply"], "the first socket's move started")
        robot.wait_moving(started["started"] - 1, "the first socket's move")
        second = Client(work, "ws-jog-short", port=gw.port)
        reply = second.wait_line("started")["reply"]
        msg = reply.get("error", {}).get("message", "")
        expect(reply.get("error", {}).get("name") == "RobotRaconteur.ObjectLockedError" and
               "motion of robot is held by JSON WebSocket from 127.0.0.1" in msg,
               "the second socket's jog refused, naming the holder: %s" % reply)
        second.kill()
        robot.wait_moving(time.time(), "the first socket's move, after the refusal")
        event = take_away(first, None, "kill")
        stopped_within_bound(robot, event, "the holder's socket closed")
    finally:
        gw.stop()
        robot.stop()


def rr_case(robot, work, url, kind, how, relay, what, target=None, start=None, mode="jog"):
    robot.mode(mode)
    c = Client(work, kind, url=url, target=target, start=start)
    started = c.wait_line("started")
    robot.wait_moving(started["started"] - 2, what)
    event = take_away(c, relay, how)
    stopped_within_bound(robot, event, "%s, client %s" % (what, how))
    c.kill()
    return started


def case_rr(exe, work):
    robot = Robot(work)
    gw = Gateway(exe, work, robot_config(robot))
    url = lambda port: "rr+tcp://127.0.0.1:%d/?service=robot" % port  # noqa: E731
    try:
        for how in ("kill", "cut"):
            relay = Relay(gw.port)
            rr_case(robot, work, url(relay.port), "rr-jog", how, relay, "official client jog_joint 60 s")
            relay.close()
        for how in ("kill", "cut"):
            relay = Relay(gw.port)
            q = robot.position()
            rr_case(robot, work, url(relay.port), "rr-freespace", how, relay,
                    "official client jog_freespace (wait false, a 17 s move)", target=[q[0] + 0.25, q[1], q[2]])
            relay.close()
        q = robot.position()
        rr_case(robot, work, url(gw.port), "rr-trajectory", "kill", None, "official client execute_trajectory (20 s)",
                target=[q[0] - 0.5, q[1], q[2]], start=q, mode="trajectory")
        # two clients: the second one's jog refused naming the first while it holds, allowed after its end
        robot.mode("jog")
        q = robot.position()
        first = Client(work, "rr-freespace", url=url(gw.port), target=[q[0] + 0.25, q[1], q[2]])
        first.wait_line("started")
        second = Client(work, "rr-jog", url=url(gw.port))
        refused = second.wait_line("refused")
        expect(refused["name"] == "ObjectLockedException" and "is held by RR session from 127.0.0.1" in refused["error"],
               "the second client's jog refused, naming the holder: %s" % refused)
        second.kill()
        event = take_away(first, None, "kill")
        stopped_within_bound(robot, event, "the holder's session closed")
        robot.mode("jog")
        third = Client(work, "rr-jog", url=url(gw.port))
        third.wait_line("started")
        third.kill()
        robot.wait_stopped(time.time(), "after the third client")
    finally:
        gw.stop()
        robot.stop()


def case_stream(exe, work):
    robot = Robot(work, ["--velocity-command"])
    gw = Gateway(exe, work, robot_config(robot))
    url = lambda port: "rr+tcp://127.0.0.1:%d/?service=robot" % port  # noqa: E731
    try:
        for how in ("cut", "kill"):
            relay = Relay(gw.port)
            robot.mode("velocity_command")
            c = Client(work, "rr-stream", url=url(relay.port))
            started = c.wait_line("started")
            robot.wait_moving(started["started"], "velocity_command stream")
            if how == "cut":
                # another sender meanwhile: its connect refused, naming the streamer
                other = Client(work, "rr-stream", url=url(gw.port))
                refused = other.wait_line("refused")
                expect("is held by RR session from 127.0.0.1" in refused["error"],
                       "a second sender's velocity_command connect refused, naming the first: %s" % refused)
                other.kill()
            event = take_away(c, relay, how)
            stopped_within_bound(robot, event, "velocity_command stream gone silent (%s)" % how)
            c.kill()
            relay.close()
    finally:
        gw.stop()
        robot.stop()


def case_locks(exe, work):
    import hashlib
    users = os.path.join(work, "users.txt")
    with open(users, "w") as f:
        for u in ("alice", "bob"):
            f.write("%s %s operator%s\n" % (u, hashlib.md5((u + "-pw").encode()).hexdigest(), ",objectlock" if u == "alice" else ""))
    robot = Robot(work)
    auth = ("gateway:\n  auth:\n    users: %s\n    roles:\n      operator:\n        - allow: [read, write, call, lock]\n" % users)
    gw = Gateway(exe, work, auth + robot_config(robot))
    try:
        url = "rr+tcp://127.0.0.1:%d/?service=robot" % gw.port
        alice = RRN.ConnectService(url, "alice", {"password": RR.VarValue("alice-pw", "string")})
        bob = RRN.ConnectService(url, "bob", {"password": RR.VarValue("bob-pw", "string")})
        robot.mode("jog")
        RRN.RequestObjectLock(alice, RR.RobotRaconteurObjectLockFlags_USER_LOCK)
        try:
            bob.jog_joint(np.array([0.1, 0, 0]), 0.15, False)
            expect(False, "bob's jog refused under alice's lock")
        except RR.ObjectLockedException as e:
            expect("alice" in str(e), "bob's jog refused under alice's lock: %s" % e)
        t0 = time.time()
        alice.jog_joint(np.array([0.1, 0, 0]), 60.0, False)  # clamped, but alice renews: a long move
        stop_renewing = threading.Event()

        def renew():
            while not stop_renewing.is_set():
                try:
                    alice.jog_joint(np.array([0.1, 0, 0]), 0.3, False)
                except RR.RobotRaconteurException:
                    return
                time.sleep(0.1)

        threading.Thread(target=renew, daemon=True).start()
        robot.wait_moving(t0, "alice's jog under her lock")
        event = time.time()
        bob.halt()  # the sim's halt(): through alice's lock
        stopped_within_bound(robot, event, "bob's halt() under alice's object lock")
        stop_renewing.set()
        # REST command_mode = halt through the same lock, bob logged in with a cookie
        robot.mode("jog")
        stop_renewing.clear()
        threading.Thread(target=renew, daemon=True).start()
        robot.wait_moving(time.time() - 0.5, "alice's jog again")
        opener = urllib.request.build_opener(urllib.request.HTTPCookieProcessor())
        req = urllib.request.Request(gw.base + "/api/login", data=json.dumps({"username": "bob", "password": "bob-pw"}).encode(),
                                     headers={"Content-Type": "application/json"}, method="POST")
        with opener.open(req, timeout=30) as r:
            expect(r.status == 200, "bob logs in over REST")
        event = time.time()
        req = urllib.request.Request(gw.base + "/api/devices/robot/properties/command_mode", data=json.dumps({"value": 0}).encode(),
                                     headers={"Content-Type": "application/json"}, method="PUT")
        with opener.open(req, timeout=30) as r:
            expect(r.status == 200, "bob's REST command_mode = halt answered 200 under alice's lock")
        stopped_within_bound(robot, event, "bob's REST command_mode = halt under alice's object lock")
        stop_renewing.set()
        # a non-stop request of bob is still refused by the lock
        req = urllib.request.Request(gw.base + "/api/devices/robot/properties/command_mode", data=json.dumps({"value": 1}).encode(),
                                     headers={"Content-Type": "application/json"}, method="PUT")
        try:
            opener.open(req, timeout=30)
            expect(False, "bob's command_mode = jog refused under alice's lock")
        except urllib.error.HTTPError as e:
            expect(e.code == 409, "bob's command_mode = jog refused under alice's lock (409)")
        RRN.ReleaseObjectLock(alice)
        RRN.DisconnectService(alice)
        RRN.DisconnectService(bob)
    finally:
        gw.stop()
        robot.stop()
    device_users = os.path.join(work, "device-users.txt")
    with open(device_users, "w") as f:
        for u, privileges in (("alice", "objectlock"), ("bob", "_"), ("gw", "_"), ("test", "_")):
            f.write("%s %s %s\n" % (u, hashlib.md5((u + "-pw").encode()).hexdigest(), privileges))
    robot = Robot(work, ["--users", device_users], login=("test", "test-pw"))
    # passthrough: the device holds the locks (its own users); alice's object lock on the device, taken
    # through the gateway, does not keep bob's halt() from the robot
    gw = Gateway(exe, work, robot_config(robot, "    auth: passthrough\n    username: gw\n    password: gw-pw\n"),
                 name="gateway-passthrough")
    try:
        url = "rr+tcp://127.0.0.1:%d/?service=robot" % gw.port
        a = RRN.ConnectService(url, "alice", {"password": RR.VarValue("alice-pw", "string")})
        b = RRN.ConnectService(url, "bob", {"password": RR.VarValue("bob-pw", "string")})
        robot.mode("jog")
        RRN.RequestObjectLock(a, RR.RobotRaconteurObjectLockFlags_USER_LOCK)
        t0 = time.time()
        a.jog_freespace(np.array([robot.position()[0] + 0.25, 0, 0]), np.array([0.015] * 3), False)
        robot.wait_moving(t0, "alice's move under her lock on the device")
        try:
            b.jog_joint(np.array([0.1, 0, 0]), 0.15, False)
            expect(False, "bob's jog refused")
        except RR.RobotRaconteurException as e:
            expect("held by" in str(e) or "locked" in str(e), "bob's jog refused (%s)" % e)
        event = time.time()
        b.halt()
        stopped_within_bound(robot, event, "bob's halt() under alice's object lock on the device (passthrough)")
        RRN.ReleaseObjectLock(a)
        RRN.DisconnectService(a)
        RRN.DisconnectService(b)
    finally:
        gw.stop()
        robot.stop()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--gateway")
    ap.add_argument("--case", choices=["rest", "ws", "rr", "stream", "locks"])
    ap.add_argument("--client")
    ap.add_argument("--port", type=int)
    ap.add_argument("--url")
    ap.add_argument("--user")
    ap.add_argument("--target", type=lambda t: [float(x) for x in t.split(",")])
    ap.add_argument("--start", type=lambda t: [float(x) for x in t.split(",")])
    args = ap.parse_args()
    if args.client:
        return client_main(args)
    work = tempfile.mkdtemp(prefix="rr-motion-")
    try:
        with RR.ClientNodeSetup(argv=["motion_safety_test"] + RR_FLAGS):
            RRC.RegisterStdRobDefServiceTypes(RRN)
            {"rest": case_rest, "ws": case_ws, "rr": case_rr, "stream": case_stream, "locks": case_locks}[args.case](
                args.gateway, work)
    except (CheckFailed, Exception) as e:
        traceback.print_exc()
        for name in sorted(os.listdir(work)):
            if name.endswith(".log"):
                text = open(os.path.join(work, name), errors="replace").read()
                print("--- %s (last 3000 characters)\n%s" % (name, text[-3000:]))
        print("FAILED: %s" % e)
        return 1
    print("PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
