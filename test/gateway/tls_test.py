#!/usr/bin/env python3
"""rr-gateway serving TLS itself (docs/security.md), from outside, with certificates made by the openssl CLI.

Cases (--case):
  serve   HTTPS /livez and plain HTTP on the same port; the JSON API over wss (a wire subscription
          streams); the rr CLI over rrs+tcp and rr+wss with --tls-ca, plain rr+tcp still served, and a
          connect failure (3) without the CA; hostile peers (garbage after 0x16, a TLS peer that sends
          neither RR nor HTTP gets HTTP's 400, a stalled handshake is closed) and the gateway keeps
          serving; /metrics counts the TLS failures.
  sighup  a wss JSON subscription stays open while the certificate files are replaced and SIGHUP is
          sent; new connections get the new certificate; a bad file on the next SIGHUP is logged and
          the certificate in use stays.
  mtls    client_ca set: HTTPS, wss (the JSON API), rrs+tcp and rr+wss without a client certificate
          (or with one of another CA) are refused in the handshake, with one they work; with
          required: true plain HTTP gets 403 and plain rr+tcp is refused. Then the client_ca file is
          replaced by another CA and SIGHUP sent: new connections need a certificate of the new CA
          (the old one's are refused); a broken client_ca file on the next SIGHUP changes nothing.
  device  a gateway whose device is another gateway's demo device over rrs+tcp (tls_ca in the
          device entry): ready, and a value read through it.
  config  bad TLS files stop the start (exit 2) naming the file; --check does the same.

Usage: tls_test.py --gateway PATH --rr PATH --case CASE
Exit status: 0 all passed, 1 a check failed, 77 openssl or the venv's modules missing (skip).
"""
import argparse
import json
import os
import shutil
import signal
import socket
import ssl
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "interop"))

import gwproc  # noqa: E402
from gwproc import expect  # noqa: E402
import tls_pki  # noqa: E402

try:
    import websocket  # noqa: E402
except ImportError:
    websocket = None


def https_get(port, path, cafile, cert=None, timeout=30):
    """(status, body) of GET https://127.0.0.1:port/path, verified against cafile (the certificates made
    here name 127.0.0.1 and localhost)."""
    import http.client
    ctx = ssl.create_default_context(cafile=cafile)
    if cert:
        ctx.load_cert_chain(cert.cert, cert.key)
    c = http.client.HTTPSConnection("127.0.0.1", port, context=ctx, timeout=timeout)
    try:
        c.request("GET", path)
        r = c.getresponse()
        return r.status, r.read().decode("utf-8", "replace")
    finally:
        c.close()


def wait_ready_https(port, cafile, cert=None, timeout=30.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        try:
            if https_get(port, "/readyz", cafile, cert=cert, timeout=2)[0] == 200:
                return
        except OSError:
            pass
        time.sleep(0.1)
    raise RuntimeError("gateway not ready over HTTPS within %.0f s" % timeout)


def rr_cli(rr, *args, timeout=60, env=None):
    return subprocess.run([rr] + list(args), capture_output=True, text=True, timeout=timeout, env=env)


def closed_within(sock, seconds):
    """True when the peer closes `sock` within `seconds` (reads and discards anything it sends)."""
    sock.settimeout(0.2)
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        try:
            if not sock.recv(4096):
                return True
        except socket.timeout:
            continue
        except OSError:
            return True
    return False


def json_ws_subscribe(port, cafile, origin=None):
    """A wss JSON API WebSocket subscribed to the demo Create's packets wire (streaming started)."""
    ws = websocket.create_connection("wss://localhost:%d/" % port, subprotocols=["rr-gateway.json.v1"], timeout=30,
                                     origin=origin or "https://localhost:%d" % port, sslopt={"ca_certs": cafile})
    ws.send(json.dumps({"id": 1, "op": "subscribe", "device": "create", "member": "packets"}))
    ws.send(json.dumps({"id": 2, "op": "call", "device": "create", "member": "StartStreaming"}))
    return ws


def wire_values(ws, n, seconds=10):
    """Reads until n wire values arrived; returns how many did."""
    got, end = 0, time.monotonic() + seconds
    while got < n and time.monotonic() < end:
        m = json.loads(ws.recv())
        if m.get("kind") == "wire":
            got += 1
    return got


def make_pki(tmp):
    pki = tls_pki.Pki(os.path.join(tmp, "pki"))
    ca = pki.ca("ca", "Test CA")
    server = pki.issue(ca, "server", "gateway.test", sans=("DNS:localhost", "IP:127.0.0.1"))
    return pki, ca, server


def case_serve(a, checks, tmp):
    pki, ca, server = make_pki(tmp)
    gw = gwproc.start_gateway(a.gateway, ["--tls-certificate", server.cert, "--tls-private-key", server.key,
                                          "--log-level", "debug"])
    try:
        gwproc.wait_ready(gw.port)
        port = gw.port
        checks.run("ready line says tls", lambda: expect(gw.info.get("tls") is True, "ready line %r" % gw.info))
        checks.run("HTTPS /livez", lambda: expect(https_get(port, "/livez", ca.cert) == (200, "ok\n"), "status"))
        checks.run("plain HTTP /livez on the same port",
                   lambda: expect(gwproc.http_status("http://127.0.0.1:%d/livez" % port)[0] == 200, "status"))

        def api():
            status, body = https_get(port, "/api/devices", ca.cert)
            expect(status == 200 and [d["name"] for d in json.loads(body)] == ["create", "webcam"], "%d %s" % (status, body))

        checks.run("JSON API over HTTPS", api)

        def wss_json():
            ws = json_ws_subscribe(port, ca.cert)
            try:
                expect(wire_values(ws, 5) >= 5, "fewer than 5 wire values over wss")
            finally:
                ws.close()

        checks.run("JSON API WebSocket over wss: a wire subscription streams", wss_json)

        for scheme in ("rrs+tcp", "rr+wss"):
            def rr_ok(scheme=scheme):
                p = rr_cli(a.rr, "get", "%s://localhost:%d/?service=create" % (scheme, port), "DistanceTraveled",
                           "--tls-ca", ca.cert, "--timeout", "30")
                expect(p.returncode == 0 and p.stdout.strip().lstrip("-").isdigit(), "exit %d: %s %s" % (p.returncode, p.stdout, p.stderr))

            checks.run("rr get over %s with --tls-ca" % scheme, rr_ok)

        def rr_untrusted():
            p = rr_cli(a.rr, "get", "rrs+tcp://localhost:%d/?service=create" % port, "DistanceTraveled", "--timeout", "30")
            expect(p.returncode == 3 and "certificate verify failed" in p.stderr, "exit %d: %s" % (p.returncode, p.stderr))

        checks.run("rr over rrs+tcp not trusting the certificate: connect failure (3)", rr_untrusted)

        def rr_system_store():
            # Without --tls-ca rr trusts OpenSSL's default store; SSL_CERT_FILE points that store at the
            # test CA here, as update-ca-certificates would put it in /etc/ssl/certs.
            for scheme in ("rrs+tcp", "rr+wss"):
                p = rr_cli(a.rr, "get", "%s://localhost:%d/?service=create" % (scheme, port), "DistanceTraveled",
                           "--timeout", "30", env=dict(os.environ, SSL_CERT_FILE=ca.cert))
                expect(p.returncode == 0 and p.stdout.strip().lstrip("-").isdigit(),
                       "%s: exit %d: %s %s" % (scheme, p.returncode, p.stdout, p.stderr))

        checks.run("rr over rrs+tcp and rr+wss trusting the system store (SSL_CERT_FILE), no --tls-ca", rr_system_store)

        def secure_cookie():
            # With logins on, the dashboard's session cookie is Secure over the gateway's own HTTPS.
            import hashlib
            import http.client
            users = os.path.join(tmp, "users.txt")
            with open(users, "w") as f:
                f.write("ann %s operator\n" % hashlib.md5(b"ann-pw").hexdigest())
            conf = os.path.join(tmp, "auth.yaml")
            with open(conf, "w") as f:
                f.write("gateway:\n  tls: {certificate: %s, private_key: %s}\n  auth:\n    users: %s\n"
                        "    roles:\n      operator:\n        - allow: [read, write, call]\n" % (server.cert, server.key, users))
            g2 = gwproc.start_gateway(a.gateway, ["--config", conf, "--no-demo"])
            try:
                gwproc.wait_ready(g2.port)
                c = http.client.HTTPSConnection("127.0.0.1", g2.port, context=ssl.create_default_context(cafile=ca.cert),
                                                timeout=30)
                try:
                    c.request("POST", "/api/login", json.dumps({"username": "ann", "password": "ann-pw"}),
                              {"Content-Type": "application/json"})
                    r = c.getresponse()
                    r.read()
                    cookie = r.getheader("Set-Cookie", "")
                    expect(r.status == 200 and "Secure" in cookie and "HttpOnly" in cookie, "%d %r" % (r.status, cookie))
                finally:
                    c.close()
            finally:
                g2.stop()

        checks.run("with logins on, the session cookie is Secure over the gateway's own HTTPS", secure_cookie)

        def rr_plain():
            p = rr_cli(a.rr, "get", "rr+tcp://127.0.0.1:%d/?service=create" % port, "DistanceTraveled", "--timeout", "30")
            expect(p.returncode == 0, "exit %d: %s" % (p.returncode, p.stderr))

        checks.run("plain rr+tcp on the same port", rr_plain)

        def garbage_after_0x16():
            with socket.create_connection(("127.0.0.1", port), timeout=5) as s:
                s.sendall(b"\x16\x03\x01\x00\x05" + b"\xff" * 64)
                expect(closed_within(s, 7), "not closed")

        def tls_then_junk():
            ctx = ssl.create_default_context(cafile=ca.cert)
            with ctx.wrap_socket(socket.create_connection(("127.0.0.1", port), timeout=5), server_hostname="localhost") as s:
                s.sendall(b"\x00\x01\x02\x03 not http at all\r\n\r\n")
                data = b""
                try:
                    while True:
                        chunk = s.recv(4096)
                        if not chunk:
                            break
                        data += chunk
                except (ssl.SSLError, OSError):
                    pass
                expect(data.startswith(b"HTTP/1.1 400"), "answer %r" % data[:80])

        def stalled_handshake():
            with socket.create_connection(("127.0.0.1", port), timeout=5) as s:
                s.sendall(b"\x16\x03\x01")
                t0 = time.monotonic()
                expect(closed_within(s, 9), "not closed within 9 s")
                expect(time.monotonic() - t0 >= 3, "closed after %.1f s, before the first-bytes timeout" % (time.monotonic() - t0))

        checks.run("garbage after 0x16: closed", garbage_after_0x16)
        checks.run("a TLS peer sending neither RR nor HTTP gets 400", tls_then_junk)
        checks.run("a stalled TLS handshake is closed at the first-bytes timeout (5 s)", stalled_handshake)
        checks.run("still serving HTTPS after the hostile peers",
                   lambda: expect(https_get(port, "/livez", ca.cert)[0] == 200, "status"))

        def metrics():
            status, body = https_get(port, "/metrics", ca.cert)
            line = [l for l in body.splitlines() if l.startswith("rr_gateway_tls_failures_total ")]
            expect(line and float(line[0].split()[1]) >= 2, "rr_gateway_tls_failures_total: %r" % line)

        checks.run("/metrics counts the TLS failures", metrics)
        checks.run("gateway still running", lambda: expect(gw.alive(), "exited"))
    finally:
        status = gw.stop()
        checks.run("gateway exits 0 on SIGTERM", lambda: expect(status == 0, "exit %r" % status))


def case_sighup(a, checks, tmp):
    pki, ca, first = make_pki(tmp)
    second = pki.issue(ca, "second", "renewed.test", sans=("DNS:localhost", "IP:127.0.0.1"))
    cert, key = os.path.join(tmp, "live.pem"), os.path.join(tmp, "live.key")
    shutil.copy(first.cert, cert)
    shutil.copy(first.key, key)
    gw = gwproc.start_gateway(a.gateway, ["--tls-certificate", cert, "--tls-private-key", key])
    try:
        gwproc.wait_ready(gw.port)
        port = gw.port
        checks.run("first certificate served",
                   lambda: expect(tls_pki.peer_subject_cn("127.0.0.1", port, ca.cert) == "gateway.test", "CN"))
        ws = json_ws_subscribe(port, ca.cert)
        try:
            checks.run("wss subscription streams", lambda: expect(wire_values(ws, 3) >= 3, "no values"))
            shutil.copy(second.cert, cert)
            shutil.copy(second.key, key)
            os.kill(gw.pid, signal.SIGHUP)

            def new_cert():
                end = time.monotonic() + 5
                cn = None
                while time.monotonic() < end:
                    cn = tls_pki.peer_subject_cn("127.0.0.1", port, ca.cert)
                    if cn == "renewed.test":
                        return
                    time.sleep(0.1)
                raise AssertionError("new connections still get CN=%s" % cn)

            checks.run("after SIGHUP new connections get the new certificate", new_cert)
            checks.run("the open wss WebSocket keeps streaming across the swap",
                       lambda: expect(wire_values(ws, 5) >= 5, "fewer than 5 values after SIGHUP"))

            shutil.copy(first.key, key)  # a key that does not match the certificate
            os.kill(gw.pid, signal.SIGHUP)
            time.sleep(1.0)
            checks.run("a bad file on SIGHUP keeps the certificate in use",
                       lambda: expect(tls_pki.peer_subject_cn("127.0.0.1", port, ca.cert) == "renewed.test", "CN"))
            checks.run("... and the open WebSocket still streams", lambda: expect(wire_values(ws, 3) >= 3, "no values"))
        finally:
            ws.close()
        checks.run("gateway still running", lambda: expect(gw.alive(), "exited"))
    finally:
        status = gw.stop()
        checks.run("gateway exits 0 on SIGTERM", lambda: expect(status == 0, "exit %r" % status))


def case_mtls(a, checks, tmp):
    pki, ca, server = make_pki(tmp)
    client_ca = pki.ca("client-ca", "Client CA")
    client = pki.issue(client_ca, "alice", "alice", client=True)
    rogue_ca = pki.ca("rogue-ca", "Rogue CA")
    rogue = pki.issue(rogue_ca, "mallory", "mallory", client=True)
    live_ca = os.path.join(tmp, "client-ca-live.pem")  # replaced below, then SIGHUP
    shutil.copy(client_ca.cert, live_ca)
    gw = gwproc.start_gateway(a.gateway, ["--tls-certificate", server.cert, "--tls-private-key", server.key,
                                          "--tls-client-ca", live_ca, "--tls-required"])
    try:
        port = gw.port
        wait_ready_https(port, ca.cert, cert=client)
        checks.run("HTTPS with a client certificate", lambda: expect(https_get(port, "/livez", ca.cert, cert=client)[0] == 200, "status"))

        def refused(cert):
            try:
                https_get(port, "/livez", ca.cert, cert=cert)
            except (ssl.SSLError, ConnectionError, OSError) as e:
                return str(e)
            raise AssertionError("served without an accepted client certificate")

        checks.run("HTTPS without a client certificate: refused in the handshake", lambda: refused(None))
        checks.run("HTTPS with a certificate of another CA: refused", lambda: refused(rogue))

        url = "rrs+tcp://localhost:%d/?service=create" % port

        def rr_with():
            p = rr_cli(a.rr, "get", url, "DistanceTraveled", "--tls-ca", ca.cert, "--tls-cert", client.cert,
                       "--tls-key", client.key, "--timeout", "30")
            expect(p.returncode == 0, "exit %d: %s" % (p.returncode, p.stderr))

        def rr_without():
            p = rr_cli(a.rr, "get", url, "DistanceTraveled", "--tls-ca", ca.cert, "--timeout", "30")
            expect(p.returncode == 3, "exit %d: %s" % (p.returncode, p.stderr))

        checks.run("rr over rrs+tcp with a client certificate", rr_with)
        checks.run("rr over rrs+tcp without one: connect failure (3)", rr_without)

        def plain_http():
            status, body = gwproc.http_status("http://127.0.0.1:%d/livez" % port)
            expect(status == 403 and "TLS required" in body, "%d %r" % (status, body))

        def plain_rr():
            p = rr_cli(a.rr, "get", "rr+tcp://127.0.0.1:%d/?service=create" % port, "DistanceTraveled", "--timeout", "5")
            expect(p.returncode == 3, "exit %d: %s" % (p.returncode, p.stderr))

        checks.run("required: plain HTTP gets 403", plain_http)
        checks.run("required: plain rr+tcp is refused (3)", plain_rr)

        def wss_json(cert):
            """The answer to a JSON API request over wss presenting `cert` (or none); raises when the
            connection fails. An HTTP refusal would mean the handshake passed: that is a failure too."""
            sslopt = {"ca_certs": ca.cert}
            if cert:
                sslopt.update(certfile=cert.cert, keyfile=cert.key)
            ws = websocket.create_connection("wss://localhost:%d/" % port, subprotocols=["rr-gateway.json.v1"],
                                             timeout=30, origin="https://localhost:%d" % port, sslopt=sslopt)
            try:
                ws.send(json.dumps({"id": 1, "op": "devices"}))
                return json.loads(ws.recv())
            finally:
                ws.close()

        def wss_refused(cert):
            try:
                answer = wss_json(cert)
            except websocket.WebSocketBadStatusException as e:
                raise AssertionError("the TLS handshake passed, HTTP refused: %s" % e)
            except (ssl.SSLError, OSError, websocket.WebSocketException) as e:
                return str(e)
            raise AssertionError("served without an accepted client certificate: %r" % answer)

        def wss_with(cert):
            answer = wss_json(cert)
            expect(answer.get("id") == 1 and "result" in answer, "answer %r" % answer)

        def rr_wss(cert, status):
            extra = ["--tls-cert", cert.cert, "--tls-key", cert.key] if cert else []
            p = rr_cli(a.rr, "get", "rr+wss://localhost:%d/?service=create" % port, "DistanceTraveled",
                       "--tls-ca", ca.cert, "--timeout", "30", *extra)
            expect(p.returncode == status, "exit %d (expected %d): %s" % (p.returncode, status, p.stderr))

        checks.run("wss (JSON API) with a client certificate", lambda: wss_with(client))
        checks.run("wss without a client certificate: refused in the handshake", lambda: wss_refused(None))
        checks.run("wss with a certificate of another CA: refused", lambda: wss_refused(rogue))
        checks.run("rr over rr+wss with a client certificate", lambda: rr_wss(client, 0))
        checks.run("rr over rr+wss without one: connect failure (3)", lambda: rr_wss(None, 3))

        # SIGHUP reads client_ca again: the rogue CA's certificates are now the accepted ones.
        shutil.copy(rogue_ca.cert, live_ca)
        os.kill(gw.pid, signal.SIGHUP)

        def swapped():
            end = time.monotonic() + 5
            while True:
                try:
                    if https_get(port, "/livez", ca.cert, cert=rogue)[0] == 200:
                        return
                except OSError:
                    pass
                if time.monotonic() > end:
                    raise AssertionError("a certificate of the new client CA is still refused after SIGHUP")
                time.sleep(0.1)

        def rr_rrs(cert, status):
            p = rr_cli(a.rr, "get", url, "DistanceTraveled", "--tls-ca", ca.cert, "--tls-cert", cert.cert,
                       "--tls-key", cert.key, "--timeout", "30")
            expect(p.returncode == status, "exit %d (expected %d): %s" % (p.returncode, status, p.stderr))

        checks.run("SIGHUP with a new client_ca file: its certificates are accepted", swapped)
        checks.run("... and the old CA's are refused (HTTPS)", lambda: refused(client))
        checks.run("... and over rrs+tcp (new CA accepted, old refused)",
                   lambda: (rr_rrs(rogue, 0), rr_rrs(client, 3)))
        checks.run("... and over wss (new CA accepted, old refused)", lambda: (wss_with(rogue), wss_refused(client)))
        with open(live_ca, "w") as f:
            f.write("not a certificate\n")
        os.kill(gw.pid, signal.SIGHUP)
        time.sleep(1.0)
        checks.run("a broken client_ca file on SIGHUP changes nothing",
                   lambda: (expect(https_get(port, "/livez", ca.cert, cert=rogue)[0] == 200, "new CA refused"),
                            refused(client)))
        checks.run("gateway still running", lambda: expect(gw.alive(), "exited"))
    finally:
        status = gw.stop()
        checks.run("gateway exits 0 on SIGTERM", lambda: expect(status == 0, "exit %r" % status))


def case_device(a, checks, tmp):
    pki, ca, server = make_pki(tmp)
    far = gwproc.start_gateway(a.gateway, ["--tls-certificate", server.cert, "--tls-private-key", server.key,
                                           "--robotraconteur-nodename", "far.gateway"])
    near = None
    try:
        gwproc.wait_ready(far.port)
        conf = os.path.join(tmp, "near.yaml")
        with open(conf, "w") as f:
            f.write("demo:\n  enabled: false\ndevices:\n  - name: far_create\n"
                    "    url: rrs+tcp://localhost:%d/?nodename=far.gateway&service=create\n"
                    "    tls_ca: %s\n" % (far.port, ca.cert))
        near = gwproc.start_gateway(a.gateway, ["--config", conf])

        def ready():
            gwproc.wait_ready(near.port, timeout=20)

        checks.run("the gateway reaches its device over rrs+tcp (/readyz)", ready)

        def read_through():
            p = rr_cli(a.rr, "get", "rr+tcp://127.0.0.1:%d/?service=far_create" % near.port, "DistanceTraveled",
                       "--timeout", "30")
            expect(p.returncode == 0 and p.stdout.strip().lstrip("-").isdigit(), "exit %d: %s %s" % (p.returncode, p.stdout, p.stderr))

        checks.run("a value read through gateway -> rrs+tcp -> gateway -> demo device", read_through)

        def untrusted():
            conf2 = os.path.join(tmp, "untrusted.yaml")
            with open(conf2, "w") as f:
                f.write("demo:\n  enabled: false\ndevices:\n  - name: far_create\n"
                        "    url: rrs+tcp://localhost:%d/?service=create\n" % far.port)
            g = gwproc.start_gateway(a.gateway, ["--config", conf2])
            try:
                end = time.monotonic() + 10
                body = ""
                while time.monotonic() < end:
                    status, body = gwproc.http_status("http://127.0.0.1:%d/readyz" % g.port)
                    if "certificate verify failed" in body:
                        break
                    time.sleep(0.2)
                expect(status == 503 and "certificate verify failed" in body, "readyz %d %r" % (status, body))
            finally:
                g.stop()

        checks.run("without tls_ca the device is not trusted (/readyz says why)", untrusted)
    finally:
        if near:
            near.stop()
        far.stop()


def case_config(a, checks, tmp):
    pki, ca, server = make_pki(tmp)
    other = pki.issue(ca, "other", "other")
    junk = os.path.join(tmp, "junk.pem")
    with open(junk, "w") as f:
        f.write("not a certificate\n")
    missing = os.path.join(tmp, "missing.pem")

    def start(args):
        return subprocess.run([a.gateway, "--listen", "127.0.0.1", "--port", "0", "--no-local", "--no-demo"] + args,
                              capture_output=True, text=True, timeout=30)

    for name, args, needle in [
        ("unreadable certificate", ["--tls-certificate", missing, "--tls-private-key", server.key],
         missing + ": cannot read: No such file or directory"),
        ("key of another certificate", ["--tls-certificate", server.cert, "--tls-private-key", other.key],
         other.key + ": the private key does not match the certificate in " + server.cert),
        ("not PEM", ["--tls-certificate", junk, "--tls-private-key", server.key], junk + ": no PEM certificate chain"),
        ("unreadable client CA", ["--tls-certificate", server.cert, "--tls-private-key", server.key,
                                  "--tls-client-ca", missing], missing + ": cannot read"),
        ("certificate without key", ["--tls-certificate", server.cert], "gateway.tls.private_key: missing"),
    ]:
        for check in (False, True):
            def one(args=args, needle=needle, check=check):
                r = start(args + (["--check"] if check else []))
                expect(r.returncode == 2, "exit %d" % r.returncode)
                expect("configuration error" in r.stderr and needle in r.stderr, "stderr %r" % r.stderr)

            checks.run("%s: exit 2 naming it%s" % (name, " (--check)" if check else ""), one)

    def good_check():
        r = start(["--tls-certificate", server.cert, "--tls-private-key", server.key, "--check"])
        expect(r.returncode == 0 and "(TLS)" in r.stdout, "exit %d: %s %s" % (r.returncode, r.stdout, r.stderr))

    checks.run("good files pass --check", good_check)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--rr", required=True)
    ap.add_argument("--case", required=True, choices=["serve", "sighup", "mtls", "device", "config"])
    a = ap.parse_args()
    if not tls_pki.have_openssl():
        print("SKIP: openssl not installed (./scripts/setup.sh installs it)")
        return 77
    if websocket is None:
        print("SKIP: websocket-client missing from the venv (./scripts/setup.sh)")
        return 77
    checks = gwproc.Checks()
    tmp = tempfile.mkdtemp(prefix="rr-tls-")
    try:
        {"serve": case_serve, "sighup": case_sighup, "mtls": case_mtls, "device": case_device,
         "config": case_config}[a.case](a, checks, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return checks.exit_code()


if __name__ == "__main__":
    sys.exit(main())
