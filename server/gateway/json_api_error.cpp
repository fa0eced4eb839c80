#include "server/gateway/json_api_error.hpp"

namespace rr::server::gateway {

ApiError api_error(unsigned status, MessageErrorType type, std::string message) {
    return ApiError{status, std::string(error_name(type)), std::move(message)};
}

ApiError bad_request(std::string message) { return api_error(400, MessageErrorType::InvalidArgument, std::move(message)); }

ApiError device_error(const RRError& error) {
    unsigned status = 502;
    switch (error.type) {
        case MessageErrorType::ServiceNotFound:
        case MessageErrorType::ObjectNotFound:
        case MessageErrorType::MemberNotFound: status = 404; break;
        case MessageErrorType::ReadOnlyMember:
        case MessageErrorType::WriteOnlyMember: status = 405; break;
        case MessageErrorType::ObjectLockedError: status = 409; break;  // as a lock held at the gateway
        case MessageErrorType::ConnectionError: status = 503; break;
        case MessageErrorType::RequestTimeout: status = 504; break;
        default: break;
    }
    std::string name = error.name;
    if (name.empty()) name = std::string(error_name(error.type));
    if (name.empty()) name = "RobotRaconteur.UnknownError";
    return ApiError{status, std::move(name), error.message};
}

ApiError value_error(const RRError& error, std::string_view where) {
    std::string name = error.name.empty() ? std::string(error_name(error.type)) : error.name;
    if (name.empty()) name = "RobotRaconteur.DataTypeError";
    std::string message = std::string(where) + ": " + error.message;
    return ApiError{400, std::move(name), std::move(message)};
}

nlohmann::json error_object(const ApiError& error) {
    return nlohmann::json{{"name", error.name}, {"message", error.message}};
}

std::string json_text(const nlohmann::json& j) { return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace); }

}  // namespace rr::server::gateway
