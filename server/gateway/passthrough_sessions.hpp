// `auth: passthrough` for one device (docs/security.md "Logins and locks through the gateway"): every
// downstream native RR client session of the device's mirror gets an upstream session to the device of
// its own, opened with the username and `credentials` element the client sent (or none), so the
// device's own users, privileges, object locks and monitor locks apply exactly as if the client had
// connected directly. The upstream session is opened when the client connects (its connect waits for
// the device's answer, and gets the device's own error when refused) and closed when the client goes;
// a client's DisconnectClient is answered once the device has answered the upstream session's own
// (MirrorService::end_session), so the locks of the session are gone on the device when the client's
// disconnect returns, as with a direct connection.
//
// Forwarding is one to one: every member request, session operation (AuthenticateUser, LogoutUser,
// RequestObjectLock, RequestClientObjectLock, ReleaseObjectLock, ReleaseClientObjectLock, MonitorEnter,
// MonitorContinueEnter, MonitorExit) and packet of the client goes to its own upstream session with
// the service path re-addressed (RequestIDs are the upstream session's), and everything the device
// sends on that session (replies, events, wire and pipe packets, PipeClosed, WireClosed, callback
// requests) goes back to that client only; pipe and wire indices pass unchanged, since both sides are
// one session each.
//
// Lock bookkeeping: locks and monitors taken through the gateway (an OK answer of the device) are
// remembered for the JSON API and the dashboard, with the user who took them; released ones and those
// of closed sessions are forgotten (a user lock when the last passthrough session of its user closes,
// as on the device). Locks taken by the device's other clients are not known to the gateway.
//
// Thread-safe: called from downstream connection strands and upstream client strands.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>

#include "base/names/connection_url.hpp"
#include "server/client/raw_client.hpp"
#include "server/node/service.hpp"

namespace rr::server::gateway {

struct DeviceCounters;

/// A lock on a device object known to the gateway (taken through it).
struct DeviceLockInfo {
    std::string path;      ///< service path in gateway naming (the device's name as service name)
    std::string username;  ///< who took it ("" for an anonymous monitor)
    std::string kind;      ///< "user" (RequestObjectLock), "client" (RequestClientObjectLock), "monitor"
    std::uint32_t endpoint = 0;  ///< the downstream session that took it
};

class PassthroughSessions : public std::enable_shared_from_this<PassthroughSessions> {
public:
    struct Settings {
        std::string device_name;       ///< the service name on the gateway
        std::string upstream_service;  ///< the device's service name
        ConnectionUrl url;             ///< the device
        RawClientOptions options;      ///< TLS, transports, node name; username/credentials set per client
        std::size_t max_sessions = 64; ///< upstream sessions at once (admissions beyond are refused)
        /// Called (without locks held, any thread) when sessions or known locks change.
        std::function<void()> on_change;
    };

    /// `counters`: the device's (may be empty; not kept alive by this object).
    PassthroughSessions(boost::asio::any_io_executor executor, Settings settings, std::weak_ptr<DeviceCounters> counters);
    ~PassthroughSessions();

    /// Opens the client's upstream session (Service::admit_session). Errors to `done`: the device's
    /// own (e.g. AuthenticationError "Invalid username or password"), ConnectionError when it cannot be
    /// reached, BufferLimitViolation "… passthrough session limit (N) reached" over max_sessions.
    void admit(std::uint32_t endpoint, std::string username, std::optional<MessageElement> credentials,
               std::function<void(Result<void>)> done);
    /// The admitted client's session is open: entries from the device may go to it now.
    void attach(const SessionRef& session);
    /// What a JSON API session (a `device_login` of docs/json-api.md, which has no RR session
    /// downstream) hears from the device. `on_entry` gets its events, wire and pipe packets, WireClosed
    /// and PipeClosed with paths in gateway naming (the JSON API's own subscriptions on that session:
    /// SessionEndpoints); `on_lost` once when the device ends the session. The device's callback
    /// requests on it are answered with InvalidOperation. Called without locks held.
    struct ApiHandlers {
        std::function<void(MessageEntry&&)> on_entry;
        std::function<void(const RRError&)> on_lost;
    };
    /// The admitted session serves a JSON API client; `on_lost` runs at once if it ended already.
    void attach_api(std::uint32_t endpoint, ApiHandlers handlers);
    /// An entry without a reply (WirePacket, PipePacket, PipePacketRet) on an attached JSON API
    /// session; paths in gateway naming. Errors: ConnectionError when the session is gone.
    Result<void> send(std::uint32_t endpoint, MessageEntry entry);
    /// Bytes waiting to be written to the device on that session (0 when it is gone).
    std::size_t queued_bytes(std::uint32_t endpoint) const;
    /// A request of an attached JSON API session, forwarded on its own upstream session; the service
    /// paths are in gateway naming both ways. Errors to `done`: ConnectionError when the session is
    /// gone (closed by the device or never admitted), and the device's own.
    void request(std::uint32_t endpoint, MessageEntry entry, std::function<void(Result<MessageEntry>)> done);
    /// The client went (or never took its admission): closes its upstream session (DisconnectClient;
    /// the device drops its client locks and monitors) and forgets its locks. `ended` (optional) is
    /// called once, from any thread or at once, when the upstream session has ended: the device answered
    /// the DisconnectClient (its locks are released by then), or 500 ms passed without an answer, or the
    /// connection closed; at once when the client had no upstream session (any more).
    void close(std::uint32_t endpoint, std::function<void()> ended = {});
    /// Closes every upstream session (the device mirror stops); admissions are refused until reopen().
    void close_all();
    void reopen();

    /// A request or packet from a client (Service::handle_entry). `observe` (optional) is told the
    /// device's answer first. `stop`: the request stops motion (docs/security.md "Motion safety"): when
    /// the device refuses it for a lock (ObjectLockedError, or a monitor held by another session), it is
    /// sent again on the session of a client that holds a lock taken through the gateway, so that no
    /// lock known here blocks a stop; the client gets that answer.
    void handle_entry(const SessionRef& session, MessageEntry&& entry, Responder responder,
                      std::function<void(const Result<MessageEntry>&)> observe = {}, bool stop = false);

    /// Whether a client's session may receive one of the device's entries (gateway.auth roles, checked
    /// packet by packet: docs/security.md): asked for events, wire and pipe packets (`read`) and
    /// callback calls (`call`), with the downstream service path. True: delivered. False: a packet or
    /// event is dropped (as on a shared device), a callback call is answered with PermissionDenied.
    using DeliveryCheck = std::function<bool(const SessionRef& session, const MessageEntry& entry)>;
    /// Sets the check (empty: everything is delivered). Thread-safe.
    void set_delivery_check(DeliveryCheck check);

    std::size_t session_count() const;
    std::vector<DeviceLockInfo> locks() const;

    /// The device refused a request for a lock (ObjectLockedError, or InvalidOperation "… monitor locked").
    static bool refused_by_lock(const MessageEntry& reply);
    /// A stop (paths in gateway naming) the device refused with `refused` for a lock: sent again on the
    /// session of a client (not `except`) that holds a lock on the root object taken through the
    /// gateway; `answer` gets that reply, or `refused` when no such session is open.
    void stop_as_lock_holder(std::uint32_t except, MessageEntry stop, std::function<void(Result<MessageEntry>)> answer,
                             Result<MessageEntry> refused);

private:
    struct Link {
        std::shared_ptr<RawClient> client;
        SessionRef session;
        std::string username;
        std::vector<MessageEntry> early;  // device entries that came before attach()
        bool attached = false;
        bool api = false;   // a JSON API session (attach_api): no downstream RR session
        std::shared_ptr<const ApiHandlers> api_handlers;
        bool lost = false;  // the device ended the upstream session
    };

    std::shared_ptr<RawClient> open_client(std::uint32_t endpoint) const;
    RRError session_gone() const;
    void forward(std::uint32_t endpoint, const std::shared_ptr<RawClient>& client, MessageEntry&& entry,
                 std::function<void(Result<MessageEntry>)> done);
    void from_device(std::uint32_t endpoint, MessageEntry&& entry);
    void deliver(const SessionRef& session, const std::shared_ptr<RawClient>& client, const std::shared_ptr<const DeliveryCheck>& check,
                 MessageEntry&& entry);
    void upstream_closed(std::uint32_t endpoint, const RRError& error);
    void note_lock_reply(std::uint32_t endpoint, const std::string& op, const std::string& path, const MessageEntry& reply);
    void forget_locks_of(std::uint32_t endpoint, const std::string& username);
    void changed() const {
        if (settings_.on_change) settings_.on_change();
    }
    std::string to_upstream(std::string_view path) const;
    std::string to_downstream(std::string_view path) const;

    boost::asio::any_io_executor executor_;
    const Settings settings_;
    std::weak_ptr<DeviceCounters> counters_;

    mutable std::mutex mutex_;
    std::map<std::uint32_t, Link> links_;       // admitted (or being admitted: client null)
    std::map<std::uint32_t, std::string> gone_;  // endpoints closed while connecting (value unused)
    std::vector<DeviceLockInfo> locks_;
    std::shared_ptr<const DeliveryCheck> delivery_check_;  // null: all delivered
    bool closed_ = false;
};

}  // namespace rr::server::gateway
