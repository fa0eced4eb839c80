// Writes a few small messages, made with our own encoder, as seed inputs for fuzz_message_reader (and
// fuzz_message_structured), and, given a second folder, the first bytes of RR clients for
// fuzz_gateway_port: a client's CreateConnection (made by core's StreamConnection) followed by a
// ConnectClientCombined request for the demo device `create` and a heartbeat. svc_values_v4.bin holds
// values of the types fuzz_message_structured renders through the JSON text plan (plan_types.hpp).
// Usage: gen_message_seeds <dir> [<port-seed-dir>]
//   (the committed seeds: test/fuzz/seeds/fuzz_message_reader, test/fuzz/seeds/fuzz_gateway_port)
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/codec/endian.hpp"
#include "core/json/value_json.hpp"
#include "base/message/error_entry.hpp"
#include "base/message/message_writer.hpp"
#include "base/message/string_table.hpp"
#include "core/session/stream_connection.hpp"
#include "core/value/pack_value.hpp"
#include "core/value/var_type.hpp"
#include "robdef/service_definition_set.hpp"
#include "test/fuzz/plan_types.hpp"

namespace {

using namespace rr;

MessageElement u32(std::string name, std::uint32_t v) {
    MessageElement e;
    e.name = std::move(name);
    e.type = DataTypes::uint32_t;
    std::byte b[4];
    store_le(b, v);
    e.data = SharedBytes::copy_of(b, 4);
    return e;
}

Message base(std::uint16_t version) {
    Message m;
    m.version = version;
    m.header.sender_node_id = NodeID::parse("0123456789abcdef0123456789abcdef").value();
    m.header.receiver_node_id = NodeID::parse("fedcba9876543210fedcba9876543210").value();
    m.header.sender_endpoint = 1000;
    m.header.receiver_endpoint = 70000;
    return m;
}

Message heartbeat(std::uint16_t version, bool stripped) {
    Message m = base(version);
    if (stripped) m.header.v4_flags = std::uint8_t{0};
    MessageEntry e;
    e.entry_type = MessageEntryType::ConnectionTest;
    m.entries.push_back(e);
    return m;
}

Message call(std::uint16_t version) {
    Message m = base(version);
    MessageEntry e;
    e.entry_type = MessageEntryType::FunctionCallReq;
    e.service_path = "svc.obj[1]";
    e.member_name = "move";
    e.request_id = 300;
    MessageElement list;
    list.name = "points";
    list.type = DataTypes::list_t;
    for (int i = 0; i < 2; ++i) {
        MessageElement p;
        p.number = i;
        p.type = DataTypes::structure_t;
        p.type_name = "demo.Point";
        p.elements.push_back(u32("x", 1));
        p.elements.push_back(make_string_element("label", "ab"));
        list.elements.push_back(p);
    }
    e.elements.push_back(list);
    MessageElement nothing;
    nothing.name = "opt";
    e.elements.push_back(nothing);
    m.entries.push_back(e);
    return m;
}

Message pipe_ack(std::uint16_t version) {
    Message m = base(version);
    m.header.metadata = "unreliable\n";
    MessageEntry e;
    e.entry_type = MessageEntryType::PipePacketRet;
    e.member_name = "p";
    MessageElement ack = u32("", 5);
    ack.number = -1;
    e.elements.push_back(ack);
    m.entries.push_back(e);
    return m;
}

Message v4_extras() {
    Message m = call(4);
    m.header.priority = 2;
    m.header.extended = "x";
    m.header.message_id = 9;
    m.entries[0].extended = "e";
    MessageEntry err;
    err.entry_type = MessageEntryType::PropertyGetRes;
    err.member_name = "value";
    set_entry_error(err, make_error(MessageErrorType::ValueNotSet, "not set"));
    m.entries.push_back(err);
    apply_string_table(m, StringTableOptions{});
    return m;
}

// Values of the svc types (plan_types.hpp) as a reply's elements, for the JSON text plan check.
std::optional<Message> svc_values() {
    robdef::ServiceDefinitionSet set;
    if (!set.add_text(rr::fuzz::kPlanRobdef, "fuzz.robdef")) return std::nullopt;
    const nlohmann::json n = {{"x", 1.5}, {"y", {-2, 1e-300}}};
    const nlohmann::json p = {{"i", -7}, {"n", n}, {"m", {{"dims", {2, 2}}, {"array", {0, 1, 254, 255}}}}};
    const nlohmann::json leaf = {{"s", "a\"\n\u00e9"}, {"d", {0.5, "NaN"}}, {"p", p}, {"ns", {n, n}}, {"e", 2},
                                 {"next", nullptr}, {"l", {1, -1}}, {"m", {{"k", "v"}, {"", ""}}},
                                 {"pm", {{"3", nlohmann::json::array({p})}, {"-1", nlohmann::json::array()}}},
                                 {"md", {{"dims", {1, 2}}, {"array", {1, 2}}}}};
    nlohmann::json full = leaf;
    full["next"] = leaf;
    const nlohmann::json w = {{"any", {{"type", "svc.P[]"}, {"value", nlohmann::json::array({p})}}},
                               {"grid", {{"dims", {1, 2}}, {"array", {p, p}}}},
                               {"x", -0.5}};
    const std::pair<const char*, nlohmann::json> values[] = {
        {"S", full}, {"W", w}, {"P[]", {p, p}}, {"N[]", nlohmann::json::array({n})}, {"string{string}", {{"b", "x\ty"}}}, {"E", 1}};
    Message m = base(4);
    MessageEntry e;
    e.entry_type = MessageEntryType::FunctionCallRes;
    e.service_path = "svc.obj";
    e.member_name = "f";
    e.request_id = 1;
    for (const auto& [type, json] : values) {
        auto t = parse_type_string(type);
        if (!t) return std::nullopt;
        auto v = value_from_json(json, *t, set, "svc");
        if (!v) return std::nullopt;
        auto el = pack_value(*v, *t, type, set, "svc");
        if (!el) return std::nullopt;
        e.elements.push_back(std::move(*el));
    }
    m.entries.push_back(std::move(e));
    return m;
}

bool write_bytes(const std::string& dir, const char* name, const std::vector<std::byte>& bytes) {
    std::FILE* f = std::fopen((dir + "/" + name).c_str(), "wb");
    if (!f) return false;
    bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
    return std::fclose(f) == 0 && ok;
}

bool write(const std::string& dir, const char* name, const Message& m) {
    auto bytes = encode_message(m);
    if (!bytes) return false;
    return write_bytes(dir, name, std::vector<std::byte>(bytes->bytes().begin(), bytes->bytes().end()));
}

// What an RR client sends first on a TCP connection: CreateConnection, then (without waiting for the
// reply, which a fuzz input cannot contain) ConnectClientCombined for `service` and a heartbeat.
std::vector<std::byte> client_stream(bool v4, const char* service) {
    StreamConfig config;
    config.local_node_id = NodeID::parse("0123456789abcdef0123456789abcdef").value();
    config.enable_message4 = v4;
    StreamConnection client(StreamRole::client, config, MonoTime{});
    auto first = client.pending_output();
    std::vector<std::byte> out(first.begin(), first.end());
    Message m = base(2);
    m.header.receiver_node_id = NodeID{};
    m.header.receiver_endpoint = 0;
    MessageEntry e;
    e.entry_type = MessageEntryType::ConnectClientCombined;
    e.service_path = service;
    e.request_id = 1;
    e.elements.push_back(make_string_element("clientversion", "1.2.8"));
    e.elements.push_back(make_string_element("returnservicedefs", "true"));
    m.entries.push_back(e);
    for (const Message& msg : {m, heartbeat(2, false)}) {
        auto bytes = encode_message(msg);
        if (bytes) out.insert(out.end(), bytes->bytes().begin(), bytes->bytes().end());
    }
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2 && argc != 3) {
        std::fprintf(stderr, "usage: %s <seed-dir> [<port-seed-dir>]\n", argv[0]);
        return 2;
    }
    const std::string dir = argv[1];
    bool ok = write(dir, "heartbeat_v2.bin", heartbeat(2, false)) && write(dir, "heartbeat_v4.bin", heartbeat(4, false)) &&
              write(dir, "heartbeat_v4_stripped.bin", heartbeat(4, true)) && write(dir, "call_v2.bin", call(2)) &&
              write(dir, "call_v4.bin", call(4)) && write(dir, "pipe_ack_v2.bin", pipe_ack(2)) &&
              write(dir, "pipe_ack_v4.bin", pipe_ack(4)) && write(dir, "extras_v4.bin", v4_extras());
    if (ok) {
        auto svc = svc_values();
        ok = svc && write(dir, "svc_values_v4.bin", *svc);
    }
    if (ok && argc == 3) {
        const std::string port = argv[2];
        ok = write_bytes(port, "rr_client_v2.bin", client_stream(false, "create")) &&
             write_bytes(port, "rr_client_v4.bin", client_stream(true, "webcam"));
    }
    if (!ok) {
        std::fprintf(stderr, "gen_message_seeds: could not write seeds to %s\n", dir.c_str());
        return 1;
    }
    return 0;
}
