#!/usr/bin/env python3
"""Reads a capture file written by recording_proxy.py and summarises it.

A deliberately small, independent walker of the message framing (wire.md §1.2-§1.4 for v2,
§2.2-§2.5 for v4): enough to list each message's version, entry types, v4 header flags and whether it
uses string-table codes. It is a sanity tool for the live identity test, not a codec.

Usage: capture_summary.py CAPTURE [--json]
"""

import argparse
import json
import struct
import sys

MAGIC = b"RRCAP1\n\0"

ENTRY_TYPE_NAMES = {
    1: "StreamOp", 2: "StreamOpRet", 3: "StreamCheckCapability", 4: "StreamCheckCapabilityRet",
    101: "GetServiceDesc", 102: "GetServiceDescRet", 103: "ObjectTypeName", 104: "ObjectTypeNameRet",
    105: "ServiceClosed", 106: "ServiceClosedRet", 107: "ConnectClient", 108: "ConnectClientRet",
    109: "DisconnectClient", 110: "DisconnectClientRet", 111: "ConnectionTest", 112: "ConnectionTestRet",
    113: "GetNodeInfo", 114: "GetNodeInfoRet", 117: "NodeCheckCapability", 118: "NodeCheckCapabilityRet",
    119: "GetServiceAttributes", 120: "GetServiceAttributesRet", 121: "ConnectClientCombined",
    122: "ConnectClientCombinedRet", 501: "EndpointCheckCapability", 502: "EndpointCheckCapabilityRet",
    1101: "ServiceCheckCapabilityReq", 1102: "ServiceCheckCapabilityRet", 1105: "ClientKeepAliveReq",
    1106: "ClientKeepAliveRet", 1107: "ClientSessionOpReq", 1108: "ClientSessionOpRet",
    1109: "ServicePathReleasedReq", 1110: "ServicePathReleasedRet", 1111: "PropertyGetReq",
    1112: "PropertyGetRes", 1113: "PropertySetReq", 1114: "PropertySetRes", 1121: "FunctionCallReq",
    1122: "FunctionCallRes", 1123: "GeneratorNextReq", 1124: "GeneratorNextRes", 1131: "EventReq",
    1132: "EventRes", 1141: "PipePacket", 1142: "PipePacketRet", 1143: "PipeConnectReq",
    1144: "PipeConnectRet", 1145: "PipeDisconnectReq", 1146: "PipeDisconnectRet", 1147: "PipeClosed",
    1148: "PipeClosedRet", 1151: "CallbackCallReq", 1152: "CallbackCallRet", 1161: "WirePacket",
    1162: "WirePacketRet", 1163: "WireConnectReq", 1164: "WireConnectRet", 1165: "WireDisconnectReq",
    1166: "WireDisconnectRet", 1167: "WireClosed", 1168: "WireClosedRet", 1171: "MemoryRead",
    1172: "MemoryReadRet", 1173: "MemoryWrite", 1174: "MemoryWriteRet", 1175: "MemoryGetParam",
    1176: "MemoryGetParamRet", 1181: "WirePeekInValueReq", 1182: "WirePeekInValueRet",
    1183: "WirePeekOutValueReq", 1184: "WirePeekOutValueRet", 1185: "WirePokeOutValueReq",
    1186: "WirePokeOutValueRet",
}

NESTED_TYPES = {101, 102, 103, 108, 109, 110, 111, 115, 116, 117}
ITEM_SIZE = {0: 0, 1: 8, 2: 4, 3: 1, 4: 1, 5: 2, 6: 2, 7: 4, 8: 4, 9: 8, 10: 8, 11: 1, 12: 16, 13: 8, 14: 1}


def read_records(path):
    """Yields (kind, connection, bytes) for every record of a capture file."""
    with open(path, "rb") as fh:
        data = fh.read()
    if data[:8] != MAGIC:
        raise ValueError("%s: not a capture file (bad magic)" % path)
    off = 8
    while off < len(data):
        if off + 9 > len(data):
            raise ValueError("%s: truncated record header at %d" % (path, off))
        kind, conn, n = struct.unpack_from("<BII", data, off)
        off += 9
        if off + n > len(data):
            raise ValueError("%s: truncated record at %d" % (path, off))
        yield chr(kind), conn, data[off:off + n]
        off += n


class _Cursor:
    def __init__(self, b, off, end):
        self.b, self.off, self.end = b, off, end

    def take(self, n):
        if self.off + n > self.end:
            raise ValueError("truncated")
        v = self.b[self.off:self.off + n]
        self.off += n
        return v

    def u8(self):
        return self.take(1)[0]

    def u16(self):
        return struct.unpack("<H", self.take(2))[0]

    def u32(self):
        return struct.unpack("<I", self.take(4))[0]

    def uint_x(self):
        b = self.u8()
        if b <= 252:
            return b
        if b == 253:
            return self.u16()
        if b == 254:
            return self.u32()
        return struct.unpack("<Q", self.take(8))[0]

    def int_x(self):
        b = struct.unpack("<b", self.take(1))[0]
        if b <= 124:
            return b
        if b == 125:
            return struct.unpack("<h", self.take(2))[0]
        if b == 126:
            return struct.unpack("<i", self.take(4))[0]
        return struct.unpack("<q", self.take(8))[0]

    def xstr(self):
        return self.take(self.uint_x())


def _walk_v4_elements(b, cur, count, info):
    for _ in range(count):
        start = cur.off
        size = cur.uint_x()
        end = start + size
        flags = cur.u8()
        if flags & 0x12:
            info["string_table_codes"] = True
        if flags & 0x01:
            cur.xstr()
        if flags & 0x02:
            cur.uint_x()
        if flags & 0x04:
            cur.int_x()
        etype = cur.u16()
        if flags & 0x08:
            cur.xstr()
        if flags & 0x10:
            cur.uint_x()
        if flags & 0x20:
            cur.xstr()
        if flags & 0x80:
            cur.xstr()
        n = cur.uint_x()
        if etype in NESTED_TYPES:
            _walk_v4_elements(b, _Cursor(b, cur.off, end), n, info)
        cur.off = end


def parse_message(b):
    """Returns a dict: version, size, entry_types, v4_flags, string_table_codes (bool)."""
    cur = _Cursor(b, 0, len(b))
    if cur.take(4) != b"RRAC":
        raise ValueError("bad magic")
    size = cur.u32()
    if size != len(b):
        raise ValueError("MessageSize %d != record length %d" % (size, len(b)))
    version = cur.u16()
    info = {"version": version, "size": size, "entry_types": [], "v4_flags": None, "string_table_codes": False}
    if version == 2:
        header_size = cur.u16()
        off = header_size
        while off < size:
            c = _Cursor(b, off, size)
            esize = c.u32()
            info["entry_types"].append(c.u16())
            if esize < 6:
                raise ValueError("bad EntrySize")
            off += esize
    elif version == 4:
        header_len = cur.uint_x()
        flags = cur.u8()
        info["v4_flags"] = flags
        if flags & 0x20:
            info["string_table_codes"] = True
        off = header_len
        while off < size:
            c = _Cursor(b, off, size)
            esize = c.uint_x()
            eflags = c.u8()
            info["entry_types"].append(c.u16())
            if eflags & 0x0A:
                info["string_table_codes"] = True
            if eflags & 0x01:
                c.xstr()
            if eflags & 0x02:
                c.uint_x()
            if eflags & 0x04:
                c.xstr()
            if eflags & 0x08:
                c.uint_x()
            if eflags & 0x10:
                c.uint_x()
            if eflags & 0x20:
                c.u16()
            if eflags & 0x40:
                c.xstr()
            if eflags & 0x80:
                c.xstr()
            n = c.uint_x()
            _walk_v4_elements(b, _Cursor(b, c.off, off + esize), n, info)
            if esize < 4:
                raise ValueError("bad EntrySize")
            off += esize
    else:
        raise ValueError("unknown message version %d" % version)
    return info


def summarize(path):
    s = {
        "records": 0, "messages": 0, "connections": 0, "raw_records": 0, "parse_errors": [],
        "versions": {}, "entry_types": {}, "v4_without_routing": 0, "string_table_messages": 0,
    }
    for kind, conn, data in read_records(path):
        s["records"] += 1
        if kind == "O":
            s["connections"] += 1
        elif kind in ("c", "s"):
            s["raw_records"] += 1
        elif kind in ("C", "S"):
            s["messages"] += 1
            try:
                info = parse_message(data)
            except (ValueError, struct.error) as e:
                s["parse_errors"].append("connection %d %s: %s" % (conn, kind, e))
                continue
            v = str(info["version"])
            s["versions"][v] = s["versions"].get(v, 0) + 1
            for t in info["entry_types"]:
                key = str(t)
                s["entry_types"][key] = s["entry_types"].get(key, 0) + 1
            if info["v4_flags"] is not None and not info["v4_flags"] & 0x01:
                s["v4_without_routing"] += 1
            if info["string_table_codes"]:
                s["string_table_messages"] += 1
    return s


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("capture")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    s = summarize(args.capture)
    if args.json:
        print(json.dumps(s, indent=1))
        return 0
    print("records %d, connections %d, messages %d, raw %d, versions %s, v4 without routing %d, "
          "with string-table codes %d" % (s["records"], s["connections"], s["messages"], s["raw_records"],
                                          s["versions"], s["v4_without_routing"], s["string_table_messages"]))
    for t in sorted(s["entry_types"], key=int):
        print("  %5s %-28s %6d" % (t, ENTRY_TYPE_NAMES.get(int(t), "?"), s["entry_types"][t]))
    for e in s["parse_errors"]:
        print("  parse error:", e)
    return 0 if not s["parse_errors"] else 1


if __name__ == "__main__":
    sys.exit(main())
