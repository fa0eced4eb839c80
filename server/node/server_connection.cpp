#include "server/node/server_connection.hpp"

#include "core/session/elements.hpp"
#include "server/transport/completion_guard.hpp"

namespace rr::server {
namespace {

std::size_t estimate_size(const MessageElement& e) {
    std::size_t n = 16 + e.name.size() + e.type_name.size() + e.data.size();
    for (const auto& c : e.elements) n += estimate_size(c);
    return n;
}

std::size_t estimate_size(const MessageEntry& e) {
    std::size_t n = 64 + e.service_path.size() + e.member_name.size();
    for (const auto& c : e.elements) n += estimate_size(c);
    return n;
}

// The connection whose strand handler (on_bytes, on_timer) runs on this thread, if any: a reply
// completed inside it is queued at once, without a dispatch through the pump.
thread_local const ServerConnection* tls_handling = nullptr;

struct HandlingScope {
    const ServerConnection* previous;
    explicit HandlingScope(const ServerConnection* c) : previous(std::exchange(tls_handling, c)) {}
    ~HandlingScope() { tls_handling = previous; }
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// SessionRef / Responder

SessionRef::SessionRef(std::weak_ptr<ServerSession> s) : session_(std::move(s)) {
    if (auto p = session_.lock()) endpoint_ = p->endpoint();
}

SessionRef::SessionRef(const std::shared_ptr<ServerSession>& s) : session_(s), endpoint_(s ? s->endpoint() : 0) {}

std::string SessionRef::username() const {
    auto p = session_.lock();
    return p ? p->username() : std::string();
}

bool SessionRef::alive() const {
    auto p = session_.lock();
    return p && p->alive();
}

Result<void> SessionRef::send(MessageEntry entry) const {
    auto p = session_.lock();
    if (!p) return fail(MessageErrorType::ConnectionError, "client session closed");
    return p->send(std::move(entry));
}

Result<void> SessionRef::send(std::shared_ptr<const EncodedEntry> entry) const {
    auto p = session_.lock();
    if (!p) return fail(MessageErrorType::ConnectionError, "client session closed");
    return p->send(std::move(entry));
}

Result<void> SessionRef::send_wire_packet(std::shared_ptr<const EncodedEntry> entry) const {
    auto p = session_.lock();
    if (!p) return fail(MessageErrorType::ConnectionError, "client session closed");
    return p->send_wire_packet(std::move(entry));
}

Result<void> SessionRef::send_wire_packet(MessageEntry entry) const {
    auto p = session_.lock();
    if (!p) return fail(MessageErrorType::ConnectionError, "client session closed");
    return p->send_wire_packet(std::move(entry));
}

void SessionRef::request(MessageEntry entry, std::function<void(Result<MessageEntry>)> done) const {
    auto p = session_.lock();
    if (!p) {
        done(fail(MessageErrorType::ConnectionError, "client session closed"));
        return;
    }
    p->request(std::move(entry), std::move(done));
}

std::size_t SessionRef::queued_bytes() const {
    auto p = session_.lock();
    return p ? p->queued_bytes() : 0;
}

std::string SessionRef::local_url() const {
    auto p = session_.lock();
    return p ? p->local_url() : std::string();
}

std::string SessionRef::peer() const {
    auto p = session_.lock();
    return p ? p->peer() : std::string();
}

void SessionRef::set_liveness_probe(std::optional<std::chrono::milliseconds> timeout) const {
    if (auto p = session_.lock()) p->set_liveness_probe(timeout);
}

Responder::Responder(std::shared_ptr<ReplySink> sink, const MessageEntry& request)
    : sink_(std::move(sink)),
      request_type_(request.entry_type),
      request_id_(request.request_id),
      service_path_(request.service_path),
      member_name_(request.member_name) {}

Responder::~Responder() {
    if (sink_) fail(make_error(MessageErrorType::InternalError, "request was not answered"));
}

void Responder::respond(MessageEntry&& reply) {
    if (!sink_) return;
    if (reply.entry_type == MessageEntryType::Null)
        reply.entry_type = static_cast<MessageEntryType>(static_cast<std::uint16_t>(request_type_) + 1);
    reply.service_path = std::move(service_path_);
    reply.member_name = std::move(member_name_);
    reply.request_id = request_id_;
    auto sink = std::move(sink_);
    sink_ = nullptr;
    sink->send_reply(std::move(reply));
}

void Responder::fail(RRError error) {
    if (!sink_) return;
    MessageEntry r;
    set_entry_error(r, error);
    respond(std::move(r));
}

// ---------------------------------------------------------------------------------------------
// ServerSession

ServerSession::ServerSession(std::uint32_t endpoint, std::uint32_t client_endpoint, std::shared_ptr<Service> service,
                             std::weak_ptr<PumpHandle> pump, std::weak_ptr<ServerConnection> connection,
                             std::size_t max_queue)
    : endpoint_(endpoint), client_endpoint_(client_endpoint), service_(std::move(service)), pump_(std::move(pump)),
      connection_(std::move(connection)), max_queue_(max_queue) {}

std::string ServerSession::username() const {
    std::lock_guard lock(mutex_);
    return username_;
}

void ServerSession::set_username(std::string name) {
    std::lock_guard lock(mutex_);
    username_ = std::move(name);
}

std::string ServerSession::local_url() const {
    auto c = connection_.lock();
    return c ? c->local_url() : std::string();
}

std::string ServerSession::peer() const {
    auto c = connection_.lock();
    return c ? c->peer() : std::string();
}

void ServerSession::set_liveness_probe(std::optional<std::chrono::milliseconds> timeout) {
    auto pump = pump_.lock();
    if (!pump || !alive()) return;
    pump->post([conn = connection_, timeout] {
        if (auto c = conn.lock()) c->set_liveness_probe(timeout);
    });
}

// From another thread (a fan-out, a worker's reply or event): queued in order with the pump's one
// wake, no closure per entry. A wake already on its way takes it; it still precedes any later post
// from this thread. Every send of another thread takes this way when the pump can tell (a concrete
// strand), and none when it cannot, so sends and replies keep their order either way.
template <class T, class Arg>
void ServerSession::queue_send(PumpHandle& pump, std::in_place_type_t<T> kind, Arg&& arg) {
    bool wake = false;
    {
        std::lock_guard lock(mutex_);
        send_pending_.emplace_back(kind, std::forward<Arg>(arg));
        wake = !std::exchange(wake_pending_, true);
    }
    if (wake) pump.wake();
}

Result<void> ServerSession::send(MessageEntry entry) {
    auto pump = pump_.lock();
    if (!pump || !alive()) return fail(MessageErrorType::ConnectionError, "client session closed");
    const std::size_t size = estimate_size(entry);
    if (queued_.load() + size > max_queue_) return fail(MessageErrorType::BufferLimitViolation, "client send queue full");
    queued_.fetch_add(size);
    if (pump->known_off_strand()) {
        queue_send(*pump, std::in_place_type<MessageEntry>, std::move(entry));
        return {};
    }
    // dispatch: on the session's own strand (a handler sending an event or ServicePathReleased before
    // answering) the entry is queued at once, so it reaches the client before the reply.
    pump->dispatch([conn = connection_, entry = std::move(entry)]() mutable {
        if (auto c = conn.lock()) c->send_session_entry(std::move(entry));
    });
    return {};
}

Result<void> ServerSession::send(std::shared_ptr<const EncodedEntry> entry) {
    auto pump = pump_.lock();
    if (!pump || !alive()) return fail(MessageErrorType::ConnectionError, "client session closed");
    const std::size_t size = estimate_size(entry->entry());
    if (queued_.load() + size > max_queue_) return fail(MessageErrorType::BufferLimitViolation, "client send queue full");
    queued_.fetch_add(size);
    if (pump->known_off_strand()) {
        queue_send(*pump, std::in_place_type<std::shared_ptr<const EncodedEntry>>, std::move(entry));
        return {};
    }
    // On the session's own strand: queued at once, before the reply of the handler that sends it.
    pump->dispatch([conn = connection_, entry = std::move(entry)] {
        if (auto c = conn.lock()) c->send_session_entry(*entry);
    });
    return {};
}

void ServerSession::queue_reply(MessageEntry&& reply) {
    auto pump = pump_.lock();
    if (!pump || !alive()) return;  // the session or its connection is gone: nobody to answer
    queue_send(*pump, std::in_place_type<PendingReply>, std::move(reply));
}

Result<void> ServerSession::send_wire_packet(MessageEntry entry) {
    auto key = std::make_pair(entry.service_path, entry.member_name);
    return queue_wire_packet(std::move(key), PendingWire(std::in_place_type<MessageEntry>, std::move(entry)));
}

Result<void> ServerSession::send_wire_packet(std::shared_ptr<const EncodedEntry> entry) {
    auto key = std::make_pair(entry->entry().service_path, entry->entry().member_name);
    return queue_wire_packet(std::move(key), PendingWire(std::move(entry)));
}

Result<void> ServerSession::queue_wire_packet(std::pair<std::string, std::string> key, PendingWire packet) {
    auto pump = pump_.lock();
    if (!pump || !alive()) return fail(MessageErrorType::ConnectionError, "client session closed");
    bool wake = false;
    {
        std::lock_guard lock(mutex_);
        auto it = wire_pending_.find(key);
        if (it == wire_pending_.end()) it = wire_pending_.emplace(std::move(key), std::nullopt).first;
        it->second = std::move(packet);  // an older packet not yet sent is replaced: wires keep only the newest value
        wake = !std::exchange(wake_pending_, true);
    }
    // At once when on the session's own strand (the packet then goes out before the reply), unless a
    // wake from another thread is already on its way: the packet rides on that one.
    if (wake) pump->wake();
    return {};
}

void ServerSession::take_queued(std::vector<PendingSend>& sends, std::vector<PendingWire>& wires) {
    std::lock_guard lock(mutex_);
    wake_pending_ = false;
    if (sends.empty()) {
        sends.swap(send_pending_);  // both keep their capacity: no allocation per wake
    } else {
        for (auto& e : send_pending_) sends.push_back(std::move(e));
        send_pending_.clear();
    }
    for (auto it = wire_pending_.begin(); it != wire_pending_.end();) {
        if (it->second) {
            wires.push_back(std::move(*it->second));
            it->second.reset();
        }
        if (wire_pending_.size() > kKeptWireSlots && !it->second)
            it = wire_pending_.erase(it);
        else
            ++it;
    }
}

void ServerSession::request(MessageEntry entry, std::function<void(Result<MessageEntry>)> done) {
    auto pump = pump_.lock();
    if (!pump || !alive()) {
        done(fail(MessageErrorType::ConnectionError, "client session closed"));
        return;
    }
    // The guard answers ConnectionError if the pump closes before this runs (the work is dropped).
    auto guard = std::make_shared<CompletionGuard<MessageEntry>>(std::move(done), "client session closed");
    pump->post([conn = connection_, entry = std::move(entry), guard]() mutable {
        if (auto c = conn.lock()) c->send_session_request(std::move(entry), guard->take());
    });
}

// ---------------------------------------------------------------------------------------------
// ServerConnection

ServerConnection::ServerConnection(std::shared_ptr<ServiceRegistry> services, std::shared_ptr<NodeStats> stats,
                                   ServerConnectionConfig config, std::string local_url, MonoTime now)
    : services_(std::move(services)), stats_(std::move(stats)), config_(std::move(config)), local_url_(std::move(local_url)),
      session_(*services_, ServiceSessionConfig{config_.stream, config_.callback_timeout, config_.wire_hold_bytes, config_.peer, config_.web_login}, now) {
    stats_->connections_open.fetch_add(1);
    stats_->connections_total.fetch_add(1, std::memory_order_relaxed);
}

ServerConnection::~ServerConnection() {
    if (current_) current_->mark_closed();
    stats_->connections_open.fetch_sub(1);
}

void ServerConnection::on_bytes(std::span<const std::byte> bytes, MonoTime now) {
    HandlingScope scope(this);
    stats_->bytes_in.fetch_add(bytes.size(), std::memory_order_relaxed);
    session_.feed(bytes, now);
    drain_events();
}

void ServerConnection::take_output(GatherBuffer& out) {
    session_.take_output(out);
    stats_->bytes_out.fetch_add(out.size(), std::memory_order_relaxed);
    update_queue_estimate();
}

void ServerConnection::set_liveness_probe(std::optional<std::chrono::milliseconds> timeout) {
    session_.set_liveness_probe(timeout, mono_now());
}

void ServerConnection::on_timer(MonoTime now) {
    HandlingScope scope(this);
    session_.on_timer(now);
    drain_events();
}

void ServerConnection::on_transport_closed(RRError error) {
    session_.on_transport_closed(std::move(error));
    drain_events();
}

void ServerConnection::update_queue_estimate() {
    if (current_) current_->set_queued_bytes(session_.pending_output_size());
}

void ServerConnection::drain_events() {
    // Handlers may send (SessionRef::send runs inline on the strand) and so come back here: only the
    // outermost call takes events, so requests are handed to the service in the order they arrived.
    if (draining_) return;
    draining_ = true;
    struct Done {
        bool& flag;
        ~Done() { flag = false; }
    } done_draining{draining_};
    // Handled in place, a batch at a time (no move per event); events queued by the handlers come in
    // the next batch, so the order is the order they were queued in.
    for (session_.take_events(batch_); !batch_.empty(); session_.take_events(batch_))
        for (auto& event : batch_) handle_event(event);
    const auto in = session_.messages_in(), out = session_.messages_out();
    stats_->messages_in.fetch_add(in - messages_in_seen_, std::memory_order_relaxed);
    stats_->messages_out.fetch_add(out - messages_out_seen_, std::memory_order_relaxed);
    messages_in_seen_ = in;
    messages_out_seen_ = out;
    update_queue_estimate();
}

void ServerConnection::handle_event(ServiceSessionEvent& event) {
    if (auto* opened = std::get_if<ServiceSessionOpened>(&event)) {
        auto service = std::static_pointer_cast<Service>(opened->service);
        current_ = std::make_shared<ServerSession>(opened->endpoint, opened->client_endpoint, service, pump_,
                                                   weak_from_this(), config_.max_send_queue_bytes);
        reply_sink_.reset();  // the next request makes this session's
        current_->set_username(opened->username);
        service->on_session_open(SessionRef(current_));
    } else if (auto* admission = std::get_if<ServiceAdmission>(&event)) {
        on_admission(std::move(*admission));
    } else if (auto* user = std::get_if<ServiceSessionUser>(&event)) {
        if (current_) current_->set_username(std::move(user->username));
    } else if (auto* request = std::get_if<ServiceRequest>(&event)) {
        on_request(*request);
    } else if (auto* query = std::get_if<ServiceObjectTypeQuery>(&event)) {
        on_object_type_query(std::move(*query));
    } else if (auto* response = std::get_if<ServiceCallbackResponse>(&event)) {
        auto it = callbacks_.find(response->request_id);
        if (it == callbacks_.end()) return;
        auto done = std::move(it->second);
        callbacks_.erase(it);
        done(std::move(response->entry));
    } else if (auto* closed = std::get_if<ServiceSessionClosed>(&event)) {
        const std::uint64_t token = closed->disconnect_token;
        if (!current_) {
            if (token != 0) session_.answer_disconnect(token, mono_now());
            return;
        }
        auto s = std::move(current_);
        current_.reset();
        reply_sink_.reset();
        s->mark_closed();
        if (token == 0) {
            s->service()->on_session_close(SessionRef(s));
            return;
        }
        s->service()->end_session(SessionRef(s), [weak = weak_from_this(), pump = pump_, token] {
            auto p = pump.lock();
            if (!p) return;
            p->post([weak, token] {
                if (auto c = weak.lock()) {
                    c->session_.answer_disconnect(token, mono_now());
                    c->drain_events();
                }
            });
        });
    }
    // ServiceConnectionClosed: the pump closes the transport (wants_close()).
}

void ServerConnection::on_request(ServiceRequest& request) {
    if (!current_) return;
    auto service = current_->service();
    if (!request.needs_reply) {
        service->handle_entry(SessionRef(current_), std::move(request.entry()), Responder());
    } else {
        // The Responder is built in the parameter's place; std::move only names the entry, which the
        // callee takes by reference, so make_responder reads it intact whatever the argument order.
        service->handle_entry(SessionRef(current_), std::move(request.entry()), make_responder(request.entry()));
    }
    session_.recycle(std::move(request));  // its entry vector, for the next message
}

void ServerConnection::on_admission(ServiceAdmission&& admission) {
    auto service = std::static_pointer_cast<Service>(admission.service);
    std::weak_ptr<ServerConnection> weak = weak_from_this();
    std::weak_ptr<PumpHandle> pump = pump_;
    const std::uint32_t endpoint = admission.endpoint;
    service->admit_session(endpoint, std::move(admission.username), std::move(admission.credentials),
                           [weak, pump, service, endpoint, token = admission.token](Result<void> outcome) mutable {
                               auto p = pump.lock();
                               if (!p) {
                                   if (outcome) service->abandon_admission(endpoint);
                                   return;
                               }
                               p->post([weak, service, endpoint, token, outcome = std::move(outcome)]() mutable {
                                   auto c = weak.lock();
                                   const bool ok = outcome.ok();
                                   const bool taken = c && c->session_.answer_admission(token, std::move(outcome), mono_now());
                                   if (!taken && ok) service->abandon_admission(endpoint);
                                   if (c) c->drain_events();
                               });
                           });
}

void ServerConnection::on_object_type_query(ServiceObjectTypeQuery&& query) {
    auto service = std::static_pointer_cast<Service>(query.service);
    std::weak_ptr<ServerConnection> weak = weak_from_this();
    std::weak_ptr<PumpHandle> pump = pump_;
    service->object_type(SessionRef(current_), query.path, [weak, pump, token = query.token](Result<ObjectTypeInfo> info) mutable {
        auto p = pump.lock();
        if (!p) return;
        p->post([weak, token, info = std::move(info)]() mutable {
            if (auto c = weak.lock()) {
                c->session_.answer_object_type(token, std::move(info), mono_now());
                c->drain_events();
            }
        });
    });
}

/// One per client session, shared by its Responders (no allocation per request).
class ServerConnection::ConnectionReplySink final : public ReplySink {
public:
    ConnectionReplySink(ServerConnection& owner, std::weak_ptr<ServerConnection> connection, std::weak_ptr<PumpHandle> pump,
                        std::weak_ptr<ServerSession> session)
        : owner_(&owner), connection_(std::move(connection)), pump_(std::move(pump)), session_(std::move(session)) {}

    void send_reply(MessageEntry&& reply) override {
        // The responder may complete on any thread; on the strand, while the connection handles its
        // bytes or timer, the reply goes out at once. Handling keeps it alive, so no weak_ptr lock; the
        // expiry check tells it from a later connection at the same address.
        if (tls_handling == owner_ && !connection_.expired()) {
            owner_->reply(std::move(reply));
            return;
        }
        auto p = pump_.lock();
        if (!p) return;
        if (p->known_off_strand()) {
            // In order with the session's other sends from other threads (ServerSession::queue_send).
            if (auto s = session_.lock()) s->queue_reply(std::move(reply));
            return;
        }
        p->dispatch([weak = connection_, reply = std::move(reply)]() mutable {
            if (auto c = weak.lock()) c->reply(std::move(reply));
        });
    }

private:
    ServerConnection* owner_;  // compared with tls_handling; used only while it handles (see send_reply)
    std::weak_ptr<ServerConnection> connection_;
    std::weak_ptr<PumpHandle> pump_;
    std::weak_ptr<ServerSession> session_;
};

Responder ServerConnection::make_responder(const MessageEntry& request) {
    if (!reply_sink_) reply_sink_ = std::make_shared<ConnectionReplySink>(*this, weak_from_this(), pump_, current_);
    return Responder(reply_sink_, request);
}

void ServerConnection::reply(MessageEntry&& entry) {
    session_.reply(std::move(entry), mono_now());
    drain_events();
}

void ServerConnection::send_session_entry(MessageEntry&& entry) {
    send_entry(std::move(entry), mono_now());
    drain_events();
}

void ServerConnection::send_entry(MessageEntry&& entry, MonoTime now) {
    // A reply sent through SessionRef::send keeps the reply rules (never lost: an error reply instead).
    if (!is_request(entry.entry_type) && entry.request_id != 0)
        session_.reply(std::move(entry), now);
    else
        (void)session_.send(std::move(entry), now);
}

void ServerConnection::send_session_entry(const EncodedEntry& entry) {
    (void)session_.send(entry, mono_now());
    drain_events();
}

void ServerConnection::on_wake() {
    if (!current_) return;
    current_->take_queued(woken_sends_, woken_wires_);
    const auto now = mono_now();
    for (auto& send : woken_sends_) {
        if (auto* shared = std::get_if<std::shared_ptr<const EncodedEntry>>(&send))
            (void)session_.send(**shared, now);
        else if (auto* own = std::get_if<MessageEntry>(&send))
            send_entry(std::move(*own), now);
        else
            session_.reply(std::move(std::get<ServerSession::PendingReply>(send).entry), now);
    }
    woken_sends_.clear();
    for (auto& packet : woken_wires_) {
        if (auto* own = std::get_if<MessageEntry>(&packet))
            session_.send_wire_packet(std::move(*own), now);
        else
            session_.send_wire_packet(std::get<std::shared_ptr<const EncodedEntry>>(std::move(packet)), now);
    }
    woken_wires_.clear();
    drain_events();
}

void ServerConnection::send_session_request(MessageEntry entry, std::function<void(Result<MessageEntry>)> done) {
    auto id = session_.request(std::move(entry), mono_now());
    if (!id) {
        done(id.take_error());
        return;
    }
    callbacks_.emplace(*id, std::move(done));
    drain_events();
}

}  // namespace rr::server
