// GET /api/devices/{name}/access (docs/json-api.md "Access"): which members of a device's root object
// the caller's gateway roles allow to read, write and call, so that a page can hide the controls a
// user may not use. The gateway's refusal of a request stays the rule; this only tells beforehand,
// with the same policy calls (auth/access_query.hpp).
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "server/gateway/json_api.hpp"

namespace rr::server::gateway {

/// The answer for `caller` (nullptr only while logins are off):
///   logins on:  {"device", "auth": true, "user": caller's name, "roles": [roles evaluated],
///                "device_user": name or null, "members": {"<member>": ["read", "write", "call"]…},
///                "lock": bool, "record": whether the roles give the `record` right on the device
///                (its recordings)}
///               every member of the root object (names as in its service definition), each with the
///               operations allowed (in that order; [] when none); `lock`: whether the roles allow
///               object and monitor locks on the root object (auth::may_lock); `members` ("a,b,c") restricts the
///               answer to those names. `device_user` (auth: passthrough devices only) evaluates the
///               roles an RR session logged in to the device as that user gets, which the gateway
///               tells only for the caller's own user name (auth::principal_for_device_user).
///   logins off: {"device", "auth": false, "user": null, "members": null, "lock": null, "record": true}
///               (the gateway checks nothing; anyone may record, inside the recordings root).
/// Errors: 404 unknown device; 400 an unknown or empty member name in `members`, `device_user` empty or
/// on a device that is not `auth: passthrough`; 403 `device_user` not the caller's own name; 401 no
/// caller while logins are on; 503 the device has not connected yet (no definitions to list); 502
/// unusable definitions.
ApiResult member_access(const JsonApi& api, std::string_view device, const auth::PrincipalPtr& caller,
                        const std::optional<std::string>& members, const std::optional<std::string>& device_user);

}  // namespace rr::server::gateway
