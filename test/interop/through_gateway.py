#!/usr/bin/env python3
"""Runs a client against a device THROUGH the gateway.

Starts a device (a command printing one JSON line with its URL), starts rr-gateway with that device
configured under a name, waits until /readyz says ready, then runs the client command with the
gateway URL of the device (rr+tcp or rr+ws). Kills everything by PID at the end.

Usage:
  through_gateway.py --gateway PATH --device-cmd "CMD ..." --name NAME[=KEY] ... [--scheme S] -- CLIENT ... {url} ...
--scheme is how the client reaches the gateway: tcp (default), ws (also --ws), local (rr+local by the
gateway's NodeName) or local-id (rr+local by its NodeID). With local and local-id the gateway serves
rr+local under a NodeName unique to this run; otherwise it runs with --no-local. The literal {unique}
in --device-cmd is replaced by a token unique to this run (for a device's own NodeName).
Each --name configures one device on the gateway: NAME is its service name there and KEY the key of
its URL in the device's JSON line (default "url"; e.g. create=create_url for rr-demo-devices, which
serves two devices on one node). The literal {url} in the client arguments is replaced by the gateway
URL of the first device, {url:NAME} by that of device NAME, and {dev:KEY} by the value of KEY in the
device's JSON line (e.g. {dev:http_url} for reynard_harness.py).
Exit status: the client's (0 = all checks passed); 2 = setup failed.
"""
import argparse
import atexit
import json
import os
import shlex
import subprocess
import sys
import time
import urllib.request

from child_procs import stop

# A bound on a hang of a start (the device's and the gateway's ready lines, /readyz), never an expected
# time: ASan processes beside a loaded CI run (load 30-50) took over 30 s to print their ready line.
START_S = 180


def forget_node_names(names, nodeids):
    """Removes what nodes of these NodeNames / NodeIDs leave in this user's node directories (the
    NodeID cache and lock files, and the entries the official library leaves behind), as the official
    library computes the directories."""
    try:
        import glob
        import RobotRaconteur as RR
        d = RR.RobotRaconteurNode.s.GetNodeDirectories()
        run, config, state = d.user_run_dir.string(), d.user_config_dir.string(), d.user_state_dir.string()
    except Exception:
        return
    paths = []
    for n in names:
        paths += glob.glob(os.path.join(run, "transport", "local", "by-nodename", n + ".*"))
        paths += [os.path.join(run, "nodeids", n + ".pid"), os.path.join(config, "nodeids", n),
                  os.path.join(state, "nodeids", n)]
    for i in nodeids:
        paths += glob.glob(os.path.join(run, "transport", "local", "by-nodeid", i.strip("{}") + ".*"))
    for p in paths:
        try:
            os.unlink(p)
        except OSError:
            pass


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
    ap.add_argument("--ws", action="store_true", help="connect the client with rr+ws (= --scheme ws)")
    ap.add_argument("--scheme", choices=["tcp", "ws", "local", "local-id"], default="tcp")
    ap.add_argument("--timeout", type=float, default=150)
    ap.add_argument("--auth", choices=["shared", "passthrough"], default="shared",
                    help="the devices' auth mode (docs/security.md); passthrough: a config file sets it")
    ap.add_argument("client", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    client = a.client[1:] if a.client and a.client[0] == "--" else a.client
    names = [n.partition("=")[0] for n in a.name]
    keys = [n.partition("=")[2] or "url" for n in a.name]
    scheme = "ws" if a.ws else a.scheme
    unique = "t%d" % os.getpid()
    device = gateway = None
    ready, dev_info = {}, {}
    try:
        device = subprocess.Popen(shlex.split(a.device_cmd.replace("{unique}", unique)), stdout=subprocess.PIPE, text=True)
        dev_info = read_json_line(device, keys[0], START_S)
        flags = []
        if a.auth == "passthrough":
            import json
            import tempfile
            cfg = tempfile.NamedTemporaryFile("w", suffix=".yaml", prefix="rr-gw-", delete=False)
            cfg.write("devices:\n")
            for name, key in zip(names, keys):
                cfg.write("  - name: %s\n    url: %s\n    auth: passthrough\n" % (name, json.dumps(dev_info[key])))
            cfg.close()
            atexit.register(os.unlink, cfg.name)
            flags += ["--config", cfg.name]
        else:
            for name, key in zip(names, keys):
                flags += ["--device", "%s=%s" % (name, dev_info[key])]
        gateway_name = "rr.gateway.%s" % unique
        local = ["--robotraconteur-nodename", gateway_name] if scheme.startswith("local") else ["--no-local"]
        gateway = subprocess.Popen([a.gateway, "--no-demo", "--listen", "127.0.0.1", "--port", "0", "--log-level",
                                    "warning"] + local + flags, stdout=subprocess.PIPE, text=True)
        ready = read_json_line(gateway, "port", START_S)
        port = ready["port"]
        deadline = time.time() + START_S
        while True:
            try:
                with urllib.request.urlopen("http://127.0.0.1:%d/readyz" % port, timeout=30) as r:
                    if r.status == 200:
                        break
            except Exception:
                pass
            if time.time() > deadline:
                raise RuntimeError("gateway not ready")
            time.sleep(0.1)
        if scheme == "local":
            urls = {n: "rr+local:///?nodename=%s&service=%s" % (gateway_name, n) for n in names}
        elif scheme == "local-id":
            urls = {n: "rr+local:///?nodeid=%s&service=%s" % (ready["nodeid"], n) for n in names}
        else:
            urls = {n: "rr+%s://127.0.0.1:%d/?service=%s" % (scheme, port, n) for n in names}
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
        if scheme.startswith("local") or "{unique}" in a.device_cmd:
            ids = [x.get("nodeid", "") for x in (ready, dev_info)]
            forget_node_names(["rr.gateway.%s" % unique, "interop.%s" % unique], [i for i in ids if i])


if __name__ == "__main__":
    sys.exit(main())
