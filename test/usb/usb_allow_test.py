#!/usr/bin/env python3
"""A board without the RR BOS capability behind the gateway (docs/usb.md "Detection"): rr_usb_fixture
with RR_USB_FIXTURE_NO_BOS=1 plugs the emulated board as product 1209:0003 without the capability. With
`usb.allow: [{vid: 0x1209, pid: 0x0003}]` in the gateway's configuration the configured rr+usb device
connects and answers the JSON API; without the entry the gateway does not take the board for an RR
device, and the device stays unconnected with a reason. Exit 0 when all passed, 1 on a failure, 77
(skipped) when umockdev or the venv is missing.

Usage: usb_allow_test.py --fixture PATH/rr_usb_fixture --wrapper test/usb/run_under_umockdev.sh
"""
import argparse
import atexit
import os
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "interop"))
import child_procs  # noqa: E402

fail, get_json = child_procs.fail, child_procs.get_json

CONFIG = """\
gateway: {{listen: 127.0.0.1, port: 0, local: false, node_name: usb.allow.test}}
demo: {{enabled: false}}
discovery: {{announce: false}}
usb:
  enabled: true
{allow}devices:
  - name: create
    url: "rr+usb:///?nodename=usb_demo&service=create"
"""


def run(args, tmp, allow):
    cfg = os.path.join(tmp, "gateway-%s.yaml" % ("allow" if allow else "plain"))
    with open(cfg, "w") as f:
        f.write(CONFIG.format(allow="  allow:\n    - {vid: 0x1209, pid: 0x0003}\n" if allow else ""))
    err_path = cfg + ".stderr"
    env = dict(os.environ, RR_USB_FIXTURE_NO_BOS="1")
    with open(err_path, "wb") as errf:
        proc = subprocess.Popen([args.wrapper, args.fixture, "gateway", cfg], stdout=subprocess.PIPE, stderr=errf,
                                stdin=subprocess.PIPE, env=env, preexec_fn=child_procs.die_with_parent)
    try:
        try:
            port = child_procs.read_json_line(proc, 60, "rr_usb_fixture")["port"]
        except child_procs.StepFailed as e:
            if proc.poll() == 77:
                return 77
            fail("%s\n%s" % (e, child_procs.tail(err_path)))

        def device():
            return next(d for d in get_json(port, "/api/devices") if d["name"] == "create")

        if allow:
            t_end = time.monotonic() + 30
            while device()["state"] != "connected" and time.monotonic() < t_end:
                time.sleep(0.2)
            d = device()
            if d["state"] != "connected":
                fail("allow-listed board without BOS: create is %s (%s)" % (d["state"], d["reason"]))
            value = get_json(port, "/api/devices/create/properties/DistanceTraveled").get("value")
            if not isinstance(value, int):
                fail("allow-listed board: DistanceTraveled %r" % value)
            print("usb.allow: a board without the BOS capability connects and answers", flush=True)
        else:
            # The board was looked at once the gateway says why it is not an RR device (bounded wait).
            t_end = time.monotonic() + 30
            while "usb_demo" not in (device()["reason"] or "") and time.monotonic() < t_end:
                time.sleep(0.2)
            d = device()
            if d["state"] == "connected" or "usb_demo" not in (d["reason"] or ""):
                fail("board without BOS and no allow entry: create is %s (%r)" % (d["state"], d["reason"]))
            print("no usb.allow entry: the board is not taken for an RR device (%s)" % d["reason"], flush=True)
    finally:
        status = child_procs.stop_by_stdin(proc)
    if status != 0:
        fail("rr_usb_fixture exited with %s\n%s" % (status, child_procs.tail(err_path)))
    return 0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--fixture", required=True)
    ap.add_argument("--wrapper", required=True)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="rr_usb_allow_")
    atexit.register(shutil.rmtree, tmp, True)
    for allow in (True, False):
        if run(args, tmp, allow) == 77:
            print("SKIP: rr_usb_fixture exited 77 (not under umockdev-wrapper)")
            return 77
    print("PASS", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
