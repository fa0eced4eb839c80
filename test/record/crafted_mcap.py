#!/usr/bin/env python3
"""MCAP files crafted to make a reader take memory (issue 52), written record by record (MCAP
specification, mcap.dev/spec; stdlib and the venv's `zstandard`).

- duplicate_chunk_index: one Chunk holding a 500 MiB message of zeros (about 16 KiB of zstd) and 16
  Chunk Index records in the summary all pointing at it (the issue's 20 KB file that grew a gateway
  to 4 GiB);
- huge_chunk: that chunk indexed once, honestly (500 MiB uncompressed);
- lying_chunk_index: that chunk, its Chunk Index saying it is 1000 bytes uncompressed (open() finds
  nothing wrong; reading the chunk must be refused before decompressing);
- announced_chunk: no summary; a Chunk announcing 200 MiB whose zstd frame (of unknown content size)
  holds one small message (the announced size must not be allocated before the data proves it).

Each takes the schemas and channels to write (a real recording's, so a replay gets as far as reading
messages) or uses a small built-in pair.

  crafted_mcap.py OUT_DIR      writes the four files (the fuzz seeds in test/fuzz/seeds/fuzz_mcap_reader)
"""
import functools
import os
import struct
import sys

import zstandard

MAGIC = b"\x89MCAP0\r\n"
ZEROS = 500 * 1024 * 1024


def record(opcode, content):
    return struct.pack("<BQ", opcode, len(content)) + content


def string(s):
    b = s.encode() if isinstance(s, str) else s
    return struct.pack("<I", len(b)) + b


def string_map(m):
    body = b"".join(string(k) + string(v) for k, v in sorted(m.items()))
    return struct.pack("<I", len(body)) + body


def header():
    return record(0x01, string("") + string("crafted (issue 52)"))


def schema(sid, name, encoding, data):
    return record(0x03, struct.pack("<H", sid) + string(name) + string(encoding) + string(data))


def channel(cid, sid, topic, encoding, metadata):
    return record(0x04, struct.pack("<HH", cid, sid) + string(topic) + string(encoding) + string_map(metadata))


def message_prefix(cid, data_len, t):
    """A Message record's prefix and fixed fields; its `data_len` bytes of data follow."""
    return struct.pack("<BQHIQQ", 0x05, 22 + data_len, cid, 0, t, t)


def chunk(t, uncompressed_size, compressed):
    content = struct.pack("<QQQI", t, t, uncompressed_size, 0) + string("zstd") + struct.pack("<Q", len(compressed)) + compressed
    return record(0x06, content)


def chunk_index(t, offset, length, compressed_size, uncompressed_size):
    content = struct.pack("<QQQQ", t, t, offset, length) + struct.pack("<I", 0) + struct.pack("<Q", 0) + string("zstd") + \
        struct.pack("<QQ", compressed_size, uncompressed_size)
    return record(0x08, content)


def footer(summary_start):
    return record(0x02, struct.pack("<QQI", summary_start, 0, 0))


DEFAULT_DEF = "service experimental.crafted\n\nobject Thing\n    wire double value [readonly]\nend\n"


def default_records():
    """(schema and channel records as bytes, the channel id)."""
    meta = {"device": "crafted", "member": "value", "kind": "wire", "object_type": "experimental.crafted.Thing", "path": "",
            "root_type": "experimental.crafted.Thing", "type": "double", "entry_format": "4"}
    return schema(1, "experimental.crafted", "robotraconteur_servicedef", DEFAULT_DEF) + \
        channel(0, 1, "crafted/value", "robotraconteur", meta), 0


@functools.lru_cache(maxsize=4)
def zeros_chunk_records(cid, t):
    """(zstd frame of one Message record of ZEROS zero bytes, its uncompressed size)."""
    cobj = zstandard.ZstdCompressor(level=3, write_content_size=False).compressobj()
    parts = [cobj.compress(message_prefix(cid, ZEROS, t))]
    mib = bytes(1024 * 1024)
    for _ in range(ZEROS // len(mib)):
        parts.append(cobj.compress(mib))
    parts.append(cobj.flush())
    return b"".join(parts), 31 + ZEROS


def indexed_file(defs, cid, index_count, index_uncompressed=None, t=1_700_000_000_000_000_000):
    frame, size = zeros_chunk_records(cid, t)
    out = MAGIC + header() + defs
    chunk_at = len(out)
    c = chunk(t, size, frame)
    out += c + record(0x0F, struct.pack("<I", 0))
    summary_start = len(out)
    out += defs
    for _ in range(index_count):
        out += chunk_index(t, chunk_at, len(c), len(frame), size if index_uncompressed is None else index_uncompressed)
    out += footer(summary_start) + MAGIC
    return out


def duplicate_chunk_index(defs=None, cid=0):
    if defs is None:
        defs, cid = default_records()
    return indexed_file(defs, cid, 16)


def huge_chunk(defs=None, cid=0):
    if defs is None:
        defs, cid = default_records()
    return indexed_file(defs, cid, 1)


def lying_chunk_index(defs=None, cid=0):
    if defs is None:
        defs, cid = default_records()
    return indexed_file(defs, cid, 1, index_uncompressed=1000)


def announced_chunk(defs=None, cid=0, t=1_700_000_000_000_000_000):
    if defs is None:
        defs, cid = default_records()
    small = message_prefix(cid, 8, t) + struct.pack("<d", 1.5)
    frame = zstandard.ZstdCompressor(write_content_size=False).compressobj()
    z = frame.compress(small) + frame.flush()
    return MAGIC + header() + defs + chunk(t, 200 * 1024 * 1024, z)


FILES = {"duplicate_chunk_index": duplicate_chunk_index, "huge_chunk": huge_chunk, "lying_chunk_index": lying_chunk_index,
         "announced_chunk": announced_chunk}


def main(out_dir):
    os.makedirs(out_dir, exist_ok=True)
    for name, make in FILES.items():
        with open(os.path.join(out_dir, "crafted_" + name + ".mcap"), "wb") as f:
            f.write(make())


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
