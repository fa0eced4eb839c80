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

Usage: run.py --build DIR [--rounds R] [--count N] [--quick] [--no-busy] [--skip-fanout] [--skip-scale]
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
import threading
import time

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
    out = subprocess.run(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=timeout)
    if out.returncode != 0:
        log("FAILED (%d): %s\n%s" % (out.returncode, " ".join(argv), out.stderr[-2000:]))
    return [json.loads(l) for l in out.stdout.splitlines() if l.startswith("{")]


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


class Sampler(threading.Thread):
    """Samples a process's CPU and RSS every 0.2 s with wall-clock stamps."""

    def __init__(self, pid):
        super().__init__(daemon=True)
        self.pid, self.samples, self.stop_flag = pid, [], threading.Event()

    def run(self):
        while not self.stop_flag.is_set():
            try:
                self.samples.append((time.time(),) + proc_sample(self.pid))
            except OSError:
                return
            time.sleep(0.2)

    def window(self, t0, t1):
        s = [x for x in self.samples if t0 <= x[0] <= t1]
        if len(s) < 2:
            return None
        return {"cpu_pct": 100 * (s[-1][1] - s[0][1]) / (s[-1][0] - s[0][0]), "rss_kib_max": max(x[2] for x in s)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", required=True, help="build folder holding bench/ and server/app/ binaries")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--count", type=int, default=5000, help="Nop calls per row and round")
    ap.add_argument("--quick", action="store_true", help="small counts, one round, fan-out to 10 and 100 only")
    ap.add_argument("--no-busy", action="store_true", help="do not start the two nice-19 busy loops")
    ap.add_argument("--skip-fanout", action="store_true")
    ap.add_argument("--skip-scale", action="store_true")
    ap.add_argument("--skip-calls", action="store_true", help="only fan-out and scale")
    ap.add_argument("--out", default=os.path.join(HERE, "results"))
    ap.add_argument("--update-doc", action="store_true",
                    help="also replace the latest figures in docs/benchmarks.md (between its latest:begin/end markers)")
    args = ap.parse_args(argv)
    if args.quick:
        args.rounds, args.count = 1, 500

    b = os.path.abspath(args.build)
    exe = {n: os.path.join(b, "bench", n) for n in ("rr_bench_service", "rr_bench_client", "rr_bench_floor", "rr_bench_ws_load")}
    exe["rr-gateway"] = os.path.join(b, "server", "app", "rr-gateway")
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    resource.setrlimit(resource.RLIMIT_NOFILE, (hard, hard))  # children inherit it (10,000 sockets)

    started = time.time()
    result = {"started": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
              "machine": machine_info(), "load_average_start": list(os.getloadavg()),
              "busy_loops": not args.no_busy, "rounds": args.rounds, "count": args.count}
    busy = [] if args.no_busy else start_busy_loops()
    if busy:
        log("two nice-19 busy loops run for the duration (busy latency regime, ../shared/BENCHMARKING.md)")
    procs = []
    try:
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
        raw = []
        if args.skip_calls:
            plan, args.rounds = [], 0
        for r in range(args.rounds):
            for name, fn in plan:
                log("round %d/%d: %s" % (r + 1, args.rounds, name))
                rows = fn()
                for row in rows:
                    row["round"] = r
                raw += rows
        # Streaming members: once per pair (their figures are rates, less sensitive to drift).
        stream = ",".join(STREAM_OPS)
        for name, fn in [] if args.skip_calls else [
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
            gw = Proc([exe["rr-gateway"], "--no-demo", "--no-local", "--port", "0", "--log-level", "warning",
                       "--device", "bench=" + dev.ready["url"]], "rr-gateway")
            procs.append(gw)
            time.sleep(1.0)
            gpid = gw.p.pid
            if not args.skip_scale:
                # a fresh gateway: its RSS is not yet inflated by the fan-out's traffic (the allocator keeps it)
                sg = Proc([exe["rr-gateway"], "--no-demo", "--no-local", "--port", "0", "--log-level", "warning",
                           "--device", "bench=" + dev.ready["url"]], "rr-gateway (scale)")
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
                for n in ([10, 100] if args.quick else [10, 100, 1000]):
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
                        fanout.append(row)
    finally:
        for p in reversed(procs):
            p.stop()
        for p in busy:
            p.kill()
            p.wait()

    result.update(summarize(raw, fanout, scale))
    result["load_average_end"] = list(os.getloadavg())
    result["duration_s"] = round(time.time() - started, 1)
    result["raw"] = raw
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "latest.json"), "w") as f:
        json.dump(result, f, indent=1)
    md = markdown(result)
    with open(os.path.join(args.out, "latest.md"), "w") as f:
        f.write(md)
    print(md)
    if args.update_doc:
        update_doc(os.path.join(ROOT, "docs", "benchmarks.md"), md)
    log("wrote %s/latest.json and latest.md in %.0f s" % (args.out, result["duration_s"]))
    return 0


LATENCY_OPS = ("nop", "nop_async", "echo10", "echo1000", "echo100000", "get", "set", "peek", "wire")
OP_ORDER = ["tcp_64", "unix_64", "tcp_bulk", "nop", "nop_async", "echo10", "echo1000", "echo100000", "get", "set",
            "peek", "wire", "wire_rate", "pipe", "memory_read", "memory_write"]
PATH_ORDER = ["floor", "ours->ours rr+tcp", "ours->ours rr+ws", "ours->ours rr+local", "official->official rr+tcp",
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
               res["rounds"]), "",
           "References measured in this run: TCP floor p50 **%s µs** (64 B ping-pong, TCP_NODELAY), Unix socket floor "
           "p50 %s µs, TCP bulk round trip (800,000 B each way) **%s MB/s**." % (
               fmt(refs.get("tcp_floor_p50_us"), 2), fmt(refs.get("unix_floor_p50_us"), 2), fmt(refs.get("tcp_bulk_mb_s"))), "",
           "| op | path | p50 µs | p99 µs | max µs | ops/s | MB/s | × TCP floor (× Unix floor for rr+local) | % TCP bulk | official p50 µs (ops/s), same transport* | speed-up vs official |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    for e in res["rows"]:
        off = fmt(e.get("official_p50_us")) if "official_p50_us" in e else (
            "(%s)" % fmt(e["official_ops_per_s"], 0) if "official_ops_per_s" in e else "")
        if off and e.get("official_path", "").split()[-1] != e["path"].split()[-1]:
            off += "*"
        out.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            e["op"], e["path"], fmt(e.get("p50_us")), fmt(e.get("p99_us")), fmt(e.get("max_us")), fmt(e.get("ops_per_s"), 0),
            fmt(e.get("mb_s")), fmt(e.get("x_tcp_floor"), 2) + (" (%s)" % fmt(e["x_unix_floor"], 2) if "x_unix_floor" in e else ""),
            fmt(e.get("pct_tcp_bulk")), off,
            (fmt(e["speedup_vs_official"], 2) + "×") if "speedup_vs_official" in e else ""))
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
        out += ["", "Fan-out: one device wire at 100 Hz → gateway → N JSON WebSocket clients (rr-gateway.json.v1); "
                "latency from the device's stamp to the client's arrival:", "",
                "| clients | delivered/s | expected/s | delivered of sent | p50 µs | p99 µs | max µs | gateway CPU % | gateway RSS MiB | load generator CPU % |",
                "|---|---|---|---|---|---|---|---|---|---|"]
        for f in res["fanout"]:
            out.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                fmt(f["clients"]), fmt(f["delivered_per_s"], 0), fmt(f["expected_per_s"], 0),
                "%.1f %%" % (100 * f.get("delivered_of_sent", 0)), fmt(f["p50_us"]), fmt(f["p99_us"]),
                fmt(f["max_us"]), fmt(f.get("gateway_cpu_pct")), fmt(f.get("gateway_rss_kib", 0) / 1024),
                fmt(f["loadgen_cpu_pct"])))
    if res["scale"]:
        out += ["", "Scale: idle JSON WebSocket connections held open on the gateway (target < 50 KiB each):", "",
                "| connections | opened | gateway RSS before MiB | with them MiB | KiB per connection |", "|---|---|---|---|---|"]
        for s in res["scale"]:
            out.append("| %s | %s | %s | %s | %s |" % (fmt(s["clients"]), fmt(s["opened"]), fmt(s["gateway_rss_base_kib"] / 1024),
                                                     fmt(s["gateway_rss_kib"] / 1024), fmt(s["rss_per_connection_kib"])))
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    sys.exit(main())
