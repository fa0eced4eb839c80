// The JSON WebSocket's requests (docs/json-api.md §WebSocket), parsed and checked without a socket or
// a device: a text message becomes its envelope ({"id", "op"}), then one typed request per op.
// JsonSocketSession (json_socket.cpp) answers what this returns; the op table lives here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>

#include "server/gateway/json_api.hpp"
#include "server/gateway/rate_window.hpp"

namespace rr::server::gateway {

/// A request message's envelope.
struct SocketEnvelope {
    nlohmann::json id;        ///< an integer or a string, echoed in the reply
    std::string op;           ///< not yet checked against the op table
    nlohmann::json message;   ///< the whole request object
};

/// A message refused before its op is read: answered with `error` under `id` (null when the message
/// had no usable id).
struct SocketRejection {
    nlohmann::json id;
    ApiError error;
};

/// Parses one text message of at most `max_bytes` bytes. Refusals: BufferLimitViolation (400) over the
/// limit; InvalidArgument (400) when it is not JSON (or nests deeper than kMaxRequestJsonDepth), not an
/// object, has no "id" (integer or string) or no "op" (string).
std::variant<SocketEnvelope, SocketRejection> parse_socket_envelope(std::string_view text, std::size_t max_bytes);

/// {"op": "login", "username", "password"} or {"op": "login", "token"} (only with gateway users).
struct LoginRequest {
    std::string username, password;  ///< by password
    std::string token;               ///< by token (`by_token`)
    bool by_token = false;
};
/// {"op": "device_login", "device", "username", "password"}: the socket's own session to a passthrough device.
struct DeviceLoginRequest {
    std::string device, username, password;
};
/// {"op": "device_logout", "device"}.
struct DeviceLogoutRequest {
    std::string device;
};
/// {"op": "devices"}.
struct DevicesRequest {};
/// {"op": "device", "device"}.
struct DeviceRequest {
    std::string device;
};
/// {"op": "access", "device", "members"?: [names], "device_user"?}: GET /api/devices/{name}/access on the
/// socket (json_access.hpp), for the socket's gateway login. `members` arrives joined by commas (an
/// empty list or name stays an error there).
struct AccessRequest {
    std::string device;
    std::optional<std::string> members, device_user;
};
/// {"op": "unsubscribe", "subscription"}.
struct UnsubscribeRequest {
    std::uint64_t subscription = 0;
};
/// {"op": "set_out_value", "subscription", "value"}: a wire subscription's OutValue.
struct SetOutValueRequest {
    std::uint64_t subscription = 0;
    nlohmann::json value;
};
/// {"op": "send", "subscription", "value", "requestack"}: a packet on a pipe subscription.
struct SendRequest {
    std::uint64_t subscription = 0;
    nlohmann::json value;
    bool request_ack = false;
};

enum class MemberOp : std::uint8_t { get, set, call, peek, subscribe };

/// {"op": "get" | "set" | "call" | "peek" | "subscribe", "device", "object", "member", …}: an operation
/// on one member. `address.principal` and `address.device_session` are the session's to fill in.
struct MemberRequest {
    MemberOp op = MemberOp::get;
    MemberAddress address;
    nlohmann::json value;        ///< set: the new value
    nlohmann::json args;         ///< call: the arguments (null when absent)
    std::size_t max_items = 0;   ///< call: how many items of a generator to read (0: the default)
    bool binary = false;         ///< subscribe: numeric arrays as binary pushes (binary_push.hpp)
    /// subscribe: "max_rate_hz" (wires and pipes: at most one value per 1/max_rate_hz, rate_window.hpp),
    /// from kMinRateHz to kMaxRateHz; `rate_period` is its period (0: not given).
    std::optional<double> max_rate_hz;
    RateClock rate_period{0};
    /// subscribe: "queue_length" (rate-limited pipes: packets waiting, 1 to kMaxQueueLength; needs max_rate_hz).
    std::optional<std::size_t> queue_length;
};

/// The longest "queue_length" of a rate-limited pipe subscription.
inline constexpr std::size_t kMaxQueueLength = 64;

using SocketRequest = std::variant<LoginRequest, DeviceLoginRequest, DeviceLogoutRequest, DevicesRequest, DeviceRequest,
                                   AccessRequest, UnsubscribeRequest, SetOutValueRequest, SendRequest, MemberRequest>;

/// Checks the op's fields. `with_logins`: the gateway has users, so "login" is an op (without them it
/// is unknown, as any other name outside the table). Errors: InvalidArgument (400) naming the missing
/// or mistyped field, or `unknown op "…"`.
std::variant<SocketRequest, ApiError> parse_socket_request(const SocketEnvelope& envelope, bool with_logins);

/// The op names parse_socket_request knows, "login" first.
std::span<const std::string_view> socket_ops();

}  // namespace rr::server::gateway
