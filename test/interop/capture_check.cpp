// rr_capture_check: byte-identity check of our codec against a live capture.
//
// Reads a capture file written by test/interop/recording_proxy.py (format documented there and in
// test/interop/README.md), and for every captured RR message:
//   decode_message(bytes, limits, context) -> encode_message(model) -> must equal the captured bytes.
// The DecodeContext of each connection is learnt from the traffic itself: client NodeID from the
// CreateConnection StreamOp, server NodeID and the negotiated string-table capability from its reply
// (wire.md §2.1, §6.2), client/server endpoints from the first messages that carry them (§6.4). It
// lets the decoder fill the header fields a v4 sender omits (wire.md §2.3).
//
// Output: a per-entry-type table (messages seen per version, identical, mismatched, undecodable) and,
// for each failure, a description with a hex diff. Exit status: 0 = every message identical,
// 1 = some mismatch / decode error / unframed bytes / no message at all, 2 = usage or file error.
//
// Usage: rr_capture_check CAPTURE [--max-reports N] [--quiet]

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "base/codec/limits.hpp"
#include "base/codec/shared_bytes.hpp"
#include "base/message/message.hpp"
#include "base/message/message_reader.hpp"
#include "base/message/message_writer.hpp"

namespace {

using Bytes = std::span<const std::byte>;

constexpr std::string_view kCaptureMagic{"RRCAP1\n\0", 8};

struct Record {
    char kind = 0;  // 'C', 'S', 'c', 's', 'O', 'X'
    std::uint32_t connection = 0;
    Bytes bytes;
    std::size_t offset = 0;  // of the record's payload in the file
};

std::uint32_t le32(Bytes b, std::size_t at) {
    return static_cast<std::uint32_t>(b[at]) | (static_cast<std::uint32_t>(b[at + 1]) << 8) |
           (static_cast<std::uint32_t>(b[at + 2]) << 16) | (static_cast<std::uint32_t>(b[at + 3]) << 24);
}
std::uint16_t le16(Bytes b, std::size_t at) {
    return static_cast<std::uint16_t>(static_cast<unsigned>(b[at]) | (static_cast<unsigned>(b[at + 1]) << 8));
}

/// Splits the capture into records. Returns false (with a message) on a malformed file.
bool read_records(Bytes file, std::vector<Record>& out, std::string& error) {
    if (file.size() < kCaptureMagic.size() ||
        std::memcmp(file.data(), kCaptureMagic.data(), kCaptureMagic.size()) != 0) {
        error = "not a capture file (bad magic)";
        return false;
    }
    std::size_t off = kCaptureMagic.size();
    while (off < file.size()) {
        if (file.size() - off < 9) {
            error = "truncated record header at offset " + std::to_string(off);
            return false;
        }
        Record r;
        r.kind = static_cast<char>(file[off]);
        r.connection = le32(file, off + 1);
        std::uint32_t n = le32(file, off + 5);
        off += 9;
        if (file.size() - off < n) {
            error = "truncated record at offset " + std::to_string(off);
            return false;
        }
        r.bytes = file.subspan(off, n);
        r.offset = off;
        off += n;
        out.push_back(r);
    }
    return true;
}

/// EntryType of the first entry, read with a minimal bounds-checked walk (for the report only, so
/// that undecodable messages are still classified). nullopt if even that fails.
std::optional<std::uint16_t> peek_entry_type(Bytes m) {
    if (m.size() < 12) return std::nullopt;
    std::uint16_t version = le16(m, 8);
    if (version == 2) {
        if (m.size() < 12) return std::nullopt;
        std::size_t header = le16(m, 10);
        if (header + 6 > m.size()) return std::nullopt;
        return le16(m, header + 4);
    }
    if (version == 4) {
        // uint_x HeaderLen at offset 10, then the first entry: uint_x EntrySize, uint8 flags, uint16 type
        auto uint_x = [&](std::size_t& at) -> std::optional<std::uint64_t> {
            if (at >= m.size()) return std::nullopt;
            auto b = static_cast<unsigned>(m[at]);
            std::size_t width = b <= 252 ? 0 : b == 253 ? 2 : b == 254 ? 4 : 8;
            if (at + 1 + width > m.size()) return std::nullopt;
            std::uint64_t v = 0;
            if (width == 0) v = b;
            for (std::size_t i = 0; i < width; ++i) v |= static_cast<std::uint64_t>(m[at + 1 + i]) << (8 * i);
            at += 1 + width;
            return v;
        };
        std::size_t at = 10;
        auto header = uint_x(at);
        if (!header || *header >= m.size()) return std::nullopt;
        at = static_cast<std::size_t>(*header);
        if (!uint_x(at)) return std::nullopt;
        if (at + 3 > m.size()) return std::nullopt;
        return le16(m, at + 1);
    }
    return std::nullopt;
}

std::string_view entry_type_name(std::uint16_t t) {
    switch (t) {
        case 1: return "StreamOp";
        case 2: return "StreamOpRet";
        case 3: return "StreamCheckCapability";
        case 4: return "StreamCheckCapabilityRet";
        case 101: return "GetServiceDesc";
        case 102: return "GetServiceDescRet";
        case 103: return "ObjectTypeName";
        case 104: return "ObjectTypeNameRet";
        case 105: return "ServiceClosed";
        case 107: return "ConnectClient";
        case 108: return "ConnectClientRet";
        case 109: return "DisconnectClient";
        case 110: return "DisconnectClientRet";
        case 111: return "ConnectionTest";
        case 112: return "ConnectionTestRet";
        case 113: return "GetNodeInfo";
        case 114: return "GetNodeInfoRet";
        case 117: return "NodeCheckCapability";
        case 118: return "NodeCheckCapabilityRet";
        case 119: return "GetServiceAttributes";
        case 120: return "GetServiceAttributesRet";
        case 121: return "ConnectClientCombined";
        case 122: return "ConnectClientCombinedRet";
        case 501: return "EndpointCheckCapability";
        case 502: return "EndpointCheckCapabilityRet";
        case 1101: return "ServiceCheckCapabilityReq";
        case 1102: return "ServiceCheckCapabilityRet";
        case 1105: return "ClientKeepAliveReq";
        case 1106: return "ClientKeepAliveRet";
        case 1107: return "ClientSessionOpReq";
        case 1108: return "ClientSessionOpRet";
        case 1109: return "ServicePathReleasedReq";
        case 1111: return "PropertyGetReq";
        case 1112: return "PropertyGetRes";
        case 1113: return "PropertySetReq";
        case 1114: return "PropertySetRes";
        case 1121: return "FunctionCallReq";
        case 1122: return "FunctionCallRes";
        case 1123: return "GeneratorNextReq";
        case 1124: return "GeneratorNextRes";
        case 1131: return "EventReq";
        case 1141: return "PipePacket";
        case 1142: return "PipePacketRet";
        case 1143: return "PipeConnectReq";
        case 1144: return "PipeConnectRet";
        case 1145: return "PipeDisconnectReq";
        case 1146: return "PipeDisconnectRet";
        case 1147: return "PipeClosed";
        case 1151: return "CallbackCallReq";
        case 1152: return "CallbackCallRet";
        case 1161: return "WirePacket";
        case 1163: return "WireConnectReq";
        case 1164: return "WireConnectRet";
        case 1165: return "WireDisconnectReq";
        case 1166: return "WireDisconnectRet";
        case 1167: return "WireClosed";
        case 1171: return "MemoryRead";
        case 1172: return "MemoryReadRet";
        case 1173: return "MemoryWrite";
        case 1174: return "MemoryWriteRet";
        case 1175: return "MemoryGetParam";
        case 1176: return "MemoryGetParamRet";
        case 1181: return "WirePeekInValueReq";
        case 1182: return "WirePeekInValueRet";
        case 1183: return "WirePeekOutValueReq";
        case 1184: return "WirePeekOutValueRet";
        case 1185: return "WirePokeOutValueReq";
        case 1186: return "WirePokeOutValueRet";
        default: return "?";
    }
}

/// What the checker knows about one TCP connection (one client session, wire.md §6.4).
struct Connection {
    rr::NodeID client_node;
    rr::NodeID server_node;
    std::uint32_t client_endpoint = 0;
    std::uint32_t server_endpoint = 0;
    bool standard_string_table = true;  // until the CreateConnection reply says otherwise
};

rr::DecodeContext context_for(const Connection& c, bool client_to_server) {
    rr::DecodeContext ctx;
    if (client_to_server) {  // the receiver is the server
        ctx.local_node_id = c.server_node;
        ctx.remote_node_id = c.client_node;
        ctx.local_endpoint = c.server_endpoint;
        ctx.remote_endpoint = c.client_endpoint;
    } else {
        ctx.local_node_id = c.client_node;
        ctx.remote_node_id = c.server_node;
        ctx.local_endpoint = c.client_endpoint;
        ctx.remote_endpoint = c.server_endpoint;
    }
    ctx.standard_string_table = c.standard_string_table;
    return ctx;
}

/// Updates the connection from a decoded message (CreateConnection exchange, endpoints).
void learn(Connection& c, const rr::Message& m, bool client_to_server) {
    if (m.entries.size() == 1) {
        const auto& e = m.entries[0];
        if (e.member_name == "CreateConnection") {
            if (client_to_server && e.entry_type == rr::MessageEntryType::StreamOp) {
                c.client_node = m.header.sender_node_id;
            } else if (!client_to_server && e.entry_type == rr::MessageEntryType::StreamOpRet) {
                c.server_node = m.header.sender_node_id;
                // capabilities: uint32 words, page in bits 31..20 (wire.md §2.1)
                bool table = false;
                if (const auto* caps = e.find("capabilities"); caps && caps->type == rr::DataTypes::uint32_t) {
                    Bytes d = caps->data.bytes();
                    for (std::size_t i = 0; i + 4 <= d.size(); i += 4) {
                        std::uint32_t w = le32(d, i);
                        if ((w & 0xFFF00000u) == 0x04100000u && (w & 0x4u)) table = true;
                    }
                }
                c.standard_string_table = table;
            }
        }
    }
    if (m.header.sender_endpoint != 0) {
        if (client_to_server) {
            if (c.client_endpoint == 0) c.client_endpoint = m.header.sender_endpoint;
        } else if (c.server_endpoint == 0) {
            c.server_endpoint = m.header.sender_endpoint;
        }
    }
}

void hex_window(const char* label, Bytes b, std::size_t from, std::size_t to) {
    std::printf("      %s", label);
    for (std::size_t i = from; i < to; ++i) {
        if (i < b.size())
            std::printf("%02x", static_cast<unsigned>(b[i]));
        else
            std::printf("  ");
        if ((i + 1) % 4 == 0) std::printf(" ");
    }
    std::printf("\n");
}

void hex_diff(Bytes want, Bytes got) {
    std::size_t n = std::min(want.size(), got.size());
    std::size_t first = n;
    for (std::size_t i = 0; i < n; ++i)
        if (want[i] != got[i]) {
            first = i;
            break;
        }
    std::printf("    captured %zu bytes, re-encoded %zu bytes, first difference at offset %zu\n", want.size(),
                got.size(), first);
    std::size_t from = first >= 16 ? (first - 16) & ~std::size_t{3} : 0;
    for (std::size_t row = from; row < from + 64 && row < std::max(want.size(), got.size()); row += 32) {
        std::printf("    @%06zu\n", row);
        hex_window("captured : ", want, row, row + 32);
        hex_window("re-encode: ", got, row, row + 32);
    }
}

struct Row {
    std::uint64_t v2 = 0, v4 = 0, identical = 0, mismatch = 0, decode_error = 0, encode_error = 0;
};

}  // namespace

int main(int argc, char** argv) {
    std::string path;
    long max_reports = 10;
    bool quiet = false;
    for (int i = 1; i < argc; ++i) {
        std::string_view a = argv[i];
        if (a == "--max-reports" && i + 1 < argc) {
            max_reports = std::strtol(argv[++i], nullptr, 10);
        } else if (a == "--quiet") {
            quiet = true;
        } else if (!a.empty() && a[0] != '-' && path.empty()) {
            path = a;
        } else {
            std::fprintf(stderr, "usage: rr_capture_check CAPTURE [--max-reports N] [--quiet]\n");
            return 2;
        }
    }
    if (path.empty()) {
        std::fprintf(stderr, "usage: rr_capture_check CAPTURE [--max-reports N] [--quiet]\n");
        return 2;
    }

    std::ifstream in(path, std::ios::binary);
    if (!in) {
        std::fprintf(stderr, "rr_capture_check: cannot open %s\n", path.c_str());
        return 2;
    }
    std::vector<char> raw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::vector<std::byte> file(raw.size());
    std::memcpy(file.data(), raw.data(), raw.size());

    std::vector<Record> records;
    std::string error;
    if (!read_records(file, records, error)) {
        std::fprintf(stderr, "rr_capture_check: %s: %s\n", path.c_str(), error.c_str());
        return 2;
    }

    std::map<std::uint32_t, Connection> connections;
    std::map<std::uint16_t, Row> table;  // by first entry's EntryType; 0xFFFF = unknown
    std::uint64_t messages = 0, identical = 0, failures = 0, raw_records = 0;
    long reports = 0;
    rr::Limits limits;

    for (std::size_t index = 0; index < records.size(); ++index) {
        const Record& r = records[index];
        if (r.kind == 'O' || r.kind == 'X') continue;
        if (r.kind == 'c' || r.kind == 's') {
            ++raw_records;
            ++failures;
            if (reports++ < max_reports)
                std::printf("  record %zu (connection %u): %zu unframed bytes %s\n", index, r.connection,
                            r.bytes.size(), r.kind == 'c' ? "client->server" : "server->client");
            continue;
        }
        if (r.kind != 'C' && r.kind != 'S') {
            std::fprintf(stderr, "rr_capture_check: record %zu has unknown kind 0x%02x\n", index,
                         static_cast<unsigned>(static_cast<unsigned char>(r.kind)));
            return 2;
        }
        ++messages;
        const bool c2s = r.kind == 'C';
        Connection& conn = connections[r.connection];
        const std::uint16_t type = peek_entry_type(r.bytes).value_or(0xFFFF);
        const std::uint16_t version = r.bytes.size() >= 10 ? le16(r.bytes, 8) : 0;
        Row& row = table[type];
        (version == 4 ? row.v4 : row.v2) += 1;

        auto describe = [&](const char* what) {
            std::printf("  %s: record %zu, connection %u, %s, v%u, entry type %u %s, %zu bytes\n", what, index,
                        r.connection, c2s ? "client->server" : "server->client", version, type,
                        std::string(entry_type_name(type)).c_str(), r.bytes.size());
        };

        rr::DecodeContext ctx = context_for(conn, c2s);
        auto decoded = rr::decode_message(rr::SharedBytes::copy_of(r.bytes), limits, &ctx);
        if (!decoded) {
            ++row.decode_error;
            ++failures;
            if (reports++ < max_reports) {
                describe("DECODE ERROR");
                std::printf("    %s: %s\n", decoded.error().name.c_str(), decoded.error().message.c_str());
                for (std::size_t row = 0; row < r.bytes.size() && row < 128; row += 32) {
                    std::printf("    @%06zu\n", row);
                    hex_window("captured : ", r.bytes, row, std::min(row + 32, r.bytes.size()));
                }
            }
            continue;
        }
        learn(conn, *decoded, c2s);

        std::vector<std::byte> out;
        auto encoded = rr::encode_message(*decoded, out);
        if (!encoded) {
            ++row.encode_error;
            ++failures;
            if (reports++ < max_reports) {
                describe("ENCODE ERROR");
                std::printf("    %s: %s\n", encoded.error().name.c_str(), encoded.error().message.c_str());
            }
            continue;
        }
        if (out.size() == r.bytes.size() && std::equal(out.begin(), out.end(), r.bytes.begin())) {
            ++row.identical;
            ++identical;
        } else {
            ++row.mismatch;
            ++failures;
            if (reports++ < max_reports) {
                describe("MISMATCH");
                hex_diff(r.bytes, out);
            }
        }
    }
    if (reports > max_reports)
        std::printf("  (%ld more failures not shown; --max-reports N)\n", reports - max_reports);

    if (!quiet) {
        std::printf("\n  %5s %-28s %7s %7s %9s %8s %7s %7s\n", "type", "name", "v2", "v4", "identical", "mismatch",
                    "decode", "encode");
        for (const auto& [type, row] : table) {
            std::printf("  %5u %-28s %7llu %7llu %9llu %8llu %7llu %7llu\n", type,
                        type == 0xFFFF ? "(unreadable)" : std::string(entry_type_name(type)).c_str(),
                        static_cast<unsigned long long>(row.v2), static_cast<unsigned long long>(row.v4),
                        static_cast<unsigned long long>(row.identical), static_cast<unsigned long long>(row.mismatch),
                        static_cast<unsigned long long>(row.decode_error),
                        static_cast<unsigned long long>(row.encode_error));
        }
    }
    std::printf("%s: %zu connections, %llu messages, %llu identical, %llu failures, %llu unframed records\n",
                path.c_str(), connections.size(), static_cast<unsigned long long>(messages),
                static_cast<unsigned long long>(identical), static_cast<unsigned long long>(failures),
                static_cast<unsigned long long>(raw_records));
    if (messages == 0) {
        std::printf("no message in capture\n");
        return 1;
    }
    return failures == 0 ? 0 : 1;
}
