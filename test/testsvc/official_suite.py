#!/usr/bin/env python3
"""The official Python client suite (test/python of robotraconteur/robotraconteur) against rr-test-service,
run by hand (docs/native-service.md "The official client suite against rr-test-service").

For each configuration it starts a service, sets ROBOTRACONTEUR_TEST_SERVER_URL and runs the suite's
service tests with pytest. Configurations (--configs, comma-separated):
  tcp, ws, wss, local        rr-test-service with the official values on rr+tcp, rr+ws, rr+wss (a
                             throw-away certificate), rr+local (also with the URL joined by &)
  gateway-tcp, gateway-ws    rr-gateway (--gateway) in front of it: the four services as devices of the
                             same names, `auth: passthrough`, the client on rr+tcp / rr+ws, the gateway
                             reaching the service on rr+tcp; gateway-CLIENT-via-DEVICE (DEVICE: ws,
                             wss, local) reaches it on another transport
  official-CONFIG            the same with the official test server (official_server.py) instead of
                             rr-test-service (not wss): the reference
--reference also runs the suite without the variable, where it serves the official test services in
pytest's own process (service_test_util.py). Prints one line per test and configuration and a summary; the JUnit files stay in --out.

    .venv/bin/python test/testsvc/official_suite.py --repo /tmp/rr-official --values /tmp/official-values.json \\
        --service build/debug/test/testsvc/rr-test-service [--gateway build/debug/server/app/rr-gateway] \\
        [--reference] [--configs tcp,ws,wss,local,gateway-tcp,gateway-ws,official-tcp,...] \\
        [--pytest-path DIR] [--select PYTEST_K_EXPR] [--repeat N] [--out DIR]
Exit 0 when every test passed in every configuration run, 1 otherwise.
"""

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import uuid
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "interop"))
sys.path.insert(0, HERE)
import gateway_front  # noqa: E402

SUITE = ["RobotRaconteurTest/test_attributes.py", "RobotRaconteurTest/test_service.py",
         "RobotRaconteurTest/test_service2.py", "RobotRaconteurTest/test_service3.py"]


class Proc:
    """A child process whose first stdout line matching `accept` is its ready line."""

    def __init__(self, argv, logdir, name, accept, timeout=90, env=None):
        self.log = open(os.path.join(logdir, name + ".log"), "w")
        self.p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=self.log, text=True, env=env)
        line = []

        def read():
            for ln in self.p.stdout:
                if accept(ln):
                    line.append(ln)
                    return
        t = threading.Thread(target=read, daemon=True)
        t.start()
        t.join(timeout)
        if not line:
            self.stop()
            raise RuntimeError("%s printed no ready line; see %s" % (argv[0], self.log.name))
        self.ready = line[0]
        threading.Thread(target=lambda: [None for _ in self.p.stdout], daemon=True).start()

    def stop(self):
        if self.p.poll() is None:
            self.p.send_signal(signal.SIGTERM)
            try:
                self.p.wait(60)
            except subprocess.TimeoutExpired:
                self.p.kill()
                self.p.wait()
        return self.p.returncode


def start_service(args, logdir, name, extra):
    p = Proc([args.service, "--port", "0", "--robdef-dir", os.path.join(args.repo, "test", "robdef"),
              "--official-values", args.values] + extra, logdir, name, lambda ln: ln.startswith("ready "))
    return p, json.loads(p.ready[len("ready "):])


def start_official(args, logdir, name):
    """The official test server (official_server.py) as the service: the reference."""
    nodename = "official_" + uuid.uuid4().hex[:10]
    env = dict(os.environ)  # the official modules import pytest
    env["PYTHONPATH"] = os.pathsep.join(x for x in (args.pytest_path, env.get("PYTHONPATH")) if x)
    p = Proc([sys.executable, os.path.join(HERE, "official_server.py"), "--repo", args.repo, "--nodename", nodename],
             logdir, name, lambda ln: ln.startswith("ready "), env=env)
    return p, json.loads(p.ready[len("ready "):])


URL_KEYS = {"tcp": "url", "ws": "ws_url", "wss": "wss_url", "local": "local_url"}


def start_gateway(args, logdir, device_url, name, tls_ca=None):
    cfg = os.path.join(logdir, name + ".yaml")
    with open(cfg, "w") as f:
        f.write(gateway_front.config_text(device_url, tls_ca))
    p = Proc(gateway_front.argv(args.gateway, cfg), logdir, name, gateway_front.is_ready_line)
    port = gateway_front.port_of(p.ready)
    if not gateway_front.wait_until_ready(port, 60, lambda: p.p.poll() is None):
        p.stop()
        raise RuntimeError("gateway not ready; see " + p.log.name)
    return p, port


def run_suite(args, logdir, name, url, env_extra=None, plugins=()):
    junit = os.path.join(logdir, name + ".xml")
    env = dict(os.environ)
    env.pop("ROBOTRACONTEUR_TEST_SERVER_URL", None)
    if url is not None:
        env["ROBOTRACONTEUR_TEST_SERVER_URL"] = url
    env["PYTHONPATH"] = os.pathsep.join(x for x in (args.pytest_path, os.path.join(args.repo, "test", "python"), HERE,
                                                    env.get("PYTHONPATH")) if x)
    env.update(env_extra or {})
    with open(os.path.join(logdir, name + ".pytest.log"), "w") as out:
        subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q", "-rA", "--junitxml", junit]
                       + [a for p in plugins for a in ("-p", p)] + (["-k", args.select] if args.select else []) + SUITE, cwd=os.path.join(args.repo, "test", "python"), env=env, stdout=out,
                       stderr=subprocess.STDOUT, timeout=1800)
    results = {}
    for case in ET.parse(junit).getroot().iter("testcase"):
        test = "%s::%s" % (case.get("classname", "").split(".")[-1], case.get("name"))
        outcome = "passed"
        for kind in ("failure", "error", "skipped"):
            el = case.find(kind)
            if el is not None:
                outcome = "%s: %s" % ("failed" if kind != "skipped" else "skipped",
                                      (el.get("message") or "").splitlines()[0][:160] if el.get("message") else "")
        results[test] = outcome
    return results


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repo", required=True)
    ap.add_argument("--values", required=True, help="made by official_values.py")
    ap.add_argument("--service", required=True)
    ap.add_argument("--gateway")
    ap.add_argument("--reference", action="store_true", help="also run the suite against the official server")
    ap.add_argument("--configs", default="tcp,ws,wss,local,gateway-tcp,gateway-ws")
    ap.add_argument("--pytest-path", default=None, help="a folder to add to PYTHONPATH for pytest")
    ap.add_argument("--out", default=None)
    ap.add_argument("--select", default=None, help="only the tests pytest -k EXPR selects")
    ap.add_argument("--repeat", type=int, default=1, help="run the suite N times against each service process")
    args = ap.parse_args()
    logdir = args.out or tempfile.mkdtemp(prefix="official-suite-")
    os.makedirs(logdir, exist_ok=True)
    configs = [c for c in args.configs.split(",") if c and (args.gateway or not c.startswith("gateway"))]
    table = {}

    if args.reference:
        table["official server"] = run_suite(args, logdir, "reference", None)
    for config in configs:
        procs = []
        official = config.startswith("official-")  # the reference: the official server in a process of its own
        kind = config[len("official-"):] if official else config
        # gateway-CLIENT[-via-DEVICE]: the suite reaches the gateway on CLIENT, the gateway the service on DEVICE
        client, _, via = kind[len("gateway-"):].partition("-via-") if kind.startswith("gateway-") else (kind, "", "")
        served = via or ("tcp" if kind.startswith("gateway-") else kind)  # the service's transport in use
        try:
            if client not in ("tcp", "ws", "wss", "local") or served not in URL_KEYS or \
                    (kind.startswith("gateway-") and client not in ("tcp", "ws")):
                raise RuntimeError("unknown configuration " + config)
            extra, env, ca_cert = [], {}, None
            if served == "wss":
                if official:
                    raise RuntimeError("the official server is not run with TLS here (it needs RR node certificates)")
                import tls_pki
                pki = tls_pki.Pki(os.path.join(logdir, "pki-" + config))
                ca = pki.ca("ca")
                leaf = pki.issue(ca, "server", "localhost", sans=["DNS:localhost", "IP:127.0.0.1"])
                extra = ["--tls-cert", leaf.cert, "--tls-key", leaf.key]
                ca_cert = ca.cert
            if served == "local":
                extra = ["--nodename", "testsvc_" + uuid.uuid4().hex[:10]]
            if official:
                svc, urls = start_official(args, logdir, "service-" + config)
            else:
                svc, urls = start_service(args, logdir, "service-" + config, extra)
            procs.append(svc)
            url = urls[URL_KEYS[served]]
            if served == "wss" and not kind.startswith("gateway-"):
                url = url.replace("localhost", "127.0.0.1")
                env = {"SSL_CERT_FILE": ca_cert}
            if kind.startswith("gateway-"):
                gw, port = start_gateway(args, logdir, url, "gateway-" + config, tls_ca=ca_cert)
                procs.append(gw)
                url = "rr+%s://127.0.0.1:%d/" % (client, port)
            print("%s: %s" % (config, url), flush=True)
            table[config] = run_suite(args, logdir, config, url, env)
            for n in range(2, args.repeat + 1):  # again against the same service process
                table["%s #%d" % (config, n)] = run_suite(args, logdir, "%s-%d" % (config, n), url, env)
            if kind == "local":  # the suite cannot name an rr+local service unaided (official_suite_local_url.py)
                table[config + " (URL joined with &)"] = run_suite(args, logdir, config + "-joined", url, env,
                                                                   plugins=["official_suite_local_url"])
        except Exception as e:
            table[config] = {"(setup)": "failed: %s" % e}
        finally:
            for p in reversed(procs):
                code = p.stop()
                if code not in (0, None):
                    name = os.path.splitext(os.path.basename(p.log.name))[0]
                    table.setdefault(config, {})["(%s exit)" % name] = "failed: exit status %s" % code

    tests = sorted({t for r in table.values() for t in r})
    ok = True
    for config, results in table.items():
        for t in tests:
            if t.startswith("(") and t not in results:
                continue  # a configuration's setup failure or exit status
            outcome = results.get(t, "not run")
            ok = ok and outcome == "passed"
            print("%-16s %-45s %s" % (config, t, outcome))
    for config, results in table.items():
        print("%s: %d of %d passed" % (config, sum(1 for v in results.values() if v == "passed"), len(results)))
    print("logs and JUnit files: " + logdir)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
