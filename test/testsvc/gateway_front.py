"""rr-gateway in front of the four test services (testsvc_checks.py --gateway, official_suite.py):
each service becomes a device of the same name in `auth: passthrough` mode, so every client gets its
own upstream session with its own login, and the services' users, locks and monitors apply as if the
client had connected directly (docs/security.md "Logins and locks through the gateway")."""

import json
import time
import urllib.request

SERVICES = ["RobotRaconteurTestService", "RobotRaconteurTestService_auth", "RobotRaconteurTestService2",
            "RobotRaconteurTestService3"]


def config_text(device_url, tls_ca=None):
    """The gateway's YAML: `device_url` is the service node's base URL (rr+tcp, rr+ws, rr+wss, rr+local)."""
    out = ["devices:"]
    for s in SERVICES:
        out += ["  - name: " + s,
                "    url: %s%sservice=%s" % (device_url, "&" if "?" in device_url else "?", s),
                "    auth: passthrough"]
        if tls_ca:
            out.append("    tls_ca: " + tls_ca)
        if s.endswith("_auth"):
            # The gateway's own session needs a login too, as a user the clients do not lock with: a
            # user lock lasts while its user has a session, and the gateway's own session lasts (as
            # testuser1 it kept testuser1's user lock after every client session of testuser1 closed).
            out += ["    username: testsuperuser", "    password: superpass1"]
    return "\n".join(out) + "\n"


def argv(gateway, config_path):
    """The gateway's command line: loopback, any free port, no demo devices, no rr+local, no discovery."""
    return [gateway, "--config", config_path, "--listen", "127.0.0.1", "--port", "0", "--no-demo", "--no-local",
            "--no-discovery", "--log-level", "warning"]


def is_ready_line(line):
    """The gateway's first stdout line is a JSON object with its port."""
    return line.strip().startswith("{") and '"port"' in line


def port_of(ready_line):
    return json.loads(ready_line)["port"]


def wait_until_ready(port, bound_s, alive):
    """Waits until /readyz answers 200 (every device connected); False after `bound_s` seconds (a hang
    bound) or when `alive()` turns false."""
    deadline = time.time() + bound_s
    while time.time() < deadline and alive():
        try:
            if urllib.request.urlopen("http://127.0.0.1:%d/readyz" % port, timeout=2).status == 200:
                return True
        except Exception:
            pass
        time.sleep(0.2)
    return False
