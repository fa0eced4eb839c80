#!/usr/bin/env python3
"""Our node directories (rr_local_probe dirs) against the official library's
(RobotRaconteurNode.GetNodeDirectories()) for a matrix of environments, as root and as an ordinary user.

Each case runs both programs with exactly the same environment (a small base plus the case's
variables) and compares all ten directories. The "ordinary user" cases run both as uid/gid 65534
(nobody) through setpriv, keeping only the capability to read files (the venv may live under /root);
they are reported skipped when this is not possible (not root, no setpriv).

Exit status 0 = all compared cases equal, 1 = a difference, 77 = cannot run (reason printed).
Usage: local_dirs.py --probe PATH [--verbose]
"""

import argparse
import json
import os
import shutil
import subprocess
import sys

OFFICIAL = r"""
import json, RobotRaconteur as RR
d = RR.RobotRaconteurNode.s.GetNodeDirectories()
print(json.dumps({k: getattr(d, k).string() for k in dir(d) if k.endswith('_dir')}))
"""

ROOT_CASES = [
    {},
    {"ROBOTRACONTEUR_SYSTEM_PREFIX": "/opt/pre"},
    {"ROBOTRACONTEUR_SYSTEM_PREFIX": "/opt/pre/"},
    {"ROBOTRACONTEUR_SYSTEM_PREFIX": ""},
    {"ROBOTRACONTEUR_SYSTEM_PREFIX": "rel"},
    {"ROBOTRACONTEUR_SYSTEM_RUN_DIR": "/x/run", "ROBOTRACONTEUR_SYSTEM_STATE_DIR": "/x/state",
     "ROBOTRACONTEUR_SYSTEM_CONFIG_DIR": "/x/etc", "ROBOTRACONTEUR_SYSTEM_DATA_DIR": "/x/data",
     "ROBOTRACONTEUR_SYSTEM_CACHE_DIR": "/x/cache", "ROBOTRACONTEUR_SYSTEM_PREFIX": "/p"},
    {"ROBOTRACONTEUR_USER_RUN_DIR": "/ignored", "ROBOTRACONTEUR_USER_CONFIG_DIR": "/ignored",
     "XDG_RUNTIME_DIR": "/run/user/0", "XDG_CONFIG_HOME": "/cfg", "ROBOTRACONTEUR_USER_HOME": "/h"},
]

USER_CASES = [
    {},
    {"HOME": "/home/ann"},
    {"HOME": "/home/ann/", "XDG_RUNTIME_DIR": "/run/user/1000/", "XDG_CONFIG_HOME": "/cfg/",
     "XDG_DATA_HOME": "/data", "XDG_STATE_HOME": "/state", "XDG_CACHE_HOME": "/cache"},
    {"HOME": "/home/ann", "ROBOTRACONTEUR_USER_HOME": "/h", "XDG_CONFIG_HOME": "/cfg", "XDG_RUNTIME_DIR": "/r"},
    {"HOME": "/home/ann", "ROBOTRACONTEUR_USER_RUN_DIR": "/ur", "ROBOTRACONTEUR_USER_CONFIG_DIR": "/uc",
     "ROBOTRACONTEUR_USER_STATE_DIR": "/us", "ROBOTRACONTEUR_USER_DATA_DIR": "/ud",
     "ROBOTRACONTEUR_USER_CACHE_DIR": "/ucc", "XDG_STATE_HOME": "/xs"},
    {"HOME": "/home/ann", "XDG_RUNTIME_DIR": "", "XDG_CONFIG_HOME": ""},
    {"HOME": "/home/ann", "XDG_STATE_HOME": "/xs", "ROBOTRACONTEUR_SYSTEM_PREFIX": "/opt/pre"},
    {"NO_HOME": "1"},
]


def run_case(probe, case, prefix, verbose):
    env = {"PATH": os.environ.get("PATH", "/usr/bin:/bin"), "HOME": os.environ.get("HOME", "/root")}
    for k in ("LD_LIBRARY_PATH", "ASAN_OPTIONS", "UBSAN_OPTIONS", "LSAN_OPTIONS"):
        if k in os.environ:
            env[k] = os.environ[k]
    for k, v in case.items():
        if k == "NO_HOME":
            env.pop("HOME", None)
        else:
            env[k] = v
    off = subprocess.run(prefix + [sys.executable, "-c", OFFICIAL], env=env, capture_output=True, timeout=60)
    ours = subprocess.run(prefix + [probe, "dirs"], env=env, capture_output=True, timeout=60)
    if off.returncode != 0 or ours.returncode != 0:
        return {"case": case, "ok": False, "error": "official %s: %s / ours %s: %s" % (
            off.returncode, off.stderr.decode()[-400:], ours.returncode, ours.stderr.decode()[-400:])}
    a = json.loads(off.stdout.decode().strip().splitlines()[-1])
    b = json.loads(ours.stdout.decode().strip().splitlines()[-1])
    diff = {k: {"official": a.get(k), "ours": b.get(k)} for k in sorted(set(a) | set(b)) if a.get(k) != b.get(k)}
    if verbose:
        print("[local_dirs]", "OK  " if not diff else "DIFF", json.dumps(case), json.dumps(diff) if diff else "",
              file=sys.stderr)
    return {"case": case, "ok": not diff, "diff": diff, "official": a}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--probe", required=True)
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args(argv)
    try:
        import RobotRaconteur  # noqa: F401
    except ImportError:
        print("SKIP: the robotraconteur package is not installed in %s" % sys.executable)
        return 77

    results = []
    skipped = []
    cases_as_me = ROOT_CASES if os.getuid() == 0 else USER_CASES
    for c in cases_as_me:
        results.append(run_case(args.probe, c, [], args.verbose))
    if os.getuid() == 0:
        setpriv = shutil.which("setpriv")
        prefix = [setpriv, "--reuid=65534", "--regid=65534", "--clear-groups", "--inh-caps=+dac_read_search",
                  "--ambient-caps=+dac_read_search", "--"] if setpriv else None
        if prefix and subprocess.run(prefix + ["true"], capture_output=True).returncode == 0:
            for c in USER_CASES:
                results.append(run_case(args.probe, c, prefix, args.verbose))
        else:
            skipped.append("ordinary-user cases: setpriv with ambient capabilities is not usable here")
    else:
        skipped.append("root cases: not running as root")
    ok = all(r["ok"] for r in results)
    print(json.dumps({"ok": ok, "compared": len(results), "failed": [r for r in results if not r["ok"]],
                      "skipped": skipped}))
    for s in skipped:
        print("[local_dirs] skipped: %s" % s, file=sys.stderr)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
