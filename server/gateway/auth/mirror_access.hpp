// Permission checks of the gateway's mirror of a device for native RR clients (`auth: gateway`):
// which operation a client's request needs (access_policy.hpp), and whether a session's user may do it.
// Member keys come from the downstream service path: `<device>` → the member's name,
// `<device>.<relative path>` → `<relative path>.<member>`.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "base/error/rr_error.hpp"
#include "base/message/message.hpp"
#include "server/gateway/auth/gateway_auth.hpp"
#include "server/node/service.hpp"

namespace rr::server::gateway::auth {

/// The operation a request from a client needs; nullopt for entries that need none (PipePacketRet
/// acknowledgements, disconnects, and anything else that is not a member operation).
///   read:  PropertyGetReq, WireConnectReq (receives InValue), WirePeekInValueReq, WirePeekOutValueReq,
///          MemoryRead, MemoryGetParam, PipeConnectReq (receives packets)
///   write: PropertySetReq, WirePacket (the client's OutValue), WirePokeOutValueReq, MemoryWrite,
///          PipePacket (sending)
///   call:  FunctionCallReq, GeneratorNextReq
/// (MirrorAccess::check opens a pipe endpoint or wire connection for `read` or `write`.)
/// ClientSessionOpReq is not a member operation: see is_lock_operation.
std::optional<Operation> operation_for_request(MessageEntryType type) noexcept;

/// Whether the ClientSessionOpReq member name `op` is a lock operation, which needs Operation::lock on
/// the object at its service path: RequestObjectLock, RequestClientObjectLock, ReleaseObjectLock,
/// ReleaseClientObjectLock, MonitorEnter, MonitorContinueEnter, MonitorExit.
bool is_lock_operation(std::string_view op) noexcept;

/// `<relative path>.<member>` for a downstream service path of device service `service`
/// (`create` → `Drive`; `create.Webcams[0]` → `Webcams[0].Capture`).
std::string member_key_for_path(std::string_view service, std::string_view service_path, std::string_view member);

/// The object key (Operation::lock) of a downstream service path: the relative path below the device
/// service (`create.Webcams[0]` → `Webcams[0]`), "" for the root object.
std::string object_key_for_path(std::string_view service, std::string_view service_path);

class MirrorAccess {
public:
    MirrorAccess() = default;
    MirrorAccess(std::shared_ptr<GatewayAuth> auth, std::string device) : auth_(std::move(auth)), device_(std::move(device)) {}

    /// Logins and checks are on.
    bool active() const noexcept { return auth_ && auth_->enabled(); }
    const std::shared_ptr<GatewayAuth>& auth() const noexcept { return auth_; }

    /// Whether `session`'s user may do `op` on `member` of the object at downstream `service_path`.
    bool may(const SessionRef& session, std::string_view service_path, std::string_view member, Operation op) const;
    /// The check for a request from a client: nothing when allowed, else PermissionDenied
    /// "<user> may not <op> <member key> of <device>" (counted in LoginCounters::denied). A lock
    /// operation (is_lock_operation) needs `lock` on its object: "user bob may not lock the root object
    /// of arm", "… may not lock object gripper of arm".
    std::optional<RRError> check(const SessionRef& session, const MessageEntry& entry) const;

private:
    std::shared_ptr<GatewayAuth> auth_;
    std::string device_;
};

}  // namespace rr::server::gateway::auth
