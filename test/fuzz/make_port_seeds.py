#!/usr/bin/env python3
"""Writes the HTTP and WebSocket seeds of fuzz_gateway_port (test/fuzz/seeds/fuzz_gateway_port).

The RR stream seeds (rr_client_v2.bin, rr_client_v4.bin) come from our encoder:
    build/<dir>/test/fuzz/gen_message_seeds /tmp/msg test/fuzz/seeds/fuzz_gateway_port
and are reused here as the payload of a raw-RR WebSocket binary frame. Run from the repository root:
    python3 test/fuzz/make_port_seeds.py
"""
import base64
import os
import struct

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "seeds", "fuzz_gateway_port")
KEY = base64.b64encode(b"0123456789abcdef").decode()
MASK = b"\x11\x22\x33\x44"


def frame(opcode, payload, fin=True):
    """A masked client frame (RFC 6455 §5.2)."""
    head = bytes([(0x80 if fin else 0) | opcode])
    n = len(payload)
    if n < 126:
        head += bytes([0x80 | n])
    elif n < 65536:
        head += bytes([0x80 | 126]) + struct.pack(">H", n)
    else:
        head += bytes([0x80 | 127]) + struct.pack(">Q", n)
    return head + MASK + bytes(b ^ MASK[i % 4] for i, b in enumerate(payload))


def upgrade(protocol=None, path="/", origin=None):
    r = "GET %s HTTP/1.1\r\nHost: 127.0.0.1:8080\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n" % path
    r += "Sec-WebSocket-Key: %s\r\nSec-WebSocket-Version: 13\r\n" % KEY
    if protocol:
        r += "Sec-WebSocket-Protocol: %s\r\n" % protocol
    if origin:
        r += "Origin: %s\r\n" % origin
    return (r + "\r\n").encode()


def get(path, extra=""):
    return ("GET %s HTTP/1.1\r\nHost: 127.0.0.1:8080\r\n%s\r\n" % (path, extra)).encode()


def main():
    os.makedirs(OUT, exist_ok=True)
    seeds = {
        "http_index.bin": get("/"),
        "http_static.bin": get("/sub/a.txt") + get("/index.html", "Connection: close\r\n"),
        "http_traversal.bin": get("/../secret.txt") + get("/%2e%2e/secret.txt") + get("/sub/../../www.txt"),
        "http_livez.bin": get("/livez") + get("/readyz") + get("/metrics"),
        "http_api.bin": get("/api/devices") + get("/api/devices/create/properties/Speed"),
        "http_put.bin": b"PUT /api/devices/create/properties/Bumpers HTTP/1.1\r\nHost: x\r\nContent-Length: 12\r\n\r\n{\"value\": 1}",
        "http_origin.bin": get("/api/devices", "Origin: http://evil.example\r\n"),
        "http_head.bin": b"HEAD / HTTP/1.0\r\n\r\n",
        "http_garbage.bin": b"GET\t/ HTTP/1.1\r\nHost: \x00\r\n\r\n",
        "ws_json.bin": upgrade("rr-gateway.json.v1")
        + frame(1, b'{"id":1,"op":"devices"}')
        + frame(1, b'{"id":2,"op":"get","device":"create","member":"Speed"}')
        + frame(8, struct.pack(">H", 1000)),
        "ws_json_fragmented.bin": upgrade("rr-gateway.json.v1")
        + frame(1, b'{"id":1,', fin=False)
        + frame(9, b"ping")
        + frame(0, b'"op":"devices"}'),
        "ws_unknown_protocol.bin": upgrade("chat, superchat"),
        "ws_bad_key.bin": upgrade("rr-gateway.json.v1").replace(KEY.encode(), b"short"),
    }
    rr = os.path.join(OUT, "rr_client_v2.bin")
    if os.path.exists(rr):
        with open(rr, "rb") as f:
            payload = f.read()
        seeds["ws_rr.bin"] = upgrade("robotraconteur.robotraconteur.com") + frame(2, payload)
        seeds["ws_rr_noprotocol.bin"] = upgrade() + frame(2, payload[:40]) + frame(2, payload[40:])
    for name, data in seeds.items():
        with open(os.path.join(OUT, name), "wb") as f:
            f.write(data)
    print("wrote %d seeds to %s" % (len(seeds), OUT))


if __name__ == "__main__":
    main()
