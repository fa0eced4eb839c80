#include "server/service/server_connection.hpp"

#include "core/core_version.hpp"
#include "core/names/service_path.hpp"
#include "core/session/elements.hpp"

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

MessageElement make_string_list(std::string name, const std::vector<std::string>& items) {
    MessageElement list;
    list.name = std::move(name);
    list.type = DataTypes::list_t;
    for (std::size_t i = 0; i < items.size(); ++i) {
        MessageElement item = make_string_element("", items[i]);
        item.number = static_cast<std::int32_t>(i);
        list.elements.push_back(std::move(item));
    }
    return list;
}

MessageEntry reply_to(const MessageEntry& request) {
    MessageEntry r;
    r.entry_type = static_cast<MessageEntryType>(static_cast<std::uint16_t>(request.entry_type) + 1);
    r.service_path = request.service_path;
    r.member_name = request.member_name;
    r.request_id = request.request_id;
    return r;
}

MessageEntry error_reply(const MessageEntry& request, const RRError& error) {
    MessageEntry r = reply_to(request);
    set_entry_error(r, error);
    return r;
}

RRError service_not_found() {
    // CORE's special-request path uses this non-canonical name (wire.md §5.1).
    RRError e = make_error(MessageErrorType::ServiceNotFound, "Service not found");
    e.name = "RobotRaconteur.ServiceNotFoundException";
    return e;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Service / SessionRef / Responder

MessageElement Service::attributes() const {
    MessageElement e;
    e.name = "attributes";
    e.type = DataTypes::dictionary_t;
    return e;
}

SessionRef::SessionRef(std::weak_ptr<ServerSession> s) : session_(std::move(s)) {
    if (auto p = session_.lock()) endpoint_ = p->endpoint();
}

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

std::string ServerSession::local_url() const {
    auto c = connection_.lock();
    return c ? c->local_url() : std::string();
}

Responder::Responder(std::function<void(MessageEntry)> send, MessageEntry request_header)
    : send_(std::move(send)), request_(std::move(request_header)) {
    request_.elements.clear();
}

Responder::~Responder() {
    if (send_) fail(make_error(MessageErrorType::InternalError, "request was not answered"));
}

void Responder::respond(MessageEntry reply) {
    if (!send_) return;
    if (reply.entry_type == MessageEntryType::Null)
        reply.entry_type = static_cast<MessageEntryType>(static_cast<std::uint16_t>(request_.entry_type) + 1);
    reply.service_path = request_.service_path;
    reply.member_name = request_.member_name;
    reply.request_id = request_.request_id;
    auto send = std::move(send_);
    send_ = nullptr;
    send(std::move(reply));
}

void Responder::fail(RRError error) {
    if (!send_) return;
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

Result<void> ServerSession::send(MessageEntry entry) {
    auto pump = pump_.lock();
    if (!pump || !alive()) return fail(MessageErrorType::ConnectionError, "client session closed");
    const std::size_t size = estimate_size(entry);
    if (queued_.load() + size > max_queue_)
        return fail(MessageErrorType::BufferLimitViolation, "client send queue full");
    queued_.fetch_add(size);
    // dispatch: on the session's own strand (a handler sending an event or ServicePathReleased before
    // answering) the entry is queued at once, so it reaches the client before the reply.
    pump->dispatch([conn = connection_, entry = std::move(entry)]() mutable {
        if (auto c = conn.lock()) c->send_session_entry(std::move(entry));
    });
    return {};
}

Result<void> ServerSession::send_wire_packet(MessageEntry entry) {
    auto pump = pump_.lock();
    if (!pump || !alive()) return fail(MessageErrorType::ConnectionError, "client session closed");
    auto key = std::make_pair(entry.service_path, entry.member_name);
    bool post = false;
    {
        std::lock_guard lock(mutex_);
        auto [it, inserted] = wire_pending_.insert_or_assign(key, std::move(entry));
        post = inserted;  // an older packet not yet sent is replaced: wires keep only the newest value
    }
    if (post) {
        // dispatch, as send(): from the session's own strand the packet goes out before the reply.
        pump->dispatch([conn = connection_, key] {
            if (auto c = conn.lock()) c->send_wire_entry(key);
        });
    }
    return {};
}

void ServerSession::request(MessageEntry entry, std::function<void(Result<MessageEntry>)> done) {
    auto pump = pump_.lock();
    if (!pump || !alive()) {
        done(fail(MessageErrorType::ConnectionError, "client session closed"));
        return;
    }
    pump->post([conn = connection_, entry = std::move(entry), done = std::move(done)]() mutable {
        if (auto c = conn.lock())
            c->send_session_request(std::move(entry), std::move(done));
        else
            done(fail(MessageErrorType::ConnectionError, "client session closed"));
    });
}

// ---------------------------------------------------------------------------------------------
// ServerConnection

ServerConnection::ServerConnection(const std::shared_ptr<NodeServices>& node, ServerConnectionConfig config, MonoTime now)
    : node_(node), stats_(node->stats()), node_id_(node->node_id()), node_name_(node->node_name()),
      config_(std::move(config)),
      stream_(StreamRole::server, [&] {
          StreamConfig s = config_.stream;
          s.local_node_id = node_id_;
          s.local_node_name = node_name_;
          return s;
      }(), now) {}

ServerConnection::~ServerConnection() {
    if (session_) {
        session_->mark_closed();
        if (auto node = node_.lock()) node->release_endpoint_id(session_->endpoint());
    }
}

std::shared_ptr<Service> ServerConnection::find_service(std::string_view name) const {
    auto node = node_.lock();
    return node ? node->find_service(name) : nullptr;
}

void ServerConnection::on_bytes(std::span<const std::byte> bytes, MonoTime now) {
    stats_->bytes_in.fetch_add(bytes.size(), std::memory_order_relaxed);
    (void)stream_.feed(bytes, now);  // errors close the stream; the Closed event follows
    drain_events(now);
}

void ServerConnection::drain_events(MonoTime now) {
    while (auto ev = stream_.poll_event()) {
        if (auto* m = std::get_if<StreamMessage>(&*ev)) {
            on_message(std::move(m->message), now);
        } else if (std::holds_alternative<StreamClosed>(*ev)) {
            close_session();
        }
    }
    update_queue_estimate();
}

void ServerConnection::take_output(std::vector<std::byte>& out) {
    stream_.take_output(out);
    stats_->bytes_out.fetch_add(out.size(), std::memory_order_relaxed);
    update_queue_estimate();
    flush_held_wires();
}

std::optional<MonoTime> ServerConnection::next_deadline() const {
    auto d = stream_.next_deadline();
    for (const auto& [id, p] : pending_callbacks_) d = d ? std::min(*d, p.deadline) : p.deadline;
    return d;
}

void ServerConnection::on_timer(MonoTime now) {
    stream_.on_timer(now);
    for (auto it = pending_callbacks_.begin(); it != pending_callbacks_.end();) {
        if (now >= it->second.deadline) {
            auto done = std::move(it->second.done);
            it = pending_callbacks_.erase(it);
            done(fail(MessageErrorType::RequestTimeout, "callback timed out"));
        } else {
            ++it;
        }
    }
    drain_events(now);
}

void ServerConnection::on_transport_closed(RRError error) {
    stream_.on_transport_closed(std::move(error));
    drain_events(MonoTime{});
    close_session();
}

void ServerConnection::close_session() {
    auto callbacks = std::move(pending_callbacks_);
    pending_callbacks_.clear();
    for (auto& [id, p] : callbacks) p.done(fail(MessageErrorType::ConnectionError, "client disconnected"));
    if (!session_) return;
    auto s = std::move(session_);
    session_.reset();
    s->mark_closed();
    if (auto node = node_.lock()) node->release_endpoint_id(s->endpoint());
    s->service()->on_session_close(SessionRef(s));
}

void ServerConnection::update_queue_estimate() {
    if (session_) session_->set_queued_bytes(stream_.pending_output_size());
}

Message ServerConnection::session_message(MessageEntry entry) {
    stats_->messages_out.fetch_add(1, std::memory_order_relaxed);
    Message m;
    m.version = 2;
    m.header.sender_node_id = node_id_;
    m.header.receiver_node_id = stream_.negotiated().remote_node_id;
    m.header.sender_endpoint = session_ ? session_->endpoint() : 0;
    m.header.receiver_endpoint = session_ ? session_->client_endpoint() : 0;
    m.header.message_id = ++message_id_;
    if (entry.metadata == "unreliable\n") m.header.metadata = entry.metadata;
    m.entries.push_back(std::move(entry));
    return m;
}

void ServerConnection::send_session_entry(MessageEntry entry) {
    if (!session_ || stream_.is_closed()) return;
    std::optional<MessageEntry> reply_header;
    if (!is_request(entry.entry_type) && entry.request_id != 0) {
        reply_header.emplace();
        reply_header->entry_type = entry.entry_type;
        reply_header->service_path = entry.service_path;
        reply_header->member_name = entry.member_name;
        reply_header->request_id = entry.request_id;
    }
    auto r = stream_.send(session_message(std::move(entry)), mono_now());
    if (!r && reply_header) {
        // A reply that cannot be sent (over the size limit) must not vanish: answer with the error.
        set_entry_error(*reply_header, r.error());
        (void)stream_.send(session_message(std::move(*reply_header)), mono_now());
    }
    update_queue_estimate();
}

void ServerConnection::send_wire_entry(const std::pair<std::string, std::string>& key) {
    if (!session_ || stream_.is_closed()) return;
    std::optional<MessageEntry> entry;
    {
        std::lock_guard lock(session_->mutex_);
        auto it = session_->wire_pending_.find(key);
        if (it == session_->wire_pending_.end()) return;
        entry = std::move(it->second);
        session_->wire_pending_.erase(it);
    }
    if (stream_.pending_output_size() > config_.wire_hold_bytes) {
        held_wires_.insert_or_assign(key, std::move(*entry));  // newest kept until the output drains
        return;
    }
    (void)stream_.send(session_message(std::move(*entry)), mono_now());
    update_queue_estimate();
}

void ServerConnection::flush_held_wires() {
    if (held_wires_.empty() || !session_) return;
    auto held = std::move(held_wires_);
    held_wires_.clear();
    for (auto& [key, entry] : held) (void)stream_.send(session_message(std::move(entry)), mono_now());
}

void ServerConnection::send_session_request(MessageEntry entry, std::function<void(Result<MessageEntry>)> done) {
    if (!session_ || stream_.is_closed()) {
        done(fail(MessageErrorType::ConnectionError, "client session closed"));
        return;
    }
    if (++callback_request_counter_ == 0) ++callback_request_counter_;
    entry.request_id = callback_request_counter_;
    auto now = mono_now();
    if (auto r = stream_.send(session_message(std::move(entry)), now); !r) {
        done(r.take_error());
        return;
    }
    pending_callbacks_[callback_request_counter_] = PendingCallback{std::move(done), now + config_.callback_timeout};
    update_queue_estimate();
}

void ServerConnection::reply_special(const MessageHeader& request_header, MessageEntry reply) {
    Message m;
    m.version = 2;
    m.header.sender_node_id = node_id_;
    m.header.sender_node_name = node_name_;
    m.header.receiver_node_id = request_header.sender_node_id;
    m.header.receiver_node_name = request_header.sender_node_name;
    m.header.sender_endpoint = session_ ? session_->endpoint() : 0;
    m.header.receiver_endpoint = request_header.sender_endpoint;
    m.header.message_id = ++message_id_;
    m.entries.push_back(std::move(reply));
    (void)stream_.send(m, mono_now());
}

void ServerConnection::reply_session(MessageEntry reply) { send_session_entry(std::move(reply)); }

Responder ServerConnection::make_responder(const MessageEntry& request) {
    std::weak_ptr<ServerConnection> weak = shared_from_this();
    std::weak_ptr<PumpHandle> pump = pump_;
    return Responder(
        [weak, pump](MessageEntry reply) {
            // The responder may complete on any thread; on the strand itself the reply goes out at once.
            auto p = pump.lock();
            if (!p) return;
            p->dispatch([weak, reply = std::move(reply)]() mutable {
                if (auto c = weak.lock()) c->reply_session(std::move(reply));
            });
        },
        request);
}

void ServerConnection::on_message(Message&& m, MonoTime now) {
    stats_->messages_in.fetch_add(1, std::memory_order_relaxed);
    for (auto& e : m.entries) {
        if (stream_.is_closed()) return;
        const auto type = e.entry_type;
        const bool special = is_special_request(type) &&
                             !(type == MessageEntryType::ObjectTypeName && m.header.receiver_endpoint != 0);
        if (special) {
            handle_special(m.header, std::move(e), now);
        } else {
            handle_session_entry(m.header, std::move(e), now);
        }
    }
}

void ServerConnection::handle_special(const MessageHeader& h, MessageEntry&& e, MonoTime now) {
    if (!is_request(e.entry_type)) return;  // even special entries (replies) carry nothing for a server
    if (!h.receiver_node_id.is_any() && h.receiver_node_id != node_id_) {
        reply_special(h, error_reply(e, make_error(MessageErrorType::NodeNotFound, "Could not find route to remote node")));
        return;
    }
    switch (e.entry_type) {
        case MessageEntryType::GetServiceDesc: {
            auto service = find_service(e.service_path);
            if (!service) {
                reply_special(h, error_reply(e, service_not_found()));
                return;
            }
            const MessageElement* type = e.find("ServiceType");
            if (!type) type = e.find("servicetype");
            MessageEntry r = reply_to(e);
            if (type) {
                auto def = service->service_definition(read_string(*type));
                if (!def) {
                    reply_special(h, error_reply(e, make_error(MessageErrorType::ServiceNotFound,
                                                               "Service definition \"" + std::string(read_string(*type)) + "\" not found")));
                    return;
                }
                r.elements.push_back(make_string_element("servicedef", *def));
            } else {
                auto defs = service->service_definitions();
                r.elements.push_back(make_string_element("servicedef", defs.empty() ? std::string() : defs.front()));
                MessageElement attrs = service->attributes();
                attrs.name = "attributes";
                r.elements.push_back(std::move(attrs));
            }
            reply_special(h, std::move(r));
            return;
        }
        case MessageEntryType::ObjectTypeName: {
            auto service = find_service(service_name_of(e.service_path));
            if (!service) {
                reply_special(h, error_reply(e, service_not_found()));
                return;
            }
            MessageEntry request = reply_to(e);
            std::weak_ptr<ServerConnection> weak = shared_from_this();
            std::weak_ptr<PumpHandle> pump = pump_;
            MessageHeader header = h;
            service->object_type(SessionRef(session_), e.service_path,
                                 [weak, pump, request, header](Result<ObjectTypeInfo> info) mutable {
                                     auto p = pump.lock();
                                     if (!p) return;
                                     p->post([weak, request = std::move(request), header, info = std::move(info)]() mutable {
                                         auto c = weak.lock();
                                         if (!c) return;
                                         if (!info) {
                                             set_entry_error(request, info.error());
                                         } else {
                                             request.elements.push_back(make_string_element("objecttype", info->object_type));
                                             if (!info->implements.empty())
                                                 request.elements.push_back(make_string_list("objectimplements", info->implements));
                                         }
                                         c->reply_special(header, std::move(request));
                                     });
                                 });
            return;
        }
        case MessageEntryType::ConnectClient: connect_client(h, std::move(e), false, now); return;
        case MessageEntryType::ConnectClientCombined: connect_client(h, std::move(e), true, now); return;
        case MessageEntryType::DisconnectClient: {
            MessageEntry r = reply_to(e);
            close_session();
            reply_special(h, std::move(r));
            return;
        }
        case MessageEntryType::GetNodeInfo: reply_special(h, reply_to(e)); return;
        case MessageEntryType::NodeCheckCapability: {
            MessageEntry r = reply_to(e);
            r.elements.push_back(make_scalar_element<std::uint32_t>("return", 0));
            reply_special(h, std::move(r));
            return;
        }
        case MessageEntryType::GetServiceAttributes: {
            auto service = find_service(e.service_path);
            if (!service) {
                reply_special(h, error_reply(e, make_error(MessageErrorType::ServiceError, "Service not found")));
                return;
            }
            MessageEntry r = reply_to(e);
            MessageElement attrs = service->attributes();
            attrs.name = "return";
            r.elements.push_back(std::move(attrs));
            reply_special(h, std::move(r));
            return;
        }
        default:
            reply_special(h, error_reply(e, make_error(MessageErrorType::ProtocolError, "Invalid Special Operation")));
            return;
    }
}

void ServerConnection::connect_client(const MessageHeader& h, MessageEntry&& e, bool combined, MonoTime now) {
    if (session_) {
        reply_special(h, error_reply(e, make_error(MessageErrorType::InvalidOperation, "Already connected")));
        return;
    }
    auto service = find_service(e.service_path);
    if (!service) {
        reply_special(h, error_reply(e, service_not_found()));
        return;
    }
    std::string username;
    if (combined) {
        const MessageElement* user = e.find("username");
        const MessageElement* creds = e.find("credentials");
        if (service->requires_authentication() || user || creds) {
            if (!user || !creds || !service->requires_authentication()) {
                reply_special(h, error_reply(e, make_error(MessageErrorType::AuthenticationError, "Authentication Failed")));
                return;
            }
            username = std::string(read_string(*user));
            if (auto ok = service->authenticate(username, creds); !ok) {
                reply_special(h, error_reply(e, ok.error()));
                return;
            }
            authenticated_ = true;
        }
    }
    if (h.sender_endpoint == 0) {
        reply_special(h, error_reply(e, make_error(MessageErrorType::InvalidEndpoint, "client endpoint 0")));
        return;
    }
    auto node = node_.lock();
    if (!node) return;
    const std::uint32_t endpoint = node->new_endpoint_id();
    session_ = std::make_shared<ServerSession>(endpoint, h.sender_endpoint, service, pump_, weak_from_this(),
                                               config_.max_send_queue_bytes);
    session_->set_username(username);
    stream_.set_session_established(endpoint, h.sender_endpoint);

    MessageEntry r = reply_to(e);
    if (combined) {
        auto type = service->root_type();
        r.elements.push_back(make_string_element("objecttype", type.object_type));
        if (!type.implements.empty()) r.elements.push_back(make_string_list("objectimplements", type.implements));
        const MessageElement* ret = e.find("returnservicedefs");
        std::string_view want = ret ? read_string(*ret) : std::string_view("true");
        if (want != "false" && want != "0") r.elements.push_back(make_string_list("servicedefs", service->service_definitions()));
        MessageElement attrs = service->attributes();
        attrs.name = "attributes";
        r.elements.push_back(std::move(attrs));
    }
    reply_special(h, std::move(r));
    service->on_session_open(SessionRef(session_));
    (void)now;
}

void ServerConnection::handle_session_entry(const MessageHeader& h, MessageEntry&& e, MonoTime now) {
    const bool request = is_request(e.entry_type);
    if (!session_ || h.receiver_endpoint != session_->endpoint()) {
        if (request && e.entry_type != MessageEntryType::PipePacket && e.entry_type != MessageEntryType::WirePacket)
            reply_special(h, error_reply(e, make_error(MessageErrorType::InvalidEndpoint, "Invalid destination endpoint")));
        return;
    }
    switch (e.entry_type) {
        case MessageEntryType::EndpointCheckCapability:
        case MessageEntryType::ServiceCheckCapabilityReq: {
            MessageEntry r = reply_to(e);
            r.elements.push_back(make_scalar_element<std::uint32_t>("return", 0));
            reply_session(std::move(r));
            return;
        }
        case MessageEntryType::ClientKeepAliveReq: reply_session(reply_to(e)); return;
        case MessageEntryType::ClientSessionOpReq: handle_session_op(std::move(e), now); return;
        case MessageEntryType::ObjectTypeName: handle_special(h, std::move(e), now); return;
        case MessageEntryType::CallbackCallRet: {
            auto it = pending_callbacks_.find(e.request_id);
            if (it == pending_callbacks_.end()) return;
            auto done = std::move(it->second.done);
            pending_callbacks_.erase(it);
            done(std::move(e));
            return;
        }
        case MessageEntryType::PipePacket:
        case MessageEntryType::PipePacketRet:
        case MessageEntryType::WirePacket: {
            auto service = session_->service();
            service->handle_entry(SessionRef(session_), std::move(e), Responder());
            return;
        }
        default: break;
    }
    if (!request) return;
    if (service_name_of(e.service_path) != session_->service()->name()) {
        reply_session(error_reply(e, make_error(MessageErrorType::ServiceNotFound, "Service \"" +
                                                                              std::string(service_name_of(e.service_path)) +
                                                                              "\" is not this session's service")));
        return;
    }
    if (session_->service()->requires_authentication() && !authenticated_) {
        // CORE (ServerContext::ProcessMessageEntry, requirevaliduser): PermissionDenied until the user logs in.
        reply_session(error_reply(e, make_error(MessageErrorType::PermissionDenied,
                                                "User must authenticate before accessing this service")));
        return;
    }
    auto service = session_->service();
    Responder responder = make_responder(e);
    service->handle_entry(SessionRef(session_), std::move(e), std::move(responder));
}

void ServerConnection::handle_session_op(MessageEntry&& e, MonoTime now) {
    MessageEntry r = reply_to(e);
    const std::string& op = e.member_name;
    auto service = session_->service();
    if (op == "AuthenticateUser") {
        const MessageElement* user = e.find("username");
        const MessageElement* creds = e.find("credentials");
        if (!user || !creds || !service->requires_authentication()) {
            reply_session(error_reply(e, make_error(MessageErrorType::AuthenticationError, "Authentication Failed")));
            return;
        }
        if (auto ok = service->authenticate(std::string(read_string(*user)), creds); !ok) {
            reply_session(error_reply(e, ok.error()));
            return;
        }
        authenticated_ = true;
        session_->set_username(std::string(read_string(*user)));
        r.elements.push_back(make_string_element("return", "OK"));
        reply_session(std::move(r));
        return;
    }
    if (op == "LogoutUser") {
        authenticated_ = false;
        session_->set_username({});
        r.elements.push_back(make_string_element("return", "OK"));
        reply_session(std::move(r));
        return;
    }
    if (op == "MonitorEnter" || op == "MonitorContinueEnter" || op == "MonitorExit") {
        // Monitor locks serialise access per object; with per-call handlers there is nothing to hold,
        // so entering always succeeds at once.
        r.elements.push_back(make_string_element("return", "OK"));
        reply_session(std::move(r));
        return;
    }
    if (op == "RequestObjectLock" || op == "ReleaseObjectLock" || op == "RequestClientObjectLock" ||
        op == "ReleaseClientObjectLock") {
        if (!service->requires_authentication()) {
            reply_session(error_reply(e, make_error(MessageErrorType::InvalidOperation,
                                                    "Object locks require an authenticated service")));
            return;
        }
        // Locks go to the service, which owns the objects.
        Responder responder = make_responder(e);
        service->handle_entry(SessionRef(session_), std::move(e), std::move(responder));
        return;
    }
    reply_session(error_reply(e, make_error(MessageErrorType::InvalidOperation, "Unknown session operation \"" + op + "\"")));
    (void)now;
}

}  // namespace rr::server
