#!/usr/bin/env python3
"""rr-gateway with no options is found and called by an official client with default settings
(issue 40), between two network namespaces joined by a veth pair (the setup of discovery_netns.py):

  A: `rr-gateway` with no options at all. Only its environment differs from a user's: its node
     directories (ROBOTRACONTEUR_*_DIR) are in a scratch folder, so that its NodeName rr.gateway does
     not meet another gateway's on this computer (rr+local is on, as by default).
  B: the official library with default settings (discovery_official.py: ClientNodeSetup).

Checks:
  1. defaults: FindServiceByType("experimental.create.Create") lists the gateway's demo device `create`
     (NodeName rr.gateway), FindNodeByName finds rr.gateway and its demo node rr.gateway.demo, and the
     client calls `create` (a property read and a function call) through the URLs the search gave;
  2. `rr-gateway --no-discovery` (serving, as /livez shows): the official client finds neither node;
  3. a kernel without IPv6 (socket(AF_INET6) refused by a seccomp filter, as with ipv6.disable=1): the
     gateway with no options says it listens on 0.0.0.0 and serves the official client in B over IPv4;
  4. IPv6 turned off in A by sysctl (a container without IPv6): the gateway with no options serves the
     official client in B over IPv4.

Needs root (ip netns); without it, or without `ip`, it exits 77 (skipped) with the reason.

    discovery_defaults_netns.py --gateway PATH --python PATH
"""

import argparse
import ctypes
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import child_procs  # noqa: E402
from discovery_netns import (EVENT_S, EXIT_S, IPV4_A, START_S, Failed, Net, http,  # noqa: E402
                             netns_skip_reason, retry, run, wait_until)

SKIP = 77
NAME = "rr.gateway"  # the default NodeName
CREATE = "experimental.create.Create"


T0 = time.monotonic()


def log(*a):
    print("[discovery_defaults +%.0fs]" % (time.monotonic() - T0), *a, flush=True)


def node_dir_env(root):
    """The process environment with every RR node directory under `root`."""
    env = dict(os.environ)
    for var, sub in (("ROBOTRACONTEUR_SYSTEM_RUN_DIR", "run"), ("ROBOTRACONTEUR_USER_RUN_DIR", "run"),
                     ("ROBOTRACONTEUR_SYSTEM_STATE_DIR", "state"), ("ROBOTRACONTEUR_SYSTEM_CONFIG_DIR", "config"),
                     ("ROBOTRACONTEUR_USER_CONFIG_DIR", "config")):
        env[var] = os.path.join(root, sub)
        os.makedirs(env[var], exist_ok=True)
    return env


# seccomp: socket(AF_INET6, ...) fails with EAFNOSUPPORT, everything else is allowed (classic BPF over
# struct seccomp_data: nr at 0, arch at 4, args[0] at 16).
AUDIT_ARCH = {"x86_64": (0xC000003E, 41), "aarch64": (0xC00000B7, 198)}  # (AUDIT_ARCH_*, __NR_socket)


class SockFilter(ctypes.Structure):
    _fields_ = [("code", ctypes.c_uint16), ("jt", ctypes.c_uint8), ("jf", ctypes.c_uint8), ("k", ctypes.c_uint32)]


class SockFprog(ctypes.Structure):
    _fields_ = [("len", ctypes.c_ushort), ("filter", ctypes.POINTER(SockFilter))]


def no_ipv6_preexec():
    """A preexec_fn that dies with the parent and makes this process (and what it execs) see a kernel
    without IPv6; None when the architecture is not known here."""
    arch = AUDIT_ARCH.get(platform.machine())
    if not arch:
        return None
    ld, jeq, ret = 0x20, 0x15, 0x06  # BPF_LD|BPF_W|BPF_ABS, BPF_JMP|BPF_JEQ|BPF_K, BPF_RET|BPF_K
    allow, errno_afnosupport = 0x7FFF0000, 0x00050000 | 97
    code = [(ld, 0, 0, 4), (jeq, 0, 5, arch[0]), (ld, 0, 0, 0), (jeq, 0, 3, arch[1]), (ld, 0, 0, 16),
            (jeq, 0, 1, 10), (ret, 0, 0, errno_afnosupport), (ret, 0, 0, allow)]
    filters = (SockFilter * len(code))(*[SockFilter(*c) for c in code])
    prog = SockFprog(len(code), filters)
    libc = ctypes.CDLL("libc.so.6", use_errno=True)

    def preexec():
        child_procs.die_with_parent()
        if libc.prctl(38, 1, 0, 0, 0) != 0:  # PR_SET_NO_NEW_PRIVS
            os._exit(90)
        if libc.prctl(22, 2, ctypes.byref(prog), 0, 0) != 0:  # PR_SET_SECCOMP, SECCOMP_MODE_FILTER
            os._exit(91)

    preexec.keep = (filters, prog)
    return preexec


def start(cmd, stderr_path, env, preexec=child_procs.die_with_parent):
    with open(stderr_path, "wb") as errf:
        return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=errf, stdin=subprocess.DEVNULL, env=env,
                                preexec_fn=preexec)


def find(net, python, official_py, call):
    argv = [python, official_py, "find", "--type", CREATE, "--name", NAME, "--also-name", NAME + ".demo", "--wait", "5"]
    r = run(net.cmd(net.b, argv + (["--call"] if call else [])))
    return json.loads(r.stdout.strip().splitlines()[-1])


def call_url(net, python, official_py, url):
    r = run(net.cmd(net.b, [python, official_py, "call", "--url", url]))
    return json.loads(r.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--python", required=True)
    args = ap.parse_args()
    reason = netns_skip_reason(args.python)
    if reason:
        print("SKIP: " + reason)
        return SKIP
    tmp = tempfile.mkdtemp(prefix="rr_discovery_defaults_")
    net = Net()
    procs = []
    logs = []
    official_py = os.path.join(HERE, "discovery_official.py")
    # The official client gets node directories of its own too: it must find the gateway over the
    # network, not through rr+local entries on the shared file system.
    client_env = node_dir_env(os.path.join(tmp, "client"))
    os.environ.update({k: v for k, v in client_env.items() if k.startswith("ROBOTRACONTEUR_")})

    def gateway(tag, extra=(), preexec=child_procs.die_with_parent):
        err = os.path.join(tmp, "gateway-%s.err" % tag)
        logs.append(err)
        gw = start(net.cmd(net.a, [args.gateway] + list(extra)), err, node_dir_env(os.path.join(tmp, "gw-" + tag)), preexec)
        procs.append(gw)
        ready = child_procs.read_json_line(gw, START_S, "rr-gateway " + " ".join(extra))
        if ready.get("port") != 8080 or ready.get("nodename") != NAME:
            raise Failed("ready line %r: expected port 8080 and NodeName %s (the defaults)" % (ready, NAME))
        wait_until("the demo devices connected (/readyz)",
                   lambda: http(net, args.python, "http://127.0.0.1:8080/readyz")["status"] == 200, EVENT_S)
        return gw, err

    def stop(gw):
        status = child_procs.stop(gw, EXIT_S)
        if status != 0:
            raise Failed("rr-gateway exited with %s" % status)

    try:
        try:
            net.setup()
        except PermissionError as e:
            print("SKIP: " + str(e))
            return SKIP

        # --- 1. no options: found by type and by NodeName, and called --------------------------------
        gw, _ = gateway("defaults")

        def found_and_called():
            # Asked again until answered: announces come by datagram, and the services by a connect to
            # the gateway's service index, either of which a loaded machine may not finish in one search.
            res = find(net, args.python, official_py, call=True)
            creates = [s for s in res["services"] if s["nodename"] == NAME and s["name"] == "create"]
            if not creates or not any(u.startswith("rr+tcp://[fe80:") for u in creates[0]["urls"]):
                raise Failed("FindServiceByType(%s) did not list the gateway's create at a link-local URL: %s" % (CREATE, res))
            if not any(n["nodename"] == NAME and n["urls"] for n in res["nodes"]):
                raise Failed("FindNodeByName(%s) did not find the gateway: %s" % (NAME, res))
            if not any(n["nodename"] == NAME + ".demo" and n["urls"] for n in res["nodes2"]):
                raise Failed("FindNodeByName(%s.demo) did not find the demo node: %s" % (NAME, res))
            call = res.get("call", {})
            if "error" in call or not isinstance(call.get("DistanceTraveled"), int):
                raise Failed("the official client's call to the create it found: %s" % call)
            return call
        call = retry("the official client finds the gateway (type, NodeName, demo node) and calls it", found_and_called)
        log("defaults: found by type and NodeName (and the demo node), called at %s: ok" % call["urls"])
        stop(gw)

        # --- 2. --no-discovery: serving, but found by neither ------------------------------------------
        gw, _ = gateway("quiet", ["--no-discovery"])
        res = find(net, args.python, official_py, call=False)
        if any(s["nodename"] == NAME for s in res["services"]) or res["nodes"] or res["nodes2"]:
            raise Failed("--no-discovery: the official client still found the gateway: %s" % res)
        features = json.loads(http(net, args.python, "http://127.0.0.1:8080/api/features")["body"])
        if features != {"discovery": False, "auth": False}:
            raise Failed("--no-discovery: /api/features %r" % features)
        log("--no-discovery: not found: ok")
        stop(gw)

        # --- 3. a kernel without IPv6: 0.0.0.0, and IPv4 clients served ------------------------------
        preexec = no_ipv6_preexec()
        if preexec is None:
            log("note: no seccomp filter for %s here: the AF_INET6 fallback is not checked" % platform.machine())
        else:
            gw, err = gateway("no-ipv6", (), preexec)
            with open(err, errors="replace") as f:
                text = f.read()
            if "listening on 0.0.0.0 (IPv4 only)" not in text:
                raise Failed("without AF_INET6 the gateway did not say it fell back to 0.0.0.0:\n" + text[-3000:])
            r = call_url(net, args.python, official_py, "rr+tcp://%s:8080/?service=create" % IPV4_A)
            if "error" in r:
                raise Failed("without AF_INET6: the official client over IPv4: %s" % r)
            log("no IPv6 in the kernel: 0.0.0.0, served over IPv4: ok")
            stop(gw)

        # --- 4. IPv6 turned off in A (as in many containers): IPv4 clients served ----------------------
        for key in ("all", "default", "lo", net.va):
            run(net.cmd(net.a, ["sysctl", "-qw", "net.ipv6.conf.%s.disable_ipv6=1" % key]))
        gw, err = gateway("ipv6-off")
        r = call_url(net, args.python, official_py, "rr+tcp://%s:8080/?service=create" % IPV4_A)
        if "error" in r:
            raise Failed("IPv6 off by sysctl: the official client over IPv4: %s" % r)
        with open(err, errors="replace") as f:
            fell_back = "listening on 0.0.0.0" in f.read()
        log("IPv6 off by sysctl: served over IPv4 (%s): ok" % ("fell back to 0.0.0.0" if fell_back else "on ::"))
        stop(gw)
        log("PASS")
        return 0
    except (Failed, child_procs.StepFailed, subprocess.TimeoutExpired) as e:
        log("FAIL:", e)
        for p in logs:
            if os.path.exists(p):
                with open(p, errors="replace") as f:
                    text = f.read()
                log("--- %s (head and tail) ---\n%s\n...\n%s" % (os.path.basename(p), text[:3000], text[-3000:]))
        return 1
    finally:
        for p in procs:
            child_procs.stop(p, 5)
        net.teardown()
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
