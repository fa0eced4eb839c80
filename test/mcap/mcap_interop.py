#!/usr/bin/env python3
"""MCAP interop (issue 44): our writer and reader (core/mcap, through rr_mcap_tool) against the reference
implementations, the `mcap` PyPI package and `@mcap/core` from npm (mcap_reference.mjs), both ways.

Every writer writes the same sample recording (described in rr_mcap_tool.cpp; Python's adds an attachment
and a metadata record in the middle): ours chunked with zstd,
chunked uncompressed, and in one chunk; Python's and TypeScript's chunked with zstd, chunked
uncompressed and unchunked. Every reader dumps every file in one JSON shape: ours, Python's indexed
(seeking) and streaming readers (CRCs checked, the data section CRC too), TypeScript's indexed reader
(chunked files) and streaming reader. Each dump must hold exactly the sample's schemas, channels (by
topic, with metadata) and messages (topic, sequence, log and publish time, bytes).
Then: files cut in the middle of their last chunk (ours and Python's) read by all three streaming
readers give exactly the messages of the complete chunks; our reader's seek by time and topic matches
a filter of the sample; and a file with a corrupted chunk makes our reader fail with a clear message.

Usage: mcap_interop.py --tool PATH/rr_mcap_tool [--seeds DIR]. With --seeds, writes small sample files of
each writer (and cut ones) into DIR instead: the seeds of the fuzz target (test/fuzz/seeds/fuzz_mcap_reader).
Exit 0 pass, 1 fail, 77 skip (no `mcap` package in the
venv or no test/mcap/node_modules: ./scripts/setup.sh installs both).
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
try:
    from mcap.exceptions import McapError
    from mcap.reader import make_reader
    from mcap.stream_reader import StreamReader
    from mcap.records import Channel, Header, Message, Schema
    from mcap.writer import CompressionType, Writer
    import zstandard  # noqa: F401  (the mcap package reads zstd chunks with it)
except ImportError as e:
    print(f"SKIP: the mcap/zstandard Python packages are missing ({e}); run ./scripts/setup.sh")
    sys.exit(77)
if not os.path.isdir(os.path.join(HERE, "node_modules", "@mcap", "core")):
    print("SKIP: test/mcap/node_modules is missing; run ./scripts/setup.sh")
    sys.exit(77)
NODE = shutil.which("node")
if not NODE:
    print("SKIP: node not found")
    sys.exit(77)

T0 = 1700000000000000000
COUNT = 200
SCHEMA_NAME = "experimental.sample.Sample"
SCHEMA_DATA = b'{"type":"object","properties":{"i":{"type":"integer"}}}'
failures = []


def sample_payload(i):
    return f'{{"i":{i}}}'.encode() if i % 2 == 0 else bytes((i + k) % 256 for k in range(i % 300))


def expected():
    return {
        "schemas": {SCHEMA_NAME: {"encoding": "jsonschema", "data": SCHEMA_DATA.hex()}},
        "channels": {
            "sample/json": {"message_encoding": "json", "schema": SCHEMA_NAME,
                            "metadata": {"device": "sample", "member": "json"}},
            "sample/rr": {"message_encoding": "robotraconteur", "schema": "", "metadata": {}},
        },
        "messages": [["sample/json" if i % 2 == 0 else "sample/rr", i // 2, str(T0 + i * 1000003),
                      str(T0 + i * 1000003 - 7), sample_payload(i).hex()] for i in range(COUNT)],
    }


# --- writers ---------------------------------------------------------------------------------------
def py_write(path, compression, chunked, chunk_size=4096):
    with open(path, "wb") as f:
        w = Writer(f, chunk_size=chunk_size, compression=compression, use_chunking=chunked)
        w.start(profile="", library="mcap python")
        sid = w.register_schema(SCHEMA_NAME, "jsonschema", SCHEMA_DATA)
        js = w.register_channel("sample/json", "json", sid, {"device": "sample", "member": "json"})
        rr = w.register_channel("sample/rr", "robotraconteur", 0, {})
        for i in range(COUNT):
            t = T0 + i * 1000003
            w.add_message(js if i % 2 == 0 else rr, log_time=t, data=sample_payload(i), publish_time=t - 7,
                          sequence=i // 2)
            if i == COUNT // 2:  # records our writer never writes, which our reader steps over
                w.add_attachment(create_time=t, log_time=t, name="calibration.txt", media_type="text/plain",
                                 data=b"x" * 100)
                w.add_metadata("robot", {"serial": "42"})
        w.finish()


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=60)
    return p.returncode, p.stdout, p.stderr


def checked(cmd):
    rc, out, err = run(cmd)
    if rc != 0:
        raise RuntimeError(f"{' '.join(cmd)} exited {rc}: {err.strip()}")
    return out


# --- readers: each returns the dump shape ----------------------------------------------------------
def row(channel, message):
    return [channel.topic, message.sequence, str(message.log_time), str(message.publish_time), message.data.hex()]


def summary_shape(schemas, channels):
    return {
        "schemas": {s.name: {"encoding": s.encoding, "data": bytes(s.data).hex()} for s in schemas.values()},
        "channels": {c.topic: {"message_encoding": c.message_encoding,
                               "schema": schemas[c.schema_id].name if c.schema_id in schemas else "",
                               "metadata": dict(c.metadata)} for c in channels.values()},
    }


def py_dump_indexed(path):
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        out = summary_shape(summary.schemas, summary.channels)
        out["messages"] = [row(c, m) for _, c, m in reader.iter_messages()]
    return out


def py_dump_stream(path):
    schemas, channels, messages, truncated = {}, {}, [], None
    with open(path, "rb") as f:
        try:
            for r in StreamReader(f, validate_crcs=True).records:
                if isinstance(r, Schema):
                    schemas[r.id] = r
                elif isinstance(r, Channel):
                    channels[r.id] = r
                elif isinstance(r, Message):
                    messages.append(row(channels[r.channel_id], r))
        except McapError as e:  # a cut-off file ends in an error after its complete records
            truncated = f"{type(e).__name__}: {e}"
    out = summary_shape(schemas, channels)
    out["messages"] = messages
    out["truncated"] = truncated
    return out


def js_dump(path, stream):
    return json.loads(checked([NODE, os.path.join(HERE, "mcap_reference.mjs"), "dump", path] +
                              (["--stream"] if stream else [])))


def ours_dump(path, *args):
    return json.loads(checked([TOOL, "dump", path, *args]))


# --- comparison ------------------------------------------------------------------------------------
def compare(label, dump, want, messages=None):
    want_messages = want["messages"] if messages is None else messages
    for key in ("schemas", "channels"):
        if dump[key] != want[key]:
            failures.append(f"{label}: {key} differ:\n  got  {dump[key]}\n  want {want[key]}")
    got = sorted(dump["messages"], key=lambda m: int(m[2]))
    if got != want_messages:
        first = next((i for i, (a, b) in enumerate(zip(got, want_messages)) if a != b), min(len(got), len(want_messages)))
        failures.append(f"{label}: messages differ: got {len(got)}, want {len(want_messages)}, first difference at {first}")
    else:
        print(f"ok  {label}: {len(got)} messages")


def write_seeds(out):
    global COUNT
    COUNT = 10
    os.makedirs(out, exist_ok=True)
    mjs = os.path.join(HERE, "mcap_reference.mjs")
    n = str(COUNT)
    checked([TOOL, "write-sample", os.path.join(out, "ours_zstd.mcap"), "--chunk-size", "200", "--count", n])
    checked([TOOL, "write-sample", os.path.join(out, "ours_none.mcap"), "--compression", "none", "--chunk-size", "150", "--count", n])
    py_write(os.path.join(out, "python_zstd.mcap"), CompressionType.ZSTD, True, chunk_size=200)
    py_write(os.path.join(out, "python_unchunked.mcap"), CompressionType.NONE, False)
    checked([NODE, mjs, "write-sample", os.path.join(out, "ts_zstd.mcap"), "--count", n, "--chunk-size", "200"])
    checked([NODE, mjs, "write-sample", os.path.join(out, "ts_unchunked.mcap"), "--count", n, "--chunked", "no", "--compression", "none"])
    for name in ("ours_zstd", "ours_none"):
        data = open(os.path.join(out, name + ".mcap"), "rb").read()
        open(os.path.join(out, name + "_cut.mcap"), "wb").write(data[: len(data) * 2 // 3])
    print("seeds written to", out)
    return 0


def main():
    global TOOL
    ap = argparse.ArgumentParser()
    ap.add_argument("--tool", required=True)
    ap.add_argument("--seeds")
    args = ap.parse_args()
    TOOL = args.tool
    if args.seeds:
        return write_seeds(args.seeds)
    want = expected()
    tmp = tempfile.mkdtemp(prefix="rr_mcap_interop_")
    try:
        files = {}  # name -> (path, chunked)
        def add(name, chunked, write):
            path = os.path.join(tmp, name + ".mcap")
            write(path)
            files[name] = (path, chunked)
        add("ours-zstd", True, lambda p: checked([TOOL, "write-sample", p, "--chunk-size", "4096"]))
        add("ours-none", True, lambda p: checked([TOOL, "write-sample", p, "--compression", "none", "--chunk-size", "4096"]))
        add("ours-one-chunk", True, lambda p: checked([TOOL, "write-sample", p]))
        add("py-zstd", True, lambda p: py_write(p, CompressionType.ZSTD, True))
        add("py-none", True, lambda p: py_write(p, CompressionType.NONE, True))
        add("py-unchunked", False, lambda p: py_write(p, CompressionType.NONE, False))
        mjs = os.path.join(HERE, "mcap_reference.mjs")
        add("js-zstd", True, lambda p: checked([NODE, mjs, "write-sample", p, "--compression", "zstd"]))
        add("js-none", True, lambda p: checked([NODE, mjs, "write-sample", p, "--compression", "none"]))
        add("js-unchunked", False, lambda p: checked([NODE, mjs, "write-sample", p, "--chunked", "no", "--compression", "none"]))

        for name, (path, chunked) in files.items():
            compare(f"{name} read by ours", ours_dump(path), want)
            compare(f"{name} read by Python (stream, CRCs)", py_dump_stream(path), want)
            compare(f"{name} read by TypeScript (stream, CRCs)", js_dump(path, True), want)
            if chunked:
                compare(f"{name} read by Python (indexed)", py_dump_indexed(path), want)
                compare(f"{name} read by TypeScript (indexed)", js_dump(path, False), want)
            d = ours_dump(path)
            if d["indexed"] != chunked or d["truncated"] is not None or d["message_count"] != COUNT:
                failures.append(f"{name} read by ours: indexed={d['indexed']} truncated={d['truncated']} "
                                f"message_count={d['message_count']}")

        # Seek: our reader from a time on, one topic.
        start = T0 + 77 * 1000003
        for name in ("ours-zstd", "py-zstd", "js-zstd", "py-unchunked"):
            d = ours_dump(files[name][0], "--start", str(start), "--topic", "sample/rr")
            sel = [m for m in want["messages"] if m[0] == "sample/rr" and int(m[2]) >= start]
            if d["messages"] != sel:
                failures.append(f"{name}: our seek from {start} on sample/rr gave {len(d['messages'])} messages, want {len(sel)}")
            else:
                print(f"ok  {name}: our seek from log_time {start} on sample/rr: {len(sel)} messages, in order")

        # Cut in the middle of the last chunk: readers give the messages of the complete chunks.
        for name in ("ours-zstd", "py-zstd"):
            path = files[name][0]
            with open(path, "rb") as f:
                chunk_indexes = make_reader(f).get_summary().chunk_indexes
            last = max(chunk_indexes, key=lambda c: c.chunk_start_offset)
            cut = os.path.join(tmp, name + "-cut.mcap")
            with open(path, "rb") as f, open(cut, "wb") as g:
                g.write(f.read(last.chunk_start_offset + last.chunk_length // 2))
            complete = [m for m in want["messages"] if int(m[2]) < last.message_start_time]
            ours = ours_dump(cut)
            compare(f"{name} cut mid-chunk, read by ours", ours, want, complete)
            if not ours["truncated"] or "inside Chunk" not in ours["truncated"]:
                failures.append(f"{name} cut: our reader says truncated={ours['truncated']!r}")
            py = py_dump_stream(cut)
            compare(f"{name} cut mid-chunk, read by Python (stream)", py, want, complete)
            js = js_dump(cut, True)
            compare(f"{name} cut mid-chunk, read by TypeScript (stream)", js, want, complete)
            if py["truncated"] is None or js["truncated"] is None:
                failures.append(f"{name} cut: a reference reader did not notice the cut ({py['truncated']}, {js['truncated']})")

        # A corrupted chunk: a clear error from our reader, no crash.
        path = files["ours-none"][0]
        data = bytearray(open(path, "rb").read())
        at = data.find(b'{"i":10}')
        data[at + 5] ^= 0x01
        bad = os.path.join(tmp, "corrupt.mcap")
        open(bad, "wb").write(bytes(data))
        rc, _, err = run([TOOL, "dump", bad])
        if rc != 1 or "uncompressed_crc mismatch" not in err or "Chunk at offset" not in err:
            failures.append(f"corrupt chunk: rr_mcap_tool exited {rc}: {err.strip()}")
        else:
            print(f"ok  corrupt chunk: {err.strip()}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

    for f in failures:
        print("FAIL", f)
    print(f"{'FAILED' if failures else 'passed'}: {len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
