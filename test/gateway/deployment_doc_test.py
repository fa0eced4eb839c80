#!/usr/bin/env python3
"""Runs the steps of docs/deployment.md, in order, in a scratch root on loopback, so the page cannot drift.

Every ```sh block is split into commands (`\\` continuations joined, `&&` chains split, trailing
`  # comments` dropped) and each command goes through the first matching RULE below: run as written
after the REWRITES, run in an adapted form, or skipped; each adaptation and skip is printed with its
reason. ```python blocks run with this Python (the official `robotraconteur` package), ```console
blocks with `$ ` lines are run and their output compared, and the ```yaml block of lab.yaml must
match gateway-config/lab.yaml. Then checks the page promises: both htpasswd users exist, 401 without a
login, the LAN server refuses other addresses, browsers and non-RR requests, the official client gets
through it, and so on.

REWRITES (for every command that runs): `sudo ` dropped; absolute paths under /etc, /usr, /lib, /var
moved below the scratch root; robots.example.com -> localhost, with the free ports of the stand-ins:
https://HOST/ and rr+wss://HOST/ -> nginx's TLS port, HOST:8443 -> the LAN server's port,
127.0.0.1:8080 -> the gateway's port. Files the commands put in place are adapted the same way when
nginx or the gateway starts (ports, paths; the lab's devices become rr-demo-devices' `create` and
`webcam`, without the device logins they do not need).

Usage: deployment_doc_test.py --doc docs/deployment.md --build-dir BUILD --devices PATH [--cpack PATH]
Exit status: 0 all passed, 1 a check failed, 77 nginx, htpasswd, openssl or dpkg-deb missing (skip).
"""
import argparse
import glob
import os
import re
import shlex
import shutil
import socket
import ssl
import subprocess
import sys
import tempfile
import time
import urllib.request

import gwproc

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "interop"))
from doc_blocks import blocks  # noqa: E402
from gwproc import expect

PASSWORDS = {"alice": "PASSWORD", "bob": "PASSWORD-bob"}  # alice's is the one the page's examples use
HOST = "robots.example.com"



# --- the page ------------------------------------------------------------------------------------



def commands(lines):
    """Logical commands of a sh block: continuations joined, comments dropped, && chains split."""
    joined, cur = [], ""
    for line in lines:
        if line.rstrip().endswith("\\"):
            cur += line.rstrip()[:-1] + " "
            continue
        cur += line
        joined.append(cur)
        cur = ""
    out = []
    for c in joined:
        c = re.sub(r"\s{2,}#\s.*$", "", c).strip()
        if not c or c.startswith("#"):
            continue
        out.append([p.strip() for p in c.split(" && ")])
    return out


def yaml_lines(text):
    """YAML lines without comments and blank lines (the page's copy may comment more)."""
    out = []
    for l in text.splitlines():
        if l.lstrip().startswith("#"):
            continue
        l = re.sub(r"\s{2,}#.*$", "", l).rstrip()
        if l:
            out.append(l)
    return out


# --- the scratch machine ------------------------------------------------------------------------------

class Scratch:
    def __init__(self, a):
        self.a = a
        self.root = tempfile.mkdtemp(prefix="rr-deploy-")
        os.chmod(self.root, 0o755)  # nginx's workers (www-data) read below it
        self.client = os.path.join(self.root, "client")  # the official client's working folder
        self.ports = dict(zip(("gw", "https", "http", "lan"), gwproc.fixed_ports(4)))
        self.deb = None
        self.devices = None
        self.gateway = None
        self.nginx = None
        self.skipped = []
        self.adapted = []
        self.ca_bundle = None  # made by the page's update-ca-certificates
        # What a Debian 12 machine with nginx and ca-certificates has before the page starts.
        for d in ["etc/ssl/certs", "etc/ssl/private", "etc/nginx/conf.d", "etc/udev/rules.d", "usr/local/share/ca-certificates",
                  "usr/share/ca-certificates", "etc/ca-certificates/update.d", "client", "nginx-run"]:
            os.makedirs(os.path.join(self.root, d), exist_ok=True)
        open(os.path.join(self.root, "etc/ca-certificates.conf"), "w").close()

    def path(self, p):
        return self.root + p

    # Rewrites of a command line (see the module docstring).
    def rewrite(self, cmd):
        c = re.sub(r"(^|&& )sudo ", r"\1", cmd)
        p = self.ports
        c = c.replace("https://%s/" % HOST, "https://localhost:%d/" % p["https"])
        c = c.replace("rr+wss://%s/" % HOST, "rr+wss://localhost:%d/" % p["https"])
        c = c.replace("%s:8443" % HOST, "localhost:%d" % p["lan"])
        c = c.replace("127.0.0.1:8080", "127.0.0.1:%d" % p["gw"])
        c = c.replace(HOST, "localhost")
        c = re.sub(r"(?<![\w.~:/-])/(etc|usr|lib|var)/", lambda m: self.root + "/" + m.group(1) + "/", c)
        return c

    def env(self):
        e = dict(gwproc.gateway_env())
        # rr+local's system folders (used when this test runs as root) below the scratch root, never the
        # machine's /var/lib/robotraconteur: a NodeID cached there by another run would not match lab.yaml's.
        for k, d in [("RUN", "/run/robotraconteur"), ("STATE", "/var/lib/robotraconteur"), ("CONFIG", "/etc/robotraconteur")]:
            e["ROBOTRACONTEUR_SYSTEM_%s_DIR" % k] = self.path(d)
        e["PATH"] = os.pathsep.join([self.path("/usr/bin"), self.path("/usr/local/bin"), e.get("PATH", "")])
        # The client's trust: the page's CA bundle once made (§6), before that the certificate itself.
        trust = self.ca_bundle or self.path("/etc/ssl/certs/localhost.pem")
        if os.path.exists(trust):
            e["SSL_CERT_FILE"] = trust
            e["CURL_CA_BUNDLE"] = trust
        return e

    def sh(self, cmd, stdin=None, timeout=120):
        return subprocess.run(["bash", "-o", "pipefail", "-c", cmd], cwd=self.client, env=self.env(), input=stdin,
                              capture_output=True, text=True, timeout=timeout)

    def note(self, kind, what, why):
        line = "%s: %s -- %s" % (kind, what, why)
        print(line, file=sys.stderr, flush=True)
        (self.skipped if kind == "SKIPPED" else self.adapted).append(line)

    # --- adaptations ----------------------------------------------------------------------------

    def adapt_gateway_config(self):
        path = self.path("/etc/rr-gateway/gateway.yaml")
        text = open(path).read()
        text = re.sub(r"(?m)^(\s*port:\s*)8080\s*$", r"\g<1>%d" % self.ports["gw"], text)
        urls = {"arm": self.devices.info["create_url"], "camera": self.devices.info["webcam_url"]}
        text = re.sub(r"url: rr\+tcp://10\.0\.0\.20:48653/\?service=robot", "url: " + urls["arm"], text)
        text = re.sub(r"url: rr\+tcp://10\.0\.0\.21:59823/\?service=camera", "url: " + urls["camera"], text)
        text = re.sub(r"(?m)^\s*(username|password):.*\n", "", text)
        open(path, "w").write(text)
        self.note("ADAPTED", "/etc/rr-gateway/gateway.yaml",
                  "port %d; devices arm and camera are rr-demo-devices' create and webcam (no device logins)" % self.ports["gw"])

    def adapt_nginx(self):
        p = self.ports
        for conf in glob.glob(self.path("/etc/nginx/conf.d/*.conf")):
            text = open(conf).read()
            text = re.sub(r"(?m)^\s*listen \[::\]:\d+( ssl)?;\n", "", text)
            text = re.sub(r"(?m)^(\s*)listen 80;", r"\1listen 127.0.0.1:%d;" % p["http"], text)
            text = re.sub(r"(?m)^(\s*)listen 443 ssl;", r"\1listen 127.0.0.1:%d ssl;" % p["https"], text)
            text = re.sub(r"(?m)^(\s*)listen 8443 ssl;", r"\1listen 127.0.0.1:%d ssl;" % p["lan"], text)
            text = text.replace("server 127.0.0.1:8080;", "server 127.0.0.1:%d;" % p["gw"])
            text = re.sub(r"(?<![\w.~:/-])/etc/", self.root + "/etc/", text)
            open(conf, "w").write(text)
        run = self.path("/nginx-run")
        user = "user www-data www-data;\n" if os.geteuid() == 0 and self.has_user("www-data") else ""
        with open(os.path.join(run, "nginx.conf"), "w") as f:
            f.write("%spid %s/nginx.pid;\nerror_log %s/error.log;\nevents {}\nhttp {\n  access_log %s/access.log;\n"
                    "  client_body_temp_path %s/body;\n  proxy_temp_path %s/proxy;\n  include %s/*.conf;\n}\n"
                    % (user, run, run, run, run, run, self.path("/etc/nginx/conf.d")))
        self.note("ADAPTED", "/etc/nginx/conf.d/*.conf",
                  "listen on 127.0.0.1 ports %d (80), %d (443), %d (8443); upstream port %d; paths in the scratch root; "
                  "a main nginx.conf of the test (as Debian's: user www-data, conf.d/*.conf)"
                  % (p["http"], p["https"], p["lan"], p["gw"]))

    @staticmethod
    def has_user(name):
        try:
            import pwd
            pwd.getpwnam(name)
            return True
        except KeyError:
            return False

    def nginx_args(self):
        run = self.path("/nginx-run")
        return [self.a.nginx, "-p", run, "-c", os.path.join(run, "nginx.conf")]

    def reload_nginx(self):
        if self.nginx is None or self.nginx.poll() is not None:
            self.nginx = subprocess.Popen(self.nginx_args() + ["-g", "daemon off;"])
        else:
            subprocess.run(self.nginx_args() + ["-s", "reload"], check=True, capture_output=True)
            time.sleep(0.5)  # the old workers finish, the new ones read the configuration
        deadline = time.monotonic() + 10
        while True:
            try:
                socket.create_connection(("127.0.0.1", self.ports["https"]), timeout=1).close()
                return
            except OSError:
                expect(time.monotonic() < deadline and self.nginx.poll() is None, "nginx did not start")
                time.sleep(0.1)

    def stop(self):
        if self.nginx is not None and self.nginx.poll() is None:
            self.nginx.terminate()
            try:
                self.nginx.wait(10)
            except subprocess.TimeoutExpired:
                self.nginx.kill()
                self.nginx.wait()
        for p in (self.gateway, self.devices):
            if p is not None:
                p.stop()
        shutil.rmtree(self.root, ignore_errors=True)


# --- rules ----------------------------------------------------------------------------------------

def page_deb_name(cmd):
    m = re.search(r"\./build/package/(rr-gateway_[^ ]+\.deb)", cmd)
    return m.group(1) if m else None


def do_pack(s, cmd, checks):
    out = s.path("/pack")
    os.makedirs(out, exist_ok=True)
    p = subprocess.run([s.a.cpack, "--config", os.path.join(s.a.build_dir, "CPackConfig.cmake"), "-G", "DEB", "-B", out,
                        "-D", "CPACK_INSTALL_PREFIX=/usr",
                        "-D", "CPACK_DEBIAN_COMPRESSION_TYPE=none"], capture_output=True, text=True, timeout=600)
    expect(p.returncode == 0, "cpack failed: %s%s" % (p.stdout[-3000:], p.stderr[-3000:]))
    debs = glob.glob(os.path.join(out, "*.deb"))
    expect(len(debs) == 1, "cpack made %r" % debs)
    s.deb = debs[0]
    s.note("ADAPTED", cmd, "a Release build of its own takes minutes here: the test's build tree is packed with the "
           "same CPack configuration (cpack -G DEB, prefix /usr)")


def do_apt_install_deb(s, cmd, checks):
    expect(s.deb, "no package was made before")
    name = page_deb_name(cmd)
    expect(name == os.path.basename(s.deb), "the page installs %s, CPack makes %s" % (name, os.path.basename(s.deb)))
    info = subprocess.run(["dpkg-deb", "--info", s.deb], capture_output=True, text=True, check=True).stdout
    depends = subprocess.run(["dpkg-deb", "--field", s.deb, "Depends"], capture_output=True, text=True, check=True).stdout
    for lib in ("libssl3", "libyaml-cpp0.7"):
        expect(lib in depends, "Depends lacks %s: %s" % (lib, depends))
    for part in ("postinst", "prerm", "postrm", "conffiles"):
        expect(part in info, "control part %s missing:\n%s" % (part, info))
    conffiles = subprocess.run(["dpkg-deb", "--ctrl-tarfile", s.deb], capture_output=True, check=True).stdout
    expect(b"conffiles" in conffiles, "no conffiles")
    listing = subprocess.run(["dpkg-deb", "--contents", s.deb], capture_output=True, text=True, check=True).stdout
    for f in ("./usr/bin/rr-gateway", "./usr/bin/rr", "./etc/rr-gateway/gateway.yaml", "./lib/systemd/system/rr-gateway.service",
              "./usr/share/rr-gateway/examples/nginx-rr-gateway-lan.conf", "./usr/share/doc/rr-gateway/deployment.md"):
        expect(re.search(r" %s$" % re.escape(f), listing, re.M), "%s not in the package" % f)
    subprocess.run(["dpkg-deb", "--extract", s.deb, s.root], check=True)
    s.note("ADAPTED", cmd, "apt-get would install on this machine: the package is unpacked into the scratch root "
           "(dpkg-deb --extract) after checking its control data (Depends, maintainer scripts, conffiles)")


def do_cmake_install(s, cmd, checks):
    m = re.search(r"--prefix (\S+)", cmd)
    prefix = m.group(1) if m else "/usr/local"
    env = dict(os.environ, DESTDIR=s.root)
    p = subprocess.run(["cmake", "--install", s.a.build_dir, "--prefix", prefix], env=env, capture_output=True, text=True)
    expect(p.returncode == 0, "cmake --install: %s" % p.stderr[-2000:])
    expect(os.access(s.path(prefix + "/bin/rr-gateway"), os.X_OK), "no %s/bin/rr-gateway" % prefix)
    s.note("ADAPTED", cmd, "the test's build tree is installed with DESTDIR=<scratch root>")


def do_install_config(s, cmd, checks):
    c = s.rewrite(cmd.replace(" -g rr-gateway", ""))
    p = s.sh(c)
    expect(p.returncode == 0, "exit %d: %s" % (p.returncode, p.stderr))
    s.note("ADAPTED", cmd, "without -g rr-gateway: the package's postinst makes that group, not run here")


def do_start_gateway(s, cmd, checks):
    s.adapt_gateway_config()
    unit = open(s.path("/lib/systemd/system/rr-gateway.service")).read()
    exec_start = shlex.split(re.search(r"(?m)^ExecStart=(.*)$", unit).group(1))
    argv = [s.root + a if a.startswith("/") else a for a in exec_start]
    # The unit's Environment= (rr+local's folders), with systemd's %t and %S below the scratch root.
    env = s.env()
    env["HOME"] = "/nonexistent"
    for k in [k for k in env if k.startswith("XDG_")]:
        del env[k]
    for m in re.finditer(r"(?m)^Environment=(.*)$", unit):
        for item in shlex.split(m.group(1)):
            k, _, v = item.partition("=")
            v = v.replace("%t", s.path("/run")).replace("%S", s.path("/var/lib"))
            os.makedirs(v, exist_ok=True)
            env[k] = v
    s.gateway = gwproc.Proc(argv, env=env)
    gwproc.wait_ready(s.gateway.port)
    expect(s.gateway.port == s.ports["gw"], "the gateway listens on %d, not %d" % (s.gateway.port, s.ports["gw"]))
    s.note("ADAPTED", cmd, "no systemd here: the unit's ExecStart (%s) runs as a child process, with the unit's "
           "Environment= (%%t, %%S below the scratch root) and no home" % " ".join(exec_start))


def do_nginx_test(s, cmd, checks):
    s.adapt_nginx()
    p = subprocess.run(s.nginx_args() + ["-t"], capture_output=True, text=True)
    expect(p.returncode == 0, "nginx -t: %s" % p.stderr)


def do_nginx_reload(s, cmd, checks):
    s.reload_nginx()
    s.note("ADAPTED", cmd, "no systemd here: nginx runs (or reloads) with the test's main nginx.conf")


def do_htpasswd(s, cmd, checks):
    user = cmd.split()[-1]
    expect(user in PASSWORDS, "unknown user %s" % user)
    c = s.rewrite(cmd).replace("htpasswd ", "htpasswd -i ", 1)
    p = s.sh(c, stdin=PASSWORDS[user] + "\n")
    expect(p.returncode == 0, "exit %d: %s" % (p.returncode, p.stderr))
    s.note("ADAPTED", cmd, "htpasswd asks on the terminal: -i and the password on stdin")


def do_update_ca(s, cmd, checks):
    r = s.root
    c = ("update-ca-certificates --certsconf %s/etc/ca-certificates.conf --certsdir %s/usr/share/ca-certificates "
         "--localcertsdir %s/usr/local/share/ca-certificates --etccertsdir %s/etc/ssl/certs --hooksdir "
         "%s/etc/ca-certificates/update.d" % (r, r, r, r, r))
    p = s.sh(c)
    expect(p.returncode == 0, "exit %d: %s%s" % (p.returncode, p.stdout, p.stderr))
    bundle = s.path("/etc/ssl/certs/ca-certificates.crt")
    cert = open(s.path("/etc/ssl/certs/localhost.pem")).read().strip()
    expect(cert in open(bundle).read(), "the certificate is not in %s" % bundle)
    s.ca_bundle = bundle
    s.note("ADAPTED", cmd, "with the scratch root's folders (--certsconf, --certsdir, --localcertsdir, --etccertsdir, "
           "--hooksdir); clients then get SSL_CERT_FILE=<its bundle>, as OpenSSL's default file")


def do_copy_cert_to_client(s, cmd, checks):
    shutil.copy(s.path("/etc/ssl/certs/localhost.pem"), os.path.join(s.client, "localhost.pem"))
    run_as_written(s, cmd, checks)
    s.note("ADAPTED", cmd, "the certificate was copied from the server into the client's working folder first")


def run_as_written(s, cmd, checks):
    c = s.rewrite(cmd)
    p = s.sh(c)
    expect(p.returncode == 0, "`%s` exit %d: %s%s" % (c, p.returncode, p.stdout[-1500:], p.stderr[-1500:]))
    return p


def skip(reason):
    def f(s, cmd, checks):
        s.note("SKIPPED", cmd, reason)
    return f


NO_SYSTEMD = "no systemd here (PID 1 is not systemd)"
RULES = [
    (r"^\./scripts/package\.sh$", do_pack),
    (r"^sudo apt-get install \./build/package/", do_apt_install_deb),
    (r"^cmake --preset release$", skip("the test's build tree stands in for a Release build")),
    (r"^cmake --build --preset release$", skip("the test's build tree stands in for a Release build")),
    (r"^sudo cmake --install build/release", do_cmake_install),
    (r"^sudo useradd ", skip("would add a user to this machine (the package's postinst does the same)")),
    (r"^sudo chgrp rr-gateway ", skip("no rr-gateway group on this machine (see useradd)")),
    (r"certbot|/etc/letsencrypt", skip("needs a public DNS name for this machine and port 80 reachable by Let's Encrypt; "
                                       "the self-signed certificate below stands in")),
    (r"^sudo apt-get install ", skip("would install on this machine; the test needs nginx, apache2-utils and openssl "
                                     "already (it reports skipped, 77, without them)")),
    (r"^sudo install -m 640 -g rr-gateway ", do_install_config),
    (r"^sudo systemctl enable --now rr-gateway$", do_start_gateway),
    (r"^(systemctl status|journalctl) ", skip(NO_SYSTEMD)),
    (r"^sudo nginx -t$", do_nginx_test),
    (r"^sudo systemctl reload nginx$", do_nginx_reload),
    (r"htpasswd -B ", do_htpasswd),
    (r"^sudo update-ca-certificates$", do_update_ca),
    (r"^sudo chgrp www-data " if os.geteuid() != 0 else r"^$^", skip("not root: the file stays readable by all")),
    (r"^sudo cp robots\.example\.com\.pem ", do_copy_cert_to_client),
    (r"^sudo udevadm ", skip("no udev and no USB bus on this machine (test/usb covers rr+usb with an emulated device)")),
    (r"^\./docker/build\.sh|^podman ", skip("the image is built and run by ctest 'docker: the image serves the "
                                             "demo devices to the official client' (test/container), not here")),
    (r"^kubectl ", skip("no Kubernetes cluster here; ctest 'docker: Kubernetes manifests validate' checks "
                        "docker/kubernetes/rr-gateway.yaml")),
]


def process_sh(s, lines, line_no, checks):
    for chain in commands(lines):
        for cmd in chain:
            fn = next((f for pattern, f in RULES if re.search(pattern, cmd)), run_as_written)
            checks.run("line %d: %s" % (line_no, cmd), lambda fn=fn, cmd=cmd: fn(s, cmd, checks))


def process_console(s, lines, line_no, checks):
    cmds = [i for i, l in enumerate(lines) if l.startswith("$ ")]
    if not cmds:
        print("not run: line %d: an output sample (no `$ ` line)" % line_no, file=sys.stderr)
        return
    for n, i in enumerate(cmds):
        end = cmds[n + 1] if n + 1 < len(cmds) else len(lines)
        cmd, expected = lines[i][2:], [s.rewrite(l) for l in lines[i + 1:end]]

        def run(cmd=cmd, expected=expected):
            p = s.sh("{ %s ; } 2>&1" % s.rewrite(cmd))
            got = p.stdout.splitlines()
            expect(got == expected, "output %r, the page says %r" % (got, expected))

        checks.run("line %d: $ %s" % (line_no, cmd), run)


def process_python(s, lines, line_no, checks):
    code = s.rewrite("\n".join(lines))
    # The LAN server admits the page's network only; the test's client is on loopback.
    lan = s.path("/etc/nginx/conf.d/rr-gateway-lan.conf")
    text = open(lan).read()
    if "allow 127.0.0.1;" not in text:
        open(lan, "w").write(re.sub(r"(?m)^(\s*)deny\s+all;", r"\1allow 127.0.0.1;\n\1deny  all;", text, count=1))
        s.reload_nginx()
        s.note("ADAPTED", "/etc/nginx/conf.d/rr-gateway-lan.conf", "allow 127.0.0.1 added: the test's official client is on loopback")

    def run():
        p = subprocess.run([sys.executable, "-c", code], cwd=s.client, env=s.env(), capture_output=True, text=True, timeout=120)
        expect(p.returncode == 0, "exit %d: %s%s" % (p.returncode, p.stdout, p.stderr[-3000:]))
        expect("experimental.create" in p.stdout, "printed %r" % p.stdout)

    checks.run("line %d: the official Python client through the LAN server" % line_no, run)


# --- checks of what the page promises --------------------------------------------------------------

def https_get(s, port, path, headers=None):
    ctx = ssl.create_default_context(cafile=s.path("/etc/ssl/certs/localhost.pem"))
    req = urllib.request.Request("https://localhost:%d%s" % (port, path), headers=headers or {})
    # Right after `nginx -s reload` a port the new configuration adds can reset a connection while the
    # workers change over (seen under load): such a reset is retried for a few seconds.
    deadline = time.monotonic() + 10
    while True:
        try:
            with urllib.request.urlopen(req, context=ctx, timeout=10) as r:
                return r.status, r.read().decode()
        except urllib.error.HTTPError as e:
            return e.code, e.read().decode()
        except (urllib.error.URLError, ConnectionResetError) as e:
            reset = isinstance(getattr(e, "reason", e), ConnectionResetError)
            if not reset or time.monotonic() > deadline:
                raise
            time.sleep(0.2)


def check_htpasswd(s):
    users = [l.split(":")[0] for l in open(s.path("/etc/nginx/rr-gateway.htpasswd")).read().splitlines() if l]
    expect(users == ["alice", "bob"], "htpasswd holds %r: -c used more than once?" % users)


def check_login_server(s):
    expect(https_get(s, s.ports["https"], "/api/devices")[0] == 401, "no login: not 401")
    import base64
    auth = "Basic " + base64.b64encode(b"bob:PASSWORD-bob").decode()
    status, body = https_get(s, s.ports["https"], "/api/devices", {"Authorization": auth})
    expect(status == 200 and '"arm"' in body and '"camera"' in body, "bob: %d %s" % (status, body[:200]))


def check_lan_denied(s):
    status, _ = https_get(s, s.ports["lan"], "/?service=arm", {"Sec-WebSocket-Protocol": "robotraconteur.robotraconteur.com"})
    expect(status == 403, "loopback is outside the page's network, got %d" % status)


def check_lan_filters(s):
    # Allowed address now: still only RR WebSocket upgrades without Origin.
    expect(https_get(s, s.ports["lan"], "/api/devices")[0] == 403, "JSON API through the LAN server")
    expect(https_get(s, s.ports["lan"], "/metrics")[0] == 403, "/metrics through the LAN server")
    expect(https_get(s, s.ports["lan"], "/", {"Origin": "https://localhost",
                                              "Sec-WebSocket-Protocol": "robotraconteur.robotraconteur.com"})[0] == 403,
           "a browser (Origin) through the LAN server")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--doc", default="docs/deployment.md")
    ap.add_argument("--source-dir", default=os.getcwd())
    ap.add_argument("--build-dir", required=True)
    ap.add_argument("--devices", required=True, help="rr-demo-devices (the lab's devices stand in)")
    ap.add_argument("--cpack", default=shutil.which("cpack") or "cpack")
    a = ap.parse_args()
    a.nginx = shutil.which("nginx") or ("/usr/sbin/nginx" if os.path.exists("/usr/sbin/nginx") else None)
    missing = [n for n, ok in [("nginx", a.nginx), ("htpasswd", shutil.which("htpasswd")), ("openssl", shutil.which("openssl")),
                               ("dpkg-deb", shutil.which("dpkg-deb")), ("update-ca-certificates",
                                                                       shutil.which("update-ca-certificates"))] if not ok]
    if missing:
        print("SKIP: %s not installed (./scripts/setup.sh installs nginx, apache2-utils, openssl)" % ", ".join(missing))
        return 77
    os.umask(0o022)
    text = open(a.doc).read()
    checks = gwproc.Checks()
    s = Scratch(a)
    try:
        s.devices = gwproc.start_devices(a.devices)
        lab = [b for b in blocks(text) if b[0] == "yaml"]
        checks.run("the page's lab.yaml is gateway-config/lab.yaml", lambda: expect(
            lab and yaml_lines("\n".join(lab[0][1])) == yaml_lines(open(os.path.join(a.source_dir, "gateway-config/lab.yaml")).read()),
            "they differ"))
        for info, lines, line_no in blocks(text):
            if info == "sh":
                process_sh(s, lines, line_no, checks)
            elif info == "console":
                process_console(s, lines, line_no, checks)
            elif info == "python":
                process_python(s, lines, line_no, checks)
            # Checks tied to where the page has got to.
            joined = "\n".join(lines)
            if "htpasswd -B /etc/nginx/rr-gateway.htpasswd bob" in joined:
                checks.run("both users are in the htpasswd file", lambda: check_htpasswd(s))
            if info == "sh" and "rr info 'rr+wss://" in joined:
                checks.run("the login server: 401 without a login, the devices with bob's", lambda: check_login_server(s))
            if info == "sh" and "rr-gateway-lan.conf" in joined:
                checks.run("the LAN server refuses addresses outside its allow lines (403)", lambda: check_lan_denied(s))
            if info == "python":
                checks.run("the LAN server passes only RR WebSockets without Origin", lambda: check_lan_filters(s))
        checks.run("every sh block ran or was skipped with a reason; gateway and nginx still up", lambda: expect(
            s.gateway is not None and s.gateway.alive() and s.nginx is not None and s.nginx.poll() is None, "not running"))
    finally:
        s.stop()
    print("skipped steps (%d):" % len(s.skipped), file=sys.stderr)
    for l in s.skipped:
        print("  " + l, file=sys.stderr)
    return checks.exit_code()


if __name__ == "__main__":
    sys.exit(main())
