// The Foxglove WebSocket protocol (docs/foxglove.md): the messages of subprotocol
// `foxglove.websocket.v1` (Lichtblick, the npm client @foxglove/ws-protocol) and `foxglove.sdk.v1`
// (current Foxglove SDK servers; the same messages), encoded and decoded without I/O.
//
// Text messages are JSON objects with an `op`; binary messages start with a one-byte opcode, integers
// little-endian. Server → client: serverInfo, status, removeStatus, advertise, unadvertise,
// parameterValues, advertiseServices, unadvertiseServices, serviceCallFailure (text); message data
// 0x01, time 0x02, service call response 0x03 (binary). Client → server: subscribe, unsubscribe,
// advertise, unadvertise, getParameters, setParameters, subscribeParameterUpdates,
// unsubscribeParameterUpdates, subscribeConnectionGraph, unsubscribeConnectionGraph, fetchAsset
// (text); client message data 0x01, service call request 0x02 (binary). Source of the facts: the
// public spec foxglove/ws-protocol docs/spec.md.
//
// Decoding never throws (nlohmann's exceptions are caught here); every count and size a message names
// is checked against DecodeLimits before use.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/error/rr_error.hpp"

namespace rr::foxglove {

inline constexpr std::string_view kSubprotocolV1 = "foxglove.websocket.v1";
inline constexpr std::string_view kSubprotocolSdk = "foxglove.sdk.v1";

/// Server capabilities (serverInfo.capabilities).
namespace capability {
inline constexpr const char* client_publish = "clientPublish";
inline constexpr const char* parameters = "parameters";
inline constexpr const char* parameters_subscribe = "parametersSubscribe";
inline constexpr const char* time = "time";
inline constexpr const char* services = "services";
}  // namespace capability

enum class StatusLevel : int { info = 0, warning = 1, error = 2 };

/// A server channel (advertise).
struct Channel {
    std::uint32_t id = 0;
    std::string topic;
    std::string encoding;        ///< e.g. "json"
    std::string schema_name;
    std::string schema;          ///< the schema text (a JSON Schema for "json")
    std::string schema_encoding; ///< "" = left out (deduced from encoding)
};

/// A service's request or response description (advertiseServices, current form).
struct ServiceSchema {
    std::string encoding, schema_name, schema_encoding, schema;
};

/// A server service (advertiseServices).
struct Service {
    std::uint32_t id = 0;
    std::string name;
    std::string type;
    ServiceSchema request, response;
};

/// One parameter: a JSON value and Foxglove's optional type tag ("", "byte_array", "float64",
/// "float64_array"). A value that is absent (unset / unknown) is null.
struct Parameter {
    std::string name;
    nlohmann::json value;
    std::string type;
};

struct ServerInfo {
    std::string name;
    std::vector<std::string> capabilities;
    std::vector<std::string> supported_encodings;
    std::map<std::string, std::string> metadata;
    std::string session_id;
};

// --- server → client --------------------------------------------------------------------------------

std::string server_info_json(const ServerInfo& info);
/// `id` "" = none.
std::string status_json(StatusLevel level, std::string_view message, std::string_view id = {});
std::string advertise_json(const std::vector<Channel>& channels);
std::string unadvertise_json(const std::vector<std::uint32_t>& channel_ids);
/// `id`: the getParameters / setParameters request's id, when it had one.
std::string parameter_values_json(const std::vector<Parameter>& parameters, const std::optional<std::string>& id);
std::string advertise_services_json(const std::vector<Service>& services);
std::string unadvertise_services_json(const std::vector<std::uint32_t>& service_ids);
std::string service_call_failure_json(std::uint32_t service_id, std::uint32_t call_id, std::string_view message);

/// The 13 bytes that precede a message data frame's payload: 0x01, subscription id, receive time (ns).
std::string message_data_head(std::uint32_t subscription_id, std::uint64_t receive_ns);
/// A whole time frame: 0x02, timestamp (ns).
std::string time_frame(std::uint64_t timestamp_ns);
/// What precedes a service call response's payload: 0x03, service id, call id, encoding length, encoding.
std::string service_call_response_head(std::uint32_t service_id, std::uint32_t call_id, std::string_view encoding);

// --- client → server --------------------------------------------------------------------------------

struct DecodeLimits {
    std::size_t max_text_bytes = 1u << 20;       ///< a text message
    std::size_t max_binary_bytes = 16u << 20;    ///< a binary message (client publish, service call)
    std::size_t max_items = 1024;                ///< entries of one message's array (subscriptions, names, …)
    std::size_t max_name_bytes = 1024;           ///< a topic, parameter name, encoding, schema name
    std::size_t max_schema_bytes = 256u << 10;   ///< a client channel's schema text
    std::size_t max_json_depth = 32;             ///< nesting of a parameter value
};

struct ClientChannel {
    std::uint32_t id = 0;
    std::string topic, encoding, schema_name, schema, schema_encoding;
};

struct Subscribe {
    struct Item {
        std::uint32_t id = 0;          ///< the client's subscription id
        std::uint32_t channel_id = 0;
    };
    std::vector<Item> subscriptions;
};
struct Unsubscribe {
    std::vector<std::uint32_t> subscription_ids;
};
struct ClientAdvertise {
    std::vector<ClientChannel> channels;
};
struct ClientUnadvertise {
    std::vector<std::uint32_t> channel_ids;
};
struct GetParameters {
    std::vector<std::string> names;  ///< empty: all
    std::optional<std::string> id;
};
struct SetParameters {
    std::vector<Parameter> parameters;
    std::optional<std::string> id;
};
struct SubscribeParameterUpdates {
    std::vector<std::string> names;  ///< empty: all known
};
struct UnsubscribeParameterUpdates {
    std::vector<std::string> names;  ///< empty: all
};
struct SubscribeConnectionGraph {};
struct UnsubscribeConnectionGraph {};
struct FetchAsset {
    std::string uri;
    std::uint32_t request_id = 0;
};
/// Binary 0x01. `payload` views the decoded message's bytes.
struct ClientMessageData {
    std::uint32_t channel_id = 0;
    std::string_view payload;
};
/// Binary 0x02. `payload` views the decoded message's bytes.
struct ServiceCallRequest {
    std::uint32_t service_id = 0;
    std::uint32_t call_id = 0;
    std::string encoding;
    std::string_view payload;
};

using ClientMessage = std::variant<Subscribe, Unsubscribe, ClientAdvertise, ClientUnadvertise, GetParameters, SetParameters,
                                   SubscribeParameterUpdates, UnsubscribeParameterUpdates, SubscribeConnectionGraph,
                                   UnsubscribeConnectionGraph, FetchAsset, ClientMessageData, ServiceCallRequest>;

/// A text message. Errors (the message says what is wrong, for a status reply): ProtocolError
/// (not JSON, not an object, no or unknown `op`, a field missing or of the wrong type, a number out
/// of uint32 range), BufferLimitViolation (over max_text_bytes, max_items, max_name_bytes, …).
Result<ClientMessage> decode_text(std::string_view text, const DecodeLimits& limits = {});
/// A binary message; the result's payload views `bytes`. Errors as decode_text (unknown opcode,
/// truncated header, encoding length past the end).
Result<ClientMessage> decode_binary(std::string_view bytes, const DecodeLimits& limits = {});

/// The `op` (text) or "binary 0xNN" of a message, for logs and status texts.
std::string_view client_message_name(const ClientMessage& m) noexcept;

}  // namespace rr::foxglove
