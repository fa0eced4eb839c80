#!/usr/bin/env python3
"""Drives experimental.bench with the official Robot Raconteur client (Python package).

Prints one JSON line per operation with the keys of bench/bench_common.hpp (op, n, p50_us, p99_us,
max_us, ops_per_s, mb_s, client_cpu_us_per_op, client_vcsw_per_op, label).

Usage: official_client.py --url URL [--label L] [--count N] [--ops a,b,...]
Operations as rr_bench_client: nop, echo10, echo1000, echo100000, get, set, peek, wire, pipe, memory.
"""
import argparse
import json
import resource
import sys
import threading
import time

import numpy as np
import RobotRaconteur as RR

RRN = RR.RobotRaconteurNode.s
LABEL = ""


def emit(row):
    row["label"] = LABEL
    print(json.dumps(row), flush=True)


def cpu():
    u = resource.getrusage(resource.RUSAGE_SELF)
    return (u.ru_utime + u.ru_stime) * 1e6, u.ru_nvcsw


def percentile(samples, q):
    if not samples:
        return 0.0
    s = sorted(samples)
    return s[int(q * (len(s) - 1) + 0.5)]


def latency_row(op, samples, wall_us, bytes_per_op, c0, c1):
    n = len(samples)
    row = {"op": op, "n": n, "p50_us": percentile(samples, 0.5), "p99_us": percentile(samples, 0.99),
           "max_us": max(samples) if samples else 0.0, "ops_per_s": n * 1e6 / wall_us if wall_us else 0.0,
           "client_cpu_us_per_op": (c1[0] - c0[0]) / n if n else 0.0,
           "client_vcsw_per_op": (c1[1] - c0[1]) / n if n else 0.0}
    if bytes_per_op:
        row["mb_s"] = bytes_per_op * n / wall_us if wall_us else 0.0
    return row


def timed(op, count, bytes_per_op, fn, warmup=50):
    for _ in range(warmup):
        fn()
    samples = []
    c0 = cpu()
    t0 = time.perf_counter()
    for _ in range(count):
        a = time.perf_counter()
        fn()
        samples.append((time.perf_counter() - a) * 1e6)
    wall = (time.perf_counter() - t0) * 1e6
    emit(latency_row(op, samples, wall, bytes_per_op, c0, cpu()))


def wire_latency(c, count, rate_hz):
    w = c.Ticks.Connect()
    lat = []
    done = threading.Event()

    def changed(conn, value, ts):
        now = time.time() * 1e6
        if len(value) >= 2 and value[1] >= 0:
            lat.append(now - value[0])
            if value[1] >= count - 1:
                done.set()

    w.WireValueChanged += changed
    c0 = cpu()
    t0 = time.perf_counter()
    c.StartTicks(float(rate_hz), count, 2)
    complete = done.wait(count / rate_hz + 10)
    wall = (time.perf_counter() - t0) * 1e6
    w.WireValueChanged -= changed
    w.Close()
    row = latency_row("wire", list(lat), wall, 0, c0, cpu())
    row.update({"rate_hz": rate_hz, "sent": count, "complete": complete})
    emit(row)


def wire_rate(c, count):
    w = c.Ticks.Connect()
    got = []
    done = threading.Event()

    def changed(conn, value, ts):
        now = time.time() * 1e6
        if len(value) >= 2 and value[1] >= 0:
            got.append((time.perf_counter(), now - value[0]))
            if value[1] >= count - 1:
                done.set()

    w.WireValueChanged += changed
    t0 = time.perf_counter()
    c.StartTicks(0.0, count, 2)
    complete = done.wait(30)
    w.WireValueChanged -= changed
    w.Close()
    got = list(got)
    window = got[-1][0] - t0 if got else 0  # StartTicks called .. last value in, as rr_bench_client
    lat = [g[1] for g in got]
    emit({"op": "wire_rate", "sent": count, "delivered": len(got), "complete": complete,
          "sent_per_s": count / window if window else 0.0, "ops_per_s": len(got) / window if window else 0.0,
          "p50_us": percentile(lat, 0.5), "p99_us": percentile(lat, 0.99)})


def pipe_rate(c, count):
    ep = c.Packets.Connect(-1)
    ep.RequestPacketAck = True
    acked = [0]
    done = threading.Event()

    def ack(e, n):
        acked[0] += 1
        if acked[0] >= count:
            done.set()

    ep.PacketAckReceivedEvent += ack
    packet = np.arange(8, dtype=np.float64) * 0.5
    c0 = cpu()
    t0 = time.perf_counter()
    for _ in range(count):
        ep.SendPacket(packet)
    complete = done.wait(60)
    wall = (time.perf_counter() - t0) * 1e6
    c1 = cpu()
    ep.Close()
    emit({"op": "pipe", "n": count, "ops_per_s": count * 1e6 / wall, "mb_s": count * 64 / wall,
          "client_cpu_us_per_op": (c1[0] - c0[0]) / count, "complete": complete})


def memory_rates(c, repeats):
    length = c.Buffer.Length
    data = np.arange(length, dtype=np.float64) * 0.5
    buf = np.zeros(length, dtype=np.float64)
    for op in ("memory_read", "memory_write"):
        samples = []
        c0 = cpu()
        t0 = time.perf_counter()
        for _ in range(repeats):
            a = time.perf_counter()
            if op == "memory_read":
                c.Buffer.Read(0, buf, 0, length)
            else:
                c.Buffer.Write(0, data, 0, length)
            samples.append((time.perf_counter() - a) * 1e6)
        row = latency_row(op, samples, (time.perf_counter() - t0) * 1e6, length * 8, c0, cpu())
        row["bytes"] = length * 8
        emit(row)


def main(argv=None):
    global LABEL
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--url", required=True)
    ap.add_argument("--label", default="")
    ap.add_argument("--count", type=int, default=5000)
    ap.add_argument("--ops", default="nop,echo10,echo1000,echo100000,get,set,peek,wire,wire_rate,pipe,memory")
    args = ap.parse_args(argv)
    LABEL = args.label
    n = args.count

    with RR.ClientNodeSetup(argv=["bench_official_client"]):
        c = RRN.ConnectService(args.url)
        for op in args.ops.split(","):
            if op == "nop":
                timed("nop", n, 0, c.Nop)
            elif op.startswith("echo"):
                k = int(op[4:])
                calls = max(20, n // 50) if k >= 100000 else (n // 2 if k >= 1000 else n)
                arg = np.arange(k, dtype=np.float64) * 0.5

                def echo(arg=arg, k=k):
                    if len(c.Echo(arg)) != k:
                        raise RuntimeError("wrong echo size")
                timed(op, calls, k * 16, echo, warmup=5 if k >= 100000 else 50)
            elif op == "get":
                timed("get", n, 0, lambda: c.Value)
            elif op == "set":
                def set_value():
                    c.Value = 1.5
                timed("set", n, 0, set_value)
            elif op == "peek":
                timed("peek", n, 0, lambda: c.Ticks.PeekInValue())
            elif op == "wire":
                wire_latency(c, max(100, n // 5), 500)
            elif op == "wire_rate":
                wire_rate(c, n * 4)
            elif op == "pipe":
                pipe_rate(c, n * 2)
            elif op == "memory":
                memory_rates(c, 3)
            else:
                print("unknown op " + op, file=sys.stderr)
                return 2
        RRN.DisconnectService(c)
    return 0


if __name__ == "__main__":
    sys.exit(main())
