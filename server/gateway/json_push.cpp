#include "server/gateway/json_push.hpp"

#include <algorithm>
#include <charconv>
#include <stdexcept>

#include "core/value/timespec.hpp"
#include "server/gateway/binary_push.hpp"

namespace rr::server::gateway {

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
