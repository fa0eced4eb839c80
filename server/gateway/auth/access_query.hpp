// Asking the policy beforehand (GET /api/devices/{name}/access, docs/security.md "Asking what a user
// may do"): which operations a principal's roles allow on a member, and whose roles a page may ask
// about on an `auth: passthrough` device. The answers come from Principal::allows and
// GatewayAuth::principal_for_user, the very calls that enforce requests (JsonApi::check_access,
// MirrorAccess), so an answer cannot disagree with what the gateway then does.
#pragma once

#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"
#include "server/gateway/auth/gateway_auth.hpp"

namespace rr::server::gateway::auth {

/// The operations `who` may do on `member_key` of `device`, in the order read, write, call (empty
/// when none, and for a null principal: an unknown user may do nothing).
std::vector<Operation> allowed_operations(const Principal* who, std::string_view device, std::string_view member_key);

/// Whether `who` may take object and monitor locks on the object at relative service path `object_key`
/// of `device` ("" = the root object; false for a null principal).
bool may_lock(const Principal* who, std::string_view device, std::string_view object_key);

/// The principal whose roles apply to an RR session that logged in to an `auth: passthrough` device as
/// `device_user` (MirrorAccess: principal_for_user of the name the device accepted), asked by `caller`.
/// The gateway answers only for the caller's own name (Principal::rr_user_name): answering for any
/// name would tell anyone which names are gateway users and what their roles allow, which only a
/// person who knows that user's device password could find out by trying. The result may be nullptr:
/// the name has no roles at the gateway (such a session may do nothing). Errors: PermissionDenied
/// "device_user "bob" is not you (alice): …" for another name.
Result<PrincipalPtr> principal_for_device_user(const GatewayAuth& auth, const Principal& caller, std::string_view device_user);

}  // namespace rr::server::gateway::auth
