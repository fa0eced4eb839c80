#include "core/foxglove/foxglove_protocol.hpp"
#include "core/json/json_nesting.hpp"

#include <cstring>
#include <limits>

namespace rr::foxglove {
namespace {

using json = nlohmann::json;

std::string dump(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

void put_u32(std::string& out, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void put_u64(std::string& out, std::uint64_t v) {
    for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
std::uint32_t get_u32(std::string_view b, std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + i])) << (8 * i);
    return v;
}

json channel_json(const Channel& c) {
    json j{{"id", c.id}, {"topic", c.topic}, {"encoding", c.encoding}, {"schemaName", c.schema_name}, {"schema", c.schema}};
    if (!c.schema_encoding.empty()) j["schemaEncoding"] = c.schema_encoding;
    return j;
}

json schema_json(const ServiceSchema& s) {
    return json{{"encoding", s.encoding}, {"schemaName", s.schema_name}, {"schemaEncoding", s.schema_encoding}, {"schema", s.schema}};
}

json parameter_json(const Parameter& p) {
    json j{{"name", p.name}};
    if (!p.value.is_null()) j["value"] = p.value;  // absent: unset
    if (!p.type.empty()) j["type"] = p.type;
    return j;
}

// --- decoding helpers: each returns an error text ("" = fine) ---

struct Reader {
    const DecodeLimits& limits;
    std::string error;
    MessageErrorType kind = MessageErrorType::ProtocolError;

    bool bad(std::string why, MessageErrorType k = MessageErrorType::ProtocolError) {
        if (error.empty()) {
            error = std::move(why);
            kind = k;
        }
        return false;
    }

    const json* field(const json& obj, const char* name, bool required) {
        auto it = obj.find(name);
        if (it == obj.end() || (it->is_null() && !required)) {
            if (required) bad(std::string("\"") + name + "\" is missing");
            return nullptr;
        }
        return &*it;
    }

    bool u32(const json& obj, const char* name, std::uint32_t& out) {
        const json* v = field(obj, name, true);
        if (!v) return false;
        if (!v->is_number_integer() || (v->is_number_integer() && !v->is_number_unsigned() && v->get<std::int64_t>() < 0))
            return bad(std::string("\"") + name + "\" is not a non-negative integer");
        const auto n = v->get<std::uint64_t>();
        if (n > std::numeric_limits<std::uint32_t>::max()) return bad(std::string("\"") + name + "\" is over 2^32-1");
        out = static_cast<std::uint32_t>(n);
        return true;
    }

    bool str(const json& obj, const char* name, std::string& out, bool required, std::size_t max) {
        const json* v = field(obj, name, required);
        if (!v) return !required;
        if (!v->is_string()) return bad(std::string("\"") + name + "\" is not a string");
        const auto& s = v->get_ref<const std::string&>();
        if (s.size() > max)
            return bad(std::string("\"") + name + "\" is longer than " + std::to_string(max) + " bytes",
                       MessageErrorType::BufferLimitViolation);
        out = s;
        return true;
    }

    const json* array(const json& obj, const char* name, bool required) {
        const json* v = field(obj, name, required);
        if (!v) return nullptr;
        if (!v->is_array()) {
            bad(std::string("\"") + name + "\" is not an array");
            return nullptr;
        }
        if (v->size() > limits.max_items) {
            bad(std::string("\"") + name + "\" has more than " + std::to_string(limits.max_items) + " entries",
                MessageErrorType::BufferLimitViolation);
            return nullptr;
        }
        return v;
    }

    bool u32_list(const json& obj, const char* name, std::vector<std::uint32_t>& out) {
        const json* a = array(obj, name, true);
        if (!a) return false;
        for (const auto& x : *a) {
            json holder{{"id", x}};
            std::uint32_t n = 0;
            if (!u32(holder, "id", n)) {
                error = std::string("\"") + name + "\" holds a value that is not an id (0 to 2^32-1)";
                return false;
            }
            out.push_back(n);
        }
        return true;
    }

    bool name_list(const json& obj, const char* name, std::vector<std::string>& out) {
        const json* a = field(obj, name, false);
        if (!a) return error.empty();  // absent: empty list
        if (!(a = array(obj, name, false))) return false;
        for (const auto& x : *a) {
            if (!x.is_string()) return bad(std::string("\"") + name + "\" holds a value that is not a string");
            if (x.get_ref<const std::string&>().size() > limits.max_name_bytes)
                return bad(std::string("a name in \"") + name + "\" is longer than " + std::to_string(limits.max_name_bytes) + " bytes",
                           MessageErrorType::BufferLimitViolation);
            out.push_back(x.get<std::string>());
        }
        return true;
    }

    bool optional_id(const json& obj, std::optional<std::string>& out) {
        const json* v = field(obj, "id", false);
        if (!v) return true;
        if (!v->is_string()) return bad("\"id\" is not a string");
        if (v->get_ref<const std::string&>().size() > limits.max_name_bytes)
            return bad("\"id\" is too long", MessageErrorType::BufferLimitViolation);
        out = v->get<std::string>();
        return true;
    }
};

std::size_t depth_of(const json& j, std::size_t limit) {
    if (!j.is_structured() || limit == 0) return 0;
    std::size_t d = 0;
    for (const auto& x : j) d = std::max(d, depth_of(x, limit - 1));
    return d + 1;
}

template <class T>
Result<ClientMessage> done(Reader& r, T value) {
    if (!r.error.empty()) return fail(r.kind, std::move(r.error));
    return ClientMessage{std::move(value)};
}

Result<ClientMessage> decode_object(const json& j, const DecodeLimits& limits) {
    Reader r{limits, {}};
    std::string op;
    if (!r.str(j, "op", op, true, 64)) return fail(r.kind, r.error);

    if (op == "subscribe") {
        Subscribe m;
        if (const json* a = r.array(j, "subscriptions", true)) {
            for (const auto& x : *a) {
                if (!x.is_object()) {
                    r.bad("\"subscriptions\" holds a value that is not an object");
                    break;
                }
                Subscribe::Item item;
                if (!r.u32(x, "id", item.id) || !r.u32(x, "channelId", item.channel_id)) break;
                m.subscriptions.push_back(item);
            }
        }
        return done(r, std::move(m));
    }
    if (op == "unsubscribe") {
        Unsubscribe m;
        r.u32_list(j, "subscriptionIds", m.subscription_ids);
        return done(r, std::move(m));
    }
    if (op == "advertise") {
        ClientAdvertise m;
        if (const json* a = r.array(j, "channels", true)) {
            for (const auto& x : *a) {
                if (!x.is_object()) {
                    r.bad("\"channels\" holds a value that is not an object");
                    break;
                }
                ClientChannel c;
                if (!r.u32(x, "id", c.id) || !r.str(x, "topic", c.topic, true, limits.max_name_bytes) ||
                    !r.str(x, "encoding", c.encoding, true, limits.max_name_bytes) ||
                    !r.str(x, "schemaName", c.schema_name, false, limits.max_name_bytes) ||
                    !r.str(x, "schema", c.schema, false, limits.max_schema_bytes) ||
                    !r.str(x, "schemaEncoding", c.schema_encoding, false, limits.max_name_bytes))
                    break;
                m.channels.push_back(std::move(c));
            }
        }
        return done(r, std::move(m));
    }
    if (op == "unadvertise") {
        ClientUnadvertise m;
        r.u32_list(j, "channelIds", m.channel_ids);
        return done(r, std::move(m));
    }
    if (op == "getParameters") {
        GetParameters m;
        if (r.name_list(j, "parameterNames", m.names)) r.optional_id(j, m.id);
        return done(r, std::move(m));
    }
    if (op == "setParameters") {
        SetParameters m;
        if (const json* a = r.array(j, "parameters", true)) {
            for (const auto& x : *a) {
                if (!x.is_object()) {
                    r.bad("\"parameters\" holds a value that is not an object");
                    break;
                }
                Parameter p;
                if (!r.str(x, "name", p.name, true, limits.max_name_bytes) || !r.str(x, "type", p.type, false, 32)) break;
                if (auto v = x.find("value"); v != x.end()) {
                    if (depth_of(*v, limits.max_json_depth + 1) > limits.max_json_depth) {
                        r.bad("a parameter value nests deeper than " + std::to_string(limits.max_json_depth),
                              MessageErrorType::BufferLimitViolation);
                        break;
                    }
                    p.value = *v;
                }
                if (!p.type.empty() && p.type != "byte_array" && p.type != "float64" && p.type != "float64_array") {
                    r.bad("parameter type \"" + p.type + "\" is not byte_array, float64 or float64_array");
                    break;
                }
                m.parameters.push_back(std::move(p));
            }
        }
        if (r.error.empty()) r.optional_id(j, m.id);
        return done(r, std::move(m));
    }
    if (op == "subscribeParameterUpdates") {
        SubscribeParameterUpdates m;
        r.name_list(j, "parameterNames", m.names);
        return done(r, std::move(m));
    }
    if (op == "unsubscribeParameterUpdates") {
        UnsubscribeParameterUpdates m;
        r.name_list(j, "parameterNames", m.names);
        return done(r, std::move(m));
    }
    if (op == "subscribeConnectionGraph") return ClientMessage{SubscribeConnectionGraph{}};
    if (op == "unsubscribeConnectionGraph") return ClientMessage{UnsubscribeConnectionGraph{}};
    if (op == "fetchAsset") {
        FetchAsset m;
        if (r.str(j, "uri", m.uri, true, limits.max_name_bytes)) r.u32(j, "requestId", m.request_id);
        return done(r, std::move(m));
    }
    return fail(MessageErrorType::ProtocolError, "unknown op \"" + op.substr(0, 64) + "\"");
}

}  // namespace

// --- server → client --------------------------------------------------------------------------------

std::string server_info_json(const ServerInfo& info) {
    json j{{"op", "serverInfo"}, {"name", info.name}, {"capabilities", info.capabilities}};
    if (!info.supported_encodings.empty()) j["supportedEncodings"] = info.supported_encodings;
    if (!info.metadata.empty()) j["metadata"] = info.metadata;
    if (!info.session_id.empty()) j["sessionId"] = info.session_id;
    return dump(j);
}

std::string status_json(StatusLevel level, std::string_view message, std::string_view id) {
    json j{{"op", "status"}, {"level", static_cast<int>(level)}, {"message", message}};
    if (!id.empty()) j["id"] = id;
    return dump(j);
}

std::string advertise_json(const std::vector<Channel>& channels) {
    json a = json::array();
    for (const auto& c : channels) a.push_back(channel_json(c));
    return dump(json{{"op", "advertise"}, {"channels", std::move(a)}});
}

std::string unadvertise_json(const std::vector<std::uint32_t>& channel_ids) {
    return dump(json{{"op", "unadvertise"}, {"channelIds", channel_ids}});
}

std::string parameter_values_json(const std::vector<Parameter>& parameters, const std::optional<std::string>& id) {
    json a = json::array();
    for (const auto& p : parameters) a.push_back(parameter_json(p));
    json j{{"op", "parameterValues"}, {"parameters", std::move(a)}};
    if (id) j["id"] = *id;
    return dump(j);
}

std::string advertise_services_json(const std::vector<Service>& services) {
    json a = json::array();
    for (const auto& s : services) {
        // The current form (`request`/`response` with their encodings); Lichtblick warns about the older
        // requestSchema/responseSchema, so they are left out.
        a.push_back(json{{"id", s.id},
                         {"name", s.name},
                         {"type", s.type},
                         {"request", schema_json(s.request)},
                         {"response", schema_json(s.response)}});
    }
    return dump(json{{"op", "advertiseServices"}, {"services", std::move(a)}});
}

std::string unadvertise_services_json(const std::vector<std::uint32_t>& service_ids) {
    return dump(json{{"op", "unadvertiseServices"}, {"serviceIds", service_ids}});
}

std::string service_call_failure_json(std::uint32_t service_id, std::uint32_t call_id, std::string_view message) {
    return dump(json{{"op", "serviceCallFailure"}, {"serviceId", service_id}, {"callId", call_id}, {"message", message}});
}

std::string message_data_head(std::uint32_t subscription_id, std::uint64_t receive_ns) {
    std::string out;
    out.reserve(13);
    out.push_back(static_cast<char>(0x01));
    put_u32(out, subscription_id);
    put_u64(out, receive_ns);
    return out;
}

std::string time_frame(std::uint64_t timestamp_ns) {
    std::string out;
    out.push_back(static_cast<char>(0x02));
    put_u64(out, timestamp_ns);
    return out;
}

std::string service_call_response_head(std::uint32_t service_id, std::uint32_t call_id, std::string_view encoding) {
    std::string out;
    out.push_back(static_cast<char>(0x03));
    put_u32(out, service_id);
    put_u32(out, call_id);
    put_u32(out, static_cast<std::uint32_t>(encoding.size()));
    out.append(encoding);
    return out;
}

// --- client → server --------------------------------------------------------------------------------

Result<ClientMessage> decode_text(std::string_view text, const DecodeLimits& limits) {
    if (text.size() > limits.max_text_bytes)
        return fail(MessageErrorType::BufferLimitViolation,
                    "text message of " + std::to_string(text.size()) + " bytes is over the limit of " +
                        std::to_string(limits.max_text_bytes));
    if (rr::json_limits::nests_deeper_than(text, limits.max_json_depth + 4))
        return fail(MessageErrorType::BufferLimitViolation, "JSON nests deeper than " + std::to_string(limits.max_json_depth + 4));
    json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) return fail(MessageErrorType::ProtocolError, "the text message is not JSON");
    if (!j.is_object()) return fail(MessageErrorType::ProtocolError, "the text message is not a JSON object");
    try {
        return decode_object(j, limits);
    } catch (const std::exception& e) {  // a type check missed above; never expected
        return fail(MessageErrorType::ProtocolError, std::string("malformed message: ") + e.what());
    }
}

Result<ClientMessage> decode_binary(std::string_view bytes, const DecodeLimits& limits) {
    if (bytes.size() > limits.max_binary_bytes)
        return fail(MessageErrorType::BufferLimitViolation,
                    "binary message of " + std::to_string(bytes.size()) + " bytes is over the limit of " +
                        std::to_string(limits.max_binary_bytes));
    if (bytes.empty()) return fail(MessageErrorType::ProtocolError, "empty binary message");
    const auto opcode = static_cast<unsigned char>(bytes[0]);
    if (opcode == 0x01) {
        if (bytes.size() < 5) return fail(MessageErrorType::ProtocolError, "client message data shorter than its 5-byte header");
        return ClientMessage{ClientMessageData{get_u32(bytes, 1), bytes.substr(5)}};
    }
    if (opcode == 0x02) {
        if (bytes.size() < 13) return fail(MessageErrorType::ProtocolError, "service call request shorter than its 13-byte header");
        ServiceCallRequest m;
        m.service_id = get_u32(bytes, 1);
        m.call_id = get_u32(bytes, 5);
        const std::uint32_t n = get_u32(bytes, 9);
        if (n > bytes.size() - 13) return fail(MessageErrorType::ProtocolError, "service call request's encoding runs past its end");
        if (n > limits.max_name_bytes) return fail(MessageErrorType::BufferLimitViolation, "service call request's encoding is too long");
        m.encoding.assign(bytes.substr(13, n));
        m.payload = bytes.substr(13 + n);
        return ClientMessage{std::move(m)};
    }
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02x", opcode);
    return fail(MessageErrorType::ProtocolError, std::string("unknown binary opcode ") + hex);
}

std::string_view client_message_name(const ClientMessage& m) noexcept {
    struct Names {
        std::string_view operator()(const Subscribe&) const { return "subscribe"; }
        std::string_view operator()(const Unsubscribe&) const { return "unsubscribe"; }
        std::string_view operator()(const ClientAdvertise&) const { return "advertise"; }
        std::string_view operator()(const ClientUnadvertise&) const { return "unadvertise"; }
        std::string_view operator()(const GetParameters&) const { return "getParameters"; }
        std::string_view operator()(const SetParameters&) const { return "setParameters"; }
        std::string_view operator()(const SubscribeParameterUpdates&) const { return "subscribeParameterUpdates"; }
        std::string_view operator()(const UnsubscribeParameterUpdates&) const { return "unsubscribeParameterUpdates"; }
        std::string_view operator()(const SubscribeConnectionGraph&) const { return "subscribeConnectionGraph"; }
        std::string_view operator()(const UnsubscribeConnectionGraph&) const { return "unsubscribeConnectionGraph"; }
        std::string_view operator()(const FetchAsset&) const { return "fetchAsset"; }
        std::string_view operator()(const ClientMessageData&) const { return "client message data (binary 0x01)"; }
        std::string_view operator()(const ServiceCallRequest&) const { return "service call request (binary 0x02)"; }
    };
    return std::visit(Names{}, m);
}

}  // namespace rr::foxglove
