#!/usr/bin/env python3
"""Runs a client against a device THROUGH the gateway.

Starts a device (a command printing one JSON line with its URL), starts rr-gateway with that device
configured under a name, waits until /readyz says ready, then runs the client command with the
gateway URL of the device (rr+tcp or rr+ws). Kills everything by PID at the end.

Usage:
  through_gateway.py --gateway PATH --device-cmd "CMD ..." --name NAME[=KEY] ... [--ws] -- CLIENT ... {url} ...
Each --name configures one device on the gateway: NAME is its service name there and KEY the key of
its URL in the device's JSON line (default "url"; e.g. create=create_url for rr-demo-devices, which
serves two devices on one node). The literal {url} in the client arguments is replaced by the gateway
URL of the first device, {url:NAME} by that of device NAME, and {dev:KEY} by the value of KEY in the
device's JSON line (e.g. {dev:http_url} for reynard_harness.py).
Exit status: the client's (0 = all checks passed); 2 = setup failed.
"""
import argparse
import json
import os
import shlex
import subprocess
import sys
import time
import urllib.request

from child_procs import stop


def read_json_line(proc, key, timeout):
    deadline = time.time() + timeout
    while time.time() < deadline:
        if proc.poll() is not None:
            raise RuntimeError("process exited early with %s" % proc.returncode)
        line = proc.stdout.readline()
        if not line:
            time.sleep(0.05)
            continue
        try:
            obj = json.loads(line)
        except ValueError:
            continue
        if key in obj:
            return obj
    raise RuntimeError("no JSON line with %r within %ss" % (key, timeout))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--device-cmd", required=True)
    ap.add_argument("--name", required=True, action="append", help="NAME[=KEY] (repeatable)")
    ap.add_argument("--ws", action="store_true", help="connect the client with rr+ws")
    ap.add_argument("--timeout", type=float, default=150)
    ap.add_argument("client", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    client = a.client[1:] if a.client and a.client[0] == "--" else a.client
    names = [n.partition("=")[0] for n in a.name]
    keys = [n.partition("=")[2] or "url" for n in a.name]
    device = gateway = None
    try:
        device = subprocess.Popen(shlex.split(a.device_cmd), stdout=subprocess.PIPE, text=True)
        dev_info = read_json_line(device, keys[0], 60)
        flags = []
        for name, key in zip(names, keys):
            flags += ["--device", "%s=%s" % (name, dev_info[key])]
        gateway = subprocess.Popen([a.gateway, "--no-demo", "--listen", "127.0.0.1", "--port", "0", "--log-level",
                                    "warning"] + flags, stdout=subprocess.PIPE, text=True)
        port = read_json_line(gateway, "port", 30)["port"]
        deadline = time.time() + 20
        while True:
            try:
                with urllib.request.urlopen("http://127.0.0.1:%d/readyz" % port, timeout=2) as r:
                    if r.status == 200:
                        break
            except Exception:
                pass
            if time.time() > deadline:
                raise RuntimeError("gateway not ready")
            time.sleep(0.1)
        scheme = "rr+ws" if a.ws else "rr+tcp"
        urls = {n: "%s://127.0.0.1:%d/?service=%s" % (scheme, port, n) for n in names}
        cmd = []
        for c in client:
            c = c.replace("{url}", urls[names[0]])
            for n, u in urls.items():
                c = c.replace("{url:%s}" % n, u)
            for k, v in dev_info.items():
                c = c.replace("{dev:%s}" % k, str(v))
            cmd.append(c)
        rc = subprocess.run(cmd, timeout=a.timeout).returncode
        if gateway.poll() is not None:
            print("gateway exited during the test with %s" % gateway.returncode, file=sys.stderr)
            return 1
        return rc
    except Exception as e:
        print("through_gateway: %s" % e, file=sys.stderr)
        return 2
    finally:
        stop(gateway)
        stop(device)


if __name__ == "__main__":
    sys.exit(main())
