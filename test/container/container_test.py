#!/usr/bin/env python3
"""The container image (docker/Containerfile, docker/build.sh) built and run with podman (issue 13).

Builds the image with docker/build.sh unless an image labelled with the same inputs key
(`docker/build.sh --print-key`: the committed sources it is built from, the base, web/dist) exists
already, so a CI run after a change to docs or tests reuses it. Then runs it like a user would:
  - a configuration file mounted at /etc/rr-gateway/gateway.yaml (node name, log level) and
    RR_GATEWAY_LOG_FORMAT=json in the environment;
  - the container's port 8080 published on a free loopback port, no host network;
and checks: /livez and /readyz through the published port, both demo devices connected, the official
Python client (robotraconteur) reads `create`'s properties over rr+tcp and `webcam`'s over rr+ws
through that port, the mounted file and the variable took effect (node name in the ready line, JSON
log lines with device / client / request), the process runs as uid 10001, the image's HEALTHCHECK
probes /livez and passes. Prints the image size.

Exit 77 (skipped, with the reason) where podman is missing or cannot run containers here.
Usage: container_test.py [--image localhost/rr-gateway:ci] [--prebuilt]
"""
import argparse
import json
import os
import socket
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "test", "gateway"))
import gwproc  # noqa: E402
import official_transport  # noqa: E402  (the official client's transport, its connect timeout)
from gwproc import expect  # noqa: E402

# runc with low ulimits: crun cannot set podman's default ones in these VMs (../shared/TOOLCHAIN.md §5).
RUN_OPTS = ["--runtime", "runc", "--ulimit", "nofile=1024:1024", "--ulimit", "nproc=1024:1024"]


def skip(why):
    print("SKIP: " + why)
    sys.exit(77)


def podman(*args, check=True, timeout=120):
    p = subprocess.run(["podman"] + list(args), capture_output=True, text=True, timeout=timeout)
    if check and p.returncode != 0:
        raise AssertionError("podman %s: exit %d: %s" % (" ".join(args), p.returncode, p.stderr.strip()[-2000:]))
    return p


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def ensure_image(image, prebuilt):
    if prebuilt:
        # scripts/test.sh made it from its Release build (docker/build.sh --from-build): test that one.
        found = podman("images", "--format", "{{.ID}}", image).stdout.split()
        expect(bool(found), "--prebuilt: no image %s" % image)
        label = podman("image", "inspect", "--format", "{{index .Labels \"rr.inputs\"}}", image).stdout.strip()
        print("image: %s as given (rr.inputs=%s)" % (image, label[:21]))
        return
    key = subprocess.run([os.path.join(ROOT, "docker", "build.sh"), "--print-key"], cwd=ROOT, capture_output=True,
                         text=True, check=True).stdout.strip()
    found = podman("images", "--filter", "label=rr.inputs=" + key, "--format", "{{.ID}}").stdout.split()
    if found:
        podman("tag", found[0], image)
        print("image: reusing %s (rr.inputs=%s)" % (found[0], key[:12]))
        return
    print("image: building (rr.inputs=%s; takes minutes on a cold cache)" % key[:12], flush=True)
    t0 = time.monotonic()
    p = subprocess.run([os.path.join(ROOT, "docker", "build.sh"), "--tag", image], cwd=ROOT)
    expect(p.returncode == 0, "docker/build.sh exited %d" % p.returncode)
    print("image: built in %.0f s" % (time.monotonic() - t0))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--image", default="localhost/rr-gateway:ci")
    ap.add_argument("--prebuilt", action="store_true",
                    help="test --image as it is (built by docker/build.sh --from-build), never build it here "
                         "(also RR_CONTAINER_PREBUILT=1: scripts/test.sh)")
    a = ap.parse_args()

    if subprocess.run(["sh", "-c", "command -v podman"], capture_output=True).returncode != 0:
        skip("podman is not installed (docker/build.sh installs it with apt: podman buildah runc mmdebstrap)")
    info = subprocess.run(["podman", "info"], capture_output=True, text=True)
    if info.returncode != 0:
        skip("podman cannot run here: " + info.stderr.strip()[-300:])
    checks = gwproc.Checks()
    try:
        ensure_image(a.image, a.prebuilt or os.environ.get("RR_CONTAINER_PREBUILT") == "1")
    except Exception as e:
        # The build's RUN steps need a working runtime: tell "cannot run containers here" from a broken build.
        base = "localhost/debian:bookworm-local"
        if podman("image", "exists", base, check=False).returncode == 0:
            probe = podman("run", *RUN_OPTS, "--rm", base, "true", check=False)
            if probe.returncode != 0:
                skip("podman cannot start containers here: " + probe.stderr.strip()[-300:])
        print("FAIL the image is built: %s" % e, file=sys.stderr)
        return 1
    probe = podman("run", *RUN_OPTS, "--rm", "--entrypoint", "/bin/id", a.image, check=False)
    if probe.returncode != 0:
        skip("podman cannot start containers here: " + probe.stderr.strip()[-300:])

    size = int(podman("image", "inspect", "--format", "{{.Size}}", a.image).stdout.strip())
    print("image size: %d bytes (%.1f MB)" % (size, size / 1e6))
    cfg = json.loads(podman("image", "inspect", a.image).stdout)[0]
    config = cfg.get("Config", {})

    def image_metadata():
        expect(config.get("User") == "10001:10001", "image user %r" % config.get("User"))
        # podman puts it at the top level of `image inspect`, Docker under Config.
        hc = cfg.get("Healthcheck") or config.get("Healthcheck") or {}
        expect("/livez" in " ".join(hc.get("Test", [])), "HEALTHCHECK %r" % hc)
        expect(size < 150 * 1000 * 1000, "image is %d bytes; expected a small runtime image" % size)

    checks.run("image: non-root user, HEALTHCHECK on /livez, small", image_metadata)

    port = free_port()
    name = "rr-gateway-ci-%d" % os.getpid()
    tmp = tempfile.mkdtemp(prefix="rr-container-")
    conf = os.path.join(tmp, "gateway.yaml")
    with open(conf, "w") as f:
        f.write("gateway:\n  node_name: rr.gateway.container\n  log_level: debug\ndemo:\n  enabled: true\n")
    os.chmod(tmp, 0o755)
    os.chmod(conf, 0o644)
    podman("run", *RUN_OPTS, "-d", "--name", name, "-p", "127.0.0.1:%d:8080" % port,
           "-v", "%s:/etc/rr-gateway/gateway.yaml:ro" % conf, "-e", "RR_GATEWAY_LOG_FORMAT=json", a.image)
    import RobotRaconteur as RR
    RRN = RR.RobotRaconteurNode.s
    try:
        def ready():
            try:
                gwproc.wait_ready(port, timeout=60)
            except Exception:
                raise AssertionError("no /readyz 200 through the published port; logs: %s" %
                                     podman("logs", name, check=False).stderr[-2000:])
            status, body = gwproc.http_status("http://127.0.0.1:%d/livez" % port)
            expect(status == 200, "/livez %d" % status)
            status, body = gwproc.http_status("http://127.0.0.1:%d/api/devices" % port)
            expect(status == 200, "/api/devices %d" % status)
            devs = {d["name"]: d for d in json.loads(body)}
            for dev in ("create", "webcam"):
                expect(dev in devs and devs[dev].get("state") == "connected", "%s in /api/devices: %r" % (dev, devs.get(dev)))

        checks.run("/livez, /readyz and both demo devices through the published port", ready)

        def official_client():
            RRN.RegisterTransport(official_transport.client_tcp_transport(RR))
            c = RRN.ConnectService("rr+tcp://127.0.0.1:%d/?service=create" % port)
            d = c.DistanceTraveled
            expect(isinstance(d, (int, float)), "create.DistanceTraveled = %r" % (d,))
            RRN.DisconnectService(c)
            w = RRN.ConnectService("rr+ws://127.0.0.1:%d/?service=webcam" % port)
            names = w.WebcamNames
            expect(isinstance(names, dict) and names, "webcam.WebcamNames = %r" % (names,))
            RRN.DisconnectService(w)

        checks.run("the official Python client reads create (rr+tcp) and webcam (rr+ws) through the port",
                   official_client)

        def config_and_logs():
            logs = podman("logs", name)
            expect('"nodename": "rr.gateway.container"' in logs.stdout,
                   "the mounted gateway.yaml's node_name is not in the ready line: %r" % logs.stdout[-500:])
            lines = [l for l in logs.stderr.splitlines() if l.strip()]
            expect(lines, "no log lines")
            objs = []
            for l in lines:
                try:
                    objs.append(json.loads(l))
                except ValueError:
                    raise AssertionError("RR_GATEWAY_LOG_FORMAT=json, yet a log line is not JSON: %r" % l)
            for o in objs:
                expect(set(o) == {"time", "level", "message", "device", "client", "request"}, "log keys %r" % sorted(o))
            expect(any(o["device"] == "create" for o in objs), "no log line names device create")
            expect(any(o["request"] == "GET /readyz" and o["client"] for o in objs),
                   "no access line (log_level debug from the mounted file) for GET /readyz")

        checks.run("the mounted config file and RR_GATEWAY_LOG_FORMAT=json took effect", config_and_logs)

        def user_and_health():
            uid = podman("exec", name, "id", "-u").stdout.strip()
            expect(uid == "10001", "runs as uid %r" % uid)
            hc = podman("healthcheck", "run", name, check=False)
            expect(hc.returncode == 0, "podman healthcheck run: exit %d %s%s" % (hc.returncode, hc.stdout, hc.stderr))

        checks.run("runs as uid 10001; the HEALTHCHECK passes", user_and_health)
    finally:
        try:
            RRN.Shutdown()
        finally:
            podman("rm", "-f", "-t", "2", name, check=False)
            for f in os.listdir(tmp):
                os.unlink(os.path.join(tmp, f))
            os.rmdir(tmp)
    return checks.exit_code()


if __name__ == "__main__":
    sys.exit(main())
