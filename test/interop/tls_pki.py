"""A throw-away PKI for the TLS tests, made with the openssl CLI in a folder (EC P-256, SHA-256).

Pki(folder).ca(name) makes a self-signed CA; .issue(ca, name, cn, sans=..., client=..., rr_marker=...)
makes a certificate signed by it. Each result has .cert and .key (PEM file paths). rr_marker adds one of
the official library's node-certificate markers (1.3.6.1.4.1.45455.1.1.3.1 root, .2 intermediate,
.3 leaf) as a critical BOOLEAN TRUE extension, as its verify callback requires (docs/security.md).
.p12(issued, ca, path) writes the PKCS#12 file an official node loads (empty password).
"""
import os
import shutil
import subprocess
from collections import namedtuple

Issued = namedtuple("Issued", "cert key")

RR_ROOT_MARKER = "1.3.6.1.4.1.45455.1.1.3.1"
RR_LEAF_MARKER = "1.3.6.1.4.1.45455.1.1.3.3"


def have_openssl():
    return shutil.which("openssl") is not None


def _run(*args):
    p = subprocess.run(["openssl"] + list(args), capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError("openssl %s failed: %s" % (args[0], p.stderr.strip()))


class Pki:
    def __init__(self, folder):
        self.dir = folder
        os.makedirs(folder, exist_ok=True)
        self._serial = 1

    def path(self, name):
        return os.path.join(self.dir, name)

    def ca(self, name, cn=None, rr_marker=None):
        cert, key = self.path(name + ".pem"), self.path(name + ".key")
        args = ["req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes", "-days", "2",
                "-subj", "/CN=" + (cn or name), "-addext", "basicConstraints=critical,CA:TRUE",
                "-addext", "keyUsage=critical,keyCertSign,cRLSign", "-keyout", key, "-out", cert]
        if rr_marker:
            args += ["-addext", "%s=critical,ASN1:BOOLEAN:TRUE" % rr_marker]
        _run(*args)
        return Issued(cert, key)

    def issue(self, ca, name, cn, sans=(), client=False, rr_marker=None, days=2):
        cert, key, csr, ext = (self.path(name + s) for s in (".pem", ".key", ".csr", ".ext"))
        _run("req", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes", "-subj", "/CN=" + cn,
             "-keyout", key, "-out", csr)
        lines = ["basicConstraints=critical,CA:FALSE", "keyUsage=critical,digitalSignature,keyAgreement",
                 "extendedKeyUsage=" + ("clientAuth" if client else "serverAuth")]
        if sans:
            lines.append("subjectAltName=" + ",".join(sans))
        if rr_marker:
            lines.append("%s=critical,ASN1:BOOLEAN:TRUE" % rr_marker)
        with open(ext, "w") as f:
            f.write("\n".join(lines) + "\n")
        self._serial += 1
        _run("x509", "-req", "-in", csr, "-CA", ca.cert, "-CAkey", ca.key, "-set_serial", str(self._serial),
             "-days", str(days), "-extfile", ext, "-out", cert)
        return Issued(cert, key)

    def p12(self, issued, ca, path):
        """The PKCS#12 file (empty password) an official node loads as its node certificate."""
        os.makedirs(os.path.dirname(path), exist_ok=True)
        _run("pkcs12", "-export", "-inkey", issued.key, "-in", issued.cert, "-certfile", ca.cert, "-passout", "pass:",
             "-out", path)
        return path


def peer_subject_cn(host, port, cafile, server_hostname="localhost", cert=None, timeout=5):
    """CN of the certificate a new TLS connection to host:port presents (verified against cafile)."""
    import socket
    import ssl
    ctx = ssl.create_default_context(cafile=cafile)
    if cert:
        ctx.load_cert_chain(cert.cert, cert.key)
    with socket.create_connection((host, port), timeout=timeout) as raw:
        with ctx.wrap_socket(raw, server_hostname=server_hostname) as s:
            subject = dict(x[0] for x in s.getpeercert()["subject"])
            return subject.get("commonName")
