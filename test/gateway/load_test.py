#!/usr/bin/env python3
"""Many clients and a slow client on the gateway's wires and pipes (issue 4), with OFFICIAL clients.

rr-demo-devices (the device) and rr-gateway run as separate processes, so the gateway's memory can be
measured alone (/proc/PID/status VmRSS; under ASan the gateway runs with a small quarantine, so RSS
follows live memory).

  fanout  --clients N (default 100) official client connections in this one process, half rr+tcp and
          half rr+ws, each connected to the Create's `packets` wire. One of them starts streaming
          (20 Hz): every connection must receive the stream (at least half the packets sent in the
          window, in increasing sequence order).
  slow    one official client behind a proxy that stops reading from the gateway (its socket buffers
          kept small), connected to a webcam's FrameStream pipe (10 frames/s of 230 KB) and the
          packets wire; a normal client connected to the same members. While the slow client stalls
          for --seconds: the gateway's RSS stays within --rss-bound-mb of what it was before (the
          stalled pipe is offered far more than that), the gateway counts drops, and the normal client
          keeps receiving frames and packets at their full rate.

Usage: load_test.py --gateway PATH --devices PATH --case fanout|slow [--clients N] [--seconds S]
Prints a JSON summary (with the measured figures); exit status 0 only if every check passed.
"""
import argparse
import json
import socket
import sys
import threading
import time

import RobotRaconteur as RR
from prometheus_client.parser import text_string_to_metric_families

import gwproc
import official_transport  # noqa: E402  (the official client's transport, its connect timeout)
from gwproc import expect, wait_for

RRN = RR.RobotRaconteurNode.s
FRAME_BYTES = 320 * 240 * 3


def seq_of(packet):
    d = bytes(bytearray(packet.Data))
    return d[2] | d[3] << 8


class Counter:
    """Values received on one wire connection or pipe endpoint, with their arrival times."""

    def __init__(self):
        self.lock = threading.Lock()
        self.items = []

    def add(self, v):
        with self.lock:
            self.items.append((time.monotonic(), v))

    def since(self, t):
        with self.lock:
            return [v for ts, v in self.items if ts >= t]


def start(gw_exe, dev_exe):
    dev = gwproc.start_devices(dev_exe, play_period=0)
    gw = gwproc.start_gateway(gw_exe, ["--no-demo", "--device", "create=" + dev.info["create_url"],
                                       "--device", "webcam=" + dev.info["webcam_url"]])
    gwproc.wait_ready(gw.port)
    return dev, gw


def case_fanout(checks, gw, n, stats):
    port = gw.port
    proxies, counters = [], []

    def connect_all():
        for i in range(n):
            scheme = "rr+tcp" if i % 2 == 0 else "rr+ws"
            c = RRN.ConnectService("%s://127.0.0.1:%d/?service=create" % (scheme, port))
            conn = c.packets.Connect()
            k = Counter()
            conn.WireValueChanged += lambda _c, v, _ts, k=k: k.add(seq_of(v))
            proxies.append((c, conn))
            counters.append(k)
        status, body = gwproc.http_status("http://127.0.0.1:%d/api/devices" % port)
        clients = {d["name"]: d["clients"] for d in json.loads(body)}
        expect(clients["create"] >= n, "gateway counts %r client sessions on create, want %d" % (clients, n))

    t0 = time.monotonic()
    checks.run("%d official clients connect the packets wire (half rr+tcp, half rr+ws)" % n, connect_all)
    stats["connect_s"] = round(time.monotonic() - t0, 2)
    if len(proxies) < n:
        return

    def all_receive():
        c0 = proxies[0][0]
        c0.StartStreaming()
        time.sleep(0.5)  # the stream reaches every connection
        t_start = time.monotonic()
        window = 4.0
        time.sleep(window)
        got = [k.since(t_start) for k in counters]
        c0.StopStreaming()
        counts = [len(g) for g in got]
        stats["packets_per_client_min"], stats["packets_per_client_max"] = min(counts), max(counts)
        missing = [i for i, c in enumerate(counts) if c < window * 20 / 2]
        expect(not missing, "%d clients got fewer than half the %d packets (e.g. #%s: %d)"
               % (len(missing), window * 20, missing[:1], counts[missing[0]] if missing else 0))
        for i, g in enumerate(got):
            expect(all(b > a or a - b > 30000 for a, b in zip(g, g[1:])), "client %d: sequence out of order" % i)

    checks.run("all %d clients receive the wire at the same time" % n, all_receive)
    for c, conn in proxies:
        try:
            RRN.DisconnectService(c)
        except RR.RobotRaconteurException:
            pass


class StallProxy:
    """TCP proxy (one upstream connection per accepted one); stall() stops reading from the gateway."""

    def __init__(self, target_port):
        self.target_port = target_port
        self.listener = socket.socket()
        self.listener.bind(("127.0.0.1", 0))
        self.listener.listen(8)
        self.port = self.listener.getsockname()[1]
        self.running = threading.Event()
        self.running.set()
        self.closed = False
        self.sockets = []
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self):
        while not self.closed:
            try:
                client, _ = self.listener.accept()
            except OSError:
                return
            upstream = socket.socket()
            # Small buffers: the gateway meets a full socket soon after the stall.
            upstream.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 32 * 1024)
            upstream.connect(("127.0.0.1", self.target_port))
            self.sockets += [client, upstream]
            threading.Thread(target=self._pump, args=(client, upstream, False), daemon=True).start()
            threading.Thread(target=self._pump, args=(upstream, client, True), daemon=True).start()

    def _pump(self, src, dst, stallable):
        while not self.closed:
            if stallable:
                self.running.wait()
            try:
                data = src.recv(16384)
            except OSError:
                break
            if not data:
                break
            try:
                dst.sendall(data)
            except OSError:
                break

    def stall(self):
        self.running.clear()

    def close(self):
        self.closed = True
        self.running.set()
        for s in self.sockets:
            try:
                s.close()
            except OSError:
                pass
        self.listener.close()


def drops(port):
    body = gwproc.http_status("http://127.0.0.1:%d/metrics" % port)[1]
    total = 0.0
    for fam in text_string_to_metric_families(body):
        for s in fam.samples:
            if s.name == "rr_gateway_device_drops_total":
                total += s.value
    return total


def case_slow(checks, gw, seconds, bound_mb, stats):
    port = gw.port
    proxy = StallProxy(port)
    slow_w = RRN.ConnectService("rr+tcp://127.0.0.1:%d/?service=webcam" % proxy.port)
    slow_c = RRN.ConnectService("rr+tcp://127.0.0.1:%d/?service=create" % proxy.port)
    w = RRN.ConnectService("rr+tcp://127.0.0.1:%d/?service=webcam" % port)
    c = RRN.ConnectService("rr+tcp://127.0.0.1:%d/?service=create" % port)
    slow_cam, cam = slow_w.get_Webcams(0), w.get_Webcams(0)
    slow_ep = slow_cam.FrameStream.Connect(-1)
    slow_wire = slow_c.packets.Connect()
    frames, packets = Counter(), Counter()
    ep = cam.FrameStream.Connect(-1)

    def on_frame(e):
        while e.Available:
            f = e.ReceivePacket()
            frames.add(len(f.data))

    ep.PacketReceivedEvent += on_frame
    wire = c.packets.Connect()
    wire.WireValueChanged += lambda _c, v, _ts: packets.add(seq_of(v))
    cam.StartStreaming()
    c.StartStreaming()
    time.sleep(3.0)  # warm: both clients take the stream
    base_kib = gwproc.vm_rss_kib(gw.pid)
    drops0 = drops(port)
    proxy.stall()
    t_stall = time.monotonic()
    samples = []
    while time.monotonic() - t_stall < seconds:
        time.sleep(0.5)
        samples.append(gwproc.vm_rss_kib(gw.pid))
    elapsed = time.monotonic() - t_stall
    got_frames, got_packets = frames.since(t_stall), packets.since(t_stall)
    drops1 = drops(port)
    stats.update({"rss_before_mib": round(base_kib / 1024, 1), "rss_max_mib": round(max(samples) / 1024, 1),
                  "rss_last_mib": round(samples[-1] / 1024, 1), "stalled_s": round(elapsed, 1),
                  "offered_to_stalled_mib": round(elapsed * 10 * FRAME_BYTES / 2**20, 1),
                  "normal_fps": round(len(got_frames) / elapsed, 1),
                  "normal_packets_hz": round(len(got_packets) / elapsed, 1), "drops": drops1 - drops0})
    print(json.dumps(stats), file=sys.stderr)

    # The bound means something only if the stalled pipe was offered clearly more than it.
    checks.run("the stall offered more than twice the bound", lambda: expect(
        stats["offered_to_stalled_mib"] > 2 * bound_mb, "only %.0f MiB offered" % stats["offered_to_stalled_mib"]))
    checks.run("gateway RSS bounded while a client stalls", lambda: expect(
        (max(samples) - base_kib) / 1024 < bound_mb,
        "RSS grew %.1f MiB (bound %d MiB) with %.0f MiB offered to the stalled pipe"
        % ((max(samples) - base_kib) / 1024, bound_mb, stats["offered_to_stalled_mib"])))
    checks.run("the stalled client's pipe packets are dropped and counted", lambda: expect(
        drops1 - drops0 > 0, "rr_gateway_device_drops_total did not grow (%r -> %r)" % (drops0, drops1)))
    checks.run("the normal client keeps the frame rate (~10/s)", lambda: expect(
        stats["normal_fps"] >= 7, "%.1f frames/s" % stats["normal_fps"]))
    checks.run("the normal client keeps the packet rate (~20/s)", lambda: expect(
        stats["normal_packets_hz"] >= 14, "%.1f packets/s" % stats["normal_packets_hz"]))
    checks.run("normal frames are whole", lambda: expect(
        all(n == FRAME_BYTES for n in got_frames), "frame sizes %r" % sorted(set(got_frames))))
    cam.StopStreaming()
    c.StopStreaming()
    proxy.close()
    checks.run("the gateway still serves new clients", lambda: expect(
        RRN.ConnectService("rr+tcp://127.0.0.1:%d/?service=create" % port).Bumpers == 0, "Bumpers"))
    del slow_ep, slow_wire


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--devices", required=True)
    ap.add_argument("--case", required=True, choices=["fanout", "slow"])
    ap.add_argument("--clients", type=int, default=100)
    ap.add_argument("--seconds", type=float, default=30)
    ap.add_argument("--rss-bound-mb", type=int, default=32)
    a = ap.parse_args()
    checks = gwproc.Checks()
    stats = {}
    dev, gw = start(a.gateway, a.devices)
    try:
        RRN.RegisterTransport(official_transport.client_tcp_transport(RR))
        RRN.RequestTimeout = 20
        if a.case == "fanout":
            case_fanout(checks, gw, a.clients, stats)
        else:
            case_slow(checks, gw, a.seconds, a.rss_bound_mb, stats)
        checks.run("gateway still running", lambda: expect(gw.alive(), "gateway exited"))
    finally:
        watchdog = threading.Timer(20, lambda: (print("RRN.Shutdown hung", file=sys.stderr), gw.kill(), dev.kill()))
        watchdog.daemon = True
        watchdog.start()
        try:
            RRN.Shutdown()
        finally:
            watchdog.cancel()
            status = gw.stop()
            dev.stop()
    checks.run("gateway exit status 0 on SIGTERM", lambda: expect(status == 0, "exit status %r" % status))
    print(json.dumps({"stats": stats}))
    return checks.exit_code()


if __name__ == "__main__":
    sys.exit(main())
