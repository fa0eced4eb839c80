#!/usr/bin/env python3
"""rr+local both ways with the official implementation (docs/local-transport.md).

--part our-client       the official service started with its default node setup
                        (official_service.py --node-setup NAME: RobotRaconteur.ServerNodeSetup(NAME, 0))
                        is reached by OUR client (rr_interop_client, every check) by NodeName, by NodeID
                        and by both; rr_local_probe finds the same socket the official entry names; our
                        service refuses the NodeName while the official node holds it; once the official
                        node stops, its entries are reported stale; our node then takes the NodeName and
                        gets the official node's NodeID from the shared NodeID cache.
--part official-client  OUR service (rr_interop_service --local-name NAME) is reached by the official
                        client (official_client.py, every check) by NodeName, by NodeID and by both; the
                        official service index over rr+local reports rr+local:///?nodeid=…&service=…;
                        the official ServerNodeSetup refuses the NodeName while our node holds it; once
                        our node stops its entries and socket are gone; the official node then takes the
                        NodeName with the NodeID our node wrote to the NodeID cache.

--dirs default   the node directories of this user as both libraries compute them (for root
                 /var/run/robotraconteur/root, /var/lib/robotraconteur/nodeids); NodeNames are unique
                 per run and everything this run leaves there is removed at the end.
--dirs temp      a temporary tree through the official environment overrides (ROBOTRACONTEUR_*_DIR).

Exit status 0 = every step passed, 1 = a step failed, 77 = cannot run here (reason printed).
Usage: local_interop.py --part our-client|official-client --service PATH --client PATH --probe PATH
                        [--dirs default|temp] [--keep DIR] [--verbose]
"""

import argparse
import glob
import json
import os
import secrets
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from child_procs import StepFailed, read_json_line, scratch_rr_env, start, stop, tail  # noqa: E402

START_S = 40
CLIENT_S = 150


class Run:
    def __init__(self, args, workdir, env):
        self.args = args
        self.workdir = workdir
        self.env = env
        self.steps = []
        self.names = []
        self.nodeids = []
        self.n = 0

    def log(self, *a):
        if self.args.verbose:
            print("[local_interop]", *a, file=sys.stderr, flush=True)

    def step(self, name, ok, detail=""):
        self.steps.append({"step": name, "ok": bool(ok), "detail": detail})
        self.log("PASS" if ok else "FAIL", name, detail if not ok else "")
        if not ok:
            raise StepFailed("%s: %s" % (name, detail))

    def name(self, stem):
        n = "rrgwtest.%s.%d.%s" % (stem, os.getpid(), secrets.token_hex(3))
        self.names.append(n)
        return n

    def logfile(self, what):
        self.n += 1
        return os.path.join(self.workdir, "%02d_%s.stderr" % (self.n, what))

    def run(self, cmd, what, timeout=CLIENT_S):
        err = self.logfile(what)
        with open(err, "wb") as fh:
            p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=fh, env=self.env, timeout=timeout)
        out = p.stdout.decode("utf-8", "replace").strip().splitlines()
        return p.returncode, (out[-1] if out else ""), err

    def start(self, cmd, what):
        err = self.logfile(what)
        env_before = os.environ.copy()
        os.environ.clear()
        os.environ.update(self.env)
        try:
            proc = start(cmd, err)
        finally:
            os.environ.clear()
            os.environ.update(env_before)
        return proc, err

    def probe(self, *a):
        rc, out, err = self.run([self.args.probe] + list(a), "probe", 30)
        try:
            return rc, json.loads(out)
        except ValueError:
            raise StepFailed("rr_local_probe %s: no JSON (status %s): %s" % (a, rc, tail(err)))

    def dirs(self):
        return self.probe("dirs")[1]

    # --- processes -----------------------------------------------------------------------------------

    def official_service(self, name):
        cmd = [sys.executable, "-u", os.path.join(HERE, "official_service.py"), "--node-setup", name,
               "--port", "0", "--max-lifetime", "240"]
        proc, err = self.start(cmd, "official_service")
        return proc, read_json_line(proc, START_S, "official_service.py --node-setup"), err

    def our_service(self, name):
        proc, err = self.start([self.args.service, "--port", "0", "--max-lifetime", "240", "--local-name", name],
                               "our_service")
        return proc, read_json_line(proc, START_S, "rr_interop_service --local-name"), err

    def our_client(self, url, only=None):
        cmd = [self.args.client, url, "--timeout", str(CLIENT_S - 20)]
        if only:
            cmd += ["--only", only]
        return self.run(cmd, "our_client")

    def official_client(self, url, only=None):
        cmd = [sys.executable, os.path.join(HERE, "official_client.py"), url, "--timeout", str(CLIENT_S - 20)]
        if only:
            cmd += ["--only", only]
        return self.run(cmd, "official_client")

    def refused_start(self, cmd, what):
        """Runs a service start that must fail: returns (status, stderr text)."""
        err = self.logfile(what)
        with open(err, "wb") as fh:
            p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=fh, env=self.env, timeout=60)
        return p.returncode, tail(err, 40)

    # --- cleanup of what this run leaves in the node directories --------------------------------------

    def cleanup(self):
        try:
            d = self.dirs()
        except StepFailed:
            return
        paths = []
        for entry_dir in [os.path.join(d["user_run_dir"], "transport", "local")]:
            for n in self.names:
                paths += glob.glob(os.path.join(entry_dir, "by-nodename", n + ".*"))
            for i in self.nodeids:
                paths += glob.glob(os.path.join(entry_dir, "by-nodeid", i + ".*"))
        for n in self.names:
            paths.append(os.path.join(d["user_run_dir"], "nodeids", n + ".pid"))
            paths.append(os.path.join(d["user_config_dir"], "nodeids", n))
            paths.append(os.path.join(d["user_state_dir"], "nodeids", n))
        for p in paths:
            try:
                os.unlink(p)
            except OSError:
                pass


def nodeid_of(ready):
    return ready["nodeid"].strip("{}").lower()


def entry(d, kind, key):
    return os.path.join(d["user_run_dir"], "transport", "local", kind, key + ".info")


def read_info(path):
    info = {}
    with open(path) as fh:
        for line in fh:
            if ":" in line:
                k, v = line.split(":", 1)
                info[k.strip()] = v.strip()  # last wins, as our reader
    return info


def part_our_client(r):
    name = r.name("offsvc")
    svc, ready, svc_err = r.official_service(name)
    try:
        nodeid = nodeid_of(ready)
        r.nodeids.append(nodeid)
        d = r.dirs()
        info = read_info(entry(d, "by-nodename", name))
        r.step("official entry is where our dirs say", info.get("nodename") == name and info.get("nodeid", "").strip("{}") == nodeid,
               json.dumps(info))
        for url in (ready["local_url"], ready["local_id_url"],
                    "rr+local:///?nodeid=%s&nodename=%s&service=interop" % (nodeid, name)):
            rc, out = r.probe("lookup", url)
            r.step("probe finds the official socket: " + url, rc == 0 and out.get("socket") == info["socket"], json.dumps(out))

        rc, out, err = r.our_client(ready["local_url"])
        r.step("our client, every check, by NodeName", rc == 0, "status %s %s\n%s" % (rc, out[:500], tail(err)))
        rc, out, err = r.our_client(ready["local_id_url"], "connection,properties,functions,pipes,wires")
        r.step("our client by NodeID", rc == 0, "status %s %s\n%s" % (rc, out[:500], tail(err)))
        rc, out, err = r.our_client("rr+local:///?nodeid={%s}&nodename=%s&service=interop" % (nodeid, name), "connection,properties")
        r.step("our client by NodeID and NodeName", rc == 0, "status %s %s\n%s" % (rc, out[:500], tail(err)))

        rc, text = r.refused_start([r.args.service, "--port", "0", "--max-lifetime", "30", "--local-name", name], "our_refused")
        r.step("our node refuses the NodeName the official node holds",
               rc == 3 and ("NodeName \"%s\" is already in use" % name) in text, "status %s: %s" % (rc, text))
    finally:
        status = stop(svc)
    r.step("official service stopped cleanly", status == 0, "status %s\n%s" % (status, tail(svc_err)))

    # CORE leaves its entries behind, unlocked, and removes its socket: stale.
    rc, out = r.probe("lookup", "rr+local:///?nodename=%s&service=interop" % name)
    r.step("the official node's leftover entries are reported stale",
           rc == 1 and "is not running" in out.get("message", "") and "stale" in out.get("message", ""), json.dumps(out))

    ours, ready2, ours_err = r.our_service(name)
    try:
        r.step("our node takes the NodeName over the stale entries, with the official node's NodeID (shared cache)",
               nodeid_of(ready2) == nodeid, "ours %s, official %s" % (ready2.get("nodeid"), nodeid))
        rc, out, err = r.official_client(ready2["local_url"], "connection,properties")
        r.step("the official client reaches it by NodeName", rc == 0, "status %s %s\n%s" % (rc, out[:500], tail(err)))
    finally:
        status = stop(ours)
    r.step("our service stopped cleanly", status == 0, "status %s\n%s" % (status, tail(ours_err)))


def part_official_client(r):
    name = r.name("oursvc")
    svc, ready, svc_err = r.our_service(name)
    try:
        nodeid = nodeid_of(ready)
        r.nodeids.append(nodeid)
        d = r.dirs()
        info_path = entry(d, "by-nodename", name)
        info = read_info(info_path)
        r.step("our entry: nodename, nodeid {…}, socket, pid, username, ServiceStateNonce",
               info.get("nodename") == name and info.get("nodeid") == "{%s}" % nodeid and
               info.get("socket") == ready["local_socket"] and set(info) == {"nodename", "nodeid", "socket", "pid", "username",
                                                                             "ServiceStateNonce"},
               json.dumps(info))

        rc, out, err = r.official_client(ready["local_url"])
        r.step("official client, every check, by NodeName", rc == 0, "status %s %s\n%s" % (rc, out[:500], tail(err)))
        rc, out, err = r.official_client(ready["local_id_url"])
        r.step("official client, every check, by NodeID", rc == 0, "status %s %s\n%s" % (rc, out[:500], tail(err)))
        rc, out, err = r.official_client("rr+local:///?nodeid=%s&nodename=%s&service=interop" % (nodeid, name),
                                         "connection,properties,functions")
        r.step("official client by NodeID and NodeName", rc == 0, "status %s %s\n%s" % (rc, out[:500], tail(err)))

        snippet = ("import json,RobotRaconteur as RR\n"
                   "RRN=RR.RobotRaconteurNode.s\n"
                   "with RR.ClientNodeSetup():\n"
                   "    c=RRN.ConnectService('rr+local:///?nodename=%s&service=RobotRaconteurServiceIndex')\n"
                   "    s=c.GetLocalNodeServices()\n"
                   "    print(json.dumps({v.Name: dict(v.ConnectionURL) for v in s.values()}))\n" % name)
        rc, out, err = r.run([sys.executable, "-c", snippet], "official_index", 60)
        urls = json.loads(out) if rc == 0 and out else {}
        want = "rr+local:///?nodeid=%s&service=interop" % nodeid
        r.step("official client reads our service index over rr+local",
               urls.get("interop", {}).get("1") == want, "status %s %s (want %s)\n%s" % (rc, out, want, tail(err)))

        rc, text = r.refused_start([sys.executable, os.path.join(HERE, "official_service.py"), "--node-setup", name,
                                    "--port", "0", "--max-lifetime", "30"], "official_refused")
        r.step("the official ServerNodeSetup refuses the NodeName our node holds",
               rc == 3 and "already in use" in text, "status %s: %s" % (rc, text))
    finally:
        status = stop(svc)
    r.step("our service stopped cleanly", status == 0, "status %s\n%s" % (status, tail(svc_err)))
    gone = [p for p in (info_path, entry(d, "by-nodeid", nodeid), ready["local_socket"]) if os.path.exists(p)]
    r.step("our entries and socket are removed on exit", not gone, "left: %s" % gone)
    rc, out, err = r.official_client(ready["local_url"], "connection")
    r.step("the official client then finds no node", rc == 2 and "Could not connect" in out, "status %s %s" % (rc, out[:300]))

    off, ready2, off_err = r.official_service(name)
    try:
        r.step("the official node takes the NodeName with the NodeID our node wrote to the cache",
               nodeid_of(ready2) == nodeid, "official %s, ours %s" % (ready2.get("nodeid"), nodeid))
    finally:
        status = stop(off)
    r.step("official service stopped cleanly", status == 0, "status %s\n%s" % (status, tail(off_err)))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--part", choices=["our-client", "official-client"], required=True)
    ap.add_argument("--service", required=True, help="rr_interop_service")
    ap.add_argument("--client", required=True, help="rr_interop_client")
    ap.add_argument("--probe", required=True, help="rr_local_probe")
    ap.add_argument("--dirs", choices=["default", "temp"], default="default")
    ap.add_argument("--keep", default=None, help="keep the logs in this directory")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args(argv)
    try:
        import RobotRaconteur  # noqa: F401
    except ImportError:
        print("SKIP: the robotraconteur package is not installed in %s" % sys.executable)
        return 77

    workdir = args.keep or tempfile.mkdtemp(prefix="local_interop_")
    os.makedirs(workdir, exist_ok=True)
    env = os.environ.copy()
    tree = None
    if args.dirs == "temp":
        tree = tempfile.mkdtemp(prefix="rr_local_dirs_")
        env = scratch_rr_env(tree, env)
    r = Run(args, workdir, env)
    result = {"ok": False, "part": args.part, "dirs": args.dirs}
    rc = 1
    try:
        (part_our_client if args.part == "our-client" else part_official_client)(r)
        result["ok"] = True
        rc = 0
    except (StepFailed, subprocess.TimeoutExpired) as e:
        result["error"] = str(e)
        print("[local_interop] FAIL: %s" % e, file=sys.stderr, flush=True)
    finally:
        r.cleanup()
        if tree:
            shutil.rmtree(tree, ignore_errors=True)
        if not args.keep:
            shutil.rmtree(workdir, ignore_errors=True)
    result["steps"] = r.steps
    print(json.dumps(result), flush=True)
    return rc


if __name__ == "__main__":
    sys.exit(main())
