// What the service side of a connection (ServiceSession) asks of the node that hosts it: the services
// registered on the node, as far as the session protocol needs them (wire.md §6.4: GetServiceDesc,
// ObjectTypeName, ConnectClient(Combined), GetServiceAttributes, AuthenticateUser), and endpoint ids.
// Member requests do not go through here: ServiceSession hands them to its host as events.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"
#include "base/message/message.hpp"

namespace rr {

/// Root and implemented types of an object, answering ObjectTypeName.
struct ObjectTypeInfo {
    std::string object_type;              ///< qualified, e.g. "experimental.create.Create"
    std::vector<std::string> implements;  ///< qualified
};

/// A service as the session protocol sees it. Implementations must be thread-safe: several
/// connections ask at once.
class HostedService {
public:
    virtual ~HostedService() = default;

    virtual const std::string& name() const = 0;
    /// Definition texts: the root object's service definition first, then every definition it imports,
    /// transitively (what ConnectClientCombined returns as `servicedefs`).
    virtual std::vector<std::string> service_definitions() const = 0;
    /// Definition text of one service definition by name (GetServiceDesc with ServiceType).
    virtual std::optional<std::string> service_definition(std::string_view service_type) const = 0;
    virtual ObjectTypeInfo root_type() const = 0;
    /// `attributes`: a map{string} element of varvalues (may be an empty map; the default).
    virtual MessageElement attributes() const;

    /// Whether a session must authenticate before member requests (CORE `requirevaliduser`,
    /// wire.md §12), and the check itself (username + `credentials` element).
    /// Errors: AuthenticationError.
    virtual bool requires_authentication() const { return false; }
    virtual Result<void> authenticate(const std::string& username, const MessageElement* credentials) {
        return fail(MessageErrorType::AuthenticationError, "Authentication Failed");
    }
    /// authenticate() with the client's address as the transport reported it (ServiceSessionConfig::
    /// peer; "" when unknown), for services that rate-limit failed logins per address (the gateway).
    virtual Result<void> authenticate_from(const std::string& username, const MessageElement* credentials,
                                           std::string_view peer) {
        return authenticate(username, credentials);
    }
    /// A login the transport carried (ServiceSessionConfig::web_login: the Cookie header of an rr+ws
    /// upgrade from a browser that logged in to the gateway's web page): the user name the session
    /// gets, or AuthenticationError. Asked only when the client sends no username and credentials
    /// itself and requires_authentication() is true.
    virtual Result<std::string> authenticate_web(std::string_view web_login) {
        return fail(MessageErrorType::AuthenticationError, "Authentication Failed");
    }
    /// Whether the service implements object and monitor locks itself: then every lock session
    /// operation (RequestObjectLock, RequestClientObjectLock, ReleaseObjectLock, ReleaseClientObjectLock,
    /// MonitorEnter, MonitorContinueEnter, MonitorExit) reaches it as a ServiceRequest. Otherwise the
    /// session answers object locks InvalidOperation and monitor operations "OK" (nothing is locked).
    virtual bool handles_locks() const { return false; }
    /// Whether the service admits each new client session itself, and answers later: ConnectClient and
    /// ConnectClientCombined then produce a ServiceAdmission event (with the client's username and
    /// `credentials` element, if any) and are answered when the host calls
    /// ServiceSession::answer_admission(). requires_authentication() and authenticate() are not asked,
    /// and AuthenticateUser / LogoutUser reach the service as ServiceRequests (ClientSessionOpReq) like
    /// the lock operations. The gateway's `auth: passthrough` mirror: the device decides, on an
    /// upstream session of the client's own.
    virtual bool admits_sessions() const { return false; }
};

/// The node, as its connections see it. Thread-safe.
class ServiceHost {
public:
    virtual ~ServiceHost() = default;
    /// A registered service by name (the node's service index included), or nullptr.
    virtual std::shared_ptr<HostedService> hosted_service(std::string_view name) const = 0;
    /// A fresh, non-zero endpoint id unused in this node (core has no RNG: the host chooses).
    virtual std::uint32_t allocate_endpoint() = 0;
    virtual void release_endpoint(std::uint32_t endpoint) = 0;
};

}  // namespace rr
