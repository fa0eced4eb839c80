#!/usr/bin/env python3
"""The folders include only the folders below them, in the order docs/architecture.md lists them
("Folders and their dependencies"): the server folders, then the sans-IO layers core/, robdef/ and base/.
In server/, library sources only: tests (`*_test.cpp`), test fixtures and test support files may reach
across. In core/, robdef/ and base/ every file is checked, tests too: base/ includes nothing of robdef/,
core/ or server/, robdef/ only base/, core/ only robdef/ and base/ (and nothing of wasm-client/). Includes
of test/ (test support) are not layers. Prints each upward include as file:line and exits 1 when there is
one.

Also the transport seam (docs/architecture.md "Transports"): the node, the clients, the service framework
and the gateway's devices name no concrete transport; of server/transport they include only the seam
itself (SEAM below), and reach TCP, WebSocket, TLS, rr+local and rr+usb through it.

Usage: layering_test.py REPO_ROOT
"""
import pathlib
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s+"server/([a-z_]+)/')
# An include of a project folder from a sans-IO layer: server/x, core, robdef, base, wasm-client.
PROJECT_INCLUDE = re.compile(r'^\s*#\s*include\s+"((server/[a-z_]+)|core|robdef|base|wasm-client)/')
SANS_IO = ("core", "robdef", "base")  # bottom last, as listed
TRANSPORT_INCLUDE = re.compile(r'^\s*#\s*include\s+"server/transport/([^"]+)"')
# The seam: what transport-neutral folders may include from server/transport.
SEAM = {"transport.hpp", "transport_registry.hpp", "connection_logic.hpp", "stream_pump.hpp", "completion_guard.hpp"}
TRANSPORT_NEUTRAL = {"node", "client", "service", "gateway"}
LISTED = re.compile(r"^ (server/[a-z_]+|core/|robdef/|base/)\s")


def folder_order(doc: pathlib.Path):
    text = doc.read_text(encoding="utf-8")
    section = text.split("## Folders and their dependencies", 1)[1]
    block = section.split("```", 2)[1]
    order = [m.group(1).rstrip("/") for line in block.splitlines() if (m := LISTED.match(line))]
    return order  # top first: "server/app", …, "core", "robdef", "base"


def is_test_file(p: pathlib.Path) -> bool:
    n = p.name
    return n.endswith("_test.cpp") or "test_" in n or "fixture" in n or "test_support" in n


def main():
    root = pathlib.Path(sys.argv[1]).resolve()
    order = folder_order(root / "docs" / "architecture.md")
    rank = {name: i for i, name in enumerate(order)}
    bad = ["%s: layer not listed in docs/architecture.md" % layer for layer in SANS_IO if layer not in rank]
    if not bad and not rank["core"] < rank["robdef"] < rank["base"]:
        bad.append("docs/architecture.md lists the sans-IO layers out of order (core/ above robdef/ above base/)")
    server = root / "server"
    on_disk = sorted(d.name for d in server.iterdir() if d.is_dir())
    unlisted = [d for d in on_disk if "server/" + d not in rank]
    bad += ["server/%s: folder not listed in docs/architecture.md" % d for d in unlisted]
    checked = 0
    for p in sorted(server.rglob("*")):
        if p.suffix not in (".cpp", ".hpp") or is_test_file(p):
            continue
        src = p.relative_to(server).parts[0]
        if "server/" + src not in rank:
            continue
        for n, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1):
            t = TRANSPORT_INCLUDE.match(line)
            if t and src in TRANSPORT_NEUTRAL and t.group(1) not in SEAM:
                bad.append("%s:%d: server/%s names a concrete transport (server/transport/%s); use the seam"
                           % (p.relative_to(root), n, src, t.group(1)))
            m = INCLUDE.match(line)
            if not m:
                continue
            checked += 1
            dst = m.group(1)
            if dst != src and ("server/" + dst not in rank or rank["server/" + dst] < rank["server/" + src]):
                bad.append("%s:%d: server/%s includes server/%s, which is above it" % (p.relative_to(root), n, src, dst))
    for layer in SANS_IO:
        if layer not in rank:
            continue
        for p in sorted((root / layer).rglob("*")):
            if p.suffix not in (".cpp", ".hpp", ".h"):
                continue
            for n, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1):
                m = PROJECT_INCLUDE.match(line)
                if not m:
                    continue
                checked += 1
                dst = m.group(1)
                if dst != layer and (dst not in rank or rank[dst] < rank[layer]):
                    bad.append("%s:%d: %s/ includes %s/, which is above it" % (p.relative_to(root), n, layer, dst))
    for b in bad:
        print(b)
    print("layering: %d folders in order %s; %d includes checked; %d problems" % (len(order), " > ".join(order), checked, len(bad)))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
