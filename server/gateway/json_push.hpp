// The JSON WebSocket's pushes (docs/json-api.md §WebSocket): the body of a wire value, an event or a
// pipe packet rendered once and shared by every subscriber, and one subscriber's push around it.
// No sockets: JsonSocketSession (json_socket.cpp) sends what these return.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "server/gateway/json_api.hpp"
#include "server/gateway/shared_entry.hpp"

namespace rr::server::gateway {

/// The part of a push made per subscriber: push_text(sid, kind, dropped, body) is `text()` followed
/// by `body` from `body_offset` on, so a socket can send the shared body as it is (JsonSocket::send_shared).
struct PushHead {
    static constexpr std::size_t kMaxKind = 16;
    std::array<char, 96> bytes;  // the longest: {"subscription":<20 digits>,"kind":"<16>","dropped":<20 digits>,
    std::size_t size = 0;
    /// 1 (after the body's '{'), or the body's size when it has no members (the head closes the object).
    std::size_t body_offset = 0;
    std::string_view text() const noexcept { return {bytes.data(), size}; }
};

/// The head of {"subscription": sid, "kind": kind[, "dropped": n], …the members of `body`}, where `body`
/// is a JSON object's text (from json_text). Throws std::length_error when `kind` is longer than
/// PushHead::kMaxKind.
PushHead push_head(std::uint64_t sid, std::string_view kind, std::uint64_t dropped, std::string_view body);

/// {"subscription": sid, "kind": kind[, "dropped": n], …the members of `body`}: `body` is a JSON
/// object's text (from json_text), so a shared body is copied, never parsed again.
std::string push_text(std::uint64_t sid, std::string_view kind, std::uint64_t dropped, std::string_view body);

/// {"value": …, "time": {"seconds", "nanoseconds"}} from a WirePacket entry, or {"error": …} (502) when
/// it lacks "packet" / "packettime" or its value does not fit the member's type. With `binary`, numeric
/// arrays go there (binary_push.hpp).
nlohmann::json wire_push_body(const JsonApi& api, const MessageEntry& packet, const MemberTarget& target,
                              BinaryArrays* binary = nullptr);

/// {"args": {parameter: value, …}} from an EventReq entry, or {"error": …} (502) when an argument is
/// missing or does not fit.
nlohmann::json event_push_body(const JsonApi& api, const MessageEntry& event, const MemberTarget& target,
                               BinaryArrays* binary = nullptr);

/// json_text(wire_push_body(api, packet, target)), written straight from the packet's element when the
/// member's type is one core/json/element_json_plan.hpp covers (DeviceTypes::json_text_plan: numbers,
/// strings, enums, structs, pods, namedarrays and containers of them), without the Value and
/// nlohmann::json trees; through wire_push_body otherwise and for every error. `omit_null_members`
/// (the recorder's json channels): the direct path leaves null struct fields and map entries out
/// (Plan::append); the general path keeps them.
std::string wire_push_text(const JsonApi& api, const MessageEntry& packet, const MemberTarget& target,
                           bool omit_null_members = false);

/// json_text(event_push_body(api, event, target)), written straight from the elements when the plan
/// covers every parameter's type; through event_push_body otherwise. `omit_null_members`: as above,
/// inside the arguments.
std::string event_push_text(const JsonApi& api, const MessageEntry& event, const MemberTarget& target,
                            bool omit_null_members = false);

/// A pipe packet's push: {"subscription", "kind": "pipe", "value" | "error"[, "dropped"]}; with the
/// arrays part (and the text already binary_push_head's) when `binary` set any aside for a value. A text
/// push of a type the plan covers is written straight from the element, the same text.
SharedEntry::BinaryRendering pipe_push(const JsonApi& api, std::uint64_t sid, const MessageElement& packet,
                                       const MemberTarget& target, std::uint64_t dropped, bool binary);

/// The rendering of `body` with `arrays` set aside by it (render_binary_body).
SharedEntry::BinaryRendering binary_rendering(const nlohmann::json& body, const BinaryArrays& arrays);

/// A body rendered for binary subscribers: `body(&arrays)` returns the JSON object. The arrays part is
/// null (a text push) when the body set none aside or is an error.
template <class Body>
SharedEntry::BinaryRendering render_binary_body(Body&& body) {
    BinaryArrays arrays;
    nlohmann::json j = body(&arrays);
    return binary_rendering(j, arrays);
}

}  // namespace rr::server::gateway
