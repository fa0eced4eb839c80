#!/usr/bin/env python3
"""Runs the benchmark suite (bench/run.sh builds first) and writes bench/results/latest.json and
bench/results/latest.md.

Every figure is measured in the same run as its reference and reported with the ratio:
  * call latencies (p50) against the raw TCP ping-pong floor (64 B, TCP_NODELAY);
  * Echo 100,000 doubles (MB/s) against the TCP bulk round trip of the same size;
  * our rows against the official library's row for the same operation (speed-up = official / ours);
  * the gateway hop (through-gateway p50 minus direct p50) against the floor.
Latency rows run in R interleaved rounds (floor, ours, official, ... repeated) and report the median
of the rounds' medians: single runs drift by about ±25 % on these machines (../shared/BENCHMARKING.md).

Each JSON fan-out row is followed by its floor (rr_bench_floor --fanout N): the same N x 100 messages/s of
the same size written by one thread to N plain loopback TCP sockets, no protocol: the kernel's own cost
for the traffic, which the gateway's CPU per value is compared with.

Issue 14's rows, off unless asked for (--rr-fanout, --camera, --browser, or --only SECTIONS):
  * rr-fanout: N native RR clients (rr_bench_rr_fanout) on the device's Ticks wire at 100 Hz through
    the gateway over rr+ws, and the same N directly on the device (the reference of the same moment);
  * camera: 640x480 RGB frames at 30 Hz (the Frames wire) to N JSON clients with binary pushes;
  * browser: the wasm client in node and in headless Chromium (wasm_bench.mjs), Nop and a property
    read through the gateway over rr+ws, with the native client and the TCP floor in the same rounds.
  * record (issue 44, --record): the camera row (640x480 RGB at 30 Hz to 10 JSON clients) and a
    1,000 values/s wire (Ticks to 10 JSON clients), each without and with a recording of it running in
    the gateway (POST /api/recordings), alternating within each round (--record-rounds, default 2).

Usage: run.py --build DIR [--rounds R] [--count N] [--quick] [--no-busy] [--skip-fanout] [--skip-scale]
              [--rr-fanout] [--camera] [--browser] [--record]
              [--only calls,fanout,scale,rr-fanout,camera,browser,pairs,record]
"""
import argparse
import datetime
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
PY = os.path.join(ROOT, ".venv", "bin", "python")
CALL_OPS = ["nop", "echo10", "echo1000", "echo100000", "get", "set", "peek"]
STREAM_OPS = ["wire", "wire_rate", "pipe", "memory"]


def log(*a):
    print("[bench]", *a, file=sys.stderr, flush=True)


class Proc:
    """A child process that prints one JSON line when ready; stopped with SIGTERM (then SIGKILL)."""

    def __init__(self, argv, name):
        self.name = name
        self.p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        line = self.p.stdout.readline()
        if not line:
            raise RuntimeError("%s exited before it was ready: %s" % (name, " ".join(argv)))
        self.ready = json.loads(line)

    def stop(self):
        if self.p.poll() is None:
            self.p.terminate()
            try:
                self.p.wait(10)
            except subprocess.TimeoutExpired:
                self.p.kill()
                self.p.wait()


def run_rows(argv, timeout=300):
    """The JSON lines a bench program prints (run_timed without the times)."""
    return [row for row, _ in run_timed(argv, timeout)]


def proc_sample(pid):
    """(CPU seconds, RSS KiB) of a process from /proc."""
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    ticks = os.sysconf("SC_CLK_TCK")
    cpu = (int(fields[11]) + int(fields[12])) / ticks
    rss = 0
    with open("/proc/%d/status" % pid) as f:
        for l in f:
            if l.startswith("VmRSS:"):
                rss = int(l.split()[1])
    return cpu, rss


def machine_info():
    info = {"uname": " ".join(platform.uname()), "cpus": os.cpu_count()}
    with open("/proc/cpuinfo") as f:
        for l in f:
            if l.startswith("model name"):
                info["cpu_model"] = l.split(":", 1)[1].strip()
                break
    with open("/proc/meminfo") as f:
        info["mem_total_kib"] = int(f.readline().split()[1])
    try:
        info["git_commit"] = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], stdout=subprocess.PIPE,
                                            text=True).stdout.strip()
    except OSError:
        pass
    return info


def start_busy_loops():
    """Two lowest-priority busy loops keep the vCPUs out of idle halts (the busy regime)."""
    return [subprocess.Popen(["nice", "-n", "19", "sh", "-c", "while :; do :; done"]) for _ in range(2)]


def median_rows(rows):
    """Rows of one (label, op) from several rounds -> one row: medians, max of max."""
    out = dict(rows[0])
    for k in ("p50_us", "p99_us", "ops_per_s", "mb_s", "client_cpu_us_per_op", "client_vcsw_per_op"):
        vals = [r[k] for r in rows if k in r]
        if vals:
            out[k] = statistics.median(vals)
    if any("max_us" in r for r in rows):
        out["max_us"] = max(r.get("max_us", 0) for r in rows)
    out["rounds"] = len(rows)
    out["p50_us_rounds"] = [round(r.get("p50_us", 0), 2) for r in rows]
    return out


def fit_slope(points):
    """Least-squares slope and intercept of (bytes, µs) points: ns/byte and µs."""
    n = len(points)
    if n < 2:
        return None
    mx = sum(p[0] for p in points) / n
    my = sum(p[1] for p in points) / n
    sxx = sum((p[0] - mx) ** 2 for p in points)
    if sxx == 0:
        return None
    slope = sum((p[0] - mx) * (p[1] - my) for p in points) / sxx
    return {"ns_per_byte": slope * 1000, "intercept_us": my - slope * mx}


def proc_vcsw(pid):
    """Voluntary context switches of all a process's threads, from /proc."""
    n = 0
    for tid in os.listdir("/proc/%d/task" % pid):
        try:
            with open("/proc/%d/task/%s/status" % (pid, tid)) as f:
                for l in f:
                    if l.startswith("voluntary_ctxt_switches:"):
                        n += int(l.split()[1])
        except OSError:
            pass  # the thread ended
    return n


def threads_cpu(pid, prefix):
    """(CPU seconds (utime + stime) of a process's live threads whose name (comm) starts with `prefix`,
    minor page faults of the other live threads), from /proc/<pid>/task/*/stat. A thread that ended is
    no longer counted (its time stays in the process's own figure)."""
    ticks = os.sysconf("SC_CLK_TCK")
    total, other_minflt = 0, 0
    for tid in os.listdir("/proc/%d/task" % pid):
        try:
            with open("/proc/%d/task/%s/stat" % (pid, tid)) as f:
                head, rest = f.read().rsplit(")", 1)
        except OSError:
            continue  # the thread ended
        fields = rest.split()
        if head.split("(", 1)[1].startswith(prefix):
            total += int(fields[11]) + int(fields[12])
        else:
            other_minflt += int(fields[7])
    return total / ticks, other_minflt


class Sampler(threading.Thread):
    """Samples a process's CPU, RSS and voluntary context switches every 0.2 s with wall-clock stamps;
    with `thread_prefix`, also the CPU of its threads so named (threads_cpu)."""

    def __init__(self, pid, thread_prefix=None):
        super().__init__(daemon=True)
        self.pid, self.samples, self.stop_flag = pid, [], threading.Event()
        self.thread_prefix = thread_prefix

    def run(self):
        while not self.stop_flag.is_set():
            try:
                named = threads_cpu(self.pid, self.thread_prefix) if self.thread_prefix else (0.0, 0)
                self.samples.append((time.time(),) + proc_sample(self.pid) + (proc_vcsw(self.pid),) + named)
            except OSError:
                return
            time.sleep(0.2)

    def finish(self):
        self.stop_flag.set()
        self.join()

    def window(self, t0, t1):
        s = [x for x in self.samples if t0 <= x[0] <= t1]
        if len(s) < 2:
            return None
        dt = s[-1][0] - s[0][0]
        return {"cpu_pct": 100 * (s[-1][1] - s[0][1]) / dt, "rss_kib_max": max(x[2] for x in s),
                "vcsw_per_s": (s[-1][3] - s[0][3]) / dt, "named_threads_cpu_pct": 100 * (s[-1][4] - s[0][4]) / dt,
                "other_threads_minflt_per_s": (s[-1][5] - s[0][5]) / dt}


SECTIONS = ("calls", "fanout", "scale", "rr-fanout", "camera", "browser", "pairs", "record", "rate", "uring", "ab",
            "gather", "scale10k")
# Fan-out and scale open more connections from 127.0.0.1 than gateway.limits.connections_per_address
# allows by default (256); 0 lifts the limit.
UNLIMITED_CONFIG = "gateway:\n  limits:\n    connections_per_address: 0\n"


def gateway_proc(exe, device_url, name="rr-gateway", unlimited=False, prefix=(), deflate=False, gathered=None):
    argv = [*prefix, exe["rr-gateway"], "--no-demo", "--no-local", "--port", "0", "--log-level", "warning", "--device",
            "bench=" + device_url]
    if unlimited:
        path = os.path.join(tempfile.gettempdir(), "rr-bench-gateway-%d.yaml" % os.getpid())
        with open(path, "w") as f:
            f.write(UNLIMITED_CONFIG)
            if deflate:
                f.write("  websocket_compression:\n    enabled: true\n")
            if gathered is not None:
                f.write("  websocket_gathered_writes: %s\n" % ("true" if gathered else "false"))
        argv += ["--config", path]
    gw = Proc(argv, name)
    time.sleep(1.0)  # the gateway connects to its device
    return gw


def run_timed(argv, timeout=600):
    """The JSON lines a bench program prints, each with the wall-clock time it arrived (a row's
    measuring window ends there). A program still running after `timeout` s is killed; a failure is
    logged and its rows so far are kept."""
    p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    rows = []
    timer = threading.Timer(timeout, p.kill)
    timer.start()
    try:
        for line in p.stdout:
            if line.startswith("{"):
                rows.append((json.loads(line), time.time()))
        err = p.stderr.read()
        p.wait()
    finally:
        timer.cancel()
    if p.returncode != 0:
        log("FAILED (%d): %s\n%s" % (p.returncode, " ".join(argv), err[-2000:]))
    return rows


def sampled(pid, argv, label_fields, thread_prefix=None):
    """Runs a load generator while sampling `pid`; each row gets the server's CPU, RSS and context
    switches over the row's measuring window (the last `seconds` before its line), per delivered value too.
    With `thread_prefix`: also the CPU of the server's threads so named (`named_threads_cpu_*`) and of the
    others (`other_threads_cpu_*`: the process less those threads)."""
    sampler = Sampler(pid, thread_prefix)
    sampler.start()
    t0 = time.time()
    rows = run_timed(argv)
    time.sleep(1.0)  # the RSS once the clients are gone
    sampler.finish()
    out = []
    for row, t_line in rows:
        row.update(label_fields)
        row["wall_s"] = t_line - t0
        w = sampler.window(t_line - row["seconds"], t_line)
        if w:
            per_s = row.get("delivered_per_s") or 0
            row.update({"server_cpu_pct": w["cpu_pct"], "server_rss_kib": w["rss_kib_max"],
                        "server_cpu_us_per_value": w["cpu_pct"] * 1e4 / per_s if per_s else None,
                        "server_vcsw_per_value": w["vcsw_per_s"] / per_s if per_s else None})
            if thread_prefix:
                named, other = w["named_threads_cpu_pct"], w["cpu_pct"] - w["named_threads_cpu_pct"]
                row.update({"named_threads": thread_prefix, "named_threads_cpu_pct": named, "other_threads_cpu_pct": other,
                            "named_threads_cpu_us_per_value": named * 1e4 / per_s if per_s else None,
                            "other_threads_cpu_us_per_value": other * 1e4 / per_s if per_s else None,
                            "other_threads_minflt_per_value": w["other_threads_minflt_per_s"] / per_s if per_s else None})
        if sampler.samples:
            row["server_rss_after_kib"] = sampler.samples[-1][2]
        out.append(row)
    return out


def rr_fanout_section(exe, args, procs):
    """Native RR clients on Ticks (100 Hz): through the gateway over rr+ws, then directly on the device
    (its own rr+ws fan-out, the reference of the same moment). A fresh gateway per N (clean RSS)."""
    rows = []
    dev = Proc([exe["rr_bench_service"], "--websocket", "--tick-hz", "100"], "bench_service (100 Hz)")
    procs.append(dev)
    seconds = "3" if args.quick else "5"
    for n in [10, 100, 1000]:
        for path in ("gateway", "direct"):
            log("rr fan-out: %d native clients over rr+ws, %s" % (n, "through the gateway" if path == "gateway" else "on the device"))
            gw = gateway_proc(exe, dev.ready["url"], unlimited=True) if path == "gateway" else None
            if gw:
                procs.append(gw)
            url = "rr+ws://127.0.0.1:%d/?service=bench" % gw.ready["port"] if gw else dev.ready["ws_url"]
            rows += sampled(gw.p.pid if gw else dev.p.pid,
                            [exe["rr_bench_rr_fanout"], "--url", url, "--clients", str(n), "--seconds", seconds, "--hz", "100",
                             "--threads", str(args.rr_fanout_threads)],
                            {"path": "ours->gateway->N x ours rr+ws" if gw else "ours->N x ours rr+ws (device direct)",
                             "server": "gateway" if gw else "device"})
            if gw:
                gw.stop()
                procs.remove(gw)
    dev.stop()
    procs.remove(dev)
    return rows


def camera_section(exe, args, procs):
    """640x480 RGB frames (921,600 bytes) at 30 Hz on Frames → gateway → N JSON clients with binary pushes.
    N = 1 is the reference of the same moment; a fresh gateway per N. The last row has 2 slow consumers
    among 10 clients (each waits 200 ms before every read: at most 5 frames/s): what the gateway does
    for a client that falls behind (a wire keeps the newest value) and what it costs the others."""
    rows = []
    dev = Proc([exe["rr_bench_service"], "--frame-hz", "30", "--frame-bytes", str(640 * 480 * 3)], "bench_service (frames)")
    procs.append(dev)
    seconds = "3" if args.quick else "5"
    for n, slow in [(1, 0), (10, 0), (50, 0), (10, 2)]:
        log("camera: 30 frames/s of 921,600 bytes to %d JSON clients (binary pushes)%s" % (n, ", %d slow" % slow if slow else ""))
        gw = gateway_proc(exe, dev.ready["url"], unlimited=True)
        procs.append(gw)
        rows += sampled(gw.p.pid, [exe["rr_bench_ws_load"], "--port", str(gw.ready["port"]), "--clients", str(n), "fanout",
                                   "--member", "Frames", "--binary", "--hz", "30", "--seconds", seconds] +
                        (["--slow", str(slow), "--read-delay-ms", "200"] if slow else []),
                        {"path": "device->gateway->N x JSON (binary)", "server": "gateway", "frame_bytes": 640 * 480 * 3,
                         "hz": 30.0})
        gw.stop()
        procs.remove(gw)
    dev.stop()
    procs.remove(dev)
    return rows


def rate_section(exe, args, procs):
    """Issue 56: what a client-chosen rate and compression cost. The device's Ticks wire at 100 Hz to N
    JSON clients: subscribed without a rate, at max_rate_hz 100 and at 10 (1,000 clients; the target:
    10 Hz at most 15 % of the gateway's CPU at 100 Hz), then 100 clients without and with
    permessage-deflate negotiated (websocket_compression enabled, the clients offer it). A fresh
    gateway per row; rows alternate within each round (--rate-rounds)."""
    rows = []
    dev = Proc([exe["rr_bench_service"], "--tick-hz", "100"], "bench_service (100 Hz)")
    procs.append(dev)
    seconds = "3" if args.quick else "5"
    n_rate = 100 if args.quick else 1000
    cases = [(n_rate, None, False), (n_rate, 100, False), (n_rate, 10, False), (100, None, False), (100, None, True)]
    for rnd in range(args.rate_rounds):
        for n, rate, deflate in cases:
            log("rate (round %d): %d JSON clients, %s, deflate %s" % (rnd + 1, n, "max_rate_hz %s" % rate if rate else "no rate",
                                                                     "on" if deflate else "off"))
            gw = gateway_proc(exe, dev.ready["url"], unlimited=True, deflate=deflate)
            procs.append(gw)
            argv = [exe["rr_bench_ws_load"], "--port", str(gw.ready["port"]), "--clients", str(n), "fanout", "--hz", "100",
                    "--seconds", seconds]
            if rate:
                argv += ["--max-rate-hz", str(rate)]
            if deflate:
                argv += ["--deflate"]
            rows += sampled(gw.p.pid, argv, {"path": "device->gateway->N x JSON", "server": "gateway", "round": rnd + 1,
                                             "deflate": deflate})
            gw.stop()
            procs.remove(gw)
    dev.stop()
    procs.remove(dev)
    return rows


def gateway_pair_section(exe, other_exe, names, rounds, n, args, procs, what, gathered=(None, None)):
    """Two gateways under the same load: the device's Ticks wire at 100 Hz to N JSON clients through this
    build's gateway and through `other_exe`'s (or the same one configured two ways: `gathered`, the
    gateway.websocket_gathered_writes of each, None = its default), alternating within each round (A B,
    then B A), the same load generator and device for both, and the plain-TCP floor (rr_bench_floor
    --fanout) once per round. A fresh gateway per row. Rows carry `backend` (the name in `names`) and `round`."""
    rows = []
    backends = [(names[0], exe, gathered[0]), (names[1], other_exe, gathered[1])]
    dev = Proc([exe["rr_bench_service"], "--tick-hz", "100"], "bench_service (100 Hz)")
    procs.append(dev)
    seconds = "3" if args.quick else "5"
    for rnd in range(rounds):
        for backend, gexe, gather in (backends if rnd % 2 == 0 else list(reversed(backends))):
            log("%s (round %d): %d JSON clients, gateway %s" % (what, rnd + 1, n, backend))
            gw = gateway_proc(gexe, dev.ready["url"], name="rr-gateway (%s)" % backend, unlimited=True, gathered=gather)
            procs.append(gw)
            got = sampled(gw.p.pid, [exe["rr_bench_ws_load"], "--port", str(gw.ready["port"]), "--clients", str(n), "fanout",
                                     "--hz", "100", "--seconds", seconds],
                          {"path": "device->gateway->N x JSON", "server": "gateway", "backend": backend, "round": rnd + 1})
            gw.stop()
            procs.remove(gw)
            rows += got
        size = next((r.get("bytes_per_value") for r in rows if r.get("bytes_per_value")), 128)
        floor = run_rows([exe["rr_bench_floor"], "--fanout", str(n), "--seconds", seconds, "--hz", "100",
                          "--bytes", str(max(16, int(round(size))))])
        for f in floor:
            f.update({"backend": "floor (plain TCP writes)", "round": rnd + 1})
            rows.append(f)
    dev.stop()
    procs.remove(dev)
    return rows


def uring_section(exe, args, procs):
    """Issue 56's io_uring lever: this build's gateway (Asio on epoll) against the gateway of --uring-build
    (configured with -DRR_IO_URING=ON), gateway_pair_section."""
    uring_gateway = os.path.join(os.path.abspath(args.uring_build), "server", "app", "rr-gateway")
    if not os.access(uring_gateway, os.X_OK):
        raise SystemExit("--uring-build: %s is missing (cmake -DRR_IO_URING=ON, target rr-gateway)" % uring_gateway)
    return gateway_pair_section(exe, dict(exe, **{"rr-gateway": uring_gateway}), ("epoll", "io_uring"), args.uring_rounds,
                                args.uring_clients, args, procs, "io_uring")


def ab_section(exe, args, procs):
    """This build's gateway against another build's (--ab-gateway: e.g. a copy of the gateway from before a
    change), gateway_pair_section: issue 56's gathered writes were measured so."""
    other = os.path.abspath(args.ab_gateway)
    if not os.access(other, os.X_OK):
        raise SystemExit("--ab-gateway: %s is missing (copy an rr-gateway built from the base commit there)" % other)
    names = tuple(x.strip() for x in args.ab_names.split(","))
    if len(names) != 2:
        raise SystemExit("--ab-names: two names, comma-separated")
    return gateway_pair_section(exe, dict(exe, **{"rr-gateway": other}), names, args.ab_rounds, args.ab_clients, args,
                                procs, "A/B")


def gather_section(exe, args, procs):
    """Issue 56's gathered writes: this build's gateway with gateway.websocket_gathered_writes true and
    false (one write per message, as before the lever), gateway_pair_section."""
    return gateway_pair_section(exe, exe, ("gathered", "one write per message"), args.gather_rounds, args.gather_clients,
                                args, procs, "gather", gathered=(True, False))


def scale10k_section(exe, args, procs):
    """Issue 56's 10,000-connection row: N (default 10,000) idle JSON WebSockets on a fresh gateway (its
    RSS before and with them), then N clients subscribed to a 1 Hz wire on another fresh gateway (CPU per
    value, RSS per connection), then the plain-TCP floor of that traffic (N sockets, 1 write each per
    second)."""
    n = args.scale10k_clients
    seconds = str(args.scale10k_seconds)
    rows = []
    dev = Proc([exe["rr_bench_service"], "--tick-hz", "1"], "bench_service (1 Hz)")
    procs.append(dev)
    gw = gateway_proc(exe, dev.ready["url"], "rr-gateway (idle %d)" % n, unlimited=True)
    procs.append(gw)
    log("scale10k: %d idle WebSocket connections" % n)
    time.sleep(1.0)
    base = proc_sample(gw.p.pid)[1]
    lg = subprocess.Popen([exe["rr_bench_ws_load"], "--port", str(gw.ready["port"]), "--clients", str(n), "idle"],
                          stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    row = json.loads(lg.stdout.readline())
    time.sleep(2.0)
    cpu0, loaded = proc_sample(gw.p.pid)
    time.sleep(5.0)
    cpu1, loaded_later = proc_sample(gw.p.pid)
    lg.stdin.write("\n")
    lg.stdin.flush()
    lg.wait(120)
    row.update({"mode": "idle", "gateway_rss_base_kib": base, "gateway_rss_kib": max(loaded, loaded_later),
                "rss_per_connection_kib": (max(loaded, loaded_later) - base) / row["opened"] if row["opened"] else None,
                "idle_cpu_pct": 100 * (cpu1 - cpu0) / 5.0})
    rows.append(row)
    gw.stop()
    procs.remove(gw)

    log("scale10k: %d JSON clients on a 1 Hz wire" % n)
    gw = gateway_proc(exe, dev.ready["url"], "rr-gateway (1 Hz x %d)" % n, unlimited=True)
    procs.append(gw)
    time.sleep(1.0)
    base = proc_sample(gw.p.pid)[1]
    got = sampled(gw.p.pid, [exe["rr_bench_ws_load"], "--port", str(gw.ready["port"]), "--clients", str(n), "fanout",
                             "--hz", "1", "--seconds", seconds],
                  {"mode": "1 Hz", "path": "device->gateway->N x JSON", "server": "gateway", "gateway_rss_base_kib": base})
    for r in got:
        if r.get("server_rss_kib") and r.get("opened"):
            r["rss_per_connection_kib"] = (r["server_rss_kib"] - base) / r["opened"]
    rows += got
    gw.stop()
    procs.remove(gw)
    dev.stop()
    procs.remove(dev)
    size = next((r.get("bytes_per_value") for r in rows if r.get("bytes_per_value")), 128)
    for f in run_rows([exe["rr_bench_floor"], "--fanout", str(n), "--seconds", seconds, "--hz", "1",
                       "--bytes", str(max(16, int(round(size))))], timeout=600):
        f["mode"] = "floor (plain TCP writes)"
        rows.append(f)
    return rows


def post_json(port, path, body, timeout=120):
    req = urllib.request.Request("http://127.0.0.1:%d%s" % (port, path), data=json.dumps(body).encode(), method="POST",
                                 headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=timeout) as r:
        return json.loads(r.read())


def record_section(exe, args, procs):
    """Issue 44: what a recording running in the gateway costs the live path. Two workloads, each on a
    fresh gateway per row, without and with a recording (docs/recording.md) of the member, alternating
    within each round so that each pair shares the moment:
      * camera: 640x480 RGB frames (921,600 bytes) at 30 Hz on Frames to 10 JSON clients (binary pushes),
        recorded with the `robotraconteur` encoding only (the frame as JSON numbers would cost ~4 ms and
        3.5 MB a frame; `json` is for plots, not images);
      * wire: Ticks at 1,000 values/s (16 doubles) to 10 JSON clients, recorded in both encodings.
    Each recorded row gets the recording's final status (messages, drops, bytes): drops > 0 means the
    writer fell behind and the queue overflowed. Each row also splits the gateway's CPU by thread: the
    recorder's threads (named rr-record*, server/record/recording.cpp) and the rest (the live path)."""
    rows = []
    work = tempfile.mkdtemp(prefix="rr-bench-record-")
    seconds = "3" if args.quick else "5"
    workloads = [
        ("camera", [exe["rr_bench_service"], "--frame-hz", "30", "--frame-bytes", str(640 * 480 * 3)],
         ["--member", "Frames", "--binary", "--hz", "30"], {"members": ["Frames"], "encoding": "robotraconteur"},
         {"frame_bytes": 640 * 480 * 3, "hz": 30.0}),
        ("wire", [exe["rr_bench_service"], "--tick-hz", "1000", "--tick-size", "16"],
         ["--member", "Ticks", "--hz", "1000"], {"members": ["Ticks"]}, {"hz": 1000.0}),
    ]
    try:
        for name, dev_argv, load_args, spec, fields in workloads:
            dev = Proc(dev_argv, "bench_service (%s)" % name)
            procs.append(dev)
            for r in range(args.record_rounds):
                for recording in ((False, True) if r % 2 == 0 else (True, False)):
                    log("record, round %d/%d: %s to 10 JSON clients, %s" % (r + 1, args.record_rounds, name,
                                                                       "with a recording" if recording else "no recording"))
                    gw = gateway_proc(exe, dev.ready["url"], unlimited=True)
                    procs.append(gw)
                    port = gw.ready["port"]
                    rec = None
                    if recording:
                        rec = post_json(port, "/api/recordings", dict(spec, device="bench", directory=work))
                    label = {"workload": name, "round": r + 1, "recording": recording, "server": "gateway",
                             "path": "device->gateway->10 x JSON" + (" + recording" if recording else "")}
                    label.update(fields)
                    got = sampled(gw.p.pid, [exe["rr_bench_ws_load"], "--port", str(port), "--clients", "10", "fanout",
                                             "--seconds", seconds] + load_args, label, thread_prefix="rr-record")
                    if rec:
                        final = post_json(port, "/api/recordings/%d/stop" % rec["id"], {})
                        for row in got:
                            row["recording_status"] = {k: final.get(k) for k in ("state", "messages", "drops", "bytes",
                                                                                 "duration_s", "error")}
                        for f in final.get("files", []):
                            try:
                                os.remove(f)
                            except OSError:
                                pass
                    rows += got
                    gw.stop()
                    procs.remove(gw)
            dev.stop()
            procs.remove(dev)
    finally:
        subprocess.run(["rm", "-rf", work])
    return rows


def browser_section(exe, args, rounds, procs):
    """Nop and a property read through the gateway over rr+ws, one call after the other: our native
    client, the wasm client in node, the wasm client in Chromium, with the TCP floor; R rounds, interleaved.
    Each row also gets the gateway's CPU µs per call (its /proc, connection set-up and warm-up included)."""
    raw = []
    dev = Proc([exe["rr_bench_service"]], "bench_service")
    procs.append(dev)
    gw = gateway_proc(exe, dev.ready["url"])
    procs.append(gw)
    port = gw.ready["port"]
    count = str(args.browser_count)
    wasm = ["node", os.path.join(HERE, "wasm_bench.mjs"), "--port", str(port), "--count", count, "--runtimes"]
    plan = [("floor", [exe["rr_bench_floor"], "--count", count]),
            ("native", [exe["rr_bench_client"], "--url", "rr+ws://127.0.0.1:%d/?service=bench" % port, "--label",
                        "ours->gateway->ours rr+ws", "--count", count, "--ops", "nop,get"]),
            ("wasm in node", wasm + ["node"]),
            ("wasm in chromium", wasm + ["chromium"])]
    skipped = set()
    for r in range(rounds):
        for name, argv in plan:
            if name in skipped:
                continue
            log("browser row, round %d/%d: %s" % (r + 1, rounds, name))
            before = proc_sample(gw.p.pid)[0]
            out = subprocess.run(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=600)
            gw_cpu_us = (proc_sample(gw.p.pid)[0] - before) * 1e6
            if out.returncode == 77:
                log("skipped: " + out.stderr.strip())
                skipped.add(name)
                continue
            if out.returncode != 0:
                log("FAILED (%d): %s\n%s" % (out.returncode, " ".join(argv), out.stderr[-2000:]))
            rows = [json.loads(l) for l in out.stdout.splitlines() if l.startswith("{")]
            calls = sum(x.get("n", 0) for x in rows)
            for row in rows:
                row["round"] = r
                if name != "floor" and calls:
                    row["gateway_cpu_us_per_op"] = gw_cpu_us / calls
            raw += [x for x in rows if name != "floor" or x["op"] == "tcp_64"]
    gw.stop()
    dev.stop()
    procs.remove(gw)
    procs.remove(dev)
    return raw


# The pairs section's figures: (key, what, how it is made from one block's rows, unit).
NOP, ASYNC, GET = ("ours", "nop"), ("ours", "nop_async"), ("ours", "get")
CIO_NOP, CIO_GET, OFF_GET, FLOOR = ("caller-io", "nop"), ("caller-io", "get"), ("official", "get"), ("floor", "tcp_64")
PAIR_FIGURES = [
    ("blocking_vs_async_p50", "Nop p50, blocking / async (same process, back to back)",
     lambda b: ratio(b, NOP + ("p50_us",), ASYNC + ("p50_us",)), "×"),
    ("blocking_vs_async_cpu", "client CPU per Nop, blocking / async",
     lambda b: ratio(b, NOP + ("client_cpu_us_per_op",), ASYNC + ("client_cpu_us_per_op",)), "×"),
    ("blocking_vcsw", "context switches per blocking Nop", lambda b: field(b, NOP + ("client_vcsw_per_op",)), ""),
    ("async_vcsw", "context switches per async Nop", lambda b: field(b, ASYNC + ("client_vcsw_per_op",)), ""),
    ("caller_io_vs_async_p50", "Nop p50, blocking with caller_runs_io / async",
     lambda b: ratio(b, CIO_NOP + ("p50_us",), ASYNC + ("p50_us",)), "×"),
    ("caller_io_vs_async_cpu", "client CPU per Nop, caller_runs_io / async",
     lambda b: ratio(b, CIO_NOP + ("client_cpu_us_per_op",), ASYNC + ("client_cpu_us_per_op",)), "×"),
    ("caller_io_vcsw", "context switches per blocking Nop with caller_runs_io",
     lambda b: field(b, CIO_NOP + ("client_vcsw_per_op",)), ""),
    ("get_vs_official", "property get, official client's p50 / ours (blocking)",
     lambda b: ratio(b, OFF_GET + ("p50_us",), GET + ("p50_us",)), "×"),
    ("get_caller_io_vs_official", "property get, official client's p50 / ours (caller_runs_io)",
     lambda b: ratio(b, OFF_GET + ("p50_us",), CIO_GET + ("p50_us",)), "×"),
    ("gateway_hop_async", "gateway hop, async Nop (through − direct) / TCP floor",
     lambda b: hop(b, "nop_async"), "× floor"),
    ("gateway_hop_blocking", "gateway hop, blocking Nop (through − direct) / TCP floor",
     lambda b: hop(b, "nop"), "× floor"),
]


def field(block, key):
    name, op, k = key
    row = block.get((name, op))
    return row.get(k) if row else None


def ratio(block, a, b):
    x, y = field(block, a), field(block, b)
    return x / y if x is not None and y else None


def hop(block, op):
    through, direct, floor = field(block, ("gateway", op, "p50_us")), field(block, ("ours", op, "p50_us")), \
        field(block, ("floor", "tcp_64", "p50_us"))
    return (through - direct) / floor if None not in (through, direct) and floor else None


def pairs_section(exe, args, procs):
    """Issue 14's ratios from many short blocks, each pair measured within one block. A block runs, back to
    back: the TCP floor; our client's blocking Nop, async Nop and blocking get in one process; the same
    blocking calls with caller_runs_io; the same client through the gateway; the official client's Nop and
    get on the official service. Blocks alternate their order (forward, then backward); each figure is
    taken within each block, then the median over blocks is reported with every block's value.

    Every process of this section runs on one vCPU (`--pairs-cpu`, default 0; empty: anywhere). On these
    VMs a wake-up of a thread on the other vCPU costs ~40 µs of CPU (an inter-processor interrupt under
    the hypervisor), and the scheduler moves peers between "same vCPU" and "other vCPU" every few tenths of
    a second: unpinned, a row's p50 flips between ~12 and ~55 µs for reasons that have nothing to do with
    the code, and two rows run one after the other can land in different modes (docs/benchmarks.md)."""
    pin = ["taskset", "-c", args.pairs_cpu] if args.pairs_cpu else []
    ours = Proc(pin + [exe["rr_bench_service"]], "bench_service")
    procs.append(ours)
    official = Proc(pin + [PY, os.path.join(HERE, "py", "official_service.py")], "official_service")
    procs.append(official)
    gw = gateway_proc(exe, ours.ready["url"], prefix=pin)
    procs.append(gw)
    gw_url = "rr+tcp://127.0.0.1:%d/?service=bench" % gw.ready["port"]
    time.sleep(1.0)
    n = str(args.pair_count)
    client = lambda url, label, ops, *extra: pin + [exe["rr_bench_client"], "--url", url, "--label", label, "--count", n,
                                                    "--ops", ops, *extra]
    plan = [("floor", pin + [exe["rr_bench_floor"], "--count", n]),
            ("ours", client(ours.ready["url"], "ours->ours rr+tcp", "nop,nop_async,get")),
            ("caller-io", client(ours.ready["url"], "ours->ours rr+tcp caller-io", "nop,get", "--caller-io", "1")),
            ("gateway", client(gw_url, "ours->gateway->ours rr+tcp", "nop,nop_async")),
            ("official", pin + [PY, os.path.join(HERE, "py", "official_client.py"), "--url", official.ready["url"], "--label",
                          "official->official rr+tcp", "--count", n, "--ops", "nop,get"])]
    blocks = []
    for i in range(args.pair_blocks):
        log("pairs: block %d/%d" % (i + 1, args.pair_blocks))
        block = {}
        for name, argv in (plan if i % 2 == 0 else list(reversed(plan))):
            for row in run_rows(argv):
                block[(name, row["op"])] = row
        blocks.append(block)
    for p in (gw, official, ours):
        p.stop()
        procs.remove(p)
    out = []
    for key, what, make, unit in PAIR_FIGURES:
        values = [make(b) for b in blocks]
        values = [v for v in values if v is not None]
        if values:
            out.append({"figure": key, "what": what, "unit": unit, "median": statistics.median(values),
                        "min": min(values), "max": max(values), "blocks": [round(v, 2) for v in values]})
    raw = [dict(row, block=i, name=name) for i, b in enumerate(blocks) for (name, _), row in b.items()]
    return {"figures": out, "raw": raw}



def summarize_browser(raw):
    """One row per (path, op): medians over rounds, the ratio to the native client's p50 and to the TCP
    floor of the same round (every round listed)."""
    if not raw:
        return []
    by_round = {}
    for row in raw:
        by_round.setdefault(row["round"], {})[(row["label"], row["op"])] = row
    groups = {}
    for row in raw:
        groups.setdefault((row["label"], row["op"]), []).append(row)
    out = []
    for (label, op), rows in groups.items():
        e = median_rows(rows)
        e["gateway_cpu_us_per_op"] = statistics.median([x["gateway_cpu_us_per_op"] for x in rows if "gateway_cpu_us_per_op" in x] or [0])
        x_native, x_floor = [], []
        for row in rows:
            same = by_round[row["round"]]
            native = same.get(("ours->gateway->ours rr+ws", op))
            floor = same.get(("floor", "tcp_64"))
            if native and native.get("p50_us") and label != native["label"]:
                x_native.append(row["p50_us"] / native["p50_us"])
            if floor and floor.get("p50_us") and label != "floor":
                x_floor.append(row["p50_us"] / floor["p50_us"])
        if x_native:
            e["x_native_rounds"] = [round(x, 2) for x in x_native]
            e["x_native"] = statistics.median(x_native)
        if x_floor:
            e["x_tcp_floor_rounds"] = [round(x, 2) for x in x_floor]
            e["x_tcp_floor"] = statistics.median(x_floor)
        out.append(e)
    rank = {"floor": 0, "ours->gateway->ours rr+ws": 1, "wasm(node)->gateway->ours rr+ws": 2, "wasm(chromium)->gateway->ours rr+ws": 3}
    out.sort(key=lambda e: (OP_ORDER.index(e["op"]) if e["op"] in OP_ORDER else 99, rank.get(e["label"], 9)))
    return out



def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", required=True, help="build folder holding bench/ and server/app/ binaries")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--count", type=int, default=5000, help="Nop calls per row and round")
    ap.add_argument("--quick", action="store_true", help="small counts, one round, fan-out to 10 and 100 only")
    ap.add_argument("--no-busy", action="store_true", help="do not start the two nice-19 busy loops")
    ap.add_argument("--skip-fanout", action="store_true")
    ap.add_argument("--skip-scale", action="store_true")
    ap.add_argument("--fanout-clients", help="client counts of the fan-out rows, comma-separated (default 10,100,1000; "
                    "--quick: 10,100); each count gets a JSON and a Foxglove row")
    ap.add_argument("--skip-calls", action="store_true", help="only fan-out and scale")
    ap.add_argument("--rr-fanout", action="store_true", help="also: N native RR clients on a wire through the gateway (rr+ws)")
    ap.add_argument("--rr-fanout-threads", type=int, default=1, help="IO threads of rr_bench_rr_fanout (default 1)")
    ap.add_argument("--camera", action="store_true", help="also: 640x480 RGB at 30 Hz to N JSON clients (binary pushes)")
    ap.add_argument("--browser", action="store_true", help="also: the wasm client in node and Chromium, with the native client")
    ap.add_argument("--record", action="store_true", help="also: the camera row and a 1,000 values/s wire with and without a recording")
    ap.add_argument("--record-rounds", type=int, default=2, help="rounds of the record section (default 2)")
    ap.add_argument("--rate", action="store_true", help="also: 1,000 JSON clients without a rate, at max_rate_hz 100 and 10; "
                    "100 clients without and with permessage-deflate (issue 56)")
    ap.add_argument("--rate-rounds", type=int, default=2, help="rounds of the rate section (default 2)")
    ap.add_argument("--uring-build", default="build/uring",
                    help="the uring section's second build (cmake -DRR_IO_URING=ON; its rr-gateway is used)")
    ap.add_argument("--uring-rounds", type=int, default=2, help="rounds of the uring section (default 2)")
    ap.add_argument("--uring-clients", type=int, default=1000, help="JSON clients of the uring section (default 1000)")
    ap.add_argument("--ab-gateway", default="build/base/server/app/rr-gateway",
                    help="the ab section's other gateway (an rr-gateway built from the base commit)")
    ap.add_argument("--ab-names", default="this build,base", help="the ab section's two names, comma-separated")
    ap.add_argument("--ab-rounds", type=int, default=4, help="rounds of the ab section (default 4)")
    ap.add_argument("--ab-clients", type=int, default=1000, help="JSON clients of the ab section (default 1000)")
    ap.add_argument("--gather-rounds", type=int, default=4, help="rounds of the gather section (default 4)")
    ap.add_argument("--gather-clients", type=int, default=1000, help="JSON clients of the gather section (default 1000)")
    ap.add_argument("--scale10k-clients", type=int, default=10000, help="connections of the scale10k section (default 10000)")
    ap.add_argument("--scale10k-seconds", type=int, default=10, help="measuring window of its 1 Hz row (default 10)")
    ap.add_argument("--browser-count", type=int, default=2000, help="calls per op and round in the browser row")
    ap.add_argument("--pairs", action="store_true", help="also: issue 14's ratios from short interleaved blocks")
    ap.add_argument("--pair-blocks", type=int, default=24, help="blocks of the pairs section (default 24)")
    ap.add_argument("--pair-count", type=int, default=500, help="calls per op and block in the pairs section")
    ap.add_argument("--pairs-cpu", default="0", help="the vCPU every process of the pairs section runs on ('' = any)")
    ap.add_argument("--only", help="run only these sections (comma-separated): " + ",".join(SECTIONS) +
                    "; results go to latest-SECTIONS.json/.md")
    ap.add_argument("--out", default=os.path.join(HERE, "results"))
    ap.add_argument("--update-doc", action="store_true",
                    help="also replace the latest figures in docs/benchmarks.md (between its latest:begin/end markers)")
    args = ap.parse_args(argv)
    if args.quick:
        args.rounds, args.count = 1, 500
        args.browser_count = min(args.browser_count, 1000)
    stem = "latest"
    if args.only:
        only = [x.strip() for x in args.only.split(",") if x.strip()]
        bad = [x for x in only if x not in SECTIONS]
        if bad:
            ap.error("--only: unknown section(s) %s (sections: %s)" % (", ".join(bad), ", ".join(SECTIONS)))
        args.skip_calls, args.skip_fanout, args.skip_scale = "calls" not in only, "fanout" not in only, "scale" not in only
        args.rr_fanout, args.camera, args.browser = "rr-fanout" in only, "camera" in only, "browser" in only
        args.pairs = "pairs" in only
        args.record = "record" in only
        args.rate = "rate" in only
        args.uring = "uring" in only
        args.ab = "ab" in only
        args.gather = "gather" in only
        args.scale10k = "scale10k" in only
        stem = "latest-" + "-".join(only)  # a partial run does not replace the suite's latest.*
    browser_rounds = args.rounds

    b = os.path.abspath(args.build)
    exe = {n: os.path.join(b, "bench", n) for n in ("rr_bench_service", "rr_bench_client", "rr_bench_floor", "rr_bench_ws_load",
                                                    "rr_bench_rr_fanout")}
    exe["rr-gateway"] = os.path.join(b, "server", "app", "rr-gateway")
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    try:
        # 10,000 sockets in one process, and the fan-out floor's 2 x 10,000: above a 20,000 hard limit
        # when the bench may raise it (root, CAP_SYS_RESOURCE); children inherit it.
        resource.setrlimit(resource.RLIMIT_NOFILE, (max(hard, 65536), max(hard, 65536)))
    except (ValueError, OSError):
        resource.setrlimit(resource.RLIMIT_NOFILE, (hard, hard))
    fd_limit = resource.getrlimit(resource.RLIMIT_NOFILE)[0]

    started = time.time()
    result = {"started": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
              "machine": machine_info(), "load_average_start": list(os.getloadavg()),
              "busy_loops": not args.no_busy, "rounds": args.rounds, "count": args.count, "pair_count": args.pair_count,
              "pairs_cpu": args.pairs_cpu}
    busy = [] if args.no_busy else start_busy_loops()
    if busy:
        log("two nice-19 busy loops run for the duration (busy latency regime, ../shared/BENCHMARKING.md)")
    procs = []
    try:
        raw = []
        if args.skip_calls:
            args.rounds = 0
        else:  # the call rows' services and gateway
            ours = Proc([exe["rr_bench_service"], "--websocket", "--local"], "bench_service")
            procs.append(ours)
            official = Proc([PY, os.path.join(HERE, "py", "official_service.py"), "--websocket", "--local"], "official_service")
            procs.append(official)
            gw = Proc([exe["rr-gateway"], "--no-demo", "--no-local", "--port", "0", "--log-level", "warning",
                       "--device", "bench=" + ours.ready["url"]], "rr-gateway")
            procs.append(gw)
            gw_url = "rr+tcp://127.0.0.1:%d/?service=bench" % gw.ready["port"]
            time.sleep(1.0)  # the gateway connects to its device

            ops = ",".join(CALL_OPS)
            ours_ops = ",".join(["nop", "nop_async"] + CALL_OPS[1:])
            cpp = lambda url, label, o=ours_ops: run_rows([exe["rr_bench_client"], "--url", url, "--label", label,
                                                            "--count", str(args.count), "--ops", o])
            pyc = lambda url, label, o=ops: run_rows([PY, os.path.join(HERE, "py", "official_client.py"), "--url", url,
                                                       "--label", label, "--count", str(args.count), "--ops", o])
            plan = [
                ("floor", lambda: run_rows([exe["rr_bench_floor"], "--count", str(args.count)])),
                ("ours->ours rr+tcp", lambda: cpp(ours.ready["url"], "ours->ours rr+tcp")),
                # the blocking calls again, the caller running the connection's I/O (no worker thread)
                ("ours->ours rr+tcp caller-io", lambda: run_rows([exe["rr_bench_client"], "--url", ours.ready["url"], "--label",
                                                                  "ours->ours rr+tcp caller-io", "--count", str(args.count),
                                                                  "--ops", "nop,echo10,get", "--caller-io", "1"])),
                ("official->official rr+tcp", lambda: pyc(official.ready["url"], "official->official rr+tcp")),
                ("ours->ours rr+ws", lambda: cpp(ours.ready["ws_url"], "ours->ours rr+ws")),
                ("official->official rr+ws", lambda: pyc(official.ready["ws_url"], "official->official rr+ws")),
                ("ours->ours rr+local", lambda: cpp(ours.ready["local_url"], "ours->ours rr+local")),
                ("official->official rr+local", lambda: pyc(official.ready["local_url"], "official->official rr+local")),
                ("official->ours rr+tcp", lambda: pyc(ours.ready["url"], "official->ours rr+tcp")),
                ("ours->official rr+tcp", lambda: cpp(official.ready["url"], "ours->official rr+tcp", ops)),
                ("ours->gateway->ours rr+tcp", lambda: cpp(gw_url, "ours->gateway->ours rr+tcp")),
                ("official->gateway->ours rr+tcp", lambda: pyc(gw_url, "official->gateway->ours rr+tcp")),
            ]
            usb = os.path.join(b, "bench", "rr_bench_usb")
            if os.path.exists(usb):  # rr+usb against the umockdev-emulated device, and in-process rr+tcp (bench_usb.cpp)
                plan.append(("ours->ours rr+usb", lambda: run_rows([usb, "--count", str(max(args.count // 5, 100))])))
            for r in range(args.rounds):
                for name, fn in plan:
                    log("round %d/%d: %s" % (r + 1, args.rounds, name))
                    rows = fn()
                    for row in rows:
                        row["round"] = r
                    raw += rows
            # Streaming members: once per pair (their figures are rates, less sensitive to drift).
            stream = ",".join(STREAM_OPS)
            for name, fn in [
                    ("ours->ours rr+tcp", lambda: cpp(ours.ready["url"], "ours->ours rr+tcp", stream)),
                    ("official->official rr+tcp", lambda: pyc(official.ready["url"], "official->official rr+tcp", stream)),
                    ("ours->ours rr+ws", lambda: cpp(ours.ready["ws_url"], "ours->ours rr+ws", stream))]:
                log("streams: " + name)
                raw += fn()
            for p in reversed(procs):
                p.stop()
            procs = []

        fanout, scale = [], []
        if not args.skip_fanout or not args.skip_scale:
            dev = Proc([exe["rr_bench_service"], "--tick-hz", "100"], "bench_service (100 Hz)")
            procs.append(dev)
            gw = gateway_proc(exe, dev.ready["url"], unlimited=True)
            procs.append(gw)
            gpid = gw.p.pid
            if not args.skip_scale:
                # a fresh gateway: its RSS is not yet inflated by the fan-out's traffic (the allocator keeps it)
                sg = gateway_proc(exe, dev.ready["url"], "rr-gateway (scale)", unlimited=True)
                procs.append(sg)
                for n in ([1000] if args.quick else [1000, 10000]):
                    log("scale: %d idle WebSocket connections" % n)
                    time.sleep(1.0)
                    base = proc_sample(sg.p.pid)[1]
                    lg = subprocess.Popen([exe["rr_bench_ws_load"], "--port", str(sg.ready["port"]), "--clients", str(n),
                                           "idle"], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
                    row = json.loads(lg.stdout.readline())
                    time.sleep(1.0)
                    loaded = proc_sample(sg.p.pid)[1]
                    lg.stdin.write("\n")
                    lg.stdin.flush()
                    lg.wait(60)
                    row.update({"gateway_rss_base_kib": base, "gateway_rss_kib": loaded,
                                "rss_per_connection_kib": (loaded - base) / row["opened"] if row["opened"] else None})
                    scale.append(row)
                sg.stop()
                procs.remove(sg)
            if not args.skip_fanout:
                counts = [int(x) for x in args.fanout_clients.split(",")] if args.fanout_clients else (
                    [10, 100] if args.quick else [10, 100, 1000])
                for n in counts:
                    log("fan-out: %d WebSocket clients" % n)
                    sampler = Sampler(gpid)
                    sampler.start()
                    t0 = time.time()
                    rows = run_rows([exe["rr_bench_ws_load"], "--port", str(gw.ready["port"]), "--clients", str(n),
                                     "fanout", "--seconds", "3" if args.quick else "5", "--hz", "100"])
                    t1 = time.time()
                    sampler.stop_flag.set()
                    sampler.join()
                    for row in rows:
                        # the measuring window is the last `seconds` of the run
                        w = sampler.window(t1 - row["seconds"], t1)
                        if w:
                            row["gateway_cpu_pct"], row["gateway_rss_kib"] = w["cpu_pct"], w["rss_kib_max"]
                        row["wall_s"] = t1 - t0
                        # The floor of the same moment: the same N x 100 Hz messages of the same size written
                        # to N plain loopback TCP sockets by one thread, no protocol (rr_bench_floor --fanout).
                        floor = run_rows([exe["rr_bench_floor"], "--fanout", str(n), "--seconds", "3" if args.quick else "5",
                                          "--hz", "100", "--bytes", str(max(16, int(round(row.get("bytes_per_value") or 128))))])
                        if floor:
                            row["floor"] = floor[0]
                        row["protocol"] = "JSON"
                        fanout.append(row)
                    # The same values to N Foxglove WebSocket clients (docs/foxglove.md), beside the JSON row.
                    log("fan-out: %d Foxglove WebSocket clients" % n)
                    sampler = Sampler(gpid)
                    sampler.start()
                    t0 = time.time()
                    rows = run_rows([exe["rr_bench_ws_load"], "--port", str(gw.ready["port"]), "--clients", str(n),
                                     "fanout", "--foxglove", "--seconds", "3" if args.quick else "5", "--hz", "100"])
                    t1 = time.time()
                    sampler.stop_flag.set()
                    sampler.join()
                    for row in rows:
                        w = sampler.window(t1 - row["seconds"], t1)
                        if w:
                            row["gateway_cpu_pct"], row["gateway_rss_kib"] = w["cpu_pct"], w["rss_kib_max"]
                        row["wall_s"] = t1 - t0
                        row["protocol"] = "Foxglove"
                        fanout.append(row)
        for p in reversed(procs):
            p.stop()
        procs = []

        rr_fanout = rr_fanout_section(exe, args, procs) if args.rr_fanout else []
        camera = camera_section(exe, args, procs) if args.camera else []
        browser = browser_section(exe, args, browser_rounds, procs) if args.browser else []
        pairs = pairs_section(exe, args, procs) if args.pairs else {}
        record = record_section(exe, args, procs) if args.record else []
        rate = rate_section(exe, args, procs) if args.rate else []
        uring = uring_section(exe, args, procs) if getattr(args, "uring", False) else []
        ab = ab_section(exe, args, procs) if getattr(args, "ab", False) else []
        gather = gather_section(exe, args, procs) if getattr(args, "gather", False) else []
        scale10k = scale10k_section(exe, args, procs) if getattr(args, "scale10k", False) else []
    finally:
        for p in reversed(procs):
            p.stop()
        for p in busy:
            p.kill()
            p.wait()

    result.update(summarize(raw, fanout, scale))
    result.update({"record": record, "rate": rate, "uring": uring, "ab": ab, "gather": gather, "scale10k": scale10k,
                   "fd_limit": fd_limit})
    result.update({"rr_fanout": rr_fanout, "camera": camera, "browser": summarize_browser(browser), "browser_raw": browser,
                   "pairs": pairs.get("figures", []), "pairs_raw": pairs.get("raw", [])})
    result["load_average_end"] = list(os.getloadavg())
    result["duration_s"] = round(time.time() - started, 1)
    result["raw"] = raw
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, stem + ".json"), "w") as f:
        json.dump(result, f, indent=1)
    md = markdown(result)
    with open(os.path.join(args.out, stem + ".md"), "w") as f:
        f.write(md)
    print(md)
    if args.update_doc and stem != "latest":
        log("--update-doc ignored: --only ran part of the suite")
    elif args.update_doc:
        update_doc(os.path.join(ROOT, "docs", "benchmarks.md"), md)
    log("wrote %s/%s.json and %s.md in %.0f s" % (args.out, stem, stem, result["duration_s"]))
    return 0


LATENCY_OPS = ("nop", "nop_async", "echo10", "echo1000", "echo100000", "get", "set", "peek", "wire")
OP_ORDER = ["tcp_64", "unix_64", "tcp_bulk", "nop", "nop_async", "echo10", "echo1000", "echo100000", "get", "set",
            "peek", "wire", "wire_rate", "pipe", "memory_read", "memory_write"]
PATH_ORDER = ["floor", "ours->ours rr+tcp", "ours->ours rr+tcp caller-io", "ours->ours rr+ws", "ours->ours rr+local", "official->official rr+tcp",
              "official->official rr+ws", "official->official rr+local", "official->ours rr+tcp",
              "ours->official rr+tcp", "ours->gateway->ours rr+tcp", "official->gateway->ours rr+tcp",
              "ours->ours rr+usb", "ours->ours rr+tcp in-process"]


def order(path, op):
    return (OP_ORDER.index(op) if op in OP_ORDER else 99, PATH_ORDER.index(path) if path in PATH_ORDER else 99)


def summarize(raw, fanout, scale):
    """One row per (path, op) with its references and ratios; the gateway hops; the cost growth."""
    groups = {}
    for row in raw:
        groups.setdefault((row["label"], row["op"]), []).append(row)
    rows = {k: median_rows(v) for k, v in groups.items()}
    floor = rows.get(("floor", "tcp_64"), {}).get("p50_us")
    bulk = rows.get(("floor", "tcp_bulk"), {}).get("mb_s")
    refs = {"tcp_floor_p50_us": floor, "tcp_bulk_mb_s": bulk,
            "unix_floor_p50_us": rows.get(("floor", "unix_64"), {}).get("p50_us")}
    table = []
    for (label, op), row in sorted(rows.items(), key=lambda kv: order(*kv[0])):
        e = {"path": label, "op": op, **{k: v for k, v in row.items() if k not in ("label", "op", "round")}}
        if label != "floor" and op in LATENCY_OPS and floor and row.get("p50_us"):
            e["x_tcp_floor"] = row["p50_us"] / floor  # target: rr+tcp Nop <= 1.5
            if label.endswith("rr+local") and refs["unix_floor_p50_us"]:
                e["x_unix_floor"] = row["p50_us"] / refs["unix_floor_p50_us"]
        if bulk and row.get("mb_s") and (op == "echo100000" or op.startswith("memory")):
            e["pct_tcp_bulk"] = 100 * row["mb_s"] / bulk  # target: >= 50 %
        if label.startswith("ours->") and "gateway" not in label and "official" not in label:
            # the official library over the same transport (rr+ws streams run only on rr+tcp for it)
            off = rows.get(("official->official " + label.split()[-1], op)) or rows.get(("official->official rr+tcp", op))
            if off:
                e["official_path"] = off["label"]
                if op in ("pipe", "wire_rate") or "p50_us" not in off:
                    if off.get("ops_per_s") and row.get("ops_per_s"):
                        e["official_ops_per_s"] = off["ops_per_s"]
                        e["speedup_vs_official"] = row["ops_per_s"] / off["ops_per_s"]
                elif off.get("p50_us") and row.get("p50_us"):
                    e["official_p50_us"] = off["p50_us"]
                    e["speedup_vs_official"] = off["p50_us"] / row["p50_us"]
        table.append(e)

    hops = []
    for (label, op), row in sorted(rows.items(), key=lambda kv: order(*kv[0])):
        if "gateway" not in label:
            continue
        direct = rows.get((label.replace("gateway->", ""), op))
        if direct and row.get("p50_us") and direct.get("p50_us"):
            hop = row["p50_us"] - direct["p50_us"]
            hops.append({"path": label, "op": op, "direct_p50_us": direct["p50_us"], "gateway_p50_us": row["p50_us"],
                         "hop_us": hop, "hop_x_tcp_floor": hop / floor if floor else None})  # target: <= 1

    growth = []
    for label in PATH_ORDER:
        pts = sorted((8 * int(op[4:]), rows[(l, op)]["p50_us"]) for (l, op) in rows if l == label and op.startswith("echo"))
        fit = fit_slope(pts)
        if fit:
            growth.append({"path": label, "points": pts, **fit})
    f64, fbulk = rows.get(("floor", "tcp_64")), rows.get(("floor", "tcp_bulk"))
    if f64 and fbulk:
        fit = fit_slope([(64, f64["p50_us"]), (800000, fbulk["p50_us"])])
        if fit:
            growth.append({"path": "floor (TCP ping-pong 64 B and 800,000 B)", "points": [(64, f64["p50_us"]), (800000, fbulk["p50_us"])], **fit})
    return {"references": refs, "rows": table, "gateway_hops": hops, "cost_growth": growth, "fanout": fanout, "scale": scale}


def update_doc(path, md):
    begin, end = "<!-- latest:begin -->", "<!-- latest:end -->"
    with open(path) as f:
        text = f.read()
    a, b = text.find(begin), text.find(end)
    if a < 0 or b < a:
        log("%s has no %s ... %s markers; not updated" % (path, begin, end))
        return
    with open(path, "w") as f:
        f.write(text[:a + len(begin)] + "\n" + md + text[b:])
    log("updated " + path)


def fmt(v, nd=1):
    if v is None or v == "":
        return ""
    if isinstance(v, float):
        if abs(v) >= 999.5:
            return "{:,.0f}".format(v)
        return ("{:.%df}" % nd).format(v)
    return "{:,}".format(v) if isinstance(v, int) else str(v)


def markdown(res):
    m, refs = res["machine"], res["references"]
    out = ["Run %s on %s (%s vCPUs, Linux %s), commit %s. Load average %s at start, %s at end; %s. "
           "%d round(s): each figure is the median of the rounds' medians (p50, p99, rates) or the largest max." % (
               res["started"], m.get("cpu_model", "?"), m.get("cpus"), m["uname"].split()[2], m.get("git_commit", "?"),
               "/".join("%.2f" % x for x in res["load_average_start"]),
               "/".join("%.2f" % x for x in res["load_average_end"]),
               "two nice-19 busy loops ran throughout (busy latency regime)" if res["busy_loops"] else "no busy loops",
               res["rounds"])]
    if res["rows"]:
        out += ["",
               "References measured in this run: TCP floor p50 **%s µs** (64 B ping-pong, TCP_NODELAY), Unix socket floor "
               "p50 %s µs, TCP bulk round trip (800,000 B each way) **%s MB/s**." % (
                   fmt(refs.get("tcp_floor_p50_us"), 2), fmt(refs.get("unix_floor_p50_us"), 2), fmt(refs.get("tcp_bulk_mb_s"))), "",
               "| op | path | p50 µs | p99 µs | max µs | ops/s | MB/s | client CPU µs / op | client vcsw / op | × TCP floor (× Unix floor for rr+local) | % TCP bulk | official p50 µs (ops/s), same transport* | speed-up vs official |",
               "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for e in res["rows"]:
        off = fmt(e.get("official_p50_us")) if "official_p50_us" in e else (
            "(%s)" % fmt(e["official_ops_per_s"], 0) if "official_ops_per_s" in e else "")
        if off and e.get("official_path", "").split()[-1] != e["path"].split()[-1]:
            off += "*"
        out.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            e["op"], e["path"], fmt(e.get("p50_us")), fmt(e.get("p99_us")), fmt(e.get("max_us")), fmt(e.get("ops_per_s"), 0),
            fmt(e.get("mb_s")), fmt(e.get("client_cpu_us_per_op")), fmt(e.get("client_vcsw_per_op"), 2),
            fmt(e.get("x_tcp_floor"), 2) + (" (%s)" % fmt(e["x_unix_floor"], 2) if "x_unix_floor" in e else ""),
            fmt(e.get("pct_tcp_bulk")), off,
            (fmt(e["speedup_vs_official"], 2) + "×") if "speedup_vs_official" in e else ""))
    if res["rows"]:
        out += ["", "\\* the official library over rr+tcp (it ran the streaming rows on rr+tcp only)."]
    if res["gateway_hops"]:
        out += ["", "The gateway hop (client → gateway → device minus client → device, p50):", "",
                "| path | op | direct µs | through gateway µs | hop µs | hop × TCP floor |", "|---|---|---|---|---|---|"]
        for h in res["gateway_hops"]:
            out.append("| %s | %s | %s | %s | %s | %s |" % (h["path"], h["op"], fmt(h["direct_p50_us"]), fmt(h["gateway_p50_us"]),
                                                         fmt(h["hop_us"]), fmt(h["hop_x_tcp_floor"], 2)))
    if res["cost_growth"]:
        out += ["", "Cost growth: least-squares fit of Echo p50 against the array bytes each way (10, 1,000, 100,000 doubles):", "",
                "| path | ns per byte | intercept µs |", "|---|---|---|"]
        for g in res["cost_growth"]:
            out.append("| %s | %.3f | %s |" % (g["path"], g["ns_per_byte"], fmt(g["intercept_us"])))
    if res["fanout"]:
        out += ["", "Fan-out: one device wire at 100 Hz → gateway → N JSON WebSocket clients (rr-gateway.json.v1), and "
                "N Foxglove WebSocket clients (foxglove.websocket.v1, docs/foxglove.md; no floor row of their own); "
                "latency from the device's stamp to the client's arrival. Floor: right after each row, one thread writes "
                "the same N × 100 messages/s of the same size to N plain loopback TCP sockets and another reads them "
                "(`rr_bench_floor --fanout`, no protocol): its writer's CPU is what the kernel alone charges a sender "
                "for this traffic:", "",
                "| clients | protocol | delivered/s | expected/s | delivered of sent | p50 µs | p99 µs | max µs | gateway CPU % | gateway CPU µs / value | gateway RSS MiB | load generator CPU % | floor: writer CPU % | floor: writer CPU µs / value | floor: p99 µs |",
                "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for f in res["fanout"]:
            fl = f.get("floor") or {}
            per_value = (10000 * f["gateway_cpu_pct"] / f["delivered_per_s"]) if f.get("gateway_cpu_pct") and f.get("delivered_per_s") else None
            out.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                fmt(f["clients"]), f.get("protocol", "JSON"), fmt(f["delivered_per_s"], 0), fmt(f["expected_per_s"], 0),
                "%.1f %%" % (100 * f.get("delivered_of_sent", 0)), fmt(f["p50_us"]), fmt(f["p99_us"]),
                fmt(f["max_us"]), fmt(f.get("gateway_cpu_pct")), fmt(per_value), fmt(f.get("gateway_rss_kib", 0) / 1024),
                fmt(f["loadgen_cpu_pct"]), fmt(fl.get("writer_cpu_pct")), fmt(fl.get("writer_cpu_us_per_value")),
                fmt(fl.get("p99_us"))))
    if res["scale"]:
        out += ["", "Scale: idle JSON WebSocket connections held open on the gateway (target < 50 KiB each):", "",
                "| connections | opened | gateway RSS before MiB | with them MiB | KiB per connection |", "|---|---|---|---|---|"]
        for s in res["scale"]:
            out.append("| %s | %s | %s | %s | %s |" % (fmt(s["clients"]), fmt(s["opened"]), fmt(s["gateway_rss_base_kib"] / 1024),
                                                     fmt(s["gateway_rss_kib"] / 1024), fmt(s["rss_per_connection_kib"])))
    if res.get("rr_fanout"):
        out += ["", "Raw RR fan-out: the device's `Ticks` wire at 100 Hz to N native clients (`rr_bench_rr_fanout`, one process, "
                "%s IO thread(s)) over rr+ws, through the gateway and directly on the device; latency from the device's stamp "
                "to the client's handler; server = the gateway, or the device for the direct rows:" % res["rr_fanout"][0].get("threads", 1), "",
                "| clients | path | opened | delivered/s | expected/s | delivered of sent | per client /s min, median | p50 µs | p99 µs | max µs "
                "| server CPU % | server CPU µs / value | server vcsw / value | server RSS MiB | load generator CPU % | load gen CPU µs / value |",
                "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for f in res["rr_fanout"]:
            out.append("| %s | %s | %s | %s | %s | %s | %s, %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                fmt(f["clients"]), f["path"], fmt(f["opened"]), fmt(f["delivered_per_s"], 0), fmt(f["expected_per_s"], 0),
                "%.1f %%" % (100 * f.get("delivered_of_sent", 0)), fmt(f["per_client_per_s_min"], 0), fmt(f["per_client_per_s_median"], 0),
                fmt(f["p50_us"]), fmt(f["p99_us"]), fmt(f["max_us"]), fmt(f.get("server_cpu_pct")), fmt(f.get("server_cpu_us_per_value")),
                fmt(f.get("server_vcsw_per_value"), 2), fmt(f.get("server_rss_kib", 0) / 1024), fmt(f["loadgen_cpu_pct"]),
                fmt(f.get("loadgen_cpu_us_per_value"))))
    if res.get("camera"):
        out += ["", "Camera stream: 640×480 RGB frames (921,600 bytes) at 30 Hz on the device's `Frames` wire → gateway → N JSON "
                "WebSocket clients subscribed with `\"binary\": true` (`rr_bench_ws_load --member Frames --binary`, one thread); "
                "latency from the device's stamp to the whole frame's arrival:", "",
                "| clients | frames/s per client min, median | sent/s | delivered of sent | MB/s delivered | p50 ms | p99 ms | max ms "
                "| gateway CPU % | gateway CPU µs / frame | gateway RSS MiB (max, 1 s after) | load generator CPU % |",
                "|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for f in res["camera"]:
            slow = f.get("slow") or {}
            out.append("| %s | %s, %s | %s | %s | %s | %s | %s | %s | %s | %s | %s, %s | %s |" % (
                fmt(f["clients"]) + (" (%d of them slow)" % slow["clients"] if slow else ""), fmt(f["per_client_per_s_min"]), fmt(f["per_client_per_s_median"]), fmt(f.get("hz")),
                "%.1f %%" % (100 * f.get("delivered_of_sent", 0)), fmt(f["delivered_per_s"] * f["bytes_per_value"] / 1e6, 0),
                fmt(f["p50_us"] / 1000), fmt(f["p99_us"] / 1000), fmt(f["max_us"] / 1000), fmt(f.get("server_cpu_pct")),
                fmt(f.get("server_cpu_us_per_value")), fmt(f.get("server_rss_kib", 0) / 1024),
                fmt(f.get("server_rss_after_kib", 0) / 1024), fmt(f["loadgen_cpu_pct"])))
        slows = [f for f in res["camera"] if f.get("slow")]
        if slows:
            out += ["", "The slow consumers of that table (each waits `read_delay_ms` before every read); the row above gives "
                    "the other clients' figures:", "",
                    "| clients | slow | read delay ms | frames/s per slow client (median) | delivered of sent | p50 ms | p99 ms | max ms |",
                    "|---|---|---|---|---|---|---|---|"]
            for f in slows:
                w = f["slow"]
                out.append("| %s | %s | %s | %s | %.1f %% | %s | %s | %s |" % (
                    fmt(f["clients"]), fmt(w["clients"]), fmt(w["read_delay_ms"]), fmt(w["per_client_per_s_median"]),
                    100 * w["delivered_of_sent"], fmt(w["p50_us"] / 1000), fmt(w["p99_us"] / 1000), fmt(w["max_us"] / 1000)))
    if res.get("rate"):
        out += ["", "Client-chosen rate and compression (issue 56): the device's `Ticks` wire at 100 Hz → gateway → N JSON "
                "WebSocket clients (`rr_bench_ws_load`, one thread), a fresh gateway per row:", "",
                "| round | clients | max_rate_hz | deflate (negotiated) | delivered/s | expected/s | p50 ms | p99 ms | gateway CPU % "
                "| gateway CPU µs / value | bytes / value | load generator CPU % |",
                "|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for f in res["rate"]:
            out.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                f.get("round"), fmt(f["clients"]), fmt(f.get("max_rate_hz")) if f.get("max_rate_hz") else "none",
                "%s (%s)" % ("on" if f.get("deflate") else "off", fmt(f.get("deflated_clients", 0))),
                fmt(f["delivered_per_s"], 0), fmt(f["expected_per_s"], 0), fmt(f["p50_us"] / 1000), fmt(f["p99_us"] / 1000),
                fmt(f.get("server_cpu_pct")), fmt(f.get("server_cpu_us_per_value")), fmt(f.get("bytes_per_value")),
                fmt(f["loadgen_cpu_pct"])))
    def pair_table(rows):
        t = ["| round | backend | clients | delivered/s | expected/s | delivered of sent | p50 ms | p99 ms | gateway CPU % "
             "| gateway CPU µs / value | load generator CPU % |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
        for f in rows:
            if f.get("backend", "").startswith("floor"):
                sent = f.get("sent") or 0
                t.append("| %s | %s | %s | %s | | %s | %s | %s | %s (writer) | %s (writer) | |" % (
                    f.get("round"), f["backend"], fmt(f.get("clients")), fmt(f.get("delivered_per_s"), 0),
                    "%.1f %%" % (100.0 * f.get("delivered", 0) / sent) if sent else "", fmt(f.get("p50_us", 0) / 1000),
                    fmt(f.get("p99_us", 0) / 1000), fmt(f.get("writer_cpu_pct")), fmt(f.get("writer_cpu_us_per_value"))))
                if "p99_tick_us" in f:  # the same messages' latency from their tick, as the gateway's rows count it
                    t.append("| %s | floor, latency from the tick | | | | | %s | %s | | | |" % (
                        f.get("round"), fmt(f["p50_tick_us"] / 1000), fmt(f["p99_tick_us"] / 1000)))
                continue
            t.append("| %s | %s | %s | %s | %s | %.1f %% | %s | %s | %s | %s | %s |" % (
                f.get("round"), f["backend"], fmt(f["clients"]), fmt(f["delivered_per_s"], 0), fmt(f["expected_per_s"], 0),
                100 * f.get("delivered_of_sent", 0), fmt(f["p50_us"] / 1000), fmt(f["p99_us"] / 1000),
                fmt(f.get("server_cpu_pct")), fmt(f.get("server_cpu_us_per_value")), fmt(f["loadgen_cpu_pct"])))
        return t

    if res.get("uring"):
        out += ["", "The io_uring lever (issue 56): the device's `Ticks` wire at 100 Hz → gateway → N JSON WebSocket clients, "
                "the gateway built on epoll (this build) and on io_uring (`-DRR_IO_URING=ON`), alternating, a fresh gateway "
                "per row; the floor is `rr_bench_floor --fanout` (plain TCP writes) once per round, its latency from each write and from the tick (one stamp per tick before its first write, as the gateway's rows count from the device's one stamp per value):", ""] + pair_table(res["uring"])
    if res.get("ab"):
        out += ["", "Two gateways alternating (`--only ab`): the device's `Ticks` wire at 100 Hz → gateway → N JSON WebSocket "
                "clients, this build's gateway and `--ab-gateway`, a fresh gateway per row; the floor is `rr_bench_floor "
                "--fanout` (plain TCP writes) once per round, its latency from each write and from the tick (one stamp per tick before its first write, as the gateway's rows count from the device's one stamp per value):", ""] + pair_table(res["ab"])
    if res.get("gather"):
        out += ["", "Gathered writes (issue 56, `--only gather`): the device's `Ticks` wire at 100 Hz → gateway → N JSON "
                "WebSocket clients, the same gateway with `gateway.websocket_gathered_writes` true and false, alternating, a "
                "fresh gateway per row; the floor is `rr_bench_floor --fanout` (plain TCP writes) once per round, its latency from each write and from the tick (one stamp per tick before its first write, as the gateway's rows count from the device's one stamp per value):", ""] + \
            pair_table(res["gather"])
    if res.get("scale10k"):
        out += ["", "10,000 connections (issue 56, `--only scale10k`; file-descriptor limit %s): idle JSON WebSockets on a "
                "fresh gateway, then as many subscribed to a 1 Hz wire on another, then the plain-TCP floor of that traffic:"
                % fmt(res.get("fd_limit")), "",
                "| row | connections | delivered/s | expected/s | delivered of sent | p50 ms | p99 ms | gateway CPU % "
                "| gateway CPU µs / value | gateway RSS before MiB | with them MiB | KiB per connection |",
                "|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for f in res["scale10k"]:
            mode = f.get("mode")
            if mode == "idle":
                out.append("| idle | %s | | | | | | %s | | %s | %s | %s |" % (
                    fmt(f.get("opened")), fmt(f.get("idle_cpu_pct")), fmt(f["gateway_rss_base_kib"] / 1024),
                    fmt(f["gateway_rss_kib"] / 1024), fmt(f.get("rss_per_connection_kib"))))
            elif mode == "1 Hz":
                out.append("| 1 Hz | %s | %s | %s | %.1f %% | %s | %s | %s | %s | %s | %s | %s |" % (
                    fmt(f.get("opened", f.get("clients"))), fmt(f["delivered_per_s"], 0), fmt(f["expected_per_s"], 0),
                    100 * f.get("delivered_of_sent", 0), fmt(f["p50_us"] / 1000), fmt(f["p99_us"] / 1000),
                    fmt(f.get("server_cpu_pct")), fmt(f.get("server_cpu_us_per_value")),
                    fmt(f.get("gateway_rss_base_kib", 0) / 1024), fmt(f.get("server_rss_kib", 0) / 1024),
                    fmt(f.get("rss_per_connection_kib"))))
            else:
                sent = f.get("sent") or 0
                out.append("| %s | %s | %s | | %s | %s | %s | %s (writer) | %s (writer) | | | |" % (
                    mode, fmt(f.get("clients")), fmt(f.get("delivered_per_s"), 0),
                    "%.1f %%" % (100.0 * f.get("delivered", 0) / sent) if sent else "", fmt(f.get("p50_us", 0) / 1000),
                    fmt(f.get("p99_us", 0) / 1000), fmt(f.get("writer_cpu_pct")), fmt(f.get("writer_cpu_us_per_value"))))
    if res.get("record"):
        out += ["", "Recording while serving (issue 44): the camera row (640×480 RGB at 30 Hz, `robotraconteur` encoding) and a "
                "1,000 values/s wire (`Ticks`, 16 doubles, both encodings), each to 10 JSON clients, without and with a recording "
                "of the member in the gateway; the two rows of a pair ran one after the other in the same round:", "",
                "| workload | round | recording | values/s per client min, median | delivered of sent | p50 ms | p99 ms | max ms "
                "| gateway CPU % | gateway CPU µs / value | live path (other threads) µs / value | recorder threads µs / value "
                "| live path page faults / value | gateway RSS MiB (max) | recorded messages | drops | MB written |",
                "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for f in res["record"]:
            st = f.get("recording_status") or {}
            out.append("| %s | %s | %s | %s, %s | %.1f %% | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                f["workload"], f["round"], "yes" if f["recording"] else "no", fmt(f["per_client_per_s_min"]),
                fmt(f["per_client_per_s_median"]), 100 * f.get("delivered_of_sent", 0), fmt(f["p50_us"] / 1000, 2),
                fmt(f["p99_us"] / 1000, 2), fmt(f["max_us"] / 1000, 2), fmt(f.get("server_cpu_pct")),
                fmt(f.get("server_cpu_us_per_value")), fmt(f.get("other_threads_cpu_us_per_value")),
                fmt(f.get("named_threads_cpu_us_per_value"), 2), fmt(f.get("other_threads_minflt_per_value"), 1),
                fmt(f.get("server_rss_kib", 0) / 1024),
                fmt(st.get("messages"), 0) if st else "", fmt(st.get("drops"), 0) if st else "",
                fmt((st.get("bytes") or 0) / 1e6) if st else ""))
    if res.get("browser"):
        out += ["", "Browser row: one call after the other through the gateway over rr+ws, the native client, the wasm client "
                "in node (`ws` package) and in headless Chromium (`bench/wasm_bench.mjs`); × native and × TCP floor are per round "
                "(every round listed), then the median. Client CPU: the client's process (Chromium: all its processes); "
                "gateway CPU per call includes the connection and the warm-up:", "",
                "| op | path | n | p50 µs | p99 µs | max µs | calls/s | client CPU µs / call | client vcsw / call | gateway CPU µs / call "
                "| × native p50 | × TCP floor |",
                "|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for e in res["browser"]:
            rounds = lambda k: " (%s)" % ", ".join("%.2f" % x for x in e[k + "_rounds"]) if len(e.get(k + "_rounds", [])) > 1 else ""
            out.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                e["op"], e["label"], fmt(e.get("n")), fmt(e.get("p50_us")), fmt(e.get("p99_us")), fmt(e.get("max_us")),
                fmt(e.get("ops_per_s"), 0), fmt(e.get("client_cpu_us_per_op")), fmt(e.get("client_vcsw_per_op"), 2),
                fmt(e.get("gateway_cpu_us_per_op")) if e["label"] != "floor" else "",
                (fmt(e["x_native"], 2) + rounds("x_native")) if "x_native" in e else "",
                (fmt(e["x_tcp_floor"], 2) + rounds("x_tcp_floor")) if "x_tcp_floor" in e else ""))
    if res.get("pairs"):
        out += ["", "Pairs: issue 14's ratios, each taken within one short block (the TCP floor, our client's blocking and async "
                "Nop and blocking get in one process, the same blocking calls with caller_runs_io, the same client through the "
                "gateway, the official client's Nop and get; %d calls per op, blocks in alternating order; %s), then the median "
                "over blocks, with every block's value:" % (
                    res["pair_count"], "every process on vCPU %s" % res["pairs_cpu"] if res.get("pairs_cpu") else "unpinned"), "",
                "| figure | median | min – max | every block |", "|---|---|---|---|"]
        for f in res["pairs"]:
            out.append("| %s | **%s%s** | %s – %s | %s |" % (
                f["what"], fmt(f["median"], 2), f["unit"] and " " + f["unit"], fmt(f["min"], 2), fmt(f["max"], 2),
                ", ".join("%.2f" % x for x in f["blocks"])))
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    sys.exit(main())
