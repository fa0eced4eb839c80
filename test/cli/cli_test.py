#!/usr/bin/env python3
"""Drives the built `rr` command-line client (server/cli, docs/cli.md) against a live service and
asserts its output and exit status.

Targets:
  --target url       a running interop service at --url (e.g. through the gateway) experimental.interop_test
  --target ours      test/interop/rr_interop_service (--service PATH)   experimental.interop_test
  --target official  test/interop/official_service.py (this Python)    experimental.interop_test
  --target reynard   test/interop/reynard_harness.py (Reynard headless) experimental.reynard_the_robot

Exit status: 0 = every check passed, 1 = a check failed (each failure is printed), 77 = skipped.
"""

import argparse
import json
import os
import re
import signal
import socket
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
INTEROP = os.path.join(HERE, "..", "interop")

# Exit codes of rr (docs/cli.md).
OK, RR_ERROR, USAGE, CONNECT = 0, 1, 2, 3

failures = []
checks_run = [0]
NODE_NAME = None  # the service's NodeName when its ready line says it (legacy tcp:// URLs by name)
HANG_S = 120  # a bound on a hang of one rr run, never an expected time: single runs took over 60 s
#              (an ASan binary beside 8 CPU hogs on 2 vCPUs, flaky.sh --load 8)


def check(cond, what, detail=""):
    checks_run[0] += 1
    if not cond:
        failures.append(what)
        print(f"FAIL: {what}" + (f"\n      {detail}" if detail else ""), flush=True)
    return cond


class Rr:
    def __init__(self, exe, url):
        self.exe = exe
        self.url = url

    def run(self, *args, url=None, timeout=HANG_S):
        cmd = [self.exe, args[0], url or self.url, *args[1:]]
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        return p.returncode, p.stdout, p.stderr

    def ok(self, *args, **kw):
        rc, out, err = self.run(*args, **kw)
        check(rc == OK, f"rr {' '.join(args)} exits 0", f"rc={rc} stderr={err.strip()}")
        return out

    def json_lines(self, *args, **kw):
        out = self.ok(*args, **kw)
        try:
            return [json.loads(line) for line in out.splitlines()]
        except ValueError as e:
            check(False, f"rr {' '.join(args)} prints JSON lines", f"{e}: {out!r}")
            return []

    def fails(self, code, pattern, *args, **kw):
        rc, out, err = self.run(*args, **kw)
        check(rc == code and re.search(pattern, err) is not None,
              f"rr {' '.join(args)} exits {code} with /{pattern}/ on stderr", f"rc={rc} stderr={err.strip()!r}")
        check(out == "", f"rr {' '.join(args)} prints nothing on stdout", repr(out))

    def popen(self, *args):
        return subprocess.Popen([self.exe, args[0], self.url, *args[1:]], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)


def start(cmd, ready_key="url", timeout=60):
    """Starts a service that prints one JSON ready line; returns (process, ready dict)."""
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=sys.stderr, text=True)
    deadline = time.time() + timeout
    line = ""
    while time.time() < deadline:
        line = p.stdout.readline()
        if not line:
            break
        try:
            ready = json.loads(line)
            if ready_key in ready:
                return p, ready
        except ValueError:
            continue
    p.kill()
    raise RuntimeError(f"service not ready: {cmd} (last line {line!r})")


def stop(p):
    if p.poll() is None:
        p.send_signal(signal.SIGTERM)
        try:
            p.wait(15)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()


def closed_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def without_service(url):
    return re.sub(r"[?&]service=[^&]*", "", url)


def watch_while(rr, args, trigger, limit=90):
    """Runs `rr watch ...` and calls trigger() every 0.5 s until it exits (events and pipe packets
    only reach a client connected when they are sent); `limit` only bounds a hang (an ASan rr beside a CI
    run takes seconds to connect). Returns (rc, stdout lines, stderr)."""
    p = rr.popen("watch", *args)
    deadline = time.time() + limit
    while p.poll() is None and time.time() < deadline:
        time.sleep(0.5)
        trigger()
    if p.poll() is None:
        p.kill()
    out, err = p.communicate()
    return p.returncode, out.splitlines(), err


# --------------------------------------------------------------------------------------------------

def interop_checks(rr, service_url):
    rr.ok("call", "reset")

    # info: definitions and members
    out = rr.ok("info")
    check("== service definition: experimental.interop_test ==" in out, "info names the definition")
    check("service experimental.interop_test" in out, "info prints the definition text")
    check("== object interop: experimental.interop_test.Root ==" in out, "info names the root object", out[-400:])
    for pat in [r"(?m)^property\s+p_int64\s+int64$", r"(?m)^function\s+add\s+int32\(int32 a, int32 b\)$",
                r"(?m)^wire\s+w_state\s+Inner \[readonly\]$", r"(?m)^event\s+ev_values\s+\(int32 seq, string text, Inner data\)$",
                r"(?m)^objref\s+child_by_int\s+Child\{int32\}$", r"(?m)^memory\s+mem_md\s+int32\[\*\]$",
                r"(?m)^pipe\s+p_stream\s+double\[\] \[readonly\]$", r"(?m)^function\s+count_up\s+int32\{generator\}\(int32 start, int32 count\)$"]:
        check(re.search(pat, out), f"info lists /{pat}/")
    sub = rr.ok("info", "--object", "child")
    check(re.search(r"(?m)^== object interop\.child: experimental\.interop_test\.Child ==$", sub) and
          re.search(r"(?m)^function\s+describe\s+string\(\)$", sub), "info --object child lists Child's members", sub[-300:])

    # get / set round trips: the service accepts a set only when the value equals its A or B value,
    # so setting back what get printed proves the JSON went both ways without loss.
    for prop in ["p_int64", "p_uint64", "p_double", "p_single", "p_string", "p_enum", "p_cdouble", "a_int64",
                 "a_uint64", "a_double", "a_fixed", "a_bounded", "a_empty", "m_fixed", "m_3d", "s_inner",
                 "s_everything", "s_null", "pod_scalar", "pod_array", "pod_md", "na_array", "na_nested",
                 "map_int", "map_str", "map_struct", "list_struct", "list_empty", "v_any", "v_map", "v_list"]:
        first = rr.json_lines("get", prop)
        text = json.dumps(first[0]) if first else "null"
        rr.ok("set", prop, text)
        again = rr.json_lines("get", prop)
        check(first == again, f"get/set/get {prop} round-trips", f"{first} vs {again}")

    # int64 / uint64 exact, both values
    check(rr.json_lines("get", "p_int64") == ["-9223372036854775808"], "p_int64 A is exact")
    rr.ok("set", "p_int64", '"9223372036854775807"')
    check(rr.json_lines("get", "p_int64") == ["9223372036854775807"], "p_int64 B is exact after set")
    rr.ok("set", "a_int64", "[0]")
    check(rr.json_lines("get", "a_int64") == [[0]], "a_int64 B after set")
    rr.ok("set", "p_string", '""')
    check(rr.json_lines("get", "p_string") == [""], "p_string B (empty) after set")
    inner_b = rr.json_lines("get", "s_inner")
    check(inner_b and inner_b[0].get("id") is not None, "s_inner is a struct object", str(inner_b))

    # wrong types and values
    rr.fails(RR_ERROR, r"RobotRaconteur\.DataTypeMismatch", "set", "p_int32", '"x"')
    rr.fails(RR_ERROR, r"RobotRaconteur\.DataTypeError", "set", "a_fixed", "[1, 2]")
    rr.fails(RR_ERROR, r"RobotRaconteur\.OutOfRange", "set", "p_int8", "300")
    rr.fails(RR_ERROR, r"RobotRaconteur\.InvalidArgument", "set", "p_int32", "12345")  # neither A nor B
    rr.fails(RR_ERROR, r"RobotRaconteur\.ReadOnlyMember", "set", "ro_value", "1")
    rr.fails(USAGE, r"not valid JSON", "set", "p_int32", "{bad")
    rr.fails(USAGE, r"not valid JSON", "call", "add", "1", "[")
    rr.fails(RR_ERROR, r"RobotRaconteur\.MemberNotFound.*nosuch", "get", "nosuch")
    rr.fails(RR_ERROR, r"RobotRaconteur\.MemberNotFound", "call", "nosuch")
    rr.fails(RR_ERROR, r"RobotRaconteur\.InvalidOperation.*function", "get", "add")

    # functions
    check(rr.json_lines("call", "add", "2", "-7") == [-5], "call add 2 -7 prints -5")
    made = rr.json_lines("call", "make_inner", "4", '"four"', "[1.5, -2]")
    check(made == [{"id": 4, "label": "four", "values": [1.5, -2.0]}], "call make_inner with struct result", str(made))
    echo = rr.json_lines("call", "echo", '{"type": "int64[]", "value": ["-9223372036854775808", 1]}')
    check(echo == [{"type": "int64[]", "value": ["-9223372036854775808", 1]}], "call echo varvalue int64[]", str(echo))
    check(rr.ok("call", "reset") == "", "void call prints nothing")
    rr.fails(RR_ERROR, r"experimental\.interop_test\.InteropError.*boom", "call", "throw_user", '"boom"')
    rr.fails(RR_ERROR, r"RobotRaconteur\.InvalidArgument", "call", "throw_standard")
    rr.fails(RR_ERROR, r"RobotRaconteur\.InvalidArgument.*2 argument", "call", "add", "1")
    rr.fails(RR_ERROR, r"RobotRaconteur\.DataTypeMismatch.*argument 2", "call", "add", "1", '"two"')

    # generator
    check(rr.json_lines("call", "count_up", "5", "3") == [5, 6, 7], "generator count_up 5 3 prints 5 6 7")
    check(rr.ok("call", "count_up", "1", "0") == "", "empty generator prints nothing")
    log = rr.json_lines("call", "generator_log")
    check(log and "count_up:close" not in log[0] and "count_up:abort" not in log[0],
          "generator ran to its end (no close/abort logged)", str(log))

    # objrefs
    check(rr.json_lines("get", "child_by_int[7].value") == rr.json_lines("get", "--object", "child_by_int[7]", "value"),
          "dotted path and --object agree")
    check(rr.json_lines("call", "any_obj.scaled", "2")[0] == 2 * rr.json_lines("get", "any_obj.x")[0],
          "varobject objref function")
    check(rr.json_lines("get", "child_by_name[with space_and-dash].name") != [], "string-indexed objref")
    check(len(rr.json_lines("get", "child.leaf.x")) == 1, "nested objref child.leaf.x")
    rr.fails(RR_ERROR, r"RobotRaconteur\.ObjectNotFound", "get", "child_by_int[5].value")
    rr.fails(RR_ERROR, r"RobotRaconteur\.InvalidArgument.*int32 index", "get", "child_by_int[x].value")
    rr.fails(RR_ERROR, r"RobotRaconteur\.InvalidArgument.*not an objref", "get", "p_int32.x")

    # wires: get peeks, set pokes, watch streams
    state = rr.json_lines("get", "w_state")
    check(state and state[0].get("label") in ("tick", "demand"), "get w_state peeks the InValue", str(state))
    t0 = time.time()
    ticks = rr.json_lines("watch", "w_state", "--count", "3")
    check(len(ticks) == 3 and all(t.get("label") == "tick" for t in ticks), "watch w_state --count 3", str(ticks))
    check(len(ticks) == 3 and ticks[0]["id"] < ticks[1]["id"] < ticks[2]["id"], "wire values in order", str(ticks))
    check(time.time() - t0 < 20, "watch --count returns")
    t0 = time.time()
    some = rr.json_lines("watch", "w_state", "--seconds", "1")
    took = time.time() - t0
    check(1 <= len(some) <= 12 and took < 10, "watch --seconds 1 stops after about a second", f"{len(some)} in {took:.1f}s")
    rr.ok("set", "w_both", "[1, 2, 3]")
    rr.fails(RR_ERROR, r"RobotRaconteur\.WriteOnlyMember", "watch", "w_sink", "--count", "1")

    # memories: get reads the whole memory
    mem = rr.json_lines("get", "mem_double")
    check(len(mem) == 1 and isinstance(mem[0], list) and len(mem[0]) > 0, "get mem_double reads the array", str(mem)[:200])
    md = rr.json_lines("get", "mem_md")
    check(len(md) == 1 and isinstance(md[0], dict) and len(md[0].get("array", [])) == 
          (lambda d: d[0] * d[1] if len(d) == 2 else -1)(md[0].get("dims", [])), "get mem_md reads dims and array",
          str(md)[:200])

    # events (fired for every connected client; keep firing until the watch got its values)
    rc, lines, err = watch_while(rr, ["ev_values", "--count", "2"], lambda: rr.run("call", "fire_events", "3"))
    evs = [json.loads(x) for x in lines]
    check(rc == OK and len(evs) == 2 and evs[0].get("seq") == 0 and evs[1].get("seq") == 1 and
          set(evs[0]) == {"seq", "text", "data"}, "watch ev_values --count 2", f"rc={rc} {lines} {err}")
    rc, lines, err = watch_while(rr, ["ev_empty", "--count", "1"], lambda: rr.run("call", "fire_events", "1"))
    check(rc == OK and lines == ["{}"], "watch ev_empty prints {}", f"rc={rc} {lines} {err}")

    # pipes
    rc, lines, err = watch_while(rr, ["p_stream", "--count", "2"], lambda: rr.run("call", "send_stream", "2"))
    check(rc == OK and [json.loads(x) for x in lines] == [[0.0, 0.0], [1.0, 0.5]], "watch p_stream --count 2",
          f"rc={rc} {lines} {err}")

    # SIGINT ends a watch cleanly
    p = rr.popen("watch", "w_state")
    first = p.stdout.readline()  # connected and streaming
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=20)
    check(p.returncode == OK and first.startswith("{"), "watch ends with status 0 on SIGINT",
          f"rc={p.returncode} first={first!r} {err}")

    # a reader that goes away (rr watch ... | head -1) ends the watch
    p = rr.popen("watch", "w_state")
    first = p.stdout.readline()
    p.stdout.close()
    try:
        p.wait(timeout=15)
    except subprocess.TimeoutExpired:
        p.kill()
        p.wait()
    p.stderr.close()
    check(first.startswith("{") and p.returncode == OK, "watch ends when its output is closed", f"rc={p.returncode}")

    # connection-level failures
    rr.fails(CONNECT, r"RobotRaconteur\.ConnectionError", "get", "p_int32",
             url=f"rr+tcp://127.0.0.1:{closed_port()}/?service=interop")
    # One name for an unknown service, whatever the node sends (CORE: "...ServiceNotFoundException",
    # "Service not found"), and the service named (issue 15).
    rr.fails(CONNECT, r'^rr: RobotRaconteur\.ServiceNotFound: service "nosuch" not found\n$', "get", "p_int32",
             url=re.sub(r"service=[^&]*", "service=nosuch", service_url))
    t0 = time.time()
    rr.fails(CONNECT, r"RobotRaconteur\.\w+", "get", "p_int32", "--timeout", "1",
             url="rr+tcp://10.255.255.1:4/?service=interop")  # unroutable: refused or timed out
    check(time.time() - t0 < 10, "--timeout bounds the connect", f"{time.time() - t0:.1f} s")
    check(rr.json_lines("get", "p_int64", "--disable-message4") == ["-9223372036854775808"], "message format v2")
    rr.fails(USAGE, r"names no service", "get", "p_int32", url=without_service(service_url))
    rr.fails(USAGE, r"InvalidArgument", "get", "p_int32", url="bogus://x")
    rr.fails(USAGE, r"InvalidArgument: invalid connection URL .*has no '='", "get", "p_int32", url=service_url + "&junk")
    rr.fails(USAGE, r"legacy tcp:// URL needs /\{node\}/service", "get", "p_int32", url="tcp://127.0.0.1:1/node")
    rr.fails(RR_ERROR, r"InvalidOperation: ev_values is an event; rr get reads", "get", "ev_values")
    legacy_url_checks(rr, service_url)
    rr.ok("call", "reset")


def legacy_url_checks(rr, service_url):
    """The legacy form tcp://HOST:PORT/NODE/SERVICE (docs/cli.md) reaches the same service."""
    m = re.match(r"rr\+tcp://([^/?]+)/", service_url)
    if not m:
        return  # rr+ws: the legacy form is TCP only
    out = rr.ok("info", url=without_service(service_url))
    node = re.search(r"(?m)^== services of node ([0-9a-f-]{36}) ==$", out)
    if not check(node, "info prints the node's NodeID", out[:300]):
        return
    want = rr.json_lines("get", "p_int64")
    legacy_urls = ["tcp://%s/{%s}/interop" % (m.group(1), node.group(1))]
    if NODE_NAME:  # the form of issue 15: tcp://HOST:PORT/interop_service/interop
        legacy_urls.append("tcp://%s/%s/interop" % (m.group(1), NODE_NAME))
    for legacy in legacy_urls:
        check(rr.json_lines("get", "p_int64", url=legacy) == want, f"legacy URL {legacy} reads the same service")
    rr.fails(CONNECT, r'ServiceNotFound: service "nosuch" not found', "get", "p_int64",
             url="tcp://%s/{%s}/nosuch" % (m.group(1), node.group(1)))


class SilentPeer:
    """A TCP listener that accepts every connection and never sends a byte."""

    def __init__(self):
        import threading
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(16)
        self.port = self.sock.getsockname()[1]
        self.held = []
        self.stopped = False
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self):
        while not self.stopped:
            try:
                c, _ = self.sock.accept()
            except OSError:
                return
            self.held.append(c)

    def close(self):
        self.stopped = True
        self.sock.close()
        for c in self.held:
            c.close()


def timeout_checks(exe, timing=False):
    """--timeout S bounds the whole connect to a peer that accepts and never answers (was 7-10 s).

    Every run: status 3 with "timed out after S s", never before S s, and within a bound on a hang.
    `timing` (the test labelled timing, run in CI's calm phase): also ends within S + 3 s."""
    peer = SilentPeer()
    try:
        for scheme, seconds in [("rr+tcp", 1), ("rr+tcp", 3), ("rr+ws", 2), ("tcp", 1)]:
            url = (f"tcp://127.0.0.1:{peer.port}/node/interop" if scheme == "tcp"
                   else f"{scheme}://127.0.0.1:{peer.port}/?service=interop")
            # What the process's start and end cost right now (an ASan binary on a loaded machine: seconds)
            t0 = time.monotonic()
            subprocess.run([exe, "--help"], capture_output=True, text=True, timeout=HANG_S)
            overhead = time.monotonic() - t0
            t0 = time.monotonic()
            try:
                p = subprocess.run([exe, "get", url, "p_int32", "--timeout", str(seconds)], capture_output=True,
                                   text=True, timeout=HANG_S)
            except subprocess.TimeoutExpired:
                check(False, f"--timeout {seconds} ({scheme}) against a silent peer ends", f"still running after {HANG_S} s")
                continue
            took = time.monotonic() - t0
            check(p.returncode == CONNECT and f"timed out after {seconds} s" in p.stderr,
                  f"--timeout {seconds} against a silent {scheme} peer: status 3, 'timed out after {seconds} s'",
                  f"rc={p.returncode} stderr={p.stderr.strip()!r}")
            # Never early: the time measured here includes the process's start, so it is at least S.
            check(took >= seconds, f"--timeout {seconds} ({scheme}) does not end before {seconds} s", f"{took:.2f} s")
            if timing:
                # Slack for the process's start-up; it was 7-10 s before.
                check(took <= seconds + 3.0 + overhead, f"--timeout {seconds} ({scheme}) ends after about {seconds} s",
                      f"{took:.2f} s (the process's own start and end: {overhead:.2f} s)")
    finally:
        peer.close()


def usage_checks(exe):
    p = subprocess.run([exe, "--help"], capture_output=True, text=True)
    check(p.returncode == OK and "usage: rr COMMAND" in p.stdout, "rr --help")
    p = subprocess.run([exe, "watch", "--help"], capture_output=True, text=True)
    check(p.returncode == OK and "usage: rr watch" in p.stdout, "rr watch --help")
    p = subprocess.run([exe], capture_output=True, text=True)
    check(p.returncode == USAGE and "no command" in p.stderr, "rr without a command is a usage error")
    p = subprocess.run([exe, "get", "rr+tcp://127.0.0.1:1/?service=x"], capture_output=True, text=True)
    check(p.returncode == USAGE and "wrong number of arguments" in p.stderr, "missing member is a usage error")
    p = subprocess.run([exe, "get", "u", "m", "--frob"], capture_output=True, text=True)
    check(p.returncode == USAGE and "unknown option --frob" in p.stderr, "unknown option is a usage error")


def node_index_checks(rr, service_url, name, root_type):
    out = rr.ok("info", url=without_service(service_url))
    scheme = "local" if service_url.startswith("rr+local:") else "tcp"
    check(re.search(rf"(?m)^{re.escape(name)}  {re.escape(root_type)}  rr\+{scheme}://\S+service={re.escape(name)}$", out),
          f"info without service= lists {name} from the node's service index", out[:600])


def local_error_checks(exe, node_name):
    """rr+local errors: each a clear message and a non-zero exit, nothing hangs."""
    missing = f"rr+local:///?nodename=no.such.{node_name}&service=interop"
    p = subprocess.run([exe, "get", missing, "p_int32"], capture_output=True, text=True, timeout=HANG_S)
    check(p.returncode == CONNECT and "no local node named" in p.stderr, "rr+local: an unknown NodeName is a connect error",
          f"rc={p.returncode} stderr={p.stderr.strip()}")
    p = subprocess.run([exe, "get", "rr+local://somehost/?nodename=x&service=interop", "p_int32"], capture_output=True,
                       text=True, timeout=HANG_S)
    check(p.returncode != OK and "host must be empty" in p.stderr, "rr+local: a host other than localhost is refused",
          f"rc={p.returncode} stderr={p.stderr.strip()}")


def local_discover_checks(exe, node_name, root_type):
    """`rr discover` lists the running rr+local node (docs/cli.md): source local, its rr+local URL, and its
    services read over rr+local."""
    # --timeout is how long rr discover waits for the node's services (read over rr+local), not what the
    # test expects it to take: it returns after half of it once every node found has answered. 3 s was
    # short of the service read at a load of 40.
    p = subprocess.run([exe, "discover", "--json", "--timeout", "20", "--type", root_type], capture_output=True,
                       text=True, timeout=90)
    check(p.returncode == OK, "rr discover exits 0", f"rc={p.returncode} stderr={p.stderr.strip()}")
    nodes = []
    for line in p.stdout.splitlines():
        try:
            nodes.append(json.loads(line))
        except ValueError:
            check(False, "rr discover --json prints JSON lines", repr(line))
    node = next((n for n in nodes if n.get("nodename") == node_name), None)
    if not check(node is not None, "rr discover lists the rr+local node", p.stdout[:800] + p.stderr[-400:]):
        return
    check(node.get("source") == "local", "rr discover: the node's source is local", str(node))
    want = f"rr+local:///?nodeid={node['nodeid']}&service=RobotRaconteurServiceIndex"
    check(want in node.get("urls", []), "rr discover: the node's rr+local URL", str(node.get("urls")))
    svc = next((x for x in node.get("services") or [] if x.get("name") == "interop"), None)
    check(svc is not None and svc.get("root_object_type") == root_type and
          f"rr+local:///?nodeid={node['nodeid']}&service=interop" in svc.get("urls", []),
          "rr discover: its services read over rr+local", str(node.get("services")) + " " + str(node.get("error")))


def stale_checks(exe, url):
    """After an official node stopped (it leaves its entries behind), its entry is reported stale."""
    p = subprocess.run([exe, "get", url, "p_int32"], capture_output=True, text=True, timeout=HANG_S)
    check(p.returncode == CONNECT and "stale" in p.stderr, "rr+local: a stopped official node's entry is reported stale",
          f"rc={p.returncode} stderr={p.stderr.strip()}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rr", required=True)
    ap.add_argument("--target", choices=["url", "ours", "official", "reynard"])
    ap.add_argument("--url", help="service URL (--target url)")
    ap.add_argument("--service", help="rr_interop_service executable (--target ours)")
    ap.add_argument("--no-node-index", action="store_true", help="skip `rr info` without service=")
    ap.add_argument("--local", action="store_true",
                    help="--target ours/official: the service serves rr+local under a NodeName of this run; rr uses it")
    ap.add_argument("--timeout-timing", action="store_true",
                    help="only the --timeout checks, with the bound on how late it may end (a timing test)")
    args = ap.parse_args()
    if args.timeout_timing:
        timeout_checks(args.rr, timing=True)
        print(json.dumps({"target": "timeout", "checks": checks_run[0], "failures": len(failures)}))
        return 1 if failures else 0
    if not args.target:
        ap.error("--target is required")
    local_name = f"cli.t{os.getpid()}"

    usage_checks(args.rr)
    if args.target in ("ours", "official"):
        timeout_checks(args.rr)
    if args.target == "url":
        proc, ready = None, {"url": args.url}
    elif args.target == "ours":
        proc, ready = start([args.service, "--port", "0", "--max-lifetime", "280"] +
                            (["--local-name", local_name] if args.local else []))
    elif args.target == "official":
        proc, ready = start([sys.executable, os.path.join(INTEROP, "official_service.py"), "--port", "0",
                             "--max-lifetime", "280"] + (["--node-setup", local_name] if args.local else []))
    else:
        proc, ready = start([sys.executable, os.path.join(INTEROP, "reynard_harness.py"), "--max-lifetime", "200"],
                            timeout=90)
    if args.local:
        ready["url"] = ready["local_url"]
    global NODE_NAME
    NODE_NAME = ready.get("nodename")
    try:
        rr = Rr(args.rr, ready["url"])
        if args.target == "reynard":
            out = rr.ok("info")
            check("== service definition: experimental.reynard_the_robot ==" in out, "reynard: definition printed")
            check("== object reynard: experimental.reynard_the_robot.Reynard ==" in out, "reynard: root object")
            check(re.search(r"(?m)^function\s+drive_robot\s+void\(", out), "reynard: drive_robot listed", out[-800:])
            pos = rr.json_lines("get", "robot_position")
            check(len(pos) == 1 and isinstance(pos[0], list), "reynard: get robot_position", str(pos))
            if not args.no_node_index:
                node_index_checks(rr, ready["url"], "reynard", "experimental.reynard_the_robot.Reynard")
        else:
            interop_checks(rr, ready["url"])
            if not args.no_node_index:
                node_index_checks(rr, ready["url"], "interop", "experimental.interop_test.Root")
        if args.local:
            local_error_checks(args.rr, local_name)
            local_discover_checks(args.rr, local_name, "experimental.interop_test.Root")
    finally:
        if proc is not None:
            stop(proc)
    if args.local and args.target == "official":
        stale_checks(args.rr, ready["url"])
    if args.local:
        sys.path.insert(0, INTEROP)
        from through_gateway import forget_node_names  # noqa: E402
        forget_node_names([local_name], [ready.get("nodeid", "")])
    if args.target == "ours":
        check(proc.returncode == 0, "service exits cleanly", f"rc={proc.returncode}")
    print(json.dumps({"target": args.target, "checks": checks_run[0], "failures": len(failures)}))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
