#include "server/gateway/json_socket_request.hpp"

#include <array>
#include <utility>

namespace rr::server::gateway {

namespace {

using Parsed = std::variant<SocketRequest, ApiError>;
using Json = nlohmann::json;

// The field `name` when it is a string.
const std::string* request_string(const Json& msg, std::string_view name) {
    auto it = msg.find(name);
    return it != msg.end() && it->is_string() ? &it->get_ref<const std::string&>() : nullptr;
}

std::optional<ApiError> parse_subscription_id(const Json& msg, std::uint64_t& sid) {
    auto s = msg.find("subscription");
    if (s == msg.end() || !s->is_number_unsigned()) return bad_request("\"subscription\" (a subscription id) is required");
    sid = s->get<std::uint64_t>();
    return std::nullopt;
}

std::optional<ApiError> parse_member_address(const Json& msg, MemberAddress& a) {
    const auto* d = request_string(msg, "device");
    const auto* m = request_string(msg, "member");
    if (!d || !m) return bad_request("\"device\" and \"member\" (strings) are required");
    a.device = *d;
    a.member = *m;
    if (auto o = msg.find("object"); o != msg.end() && !o->is_null()) {
        if (!o->is_string()) return bad_request("\"object\" must be a string (a relative service path)");
        a.object = o->get<std::string>();
    }
    return std::nullopt;
}

Parsed parse_login(const Json& msg) {
    const auto* u = request_string(msg, "username");
    const auto* p = request_string(msg, "password");
    const auto* t = request_string(msg, "token");
    if (u && p) return LoginRequest{*u, *p, {}, false};
    if (t) return LoginRequest{{}, {}, *t, true};
    return bad_request("login takes \"username\" and \"password\", or \"token\"");
}

Parsed parse_device_login(const Json& msg) {
    const auto* d = request_string(msg, "device");
    const auto* u = request_string(msg, "username");
    auto p = msg.find("password");
    if (!d || !u || u->empty() || (p != msg.end() && !p->is_string()))
        return bad_request("device_login takes \"device\", \"username\" (non-empty strings) and \"password\" (string)");
    return DeviceLoginRequest{*d, *u, p == msg.end() ? std::string() : p->get<std::string>()};
}

Parsed parse_device_logout(const Json& msg) {
    const auto* d = request_string(msg, "device");
    if (!d) return bad_request("\"device\" (string) is required");
    return DeviceLogoutRequest{*d};
}

Parsed parse_devices(const Json&) { return DevicesRequest{}; }

Parsed parse_device(const Json& msg) {
    const auto* d = request_string(msg, "device");
    if (!d) return bad_request("\"device\" (string) is required");
    return DeviceRequest{*d};
}

Parsed parse_access(const Json& msg) {
    const auto* d = request_string(msg, "device");
    if (!d) return bad_request("\"device\" (string) is required");
    AccessRequest r{*d, std::nullopt, std::nullopt};
    if (auto m = msg.find("members"); m != msg.end() && !m->is_null()) {
        if (!m->is_array()) return bad_request("\"members\" must be an array of member names");
        std::string joined;
        for (const auto& name : *m) {
            if (!name.is_string()) return bad_request("\"members\" must be an array of member names");
            if (!joined.empty() || &name != &m->front()) joined += ',';
            joined += name.get<std::string>();
        }
        r.members = std::move(joined);
    }
    if (auto u = msg.find("device_user"); u != msg.end() && !u->is_null()) {
        if (!u->is_string()) return bad_request("\"device_user\" must be a string");
        r.device_user = u->get<std::string>();
    }
    return r;
}

Parsed parse_unsubscribe(const Json& msg) {
    UnsubscribeRequest r;
    if (auto e = parse_subscription_id(msg, r.subscription)) return *e;
    return r;
}

// "subscription" and "value": what set_out_value and send both carry.
std::optional<ApiError> parse_subscription_value(const Json& msg, std::uint64_t& sid, Json& value) {
    if (auto e = parse_subscription_id(msg, sid)) return e;
    auto v = msg.find("value");
    if (v == msg.end()) return bad_request("\"value\" is required");
    value = *v;
    return std::nullopt;
}

Parsed parse_set_out_value(const Json& msg) {
    SetOutValueRequest r;
    if (auto e = parse_subscription_value(msg, r.subscription, r.value)) return *e;
    return r;
}

Parsed parse_send(const Json& msg) {
    SendRequest r;
    if (auto e = parse_subscription_value(msg, r.subscription, r.value)) return *e;
    if (auto a = msg.find("requestack"); a != msg.end()) {
        if (!a->is_boolean()) return bad_request("\"requestack\" must be true or false");
        r.request_ack = a->get<bool>();
    }
    return r;
}

template <MemberOp Op>
Parsed parse_member(const Json& msg) {
    MemberRequest r;
    r.op = Op;
    if (auto e = parse_member_address(msg, r.address)) return *e;
    if constexpr (Op == MemberOp::set) {
        auto v = msg.find("value");
        if (v == msg.end()) return bad_request("\"value\" is required");
        r.value = *v;
    }
    if constexpr (Op == MemberOp::call) {
        if (auto a = msg.find("args"); a != msg.end()) r.args = *a;
        if (auto m = msg.find("max_items"); m != msg.end()) {
            if (!m->is_number_unsigned()) return bad_request("\"max_items\" must be a non-negative integer");
            r.max_items = m->get<std::size_t>();
        }
    }
    if constexpr (Op == MemberOp::subscribe) {
        if (auto b = msg.find("binary"); b != msg.end()) {
            if (!b->is_boolean()) return bad_request("\"binary\" must be true or false");
            r.binary = b->get<bool>();
        }
        if (auto m = msg.find("max_rate_hz"); m != msg.end()) {
            if (!m->is_number()) return bad_request("\"max_rate_hz\" must be a number (values per second)");
            auto period = rate_period(m->get<double>());
            if (!period.error.empty()) return bad_request(period.error);
            r.max_rate_hz = m->get<double>();
            r.rate_period = period.period;
        }
        if (auto q = msg.find("queue_length"); q != msg.end()) {
            if (!q->is_number_unsigned() || q->get<std::uint64_t>() < 1 || q->get<std::uint64_t>() > kMaxQueueLength)
                return bad_request("\"queue_length\" must be an integer from 1 to " + std::to_string(kMaxQueueLength));
            if (!r.max_rate_hz) return bad_request("\"queue_length\" needs \"max_rate_hz\" (a pipe's packets wait for their window)");
            r.queue_length = q->get<std::size_t>();
        }
    }
    return r;
}

struct OpEntry {
    std::string_view name;
    Parsed (*parse)(const Json&);
};

// "login" first: without gateway users the table starts after it.
constexpr std::array<OpEntry, 14> kOps{{
    {"login", parse_login},
    {"device_login", parse_device_login},
    {"device_logout", parse_device_logout},
    {"devices", parse_devices},
    {"device", parse_device},
    {"access", parse_access},
    {"get", parse_member<MemberOp::get>},
    {"set", parse_member<MemberOp::set>},
    {"call", parse_member<MemberOp::call>},
    {"peek", parse_member<MemberOp::peek>},
    {"subscribe", parse_member<MemberOp::subscribe>},
    {"unsubscribe", parse_unsubscribe},
    {"set_out_value", parse_set_out_value},
    {"send", parse_send},
}};

constexpr auto kOpNames = [] {
    std::array<std::string_view, kOps.size()> names{};
    for (std::size_t i = 0; i < kOps.size(); ++i) names[i] = kOps[i].name;
    return names;
}();

}  // namespace

std::variant<SocketEnvelope, SocketRejection> parse_socket_envelope(std::string_view text, std::size_t max_bytes) {
    if (text.size() > max_bytes)
        return SocketRejection{nullptr, api_error(400, MessageErrorType::BufferLimitViolation,
                                                  "message of " + std::to_string(text.size()) + " bytes is over the limit of " +
                                                      std::to_string(max_bytes))};
    auto msg = parse_request_json(text);
    if (!msg) return SocketRejection{nullptr, bad_request(msg.error().message)};
    if (!msg->is_object()) return SocketRejection{nullptr, bad_request("a request is a JSON object")};
    nlohmann::json id = nullptr;
    if (auto it = msg->find("id"); it != msg->end()) id = *it;
    if (!id.is_number_integer() && !id.is_string())
        return SocketRejection{nullptr, bad_request("a request needs an \"id\" (integer or string)")};
    const auto* op = request_string(*msg, "op");
    if (!op) return SocketRejection{std::move(id), bad_request("a request needs an \"op\" (string)")};
    SocketEnvelope e{std::move(id), *op, {}};
    e.message = std::move(*msg);
    return e;
}

std::variant<SocketRequest, ApiError> parse_socket_request(const SocketEnvelope& envelope, bool with_logins) {
    for (const auto& op : std::span(kOps).subspan(with_logins ? 0 : 1))
        if (op.name == envelope.op) return op.parse(envelope.message);
    return bad_request("unknown op \"" + envelope.op + "\"");
}

std::span<const std::string_view> socket_ops() { return kOpNames; }

}  // namespace rr::server::gateway
