// ObjectService: a Service (service.hpp) made of ServiceObjects typed by robdef (service_object.hpp).
//
//   definitions     ConnectClientCombined `servicedefs` / GetServiceDesc: the root object's definition
//                   first, then its imports, transitively (ServiceTypes::texts_for); one by name.
//   object types    ObjectTypeName for any path (wire.md §6.5): the root, or `parent.member[index]…`
//                   resolved through the objref resolvers, with the object's `implements` (qualified).
//                   Resolved objects are kept per path (one object per path, shared by all clients, as
//                   CORE keeps its skels) until release_path(); unknown paths → ObjectNotFound.
//   member requests dispatched to the object at ServicePath and the member MemberName (§6.7); entry types
//                   no member handles → ProtocolError "Unknown request type" (as CORE).
//   generators      per-session table of open generators (generator.hpp).
//   attributes      optional map{string} of varvalues (GetServiceAttributes, connect replies).
//   authentication  optional user table (password_table.hpp): when set, every session must log in
//                   (ConnectClientCombined `username` + `credentials{password}` or AuthenticateUser)
//                   before member requests are accepted, and events skip sessions not logged in.
//   object locks    request_object_lock() from the service side, and RequestObjectLock, RequestClientObjectLock, ReleaseObjectLock and MonitorEnter /
//                   MonitorContinueEnter / MonitorExit with CORE's semantics (service_locks.hpp): object
//                   locks need a logged-in user with the `objectlock` or `objectlockoverride` privilege
//                   (PermissionDenied / ObjectLockedError otherwise); every member request (not pipe or
//                   wire packets) to a locked object from another user or session gets ObjectLockedError
//                   "Object locked by <user>", to a monitor-locked one InvalidOperation. A MonitorEnter
//                   that must wait is answered "Continue" after at most 5 s (the client then repeats
//                   MonitorContinueEnter) or "OK" as soon as the monitor is handed over. Locks go when
//                   their session (client lock) or their user's last session (user lock) closes.
//
// Threads: thread-safe. Requests run on the client's strand (see ServiceObject for handler rules).
#pragma once

#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <unordered_map>
#include <vector>

#include "server/service/service_locks.hpp"
#include "server/service/password_table.hpp"
#include "server/service/service_object.hpp"

namespace rr::server {

class ObjectService : public Service, public std::enable_shared_from_this<ObjectService> {
public:
    /// A service named `name` (`^[a-zA-Z][a-zA-Z0-9_]*$`) serving `root`, whose type must belong to `types`.
    /// Errors: InvalidArgument (bad name, root of another ServiceTypes), InvalidOperation (root already
    /// served by another service).
    static Result<std::shared_ptr<ObjectService>> create(std::string name, std::shared_ptr<ServiceObject> root);
    ~ObjectService() override;

    const std::shared_ptr<ServiceObject>& root() const noexcept { return root_; }
    const std::shared_ptr<const ServiceTypes>& types() const noexcept { return types_; }

    /// Service attributes (each value packed as a varvalue). Errors: packing errors (nothing changes).
    Result<void> set_attributes(MapString attributes);
    /// Requires every session to log in against `users` (an empty table turns authentication off).
    void set_users(PasswordTable users);

    /// Releases `path` and every path below it: the objects are forgotten (their pipe endpoints and wire
    /// connections at those paths are dropped) and every client gets ServicePathReleasedReq (1109) for
    /// `path`. The next request for the path resolves it again. Errors: InvalidArgument for the root
    /// path; ObjectNotFound when nothing is served at `path`.
    Result<void> release_path(const std::string& path);

    /// Locks the object at `path` and every object below it for user `username`, from the service
    /// side (CORE: ServerContext::RequestObjectLock; the official test service locks
    /// `RobotRaconteurTestService2.nolock_test` for "server"): requests from sessions of other users
    /// and anonymous sessions get ObjectLockedError, except to `[nolock]` members (and reads of
    /// `[nolockread]` ones). The path need not be resolved yet. Held until release_object_lock(), a
    /// client's ReleaseObjectLock with `objectlockoverride`, or the close of the last session of a
    /// client logged in as `username`. Errors: InvalidArgument (`path` not in this service),
    /// ObjectLockedError (a lock already covers `path` or an object below it).
    Result<void> request_object_lock(const std::string& path, const std::string& username);
    /// Releases the lock taken on exactly `path` (by the service or a client). Nothing held: OK.
    /// Errors: InvalidArgument (`path` not in this service), ObjectLockedError (the lock covering
    /// `path` was taken on an ancestor).
    Result<void> release_object_lock(const std::string& path);

    /// The object lock covering `path` (its user, the path it was taken on, its session for a client
    /// lock), if any.
    std::optional<ObjectLocks::Holder> lock_holder(const std::string& path) const;

    /// Client sessions currently open (logged-in ones only when authentication is on).
    std::vector<SessionRef> sessions() const;

    /// Drops every handler of every object this service ever served and forgets all paths: breaks
    /// handler/object reference cycles before the application exits. The service answers nothing
    /// useful afterwards.
    void shutdown();

    /// Generator table limits: open generators per client session, and the idle time after which an
    /// untouched generator is dropped.
    static constexpr std::size_t kMaxGeneratorsPerSession = 1024;
    static constexpr std::chrono::minutes kGeneratorIdleTimeout{10};
    /// How long a closed or aborted generator's index stays known (CORE: 30 s): its next Next is
    /// answered StopIteration (closed) or OperationAborted (aborted), then the index goes.
    static constexpr std::chrono::seconds kEndedGeneratorGrace{30};
    /// A waiting MonitorEnter / MonitorContinueEnter is answered "Continue" after this (CORE: 5 s).
    static constexpr std::chrono::seconds kMonitorWait = ServiceLocks::kMonitorWait;

    // --- Service ---
    const std::string& name() const override { return name_; }
    std::vector<std::string> service_definitions() const override;
    std::optional<std::string> service_definition(std::string_view service_type) const override;
    ObjectTypeInfo root_type() const override;
    MessageElement attributes() const override;
    void object_type(const SessionRef& session, const std::string& path,
                     std::function<void(Result<ObjectTypeInfo>)> done) override;
    bool requires_authentication() const override;
    bool handles_locks() const override { return true; }
    void attach(boost::asio::io_context& io) override;
    Result<void> authenticate(const std::string& username, const MessageElement* credentials) override;
    void on_session_open(const SessionRef& session) override;
    void on_session_close(const SessionRef& session) override;
    void handle_entry(const SessionRef& session, MessageEntry&& entry, Responder responder) override;

    // --- used by ServiceObject ---
    /// Registers a generator for `session`; returns its index. Errors: BufferLimitViolation when the
    /// session has kMaxGeneratorsPerSession open.
    Result<std::int32_t> add_generator(const SessionRef& session, const std::string& path, const std::string& member,
                                       std::shared_ptr<Generator> generator);

private:
    ObjectService(std::string name, std::shared_ptr<ServiceObject> root);
    /// The object at `path`, resolving objrefs as needed. Errors: ObjectNotFound.
    Result<std::shared_ptr<ServiceObject>> resolve(const SessionRef& session, const std::string& path);
    void handle_generator_next(const SessionRef& session, MessageEntry&& entry, Responder responder);
    void handle_lock_op(const SessionRef& session, MessageEntry&& entry, Responder responder);
    /// Object and monitor locks for a member request. Errors: ObjectLockedError, InvalidOperation.
    /// `obj`: the object at `path` when resolved (for its members' [nolock] / [nolockread]).
    Result<void> check_locks(const SessionRef& session, const std::string& path, const ServiceObject* obj,
                             const MessageEntry& entry);
    bool has_privilege(const std::string& username, std::string_view privilege) const;  // mutex_ held

    struct GeneratorEntry {
        std::uint32_t session = 0;
        std::string path, member;
        std::shared_ptr<Generator> generator;
        std::chrono::steady_clock::time_point last_access;
        /// StopIteration after a close, OperationAborted after an abort: the answer to the next Next,
        /// within kEndedGeneratorGrace (requests do not refresh last_access then).
        MessageErrorType ended = MessageErrorType::None;
    };

    const std::string name_;
    const std::shared_ptr<ServiceObject> root_;
    const std::shared_ptr<const ServiceTypes> types_;
    mutable std::mutex mutex_;
    std::unordered_map<std::string, std::shared_ptr<ServiceObject>> objects_;  // by service path
    std::vector<std::weak_ptr<ServiceObject>> ever_bound_;                       // for shutdown()
    std::map<std::uint32_t, SessionRef> sessions_;
    std::unordered_map<std::int32_t, GeneratorEntry> generators_;
    std::mt19937 rng_;
    MessageElement attributes_;
    PasswordTable users_;
    std::atomic<bool> has_users_{false};  // !users_.empty(), read on every request without mutex_
    const std::shared_ptr<ServiceLocks> locks_ = std::make_shared<ServiceLocks>();
    std::atomic<bool> shut_down_{false};  // set under mutex_; resolve() reads it without, for the root
};

}  // namespace rr::server
