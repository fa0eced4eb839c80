#!/usr/bin/env python3
"""gateway-config/nginx-rr-gateway.conf in front of a real rr-gateway (docs/deployment.md).

Runs the shipped file with nginx (apt `nginx`), changing only what a site changes: the listen ports
(ephemeral on 127.0.0.1 instead of 80/443), the upstream port, the certificate (self-signed, made with
the openssl CLI) and the htpasswd file (`openssl passwd -apr1`). Then, through nginx over TLS:
`nginx -t` passes; a request without login gets 401 and /livez needs none; the JSON API answers with
a login; a foreign Origin gets 403 from nginx; a JSON WebSocket (wss, with login and the site's Origin)
subscribes to the demo Create's `packets` wire and receives values; an RR WebSocket upgrade is
accepted; plain HTTP redirects to HTTPS. With --rr, the `rr` CLI reads a device over rr+wss with the
proxy login and the self-signed certificate as its trust, and fails cleanly without either.

Usage: nginx_test.py --gateway PATH [--rr PATH] [--conf gateway-config/nginx-rr-gateway.conf]
Exit status: 0 all passed, 1 a check failed, 77 nginx or openssl missing (skip).
"""
import argparse
import base64
import http.client
import json
import os
import shutil
import ssl
import subprocess
import sys
import tempfile
import time
import urllib.request

import websocket

import gwproc
from gwproc import expect

SITE = "https://lab.example.org"
USER, PASSWORD = "alice", "wonderland"



def substitute(text, pairs):
    for old, new in pairs:
        if old not in text:
            raise RuntimeError("%r not found in the nginx config: the test no longer matches it" % old)
        text = text.replace(old, new)
    return text


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--conf", default="gateway-config/nginx-rr-gateway.conf")
    ap.add_argument("--rr", help="the rr CLI: also check it over rr+wss")
    a = ap.parse_args()
    nginx = shutil.which("nginx") or ("/usr/sbin/nginx" if os.path.exists("/usr/sbin/nginx") else None)
    if not nginx or not shutil.which("openssl"):
        print("SKIP: nginx or openssl not installed (./scripts/setup.sh installs them)")
        return 77

    checks = gwproc.Checks()
    tmp = tempfile.mkdtemp(prefix="rr-nginx-")
    gw = proc = None
    try:
        gw = gwproc.start_gateway(a.gateway, ["--allow-origin", SITE])
        gwproc.wait_ready(gw.port)
        cert, key = os.path.join(tmp, "cert.pem"), os.path.join(tmp, "key.pem")
        subprocess.run(["openssl", "req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1",
                        "-nodes", "-days", "1", "-subj", "/CN=localhost", "-keyout", key, "-out", cert],
                       check=True, capture_output=True)
        hashed = subprocess.run(["openssl", "passwd", "-apr1", PASSWORD], check=True, capture_output=True,
                                text=True).stdout.strip()
        htpasswd = os.path.join(tmp, "htpasswd")
        with open(htpasswd, "w") as f:
            f.write("%s:%s\n" % (USER, hashed))
        # nginx workers run as an unprivileged user and read the password file on every request.
        os.chmod(tmp, 0o755)
        os.chmod(htpasswd, 0o644)
        https_port, http_port = gwproc.fixed_ports(2)
        site = substitute(open(a.conf).read(), [
            ("server 127.0.0.1:8080;", "server 127.0.0.1:%d;" % gw.port),
            ("    listen 80;\n    listen [::]:80;\n", "    listen 127.0.0.1:%d;\n" % http_port),
            ("    listen 443 ssl;\n    listen [::]:443 ssl;\n", "    listen 127.0.0.1:%d ssl;\n" % https_port),
            ("/etc/ssl/certs/lab.example.org.pem", cert),
            ("/etc/ssl/private/lab.example.org.key", key),
            ("/etc/nginx/rr-gateway.htpasswd", htpasswd),
        ])
        with open(os.path.join(tmp, "site.conf"), "w") as f:
            f.write(site)
        main_conf = os.path.join(tmp, "nginx.conf")
        with open(main_conf, "w") as f:
            f.write("pid %s/nginx.pid;\nerror_log %s/error.log;\nevents {}\nhttp {\n"
                    "  access_log %s/access.log;\n  client_body_temp_path %s/body;\n  proxy_temp_path %s/proxy;\n"
                    "  include %s/site.conf;\n}\n" % (tmp, tmp, tmp, tmp, tmp, tmp))

        t = subprocess.run([nginx, "-t", "-p", tmp, "-c", main_conf], capture_output=True, text=True)
        checks.run("nginx -t accepts the config", lambda: expect(t.returncode == 0, t.stderr))
        if t.returncode != 0:
            return checks.exit_code()
        proc = subprocess.Popen([nginx, "-p", tmp, "-c", main_conf, "-g", "daemon off;"])
        base = "https://127.0.0.1:%d" % https_port
        ctx = ssl.create_default_context(cafile=cert)
        ctx.check_hostname = False  # the certificate names localhost; we connect to 127.0.0.1
        login = "Basic " + base64.b64encode(("%s:%s" % (USER, PASSWORD)).encode()).decode()

        def get(path, headers=None):
            req = urllib.request.Request(base + path, headers=headers or {})
            try:
                with urllib.request.urlopen(req, context=ctx, timeout=30) as r:
                    return r.status, r.read().decode()
            except urllib.error.HTTPError as e:
                return e.code, e.read().decode()

        deadline = time.monotonic() + 10
        while True:
            try:
                get("/livez")
                break
            except OSError:
                if time.monotonic() > deadline or proc.poll() is not None:
                    raise RuntimeError("nginx did not start")
                time.sleep(0.1)

        checks.run("no login: 401", lambda: expect(get("/api/devices")[0] == 401, "status"))
        checks.run("wrong password: 401", lambda: expect(get("/api/devices", {
            "Authorization": "Basic " + base64.b64encode(b"alice:nope").decode()})[0] == 401, "status"))
        checks.run("/livez and /readyz without login: 200",
                   lambda: expect(get("/livez")[0] == 200 and get("/readyz")[0] == 200, "status"))

        def api():
            status, body = get("/api/devices", {"Authorization": login, "Origin": SITE})
            expect(status == 200, "status %d: %s" % (status, body))
            names = [d["name"] for d in json.loads(body)]
            expect(names == ["create", "webcam"], "devices %r" % names)

        checks.run("JSON API through nginx with login and the site's Origin", api)
        checks.run("foreign Origin: 403 from nginx", lambda: expect(
            get("/api/devices", {"Authorization": login, "Origin": "https://evil.example.com"})[0] == 403, "status"))

        def json_ws():
            ws = websocket.create_connection("wss://127.0.0.1:%d/" % https_port, subprotocols=["rr-gateway.json.v1"],
                                             origin=SITE, header=["Authorization: " + login], timeout=30,
                                             sslopt={"ca_certs": cert, "check_hostname": False})
            try:
                ws.send(json.dumps({"id": 1, "op": "subscribe", "device": "create", "member": "packets"}))
                ws.send(json.dumps({"id": 2, "op": "call", "device": "create", "member": "StartStreaming"}))
                values, replies = 0, set()
                end = time.monotonic() + 10
                while time.monotonic() < end and (values < 5 or len(replies) < 2):
                    m = json.loads(ws.recv())
                    if m.get("id") in (1, 2):
                        expect("result" in m, "reply %r" % m)
                        replies.add(m["id"])
                    elif m.get("kind") == "wire":
                        expect(m["value"]["ID"] == 19, "SensorPacket ID in %r" % m)
                        values += 1
                expect(len(replies) == 2 and values >= 5, "replies %r, %d wire values" % (replies, values))
                ws.send(json.dumps({"id": 3, "op": "call", "device": "create", "member": "StopStreaming"}))
            finally:
                ws.close()

        checks.run("wss JSON WebSocket: subscribe to packets, values stream through nginx", json_ws)

        def rr_ws():
            ws = websocket.create_connection("wss://127.0.0.1:%d/?service=create" % https_port,
                                             subprotocols=["robotraconteur.robotraconteur.com"], origin=SITE,
                                             header=["Authorization: " + login], timeout=30,
                                             sslopt={"ca_certs": cert, "check_hostname": False})
            expect(ws.getsubprotocol() == "robotraconteur.robotraconteur.com", "subprotocol %r" % ws.getsubprotocol())
            ws.close()

        checks.run("wss RR WebSocket upgrade accepted (subprotocol robotraconteur.robotraconteur.com)", rr_ws)

        if a.rr:
            # The certificate names localhost, which the client verifies against the URL's host.
            url = "rr+wss://localhost:%d/?service=create" % https_port

            def rr(*extra):
                return subprocess.run([a.rr, "info", url, "--timeout", "30"] + list(extra), capture_output=True,
                                      text=True, timeout=60)

            def rr_wss():
                p = rr("--tls-ca", cert, "--http-login", "%s:%s" % (USER, PASSWORD))
                expect(p.returncode == 0, "exit %d: %s" % (p.returncode, p.stderr))
                expect("service experimental.create" in p.stdout, "no definition in %r" % p.stdout[:300])

            def rr_wss_no_login():
                p = rr("--tls-ca", cert)
                expect(p.returncode == 3 and "HTTP 401: a login is needed" in p.stderr, "exit %d: %s" % (p.returncode, p.stderr))

            def rr_wss_wrong_login():
                p = rr("--tls-ca", cert, "--http-login", "%s:nope" % USER)
                expect(p.returncode == 3 and "HTTP 401: the login was refused" in p.stderr,
                       "exit %d: %s" % (p.returncode, p.stderr))

            def rr_wss_untrusted():
                p = rr("--http-login", "%s:%s" % (USER, PASSWORD))
                expect(p.returncode == 3 and "TLS handshake" in p.stderr, "exit %d: %s" % (p.returncode, p.stderr))

            checks.run("rr info over rr+wss through nginx (CA file, proxy login)", rr_wss)
            checks.run("rr over rr+wss without the proxy login: connect failure (3), HTTP 401 named", rr_wss_no_login)
            checks.run("rr over rr+wss with a wrong proxy login: connect failure (3), HTTP 401 named", rr_wss_wrong_login)
            checks.run("rr over rr+wss not trusting the certificate: connect failure (3)", rr_wss_untrusted)

        def redirect():
            c = http.client.HTTPConnection("127.0.0.1", http_port, timeout=30)
            c.request("GET", "/api/devices", headers={"Host": "lab.example.org"})
            r = c.getresponse()
            c.close()
            expect(r.status == 301 and r.getheader("Location") == "https://lab.example.org/api/devices",
                   "redirect: %d %r" % (r.status, r.getheader("Location")))

        checks.run("plain HTTP redirects to HTTPS", redirect)
        checks.run("nginx and gateway still running", lambda: expect(proc.poll() is None and gw.alive(), "exited"))
    finally:
        if proc is not None:
            proc.terminate()
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        if gw is not None:
            gw.stop()
        shutil.rmtree(tmp, ignore_errors=True)
    return checks.exit_code()


if __name__ == "__main__":
    sys.exit(main())
