#!/usr/bin/env python3
"""The running rr-gateway process, from outside (issue 4):

  origin   a browser Origin that is not allowed gets 403 for HTTP requests and for WebSocket upgrades
           (RR subprotocol and JSON subprotocol); allowed and same-origin requests pass.
  config   a bad configuration file makes rr-gateway exit non-zero before listening, naming the file,
           the line and the key; so does an unknown flag; so does a second gateway whose NodeName
           another gateway on this computer serves over rr+local.
  metrics  /metrics (Prometheus text, parsed with prometheus_client) has every series that
           docs/deployment.md §Monitoring lists, with its type and label names, serves none it does not
           list (with --no-discovery and with discovery on, the default), and the counters follow the traffic of an official RR
           client.

Usage: process_test.py --gateway PATH --case origin|config|metrics [--doc docs/deployment.md]
Prints a JSON summary; exit status 0 only if every check passed.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

import websocket
from prometheus_client.parser import text_string_to_metric_families

import gwproc
import official_transport  # noqa: E402  (the official client's transport, its connect timeout)
from gwproc import expect

RR_SUBPROTOCOL = "robotraconteur.robotraconteur.com"
JSON_SUBPROTOCOL = "rr-gateway.json.v1"


def ws_status(port, origin, subprotocol):
    """HTTP status of a WebSocket upgrade: 101 when it is accepted."""
    try:
        ws = websocket.create_connection("ws://127.0.0.1:%d/" % port, origin=origin, subprotocols=[subprotocol],
                                         timeout=30)
    except websocket.WebSocketBadStatusException as e:
        return e.status_code
    ws.close()
    return 101


def case_origin(checks, exe):
    gw = gwproc.start_gateway(exe, ["--no-demo", "--allow-origin", "https://lab.example.org"])
    port = gw.port
    url = "http://127.0.0.1:%d" % port
    try:
        def http():
            for path in ("/livez", "/api/devices", "/index.html"):
                status, body = gwproc.http_status(url + path, {"Origin": "https://evil.example.com"})
                expect(status == 403, "GET %s with a foreign Origin: %d, want 403" % (path, status))
                expect("Origin" in body, "403 body names the Origin: %r" % body)
            expect(gwproc.http_status(url + "/livez", {"Origin": "https://lab.example.org"})[0] == 200,
                   "allowed Origin gets 200")
            expect(gwproc.http_status(url + "/livez", {"Origin": "http://127.0.0.1:%d" % port})[0] == 200,
                   "same-origin request (Origin = http://Host) gets 200")
            expect(gwproc.http_status(url + "/livez")[0] == 200, "no Origin (not a browser) gets 200")
            # With an explicit allowlist, localhost is no longer implied.
            status = gwproc.http_status(url + "/livez", {"Origin": "http://localhost:9999"})[0]
            expect(status == 403, "http://localhost:9999 not in the allowlist: %d" % status)

        checks.run("HTTP: foreign Origin 403, allowed / same-origin / none 200", http)

        def upgrades():
            for sub in (RR_SUBPROTOCOL, JSON_SUBPROTOCOL):
                st = ws_status(port, "https://evil.example.com", sub)
                expect(st == 403, "WebSocket %s with a foreign Origin: %s, want 403" % (sub, st))
                st = ws_status(port, "https://lab.example.org", sub)
                expect(st == 101, "WebSocket %s with an allowed Origin: %s, want 101" % (sub, st))

        checks.run("WebSocket upgrade: foreign Origin 403, allowed 101 (RR and JSON subprotocols)", upgrades)
        checks.run("gateway still running", lambda: expect(gw.alive(), "gateway exited"))
    finally:
        status = gw.stop()
    checks.run("gateway exit status 0 on SIGTERM", lambda: expect(status == 0, "exit status %r" % status))


def run_config(exe, text, extra=()):
    with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
        f.write(text)
        path = f.name
    try:
        t0 = time.monotonic()
        r = subprocess.run([exe, "--config", path, "--port", "0", "--listen", "127.0.0.1", "--no-local"] + list(extra),
                           capture_output=True, text=True, timeout=90, env=gwproc.gateway_env())
        return r, path, time.monotonic() - t0
    finally:
        os.unlink(path)


def case_config(checks, exe):
    bad = [
        # (yaml, line, key, problem)
        ("gateway:\n  port: 8080\n  log_level: loud\n", 3, "gateway.log_level", "unknown level"),
        ("demo:\n  enabled: true\ndevices:\n  - name: arm\n    url: rr+tcp://10.0.0.20:48653/\n", 5,
         "devices.arm.url", "names no service"),
        ("gateway:\n  listen: 127.0.0.1\n  prot: 8080\n", 3, "gateway.prot", "unknown key"),
        ("devices:\n  - name: a\n    url: rr+tcp://x/?service=s\n  - name: a\n    url: rr+tcp://y/?service=s\n", 4,
         "devices.a", "duplicate device name"),
    ]
    for text, line, key, problem in bad:
        def one(text=text, line=line, key=key, problem=problem):
            r, path, took = run_config(exe, text)
            expect(r.returncode != 0, "exit status %d for a bad %s" % (r.returncode, key))
            want = "%s:%d: %s: %s" % (path, line, key, problem)
            expect(want in r.stderr, "stderr names file, line and key: want %r in %r" % (want, r.stderr))
            expect('"port"' not in r.stdout, "no ready line (nothing started): %r" % r.stdout)
            expect(took < 60, "exits without serving, within the 60 s bound on a start or an exit (%.1f s)" % took)

        checks.run("bad config: %s -> exit != 0 naming line %d" % (key, line), one)

    def unreadable():
        r = subprocess.run([exe, "--config", "/nonexistent/gw.yaml"], capture_output=True, text=True, timeout=30,
                           env=gwproc.gateway_env())
        expect(r.returncode != 0, "exit status %d" % r.returncode)
        expect("/nonexistent/gw.yaml" in r.stderr, "names the file: %r" % r.stderr)

    checks.run("unreadable config file -> exit != 0 naming it", unreadable)

    def bad_flag():
        r, _, _ = run_config(exe, "demo:\n  enabled: false\n", ["--robotraconteur-tcp-port=eighty"])
        expect(r.returncode != 0, "exit status %d" % r.returncode)
        expect("--robotraconteur-tcp-port" in r.stderr, "names the flag: %r" % r.stderr)

    checks.run("bad flag value -> exit != 0 naming the flag", bad_flag)

    def good():
        r, _, _ = run_config(exe, "demo:\n  enabled: false\n", ["--check"])
        expect(r.returncode == 0 and "configuration ok" in r.stdout, "a good file passes --check: %r" % (r,))

    checks.run("a good config passes --check", good)

    def node_name_taken():
        # rr+local on (the default) in a scratch tree of node directories: a second gateway with the
        # same NodeName exits at once, naming it and the way out; the first keeps serving.
        tree = tempfile.mkdtemp(prefix="rr_gw_taken_")
        env = gwproc.gateway_env()
        for var, sub in (("ROBOTRACONTEUR_SYSTEM_RUN_DIR", "sysrun"), ("ROBOTRACONTEUR_SYSTEM_STATE_DIR", "sysstate"),
                         ("ROBOTRACONTEUR_SYSTEM_CONFIG_DIR", "sysconfig"), ("ROBOTRACONTEUR_USER_RUN_DIR", "run"),
                         ("ROBOTRACONTEUR_USER_CONFIG_DIR", "config")):
            env[var] = os.path.join(tree, sub)
        name = "gw.taken.%d" % os.getpid()
        argv = [exe, "--listen", "127.0.0.1", "--port", "0", "--no-demo", "--robotraconteur-nodename=" + name]
        first = gwproc.Proc(argv, env=env)
        try:
            t0 = time.monotonic()
            r = subprocess.run(argv, capture_output=True, text=True, timeout=90, env=env)
            took = time.monotonic() - t0
            expect(r.returncode != 0, "second gateway: exit status %d" % r.returncode)
            expect(name in r.stderr and "--no-local" in r.stderr, "names the NodeName and --no-local: %r" % r.stderr)
            expect('"port"' not in r.stdout, "no ready line: %r" % r.stdout)
            expect(took < 60, "exits without serving, within the 60 s bound on a start or an exit (%.1f s)" % took)
            expect(first.alive() and gwproc.http_status("http://127.0.0.1:%d/livez" % first.port)[0] == 200,
                   "the first gateway still serves")
        finally:
            status = first.stop()
            shutil.rmtree(tree, ignore_errors=True)
        expect(status == 0, "the first gateway exits 0 on SIGTERM, got %s" % status)

    checks.run("a second gateway with a NodeName in use (rr+local) -> exit != 0 naming it", node_name_taken)


def documented_series(doc):
    """`| `name` | type | labels | meaning |` rows of the Monitoring table in docs/deployment.md, as
    (name, type) pairs; see documented_table for the label names."""
    return [(name, kind) for name, kind, _, _ in documented_table(doc)]


def documented_table(doc):
    """(name, type, label names, only_with_discovery) for each row of the Monitoring table. Label names:
    the first `name` of each comma-separated part of the labels column, parentheses (value lists) left
    out; a meaning starting with "with discovery on" marks series served only with discovery on."""
    rows = re.findall(r"^\|\s*`(rr_gateway_[a-z_]+)`\s*\|\s*(gauge|counter|histogram)\s*\|([^|]*)\|([^|]*)\|",
                      open(doc).read(), re.M)
    if len(rows) < 5:
        raise RuntimeError("%s lists %d series; expected the Monitoring table" % (doc, len(rows)))
    table = []
    for name, kind, labels, meaning in rows:
        labels = re.sub(r"\([^)]*\)", "", labels)
        names = set()
        for part in labels.split(","):
            m = re.search(r"`([a-z_]+)`", part)
            if m:
                names.add(m.group(1))
        table.append((name, kind, names, meaning.strip().startswith("with discovery on")))
    return table


def family_name(name):
    # prometheus_client names a counter family without its _total suffix.
    return name[:-len("_total")] if name.endswith("_total") else name


def check_against_table(fams, table, discovery):
    """Both directions: every documented series (of this mode) is served with its type and label names,
    and every served family is documented."""
    documented = {}
    for name, kind, labels, only_discovery in table:
        documented[family_name(name) if kind == "counter" else name] = name
        if only_discovery and not discovery:
            expect(family(fams, name) is None, "%s served without discovery" % name)
            continue
        fam = family(fams, name)
        expect(fam is not None, "series %s missing from /metrics" % name)
        expect(fam.type == kind, "%s has type %s, documented %s" % (name, fam.type, kind))
        served = set()
        for smp in fam.samples:
            if smp.name.endswith("_created"):
                continue
            served |= set(smp.labels)
        expect(served == labels, "%s has labels %s, documented %s" % (name, sorted(served), sorted(labels)))
    for n in fams:
        expect(n in documented, "/metrics serves %s, which docs/deployment.md does not document" % n)


def scrape(port):
    status, body = gwproc.http_status("http://127.0.0.1:%d/metrics" % port)
    expect(status == 200, "/metrics status %d" % status)
    families = {}
    for fam in text_string_to_metric_families(body):
        families[fam.name] = fam
    return families


def family(families, name):
    # prometheus_client names a counter family without its _total suffix.
    for n in (name, name[:-len("_total")] if name.endswith("_total") else None):
        if n and n in families:
            return families[n]
    return None


def samples(fam, name, **labels):
    return [s for s in fam.samples if s.name == name and all(s.labels.get(k) == v for k, v in labels.items())]


def case_metrics(checks, exe, doc):
    import RobotRaconteur as RR
    RRN = RR.RobotRaconteurNode.s
    # First without discovery (on by default): the series documented as "with discovery on" are absent.
    gw = gwproc.start_gateway(exe, ["--no-discovery"])
    port = gw.port
    try:
        gwproc.wait_ready(port)
        table = documented_table(doc)

        def present():
            fams = scrape(port)
            check_against_table(fams, table, discovery=False)
            up = family(fams, "rr_gateway_device_up")
            for dev in ("create", "webcam"):
                s = samples(up, "rr_gateway_device_up", device=dev)
                expect(len(s) == 1 and s[0].value == 1 and s[0].labels["state"] == "connected",
                       "device_up for %s: %r" % (dev, s))

        checks.run("every documented series, with its type", present)

        def traffic():
            before = scrape(port)
            req0 = samples(family(before, "rr_gateway_device_requests_total"), "rr_gateway_device_requests_total",
                           device="create")[0].value
            hist0 = samples(family(before, "rr_gateway_request_duration_seconds"),
                            "rr_gateway_request_duration_seconds_count", device="create")[0].value
            RRN.RegisterTransport(official_transport.client_tcp_transport(RR))
            c = RRN.ConnectService("rr+tcp://127.0.0.1:%d/?service=create" % port)
            for _ in range(5):
                c.DistanceTraveled
            mid = scrape(port)
            conns = samples(family(mid, "rr_gateway_connections"), "rr_gateway_connections")[0].value
            expect(conns >= 1, "rr_gateway_connections %r while a client is connected" % conns)
            RRN.DisconnectService(c)
            after = scrape(port)
            req1 = samples(family(after, "rr_gateway_device_requests_total"), "rr_gateway_device_requests_total",
                           device="create")[0].value
            hist = family(after, "rr_gateway_request_duration_seconds")
            hist1 = samples(hist, "rr_gateway_request_duration_seconds_count", device="create")[0].value
            expect(req1 - req0 >= 5, "requests_total{create} %r -> %r after 5 property reads" % (req0, req1))
            expect(hist1 - hist0 >= 5, "latency histogram count %r -> %r" % (hist0, hist1))
            buckets = samples(hist, "rr_gateway_request_duration_seconds_bucket", device="create")
            values = [b.value for b in buckets]
            expect(values == sorted(values) and buckets[-1].labels["le"] == "+Inf" and values[-1] == hist1,
                   "cumulative buckets ending at +Inf = count: %r" % values)
            for d in ("in", "out"):
                for name in ("rr_gateway_messages_total", "rr_gateway_bytes_total"):
                    v = samples(family(after, name), name, direction=d)[0].value
                    expect(v > 0, "%s{direction=%s} = %r" % (name, d, v))

        checks.run("counters follow an official client's requests", traffic)
    finally:
        try:
            RRN.Shutdown()
        finally:
            gw.stop()

    gw = gwproc.start_gateway(exe, [])
    try:
        gwproc.wait_ready(gw.port)

        def with_discovery():
            check_against_table(scrape(gw.port), documented_table(doc), discovery=True)

        checks.run("with discovery (the default): every documented series, type and labels; nothing undocumented",
                   with_discovery)
    finally:
        gw.stop()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--case", required=True, choices=["origin", "config", "metrics"])
    ap.add_argument("--doc", default="docs/deployment.md")
    a = ap.parse_args()
    checks = gwproc.Checks()
    if a.case == "origin":
        case_origin(checks, a.gateway)
    elif a.case == "config":
        case_config(checks, a.gateway)
    else:
        case_metrics(checks, a.gateway, a.doc)
    return checks.exit_code()


if __name__ == "__main__":
    sys.exit(main())
