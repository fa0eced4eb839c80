#include "server/gateway/mirror_service.hpp"

#include "base/message/error_entry.hpp"
#include "base/names/service_path.hpp"
#include "core/session/elements.hpp"
#include "robdef/parser.hpp"
#include "server/gateway/pipe_entries.hpp"

namespace rr::server::gateway {
namespace {

RRError not_connected(const std::string& device) {
    return make_error(MessageErrorType::ConnectionError, "device \"" + device + "\" is not connected");
}

void set_index(MessageEntry& e, std::int32_t idx) {
    for (auto& el : e.elements)
        if (!el.number && el.name == "index") {
            el = make_scalar_element<std::int32_t>("index", idx);
            return;
        }
    e.elements.push_back(make_scalar_element<std::int32_t>("index", idx));
}

}  // namespace

MirrorService::MirrorService(std::weak_ptr<DeviceMirror> mirror, std::shared_ptr<DeviceCounters> counters, std::string name,
                             std::string upstream_service)
    : mirror_(std::move(mirror)),
      counters_(std::move(counters)),
      name_(std::move(name)),
      upstream_service_(std::move(upstream_service)) {
    // The shared session's pipe endpoints reach the device through the mirror's upstream client: no
    // reference to this service, which they may outlive inside a completion.
    SessionEndpoints::Upstream up;
    auto client = [mirror = mirror_] {
        auto m = mirror.lock();
        return m ? m->upstream() : nullptr;
    };
    up.request = [client, name = name_, upstream = upstream_service_](MessageEntry e,
                                                                       std::function<void(Result<MessageEntry>)> done) {
        auto c = client();
        if (!c) return done(fail(not_connected(name)));
        e.service_path = replace_service_name(e.service_path, upstream);
        c->request(std::move(e), std::move(done));
    };
    up.send = [client, name = name_, upstream = upstream_service_, counters = counters_](MessageEntry e) -> Result<void> {
        auto c = client();
        if (!c) return fail(not_connected(name));
        if (e.entry_type == MessageEntryType::PipePacket) counters->pipe_packets.fetch_add(1);
        e.service_path = replace_service_name(e.service_path, upstream);
        c->send(std::move(e));
        return {};
    };
    up.queued_bytes = [client]() -> std::size_t {
        auto c = client();
        return c ? c->queued_bytes() : 0;
    };
    shared_endpoints_ = std::make_shared<SessionEndpoints>(std::move(up));
}

void MirrorService::set_locks_listener(std::function<void()> listener) { locks_->set_on_change(std::move(listener)); }

std::string MirrorService::to_upstream(std::string_view path) const { return replace_service_name(path, upstream_service_); }
std::string MirrorService::to_downstream(std::string_view path) const { return replace_service_name(path, name_); }

std::shared_ptr<RawClient> MirrorService::client() const {
    auto m = mirror_.lock();
    return m ? m->upstream() : nullptr;
}

std::vector<std::string> MirrorService::service_definitions() const {
    auto m = mirror_.lock();
    return m ? m->service_definitions() : std::vector<std::string>{};
}

std::optional<std::string> MirrorService::service_definition(std::string_view service_type) const {
    for (auto& text : service_definitions()) {
        auto parsed = robdef::parse_service_definition(text, "");
        if (parsed && parsed->definition.name == service_type) return text;
    }
    return std::nullopt;
}

ObjectTypeInfo MirrorService::root_type() const {
    auto m = mirror_.lock();
    return m ? m->root_type() : ObjectTypeInfo{};
}

MessageElement MirrorService::attributes() const {
    if (auto m = mirror_.lock())
        if (auto a = m->attributes(); a.type == DataTypes::dictionary_t) return a;
    return Service::attributes();
}

void MirrorService::object_type(const SessionRef& session, const std::string& path,
                                std::function<void(Result<ObjectTypeInfo>)> done) {
    if (path == name_) {
        done(root_type());
        return;
    }
    auto c = client();
    if (!c) {
        done(fail(not_connected(name_)));
        return;
    }
    MessageEntry e;
    e.entry_type = MessageEntryType::ObjectTypeName;
    e.service_path = to_upstream(path);
    e.elements.push_back(make_string_element("clientversion", "1.2.8"));
    c->request(std::move(e), [done = std::move(done)](Result<MessageEntry> r) {
        if (!r) {
            done(r.take_error());
            return;
        }
        if (auto err = entry_error(*r)) {
            done(fail(*err));
            return;
        }
        ObjectTypeInfo info;
        if (const auto* t = r->find("objecttype")) info.object_type = std::string(read_string(*t));
        if (const auto* i = r->find("objectimplements"))
            for (const auto& item : i->elements) info.implements.emplace_back(read_string(item));
        done(std::move(info));
    });
}

void MirrorService::on_session_open(const SessionRef& session) {
    {
        std::lock_guard lock(mutex_);
        sessions_.push_back(session);
    }
    if (passthrough_) passthrough_->attach(session);
}

MotionClient MirrorService::motion_client(const SessionRef& session, bool passthrough) {
    MotionClient c;
    c.key = "rr:" + std::to_string(session.endpoint());
    c.user = session.username();
    const std::string peer = session.peer();
    c.description = "RR session from " + (peer.empty() ? std::string("an unknown address") : peer);
    if (passthrough) c.device_session = session.endpoint();
    c.liveness = [session](std::optional<std::chrono::milliseconds> timeout) { session.set_liveness_probe(timeout); };
    return c;
}

void MirrorService::on_session_close(const SessionRef& session) {
    if (passthrough_) {
        end_session(session, {});
        return;
    }
    // What it started without a timeout of its own ends with it (motion safety).
    if (motion_) motion_->client_gone(motion_client(session, false).key);
    drop_session_state(session.endpoint());
    // Its client locks and monitors go; its user's user locks with the user's last session here.
    const std::string user = session.username();
    bool last_of_user = true;
    {
        std::lock_guard lock(mutex_);
        for (const auto& s : sessions_)
            if (!user.empty() && s.username() == user) last_of_user = false;
    }
    locks_->session_closed(session.endpoint(), user, last_of_user);
}

void MirrorService::end_session(const SessionRef& session, std::function<void()> ended) {
    if (!passthrough_) {
        Service::end_session(session, std::move(ended));  // the gateway's own locks: gone at once
        return;
    }
    drop_session_state(session.endpoint());
    // The motion guard's stops go on the client's own upstream session (its device locks are still
    // held there) before that session closes.
    auto close = [p = passthrough_, endpoint = session.endpoint(), ended = std::move(ended)]() mutable {
        p->close(endpoint, std::move(ended));
    };
    if (!motion_) return close();
    motion_->client_gone(motion_client(session, true).key, std::move(close));
}

void MirrorService::admit_session(std::uint32_t endpoint, std::string username, std::optional<MessageElement> credentials,
                                  std::function<void(Result<void>)> done) {
    if (!passthrough_) {
        Service::admit_session(endpoint, std::move(username), std::move(credentials), std::move(done));
        return;
    }
    passthrough_->admit(endpoint, std::move(username), std::move(credentials), std::move(done));
}

void MirrorService::abandon_admission(std::uint32_t endpoint) {
    if (passthrough_) passthrough_->close(endpoint);
}

void MirrorService::check_passthrough_deliveries() {
    if (!passthrough_) return;
    if (!access_.active()) return passthrough_->set_delivery_check({});
    passthrough_->set_delivery_check([access = access_](const SessionRef& session, const MessageEntry& entry) {
        const auto op = entry.entry_type == MessageEntryType::CallbackCallReq ? auth::Operation::call : auth::Operation::read;
        return access.may(session, entry.service_path, entry.member_name, op);
    });
}

void MirrorService::stop_passthrough() {
    if (passthrough_) passthrough_->close_all();
}

std::size_t MirrorService::session_count() const {
    std::lock_guard lock(mutex_);
    return sessions_.size();
}

void MirrorService::drop_session_state(std::uint32_t endpoint) {
    std::vector<MessageEntry> to_device;
    disconnect_upstream_wires(subscriptions_.leave_all(endpoint));
    {
        std::lock_guard lock(mutex_);
        std::erase_if(sessions_, [&](const SessionRef& s) { return s.endpoint() == endpoint; });
        for (auto it = pipes_by_downstream_.begin(); it != pipes_by_downstream_.end();) {
            if (std::get<0>(it->first) != endpoint) {
                ++it;
                continue;
            }
            const auto& [ep, path, member, d] = it->first;
            to_device.push_back(pipe_disconnect_request(to_upstream(path), member, it->second));
            pipes_by_upstream_.erase({path, member, it->second});
            it = pipes_by_downstream_.erase(it);
        }
        std::erase_if(generators_, [&](const auto& g) { return g.first == endpoint; });
    }
    if (auto c = client())
        for (auto& e : to_device) c->request(std::move(e), [](Result<MessageEntry>) {});
}

bool MirrorService::requires_authentication() const { return access_.active(); }

Result<void> MirrorService::authenticate(const std::string& username, const MessageElement* credentials) {
    return authenticate_from(username, credentials, {});
}

Result<void> MirrorService::authenticate_from(const std::string& username, const MessageElement* credentials,
                                              std::string_view peer) {
    if (!access_.active()) return fail(MessageErrorType::AuthenticationError, "Authentication Failed");
    auto who = access_.auth()->login_rr(username, credentials, peer);
    if (!who) return who.take_error();
    return {};
}

Result<std::string> MirrorService::authenticate_web(std::string_view web_login) {
    if (!access_.active()) return fail(MessageErrorType::AuthenticationError, "Authentication Failed");
    return access_.auth()->web_rr_user(web_login);
}

void MirrorService::handle_entry(const SessionRef& session, MessageEntry&& entry, Responder responder) {
    auto mirror = mirror_.lock();
    if (!mirror) return;
    // The gateway's roles (gateway.auth), on shared and passthrough devices alike: a passthrough device
    // checked the client's password, the roles still apply to that user name, so a device without logins
    // of its own is not open to anyone. Packets (pipe, wire) have no reply: dropped.
    if (auto denied = access_.check(session, entry)) {
        if (!responder.done()) responder.fail(std::move(*denied));
        return;
    }
    // Motion safety: a hold-to-run call's timeout clamped, another client's motion refused while one
    // holds (a refused packet is dropped), stops through every lock.
    ReplyObserver observe;
    bool stop = false;
    if (motion_ && motion_->concerns(entry)) {
        const MotionClient who = motion_client(session, passthrough_ != nullptr);
        auto ticket = motion_->admit(who, entry);
        if (!ticket) {
            if (!responder.done()) responder.fail(ticket.error());
            return;
        }
        stop = ticket->kind == MotionGuard::Ticket::Kind::stop;
        if (ticket->kind != MotionGuard::Ticket::Kind::pass && !stop)
            observe = [guard = motion_, who, t = *ticket](const Result<MessageEntry>& r) { guard->on_reply(who, t, r); };
    }
    if (passthrough_) {
        passthrough_->handle_entry(session, std::move(entry), std::move(responder), std::move(observe), stop);
        return;
    }
    if (entry.entry_type == MessageEntryType::ClientSessionOpReq) {
        lock_op(session, std::move(entry), std::move(responder));
        return;
    }
    const auto type = entry.entry_type;
    const bool packet = type == MessageEntryType::PipePacket || type == MessageEntryType::PipePacketRet ||
                        type == MessageEntryType::WirePacket;
    // A stop passes every lock held at the gateway (docs/security.md "Motion safety").
    if (!packet && !stop && locks_->any()) {  // while nothing is locked: no username copy per request
        // Locks held at the gateway bind every member request, as ObjectService's do; packets on
        // connections opened before a lock pass (CORE checks requests only).
        auto ok = locks_->check(entry.service_path, ServiceLocks::Requester{session.endpoint(), session.username()}, false);
        if (!ok && ok.error().type == MessageErrorType::ObjectLockedError) {
            recheck_nolock(session, std::move(entry), std::move(responder), std::move(observe));
            return;
        }
        if (!ok) {
            if (observe) observe(fail(ok.error()));
            responder.fail(ok.error());
            return;
        }
    }
    dispatch_shared(session, std::move(entry), std::move(responder), std::move(observe));
}

void MirrorService::dispatch_shared(const SessionRef& session, MessageEntry&& entry, Responder responder, ReplyObserver observe) {
    switch (entry.entry_type) {
        case MessageEntryType::WireConnectReq: wire_connect(session, std::move(entry), std::move(responder)); return;
        case MessageEntryType::WireDisconnectReq: wire_disconnect(session, std::move(entry), std::move(responder)); return;
        case MessageEntryType::PipeConnectReq: pipe_connect(session, std::move(entry), std::move(responder)); return;
        case MessageEntryType::PipeDisconnectReq: pipe_disconnect(session, std::move(entry), std::move(responder)); return;
        case MessageEntryType::PipePacket:
        case MessageEntryType::PipePacketRet: pipe_packets_from_client(session, std::move(entry)); return;
        case MessageEntryType::WirePacket: {
            // A client's OutValue is the device's InValue, passed on as it is; only on a wire this client
            // connected (the upstream connection is the gateway's, so an unconnected client's packet
            // would otherwise pass a lock taken after it).
            if (!subscriptions_.has_session({entry.service_path, entry.member_name}, session)) return;
            if (auto c = client()) {
                entry.service_path = to_upstream(entry.service_path);
                c->send(std::move(entry));
            }
            return;
        }
        case MessageEntryType::GeneratorNextReq: {
            std::int32_t idx = entry_pipe_index(entry);
            bool owned;
            {
                std::lock_guard lock(mutex_);
                owned = generators_.count({session.endpoint(), idx}) != 0;
            }
            if (!owned) {
                responder.fail(make_error(MessageErrorType::InvalidOperation, "generator index not owned by this client"));
                return;
            }
            forward(session, std::move(entry), std::move(responder), std::move(observe));
            return;
        }
        default: forward(session, std::move(entry), std::move(responder), std::move(observe)); return;
    }
}

// --- locks held at the gateway (auth: shared) ---------------------------------------------------------

ServiceLocks::Privileges MirrorService::privileges(const std::string& user) const {
    if (user.empty() || !access_.active()) return {};
    auto who = access_.auth()->principal_for_user(user);
    if (!who) return {};
    return ServiceLocks::Privileges{who->has_privilege("objectlock"), who->has_privilege("objectlockoverride")};
}

void MirrorService::lock_op(const SessionRef& session, MessageEntry&& entry, Responder responder) {
    const std::string user = session.username();
    const auto granted = privileges(user);
    if (auto ok = ServiceLocks::check_privileges(entry.member_name, user, granted); !ok) {
        responder.fail(ok.error());
        return;
    }
    ServiceLocks::Requester who{session.endpoint(), user};
    if (entry.service_path == name_) {
        locks_->handle_op(who, granted, entry, std::move(responder));
        return;
    }
    // An object below the root must exist on the device (its ObjectNotFound otherwise), as our
    // ObjectService resolves the path before locking it.
    auto shared = std::make_shared<Responder>(std::move(responder));
    auto op = std::make_shared<MessageEntry>(std::move(entry));
    auto self = shared_from_this();
    object_type(session, op->service_path, [self, who, granted, op, shared](Result<ObjectTypeInfo> r) {
        if (!r) {
            shared->fail(r.error());
            return;
        }
        self->locks_->handle_op(who, granted, *op, std::move(*shared));
    });
}

void MirrorService::recheck_nolock(const SessionRef& session, MessageEntry&& entry, Responder responder, ReplyObserver observe) {
    auto shared = std::make_shared<Responder>(std::move(responder));
    auto request = std::make_shared<MessageEntry>(std::move(entry));
    auto self = shared_from_this();
    auto decide = [self, session, request, shared, observe = std::move(observe)](Result<ObjectTypeInfo> type) mutable {
        bool nolock = false;
        if (type) nolock = passes_object_locks(self->member_modifiers(type->object_type, request->member_name), request->entry_type);
        auto ok = self->locks_->check(request->service_path, ServiceLocks::Requester{session.endpoint(), session.username()}, nolock);
        if (!ok) {
            if (observe) observe(fail(ok.error()));
            shared->fail(ok.error());
            return;
        }
        self->dispatch_shared(session, std::move(*request), std::move(*shared), std::move(observe));
    };
    if (request->service_path == name_) {
        decide(root_type());
        return;
    }
    object_type(session, request->service_path, std::move(decide));
}

std::vector<std::string> MirrorService::member_modifiers(const std::string& type, const std::string& member) {
    auto texts = service_definitions();
    std::shared_ptr<const DeviceTypes> types;
    {
        std::lock_guard lock(mutex_);
        if (types_ && types_->texts() == texts) types = types_;
    }
    if (!types) {
        auto parsed = DeviceTypes::parse(std::move(texts));
        if (!parsed) return {};
        types = *parsed;
        std::lock_guard lock(mutex_);
        types_ = types;
    }
    auto obj = types->find_object(type);
    const auto* m = obj ? obj->entry->find_member(member) : nullptr;
    return m ? m->modifiers : std::vector<std::string>{};
}

Result<void> MirrorService::check_api_request(const std::string& path, const std::string& user, bool nolock) {
    if (passthrough_) return {};
    return locks_->check(path, ServiceLocks::Requester{0, user}, nolock);
}

std::vector<DeviceLockInfo> MirrorService::gateway_locks() const {
    std::vector<DeviceLockInfo> out;
    if (passthrough_) return out;
    for (auto& h : locks_->held()) out.push_back(DeviceLockInfo{std::move(h.path), std::move(h.username), std::move(h.kind), h.endpoint});
    return out;
}

void MirrorService::forward(const SessionRef& session, MessageEntry&& entry, Responder responder, ReplyObserver observe) {
    auto c = client();
    if (!c) {
        if (observe) observe(fail(not_connected(name_)));
        if (!responder.done()) responder.fail(not_connected(name_));
        return;
    }
    {
        std::lock_guard lock(mutex_);
        last_caller_ = session.endpoint();
    }
    const auto type = entry.entry_type;
    const auto endpoint = session.endpoint();
    const auto start = std::chrono::steady_clock::now();
    entry.service_path = to_upstream(entry.service_path);
    counters_->requests.fetch_add(1);
    auto self = shared_from_this();
    auto shared = std::make_shared<Responder>(std::move(responder));
    c->request(std::move(entry), [self, shared, type, endpoint, start, observe = std::move(observe)](Result<MessageEntry> r) {
        self->counters_->observe_latency(std::chrono::steady_clock::now() - start);
        if (observe) observe(r);
        if (!r) {
            // No answer from the device (its connection dropped, the request timed out): say which device,
            // as not_connected() does for requests made while it is down.
            self->counters_->request_errors.fetch_add(1);
            shared->fail(make_error(r.error().type, "device \"" + self->name_ + "\": " + r.error().message));
            return;
        }
        if (r->error != MessageErrorType::None) self->counters_->request_errors.fetch_add(1);
        if (type == MessageEntryType::FunctionCallReq && r->error == MessageErrorType::None && !r->find("return")) {
            if (const auto* idx = r->find("index")) {
                std::int32_t g = 0;
                if (read_scalar(*idx, g)) {
                    std::lock_guard lock(self->mutex_);
                    self->generators_.insert({endpoint, g});
                }
            }
        }
        if (type == MessageEntryType::GeneratorNextReq && r->error != MessageErrorType::None) {
            // StopIteration, close and abort end the generator (the request's index is not in the reply:
            // ownership is dropped when the session closes or the device reconnects).
        }
        shared->respond(std::move(*r));
    });
}

// --- wires -------------------------------------------------------------------------------------

void MirrorService::wire_connect(const SessionRef& session, MessageEntry&& entry, Responder responder) {
    MemberKey key{entry.service_path, entry.member_name};
    auto shared = std::make_shared<Responder>(std::move(responder));
    std::weak_ptr<MirrorService> weak = shared_from_this();
    auto joined = subscriptions_.join_wire(key, session, [shared, weak, key, session](Result<void> r) {
        if (!r) {
            shared->fail(r.error());
            return;
        }
        shared->respond(MessageEntry{});
        // The device sends a wire's value before its WireConnectRet: sent again after ours, a client
        // that took no value for a wire it had not connected yet has it (a client keeps one value per
        // timestamp, so one it took is not taken twice).
        if (auto self = weak.lock()) self->send_newest(key, session, self->subscriptions_.newest(key));
    });
    if (!joined.ready) return ensure_upstream_wire(key);
    shared->respond(MessageEntry{});
    send_newest(key, session, joined.last);
}

void MirrorService::send_newest(const MemberKey& key, const SessionRef& session, const SharedEntryPtr& newest) {
    // Under the same rule as live values: a session that may only send (auth: gateway, `write` without
    // `read`) receives no InValue, cached or not.
    if (newest && (!access_.active() || access_.may(session, key.first, key.second, auth::Operation::read)))
        (void)session.send_wire_packet(newest);
}

void MirrorService::ensure_upstream_wire(const MemberKey& key) {
    auto c = client();
    if (!c) {
        for (auto& r : subscriptions_.no_upstream(key))
            if (r) r(fail(not_connected(name_)));
        return;
    }
    if (!subscriptions_.begin_connect(key)) return;
    MessageEntry e;
    e.entry_type = MessageEntryType::WireConnectReq;
    e.service_path = to_upstream(key.first);
    e.member_name = key.second;
    auto self = shared_from_this();
    c->request(std::move(e), [self, key](Result<MessageEntry> r) {
        Result<void> outcome;
        if (!r)
            outcome = r.take_error();
        else if (auto err = entry_error(*r))
            outcome = fail(*err);
        for (auto& w : self->subscriptions_.connect_done(key, outcome))
            if (w) w(outcome);
    });
}

void MirrorService::wire_disconnect(const SessionRef& session, MessageEntry&& entry, Responder responder) {
    MemberKey key{entry.service_path, entry.member_name};
    const bool last = subscriptions_.leave_wire(key, session);
    responder.respond(MessageEntry{});
    if (last) disconnect_upstream_wires({std::move(key)});
}

void MirrorService::disconnect_upstream_wires(std::vector<MemberKey> keys) {
    if (keys.empty()) return;
    auto c = client();
    if (!c) return;
    for (auto& key : keys) {
        MessageEntry e;
        e.entry_type = MessageEntryType::WireDisconnectReq;
        e.service_path = to_upstream(key.first);
        e.member_name = std::move(key.second);
        c->request(std::move(e), [](Result<MessageEntry>) {});
    }
}

// --- pipes -------------------------------------------------------------------------------------

void MirrorService::pipe_connect(const SessionRef& session, MessageEntry&& entry, Responder responder) {
    auto c = client();
    if (!c) {
        responder.fail(not_connected(name_));
        return;
    }
    const std::string path = entry.service_path, member = entry.member_name;
    const std::int32_t wanted = entry_pipe_index(entry);
    {
        std::lock_guard lock(mutex_);
        if (wanted >= 0 && pipes_by_downstream_.count({session.endpoint(), path, member, wanted})) {
            responder.fail(make_error(MessageErrorType::InvalidArgument, "pipe endpoint index already in use"));
            return;
        }
    }
    // Upstream the gateway always lets the device choose: downstream indices are per client.
    set_index(entry, -1);
    entry.service_path = to_upstream(path);
    auto self = shared_from_this();
    auto shared = std::make_shared<Responder>(std::move(responder));
    c->request(std::move(entry), [self, session, shared, path, member, wanted](Result<MessageEntry> r) {
        if (!r) {
            shared->fail(r.error());
            return;
        }
        if (auto err = entry_error(*r)) {
            shared->fail(*err);
            return;
        }
        const std::int32_t upstream = entry_pipe_index(*r);
        std::int32_t downstream = wanted;
        {
            std::lock_guard lock(self->mutex_);
            if (downstream < 0) {
                downstream = 0;
                while (self->pipes_by_downstream_.count({session.endpoint(), path, member, downstream})) ++downstream;
            }
            self->pipes_by_downstream_[{session.endpoint(), path, member, downstream}] = upstream;
            self->pipes_by_upstream_[{path, member, upstream}] = PipeLink{session, path, member, downstream, upstream};
        }
        set_index(*r, downstream);
        shared->respond(std::move(*r));
    });
}

void MirrorService::pipe_disconnect(const SessionRef& session, MessageEntry&& entry, Responder responder) {
    const std::int32_t d = entry_pipe_index(entry);
    std::optional<std::int32_t> u;
    {
        std::lock_guard lock(mutex_);
        auto it = pipes_by_downstream_.find({session.endpoint(), entry.service_path, entry.member_name, d});
        if (it != pipes_by_downstream_.end()) {
            u = it->second;
            pipes_by_upstream_.erase({entry.service_path, entry.member_name, *u});
            pipes_by_downstream_.erase(it);
        }
    }
    if (!u) {
        responder.fail(make_error(MessageErrorType::InvalidArgument, "pipe endpoint not connected"));
        return;
    }
    set_index(entry, *u);
    forward(session, std::move(entry), std::move(responder));
}

void MirrorService::pipe_packets_from_client(const SessionRef& session, MessageEntry&& entry) {
    auto c = client();
    if (!c) return;
    const bool acks = entry.entry_type == MessageEntryType::PipePacketRet;
    {
        std::lock_guard lock(mutex_);
        // Only packets of this client's own endpoints go on: an index it did not open could name
        // another client's upstream endpoint (or pass a lock taken since).
        std::erase_if(entry.elements, [&](MessageElement& el) {
            // Packets name their pipe index; acks number it (wire.md §6.7).
            std::optional<std::int32_t> d = acks ? el.number : parse_pipe_index(el.name);
            if (!d) return true;
            auto it = pipes_by_downstream_.find({session.endpoint(), entry.service_path, entry.member_name, *d});
            if (it == pipes_by_downstream_.end()) return true;
            if (acks)
                el.number = it->second;
            else
                el.name = std::to_string(it->second);
            return false;
        });
    }
    if (entry.elements.empty()) return;
    counters_->pipe_packets.fetch_add(1);
    entry.service_path = to_upstream(entry.service_path);
    c->send(std::move(entry));
}

void MirrorService::pipe_packets_from_device(MessageEntry&& entry) {
    const std::string path = to_downstream(entry.service_path);
    entry.service_path = path;
    if (shared_endpoints_->take_pipe_elements(entry)) return;  // the gateway's own endpoints' (JSON API)
    const bool acks = entry.entry_type == MessageEntryType::PipePacketRet;
    // Regroup the elements per owning client session.
    std::map<std::uint32_t, std::pair<SessionRef, MessageEntry>> per_session;
    {
        std::lock_guard lock(mutex_);
        for (auto& el : entry.elements) {
            std::optional<std::int32_t> u = acks ? el.number : parse_pipe_index(el.name);
            if (!u) continue;
            auto it = pipes_by_upstream_.find({path, entry.member_name, *u});
            if (it == pipes_by_upstream_.end()) continue;
            auto& slot = per_session[it->second.session.endpoint()];
            if (slot.second.elements.empty()) {
                slot.first = it->second.session;
                slot.second.entry_type = entry.entry_type;
                slot.second.service_path = path;
                slot.second.member_name = entry.member_name;
                slot.second.metadata = entry.metadata;
            }
            if (acks)
                el.number = it->second.downstream_index;
            else
                el.name = std::to_string(it->second.downstream_index);
            slot.second.elements.push_back(std::move(el));
        }
    }
    for (auto& [ep, pair] : per_session) {
        // A session that may only send on the pipe (auth: gateway) does not receive its packets.
        if (!acks && access_.active() && !access_.may(pair.first, path, pair.second.member_name, auth::Operation::read))
            continue;
        if (!pair.first.send(std::move(pair.second))) counters_->pipe_drops.fetch_add(1);
    }
}

// --- upstream traffic ----------------------------------------------------------------------------

void MirrorService::fan_out(MessageEntry&& entry) {
    std::vector<SessionRef> sessions;
    {
        std::lock_guard lock(mutex_);
        // Passthrough clients get the device's events on their own upstream sessions.
        if (!passthrough_) sessions = sessions_;
    }
    auto internal = subscriptions_.event_subscribers({entry.service_path, entry.member_name});
    if (sessions.empty() && !internal) return;
    // One shared copy, encoded once per message format for the native clients.
    const auto shared = std::make_shared<const SharedEntry>(std::move(entry));
    const MessageEntry& e = shared->entry();
    const bool check = access_.active() && e.entry_type == MessageEntryType::EventReq;
    for (const auto& s : sessions) {
        if (check && !access_.may(s, e.service_path, e.member_name, auth::Operation::read)) continue;
        if (!s.send(shared)) counters_->event_drops.fetch_add(1);
    }
    deliver(internal, shared);
}

void MirrorService::deliver(const UpstreamSubscriptions::InternalSubs& subs, const SharedEntryPtr& entry) {
    if (subs)
        for (const auto& s : *subs) s.on_entry(entry);
}

void MirrorService::callback_from_device(MessageEntry&& entry) {
    auto c = client();
    SessionRef target;
    {
        std::lock_guard lock(mutex_);
        // Passthrough: no client calls the device on the gateway's own session, so nobody is called back.
        // auth: gateway: only a session whose user may `call` the callback is called.
        if (!passthrough_) {
            const std::string down_path = to_downstream(entry.service_path);
            auto allowed = [&](const SessionRef& s) {
                return s.alive() && access_.may(s, down_path, entry.member_name, auth::Operation::call);
            };
            for (const auto& s : sessions_)
                if (s.endpoint() == last_caller_ && allowed(s)) target = s;
            if (!target.alive())
                for (const auto& s : sessions_)
                    if (allowed(s)) target = s;
        }
    }
    MessageEntry reply_header = reply_to(entry);
    if (!target.alive()) {
        if (c) {
            set_entry_error(reply_header, make_error(MessageErrorType::OperationFailed, "no client connected through the gateway"));
            c->send(std::move(reply_header));
        }
        return;
    }
    counters_->callbacks.fetch_add(1);
    entry.service_path = to_downstream(entry.service_path);
    std::weak_ptr<DeviceMirror> weak = mirror_;
    target.request(std::move(entry), [weak, reply_header](Result<MessageEntry> r) mutable {
        auto m = weak.lock();
        auto c = m ? m->upstream() : nullptr;
        if (!c) return;
        c->send(relayed_reply(reply_header, std::move(r)));
    });
}

void MirrorService::on_upstream_entry(MessageEntry&& entry) {
    switch (entry.entry_type) {
        case MessageEntryType::EventReq:
        case MessageEntryType::ServicePathReleasedReq:
            counters_->events.fetch_add(1);
            entry.service_path = to_downstream(entry.service_path);
            fan_out(std::move(entry));
            return;
        case MessageEntryType::WirePacket: {
            counters_->wire_packets_in.fetch_add(1);
            entry.service_path = to_downstream(entry.service_path);
            // One shared copy: the newest value for late subscribers and what internal subscribers get.
            auto shared = std::make_shared<const SharedEntry>(std::move(entry));
            auto targets = subscriptions_.wire_value(shared);
            if (!targets) return;
            const bool check = access_.active();
            for (const auto& s : *targets->sessions) {
                // A session that may only set the wire's OutValue (auth: gateway) receives no InValue.
                if (check && !access_.may(s, shared->entry().service_path, shared->entry().member_name, auth::Operation::read))
                    continue;
                if (s.send_wire_packet(shared)) counters_->wire_packets_out.fetch_add(1);
            }
            deliver(targets->internal, shared);
            return;
        }
        case MessageEntryType::WireClosed: {
            entry.service_path = to_downstream(entry.service_path);
            auto targets = subscriptions_.wire_closed({entry.service_path, entry.member_name});
            if (!targets) return;
            for (const auto& s : *targets->sessions) (void)s.send(entry);
            // Internal subscribers see the WireClosed too.
            if (targets->internal) deliver(targets->internal, std::make_shared<const SharedEntry>(std::move(entry)));
            return;
        }
        case MessageEntryType::PipePacket:
        case MessageEntryType::PipePacketRet: pipe_packets_from_device(std::move(entry)); return;
        case MessageEntryType::PipeClosed: {
            std::string path = to_downstream(entry.service_path);
            const std::int32_t u = entry_pipe_index(entry);
            if (shared_endpoints_->pipe_closed(path, entry.member_name, u)) return;
            std::optional<PipeLink> link;
            {
                std::lock_guard lock(mutex_);
                auto it = pipes_by_upstream_.find({path, entry.member_name, u});
                if (it == pipes_by_upstream_.end()) return;
                link = it->second;
                pipes_by_downstream_.erase({link->session.endpoint(), path, entry.member_name, link->downstream_index});
                pipes_by_upstream_.erase(it);
            }
            entry.service_path = path;
            set_index(entry, link->downstream_index);
            (void)link->session.send(std::move(entry));
            return;
        }
        case MessageEntryType::CallbackCallReq: callback_from_device(std::move(entry)); return;
        default: return;
    }
}

void MirrorService::on_upstream_connected(const std::shared_ptr<RawClient>&) {
    shared_endpoints_->resume();
    for (const auto& key : subscriptions_.upstream_back()) ensure_upstream_wire(key);
}

void MirrorService::on_upstream_lost(const RRError& error) {
    // Pipes cannot outlive the upstream session: their clients get PipeClosed. Wire connections stay,
    // to be re-subscribed when the device returns. Generators are gone with the session.
    std::vector<std::pair<SessionRef, MessageEntry>> closed;
    {
        std::lock_guard lock(mutex_);
        for (auto& [key, link] : pipes_by_upstream_) {
            MessageEntry e;
            e.entry_type = MessageEntryType::PipeClosed;
            e.service_path = link.path;
            e.member_name = link.member;
            e.elements.push_back(make_scalar_element<std::int32_t>("index", link.downstream_index));
            closed.emplace_back(link.session, std::move(e));
        }
        pipes_by_upstream_.clear();
        pipes_by_downstream_.clear();
        generators_.clear();
    }
    for (auto& [s, e] : closed) (void)s.send(std::move(e));
    for (auto& w : subscriptions_.upstream_lost())
        if (w) w(fail(not_connected(name_)));
    shared_endpoints_->lost(not_connected(name_));  // a connect still in flight fails with the connection
    (void)error;
}

std::uint64_t MirrorService::add_internal_subscriber(std::string path, std::string member, bool is_wire,
                                                     std::function<void(const SharedEntryPtr&)> on_entry,
                                                     std::function<void(Result<void>)> done) {
    MemberKey key{std::move(path), std::move(member)};
    auto [id, joined] = subscriptions_.add_internal(key, is_wire, on_entry, done);
    if (!joined.ready) {
        // A value that came while the wire connects (before its WireConnectRet) went to the subscribers
        // of then: this one has it now.
        if (joined.last) on_entry(joined.last);
        ensure_upstream_wire(key);
        return id;
    }
    if (joined.last) on_entry(joined.last);
    if (done) done({});
    return id;
}

void MirrorService::remove_internal_subscriber(std::uint64_t id) {
    disconnect_upstream_wires(subscriptions_.remove_internal(id));
}

}  // namespace rr::server::gateway
