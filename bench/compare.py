#!/usr/bin/env python3
"""Two builds of ours, interleaved in one run, with the ratio of each figure (issue 14: `--compare REV`).

bench/run.sh --compare REV builds REV next to the working tree's build and calls this script with both.
Every round runs the TCP floor once, then both builds' rows in alternating order (A B, then B A, ...), so
slow drift of the machine and the bimodal floor of these vCPUs hit both sides alike. A build's rows are
its own client against its own service (rr+tcp and rr+local) and through its own gateway (rr+tcp).

Figures per (path, op) and build: p50 latency (median of the rounds' p50s, every round printed), client
CPU µs per call (getrusage in the client) and service CPU µs per call (the service process's schedstat
around the client's run, connection setup included; for the gateway row, the gateway's). The ratio column is new / base:
below 1 the new build is faster or cheaper.

Usage: compare.py --base DIR --new DIR [--base-name REV] [--new-name NAME] [--rounds R] [--count N]
                  [--ops nop,nop_async,echo100000,get] [--no-busy] [--out FILE.json]
"""
import argparse
import json
import os
import statistics
import sys
import time

from run import Proc, log, run_rows, start_busy_loops

DEFAULT_OPS = "nop,nop_async,echo10,echo100000,get"
PATHS = ("rr+tcp", "rr+local", "gateway rr+tcp")


def cpu_ns(pid):
    """CPU time of every thread of `pid` in ns (schedstat: the tick-based /proc/PID/stat is too coarse for
    a few thousand calls of ~10 µs)."""
    total = 0
    for tid in os.listdir("/proc/%d/task" % pid):
        try:
            with open("/proc/%d/task/%s/schedstat" % (pid, tid)) as f:
                total += int(f.read().split()[0])
        except OSError:
            pass  # a thread that just ended
    return total


class Build:
    """One build's service and gateway, running for the whole comparison."""

    def __init__(self, name, folder):
        self.name = name
        self.client = os.path.join(folder, "bench", "rr_bench_client")
        self.floor = os.path.join(folder, "bench", "rr_bench_floor")
        service = os.path.join(folder, "bench", "rr_bench_service")
        gateway = os.path.join(folder, "server", "app", "rr-gateway")
        for exe in (self.client, service, gateway):
            if not os.access(exe, os.X_OK):
                raise SystemExit("%s: %s is missing (build the rr_bench and rr-gateway targets)" % (name, exe))
        self.procs = []
        self.service = Proc([service, "--local"], name + " bench_service")
        self.procs.append(self.service)
        self.gateway = Proc([gateway, "--no-demo", "--no-local", "--port", "0", "--log-level", "warning",
                             "--device", "bench=" + self.service.ready["url"]], name + " rr-gateway")
        self.procs.append(self.gateway)
        self.urls = {"rr+tcp": self.service.ready["url"], "rr+local": self.service.ready["local_url"],
                     "gateway rr+tcp": "rr+tcp://127.0.0.1:%d/?service=bench" % self.gateway.ready["port"]}

    def rows(self, path, ops, count):
        """The client's rows for `path`, each with the serving process's CPU per call added."""
        server = self.gateway if path.startswith("gateway") else self.service
        cpu0 = cpu_ns(server.p.pid)
        rows = run_rows([self.client, "--url", self.urls[path], "--label", path, "--count", str(count), "--ops", ops])
        cpu1 = cpu_ns(server.p.pid)
        calls = sum(r.get("n", 0) for r in rows)
        for r in rows:
            r["build"] = self.name
            r["path"] = path
            if calls and len(rows) == 1:
                r["server_cpu_us_per_op"] = (cpu1 - cpu0) / 1e3 / calls
        return rows

    def stop(self):
        for p in reversed(self.procs):
            p.stop()


def median(values):
    return statistics.median(values) if values else None


def ratio(new, base):
    return new / base if new is not None and base else None


def fmt(v, digits=1):
    return "" if v is None else ("%.*f" % (digits, v))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--base", required=True, help="build folder of the reference (REV)")
    ap.add_argument("--new", required=True, help="build folder of the working tree")
    ap.add_argument("--base-name", default="base")
    ap.add_argument("--new-name", default="new")
    ap.add_argument("--rounds", type=int, default=4)
    ap.add_argument("--count", type=int, default=3000)
    ap.add_argument("--ops", default=DEFAULT_OPS)
    ap.add_argument("--no-busy", action="store_true")
    ap.add_argument("--out", help="also write the raw rows and the summary as JSON here")
    args = ap.parse_args(argv)
    if args.rounds < 1 or args.count < 1:
        raise SystemExit("--rounds and --count must be positive")

    busy = [] if args.no_busy else start_busy_loops()
    builds = []
    raw, floors = [], []
    try:
        builds = [Build(args.base_name, os.path.abspath(args.base)), Build(args.new_name, os.path.abspath(args.new))]
        time.sleep(1.0)  # the gateways connect to their devices
        # Each op runs on its own (one client process per op): the service's CPU counter then belongs to it.
        ops = [o for o in args.ops.split(",") if o]
        for r in range(args.rounds):
            floor = run_rows([builds[0].floor, "--count", str(args.count)])
            tcp = [f for f in floor if f.get("op") == "tcp_64"]
            floors.append(tcp[0]["p50_us"] if tcp else None)
            order = builds if r % 2 == 0 else list(reversed(builds))
            for b in order:
                log("round %d/%d: %s" % (r + 1, args.rounds, b.name))
                for path in PATHS:
                    for op in ops:
                        for row in b.rows(path, op, args.count):
                            row["round"] = r
                            raw.append(row)
    finally:
        for b in builds:
            b.stop()
        for p in busy:
            p.kill()
            p.wait()

    summary = []
    for path in PATHS:
        for op in args.ops.split(","):
            entry = {"path": path, "op": op}
            for b in (args.base_name, args.new_name):
                rows = [x for x in raw if x["build"] == b and x["path"] == path and x.get("op") == op]
                entry[b] = {"p50_us": median([x["p50_us"] for x in rows if "p50_us" in x]),
                            "p50_us_rounds": [round(x.get("p50_us", 0), 1) for x in rows],
                            "client_cpu_us": median([x["client_cpu_us_per_op"] for x in rows if "client_cpu_us_per_op" in x]),
                            "server_cpu_us": median([x["server_cpu_us_per_op"] for x in rows if "server_cpu_us_per_op" in x])}
            if not entry[args.base_name]["p50_us_rounds"] and not entry[args.new_name]["p50_us_rounds"]:
                continue
            summary.append(entry)

    a, b = args.base_name, args.new_name
    lines = ["TCP floor p50 per round (µs): " + ", ".join(fmt(f) for f in floors), "",
             "| path | op | p50 µs %s | p50 µs %s | ratio | client CPU µs %s / %s | ratio | server CPU µs %s / %s | ratio | p50 per round %s ; %s |"
             % (a, b, a, b, a, b, a, b),
             "|---|---|---|---|---|---|---|---|---|---|"]
    for e in summary:
        ea, eb = e[a], e[b]
        lines.append("| %s | %s | %s | %s | %s | %s / %s | %s | %s / %s | %s | %s ; %s |" % (
            e["path"], e["op"], fmt(ea["p50_us"]), fmt(eb["p50_us"]), fmt(ratio(eb["p50_us"], ea["p50_us"]), 2),
            fmt(ea["client_cpu_us"]), fmt(eb["client_cpu_us"]), fmt(ratio(eb["client_cpu_us"], ea["client_cpu_us"]), 2),
            fmt(ea["server_cpu_us"]), fmt(eb["server_cpu_us"]), fmt(ratio(eb["server_cpu_us"], ea["server_cpu_us"]), 2),
            " ".join(str(v) for v in ea["p50_us_rounds"]), " ".join(str(v) for v in eb["p50_us_rounds"])))
    text = "\n".join(lines)
    print(text)
    if args.out:
        with open(args.out, "w") as f:
            json.dump({"base": a, "new": b, "floors_us": floors, "summary": summary, "raw": raw}, f, indent=1)
    missing = [e for e in summary if e[a]["p50_us"] is None or e[b]["p50_us"] is None]
    if missing:
        log("rows missing on one side: " + ", ".join("%s %s" % (e["path"], e["op"]) for e in missing))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
