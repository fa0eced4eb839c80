"""What the recording tests share: a failed check, a JSON API request, waiting for an event, a failed
test's logs (stdlib only; recorded_so_far imports PyPI mcap when called)."""
import json
import os
import shutil
import subprocess
import time
import urllib.error
import urllib.request


class CheckFailed(Exception):
    pass


def expect(cond, what):
    if not cond:
        raise CheckFailed(what)


def http(base, method, path, body=None, timeout=60):
    """`method base+path` with an optional JSON body; returns (status, parsed JSON body or None)."""
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(base + path, data=data, method=method, headers={"Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            return r.status, json.loads(r.read() or b"null")
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read() or b"null")
    except TimeoutError as e:  # name the request that did not answer
        raise CheckFailed("%s %s: no answer within %s s (%s)" % (method, path, timeout, e))


def foxglove_check(paths, checks, max_messages=20):
    """The recording's json channels checked by the rules of Foxglove/Lichtblick's parser
    (foxglove_json_check.mjs, with @mcap/core); its summary goes to checks["foxglove"]. A missing node
    or test/mcap/node_modules is said there as SKIP, not failed."""
    node = shutil.which("node")
    here = os.path.dirname(os.path.abspath(__file__))
    if not node or not os.path.isdir(os.path.join(here, "..", "mcap", "node_modules", "@foxglove", "schemas")):
        checks["foxglove"] = "SKIP: node or test/mcap/node_modules missing (run ./scripts/setup.sh)"
        return
    r = subprocess.run([node, os.path.join(here, "foxglove_json_check.mjs"), *paths, "--max-messages", str(max_messages)],
                       capture_output=True, text=True, timeout=120)
    if r.returncode == 77:
        checks["foxglove"] = r.stdout.strip()
        return
    expect(r.returncode == 0, "json channels as Foxglove reads them: %s%s" % (r.stdout[-1500:], r.stderr[-500:]))
    checks["foxglove"] = json.loads(r.stdout.strip().splitlines()[-1])


def official_foxglove_schemas():
    """{"foxglove.RawImage": schema, "foxglove.CompressedImage": schema} from the npm package
    @foxglove/schemas (pinned in test/mcap/package.json), or None without node or the package."""
    node = shutil.which("node")
    here = os.path.dirname(os.path.abspath(__file__))
    mcap_dir = os.path.join(here, "..", "mcap")
    if not node or not os.path.isdir(os.path.join(mcap_dir, "node_modules", "@foxglove", "schemas")):
        return None
    code = ('const s = require("@foxglove/schemas/jsonschema");'
            'console.log(JSON.stringify({"foxglove.RawImage": s.RawImage, "foxglove.CompressedImage": s.CompressedImage}))')
    r = subprocess.run([node, "-e", code], cwd=mcap_dir, capture_output=True, text=True, timeout=60)
    expect(r.returncode == 0, "@foxglove/schemas: %s" % r.stderr[-500:])
    return json.loads(r.stdout)


def print_log_tails(work, lines=60):
    """The end of every log the test's processes wrote in `work` (gateway.log, *.err, ...), so that a
    failure in CI says what the gateway saw, not only what the test asserted."""
    for root, _, files in os.walk(work):
        for name in sorted(files):
            if not name.endswith((".log", ".err")):
                continue
            path = os.path.join(root, name)
            try:
                with open(path, "rb") as f:
                    f.seek(0, os.SEEK_END)
                    f.seek(max(0, f.tell() - 64 * 1024))
                    tail = f.read().decode(errors="replace").splitlines()[-lines:]
            except OSError as e:
                tail = ["(cannot read: %s)" % e]
            print("---- %s (last %d lines) ----" % (path, len(tail)))
            print("\n".join(tail))


def report_and_clean(checks, work, keep, failed=False):
    """Prints the test's checks as JSON, then removes its work folder (or says where it was kept). A
    failed test prints its processes' logs and keeps the folder, logs and recordings included."""
    print(json.dumps(checks, indent=1, default=str))
    if failed:
        print_log_tails(work)
    if keep or failed:
        print("kept", work)
    else:
        shutil.rmtree(work, ignore_errors=True)


def exit_status(ok, checks):
    """The test's exit status: 1 when a check failed; 77 (ctest: Skipped) when every check that ran
    passed but a part could not run here (a value in `checks` starting with "SKIP", its reason; each is
    printed); 0 otherwise. A part that ran and was not met is a failure, never a skip."""
    if not ok:
        return 1
    skipped = ["%s: %s" % (k, v) for k, v in checks.items() if isinstance(v, str) and v.startswith("SKIP")]
    for line in skipped:
        print(line)
    if skipped:
        print("SKIP: every check that ran passed, %d part(s) could not run here (above)" % len(skipped))
        return 77
    return 0


def wait_for(what, predicate, timeout=60, interval=0.2):
    """Polls `predicate()` until it returns a true value (returned) or `timeout` s pass (CheckFailed
    naming `what`). The timeout only bounds a hang: a test waits for the event, never for a duration."""
    deadline = time.monotonic() + timeout
    while True:
        got = predicate()
        if got:
            return got
        if time.monotonic() > deadline:
            raise CheckFailed("%s: not within %.0f s" % (what, timeout))
        time.sleep(interval)


def recorded_so_far(path, topic, encoding="json"):
    """The messages (data bytes) of channel `topic` (`encoding`) a recording being written holds on disk
    now: the writer flushes a chunk at least every second, so the file grows while the recording runs.
    Read with the reference reader's streaming mode up to the last complete record."""
    from mcap.exceptions import EndOfFile
    from mcap.records import Channel, Message
    from mcap.stream_reader import StreamReader
    channels, data = set(), []
    try:
        with open(path, "rb") as f:
            for r in StreamReader(f, skip_magic=False).records:
                if isinstance(r, Channel) and r.topic == topic and r.message_encoding == encoding:
                    channels.add(r.id)
                elif isinstance(r, Message) and r.channel_id in channels:
                    data.append(r.data)
    except EndOfFile:
        pass  # the end of what is written so far
    return data


def stop_recording(base, rid, timeout=120):
    """POST /api/recordings/{id}/stop; returns (seconds the answer took, the final status). The answer
    comes once the file is closed (docs/recording.md); a recording still `stopping` in it is waited for
    through GET. Fails unless it ends `stopped`."""
    t0 = time.monotonic()
    status, done = http(base, "POST", "/api/recordings/%d/stop" % rid, {}, timeout=timeout)
    took = time.monotonic() - t0
    expect(status == 200, "stop %d: %s %s" % (rid, status, done))
    if done.get("state") == "stopping":
        done = wait_for("recording %d stopped" % rid,
                        lambda: (lambda s: s if s.get("state") != "stopping" else None)(http(base, "GET", "/api/recordings/%d" % rid)[1]),
                        timeout)
    expect(done.get("state") == "stopped", "stop %d: state %s (%s)" % (rid, done.get("state"), done.get("error")))
    return took, done
