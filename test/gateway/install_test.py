#!/usr/bin/env python3
"""`cmake --install` into a scratch DESTDIR, then the installed gateway runs (packaging/CMakeLists.txt).

Checks, for --prefix /usr (the Debian package's layout) and for another prefix (/opt/rr-gateway):
  * the tree: the four binaries in PREFIX/bin; examples, docs and (when web/dist was built) the
    dashboard under PREFIX/share; the configuration in /etc (PREFIX/etc for other prefixes), mode 0640;
    the systemd unit in /lib/systemd/system (PREFIX/lib/systemd/system) whose ExecStart names the
    installed binary and configuration and which has the hardening options; nothing else (no tests,
    no static libraries, no headers);
  * `systemd-analyze verify` accepts the unit (when systemd-analyze exists);
  * the installed gateway started as the unit starts it (its ExecStart below DESTDIR, on a free port),
    from / and found on PATH: /readyz, the demo devices in the JSON API, its dashboard served from
    PREFIX/share/rr-gateway/web (a marker page is installed there when web/dist was not built, so the
    lookup is checked either way), the installed `rr` reads a device through it; then SIGTERM ends it
    with status 0.

Usage: install_test.py --build-dir BUILD [--source-dir SRC]
Exit status: 0 all passed, 1 a check failed.
"""
import argparse
import os
import re
import shlex
import shutil
import stat
import subprocess
import sys
import tempfile
import urllib.request

import gwproc
from gwproc import expect

BINARIES = ["rr-gateway", "rr", "rr-robdef", "rr-demo-devices"]
EXAMPLES = ["demo.yaml", "lab.yaml", "reynard.yaml", "secure.yaml", "nginx-rr-gateway.conf", "nginx-rr-gateway-lan.conf",
            "70-robotraconteur-usb.rules"]
HARDENING = ["NoNewPrivileges=yes", "ProtectSystem=strict", "ProtectHome=yes", "PrivateTmp=yes", "PrivateDevices=yes",
             "CapabilityBoundingSet=", "RestrictAddressFamilies=AF_UNIX AF_INET AF_INET6 AF_NETLINK", "SystemCallFilter=@system-service",
             "MemoryDenyWriteExecute=yes", "User=rr-gateway"]


def layout(prefix):
    """(etc, unit folder) for a prefix, as packaging/CMakeLists.txt chooses them."""
    if prefix == "/usr":
        return "/etc", "/lib/systemd/system"
    return prefix + "/etc", prefix + "/lib/systemd/system"


def install(build, destdir, prefix):
    env = dict(os.environ, DESTDIR=destdir)
    p = subprocess.run(["cmake", "--install", build, "--prefix", prefix], env=env, capture_output=True, text=True)
    expect(p.returncode == 0, "cmake --install failed: %s%s" % (p.stdout[-2000:], p.stderr[-2000:]))


def unit_exec_start(unit_text):
    m = re.search(r"^ExecStart=(.*)$", unit_text, re.M)
    expect(m, "no ExecStart in the unit")
    return shlex.split(m.group(1))


def check_tree(src, dest, prefix, checks):
    etc, units = layout(prefix)
    root = lambda p: dest + p  # noqa: E731 (an absolute install path below DESTDIR)

    def binaries():
        for b in BINARIES:
            path = root("%s/bin/%s" % (prefix, b))
            expect(os.path.isfile(path) and os.access(path, os.X_OK), "%s missing or not executable" % path)

    def shared():
        for e in EXAMPLES:
            expect(os.path.isfile(root("%s/share/rr-gateway/examples/%s" % (prefix, e))), "example %s missing" % e)
        expect(os.path.isfile(root("%s/share/doc/rr-gateway/deployment.md" % prefix)), "docs missing")
        web = root("%s/share/rr-gateway/web/index.html" % prefix)
        if os.path.isfile(os.path.join(src, "web/dist/index.html")):
            expect(os.path.isfile(web), "web/dist was built but %s is missing" % web)
        else:
            expect(not os.path.exists(web), "%s installed without web/dist" % web)
            print("note: web/dist not built: no dashboard installed (a marker page stands in below)", file=sys.stderr)

    def config():
        path = root(etc + "/rr-gateway/gateway.yaml")
        expect(os.path.isfile(path), "%s missing" % path)
        mode = stat.S_IMODE(os.stat(path).st_mode)
        expect(mode == 0o640, "gateway.yaml has mode %o, not 640 (it may hold device passwords)" % mode)
        expect(open(path).read() == open(os.path.join(src, "packaging/gateway.yaml")).read(), "not packaging/gateway.yaml")

    def unit():
        path = root(units + "/rr-gateway.service")
        expect(os.path.isfile(path), "%s missing" % path)
        text = open(path).read()
        expect(unit_exec_start(text) == ["%s/bin/rr-gateway" % prefix, "--config", etc + "/rr-gateway/gateway.yaml"],
               "ExecStart is %r" % unit_exec_start(text))
        lines = set(l.strip() for l in text.splitlines())
        missing = [h for h in HARDENING if h not in lines]
        expect(not missing, "hardening options missing: %r" % missing)
        expect(not re.search(r"@RR_[A-Z]+@", text), "unsubstituted @RR_…@ in the unit")

    def nothing_else():
        allowed = [root(prefix + "/bin/"), root(prefix + "/share/rr-gateway/"), root(prefix + "/share/doc/rr-gateway/"),
                   root(etc + "/rr-gateway/"), root(units + "/")]
        stray = []
        for d, _, files in os.walk(dest):
            for f in files:
                p = os.path.join(d, f)
                if not any(p.startswith(a) for a in allowed):
                    stray.append(p[len(dest):])
        expect(not stray, "installed outside the documented layout: %r" % stray[:10])
        bins = sorted(os.listdir(root(prefix + "/bin")))
        expect(bins == sorted(BINARIES), "bin holds %r" % bins)

    for name, fn in [("binaries", binaries), ("examples, docs, dashboard", shared), ("configuration, mode 0640", config),
                     ("systemd unit: ExecStart and hardening", unit), ("nothing else installed", nothing_else)]:
        checks.run("prefix %s: %s" % (prefix, name), fn)


def verify_unit(dest, prefix, checks):
    tool = shutil.which("systemd-analyze")
    if not tool:
        print("note: systemd-analyze missing: unit not verified", file=sys.stderr)
        return
    _, units = layout(prefix)

    def verify():
        # A copy whose ExecStart names the files below DESTDIR (verify wants an existing executable);
        # systemd-analyze reports unknown keys and values on stderr and still exits 0: any line fails.
        text = open(dest + units + "/rr-gateway.service").read()
        argv = [dest + a if a.startswith("/") else a for a in unit_exec_start(text)]
        tmp = tempfile.mkdtemp(prefix="rr-unit-")
        try:
            path = os.path.join(tmp, "rr-gateway.service")
            with open(path, "w") as f:
                f.write(re.sub(r"(?m)^ExecStart=.*$", "ExecStart=" + " ".join(argv), text))
            p = subprocess.run([tool, "verify", path], capture_output=True, text=True, timeout=60)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
        out = (p.stdout + p.stderr).strip()
        expect(p.returncode == 0 and not out, "exit %d: %s" % (p.returncode, out))

    checks.run("prefix %s: systemd-analyze verify accepts the unit" % prefix, verify)


def service_environment(unit_text, dest):
    """The unit's Environment= with %t (/run) and %S (/var/lib) below `dest`, and the folders its
    RuntimeDirectory= and StateDirectory= name, made there. Returns (variables, folders made)."""
    spec = {"%t": dest + "/run", "%S": dest + "/var/lib"}
    made = []
    for key, base in [("RuntimeDirectory", spec["%t"]), ("StateDirectory", spec["%S"])]:
        for m in re.finditer(r"(?m)^%s=(.*)$" % key, unit_text):
            for name in m.group(1).split():
                d = os.path.join(base, name)
                os.makedirs(d, exist_ok=True)
                os.chmod(base, 0o755)
                made.append(d)
    variables = {}
    for m in re.finditer(r"(?m)^Environment=(.*)$", unit_text):
        for item in shlex.split(m.group(1)):
            k, _, v = item.partition("=")
            for sp, path in spec.items():
                v = v.replace(sp, path)
            variables[k] = v
    return variables, made


def run_installed(src, dest, prefix, checks):
    _, units = layout(prefix)
    argv = unit_exec_start(open(dest + units + "/rr-gateway.service").read())
    exe, rest = argv[0], argv[1:]
    rest = [dest + a if a.startswith("/") else a for a in rest]  # the configuration below DESTDIR
    web = dest + prefix + "/share/rr-gateway/web"
    marker = None
    if not os.path.isfile(os.path.join(web, "index.html")):
        os.makedirs(web, exist_ok=True)
        marker = "<!-- rr-gateway install_test marker %d -->" % os.getpid()
        with open(os.path.join(web, "index.html"), "w") as f:
            f.write(marker)
    expected_index = open(os.path.join(web, "index.html"), "rb").read()
    bindir = os.path.dirname(dest + exe)
    env = dict(gwproc.gateway_env(), PATH=bindir + os.pathsep + os.environ.get("PATH", ""))
    tools_env = dict(env)
    # The unit's environment as systemd gives it: a user without home, no XDG_* variables, the
    # unit's Environment= (its directories made as RuntimeDirectory=/StateDirectory= would).
    service_env = {k: v for k, v in env.items() if not k.startswith("XDG_")}
    service_env["HOME"] = "/nonexistent"
    unit_env, made = service_environment(open(dest + units + "/rr-gateway.service").read(), dest)
    service_env.update(unit_env)
    # As the unit does, but found on PATH (argv[0] "rr-gateway") and from / : the binary must find its
    # files from where it is installed, not from the source tree or the working directory. As root,
    # the test runs it as an unprivileged user whose group may read the configuration (0640), as the
    # package's user rr-gateway.
    run_as = []
    if os.geteuid() == 0 and shutil.which("setpriv"):
        import grp
        import pwd
        uid, gid = pwd.getpwnam("nobody").pw_uid, grp.getgrnam("nogroup").gr_gid
        os.chmod(dest, 0o755)
        for d in made:
            os.chown(d, uid, gid)
        os.chown(rest[rest.index("--config") + 1], 0, gid)
        run_as = ["setpriv", "--reuid=%d" % uid, "--regid=%d" % gid, "--clear-groups"]
    gw = None
    cwd = os.getcwd()
    try:
        os.chdir("/")
        gw = gwproc.Proc(run_as + [os.path.basename(exe)] + rest + ["--port", "0", "--log-level", "warning"],
                         env=service_env)
    finally:
        os.chdir(cwd)
    env = tools_env
    try:
        base = "http://127.0.0.1:%d" % gw.port
        checks.run("prefix %s: the installed gateway gets ready (demo devices)" % prefix, lambda: gwproc.wait_ready(gw.port))

        def api():
            status, body = gwproc.http_status(base + "/api/devices")
            expect(status == 200 and '"create"' in body and '"webcam"' in body, "%d %s" % (status, body[:300]))

        def dashboard():
            with urllib.request.urlopen(base + "/", timeout=5) as r:
                got = r.read()
            expect(got == expected_index, "GET / is not %s/index.html (%d bytes%s)"
                   % (web, len(got), ", marker page" if marker else ""))

        def rr_cli():
            url = "rr+tcp://127.0.0.1:%d/?service=create" % gw.port
            p = subprocess.run(["rr", "info", url, "--timeout", "10"], env=env, capture_output=True, text=True, timeout=60)
            expect(p.returncode == 0 and "service experimental.create" in p.stdout, "exit %d: %s" % (p.returncode, p.stderr))

        def tools():
            robdef = os.path.join(dest, "t.robdef")
            with open(robdef, "w") as f:
                f.write("service example.installed\n\nstdver 0.10\n\nobject Obj\n    property double x\nend\n")
            for b, args in [("rr-robdef", ["check", robdef]), ("rr-demo-devices", ["--help"]), ("rr-gateway", ["--help"])]:
                p = subprocess.run([b] + args, env=env, capture_output=True, text=True, timeout=30)
                expect(p.returncode == 0, "%s %s: exit %d %s" % (b, " ".join(args), p.returncode, p.stderr[:200]))

        checks.run("prefix %s: JSON API lists the demo devices" % prefix, api)
        checks.run("prefix %s: the dashboard comes from PREFIX/share/rr-gateway/web" % prefix, dashboard)
        checks.run("prefix %s: the installed rr reads a device through the installed gateway" % prefix, rr_cli)
        checks.run("prefix %s: the other installed tools run" % prefix, tools)
    finally:
        status = gw.stop()
    checks.run("prefix %s: SIGTERM ends the installed gateway with status 0" % prefix,
               lambda: expect(status == 0, "status %r" % status))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build-dir", required=True)
    ap.add_argument("--source-dir", default=os.getcwd())
    a = ap.parse_args()
    checks = gwproc.Checks()
    for prefix in ["/usr", "/opt/rr-gateway"]:
        dest = tempfile.mkdtemp(prefix="rr-install-")
        try:
            checks.run("prefix %s: DESTDIR=%s cmake --install" % (prefix, dest), lambda: install(a.build_dir, dest, prefix))
            check_tree(a.source_dir, dest, prefix, checks)
            verify_unit(dest, prefix, checks)
            run_installed(a.source_dir, dest, prefix, checks)
        finally:
            shutil.rmtree(dest, ignore_errors=True)
    return checks.exit_code()


if __name__ == "__main__":
    sys.exit(main())
