"""What the recording tests share: a failed check and a JSON API request (stdlib only)."""
import json
import os
import shutil
import subprocess
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


def report_and_clean(checks, work, keep):
    """Prints the test's checks as JSON, then removes its work folder (or says where it was kept)."""
    print(json.dumps(checks, indent=1, default=str))
    if keep:
        print("kept", work)
    else:
        shutil.rmtree(work, ignore_errors=True)
