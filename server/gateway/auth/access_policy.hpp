// Per-role, per-device, per-member permissions of the gateway's own users (`auth: gateway` mode;
// docs/security.md "Gateway users and permissions").
//
// A role is a list of rules; a rule names devices and members (patterns where `*` matches any run of
// characters, everything else literally) and the operations it allows:
//   read   property get, wire InValue (receiving wire values) and peek, memory read, event and pipe receive
//   write  property set, wire OutValue (sending wire values) and poke, memory write, pipe send
//   call   functions, generator functions (and their next/close/abort), callbacks
//   lock   object locks and monitor locks (RequestObjectLock, RequestClientObjectLock, ReleaseObjectLock,
//          ReleaseClientObjectLock, MonitorEnter, MonitorContinueEnter, MonitorExit: mirror_access.hpp
//          is_lock_operation); for `lock` a rule's members name objects
//          (object_key: the relative service path, "" for the root object), as a lock covers an object
//   record starting, stopping and seeing the files of the device's recordings (asked with member `*`:
//          a rule's `members` must match `*`, i.e. be `*` or left out; docs/recording.md)
// A member of the device's root object is named by its member name (`Drive`); a member of an object
// below the root by `<relative service path>.<member>` (`Webcams[0].Capture`), the path in RR's
// encoding as the JSON API's `object` parameter normalises it. Rules only allow: an operation is
// permitted when any rule of any of the principal's roles allows it, and denied otherwise (deny by
// default). Thread-safe once built (const after construction).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace rr::server::gateway::auth {

enum class Operation { read, write, call, lock, record };

/// "read", "write", "call", "lock", "record".
std::string_view operation_name(Operation op) noexcept;

struct AccessRule {
    std::vector<std::string> devices;  ///< patterns
    std::vector<std::string> members;  ///< patterns
    bool read = false, write = false, call = false, lock = false, record = false;

    bool allows(Operation op) const noexcept;
};

class AccessPolicy {
public:
    void add_role(std::string role, std::vector<AccessRule> rules);
    bool has_role(std::string_view role) const;
    std::vector<std::string> role_names() const;

    /// Whether any rule of any role in `roles` allows `op` on `member_key` of `device`. Unknown roles
    /// allow nothing.
    bool allows(const std::vector<std::string>& roles, std::string_view device, std::string_view member_key,
                Operation op) const;

    /// `*` matches any run of characters (also none, also '.' and brackets); every other character
    /// matches itself.
    static bool glob_match(std::string_view pattern, std::string_view text) noexcept;

private:
    std::map<std::string, std::vector<AccessRule>, std::less<>> roles_;
};

/// The member key of `member` on the object at relative service path `object` ("" = the root).
std::string member_key(std::string_view object, std::string_view member);

/// How a refusal names what was asked for: `<member key>` for read, write and call; for lock
/// `the root object` or `object <relative service path>` (the key of Operation::lock is an object's).
std::string refused_target(std::string_view key, Operation op);

/// Who is asking: a user of the password file, a bearer token, a JWT subject. Immutable.
struct Principal {
    std::string name;
    std::vector<std::string> roles;
    std::string via;  ///< "password", "token", "jwt", "session"
    std::shared_ptr<const AccessPolicy> policy;

    bool allows(std::string_view device, std::string_view member_key, Operation op) const {
        return policy && policy->allows(roles, device, member_key, op);
    }
    /// Adding devices while running (POST /api/discovered/add) changes the gateway for everyone: it
    /// takes rules that allow read, write and call on every member of every device (devices and
    /// members "*" or left out, as the `operator` role of gateway-config/auth.yaml).
    bool may_add_devices() const {
        return allows("*", "*", Operation::read) && allows("*", "*", Operation::write) && allows("*", "*", Operation::call);
    }
    /// Whether the privilege column of the user's password file line (a token's or JWT's roles) lists
    /// `privilege`: `objectlock`, `objectlockoverride` (docs/security.md).
    bool has_privilege(std::string_view privilege) const {
        for (const auto& r : roles)
            if (r == privilege) return true;
        return false;
    }
    /// The user name the principal's RR sessions carry: the user's own name for a password login,
    /// `<name>@token` / `<name>@jwt` for a token or JWT (so a token never passes for a password user).
    std::string rr_user_name() const { return via == "password" ? name : name + "@" + via; }
};

}  // namespace rr::server::gateway::auth
