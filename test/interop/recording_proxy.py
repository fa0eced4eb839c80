#!/usr/bin/env python3
"""A recording TCP proxy for Robot Raconteur streams.

Listens on a port, connects every accepted connection to TARGET host:port, forwards bytes both ways
unchanged and immediately, and splits each direction's byte stream into RR messages using the 8-byte
preamble ("RRAC" + uint32 LE MessageSize, wire.md §6). Every complete message is appended to the
capture file. Any number of connections (the official client opens one TCP connection per service).

Usage:
    recording_proxy.py --target HOST:PORT --capture FILE [--listen-port N] [--max-lifetime S]
When ready it prints one JSON line on stdout: {"port": N, "target": "HOST:PORT", "capture": FILE}.
Runs until SIGTERM/SIGINT (or --max-lifetime), then closes every connection and exits 0; on exit it
prints counters as one JSON line on stderr.

Capture file format (all integers little-endian):
    file   = magic record*
    magic  = the 8 bytes  b"RRCAP1\\n\\0"
    record = kind:uint8  connection:uint32  length:uint32  bytes[length]
    kind   = 'C' (0x43) one complete RR message, client -> server
             'S' (0x53) one complete RR message, server -> client
             'c' / 's'  raw bytes of that direction that could not be framed as RR messages: a stream
                        that does not start with "RRAC" (e.g. a WebSocket "GET "), a bad preamble
                        (then the rest of that direction is raw), or an incomplete message at close
             'O' (0x4F) connection accepted (length 0)
             'X' (0x58) connection finished, both directions closed (length 0)
    connection = 1, 2, 3, ... in accept order.
Records are written in the order the bytes were received and flushed as they are written.
"""

import argparse
import asyncio
import json
import signal
import struct
import sys

MAGIC = b"RRCAP1\n\0"
PREAMBLE = 8
MAX_MESSAGE = 64 * 1024 * 1024  # larger than any RR limit; only to detect garbage


class Capture:
    def __init__(self, path):
        self.f = open(path, "wb")
        self.f.write(MAGIC)
        self.f.flush()
        self.counts = {}

    def record(self, kind, conn, data=b""):
        self.f.write(struct.pack("<BII", ord(kind), conn, len(data)))
        self.f.write(data)
        self.f.flush()
        self.counts[kind] = self.counts.get(kind, 0) + 1

    def close(self):
        self.f.close()


class Framer:
    """Splits one direction's byte stream into RR messages."""

    def __init__(self, capture, conn, msg_kind, raw_kind):
        self.capture, self.conn, self.msg_kind, self.raw_kind = capture, conn, msg_kind, raw_kind
        self.buf = bytearray()
        self.raw = False

    def feed(self, data):
        if self.raw:
            self.capture.record(self.raw_kind, self.conn, bytes(data))
            return
        self.buf += data
        while len(self.buf) >= PREAMBLE:
            size = struct.unpack_from("<I", self.buf, 4)[0]
            if self.buf[:4] != b"RRAC" or size < PREAMBLE or size > MAX_MESSAGE:
                print("recording_proxy: connection %d %s: not an RR preamble, recording raw bytes"
                      % (self.conn, self.msg_kind), file=sys.stderr, flush=True)
                self.raw = True
                self.capture.record(self.raw_kind, self.conn, bytes(self.buf))
                self.buf.clear()
                return
            if len(self.buf) < size:
                return
            self.capture.record(self.msg_kind, self.conn, bytes(self.buf[:size]))
            del self.buf[:size]

    def finish(self):
        if self.buf:
            self.capture.record(self.raw_kind, self.conn, bytes(self.buf))
            self.buf.clear()


class Proxy:
    def __init__(self, target_host, target_port, capture):
        self.target_host, self.target_port, self.capture = target_host, target_port, capture
        self.next_conn = 1
        self.tasks = set()
        self.writers = set()

    async def handle(self, client_reader, client_writer):
        conn = self.next_conn
        self.next_conn += 1
        self.capture.record("O", conn)
        self.writers.add(client_writer)
        server_writer = None
        try:
            server_reader, server_writer = await asyncio.wait_for(
                asyncio.open_connection(self.target_host, self.target_port), 10)
            self.writers.add(server_writer)
            await asyncio.gather(
                self.pump(client_reader, server_writer, Framer(self.capture, conn, "C", "c")),
                self.pump(server_reader, client_writer, Framer(self.capture, conn, "S", "s")))
        except (OSError, asyncio.TimeoutError) as e:
            print("recording_proxy: connection %d: %s" % (conn, e), file=sys.stderr, flush=True)
        finally:
            for w in (client_writer, server_writer):
                if w is not None:
                    self.writers.discard(w)
                    w.close()
            self.capture.record("X", conn)

    async def pump(self, reader, writer, framer):
        try:
            while True:
                data = await reader.read(65536)
                if not data:
                    break
                writer.write(data)
                framer.feed(data)
                await writer.drain()
        except (ConnectionError, OSError):
            pass
        finally:
            framer.finish()
            try:
                if writer.can_write_eof():
                    writer.write_eof()
            except (OSError, RuntimeError):
                pass

    def on_connect(self, reader, writer):
        t = asyncio.ensure_future(self.handle(reader, writer))
        self.tasks.add(t)
        t.add_done_callback(self.tasks.discard)


async def amain(args):
    host, _, port = args.target.rpartition(":")
    capture = Capture(args.capture)
    proxy = Proxy(host or "127.0.0.1", int(port), capture)
    server = await asyncio.start_server(proxy.on_connect, args.listen_host, args.listen_port)
    listen_port = server.sockets[0].getsockname()[1]
    print(json.dumps({"port": listen_port, "target": args.target, "capture": args.capture}), flush=True)

    stop = asyncio.Event()
    loop = asyncio.get_running_loop()
    for sig in (signal.SIGTERM, signal.SIGINT):
        loop.add_signal_handler(sig, stop.set)
    try:
        if args.max_lifetime > 0:
            await asyncio.wait_for(stop.wait(), args.max_lifetime)
        else:
            await stop.wait()
    except asyncio.TimeoutError:
        print("recording_proxy: max lifetime reached", file=sys.stderr, flush=True)
    server.close()
    for w in list(proxy.writers):
        w.close()
    if proxy.tasks:
        await asyncio.wait(list(proxy.tasks), timeout=5)
    capture.close()
    print(json.dumps({"recording_proxy": "stopped", "records": capture.counts}), file=sys.stderr, flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--target", required=True, help="HOST:PORT to forward to")
    ap.add_argument("--capture", required=True, help="capture file to write (overwritten)")
    ap.add_argument("--listen-host", default="127.0.0.1")
    ap.add_argument("--listen-port", type=int, default=0, help="0 = ephemeral")
    ap.add_argument("--max-lifetime", type=float, default=0, help="exit after this many seconds (0 = never)")
    args = ap.parse_args(argv)
    asyncio.run(amain(args))
    return 0


if __name__ == "__main__":
    sys.exit(main())
