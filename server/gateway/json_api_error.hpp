// Errors of the JSON API (docs/json-api.md §Errors): an RR error name and message, plus the HTTP status
// that REST answers with. The WebSocket API sends the same name and message without the status.
//
//   404  unknown device, object or member, or a member of another kind than the request needs
//        (RobotRaconteur.ServiceNotFound / ObjectNotFound / MemberNotFound)
//   400  bad JSON, bad arguments, a value that does not fit the robdef type (the JSON mapping's error)
//   405  a read-only / write-only member used the other way (ReadOnlyMember / WriteOnlyMember)
//   503  the device is not connected (ConnectionError)
//   504  the device did not answer in time (RequestTimeout)
//   502  any other error the device reported, under the device's own error name
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "base/error/rr_error.hpp"

namespace rr::server::gateway {

struct ApiError {
    unsigned status = 500;  ///< HTTP status code
    std::string name;       ///< `RobotRaconteur.X`, or the device's own error name
    std::string message;
};

/// An error the gateway found itself (bad input, unknown names): `type` gives the standard name.
ApiError api_error(unsigned status, MessageErrorType type, std::string message);
/// 400 InvalidArgument: a request the client got wrong (a missing or mistyped field, an unknown op).
ApiError bad_request(std::string message);

/// An error from the device or from the device connection, mapped to its HTTP status (see above).
ApiError device_error(const RRError& error);

/// An error the JSON mapping (core/json) found in a client's value: 400 with the mapping's error name.
ApiError value_error(const RRError& error, std::string_view where);

/// `{"name": …, "message": …}`.
nlohmann::json error_object(const ApiError& error);

/// The outcome of one API operation: a JSON result or an error.
struct ApiResult {
    nlohmann::json value;
    std::optional<ApiError> error;

    static ApiResult ok(nlohmann::json v) { return ApiResult{std::move(v), std::nullopt}; }
    static ApiResult failed(ApiError e) { return ApiResult{nullptr, std::move(e)}; }
    explicit operator bool() const noexcept { return !error; }
};

/// JSON text for the wire: invalid UTF-8 in strings (device error messages, names) is replaced by
/// U+FFFD instead of throwing.
std::string json_text(const nlohmann::json& j);

}  // namespace rr::server::gateway
