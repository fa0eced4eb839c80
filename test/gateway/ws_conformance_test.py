#!/usr/bin/env python3
"""WebSocket conformance of rr-gateway's WebSocket endpoints (issue 16), by Autobahn|Testsuite case group.

Autobahn|Testsuite (the reference) is Python 2 code and does not run here, so this covers the same
ground with a raw-socket client that writes frames byte by byte (any flag, opcode, length form or mask),
against both subprotocols the gateway serves on its port:

  rr    robotraconteur.robotraconteur.com: RR messages as a byte stream in binary frames. The "echo" is an
        RR ConnectionTest (entry 111) padded with a string element to the wanted size; the node answers
        ConnectionTestRet (112) with the same RequestID only when every byte arrived intact.
  json  rr-gateway.json.v1: JSON in text frames. The "echo" is {"id": <padding>, "op": "devices"}, whose
        reply carries the id back.

Groups (Autobahn numbering): 1 framing (lengths 0/125/126/127/65535/65536 and more), 2 pings and pongs,
3 reserved bits, 4 opcodes, 5 fragmentation, 6 UTF-8, 7 close handshake, 9 large messages and many small
ones, 10 fragment sizes, 12/13 permessage-deflate (not offered: the offer must be declined), plus RFC 6455
rules Autobahn does not test on servers (unmasked client frames, oversized length headers).

Usage: ws_conformance_test.py --gateway PATH [--group N ...]
Prints one line per check and a JSON summary; exit status 0 only if every check passed.
"""
import argparse
import json
import os
import socket
import struct
import sys
import time
import uuid

import gwproc
from gwproc import expect
from ws_handshake import open_handshake

RR_SUBPROTOCOL = "robotraconteur.robotraconteur.com"
JSON_SUBPROTOCOL = "rr-gateway.json.v1"

OP_CONT, OP_TEXT, OP_BIN, OP_CLOSE, OP_PING, OP_PONG = 0, 1, 2, 8, 9, 10


class Closed(Exception):
    """The server closed the TCP connection (with the close frame's code, if one came)."""

    def __init__(self, code, reason=b""):
        super().__init__("closed with code %r" % code)
        self.code = code
        self.reason = reason


class RawWs:
    """A WebSocket client on a plain socket: frames are written exactly as asked."""

    def __init__(self, port, subprotocol, extensions=None, timeout=10.0):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=timeout)
        self.headers, self.buf = open_handshake(self.sock, port, "/", subprotocol, extensions)
        self.close_code = None

    # -- writing
    def frame(self, opcode, payload=b"", fin=True, rsv=0, mask=True, length_form=None):
        b0 = (0x80 if fin else 0) | (rsv << 4) | opcode
        n = len(payload)
        form = length_form or (7 if n < 126 else 16 if n < 65536 else 64)
        mbit = 0x80 if mask else 0
        if form == 7:
            head = struct.pack("!BB", b0, mbit | n)
        elif form == 16:
            head = struct.pack("!BBH", b0, mbit | 126, n)
        else:
            head = struct.pack("!BBQ", b0, mbit | 127, n)
        if mask:
            key = os.urandom(4)
            payload = xor_mask(payload, key)
            head += key
        return head + payload

    def send(self, opcode, payload=b"", **kw):
        self.sock.sendall(self.frame(opcode, payload, **kw))

    def send_raw(self, data):
        self.sock.sendall(data)

    # -- reading
    def _need(self, n):
        while len(self.buf) < n:
            chunk = self.sock.recv(1 << 20)
            if not chunk:
                raise Closed(self.close_code)
            self.buf += chunk
        out, self.buf = self.buf[:n], self.buf[n:]
        return out

    def recv_frame(self):
        b0, b1 = self._need(2)
        n = b1 & 0x7F
        if n == 126:
            n = struct.unpack("!H", self._need(2))[0]
        elif n == 127:
            n = struct.unpack("!Q", self._need(8))[0]
        expect(not (b1 & 0x80), "a server frame must not be masked")
        expect(not (b0 & 0x70), "a server frame with reserved bits 0x%02x" % b0)
        return bool(b0 & 0x80), b0 & 0x0F, self._need(n)

    def recv(self, answer_pings=True):
        """The next data message (opcode, payload); pongs are skipped, a close frame raises Closed."""
        parts, op = [], None
        while True:
            fin, opcode, payload = self.recv_frame()
            if opcode == OP_CLOSE:
                self.close_code = struct.unpack("!H", payload[:2])[0] if len(payload) >= 2 else 1005
                raise Closed(self.close_code, payload[2:])
            if opcode == OP_PING:
                if answer_pings:
                    self.send(OP_PONG, payload)
                continue
            if opcode == OP_PONG:
                continue
            if opcode != OP_CONT:
                op = opcode
            parts.append(payload)
            if fin:
                return op, b"".join(parts)

    def expect_close(self, codes, what, timeout=10.0):
        """The server fails the connection: a close frame with one of `codes` (or, for None in codes, a
        TCP close without one), then EOF. Data frames before it are skipped."""
        self.sock.settimeout(timeout)
        try:
            while True:
                self.recv()
        except Closed as c:
            code = c.code
        except (ConnectionResetError, BrokenPipeError):
            code = None
        except socket.timeout:
            raise AssertionError("%s: no close within %.0f s" % (what, timeout))
        expect(code in codes, "%s: close code %r, want one of %r" % (what, code, codes))
        # The server closes the TCP connection after the handshake (or at once).
        try:
            self.send(OP_CLOSE, struct.pack("!H", 1000))
        except OSError:
            pass
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                if not self.sock.recv(65536):
                    return code
            except OSError:
                return code
        raise AssertionError("%s: TCP connection still open after the close" % what)

    def close(self):
        try:
            self.sock.close()
        except OSError:
            pass


def xor_mask(payload, key):
    if not payload:
        return payload
    n = len(payload)
    k = (key * (n // 4 + 1))[:n]
    return (int.from_bytes(payload, "little") ^ int.from_bytes(k, "little")).to_bytes(n, "little")


# ---- the two echoes ------------------------------------------------------------------------------------

def rr_str(s):
    b = s.encode() if isinstance(s, str) else s
    return struct.pack("<H", len(b)) + b


def rr_message(entry_type, member, request_id, elements=b"", n_elements=0, sender=None, path="", endpoint=0):
    """A v2 message with one entry (wire.md §1.2–1.4)."""
    entry_body = (struct.pack("<HH", entry_type, 0) + rr_str(path) + rr_str(member) +
                  struct.pack("<IH", request_id, 0) + rr_str("") + struct.pack("<H", n_elements) + elements)
    entry = struct.pack("<I", 4 + len(entry_body)) + entry_body
    sender = sender or uuid.uuid4().bytes
    header_rest = (struct.pack("<HH", 2, 64) + sender + bytes(16) + struct.pack("<II", 0, 0) +
                   rr_str("") + rr_str("") + rr_str("") + struct.pack("<HHH", 1, 0, 0))
    header_rest = header_rest[:4 + 32] + struct.pack("<I", endpoint) + header_rest[4 + 36:]
    total = 8 + len(header_rest) + len(entry)
    return b"RRAC" + struct.pack("<I", total) + header_rest + entry


def rr_element_uint32s(name, values):
    data = b"".join(struct.pack("<I", v) for v in values)
    body = rr_str(name) + struct.pack("<H", 8) + rr_str("") + rr_str("") + struct.pack("<I", len(values)) + data
    return struct.pack("<I", 4 + len(body)) + body


def rr_element_string(name, value):
    body = rr_str(name) + struct.pack("<H", 11) + rr_str("") + rr_str("") + struct.pack("<I", len(value)) + value
    return struct.pack("<I", 4 + len(body)) + body


def rr_parse_entry(msg):
    """(entry type, request id) of the first entry of a v2 message."""
    expect(msg[:4] == b"RRAC", "reply magic %r" % msg[:4])
    hsize = struct.unpack_from("<H", msg, 10)[0]
    e = hsize
    etype = struct.unpack_from("<H", msg, e + 4)[0]
    p = e + 8
    p += 2 + struct.unpack_from("<H", msg, p)[0]  # service path
    p += 2 + struct.unpack_from("<H", msg, p)[0]  # member name
    rid = struct.unpack_from("<I", msg, p)[0]
    return etype, rid


class RrEcho:
    """An RR connection over a WebSocket: CreateConnection, then padded ConnectionTests."""

    def __init__(self, port, subprotocol=RR_SUBPROTOCOL, session=False):
        self.ws = RawWs(port, subprotocol)
        self.pending = b""
        self.rid = 0
        self.sender = uuid.uuid4().bytes
        cc = rr_message(1, "CreateConnection", 0, rr_element_uint32s("capabilities", [0x02000003]), 1, self.sender)
        self.ws.send(OP_BIN, cc)
        etype, _ = rr_parse_entry(self.read_message())
        expect(etype == 2, "CreateConnection answered with entry type %d" % etype)
        if session:
            # A client session with the gateway's service index lifts the 512 KiB pre-session limit to
            # 12 MiB (wire.md §6.4).
            self.rid += 1
            self.ws.send(OP_BIN, rr_message(107, "", self.rid, sender=self.sender, path="RobotRaconteurServiceIndex",
                                            endpoint=7))
            etype, rid = rr_parse_entry(self.read_message())
            expect(etype == 108 and rid == self.rid, "ConnectClient answered with entry %d" % etype)

    def read_message(self):
        while True:
            if len(self.pending) >= 8:
                size = struct.unpack_from("<I", self.pending, 4)[0]
                if len(self.pending) >= size:
                    msg, self.pending = self.pending[:size], self.pending[size:]
                    return msg
            op, data = self.ws.recv()
            expect(op == OP_BIN, "RR over WebSocket answered with opcode %d" % op)
            self.pending += data

    def message_of_size(self, size):
        """A ConnectionTest message of exactly `size` bytes (size >= 150)."""
        self.rid += 1
        bare = rr_message(111, "", self.rid, rr_element_string("pad", b""), 1, self.sender)
        pad = size - len(bare)
        expect(pad >= 0, "message size %d below the minimum %d" % (size, len(bare)))
        msg = rr_message(111, "", self.rid, rr_element_string("pad", b"x" * pad), 1, self.sender)
        assert len(msg) == size
        return msg

    def expect_reply(self):
        etype, rid = rr_parse_entry(self.read_message())
        expect(etype == 112 and rid == self.rid, "reply entry %d request %d, want 112 / %d" % (etype, rid, self.rid))

    def roundtrip(self, size, frame_sizes=None, opcode=OP_BIN):
        """One message of `size` bytes sent in frames of `frame_sizes` (a list, cycled; None: one frame);
        each frame a complete message (FIN set), as RR's byte stream allows."""
        msg = self.message_of_size(size)
        if frame_sizes is None:
            self.ws.send(opcode, msg)
        else:
            i, k = 0, 0
            while i < len(msg):
                n = frame_sizes[k % len(frame_sizes)]
                self.ws.send(opcode, msg[i:i + n])
                i += n
                k += 1
        self.expect_reply()


class JsonEcho:
    def __init__(self, port, extensions=None):
        self.ws = RawWs(port, JSON_SUBPROTOCOL, extensions=extensions)

    @staticmethod
    def message_of_size(size, tag="p"):
        bare = json.dumps({"id": tag, "op": "devices"}, separators=(",", ":"))
        pad = size - len(bare.encode())
        expect(pad >= 0, "JSON message size %d below %d" % (size, len(bare)))
        ident = tag + "x" * pad
        text = json.dumps({"id": ident, "op": "devices"}, separators=(",", ":")).encode()
        assert len(text) == size
        return ident, text

    def expect_reply(self, ident):
        while True:
            op, data = self.ws.recv()
            expect(op == OP_TEXT, "JSON reply in opcode %d" % op)
            reply = json.loads(data.decode("utf-8"))
            if "id" in reply:  # pushes (device_state, subscriptions) carry no id
                break
        expect(reply.get("id") == ident, "reply to id %r...: %r" % (ident[:20], str(reply)[:200]))
        return reply

    def roundtrip(self, size, fragments=None):
        ident, text = self.message_of_size(size)
        send_fragmented(self.ws, OP_TEXT, text, fragments)
        self.expect_reply(ident)


def send_fragmented(ws, opcode, payload, fragments, between=None):
    """`payload` as one message in fragments of the sizes `fragments` (cycled; None: one frame).
    `between(i)` runs after fragment i (to interleave control frames)."""
    if not fragments:
        ws.send(opcode, payload)
        return
    i, k = 0, 0
    while True:
        n = fragments[k % len(fragments)]
        part = payload[i:i + n]
        last = i + n >= len(payload)
        ws.send(opcode if k == 0 else OP_CONT, part, fin=last)
        if last:
            return
        if between:
            between(k)
        i += n
        k += 1


# ---- the groups ----------------------------------------------------------------------------------------

BOUNDARIES = [125, 126, 127, 128, 65535, 65536, 65537]
FAIL = (1002,)  # protocol error


def group1(c, port):
    """1 Framing: text and binary messages at every length boundary (7-bit, 16-bit and 64-bit forms)."""
    def rr_lengths():
        e = RrEcho(port)
        for n in [150] + BOUNDARIES + [200000, 500000]:
            if n >= 150:
                e.roundtrip(n)
        # The frame (not the message) at each boundary: one RR message cut into frames of that size.
        for f in [1, 125, 126, 127, 65535, 65536]:
            e.roundtrip(max(3 * f + 7, 400), [f])
        # A zero-length binary frame between messages is no data.
        e.ws.send(OP_BIN, b"")
        e.roundtrip(300)
        e.ws.close()
        # RFC 6455 §5.2: "the minimal number of bytes MUST be used to encode the length": a 100-byte
        # frame in the 16-bit or 64-bit form fails the connection.
        for form in (16, 64):
            e = RrEcho(port)
            e.ws.send(OP_BIN, e.message_of_size(200)[:100], length_form=form)
            e.ws.expect_close(FAIL, "a 100-byte frame in the %d-bit length form" % form)
            e.ws.close()

    c.run("1 rr: binary messages of 150..500000 bytes, frames of 1/125/126/127/65535/65536 bytes, non-minimal lengths refused", rr_lengths)

    def json_lengths():
        e = JsonEcho(port)
        for n in [40, 125, 126, 127, 128, 65535, 65536, 65537, 500000]:
            e.roundtrip(n)
        e.ws.close()

    c.run("1 json: text messages of 40..500000 bytes (125/126/127/65535/65536 boundaries)", json_lengths)

    def json_empty_text():
        e = JsonEcho(port)
        e.ws.send(OP_TEXT, b"")
        op, data = e.ws.recv()
        reply = json.loads(data)
        expect(reply.get("id") is None and "error" in reply, "empty text message: %r" % reply)
        e.roundtrip(100)
        e.ws.close()

    c.run("1 json: an empty text message gets an error reply, the socket stays open", json_empty_text)

    def binary_on_json():
        e = JsonEcho(port)
        e.ws.send(OP_BIN, b'{"id":1,"op":"devices"}')
        op, data = e.ws.recv()
        reply = json.loads(data)
        expect(reply.get("error") is not None or reply.get("id") == 1, "binary frame on the JSON socket: %r" % reply)
        e.roundtrip(100)
        e.ws.close()

    c.run("1 json: a binary frame is answered (as JSON text) and the socket stays open", binary_on_json)


def group2(c, port):
    """2 Pings and pongs."""
    def ping_payloads(make):
        e = make()
        for n in (0, 1, 10, 125):
            payload = os.urandom(n)
            e.ws.send(OP_PING, payload)
            fin, op, data = e.ws.recv_frame()
            expect(op == OP_PONG and data == payload and fin, "pong for a %d-byte ping: op %d, %d bytes" % (n, op, len(data)))
        e.roundtrip(200)
        e.ws.close()

    def too_long_ping(make):
        e = make()
        e.ws.send(OP_PING, b"x" * 126)
        e.ws.expect_close(FAIL, "ping of 126 bytes")
        e.ws.close()

    def fragmented_ping(make):
        e = make()
        e.ws.send(OP_PING, b"abc", fin=False)
        e.ws.expect_close(FAIL, "ping without FIN")
        e.ws.close()

    def unsolicited_pong(make):
        e = make()
        e.ws.send(OP_PONG, b"")
        e.ws.send(OP_PONG, b"unsolicited" * 10)
        e.roundtrip(200)
        e.ws.close()

    def ping_flood(make):
        e = make()
        n = 1000
        e.ws.send_raw(b"".join(e.ws.frame(OP_PING, struct.pack("!I", i)) for i in range(n)))
        got = []
        e.ws.sock.settimeout(20)
        while len(got) < n:
            fin, op, data = e.ws.recv_frame()
            if op == OP_PONG:
                got.append(struct.unpack("!I", data)[0])
        expect(got == list(range(n)), "pongs out of order or missing")
        e.roundtrip(200)
        e.ws.close()

    for name, make in (("rr", lambda: RrEcho(port)), ("json", lambda: JsonEcho(port))):
        c.run("2 %s: pings of 0/1/10/125 bytes get pongs with the same payload" % name, lambda m=make: ping_payloads(m))
        c.run("2 %s: a 126-byte ping fails the connection (1002)" % name, lambda m=make: too_long_ping(m))
        c.run("2 %s: a fragmented ping (FIN clear) fails the connection (1002)" % name, lambda m=make: fragmented_ping(m))
        c.run("2 %s: unsolicited pongs are ignored" % name, lambda m=make: unsolicited_pong(m))
        c.run("2 %s: a flood of 1000 pings gets 1000 pongs in order" % name, lambda m=make: ping_flood(m))


def group3(c, port):
    """3 Reserved bits: any RSV bit without a negotiated extension fails the connection."""
    for name, make, op, payload in (("rr", lambda: RrEcho(port), OP_BIN, None),
                                    ("json", lambda: JsonEcho(port), OP_TEXT, b'{"id":1,"op":"devices"}')):
        for rsv in range(1, 8):
            for frame_op in (op, OP_PING, OP_CLOSE):
                def run(make=make, rsv=rsv, frame_op=frame_op, payload=payload):
                    e = make()
                    data = payload if payload is not None else e.message_of_size(200)
                    if frame_op == OP_CLOSE:
                        data = struct.pack("!H", 1000)
                    elif frame_op == OP_PING:
                        data = b"ping"
                    e.ws.send(frame_op, data, rsv=rsv)
                    e.ws.expect_close(FAIL, "RSV %d on opcode %d" % (rsv, frame_op))
                    e.ws.close()

                c.run("3 %s: RSV=%d on opcode %d fails the connection (1002)" % (name, rsv, frame_op), run)


def group4(c, port):
    """4 Opcodes: reserved data (3-7) and control (11-15) opcodes fail the connection."""
    for name, make in (("rr", lambda: RrEcho(port)), ("json", lambda: JsonEcho(port))):
        for op in (3, 4, 5, 6, 7, 11, 12, 13, 14, 15):
            def run(make=make, op=op):
                e = make()
                e.ws.send(op, b"" if op % 2 else b"payload")
                e.ws.expect_close(FAIL, "opcode %d" % op)
                e.ws.close()

            c.run("4 %s: reserved opcode %d fails the connection (1002)" % (name, op), run)


def group5(c, port):
    """5 Fragmentation."""
    def rr_fragments():
        e = RrEcho(port)
        msg = e.message_of_size(1000)
        send_fragmented(e.ws, OP_BIN, msg, [1, 7, 100, 400])
        e.expect_reply()
        # Ping and pong interleaved between fragments: the pong comes before the message completes.
        msg = e.message_of_size(3000)
        pongs = []

        def between(k):
            e.ws.send(OP_PING, b"p%d" % k)
            fin, op, data = e.ws.recv_frame()
            pongs.append((op, data))
            e.ws.send(OP_PONG, b"u")

        send_fragmented(e.ws, OP_BIN, msg, [1000], between)
        expect(pongs == [(OP_PONG, b"p0"), (OP_PONG, b"p1")], "pongs between fragments: %r" % pongs)
        e.expect_reply()
        e.ws.close()

    c.run("5 rr: binary message in fragments of 1..400 bytes; pings and pongs between fragments", rr_fragments)

    def json_fragments():
        e = JsonEcho(port)
        ident, text = e.message_of_size(5000)
        send_fragmented(e.ws, OP_TEXT, text, [1, 3, 64, 1000])
        e.expect_reply(ident)
        ident, text = e.message_of_size(70000)
        pongs = []

        def between(k):
            e.ws.send(OP_PING, b"q%d" % k)
            fin, op, data = e.ws.recv_frame()
            pongs.append((op, data))

        send_fragmented(e.ws, OP_TEXT, text, [30000], between)
        expect(pongs == [(OP_PONG, b"q0"), (OP_PONG, b"q1")], "pongs between fragments: %r" % pongs)
        e.expect_reply(ident)
        # Empty fragments (first, middle, last) are part of the message.
        ident, text = e.message_of_size(100)
        e.ws.send(OP_TEXT, b"", fin=False)
        e.ws.send(OP_CONT, text[:50], fin=False)
        e.ws.send(OP_CONT, b"", fin=False)
        e.ws.send(OP_CONT, text[50:], fin=False)
        e.ws.send(OP_CONT, b"", fin=True)
        e.expect_reply(ident)
        e.ws.close()

    c.run("5 json: text message in fragments of 1..30000 bytes, pings between, empty fragments", json_fragments)

    for name, make, op in (("rr", lambda: RrEcho(port), OP_BIN), ("json", lambda: JsonEcho(port), OP_TEXT)):
        def cont_without_start(make=make):
            e = make()
            e.ws.send(OP_CONT, b"abc", fin=True)
            e.ws.expect_close(FAIL, "continuation without a start")
            e.ws.close()

        def cont_without_start_nofin(make=make):
            e = make()
            e.ws.send(OP_CONT, b"abc", fin=False)
            e.ws.send(OP_CONT, b"def", fin=True)
            e.ws.expect_close(FAIL, "continuation (FIN clear) without a start")
            e.ws.close()

        def new_message_inside(make=make, op=op):
            e = make()
            data = e.message_of_size(400) if op == OP_BIN else b'{"id":1,"op":"devices"}'
            e.ws.send(op, data[:10], fin=False)
            e.ws.send(op, data[10:], fin=True)
            e.ws.expect_close(FAIL, "a new data frame inside a fragmented message")
            e.ws.close()

        def fragmented_control(make=make):
            e = make()
            e.ws.send(OP_PONG, b"ab", fin=False)
            e.ws.send(OP_CONT, b"cd", fin=True)
            e.ws.expect_close(FAIL, "a fragmented pong")
            e.ws.close()

        c.run("5 %s: continuation (FIN set) without a start fails the connection" % name, cont_without_start)
        c.run("5 %s: continuation (FIN clear) without a start fails the connection" % name, cont_without_start_nofin)
        c.run("5 %s: a new data frame inside a fragmented message fails the connection" % name, new_message_inside)
        c.run("5 %s: a fragmented control frame fails the connection" % name, fragmented_control)


VALID_UTF8 = ["κόσμε", "\u0080", "\u07ff", "\u0800", "\uffff", "\U00010000", "\U0010ffff", "\ud7ff", "\ue000",
              "\ufffd", "Hello-µ@ßöäüàá-UTF-8!!"]
INVALID_UTF8 = [b"\xce\xba\xe1\xbd\xb9\xcf\x83\xce\xbc\xce\xb5\xed\xa0\x80edited",  # surrogate
                b"\x80", b"\xbf", b"\xc0\xaf", b"\xe0\x80\xaf", b"\xf0\x80\x80\xaf", b"\xf4\x90\x80\x80",
                b"\xf5\x80\x80\x80", b"\xfe", b"\xff", b"\xed\xa0\x80", b"\xed\xbf\xbf", b"\xc1\xbf",
                b"\xe0\x9f\xbf", b"\xce", b"\xe1\xbd"]


def group6(c, port):
    """6 UTF-8 handling of text frames (the JSON subprotocol; text on the RR subprotocol is refused)."""
    def valid():
        e = JsonEcho(port)
        for i, s in enumerate(VALID_UTF8):
            ident = "u%d-%s" % (i, s)
            text = json.dumps({"id": ident, "op": "devices"}, ensure_ascii=False).encode("utf-8")
            e.ws.send(OP_TEXT, text)
            e.expect_reply(ident)
            # The same, cut inside every multi-byte sequence (one byte per fragment).
            send_fragmented(e.ws, OP_TEXT, text, [1])
            e.expect_reply(ident)
        e.ws.close()

    c.run("6 json: valid UTF-8 (boundary code points) whole and split byte by byte across fragments", valid)

    for k, bad in enumerate(INVALID_UTF8):
        def whole(bad=bad):
            e = JsonEcho(port)
            e.ws.send(OP_TEXT, b'{"id":"' + bad + b'","op":"devices"}')
            e.ws.expect_close((1007,), "invalid UTF-8 %r" % bad)
            e.ws.close()

        c.run("6 json: invalid UTF-8 %s fails the connection (1007)" % bad.hex(), whole)

    def split_invalid_fails_fast():
        # The invalid byte is in the first fragment: the server fails before the message is complete.
        e = JsonEcho(port)
        e.ws.send(OP_TEXT, b'{"id":"\xc0\xaf', fin=False)
        e.ws.expect_close((1007,), "invalid UTF-8 in the first fragment", timeout=5)
        e.ws.close()

    c.run("6 json: invalid UTF-8 in the first fragment fails at once (1007), not at the end", split_invalid_fails_fast)

    def truncated_at_end():
        e = JsonEcho(port)
        e.ws.send(OP_TEXT, b'{"id":"a","op":"devices"}\xe2\x82', fin=False)
        e.ws.send(OP_CONT, b"", fin=True)
        e.ws.expect_close((1007,), "a message ending inside a UTF-8 sequence")
        e.ws.close()

    c.run("6 json: a text message ending inside a UTF-8 sequence fails (1007)", truncated_at_end)

    def text_on_rr():
        ws = RawWs(port, RR_SUBPROTOCOL)
        ws.send(OP_TEXT, b"hello")
        ws.expect_close((1002, 1003, 1008, None), "a text frame on the RR subprotocol")
        ws.close()

    c.run("6 rr: a text frame on the RR subprotocol ends the connection", text_on_rr)


VALID_CLOSE = [1000, 1001, 1002, 1003, 1007, 1008, 1009, 1010, 1011, 3000, 3999, 4000, 4999]
# Autobahn 7.9.x's invalid codes plus 1015. 1012-1014 (registered with IANA after
# RFC 6455) and codes of 5000 and more (the RFC defines no range there) are in neither list: Beast
# accepts them, Autobahn does not test them.
INVALID_CLOSE = [0, 999, 1004, 1005, 1006, 1015, 1016, 1100, 2000, 2999]


def group7(c, port):
    """7 Close handshake and codes."""
    for name, make in (("rr", lambda: RrEcho(port)), ("json", lambda: JsonEcho(port))):
        def normal(make=make):
            e = make()
            e.ws.send(OP_CLOSE, struct.pack("!H", 1000) + b"bye")
            code = e.ws.expect_close((1000,), "close 1000")
            e.ws.close()

        def empty(make=make):
            e = make()
            e.ws.send(OP_CLOSE, b"")
            e.ws.expect_close((1000, 1005), "empty close")
            e.ws.close()

        def one_byte(make=make):
            e = make()
            e.ws.send(OP_CLOSE, b"\x03")
            e.ws.expect_close(FAIL, "1-byte close payload")
            e.ws.close()

        def valid_codes(make=make):
            for code in VALID_CLOSE:
                e = make()
                e.ws.send(OP_CLOSE, struct.pack("!H", code))
                e.ws.expect_close((code, 1000), "close %d" % code)
                e.ws.close()

        def invalid_codes(make=make):
            for code in INVALID_CLOSE:
                e = make()
                e.ws.send(OP_CLOSE, struct.pack("!H", code))
                e.ws.expect_close(FAIL, "close code %d" % code)
                e.ws.close()

        def long_reason(make=make):
            e = make()
            e.ws.send(OP_CLOSE, struct.pack("!H", 1000) + b"r" * 123)
            e.ws.expect_close((1000,), "close with a 123-byte reason")
            e.ws.close()
            e = make()
            e.ws.send(OP_CLOSE, struct.pack("!H", 1000) + b"r" * 124)
            e.ws.expect_close(FAIL, "close payload of 126 bytes")
            e.ws.close()

        def bad_utf8_reason(make=make):
            e = make()
            e.ws.send(OP_CLOSE, struct.pack("!H", 1000) + b"\xc0\xaf")
            e.ws.expect_close((1007, 1002), "close reason with invalid UTF-8")
            e.ws.close()

        def data_after_close(make=make):
            e = make()
            e.ws.send_raw(e.ws.frame(OP_CLOSE, struct.pack("!H", 1000)) + e.ws.frame(OP_PING, b"after") +
                          e.ws.frame(OP_BIN, b"after"))
            e.ws.sock.settimeout(10)
            frames = []
            try:
                while True:
                    frames.append(e.ws.recv_frame()[1])
            except Closed:
                pass
            except (ConnectionResetError, BrokenPipeError):
                pass
            expect(frames and frames[-1] == OP_CLOSE and OP_PONG not in frames,
                   "frames after the client's close must be ignored: server sent opcodes %r" % frames)
            e.ws.close()

        def close_mid_message(make=make, name=name):
            e = make()
            data = e.message_of_size(400) if name == "rr" else b'{"id":1,"op":"devices"}'
            e.ws.send(OP_TEXT if name == "json" else OP_BIN, data[:10], fin=False)
            e.ws.send(OP_CLOSE, struct.pack("!H", 1000))
            e.ws.expect_close((1000,), "close inside a fragmented message")
            e.ws.close()

        def tcp_drop(make=make):
            for _ in range(20):
                e = make()
                e.ws.send(OP_BIN if name == "rr" else OP_TEXT, b"x", fin=False)
                e.ws.sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
                e.ws.close()  # RST, no close frame
            make().roundtrip(200)

        c.run("7 %s: close 1000 with a reason is answered with 1000, then TCP closes" % name, normal)
        c.run("7 %s: an empty close frame is answered" % name, empty)
        c.run("7 %s: a 1-byte close payload fails the connection (1002)" % name, one_byte)
        c.run("7 %s: valid close codes %s are answered" % (name, VALID_CLOSE), valid_codes)
        c.run("7 %s: invalid close codes %s fail the connection (1002)" % (name, INVALID_CLOSE), invalid_codes)
        c.run("7 %s: 123-byte close reason accepted, 124 bytes (126-byte control frame) refused" % name, long_reason)
        c.run("7 %s: a close reason with invalid UTF-8 fails the connection" % name, bad_utf8_reason)
        c.run("7 %s: frames after the client's close frame are ignored" % name, data_after_close)
        c.run("7 %s: a close frame inside a fragmented message is answered" % name, close_mid_message)
        c.run("7 %s: 20 connections dropped with RST mid-message; a new one works" % name, tcp_drop)


def group9(c, port, gw):
    """9 Large messages and many small ones (Autobahn's 'limits/performance'), and the size limits."""
    def rr_large():
        e = RrEcho(port, session=True)
        for n in (4 << 20, (12 << 20) - 1000):
            t0 = time.monotonic()
            e.roundtrip(n, [65536])
            print("    rr %d byte message in 64 KiB frames: %.2f s" % (n, time.monotonic() - t0), file=sys.stderr)
        t0 = time.monotonic()
        e.roundtrip(4 << 20)  # one 4 MiB frame
        print("    rr 4 MiB message in one frame: %.2f s" % (time.monotonic() - t0), file=sys.stderr)
        e.ws.close()

    c.run("9 rr: 4 MiB and ~12 MiB (the RR limit) messages in 64 KiB frames, 4 MiB in one frame", rr_large)

    def many_small():
        e = RrEcho(port)
        n = 2000
        msgs = []
        for i in range(n):
            msgs.append(e.ws.frame(OP_BIN, e.message_of_size(160)))
        t0 = time.monotonic()
        e.ws.send_raw(b"".join(msgs))
        first = e.rid - n + 1
        for i in range(n):
            etype, rid = rr_parse_entry(e.read_message())
            expect(etype == 112 and rid == first + i, "reply %d: entry %d rid %d" % (i, etype, rid))
        print("    rr %d small messages: %.2f s" % (n, time.monotonic() - t0), file=sys.stderr)
        j = JsonEcho(port)
        frames, ids = [], []
        for i in range(500):
            ident, text = JsonEcho.message_of_size(60, "m%d" % i)
            frames.append(j.ws.frame(OP_TEXT, text))
            ids.append(ident)
        j.ws.send_raw(b"".join(frames))
        got = set()
        for _ in ids:
            op, data = j.ws.recv()
            got.add(json.loads(data)["id"])
        expect(got == set(ids), "every one of 500 pipelined JSON requests answered")
        e.ws.close()
        j.ws.close()

    c.run("9 rr+json: 2000 pipelined RR messages and 500 JSON requests all answered in order", many_small)

    for name, make, op in (("rr", lambda: RrEcho(port), OP_BIN), ("json", lambda: JsonEcho(port), OP_TEXT)):
        def huge_header(make=make, op=op):
            rss0 = gwproc.vm_rss_kib(gw.pid)
            e = make()
            # A frame header announcing 2^63-1 bytes, and one announcing 100 MiB: refused from the header
            # (1009, message too big) without waiting for or buffering the payload.
            e.ws.send_raw(struct.pack("!BBQ", 0x80 | op, 0x80 | 127, (1 << 63) - 1) + os.urandom(4) + b"abc")
            e.ws.expect_close((1009,), "a frame of 2^63-1 bytes", timeout=5)
            e.ws.close()
            e = make()
            e.ws.send_raw(struct.pack("!BBQ", 0x80 | op, 0x80 | 127, 100 << 20) + os.urandom(4) + b"abc")
            e.ws.expect_close((1009,), "a frame of 100 MiB", timeout=5)
            e.ws.close()
            grown = gwproc.vm_rss_kib(gw.pid) - rss0
            expect(grown < 32 * 1024, "RSS grew %d KiB" % grown)

        def over_limit_fragments(make=make, op=op, name=name):
            # json: 65 MiB in 1 MiB fragments, over the 64 MiB WebSocket message limit -> 1009 before the end.
            # rr: the RR byte stream has its own 12 MiB message limit, reached first: an RR header
            # announcing 4 GiB - 1 ends the connection at once, whatever the WebSocket framing.
            e = make()
            if name == "rr":
                head = b"RRAC" + struct.pack("<IHH", 0xFFFFFFFF, 2, 64) + bytes(52)
                e.ws.send(OP_BIN, head, fin=False)
                e.ws.expect_close((None, 1002, 1008, 1009), "an RR message header announcing 4 GiB", timeout=5)
                e.ws.close()
                return
            chunk = b"a" * (1 << 20)
            try:
                for i in range(65):
                    e.ws.send(op if i == 0 else OP_CONT, chunk, fin=False)
            except (BrokenPipeError, ConnectionResetError):
                pass
            e.ws.expect_close((1009,), "a fragmented message over 64 MiB")
            e.ws.close()

        c.run("9 %s: frame headers of 2^63-1 and 100 MiB are refused at once (1009), RSS flat" % name, huge_header)
        c.run("9 %s: a message over the limit (json: 64 MiB WebSocket; rr: 4 GiB RR header) ends the connection" % name,
              over_limit_fragments)

    def json_over_api_limit():
        e = JsonEcho(port)
        e.ws.send(OP_TEXT, b'{"id":"big","op":"devices","pad":"' + b"y" * (1 << 20) + b'"}')
        op, data = e.ws.recv()
        reply = json.loads(data)
        expect(reply.get("error", {}).get("name") == "RobotRaconteur.BufferLimitViolation",
               "a 1 MiB JSON request: %r" % str(reply)[:200])
        e.roundtrip(100)
        e.ws.close()

    c.run("9 json: a request over the 1 MiB API limit gets BufferLimitViolation, the socket stays open",
          json_over_api_limit)


def group10(c, port):
    """10 Fragment sizes: a 64 KiB message in fragments of every power of two (Autobahn 10.1 style)."""
    def run():
        e = RrEcho(port)
        j = JsonEcho(port)
        for f in (1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 4096, 65536):
            if f >= 64:
                msg = e.message_of_size(65536)
                send_fragmented(e.ws, OP_BIN, msg, [f])
                e.expect_reply()
            ident, text = JsonEcho.message_of_size(65536 if f >= 64 else 4096)
            send_fragmented(j.ws, OP_TEXT, text, [f])
            j.expect_reply(ident)
        e.ws.close()
        j.ws.close()

    c.run("10 rr+json: 64 KiB messages in fragments of 1..65536 bytes", run)


def group12(c, port):
    """12/13 permessage-deflate: the gateway does not offer it, so an offer is declined and nothing is compressed."""
    def run():
        for make in (lambda ext: RawWs(port, RR_SUBPROTOCOL, extensions=ext),
                     lambda ext: RawWs(port, JSON_SUBPROTOCOL, extensions=ext)):
            ws = make("permessage-deflate; client_max_window_bits, permessage-deflate; server_no_context_takeover")
            expect("sec-websocket-extensions" not in ws.headers,
                   "the handshake accepted extensions: %r" % ws.headers.get("sec-websocket-extensions"))
            ws.close()
        e = JsonEcho(port, extensions="permessage-deflate")
        e.roundtrip(5000)
        # A compressed (RSV1) frame after a declined offer is a protocol error.
        e.ws.send(OP_TEXT, b"\xaa\x56\xca\x4c\x51\xb2\x32\xd4\x51\xca\x2f\x50\xb2\x52\x4a\x49\x2d\xcb\x4c\x4e\x2d\x56\xaa\x05\x00", rsv=4)
        e.ws.expect_close(FAIL, "RSV1 frame after a declined permessage-deflate")
        e.ws.close()

    c.run("12/13: permessage-deflate offers are declined; an RSV1 frame then fails the connection", run)


def group_rfc(c, port):
    """RFC 6455 §5.1 beyond Autobahn's server cases: client frames must be masked."""
    for name, make, op in (("rr", lambda: RrEcho(port), OP_BIN), ("json", lambda: JsonEcho(port), OP_TEXT)):
        def unmasked(make=make, op=op):
            e = make()
            e.ws.send(op, b'{"id":1,"op":"devices"}', mask=False)
            e.ws.expect_close(FAIL, "an unmasked client frame")
            e.ws.close()

        c.run("rfc %s: an unmasked client frame fails the connection (1002)" % name, unmasked)


GROUPS = {"1": group1, "2": group2, "3": group3, "4": group4, "5": group5, "6": group6, "7": group7,
          "9": group9, "10": group10, "12": group12, "rfc": group_rfc}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gateway", required=True)
    ap.add_argument("--group", action="append", help="run only these groups (1..12, rfc)")
    args = ap.parse_args()
    checks = gwproc.Checks()
    gw = gwproc.start_gateway(args.gateway, ["--no-demo"])
    try:
        gwproc.wait_ready(gw.port)
        rss0 = gwproc.vm_rss_kib(gw.pid)
        for key, fn in GROUPS.items():
            if args.group and key not in args.group:
                continue
            if key == "9":
                fn(checks, gw.port, gw)
            else:
                fn(checks, gw.port)
            if not gw.alive():
                checks.run("gateway alive after group %s" % key, lambda: expect(False, "gateway exited"))
                break
        # Other clients unaffected: a fresh RR and JSON connection still work after all of the above.
        checks.run("after all groups: new RR and JSON WebSockets work", lambda: (RrEcho(gw.port).roundtrip(300),
                                                                              JsonEcho(gw.port).roundtrip(300)))
        print("    gateway RSS %d KiB at start, %d KiB at the end" % (rss0, gwproc.vm_rss_kib(gw.pid)), file=sys.stderr)
    finally:
        status = gw.stop()
    checks.run("gateway exit status 0 on SIGTERM", lambda: expect(status == 0, "exit status %r" % status))
    return checks.exit_code()


if __name__ == "__main__":
    sys.exit(main())
