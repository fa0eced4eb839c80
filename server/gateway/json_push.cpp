#include "server/gateway/json_push.hpp"

#include <algorithm>
#include <charconv>
#include <stdexcept>

#include "core/json/element_json_plan.hpp"
#include "core/value/timespec.hpp"
#include "server/gateway/binary_push.hpp"

namespace rr::server::gateway {

namespace {
// The decimal text of `v`, as nlohmann writes an integer.
template <class Integer>
void append_integer(std::string& out, Integer v) {
    char digits[24];
    out.append(digits, std::to_chars(digits, digits + sizeof digits, v).ptr);
}

// The direct JSON text plan of a member's type or parameter, from the device's types.
const element_json_text::Plan* text_plan(const JsonApi& api, const MemberTarget& target,
                                         const robdef::TypeDefinition& type) {
    if (!target.types || !target.service) return nullptr;
    return target.types->json_text_plan(type, target.context(), api.options().limits);
}
}  // namespace

PushHead push_head(std::uint64_t sid, std::string_view kind, std::uint64_t dropped, std::string_view body) {
    if (kind.size() > PushHead::kMaxKind) throw std::length_error("push kind longer than PushHead::kMaxKind");
    PushHead h;
    char* out = h.bytes.data();
    char* const end = out + h.bytes.size();
    auto put = [&](std::string_view s) { out = std::copy(s.begin(), s.end(), out); };
    put("{\"subscription\":");
    out = std::to_chars(out, end, sid).ptr;
    put(",\"kind\":\"");
    put(kind);
    put("\"");
    if (dropped) {
        put(",\"dropped\":");
        out = std::to_chars(out, end, dropped).ptr;
    }
    if (body.size() > 2) {
        put(",");
        h.body_offset = 1;  // the members and the closing brace
    } else {
        put("}");
        h.body_offset = body.size();
    }
    h.size = static_cast<std::size_t>(out - h.bytes.data());
    return h;
}

std::string push_text(std::uint64_t sid, std::string_view kind, std::uint64_t dropped, std::string_view body) {
    const PushHead head = push_head(sid, kind, dropped, body);
    std::string out;
    out.reserve(head.size + body.size());
    out += head.text();
    out += body.substr(head.body_offset);
    return out;
}

nlohmann::json wire_push_body(const JsonApi& api, const MessageEntry& packet, const MemberTarget& target,
                              BinaryArrays* binary) {
    nlohmann::json msg = nlohmann::json::object();
    const auto* p = packet.find("packet");
    const auto* ts = packet.find("packettime");
    if (!p || !ts) {
        msg["error"] = error_object(api_error(502, MessageErrorType::MessageElementNotFound,
                                              "WirePacket from the device without packet / packettime"));
        return msg;
    }
    auto time = unpack_timespec(*ts);
    auto j = api.element_json(*p, target.member->type, target, binary);
    if (!time) {
        msg["error"] = error_object(ApiError{502, time.error().name, time.error().message});
    } else if (!j) {
        msg["error"] = error_object(*j.error);
    } else {
        msg["value"] = std::move(j.value);
        msg["time"] = time_json(time->seconds, time->nanoseconds);
    }
    return msg;
}

std::string wire_push_text(const JsonApi& api, const MessageEntry& packet, const MemberTarget& target,
                           bool omit_null_members) {
    // The direct path writes what json_text(wire_push_body(…)) would: nlohmann sorts an object's keys.
    const auto* p = packet.find("packet");
    const auto* ts = packet.find("packettime");
    const auto* plan = text_plan(api, target, target.member->type);
    if (p && ts && plan) {
        if (auto time = unpack_timespec(*ts)) {
            std::string out = "{\"time\":{\"nanoseconds\":";
            append_integer(out, time->nanoseconds);
            out += ",\"seconds\":";
            append_integer(out, time->seconds);
            out += "},\"value\":";
            if (plan->append(out, *p, omit_null_members)) {
                out += '}';
                return out;
            }
        }
    }
    return json_text(wire_push_body(api, packet, target));
}

std::string event_push_text(const JsonApi& api, const MessageEntry& event, const MemberTarget& target,
                            bool omit_null_members) {
    const auto& params = target.member->parameters;
    std::vector<std::pair<const robdef::TypeDefinition*, const element_json_text::Plan*>> sorted;
    sorted.reserve(params.size());
    for (const auto& p : params) {
        const auto* plan = text_plan(api, target, p);
        if (!plan) return json_text(event_push_body(api, event, target));
        sorted.emplace_back(&p, plan);
    }
    // In nlohmann's key order (parameter names are identifiers: nothing to escape). Two parameters of
    // one name (an unchecked received definition) are the general path's: it keeps one of them.
    std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first->name < b.first->name; });
    std::string out = "{\"args\":{";
    for (std::size_t i = 0; i < sorted.size(); ++i) {
        const auto& [p, plan] = sorted[i];
        const auto* el = event.find(p->name);
        if (!el || (i && sorted[i - 1].first->name == p->name)) return json_text(event_push_body(api, event, target));
        if (i) out += ',';
        out += '"';
        out += p->name;
        out += "\":";
        if (!plan->append(out, *el, omit_null_members)) return json_text(event_push_body(api, event, target));
    }
    out += "}}";
    return out;
}

nlohmann::json event_push_body(const JsonApi& api, const MessageEntry& event, const MemberTarget& target,
                               BinaryArrays* binary) {
    auto args = nlohmann::json::object();
    for (const auto& p : target.member->parameters) {
        const auto* el = event.find(p.name);
        if (!el)
            return {{"error", error_object(api_error(502, MessageErrorType::MessageElementNotFound,
                                                     "event from the device has no \"" + p.name + "\" element"))}};
        auto j = api.element_json(*el, p, target, binary);
        if (!j) return {{"error", error_object(*j.error)}};
        args[p.name] = std::move(j.value);
    }
    return {{"args", std::move(args)}};
}

SharedEntry::BinaryRendering pipe_push(const JsonApi& api, std::uint64_t sid, const MessageElement& packet,
                                       const MemberTarget& target, std::uint64_t dropped, bool binary) {
    const auto* plan = binary ? nullptr : text_plan(api, target, target.member->type);
    if (plan) {
        // What json_text(msg) below gives, nlohmann's keys sorted: dropped, kind, subscription, value.
        std::string out = "{";
        if (dropped) {
            out += "\"dropped\":";
            append_integer(out, dropped);
            out += ',';
        }
        out += "\"kind\":\"pipe\",\"subscription\":";
        append_integer(out, sid);
        out += ",\"value\":";
        if (plan->append(out, packet)) {
            out += '}';
            return {std::move(out), nullptr};
        }
    }
    nlohmann::json msg{{"subscription", sid}, {"kind", "pipe"}};
    BinaryArrays arrays;
    auto j = api.element_json(packet, target.member->type, target, binary ? &arrays : nullptr);
    if (j)
        msg["value"] = std::move(j.value);
    else
        msg["error"] = error_object(*j.error);
    if (dropped) msg["dropped"] = dropped;
    auto push = binary_rendering(msg, arrays);
    if (push.arrays) push.body = binary_push_head(push.body);  // the whole push, not a shared body
    return push;
}

SharedEntry::BinaryRendering binary_rendering(const nlohmann::json& body, const BinaryArrays& arrays) {
    // An error made after a part set arrays aside refers to none of them: a text push.
    if (body.contains("error") || arrays.blobs.empty()) return {json_text(body), nullptr};
    return {json_text(body), std::make_shared<const std::string>(binary_push_arrays(arrays.blobs))};
}

}  // namespace rr::server::gateway
