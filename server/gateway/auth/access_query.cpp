#include "server/gateway/auth/access_query.hpp"

namespace rr::server::gateway::auth {

std::vector<Operation> allowed_operations(const Principal* who, std::string_view device, std::string_view member_key) {
    std::vector<Operation> out;
    if (!who) return out;
    for (auto op : {Operation::read, Operation::write, Operation::call})
        if (who->allows(device, member_key, op)) out.push_back(op);
    return out;
}

bool may_lock(const Principal* who, std::string_view device, std::string_view object_key) {
    return who && who->allows(device, object_key, Operation::lock);
}

Result<PrincipalPtr> principal_for_device_user(const GatewayAuth& auth, const Principal& caller, std::string_view device_user) {
    const std::string own = caller.rr_user_name();
    if (device_user != own)
        return fail(MessageErrorType::PermissionDenied,
                    "device_user \"" + std::string(device_user) + "\" is not you (" + own +
                        "): the gateway tells a user only about its own roles; log in to the gateway as that user to ask");
    return auth.principal_for_user(device_user);
}

}  // namespace rr::server::gateway::auth
