#include "core/session/service_session.hpp"

#include <utility>

#include "base/message/error_entry.hpp"
#include "base/names/service_path.hpp"
#include "core/session/elements.hpp"

namespace rr {
namespace {

// ObjectTypeName queries a client may have waiting for the service at once; more are refused, so a
// client cannot grow the table by asking faster than the service answers.
constexpr std::size_t kMaxPendingObjectTypes = 256;

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

MessageEntry error_reply(const MessageEntry& request, const RRError& error) {
    MessageEntry r = reply_to(request);
    set_entry_error(r, error);
    return r;
}

RRError service_not_found(std::string_view name) {
    // CORE's special-request path uses this non-canonical name (wire.md §5.1).
    RRError e = make_error(MessageErrorType::ServiceNotFound, "Service \"" + std::string(name) + "\" not found");
    e.name = "RobotRaconteur.ServiceNotFoundException";
    return e;
}

}  // namespace

MessageElement HostedService::attributes() const {
    MessageElement e;
    e.name = "attributes";
    e.type = DataTypes::dictionary_t;
    return e;
}

ServiceSession::ServiceSession(ServiceHost& host, ServiceSessionConfig config, MonoTime now)
    : host_(host), config_(std::move(config)), stream_(StreamRole::server, config_.stream, now) {}

ServiceSession::~ServiceSession() {
    if (service_) host_.release_endpoint(endpoint_);
    if (admission_) host_.release_endpoint(admission_->endpoint);
}

void ServiceSession::feed(std::span<const std::byte> bytes, MonoTime now) {
    (void)stream_.feed(bytes, now);  // errors close the stream; its Closed event follows
    drain_stream(now);
}

void ServiceSession::on_transport_closed(RRError error) {
    stream_.on_transport_closed(std::move(error));
    drain_stream(MonoTime{});
}

void ServiceSession::close(RRError error) {
    if (stream_.is_closed()) return;
    stream_.on_transport_closed(std::move(error));
    drain_stream(MonoTime{});
}

void ServiceSession::drain_stream(MonoTime now) {
    // Handled in place (no move per message). Handling runs no host code, so this is never re-entered
    // and the one batch vector is never in use twice; stream events queued meanwhile come next round.
    for (stream_.take_events(stream_batch_); !stream_batch_.empty(); stream_.take_events(stream_batch_)) {
        for (auto& ev : stream_batch_) {
            if (auto* m = std::get_if<StreamMessage>(&ev)) {
                on_message(std::move(m->message), now);
            } else if (auto* c = std::get_if<StreamClosed>(&ev)) {
                close_session();
                if (!closed_reported_) {
                    closed_reported_ = true;
                    events_.emplace_back(ServiceConnectionClosed{std::move(c->error)});
                }
            }
        }
    }
}

void ServiceSession::take_output(GatherBuffer& out) {
    stream_.take_output(out);
    // Held wire values go out once the backlog has been handed to the transport.
    if (!held_wires_.empty()) flush_held_wires(MonoTime{});
}

void ServiceSession::take_output(std::vector<std::byte>& out) {
    stream_.take_output(out);
    if (!held_wires_.empty()) flush_held_wires(MonoTime{});
}

std::optional<MonoTime> ServiceSession::next_deadline() const {
    auto d = stream_.next_deadline();
    for (const auto& [id, deadline] : pending_callbacks_) d = d ? std::min(*d, deadline) : deadline;
    return d;
}

void ServiceSession::on_timer(MonoTime now) {
    stream_.on_timer(now);
    for (auto it = pending_callbacks_.begin(); it != pending_callbacks_.end();) {
        if (now >= it->second) {
            events_.emplace_back(std::in_place_type<ServiceCallbackResponse>, it->first,
                                 fail(MessageErrorType::RequestTimeout, "callback timed out"));
            it = pending_callbacks_.erase(it);
        } else {
            ++it;
        }
    }
    drain_stream(now);
}

std::optional<ServiceSessionEvent> ServiceSession::poll_event() {
    return events_.pop();
}

void ServiceSession::take_events(std::vector<ServiceSessionEvent>& batch) { events_.take_all(batch); }

void ServiceSession::close_session(std::uint64_t disconnect_token) {
    for (auto& [id, deadline] : pending_callbacks_)
        events_.emplace_back(std::in_place_type<ServiceCallbackResponse>, id,
                             fail(MessageErrorType::ConnectionError, "client disconnected"));
    pending_callbacks_.clear();
    pending_object_types_.clear();
    held_wires_.clear();
    if (admission_) {
        host_.release_endpoint(admission_->endpoint);  // a late answer_admission() returns false
        admission_.reset();
    }
    if (!service_) return;
    auto service = std::move(service_);
    service_.reset();
    host_.release_endpoint(endpoint_);
    events_.emplace_back(ServiceSessionClosed{std::move(service), endpoint_, disconnect_token});
    endpoint_ = 0;
    client_endpoint_ = 0;
    authenticated_ = false;
    username_.clear();
}

Message ServiceSession::session_header(const MessageEntry& entry) {
    ++messages_out_;
    Message m;
    m.version = 2;
    m.header.sender_node_id = config_.stream.local_node_id;
    m.header.receiver_node_id = stream_.negotiated().remote_node_id;
    m.header.sender_endpoint = endpoint_;
    m.header.receiver_endpoint = client_endpoint_;
    m.header.message_id = ++message_id_;
    if (entry.metadata == "unreliable\n") m.header.metadata = entry.metadata;
    return m;
}

Message ServiceSession::session_message(MessageEntry&& entry) {
    Message m = session_header(entry);
    m.entries = stream_.entry_vectors().take();
    m.entries.push_back(std::move(entry));
    return m;
}

void ServiceSession::reply(MessageEntry&& entry, MonoTime now) {
    if (!service_ || stream_.is_closed()) return;
    // Encoded where it is (not moved into a Message); its element vector is kept for a later reply.
    auto sent = stream_.send(session_header(entry), entry, now);
    if (sent) {
        stream_.entry_vectors().give_elements(std::move(entry.elements));
        return;
    }
    // A reply must not vanish: answer with the error instead (e.g. over the size limit).
    MessageEntry header;
    header.entry_type = entry.entry_type;
    header.service_path = std::move(entry.service_path);
    header.member_name = std::move(entry.member_name);
    header.request_id = entry.request_id;
    set_entry_error(header, sent.error());
    (void)stream_.send(session_message(std::move(header)), now);
}

Result<void> ServiceSession::send(MessageEntry entry, MonoTime now) {
    if (!service_ || stream_.is_closed()) return fail(MessageErrorType::InvalidState, "client session closed");
    return stream_.send(session_message(std::move(entry)), now);
}

Result<void> ServiceSession::send(const EncodedEntry& entry, MonoTime now) {
    if (!service_ || stream_.is_closed()) return fail(MessageErrorType::InvalidState, "client session closed");
    return stream_.send(session_header(entry.entry()), entry, now);
}

void ServiceSession::send_wire_packet(MessageEntry entry, MonoTime now) {
    if (!service_ || stream_.is_closed()) return;
    if (stream_.pending_output_size() > config_.wire_hold_bytes) {
        WireKey key(entry.service_path, entry.member_name);
        held_wires_.insert_or_assign(std::move(key), HeldWire(std::in_place_type<MessageEntry>, std::move(entry)));
        return;  // newest kept until the output drains
    }
    (void)stream_.send(session_message(std::move(entry)), now);
}

void ServiceSession::send_wire_packet(std::shared_ptr<const EncodedEntry> entry, MonoTime now) {
    if (!service_ || stream_.is_closed() || !entry) return;
    if (stream_.pending_output_size() > config_.wire_hold_bytes) {
        WireKey key(entry->entry().service_path, entry->entry().member_name);
        held_wires_.insert_or_assign(std::move(key), HeldWire(std::move(entry)));
        return;
    }
    (void)stream_.send(session_header(entry->entry()), *entry, now);
}

void ServiceSession::flush_held_wires(MonoTime now) {
    if (!service_) return;
    auto held = std::move(held_wires_);
    held_wires_.clear();
    for (auto& [key, packet] : held) {
        if (auto* own = std::get_if<MessageEntry>(&packet))
            (void)stream_.send(session_message(std::move(*own)), now);
        else if (const auto& shared = std::get<std::shared_ptr<const EncodedEntry>>(packet))
            (void)stream_.send(session_header(shared->entry()), *shared, now);
    }
}

Result<std::uint32_t> ServiceSession::request(MessageEntry entry, MonoTime now) {
    if (!service_ || stream_.is_closed()) return fail(MessageErrorType::ConnectionError, "client session closed");
    if (++callback_request_counter_ == 0) ++callback_request_counter_;
    const std::uint32_t id = callback_request_counter_;
    entry.request_id = id;
    if (auto r = stream_.send(session_message(std::move(entry)), now); !r) return r.take_error();
    pending_callbacks_[id] = now + config_.callback_timeout;
    return id;
}

void ServiceSession::answer_object_type(std::uint64_t token, Result<ObjectTypeInfo> info, MonoTime now) {
    auto it = pending_object_types_.find(token);
    if (it == pending_object_types_.end()) return;
    PendingObjectType p = std::move(it->second);
    pending_object_types_.erase(it);
    if (stream_.is_closed()) return;
    if (!info) {
        set_entry_error(p.reply, info.error());
    } else {
        p.reply.elements.push_back(make_string_element("objecttype", info->object_type));
        if (!info->implements.empty()) p.reply.elements.push_back(make_string_list("objectimplements", info->implements));
    }
    reply_special(p.header, std::move(p.reply), now);
}

void ServiceSession::reply_special(const MessageHeader& request_header, MessageEntry reply, MonoTime now) {
    Message m;
    m.version = 2;
    m.header.sender_node_id = config_.stream.local_node_id;
    m.header.sender_node_name = config_.stream.local_node_name;
    m.header.receiver_node_id = request_header.sender_node_id;
    m.header.receiver_node_name = request_header.sender_node_name;
    m.header.sender_endpoint = endpoint_;
    m.header.receiver_endpoint = request_header.sender_endpoint;
    m.header.message_id = ++message_id_;
    ++messages_out_;
    m.entries.push_back(std::move(reply));
    (void)stream_.send(m, now);
}

void ServiceSession::on_message(Message&& m, MonoTime now) {
    ++messages_in_;
    // A request alone in its message takes the message's vector with it (queue_request).
    lone_entry_ = m.entries.size() == 1 ? &m.entries : nullptr;
    on_entries(m, now);
    lone_entry_ = nullptr;
    stream_.entry_vectors().give(std::move(m.entries));
}

void ServiceSession::on_entries(Message& m, MonoTime now) {
    for (auto& e : m.entries) {
        if (stream_.is_closed()) return;
        const auto type = e.entry_type;
        const bool special = is_special_request(type) &&
                             !(type == MessageEntryType::ObjectTypeName && m.header.receiver_endpoint != 0);
        if (special)
            handle_special(m.header, std::move(e), now);
        else
            handle_session_entry(m.header, std::move(e), now);
    }
}

void ServiceSession::handle_special(const MessageHeader& h, MessageEntry&& e, MonoTime now) {
    if (!is_request(e.entry_type)) return;  // special replies carry nothing for a service
    if (!h.receiver_node_id.is_any() && h.receiver_node_id != config_.stream.local_node_id) {
        reply_special(h, error_reply(e, make_error(MessageErrorType::NodeNotFound, "Could not find route to remote node")),
                      now);
        return;
    }
    switch (e.entry_type) {
        case MessageEntryType::GetServiceDesc: get_service_desc(h, std::move(e), now); return;
        case MessageEntryType::ObjectTypeName: object_type_name(h, std::move(e), now); return;
        case MessageEntryType::ConnectClient: connect_client(h, std::move(e), false, now); return;
        case MessageEntryType::ConnectClientCombined: connect_client(h, std::move(e), true, now); return;
        case MessageEntryType::DisconnectClient: {
            MessageEntry r = reply_to(e);
            if (service_ && service_->admits_sessions()) {
                // The service ends the session itself (the gateway's passthrough mirror closes the
                // device's session first): CORE answers DisconnectClient only after RemoveClient, so
                // a client whose DisconnectService returned finds the session's locks gone.
                disconnect_ = PendingDisconnect{++disconnect_counter_, h, std::move(r)};
                close_session(disconnect_->token);
                return;
            }
            close_session();
            reply_special(h, std::move(r), now);
            return;
        }
        case MessageEntryType::GetNodeInfo: reply_special(h, reply_to(e), now); return;
        case MessageEntryType::NodeCheckCapability: {
            MessageEntry r = reply_to(e);
            r.elements.push_back(make_scalar_element<std::uint32_t>("return", 0));
            reply_special(h, std::move(r), now);
            return;
        }
        case MessageEntryType::GetServiceAttributes: {
            auto service = host_.hosted_service(e.service_path);
            if (!service) {
                reply_special(h, error_reply(e, make_error(MessageErrorType::ServiceError, "Service not found")), now);
                return;
            }
            MessageEntry r = reply_to(e);
            MessageElement attrs = service->attributes();
            attrs.name = "return";
            r.elements.push_back(std::move(attrs));
            reply_special(h, std::move(r), now);
            return;
        }
        default:
            reply_special(h, error_reply(e, make_error(MessageErrorType::ProtocolError, "Invalid Special Operation")), now);
            return;
    }
}

void ServiceSession::get_service_desc(const MessageHeader& h, MessageEntry&& e, MonoTime now) {
    auto service = host_.hosted_service(e.service_path);
    if (!service) {
        reply_special(h, error_reply(e, service_not_found(e.service_path)), now);
        return;
    }
    const MessageElement* type = e.find("ServiceType");
    if (!type) type = e.find("servicetype");
    MessageEntry r = reply_to(e);
    if (type) {
        auto def = service->service_definition(read_string(*type));
        if (!def) {
            reply_special(h,
                          error_reply(e, make_error(MessageErrorType::ServiceNotFound, "Service definition \"" +
                                                                                         std::string(read_string(*type)) +
                                                                                         "\" not found")),
                          now);
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
    reply_special(h, std::move(r), now);
}

void ServiceSession::object_type_name(const MessageHeader& h, MessageEntry&& e, MonoTime now) {
    const std::string_view name = service_name_of(e.service_path);
    auto service = host_.hosted_service(name);
    if (!service) {
        reply_special(h, error_reply(e, service_not_found(name)), now);
        return;
    }
    if (pending_object_types_.size() >= kMaxPendingObjectTypes) {
        reply_special(h, error_reply(e, make_error(MessageErrorType::BufferLimitViolation, "too many ObjectTypeName requests waiting")),
                      now);
        return;
    }
    const std::uint64_t token = ++object_type_counter_;
    pending_object_types_.emplace(token, PendingObjectType{h, reply_to(e)});
    events_.emplace_back(ServiceObjectTypeQuery{token, std::move(service), std::move(e.service_path)});
}

void ServiceSession::connect_client(const MessageHeader& h, MessageEntry&& e, bool combined, MonoTime now) {
    if (service_ || admission_) {
        reply_special(h, error_reply(e, make_error(MessageErrorType::InvalidOperation, "Already connected")), now);
        return;
    }
    auto service = host_.hosted_service(e.service_path);
    if (!service) {
        reply_special(h, error_reply(e, service_not_found(e.service_path)), now);
        return;
    }
    const MessageElement* ret = e.find("returnservicedefs");
    const std::string_view want = ret ? read_string(*ret) : std::string_view("true");
    const bool return_defs = want != "false" && want != "0";
    if (service->admits_sessions()) {
        if (h.sender_endpoint == 0) {
            reply_special(h, error_reply(e, make_error(MessageErrorType::InvalidEndpoint, "client endpoint 0")), now);
            return;
        }
        PendingAdmission p;
        p.token = ++admission_counter_;
        p.header = h;
        p.reply = reply_to(e);
        p.combined = combined;
        p.return_defs = return_defs;
        p.service = service;
        p.endpoint = host_.allocate_endpoint();
        ServiceAdmission ev{p.token, service, p.endpoint, {}, std::nullopt};
        if (combined) {
            if (const auto* user = e.find("username")) ev.username = p.username = std::string(read_string(*user));
            if (const auto* creds = e.find("credentials")) ev.credentials = *creds;
        }
        admission_ = std::move(p);
        events_.emplace_back(std::move(ev));
        return;
    }
    std::string username;
    bool authenticated = false;
    // A browser that logged in to the web page: its session cookie came with the rr+ws upgrade.
    bool web = false;
    if (!config_.web_login.empty() && service->requires_authentication() && !e.find("username") && !e.find("credentials")) {
        if (auto name = service->authenticate_web(config_.web_login)) {
            username = std::move(*name);
            authenticated = true;
            web = true;
        }
    }
    if (combined && !web) {
        const MessageElement* user = e.find("username");
        const MessageElement* creds = e.find("credentials");
        // CORE RobotRaconteurNode (ConnectClientCombined): the same error types; the message keeps the
        // reason where CORE says only "Authentication Failed" (docs/security.md, differences).
        const char* refused = nullptr;
        if (!service->requires_authentication()) {
            if (user && creds) refused = "Authentication not enabled for service";
        } else if (!user) {
            refused = "Username not provided";
        } else if (!creds) {
            refused = "Credentials not provided";
        }
        if (refused) {
            reply_special(h, error_reply(e, make_error(MessageErrorType::AuthenticationError, refused)), now);
            return;
        }
        if (service->requires_authentication()) {
            username = std::string(read_string(*user));
            if (auto ok = service->authenticate_from(username, creds, config_.peer); !ok) {
                reply_special(h, error_reply(e, ok.error()), now);
                return;
            }
            authenticated = true;
        }
    }
    if (h.sender_endpoint == 0) {
        reply_special(h, error_reply(e, make_error(MessageErrorType::InvalidEndpoint, "client endpoint 0")), now);
        return;
    }
    open_session(h, reply_to(e), combined, return_defs, std::move(service), host_.allocate_endpoint(), std::move(username),
                 authenticated, now);
}

bool ServiceSession::answer_admission(std::uint64_t token, Result<void> outcome, MonoTime now) {
    if (!admission_ || admission_->token != token || stream_.is_closed()) return false;
    PendingAdmission p = std::move(*admission_);
    admission_.reset();
    if (!outcome) {
        host_.release_endpoint(p.endpoint);
        set_entry_error(p.reply, outcome.error());
        reply_special(p.header, std::move(p.reply), now);
        return true;
    }
    open_session(p.header, std::move(p.reply), p.combined, p.return_defs, std::move(p.service), p.endpoint,
                 std::move(p.username), true, now);
    return true;
}

bool ServiceSession::answer_disconnect(std::uint64_t token, MonoTime now) {
    if (!disconnect_ || disconnect_->token != token || stream_.is_closed()) return false;
    PendingDisconnect p = std::move(*disconnect_);
    disconnect_.reset();
    reply_special(p.header, std::move(p.reply), now);
    return true;
}

void ServiceSession::open_session(const MessageHeader& h, MessageEntry reply, bool combined, bool return_defs,
                                  std::shared_ptr<HostedService> service, std::uint32_t endpoint, std::string username,
                                  bool authenticated, MonoTime now) {
    service_ = service;
    endpoint_ = endpoint;
    client_endpoint_ = h.sender_endpoint;
    username_ = username;
    authenticated_ = authenticated;
    stream_.set_session_established(endpoint_, client_endpoint_);

    MessageEntry r = std::move(reply);
    if (combined) {
        auto type = service->root_type();
        r.elements.push_back(make_string_element("objecttype", type.object_type));
        if (!type.implements.empty()) r.elements.push_back(make_string_list("objectimplements", type.implements));
        if (return_defs) r.elements.push_back(make_string_list("servicedefs", service->service_definitions()));
        MessageElement attrs = service->attributes();
        attrs.name = "attributes";
        r.elements.push_back(std::move(attrs));
    }
    reply_special(h, std::move(r), now);
    events_.emplace_back(ServiceSessionOpened{std::move(service), endpoint_, client_endpoint_, std::move(username)});
}

void ServiceSession::handle_session_entry(const MessageHeader& h, MessageEntry&& e, MonoTime now) {
    const bool request = is_request(e.entry_type);
    if (!service_ || h.receiver_endpoint != endpoint_) {
        if (request && e.entry_type != MessageEntryType::PipePacket && e.entry_type != MessageEntryType::WirePacket)
            reply_special(h, error_reply(e, make_error(MessageErrorType::InvalidEndpoint, "Invalid destination endpoint")), now);
        return;
    }
    switch (e.entry_type) {
        case MessageEntryType::EndpointCheckCapability:
        case MessageEntryType::ServiceCheckCapabilityReq: {
            MessageEntry r = reply_to(e);
            r.elements.push_back(make_scalar_element<std::uint32_t>("return", 0));
            reply(std::move(r), now);
            return;
        }
        case MessageEntryType::ClientKeepAliveReq: reply(reply_to(e), now); return;
        case MessageEntryType::ClientSessionOpReq: handle_session_op(std::move(e), now); return;
        case MessageEntryType::ObjectTypeName: handle_special(h, std::move(e), now); return;
        case MessageEntryType::CallbackCallRet: {
            auto it = pending_callbacks_.find(e.request_id);
            if (it == pending_callbacks_.end()) return;
            pending_callbacks_.erase(it);
            const std::uint32_t id = e.request_id;
            events_.emplace_back(std::in_place_type<ServiceCallbackResponse>, id, std::move(e));
            return;
        }
        case MessageEntryType::PipePacket:
        case MessageEntryType::PipePacketRet:
        case MessageEntryType::WirePacket: queue_request(std::move(e), false); return;
        default: break;
    }
    if (!request) return;
    if (service_name_of(e.service_path) != service_->name()) {
        reply(error_reply(e, make_error(MessageErrorType::ServiceNotFound,
                                        "Service \"" + std::string(service_name_of(e.service_path)) +
                                            "\" is not this session's service")),
              now);
        return;
    }
    if (service_->requires_authentication() && !authenticated_) {
        // CORE (ServerContext::ProcessMessageEntry, requirevaliduser): PermissionDenied until the user logs in.
        reply(error_reply(e, make_error(MessageErrorType::PermissionDenied, "User must authenticate before accessing this service")),
              now);
        return;
    }
    if (e.elements.capacity() == 0) e.elements = stream_.entry_vectors().take_elements();  // room for the reply
    queue_request(std::move(e), true);
}

void ServiceSession::queue_request(MessageEntry&& e, bool needs_reply) {
    if (lone_entry_ && lone_entry_->size() == 1 && &lone_entry_->front() == &e) {
        // The message's own vector goes with the request (on_entries' loop has no entry after this one).
        auto* holder = std::exchange(lone_entry_, nullptr);
        events_.emplace_back(std::in_place_type<ServiceRequest>, std::move(*holder), needs_reply);
        return;
    }
    auto holder = stream_.entry_vectors().take();
    holder.push_back(std::move(e));
    events_.emplace_back(std::in_place_type<ServiceRequest>, std::move(holder), needs_reply);
}

void ServiceSession::handle_session_op(MessageEntry&& e, MonoTime now) {
    MessageEntry r = reply_to(e);
    const std::string& op = e.member_name;
    if ((op == "AuthenticateUser" || op == "LogoutUser") && service_->admits_sessions()) {
        queue_request(std::move(e), true);  // the service's own login (passthrough)
        return;
    }
    if (op == "AuthenticateUser") {
        const MessageElement* user = e.find("username");
        const MessageElement* creds = e.find("credentials");
        if (!user || !creds || !service_->requires_authentication()) {
            reply(error_reply(e, make_error(MessageErrorType::AuthenticationError, "Authentication Failed")), now);
            return;
        }
        std::string name(read_string(*user));
        if (auto ok = service_->authenticate_from(name, creds, config_.peer); !ok) {
            reply(error_reply(e, ok.error()), now);
            return;
        }
        authenticated_ = true;
        username_ = name;
        events_.emplace_back(ServiceSessionUser{std::move(name)});
        r.elements.push_back(make_string_element("return", "OK"));
        reply(std::move(r), now);
        return;
    }
    if (op == "LogoutUser") {
        authenticated_ = false;
        username_.clear();
        events_.emplace_back(ServiceSessionUser{});
        r.elements.push_back(make_string_element("return", "OK"));
        reply(std::move(r), now);
        return;
    }
    const bool monitor_op = op == "MonitorEnter" || op == "MonitorContinueEnter" || op == "MonitorExit";
    const bool lock_op = op == "RequestObjectLock" || op == "ReleaseObjectLock" || op == "RequestClientObjectLock" ||
                         op == "ReleaseClientObjectLock";
    if ((monitor_op || lock_op) && service_->handles_locks()) {
        // CORE ServerContext::ClientLockOp: the service owns the objects and their locks.
        queue_request(std::move(e), true);
        return;
    }
    if (monitor_op) {
        // A service without locks of its own (the gateway's mirror today): entering succeeds at once
        // and locks nothing.
        r.elements.push_back(make_string_element("return", "OK"));
        reply(std::move(r), now);
        return;
    }
    if (lock_op) {
        reply(error_reply(e, make_error(MessageErrorType::InvalidOperation, "Object locks are not supported by this service")),
              now);
        return;
    }
    reply(error_reply(e, make_error(MessageErrorType::InvalidOperation, "Unknown session operation \"" + op + "\"")), now);
}

}  // namespace rr
