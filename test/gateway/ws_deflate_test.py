#!/usr/bin/env python3
"""permessage-deflate on the JSON WebSocket (issue 56; docs/gateway-config.md "websocket_compression").

One gateway with its demo devices and `websocket_compression: {paths: [/compressed]}`:
  * an upgrade to /compressed/... that offers the extension gets it (Sec-WebSocket-Extensions in the
    101 response); the replies and text pushes then come compressed (RSV1) and inflate to the JSON
    expected; a client that sends its own frames uncompressed is answered as usual;
  * binary pushes (a webcam frame subscribed with "binary": true) are never compressed (RSV1 clear);
  * an upgrade to another path, offering the same, is declined (no extension, no RSV1 frame);
  * a client that does not offer it gets plain frames on /compressed too.
The gateway without the key (the default) declines every offer: ws_conformance_test.py group 12.

Usage: ws_deflate_test.py --gateway PATH
Exit: 0 all checks passed, 1 a check failed.
"""
import argparse
import json
import os
import socket
import struct
import sys
import tempfile
import zlib

import gwproc
from gwproc import expect
from ws_handshake import open_handshake

JSON_SUBPROTOCOL = "rr-gateway.json.v1"
OP_TEXT, OP_BIN, OP_CLOSE, OP_PING = 1, 2, 8, 9
OFFER = "permessage-deflate; client_max_window_bits"


class DeflateWs:
    """A JSON WebSocket client on a plain socket that records each message's RSV1 bit and inflates it."""

    def __init__(self, port, path, offer=True, timeout=30.0):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=timeout)
        self.headers, self.buf = open_handshake(self.sock, port, path, JSON_SUBPROTOCOL, OFFER if offer else None)
        # Context takeover: one inflater for every compressed message of the connection (RFC 7692 §7.2.2).
        self.inflater = zlib.decompressobj(-zlib.MAX_WBITS)
        self.next_id = 1

    def extensions(self):
        return self.headers.get("sec-websocket-extensions", "")

    def _need(self, n):
        while len(self.buf) < n:
            chunk = self.sock.recv(1 << 20)
            expect(chunk, "the gateway closed the connection")
            self.buf += chunk
        out, self.buf = self.buf[:n], self.buf[n:]
        return out

    def recv(self):
        """The next data message: (opcode, compressed, payload inflated)."""
        parts, op, rsv1 = [], None, False
        while True:
            b0, b1 = self._need(2)
            n = b1 & 0x7F
            if n == 126:
                n = struct.unpack("!H", self._need(2))[0]
            elif n == 127:
                n = struct.unpack("!Q", self._need(8))[0]
            payload = self._need(n)
            opcode = b0 & 0x0F
            expect(not (b0 & 0x30), "RSV2/RSV3 set: 0x%02x" % b0)
            if opcode == OP_CLOSE:
                raise AssertionError("the gateway closed the WebSocket: %r" % payload)
            if opcode == OP_PING:
                self.send(0xA, payload)
                continue
            if opcode >= 8:
                continue
            if opcode != 0:
                op, rsv1 = opcode, bool(b0 & 0x40)
            parts.append(payload)
            if b0 & 0x80:
                data = b"".join(parts)
                if rsv1:
                    data = self.inflater.decompress(data + b"\x00\x00\xff\xff")
                return op, rsv1, data

    def send(self, opcode, payload):
        key = os.urandom(4)
        n = len(payload)
        head = struct.pack("!BB", 0x80 | opcode, 0x80 | n) if n < 126 else struct.pack("!BBH", 0x80 | opcode, 0xFE, n)
        masked = bytes(b ^ key[i % 4] for i, b in enumerate(payload))
        self.sock.sendall(head + key + masked)

    def request(self, fields, seen=None):
        """Sends a request (uncompressed) and returns its reply; every message read meanwhile goes to `seen`."""
        ident = self.next_id
        self.next_id += 1
        self.send(OP_TEXT, json.dumps(dict(fields, id=ident)).encode())
        while True:
            op, rsv1, data = self.recv()
            if seen is not None:
                seen.append((op, rsv1, data))
            if op == OP_TEXT:
                msg = json.loads(data.decode())
                if msg.get("id") == ident:
                    return msg

    def close(self):
        try:
            self.sock.close()
        except OSError:
            pass


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gateway", required=True)
    args = ap.parse_args()
    checks = gwproc.Checks()
    with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
        f.write("gateway:\n  websocket_compression:\n    paths: [/compressed]\n")
        config = f.name
    gw = gwproc.start_gateway(args.gateway, ["--config", config])
    try:
        gwproc.wait_ready(gw.port)

        def negotiated():
            ws = DeflateWs(gw.port, "/compressed/json")
            expect(ws.extensions().startswith("permessage-deflate"),
                   "the offer on /compressed was declined: %r" % ws.extensions())
            seen = []
            reply = ws.request({"op": "devices"}, seen)
            names = sorted(d["name"] for d in reply["result"])
            expect("create" in names and "webcam" in names, "devices: %r" % names)
            replies = [s for s in seen if s[0] == OP_TEXT]
            expect(replies and all(rsv1 for _, rsv1, _ in replies),
                   "text messages not compressed: %r" % [(rsv1, len(d)) for _, rsv1, d in replies])
            # A wire value arrives compressed and inflates to its push.
            sub = ws.request({"op": "subscribe", "device": "create", "member": "packets"})
            expect("result" in sub, "subscribe: %r" % sub)
            ws.request({"op": "call", "device": "create", "member": "StartStreaming", "args": []})
            while True:
                op, rsv1, data = ws.recv()
                msg = json.loads(data.decode()) if op == OP_TEXT else {}
                if msg.get("subscription") == sub["result"]["subscription"] and msg.get("kind") == "wire":
                    break
            expect(rsv1 and "value" in msg, "a wire push: compressed %s, %r" % (rsv1, str(msg)[:200]))
            ws.close()

        checks.run("an offer on a path under websocket_compression.paths is accepted; text messages come deflated", negotiated)

        def images_plain():
            ws = DeflateWs(gw.port, "/compressed")
            expect(ws.extensions().startswith("permessage-deflate"), "declined: %r" % ws.extensions())
            sub = ws.request({"op": "subscribe", "device": "webcam", "object": "Webcams[0]", "member": "FrameStream",
                              "binary": True})
            expect("result" in sub, "subscribe: %r" % sub)
            started = ws.request({"op": "call", "device": "webcam", "object": "Webcams[0]", "member": "StartStreaming",
                                  "args": []})
            expect("result" in started, "StartStreaming: %r" % started)
            frames = []
            while len(frames) < 2:
                op, rsv1, data = ws.recv()
                if op == OP_BIN:
                    frames.append((rsv1, data))
            for rsv1, data in frames:
                expect(not rsv1, "a binary push came compressed")
                expect(data[:4] == b"RRJB" and len(data) > 100000, "a binary push of %d bytes: %r" % (len(data), data[:8]))
            ws.request({"op": "call", "device": "webcam", "object": "Webcams[0]", "member": "StopStreaming", "args": []})
            ws.close()

        checks.run("binary pushes (webcam frames) are never compressed on a deflate socket", images_plain)

        def declined_elsewhere():
            ws = DeflateWs(gw.port, "/other")
            expect(ws.extensions() == "", "an offer on /other was accepted: %r" % ws.extensions())
            seen = []
            ws.request({"op": "devices"}, seen)
            expect(not any(rsv1 for _, rsv1, _ in seen), "a compressed message on a declined socket")
            ws.close()
            ws = DeflateWs(gw.port, "/compressedx")  # a sibling path, not below /compressed
            expect(ws.extensions() == "", "an offer on /compressedx was accepted: %r" % ws.extensions())
            ws.close()
            ws = DeflateWs(gw.port, "/compressed", offer=False)
            expect(ws.extensions() == "", "an extension without an offer: %r" % ws.extensions())
            seen = []
            ws.request({"op": "devices"}, seen)
            expect(not any(rsv1 for _, rsv1, _ in seen), "a compressed message without an offer")
            ws.close()

        checks.run("declined on other paths and without an offer: plain frames", declined_elsewhere)
    finally:
        status = gw.stop()
        os.unlink(config)
        checks.run("the gateway ends cleanly (exit 0, no sanitizer report)", lambda: expect(status == 0, "exit %r" % status))
    return checks.exit_code()


if __name__ == "__main__":
    sys.exit(main())
