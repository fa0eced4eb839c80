#!/usr/bin/env python3
"""TLS between our gateway/CLI and the official Robot Raconteur library, both ways (docs/security.md,
"The official library"). Every certificate is made here with the openssl CLI.

Official client (Python, a child process per attempt, so that its environment can differ) → gateway:
  * rr+wss with SSL_CERT_FILE = our CA: works; without it: refused; rrs+wss (STARTTLS inside the
    WebSocket): refused with "Server certificate not loaded";
  * rrs+tcp to a gateway with an ordinary certificate, even with our CA trusted through
    ROBOTRACONTEUR_SSL_CERT_FILE: refused (the official verify callback wants RR's markers);
  * rrs+tcp to a gateway whose node_certificate comes from our own CA with RR's critical markers and
    names the gateway's NodeID, client started with ROBOTRACONTEUR_SSL_CERT_FILE = that CA: works
    (also with ?nodeid=); without the variable: refused.
Ours → official node (official_service.py --load-tls):
  * without a node certificate: `rr` exits 3 with "Server certificate not loaded";
  * with one from our CA (PKCS#12 in its certificates folder): `rr info` works with --tls-ca, exits 3
    without; and a gateway with that node as an rrs+tcp device (tls_ca) serves it.

Usage: tls_interop.py --gateway PATH --rr PATH
Exit status: 0 all passed, 1 a check failed, 77 openssl or the venv missing (skip).
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import uuid

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "gateway"))

import gwproc  # noqa: E402
from gwproc import expect  # noqa: E402
import tls_pki  # noqa: E402

OFFICIAL_CLIENT = r"""
import json, sys
import RobotRaconteur as RR
RRN = RR.RobotRaconteurNode.s
t = RR.TcpTransport()
RRN.RegisterTransport(t)
try:
    c = RRN.ConnectService(sys.argv[1])
    print(json.dumps({"ok": True, "value": int(getattr(c, sys.argv[2]))}))
except Exception as e:
    print(json.dumps({"ok": False, "error": "%s: %s" % (type(e).__name__, e)}))
RRN.Shutdown()
"""


def official(url, member, env_extra):
    env = dict(os.environ)
    for k in ("SSL_CERT_FILE", "ROBOTRACONTEUR_SSL_CERT_FILE", "ROBOTRACONTEUR_SSL_CERT_DIR"):
        env.pop(k, None)
    env.update(env_extra)
    p = subprocess.run([sys.executable, "-c", OFFICIAL_CLIENT, url, member], capture_output=True, text=True,
                       timeout=60, env=env)
    lines = [l for l in p.stdout.splitlines() if l.startswith("{")]
    if not lines:
        raise AssertionError("official client printed nothing (exit %d): %s" % (p.returncode, p.stderr[-2000:]))
    return json.loads(lines[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--rr", required=True)
    a = ap.parse_args()
    if not tls_pki.have_openssl():
        print("SKIP: openssl not installed (./scripts/setup.sh)")
        return 77
    try:
        import RobotRaconteur  # noqa: F401
    except ImportError:
        print("SKIP: the official robotraconteur package is not in this Python (run ./scripts/setup.sh)")
        return 77

    checks = gwproc.Checks()
    tmp = tempfile.mkdtemp(prefix="rr-tls-interop-")
    procs = []
    try:
        pki = tls_pki.Pki(os.path.join(tmp, "pki"))
        ca = pki.ca("ca", "Test CA")
        web = pki.issue(ca, "web", "localhost", sans=("DNS:localhost", "IP:127.0.0.1"))
        rr_ca = pki.ca("rr-ca", "Test RR Root", rr_marker=tls_pki.RR_ROOT_MARKER)
        gw_id = str(uuid.uuid4())
        node = pki.issue(rr_ca, "gw-node", "Robot Raconteur Node {%s}" % gw_id, rr_marker=tls_pki.RR_LEAF_MARKER)

        plain = gwproc.start_gateway(a.gateway, ["--tls-certificate", web.cert, "--tls-private-key", web.key])
        procs.append(plain)
        conf = os.path.join(tmp, "node.yaml")
        with open(conf, "w") as f:
            f.write("gateway:\n  node_id: \"{%s}\"\n  tls:\n    certificate: %s\n    private_key: %s\n"
                    "    node_certificate: %s\n    node_private_key: %s\n" % (gw_id, web.cert, web.key, node.cert, node.key))
        noded = gwproc.start_gateway(a.gateway, ["--config", conf])
        procs.append(noded)
        gwproc.wait_ready(plain.port)
        gwproc.wait_ready(noded.port)

        def works(url, env):
            r = official(url, "DistanceTraveled", env)
            expect(r["ok"], "official client: %s" % r.get("error"))

        # The official client's message for a failed connect is racy: its connect timer's callback
        # ignores the error code (RobotRaconteurNode_connector.cpp, connect_timer_callback), so when the
        # timer is cancelled after a failure it may report "Connection timed out" at once instead of
        # the real reason. Both are accepted where the reason is checked.
        def refused(url, env, *needles):
            r = official(url, "DistanceTraveled", env)
            expect(not r["ok"] and any(n in r["error"] for n in needles), "official client: %r" % r)
            print("    official client said: %s" % r["error"], file=sys.stderr)

        wss = "rr+wss://127.0.0.1:%d/?service=create" % plain.port
        checks.run("official rr+wss -> gateway, SSL_CERT_FILE = our CA: works",
                   lambda: works(wss, {"SSL_CERT_FILE": ca.cert}))
        checks.run("official rr+wss -> gateway without our CA: refused",
                   lambda: refused(wss, {}, "ConnectionError"))

        checks.run("official rrs+wss (STARTTLS inside a WebSocket) -> gateway: 'Server certificate not loaded'",
                   lambda: refused("rrs+wss://127.0.0.1:%d/?service=create" % plain.port, {"SSL_CERT_FILE": ca.cert},
                                   "Server certificate not loaded", "Connection timed out"))

        rrs_plain = "rrs+tcp://127.0.0.1:%d/?service=create" % plain.port
        checks.run("official rrs+tcp -> gateway with an ordinary certificate: refused (even with its CA trusted)",
                   lambda: refused(rrs_plain, {"ROBOTRACONTEUR_SSL_CERT_FILE": ca.cert}, "RobotRaconteur.ConnectionError"))
        checks.run("official rrs+tcp -> gateway with an ordinary certificate, CA not trusted: refused",
                   lambda: refused(rrs_plain, {}, "RobotRaconteur.ConnectionError"))

        rrs_node = "rrs+tcp://127.0.0.1:%d/?service=create" % noded.port
        rrs_node_id = "rrs+tcp://127.0.0.1:%d/?nodeid=%s&service=create" % (noded.port, gw_id)
        checks.run("official rrs+tcp -> gateway with an RR node certificate from our CA, CA trusted: works",
                   lambda: works(rrs_node, {"ROBOTRACONTEUR_SSL_CERT_FILE": rr_ca.cert}))
        checks.run("... also asking for the gateway's NodeID",
                   lambda: works(rrs_node_id, {"ROBOTRACONTEUR_SSL_CERT_FILE": rr_ca.cert}))
        checks.run("... refused without the CA (only the vendor's roots and the system's are trusted)",
                   lambda: refused(rrs_node, {}, "RobotRaconteur.ConnectionError"))
        checks.run("the same gateway still serves HTTPS with its web certificate",
                   lambda: expect(tls_pki.peer_subject_cn("127.0.0.1", noded.port, ca.cert) == "localhost", "CN"))

        # Ours -> official nodes.
        cfg = os.path.join(tmp, "rrconfig")
        env = dict(os.environ, ROBOTRACONTEUR_SYSTEM_CONFIG_DIR=cfg, ROBOTRACONTEUR_USER_CONFIG_DIR=cfg)
        service = [sys.executable, os.path.join(HERE, "official_service.py"), "--max-lifetime", "300", "--load-tls"]
        nocert = gwproc.Proc(service + ["--nodeid", str(uuid.uuid4())], env=env)
        procs.append(nocert)
        off_id = str(uuid.uuid4())
        off_cert = pki.issue(ca, "official-node", "Robot Raconteur Node {%s}" % off_id)
        pki.p12(off_cert, ca, os.path.join(cfg, "certificates", "{%s}.p12" % off_id))
        withcert = gwproc.Proc(service + ["--nodeid", off_id], env=env)
        procs.append(withcert)
        checks.run("official node loaded its certificate", lambda: expect(
            withcert.info.get("tls") is True and nocert.info.get("tls") is False, "%r %r" % (withcert.info, nocert.info)))

        def rr_info(url, *extra):
            return subprocess.run([a.rr, "info", url, "--timeout", "10"] + list(extra), capture_output=True, text=True,
                                  timeout=60)

        def ours_nocert():
            p = rr_info("rrs+tcp://127.0.0.1:%d/?service=interop" % nocert.port, "--tls-ca", ca.cert)
            expect(p.returncode == 3 and "Server certificate not loaded" in p.stderr, "exit %d: %s" % (p.returncode, p.stderr))
            print("    rr said: %s" % p.stderr.strip(), file=sys.stderr)

        def ours_cert():
            p = rr_info("rrs+tcp://127.0.0.1:%d/?service=interop" % withcert.port, "--tls-ca", ca.cert)
            expect(p.returncode == 0 and "service experimental.interop_test" in p.stdout, "exit %d: %s" % (p.returncode, p.stderr))
            p2 = rr_info("rrs+tcp://127.0.0.1:%d/?nodeid=%s&service=interop" % (withcert.port, off_id), "--tls-ca", ca.cert)
            expect(p2.returncode == 0, "with nodeid: exit %d: %s" % (p2.returncode, p2.stderr))

        def ours_untrusted():
            p = rr_info("rrs+tcp://127.0.0.1:%d/?service=interop" % withcert.port)
            expect(p.returncode == 3 and "certificate verify failed" in p.stderr, "exit %d: %s" % (p.returncode, p.stderr))

        checks.run("our rrs+tcp -> official node without a certificate: 'Server certificate not loaded' (3)", ours_nocert)
        checks.run("our rrs+tcp -> official node with a certificate from our CA (--tls-ca): works", ours_cert)
        checks.run("... without --tls-ca: certificate verify failed (3)", ours_untrusted)

        def gateway_device():
            dconf = os.path.join(tmp, "dev.yaml")
            with open(dconf, "w") as f:
                f.write("demo:\n  enabled: false\ndevices:\n  - name: official\n"
                        "    url: rrs+tcp://127.0.0.1:%d/?service=interop\n    tls_ca: %s\n" % (withcert.port, ca.cert))
            g = gwproc.start_gateway(a.gateway, ["--config", dconf])
            procs.append(g)
            gwproc.wait_ready(g.port, timeout=20)
            p = rr_info("rr+tcp://127.0.0.1:%d/?service=official" % g.port)
            expect(p.returncode == 0 and "service experimental.interop_test" in p.stdout, "exit %d: %s" % (p.returncode, p.stderr))

        checks.run("gateway -> official node over rrs+tcp as a device (tls_ca): served", gateway_device)
    finally:
        for p in reversed(procs):
            p.stop()
        shutil.rmtree(tmp, ignore_errors=True)
    return checks.exit_code()


if __name__ == "__main__":
    sys.exit(main())
