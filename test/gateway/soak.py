#!/usr/bin/env python3
"""Soak of the rr-gateway process (issue 16; scripts/soak.sh runs it; not a CI test).

For --seconds (default 1800) it keeps, at once:
  * client churn over every transport: RR connections (CreateConnection, ConnectClient to a device, a
    ConnectionTest, close) over rr+tcp, rr+ws and rr+local; JSON WebSockets opened, asked, closed; REST;
  * requests whose latency is measured: JSON `get` of a device property through the gateway to the device
    (WebSocket and REST), every 0.2 s;
  * the demo devices killed (SIGKILL) and restarted on the same port every --restart-every seconds;
  * a stalled consumer (a JSON WebSocket subscribed to the webcam's frames, never reading) and a slow one
    (reads a little every second), replaced every few minutes;
  * hostile peers: bad magic, a 4 GiB MessageSize, half headers, connect/close bursts, on each listener.
Every --sample seconds it records the gateway's RSS, open fds, threads and the latency of the window.

It fails (exit 1) when, between the first quarter of the run (after --warmup) and the last quarter:
  RSS median grows more than --rss-growth-mb (default 24 MiB), fd median more than 8, threads more than 2,
  or the p99 latency of the last quarter exceeds 3x that of the first quarter plus 50 ms; or when the
  gateway exits, or a request of the latency probe fails while the devices are up.
A JSON summary and a CSV of the samples (--csv) are written.

Usage: soak.py --gateway PATH --devices PATH [--seconds 1800] [--csv FILE]
"""
import argparse
import csv
import json
import os
import random
import socket
import statistics
import sys
import tempfile
import threading
import time

import gwproc
import hostile_test as hostile
from ws_conformance_test import OP_TEXT, JsonEcho, rr_message, rr_parse_entry


class Stats:
    def __init__(self):
        self.lock = threading.Lock()
        self.lat = []           # (t, seconds) of successful probe requests
        self.errors = []        # (t, what): probe requests that failed while the devices were up
        self.hostile = []       # (t, what): hostile cases whose connection was not dropped as it must be
        self.counts = {}

    def add_lat(self, dt):
        with self.lock:
            self.lat.append((time.monotonic(), dt))

    def count(self, what, n=1):
        with self.lock:
            self.counts[what] = self.counts.get(what, 0) + n

    def error(self, what):
        with self.lock:
            self.errors.append((time.monotonic(), what))


def p99(values):
    if not values:
        return 0.0
    v = sorted(values)
    return v[min(len(v) - 1, int(len(v) * 0.99))]


class World:
    def __init__(self, args, run_dir):
        self.args = args
        self.run_dir = run_dir
        self.stop = threading.Event()
        self.stats = Stats()
        self.devices_up = threading.Event()
        self.dev_port = gwproc.fixed_port()
        self.dev = gwproc.start_devices(args.devices, port=self.dev_port, play_period=0.05)
        self.devices_up.set()
        cfg = os.path.join(run_dir, "gw.yaml")
        with open(cfg, "w") as f:
            f.write("demo:\n  enabled: false\ndevices:\n"
                    "  - name: create\n    url: rr+tcp://127.0.0.1:%d/?service=create\n    backoff_max_ms: 1000\n"
                    "  - name: webcam\n    url: rr+tcp://127.0.0.1:%d/?service=webcam\n    backoff_max_ms: 1000\n"
                    % (self.dev_port, self.dev_port))
        env = gwproc.gateway_env()
        for k, sub in (("ROBOTRACONTEUR_SYSTEM_RUN_DIR", "run"), ("ROBOTRACONTEUR_USER_RUN_DIR", "run"),
                       ("ROBOTRACONTEUR_SYSTEM_STATE_DIR", "state"), ("ROBOTRACONTEUR_USER_CONFIG_DIR", "config")):
            env[k] = os.path.join(run_dir, sub)
        self.gw = gwproc.Proc([args.gateway, "--listen", "127.0.0.1", "--port", "0", "--log-level", "error",
                               "--config", cfg], env=env)
        gwproc.wait_ready(self.gw.port)
        info = hostile.start.__globals__["glob"].glob(os.path.join(run_dir, "**", "by-nodeid", "*.info"), recursive=True)
        self.gw.local_socket = None
        for path in info:
            for line in open(path):
                if line.startswith("socket:"):
                    self.gw.local_socket = line.split(":", 1)[1].strip()

    def loop(self, name, period, fn):
        def run():
            while not self.stop.is_set():
                try:
                    fn()
                    self.stats.count(name)
                except Exception as e:  # counted; the bounds decide
                    self.stats.count(name + " failed")
                    if self.devices_up.is_set() and name == "probe":
                        self.stats.error("%s: %s: %s" % (name, type(e).__name__, e))
                self.stop.wait(period)
        t = threading.Thread(target=run, name=name, daemon=True)
        t.start()
        return t

    # -- activities
    def probe(self):
        j = self.probe_ws
        t0 = time.monotonic()
        j.ws.sock.settimeout(10)
        ident = "p%d" % random.randrange(1 << 30)
        j.ws.send(OP_TEXT, json.dumps({"id": ident, "op": "get", "device": "create", "member": "DistanceTraveled"}).encode())
        while True:
            op, data = j.ws.recv()
            reply = json.loads(data)
            if reply.get("id") == ident:
                break
        if "error" in reply:
            raise RuntimeError(str(reply["error"])[:200])
        self.stats.add_lat(time.monotonic() - t0)
        t0 = time.monotonic()
        st, body = gwproc.http_status("http://127.0.0.1:%d/api/devices/create/properties/DistanceTraveled" % self.gw.port,
                                      timeout=10)
        if st != 200:
            raise RuntimeError("REST %d %s" % (st, body[:100]))
        self.stats.add_lat(time.monotonic() - t0)

    def churn(self):
        kind = random.choice(["tcp", "ws", "local"] if self.gw.local_socket else ["tcp", "ws"])
        p = hostile.Pipe(kind, self.gw).handshake()
        p.send(rr_message(107, "", 1, sender=p.sender, path="create", endpoint=random.randrange(1, 1 << 30)))
        etype, _ = rr_parse_entry(p.read_message())
        p.send(p.ping(2))
        p.read_message()
        p.close(rst=random.random() < 0.3)
        j = JsonEcho(self.gw.port)
        j.roundtrip(200)
        j.ws.close()

    def consumers(self):
        """A stalled and a slow consumer of the webcam frames, for a while, then closed."""
        subs = []
        for _ in range(2):
            j = JsonEcho(self.gw.port)
            j.ws.send(OP_TEXT, json.dumps({"id": 1, "op": "subscribe", "device": "webcam", "member": "FrameStream",
                                           "object": "Webcams[0]"}).encode())
            subs.append(j)
        stalled, slow = subs
        slow.ws.sock.settimeout(0.2)
        end = time.monotonic() + 120
        while time.monotonic() < end and not self.stop.is_set():
            try:
                slow.ws.sock.recv(16384)
            except (socket.timeout, OSError):
                pass
            self.stop.wait(1.0)
        for j in subs:
            j.ws.close()

    def hostile(self):
        kind = random.choice(["tcp", "ws", "local"] if self.gw.local_socket else ["tcp", "ws"])
        for fn in (hostile.case_bad_magic, hostile.case_4gib):
            try:
                fn(self.gw, kind, self.victims)
            except AssertionError as e:
                with self.stats.lock:
                    self.stats.hostile.append((time.monotonic(), "%s: %s" % (kind, e)))
        socks = []
        for _ in range(50):
            p = hostile.Pipe("tcp", self.gw)
            p.sock.sendall(b"GET / HTTP/1.1\r\nHost: x\r\n")
            socks.append(p)
        self.stop.wait(2)
        for p in socks:
            p.close()
        for i in range(100):
            hostile.Pipe(kind, self.gw).close(rst=i % 2 == 0)

    def restart_devices(self):
        self.devices_up.clear()
        self.dev.kill()
        self.stop.wait(2)
        self.dev = gwproc.start_devices(self.args.devices, port=self.dev_port, play_period=0.05)
        # The gateway reconnects within its backoff (1 s); the probe's errors count again after that.
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline:
            st, body = gwproc.http_status("http://127.0.0.1:%d/api/devices/create" % self.gw.port)
            if st == 200 and '"connected"' in body:
                break
            time.sleep(0.2)
        self.stop.wait(1)
        self.devices_up.set()
        self.stats.count("device restarts")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--devices", required=True)
    ap.add_argument("--seconds", type=float, default=1800)
    ap.add_argument("--warmup", type=float, default=None, help="seconds ignored at the start (default 10%%, max 120)")
    ap.add_argument("--sample", type=float, default=10)
    ap.add_argument("--restart-every", type=float, default=120)
    ap.add_argument("--rss-growth-mb", type=float, default=24)
    ap.add_argument("--csv")
    args = ap.parse_args()
    warmup = args.warmup if args.warmup is not None else min(120.0, args.seconds * 0.1)
    samples = []
    failures = []
    with tempfile.TemporaryDirectory() as run_dir:
        w = World(args, run_dir)
        gw = w.gw
        try:
            w.probe_ws = JsonEcho(gw.port)
            w.victims = hostile.Victims(gw)
            w.loop("probe", 0.2, w.probe)
            w.loop("churn", 0.05, w.churn)
            w.loop("consumers", 5, w.consumers)
            w.loop("hostile", 20, w.hostile)
            w.loop("victims", 2, lambda: w.victims.check("soak", timeout=5))
            t_start = time.monotonic()
            next_restart = t_start + args.restart_every
            while time.monotonic() - t_start < args.seconds:
                time.sleep(args.sample)
                if not gw.alive():
                    failures.append("the gateway exited (status %r)" % gw.p.poll())
                    break
                now = time.monotonic()
                with w.stats.lock:
                    window = [dt for t, dt in w.stats.lat if t > now - args.sample]
                s = {"t": round(now - t_start, 1), "rss_kib": gwproc.vm_rss_kib(gw.pid), "fds": hostile.fd_count(gw.pid),
                     "threads": hostile.thread_count(gw.pid), "requests": len(window),
                     "p50_ms": round(1000 * statistics.median(window), 2) if window else None,
                     "p99_ms": round(1000 * p99(window), 2) if window else None}
                samples.append(s)
                print(json.dumps(s), file=sys.stderr, flush=True)
                if now >= next_restart:
                    w.restart_devices()
                    next_restart = time.monotonic() + args.restart_every
        finally:
            w.stop.set()
            status = gw.stop()
            w.dev.stop()
        if status != 0:
            failures.append("gateway exit status %r on SIGTERM" % status)
    body = [s for s in samples if s["t"] >= warmup]
    q = max(1, len(body) // 4)
    first, last = body[:q], body[-q:]
    result = {"seconds": args.seconds, "samples": len(samples), "counts": w.stats.counts,
              "probe_errors": len(w.stats.errors), "first_errors": [e for _, e in w.stats.errors[:5]],
              "hostile_failures": len(w.stats.hostile), "first_hostile": [e for _, e in w.stats.hostile[:5]]}
    if first and last:
        med = lambda xs, k: statistics.median([x[k] for x in xs])
        lat_first = [dt for t, dt in w.stats.lat if first[0]["t"] - args.sample <= t - t_start <= first[-1]["t"]]
        lat_last = [dt for t, dt in w.stats.lat if last[0]["t"] - args.sample <= t - t_start <= last[-1]["t"]]
        result.update({
            "rss_mib": [round(med(first, "rss_kib") / 1024, 1), round(med(last, "rss_kib") / 1024, 1)],
            "rss_max_mib": round(max(s["rss_kib"] for s in samples) / 1024, 1),
            "fds": [med(first, "fds"), med(last, "fds")], "threads": [med(first, "threads"), med(last, "threads")],
            "p99_ms": [round(1000 * p99(lat_first), 1), round(1000 * p99(lat_last), 1)],
            "p50_ms": [round(1000 * statistics.median(lat_first), 1) if lat_first else None,
                       round(1000 * statistics.median(lat_last), 1) if lat_last else None],
        })
        if result["rss_mib"][1] - result["rss_mib"][0] > args.rss_growth_mb:
            failures.append("RSS grew %.1f MiB (bound %.0f)" % (result["rss_mib"][1] - result["rss_mib"][0], args.rss_growth_mb))
        if result["fds"][1] - result["fds"][0] > 8:
            failures.append("fds grew %s" % result["fds"])
        if result["threads"][1] - result["threads"][0] > 2:
            failures.append("threads grew %s" % result["threads"])
        if result["p99_ms"][1] > 3 * result["p99_ms"][0] + 50:
            failures.append("p99 latency grew %s ms" % result["p99_ms"])
    else:
        failures.append("too few samples (%d) after the warm-up" % len(body))
    if w.stats.errors:
        failures.append("%d probe requests failed while the devices were up" % len(w.stats.errors))
    if w.stats.hostile:
        failures.append("%d hostile connections were not dropped" % len(w.stats.hostile))
    result["failures"] = failures
    result["ok"] = not failures
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            wr = csv.DictWriter(f, fieldnames=list(samples[0].keys()) if samples else ["t"])
            wr.writeheader()
            wr.writerows(samples)
    print(json.dumps(result), flush=True)
    return 0 if not failures else 1


if __name__ == "__main__":
    sys.exit(main())
