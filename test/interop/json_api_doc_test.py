#!/usr/bin/env python3
"""Runs the examples of docs/json-api.md against a live rr-gateway with its demo devices.

Starts `rr-gateway --listen 127.0.0.1 --port 0` (demo devices on), waits for /readyz, then runs every
example of the document in order (see its section "How the examples run"):
  * ```http``` block = a request; the following ```json``` block = the expected answer, its first
    line `// status: N`; `// exact` asks for an exact match, otherwise the shape is compared;
  * ```ws``` block = one WebSocket session (subprotocol rr-gateway.json.v1): `>` lines are sent, `<`
    lines expected by shape, `<=` lines exactly (non-matching messages are skipped while waiting);
  * a ```json``` block starting with `// not run:` is only checked to be valid JSON.
The string "..." in an expected value matches anything.

Usage: json_api_doc_test.py --gateway PATH [--doc docs/json-api.md] [--verbose]
       json_api_doc_test.py --url http://127.0.0.1:PORT   (a gateway that is already running)
Prints one line per example and "N passed, M failed"; exit status 0 when all pass, 1 otherwise,
2 when the gateway cannot be started, 77 (skip) when the websocket-client package is missing.
HTTP uses the standard library (urllib); the WebSocket side uses websocket-client (requirements.txt).
"""
import argparse
import json
import os
import subprocess
import sys
import time
import urllib.error
import urllib.request

from child_procs import stop
from doc_blocks import blocks

try:
    import websocket  # websocket-client
except ImportError:  # pragma: no cover
    print("SKIP: the websocket-client package is missing (pip install -r test/interop/requirements.txt)")
    sys.exit(77)

SUBPROTOCOL = "rr-gateway.json.v1"
WILDCARD = "..."


# --- matching ----------------------------------------------------------------------------------

def kind_of(v):
    if v is None:
        return "null"
    if isinstance(v, bool):
        return "bool"
    if isinstance(v, (int, float)):
        return "number"
    if isinstance(v, str):
        return "string"
    if isinstance(v, list):
        return "array"
    return "object"


def match(expected, actual, exact, path="$"):
    """None when `actual` matches `expected`, else a description of the first difference."""
    if expected == WILDCARD:
        return None
    ke, ka = kind_of(expected), kind_of(actual)
    if ke != ka:
        return "%s: expected %s, got %s" % (path, ke, json.dumps(actual)[:200])
    if ke == "object":
        if set(expected) != set(actual):
            return "%s: keys %s, expected %s" % (path, sorted(actual), sorted(expected))
        for k in expected:
            d = match(expected[k], actual[k], exact, "%s.%s" % (path, k))
            if d:
                return d
        return None
    if ke == "array":
        if exact:
            if len(expected) != len(actual):
                return "%s: %d items, expected %d" % (path, len(actual), len(expected))
            for i, (e, a) in enumerate(zip(expected, actual)):
                d = match(e, a, exact, "%s[%d]" % (path, i))
                if d:
                    return d
            return None
        if not expected:
            return None
        for i, a in enumerate(actual):
            diffs = [match(e, a, exact, "%s[%d]" % (path, i)) for e in expected]
            if all(diffs):
                return diffs[0]
        return None
    if exact and expected != actual:
        return "%s: expected %s, got %s" % (path, json.dumps(expected), json.dumps(actual)[:200])
    return None


# --- the document ------------------------------------------------------------------------------



def split_comments(lines):
    comments = [l.strip()[2:].strip() for l in lines if l.strip().startswith("//")]
    body = "\n".join(l for l in lines if not l.strip().startswith("//"))
    return comments, body


def examples(text):
    """Examples in document order: ("http", request, expected, line), ("ws", lines, line), ("json", ...)."""
    out = []
    bs = blocks(text)
    i = 0
    while i < len(bs):
        info, lines, line = bs[i]
        if info == "http":
            if i + 1 >= len(bs) or bs[i + 1][0] != "json":
                raise ValueError("line %d: http block without a json answer block" % line)
            out.append(("http", lines, bs[i + 1][1], line))
            i += 2
            continue
        if info == "ws":
            out.append(("ws", lines, None, line))
        elif info == "json":
            out.append(("json", lines, None, line))
        i += 1
    return out


# --- running -----------------------------------------------------------------------------------

def run_http(base, request, expected_lines):
    head, _, body = "\n".join(request).partition("\n\n")
    head_lines = head.splitlines()
    method, target = head_lines[0].split(" ", 1)
    headers = {}
    for h in head_lines[1:]:
        k, _, v = h.partition(":")
        headers[k.strip()] = v.strip()
    comments, expected_text = split_comments(expected_lines)
    status = None
    exact = False
    for c in comments:
        if c.startswith("status:"):
            status = int(c.split(":", 1)[1])
        elif c == "exact":
            exact = True
    if status is None:
        return "the answer block has no // status: line"
    expected = json.loads(expected_text)
    # urllib quotes nothing by itself: keep the target as written, except for characters HTTP forbids.
    target = target.replace(" ", "%20")
    req = urllib.request.Request(base + target, method=method,
                                 data=body.encode() if body else None, headers=headers)
    try:
        with urllib.request.urlopen(req, timeout=30) as r:
            got_status, got_body = r.status, r.read()
    except urllib.error.HTTPError as e:
        got_status, got_body = e.code, e.read()
    if got_status != status:
        return "status %d, expected %d: %s" % (got_status, status, got_body[:300])
    try:
        actual = json.loads(got_body)
    except ValueError:
        return "answer is not JSON: %r" % got_body[:300]
    return match(expected, actual, exact)


def run_ws(ws_url, lines, timeout=60.0):
    # timeout bounds a hang (a reply may queue behind pipe frames rendered slowly under ASan and load)
    ws = websocket.create_connection(ws_url, subprotocols=[SUBPROTOCOL], timeout=timeout)
    try:
        if ws.getsubprotocol() != SUBPROTOCOL:
            return "the gateway chose subprotocol %r" % ws.getsubprotocol()
        for line in lines:
            line = line.strip()
            if not line:
                continue
            if line.startswith(">"):
                ws.send(line[1:].strip())
                continue
            exact = line.startswith("<=")
            expected = json.loads(line[2:] if exact else line[1:])
            deadline = time.time() + timeout
            last = None
            while True:
                left = deadline - time.time()
                if left <= 0:
                    return "no message matched %s (last difference: %s)" % (line[:200], last)
                ws.settimeout(left)
                try:
                    msg = json.loads(ws.recv())
                except websocket.WebSocketTimeoutException:
                    return "timed out waiting for %s (last difference: %s)" % (line[:200], last)
                last = match(expected, msg, exact)
                if last is None:
                    break
        return None
    finally:
        ws.close()


def wait_ready(base, timeout=30):
    deadline = time.time() + timeout
    while time.time() < deadline:
        try:
            with urllib.request.urlopen(base + "/readyz", timeout=2) as r:
                if r.status == 200:
                    return True
        except Exception:
            pass
        time.sleep(0.1)
    return False


def start_gateway(path):
    proc = subprocess.Popen([path, "--listen", "127.0.0.1", "--port", "0", "--log-level", "warning", "--no-local"],
                            stdout=subprocess.PIPE, text=True)
    deadline = time.time() + 30
    while time.time() < deadline:
        if proc.poll() is not None:
            raise RuntimeError("rr-gateway exited with %s" % proc.returncode)
        line = proc.stdout.readline()
        try:
            obj = json.loads(line)
        except ValueError:
            continue
        if "port" in obj:
            return proc, obj["port"]
    raise RuntimeError("rr-gateway printed no port")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gateway", help="rr-gateway executable (started with its demo devices)")
    ap.add_argument("--url", help="base URL of a running gateway instead")
    ap.add_argument("--doc", default=os.path.join(os.path.dirname(__file__), "..", "..", "docs", "json-api.md"))
    ap.add_argument("--verbose", action="store_true")
    a = ap.parse_args()
    if not a.gateway and not a.url:
        ap.error("--gateway or --url is required")
    with open(a.doc, encoding="utf-8") as f:
        items = examples(f.read())

    proc = None
    try:
        if a.url:
            base = a.url.rstrip("/")
        else:
            try:
                proc, port = start_gateway(a.gateway)
            except RuntimeError as e:
                print("cannot start the gateway: %s" % e)
                return 2
            base = "http://127.0.0.1:%d" % port
        if not wait_ready(base):
            print("the gateway did not become ready (demo devices connected)")
            return 2
        ws_url = base.replace("http://", "ws://", 1) + "/"
        passed = failed = 0
        for kind, lines, expected, line in items:
            try:
                if kind == "http":
                    diff = run_http(base, lines, expected)
                    what = lines[0]
                elif kind == "ws":
                    diff = run_ws(ws_url, lines)
                    what = "ws: " + (lines[0][:70] if lines else "")
                else:
                    comments, body = split_comments(lines)
                    if not any(c.startswith("not run:") for c in comments):
                        diff = "a json block that is neither an answer nor marked // not run:"
                    else:
                        json.loads(body)
                        diff = None
                    what = "json (not run)"
            except Exception as e:  # a broken example or a crash is a failure, reported with its line
                diff = "%s: %s" % (type(e).__name__, e)
            if diff:
                failed += 1
                print("FAIL docs/json-api.md:%d %s\n     %s" % (line, what, diff))
            else:
                passed += 1
                if a.verbose:
                    print("ok   docs/json-api.md:%d %s" % (line, what))
        print("json-api examples: %d passed, %d failed" % (passed, failed))
        return 0 if failed == 0 and passed > 0 else 1
    finally:
        stop(proc)


if __name__ == "__main__":
    sys.exit(main())
