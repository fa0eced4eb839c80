// The Service a DeviceMirror registers on the gateway node: the downstream half of the mirror (see
// device_mirror.hpp for the forwarding rules). Thread-safe: called from downstream connection strands
// and from the upstream client's strand.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <tuple>

#include "server/gateway/auth/mirror_access.hpp"
#include "server/gateway/device_mirror.hpp"
#include "server/gateway/device_types.hpp"
#include "server/gateway/motion_guard.hpp"
#include "server/gateway/upstream_subscriptions.hpp"
#include "server/service/service_locks.hpp"

namespace rr::server::gateway {

class MirrorService : public Service, public std::enable_shared_from_this<MirrorService> {
public:
    /// `counters` are the device's (DeviceMirror::counters()): this side counts requests, events, wire
    /// and pipe packets and their drops into them.
    MirrorService(std::weak_ptr<DeviceMirror> mirror, std::shared_ptr<DeviceCounters> counters, std::string name,
                  std::string upstream_service);
    /// Called (from any thread) whenever the lock holders change: they are part of the device's status.
    /// Set once, before registration.
    void set_locks_listener(std::function<void()> listener);

    // Service
    const std::string& name() const override { return name_; }
    std::vector<std::string> service_definitions() const override;
    std::optional<std::string> service_definition(std::string_view service_type) const override;
    ObjectTypeInfo root_type() const override;
    MessageElement attributes() const override;
    void object_type(const SessionRef& session, const std::string& path,
                     std::function<void(Result<ObjectTypeInfo>)> done) override;
    void on_session_open(const SessionRef& session) override;
    void on_session_close(const SessionRef& session) override;
    /// auth: passthrough: the client's DisconnectClient is answered once the device has answered the
    /// DisconnectClient of the client's upstream session (its locks are gone there by then).
    void end_session(const SessionRef& session, std::function<void()> ended) override;
    void handle_entry(const SessionRef& session, MessageEntry&& entry, Responder responder) override;
    /// Lock operations reach the mirror: forwarded on the client's own session (passthrough), or
    /// decided by the gateway's own lock table (shared; docs/security.md "auth: shared").
    bool handles_locks() const override { return true; }
    void attach(boost::asio::io_context& io) override { locks_->attach(io); }
    bool admits_sessions() const override { return passthrough_ != nullptr; }
    void admit_session(std::uint32_t endpoint, std::string username, std::optional<MessageElement> credentials,
                       std::function<void(Result<void>)> done) override;
    void abandon_admission(std::uint32_t endpoint) override;

    /// The device's motion guard (set once, by DeviceMirror::create, before registration): motion
    /// requests are admitted by it, stops pass every lock, a session's going away ends its motions.
    void set_motion_guard(std::shared_ptr<MotionGuard> guard) { motion_ = std::move(guard); }
    /// How the motion guard sees a native client's session.
    static MotionClient motion_client(const SessionRef& session, bool passthrough);

    /// auth: passthrough (set once, by DeviceMirror::create, before registration).
    void set_passthrough(std::shared_ptr<PassthroughSessions> p) {
        passthrough_ = std::move(p);
        check_passthrough_deliveries();
    }
    const std::shared_ptr<PassthroughSessions>& passthrough() const noexcept { return passthrough_; }
    void stop_passthrough();
    // Logins with the gateway's own users (`auth: gateway`; server/gateway/auth/), when set_access()
    // gave it users.
    bool requires_authentication() const override;
    Result<void> authenticate(const std::string& username, const MessageElement* credentials) override;
    Result<void> authenticate_from(const std::string& username, const MessageElement* credentials,
                                   std::string_view peer) override;
    Result<std::string> authenticate_web(std::string_view web_login) override;
    /// The gateway's users and permissions for this device's clients (docs/security.md): logins and
    /// per-member checks of every request (PermissionDenied), events, pipe packets and callbacks only
    /// to sessions allowed to receive them. Set before the service is registered (not thread-safe).
    void set_access(auth::MirrorAccess access) {
        access_ = std::move(access);
        check_passthrough_deliveries();
    }

    // Upstream side, called by DeviceMirror.
    void on_upstream_entry(MessageEntry&& entry);
    void on_upstream_connected(const std::shared_ptr<RawClient>& client);
    void on_upstream_lost(const RRError& error);
    std::size_t session_count() const;

    /// Gateway-internal subscribers (JSON API), keyed by id. A wire subscriber's `on_entry` gets the
    /// WirePackets and, when the device closes the wire, its WireClosed (the subscription is gone then).
    std::uint64_t add_internal_subscriber(std::string path, std::string member, bool is_wire,
                                          std::function<void(const SharedEntryPtr&)> on_entry,
                                          std::function<void(Result<void>)> done);
    void remove_internal_subscriber(std::uint64_t id);

    /// The gateway's own pipe endpoints on the device's shared session (the JSON API's pipe
    /// subscriptions), paths in gateway naming: their packets and PipeClosed are taken out of the
    /// device's traffic before the downstream clients', they close when the device connection is lost
    /// and work again once it is back; packets sent on them count as the device's pipe_packets.
    const std::shared_ptr<SessionEndpoints>& shared_endpoints() const noexcept { return shared_endpoints_; }

    std::string to_upstream(std::string_view path) const;
    std::string to_downstream(std::string_view path) const;

    /// Locks held at the gateway (auth: shared): a JSON API request to the object at `path` (gateway
    /// naming) made by gateway user `user` ("" without logins), which has no session of its own: it
    /// passes `user`'s user locks and nothing else (no client lock, no monitor). `nolock`: the member
    /// passes object locks (passes_object_locks). Always passes on a passthrough device, whose locks
    /// the device keeps. Errors: ObjectLockedError, InvalidOperation (monitor), as for a native client.
    Result<void> check_api_request(const std::string& path, const std::string& user, bool nolock);
    /// The locks and monitors held at the gateway (auth: shared), paths in gateway naming.
    std::vector<DeviceLockInfo> gateway_locks() const;

private:
    using MemberKey = UpstreamSubscriptions::MemberKey;  // downstream service path, member
    struct PipeLink {
        SessionRef session;
        std::string path, member;
        std::int32_t downstream_index = 0;
        std::int32_t upstream_index = 0;
    };

    /// Told the device's answer to a forwarded request (the motion guard follows its motions).
    using ReplyObserver = std::function<void(const Result<MessageEntry>&)>;

    std::shared_ptr<RawClient> client() const;
    void forward(const SessionRef& session, MessageEntry&& entry, Responder responder, ReplyObserver observe = {});
    void wire_connect(const SessionRef& session, MessageEntry&& entry, Responder responder);
    void wire_disconnect(const SessionRef& session, MessageEntry&& entry, Responder responder);
    /// Connects the wire upstream unless it is connected or being connected (or fails its waiting
    /// subscriptions when the device is away).
    void ensure_upstream_wire(const MemberKey& key);
    void send_newest(const MemberKey& key, const SessionRef& session, const SharedEntryPtr& newest);
    /// WireDisconnectReq to the device for wires nobody here subscribes to any more.
    void disconnect_upstream_wires(std::vector<MemberKey> keys);
    static void deliver(const UpstreamSubscriptions::InternalSubs& subs, const SharedEntryPtr& entry);
    void pipe_connect(const SessionRef& session, MessageEntry&& entry, Responder responder);
    void pipe_disconnect(const SessionRef& session, MessageEntry&& entry, Responder responder);
    void pipe_packets_from_client(const SessionRef& session, MessageEntry&& entry);
    void pipe_packets_from_device(MessageEntry&& entry);
    void callback_from_device(MessageEntry&& entry);
    void fan_out(MessageEntry&& entry);
    void drop_session_state(std::uint32_t endpoint);
    /// auth: shared: a client's request after the roles (and, for member requests, the locks).
    void dispatch_shared(const SessionRef& session, MessageEntry&& entry, Responder responder, ReplyObserver observe = {});
    /// auth: shared: RequestObjectLock … MonitorExit, decided by locks_.
    void lock_op(const SessionRef& session, MessageEntry&& entry, Responder responder);
    /// auth: shared: a member request an object lock refused: passes when the device's definition
    /// marks the member [nolock] / [nolockread] (the object's type asked of the device when below the root).
    void recheck_nolock(const SessionRef& session, MessageEntry&& entry, Responder responder, ReplyObserver observe);
    /// The robdef modifiers of `member` of object type `type` (empty when unknown).
    std::vector<std::string> member_modifiers(const std::string& type, const std::string& member);
    /// objectlock / objectlockoverride of a gateway user (none without gateway.auth).
    ServiceLocks::Privileges privileges(const std::string& user) const;

    std::weak_ptr<DeviceMirror> mirror_;
    const std::shared_ptr<DeviceCounters> counters_;
    std::shared_ptr<PassthroughSessions> passthrough_;
    std::shared_ptr<MotionGuard> motion_;
    // auth: shared: the object and monitor locks of this device's gateway clients, held here (the
    // device sees one session); unused on a passthrough device.
    const std::shared_ptr<ServiceLocks> locks_ = std::make_shared<ServiceLocks>();
    auth::MirrorAccess access_;
    /// With gateway.auth on a passthrough device: the roles apply to what the device sends each client
    /// (events, wire and pipe packets: read; callback calls: call), as on a shared device.
    void check_passthrough_deliveries();
    const std::string name_;
    const std::string upstream_service_;

    mutable std::mutex mutex_;
    std::vector<SessionRef> sessions_;
    std::uint32_t last_caller_ = 0;  // endpoint of the client that most recently called into the device
    UpstreamSubscriptions subscriptions_;  // wires and events: who gets what, the upstream wire connections
    std::map<std::tuple<std::string, std::string, std::int32_t>, PipeLink> pipes_by_upstream_;
    std::map<std::tuple<std::uint32_t, std::string, std::string, std::int32_t>, std::int32_t> pipes_by_downstream_;
    std::set<std::pair<std::uint32_t, std::int32_t>> generators_;  // (endpoint, generator index)
    std::shared_ptr<SessionEndpoints> shared_endpoints_;  // set once, in the constructor
    std::shared_ptr<const DeviceTypes> types_;  // the device's definitions parsed, for member modifiers
};

}  // namespace rr::server::gateway
