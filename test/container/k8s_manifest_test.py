#!/usr/bin/env python3
"""docker/kubernetes/rr-gateway.yaml against the Kubernetes API schemas (kubernetes-validate --strict,
schemas shipped in the package, offline) and against what the gateway and the image expect:

  - a ConfigMap, a Deployment and a Service; the Deployment mounts the ConfigMap's gateway.yaml where
    docker/entrypoint.sh reads it, and that gateway.yaml passes `rr-gateway --check`;
  - liveness probe GET /livez, readiness probe GET /readyz on the container port the config listens on;
  - resources (requests and limits), a non-root securityContext (uid 10001 as in the image, no
    privilege escalation, read-only root with the writable folders the gateway uses as volumes);
  - the RR_GATEWAY_* variables it sets are ones docker/entrypoint.sh reads;
  - the Service selects the Deployment's pods and targets the container port.
A copy with a schema error must fail validation (the validator really runs).

Usage: k8s_manifest_test.py --manifest docker/kubernetes/rr-gateway.yaml --gateway PATH
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "test", "gateway"))
import gwproc  # noqa: E402
from gwproc import expect  # noqa: E402


def validate(path):
    exe = os.path.join(os.path.dirname(sys.executable), "kubernetes-validate")
    return subprocess.run([exe, "--strict", path], capture_output=True, text=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--manifest", required=True)
    ap.add_argument("--gateway", required=True)
    a = ap.parse_args()
    try:
        import kubernetes_validate  # noqa: F401
    except ImportError:
        print("SKIP: kubernetes-validate is not installed (./scripts/setup.sh installs test/interop/requirements.txt)")
        return 77
    checks = gwproc.Checks()
    docs = [d for d in yaml.safe_load_all(open(a.manifest)) if d]
    by_kind = {d["kind"]: d for d in docs}

    def schemas():
        p = validate(a.manifest)
        expect(p.returncode == 0, "kubernetes-validate --strict: exit %d\n%s%s" % (p.returncode, p.stdout, p.stderr))
        expect(p.stdout.count("passed") == len(docs), "not every resource passed: %s" % p.stdout)

    checks.run("kubernetes-validate --strict passes every resource", schemas)

    def negative_control():
        bad = [dict(d) for d in docs]
        for d in bad:
            if d["kind"] == "Deployment":
                d["spec"] = dict(d["spec"], replicas="one")
        with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
            yaml.safe_dump_all(bad, f)
        try:
            p = validate(f.name)
            expect(p.returncode != 0 and "replicas" in p.stdout + p.stderr,
                   "a Deployment with replicas: \"one\" validated: %s%s" % (p.stdout, p.stderr))
        finally:
            os.unlink(f.name)

    checks.run("a schema error is caught (negative control)", negative_control)

    def kinds():
        expect(set(by_kind) >= {"ConfigMap", "Deployment", "Service"}, "kinds %s" % sorted(by_kind))

    checks.run("ConfigMap, Deployment and Service", kinds)
    if checks.results[-1][1]:
        return checks.exit_code()
    dep, svc, cm = by_kind["Deployment"], by_kind["Service"], by_kind["ConfigMap"]
    pod = dep["spec"]["template"]["spec"]
    c = pod["containers"][0]
    gw_yaml = cm["data"]["gateway.yaml"]
    gw_cfg = yaml.safe_load(gw_yaml)

    def config_checks():
        with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
            f.write(gw_yaml)
        try:
            p = subprocess.run([a.gateway, "--config", f.name, "--check"], capture_output=True, text=True, timeout=30)
            expect(p.returncode == 0, "rr-gateway --check on the ConfigMap's gateway.yaml: %s%s" % (p.stdout, p.stderr))
        finally:
            os.unlink(f.name)
        mounts = {m["mountPath"]: m for m in c["volumeMounts"]}
        m = mounts.get("/etc/rr-gateway/gateway.yaml")
        expect(m and m.get("subPath") == "gateway.yaml" and m.get("readOnly"), "gateway.yaml mount %r" % m)
        vol = {v["name"]: v for v in pod["volumes"]}[m["name"]]
        expect(vol.get("configMap", {}).get("name") == cm["metadata"]["name"], "config volume %r" % vol)

    checks.run("the ConfigMap's gateway.yaml passes rr-gateway --check and is mounted where the image reads it",
               config_checks)

    def probes():
        port = gw_cfg.get("gateway", {}).get("port", 8080)
        ports = {p["name"]: p["containerPort"] for p in c["ports"]}
        expect(port in ports.values(), "containerPort %r, config port %r" % (ports, port))
        for probe, path in (("livenessProbe", "/livez"), ("readinessProbe", "/readyz")):
            g = c[probe]["httpGet"]
            expect(g["path"] == path, "%s path %r" % (probe, g["path"]))
            expect(ports.get(g["port"], g["port"]) == port, "%s port %r" % (probe, g["port"]))
        expect(svc["spec"]["selector"].items() <= dep["spec"]["template"]["metadata"]["labels"].items(),
               "Service selector %r" % svc["spec"]["selector"])
        tp = svc["spec"]["ports"][0]["targetPort"]
        expect(ports.get(tp, tp) == port, "Service targetPort %r" % tp)

    checks.run("probes on /livez and /readyz at the config's port; the Service reaches it", probes)

    def security_and_resources():
        r = c["resources"]
        expect(r.get("requests", {}).get("cpu") and r.get("requests", {}).get("memory"), "requests %r" % r)
        expect(r.get("limits", {}).get("cpu") and r.get("limits", {}).get("memory"), "limits %r" % r)
        psc, sc = pod["securityContext"], c["securityContext"]
        expect(psc.get("runAsNonRoot") is True and psc.get("runAsUser") == 10001, "pod securityContext %r" % psc)
        expect(sc.get("allowPrivilegeEscalation") is False and sc.get("readOnlyRootFilesystem") is True and
               sc.get("capabilities", {}).get("drop") == ["ALL"], "container securityContext %r" % sc)
        # The image's writable folders (Containerfile ENV) must be volumes on a read-only root.
        writable = {m["mountPath"] for m in c["volumeMounts"] if not m.get("readOnly")}
        containerfile = open(os.path.join(ROOT, "docker", "Containerfile")).read()
        for var in ("ROBOTRACONTEUR_USER_RUN_DIR", "ROBOTRACONTEUR_USER_CONFIG_DIR"):
            d = re.search(var + r"=(\S+)", containerfile).group(1)
            expect(d in writable, "%s (%s) is not a writable volume" % (var, d))

    checks.run("resources and a non-root, read-only securityContext", security_and_resources)

    def env():
        entry = open(os.path.join(ROOT, "docker", "entrypoint.sh")).read()
        for e in c.get("env", []):
            expect(e["name"] in entry, "%s is not read by docker/entrypoint.sh" % e["name"])

    checks.run("the RR_GATEWAY_* variables are ones the entry point reads", env)
    return checks.exit_code()


if __name__ == "__main__":
    sys.exit(main())
