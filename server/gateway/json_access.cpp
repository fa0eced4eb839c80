#include "server/gateway/json_access.hpp"

#include <set>

#include "server/gateway/auth/access_query.hpp"

namespace rr::server::gateway {

namespace {

// "a,b,c" → the names, in that order, each once. Errors: an empty name (",", "a,,b", "").
Result<std::vector<std::string>> member_list(std::string_view csv) {
    std::vector<std::string> out;
    std::set<std::string, std::less<>> seen;
    while (true) {
        const auto comma = csv.find(',');
        const std::string_view name = csv.substr(0, comma);
        if (name.empty())
            return fail(MessageErrorType::InvalidArgument,
                        "members must list member names separated by commas (\"members=jog_freespace,enable\"); it has an empty name");
        if (seen.insert(std::string(name)).second) out.emplace_back(name);
        if (comma == std::string_view::npos) break;
        csv.remove_prefix(comma + 1);
    }
    return out;
}

nlohmann::json operation_names(const std::vector<auth::Operation>& ops) {
    auto j = nlohmann::json::array();
    for (auto op : ops) j.push_back(std::string(auth::operation_name(op)));
    return j;
}

}  // namespace

ApiResult member_access(const JsonApi& api, std::string_view name, const auth::PrincipalPtr& caller,
                        const std::optional<std::string>& members, const std::optional<std::string>& device_user) {
    auto d = api.find_device(name);
    if (!d) return ApiResult::failed(api_error(404, MessageErrorType::ServiceNotFound, "no device named \"" + std::string(name) + "\""));
    if (device_user) {
        if (d->config().auth != DeviceAuth::passthrough)
            return ApiResult::failed(bad_request("device_user applies to auth: passthrough devices only; device \"" + std::string(name) +
                                                 "\" is auth: " + std::string(device_auth_name(d->config().auth)) +
                                                 ", where every request acts as your gateway user"));
        if (device_user->empty()) return ApiResult::failed(bad_request("device_user must name the user the page logged in to the device as"));
    }
    const auto& a = api.auth();
    if (!a || !a->enabled())
        return ApiResult::ok({{"device", name}, {"auth", false}, {"user", nullptr}, {"members", nullptr},
                              {"lock", nullptr}, {"record", true}});
    if (!caller) return ApiResult::failed(api_error(401, MessageErrorType::AuthenticationError, "login required"));

    // Whose roles: the caller's (REST and JSON WebSocket requests), or those an RR session logged in to
    // the passthrough device as `device_user` gets (MirrorAccess), for the caller's own name only.
    auth::PrincipalPtr who = caller;
    if (device_user) {
        auto p = auth::principal_for_device_user(*a, *caller, *device_user);
        if (!p) return ApiResult::failed(api_error(403, MessageErrorType::PermissionDenied, p.error().message));
        who = *p;
    }

    ApiError unusable;
    auto types = api.types_for(*d, &unusable);
    if (!types) return ApiResult::failed(std::move(unusable));
    const std::string root_type = d->object_type();
    auto root = types->find_object(root_type);
    if (!root)
        return ApiResult::failed(api_error(503, MessageErrorType::ConnectionError, "device \"" + std::string(name) + "\" has not connected yet"));

    std::vector<std::string> names;
    if (members) {
        auto wanted = member_list(*members);
        if (!wanted) return ApiResult::failed(bad_request(wanted.error().message));
        for (auto& m : *wanted) {
            bool known = false;
            for (const auto& def : root->entry->members) known |= def.name == m;
            if (!known)
                return ApiResult::failed(bad_request("device \"" + std::string(name) + "\" has no member \"" + m + "\" on its root object (" +
                                                     root_type + ")"));
            names.push_back(std::move(m));
        }
    } else {
        for (const auto& def : root->entry->members) names.push_back(def.name);
    }

    auto out = nlohmann::json::object();
    for (const auto& m : names) out[m] = operation_names(auth::allowed_operations(who.get(), name, auth::member_key("", m)));
    return ApiResult::ok({{"device", name},
                          {"auth", true},
                          {"user", caller->name},
                          {"roles", who ? nlohmann::json(who->roles) : nlohmann::json::array()},
                          {"device_user", device_user ? nlohmann::json(*device_user) : nlohmann::json(nullptr)},
                          {"members", std::move(out)},
                          {"lock", auth::may_lock(who.get(), name, "")},
                          {"record", who != nullptr && who->allows(name, "*", auth::Operation::record)}});
}

}  // namespace rr::server::gateway
