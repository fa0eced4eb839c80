#include "server/service/wire_member.hpp"

#include <algorithm>
#include <chrono>

#include "server/service/member_support.hpp"

namespace rr::server {

namespace {

TimeSpec add_ns(TimeSpec t, std::int64_t ns) {
    std::int64_t total = t.nanoseconds + ns;
    t.seconds += total / 1'000'000'000;
    t.nanoseconds = static_cast<std::int32_t>(total % 1'000'000'000);
    return t;
}

RRError value_not_set() { return make_error(MessageErrorType::ValueNotSet, "Value not set"); }

}  // namespace

TimeSpec wall_clock_timespec() {
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                        std::chrono::system_clock::now().time_since_epoch())
                        .count();
    TimeSpec t;
    t.seconds = ns / 1'000'000'000;
    t.nanoseconds = static_cast<std::int32_t>(ns % 1'000'000'000);
    if (t.nanoseconds < 0) {  // before 1970: keep 0 ≤ ns < 1e9
        t.nanoseconds += 1'000'000'000;
        t.seconds -= 1;
    }
    return t;
}

// ---------------------------------------------------------------------------------------------
// WireConnection

std::optional<TimedValue> WireConnection::in_value() const {
    std::lock_guard lock(mutex_);
    return in_;
}

Result<void> WireConnection::set_out_value(const Value& value) {
    if (!open_.load()) return fail(MessageErrorType::InvalidOperation, "Wire connection is closed");
    auto member = member_.lock();
    if (!member) return fail(MessageErrorType::InvalidOperation, "Wire connection is closed");
    return member->send_to(*this, value);
}

void WireConnection::close() {
    if (!open_.load()) return;
    if (auto member = member_.lock()) member->close_connection(shared_from_this());
    open_.store(false);
}

// ---------------------------------------------------------------------------------------------
// WireMember

WireMember::WireMember(std::shared_ptr<const detail::MemberInfo> info) : info_(std::move(info)) {}

const std::string& WireMember::name() const noexcept { return info_->def->name; }
robdef::MemberDirection WireMember::direction() const noexcept { return info_->def->direction(); }

void WireMember::on_value(ValueHandler handler) { set_handler(on_value_, std::move(handler)); }

void WireMember::set_peek_in_handler(PeekHandler handler) { set_handler(peek_in_, std::move(handler)); }

void WireMember::set_peek_out_handler(PeekHandler handler) { set_handler(peek_out_, std::move(handler)); }

void WireMember::set_poke_handler(PokeHandler handler) { set_handler(poke_, std::move(handler)); }

void WireMember::clear_handlers() { clear_handler_slots(on_value_, peek_in_, peek_out_, poke_); }

TimeSpec WireMember::next_time() {
    TimeSpec t = wall_clock_timespec();
    std::lock_guard lock(mutex_);
    if (t <= last_time_) t = add_ns(last_time_, 1);
    last_time_ = t;
    return t;
}

Result<MessageEntry> WireMember::pack_packet(const Value& value, TimeSpec time, MessageEntryType type) const {
    auto packed = detail::pack_member(*info_, value, info_->def->type, "packet");
    if (!packed) return packed.take_error();
    MessageEntry e = detail::member_entry(type, {}, info_->def->name);
    if (type == MessageEntryType::WirePacket) e.metadata = "unreliable\n";
    e.elements.reserve(2);
    e.elements.push_back(pack_timespec(time, "packettime"));
    e.elements.push_back(std::move(*packed));
    return e;
}

Result<void> WireMember::set_out_value(Value value) {
    if (direction() == robdef::MemberDirection::writeonly)
        return fail(MessageErrorType::ReadOnlyMember, "wire " + name() + " is [writeonly]: only clients send");
    std::lock_guard order(send_order_mutex_);
    const TimeSpec time = next_time();
    auto entry = pack_packet(value, time, MessageEntryType::WirePacket);
    if (!entry) return entry.take_error();
    std::vector<std::shared_ptr<WireConnection>> targets;
    {
        std::lock_guard lock(mutex_);
        out_ = TimedValue{std::move(value), time};
        targets.reserve(connections_.size());
        for (const auto& [k, c] : connections_) targets.push_back(c);
    }
    // Newest wins; a gone client is dropped on close.
    for (const auto& t : targets) t->last_sent_ = time;
    if (targets.size() == 1) {
        entry->service_path = targets.front()->service_path();
        (void)targets.front()->session().send_wire_packet(std::move(*entry));
        return {};
    }
    // Many clients: one entry per service path (usually one), encoded once per message format.
    std::vector<std::shared_ptr<const EncodedEntry>> shared;
    for (const auto& t : targets) {
        auto it = std::find_if(shared.begin(), shared.end(),
                               [&](const auto& s) { return s->entry().service_path == t->service_path(); });
        if (it == shared.end()) {
            MessageEntry e = *entry;  // copies share the packed data
            e.service_path = t->service_path();
            it = shared.insert(shared.end(), std::make_shared<const EncodedEntry>(std::move(e)));
        }
        (void)t->session().send_wire_packet(*it);
    }
    return {};
}

Result<void> WireMember::send_to(WireConnection& connection, const Value& value) {
    if (direction() == robdef::MemberDirection::writeonly)
        return fail(MessageErrorType::ReadOnlyMember, "wire " + name() + " is [writeonly]: only clients send");
    std::lock_guard order(send_order_mutex_);
    const TimeSpec time = next_time();
    auto entry = pack_packet(value, time, MessageEntryType::WirePacket);
    if (!entry) return entry.take_error();
    entry->service_path = connection.service_path();
    connection.last_sent_ = time;
    return connection.session().send_wire_packet(std::move(*entry));
}

void WireMember::send_current(WireConnection& connection) {
    // Read under the order lock: a value set since the connection was added has reached it already,
    // and the current one goes only if nothing newer did.
    std::lock_guard order(send_order_mutex_);
    std::optional<TimedValue> current;
    {
        std::lock_guard lock(mutex_);
        current = out_;
    }
    if (!current || (connection.last_sent_ && current->time <= *connection.last_sent_)) return;
    if (auto e = pack_packet(current->value, current->time, MessageEntryType::WirePacket)) {
        e->service_path = connection.service_path();
        connection.last_sent_ = current->time;
        (void)connection.session().send_wire_packet(std::move(*e));
    }
}

Result<TimedValue> WireMember::out_value() const {
    std::lock_guard lock(mutex_);
    if (!out_) return fail(value_not_set());
    return *out_;
}

Result<TimedValue> WireMember::in_value() const {
    std::lock_guard lock(mutex_);
    if (!in_) return fail(value_not_set());
    return *in_;
}

std::vector<std::shared_ptr<WireConnection>> WireMember::connections() const { return snapshot(); }

void WireMember::close_connection(const std::shared_ptr<WireConnection>& connection) {
    remove(Key{connection->session().endpoint(), connection->service_path()}, connection,
           detail::member_entry(MessageEntryType::WireClosed, connection->service_path(), name()));
}

void WireMember::handle_request(const SessionRef& session, MessageEntry&& entry, Responder responder) {
    const auto dir = direction();
    switch (entry.entry_type) {
        case MessageEntryType::WireConnectReq: {
            std::shared_ptr<WireConnection> conn;
            std::shared_ptr<const ConnectHandler> on_connect;
            bool created = false;
            {
                std::lock_guard lock(mutex_);
                auto& slot = connections_[Key{session.endpoint(), entry.service_path}];
                if (!slot) {
                    slot.reset(new WireConnection(weak_from_this(), session, entry.service_path));
                    created = true;
                }
                conn = slot;
                on_connect = on_connect_;
            }
            if (auto r = run_on_connect(on_connect, Key{session.endpoint(), entry.service_path}, conn, created); !r) {
                responder.fail(r.error());
                return;
            }
            if (dir != robdef::MemberDirection::writeonly) send_current(*conn);
            responder.respond(MessageEntry{});
            return;
        }
        case MessageEntryType::WireDisconnectReq:
            disconnect(Key{session.endpoint(), entry.service_path}, responder,
                       make_error(MessageErrorType::ServiceError, "Invalid wire connection"));
            return;
        case MessageEntryType::WirePeekInValueReq:
        case MessageEntryType::WirePeekOutValueReq: {
            const bool in = entry.entry_type == MessageEntryType::WirePeekInValueReq;
            if (in && dir == robdef::MemberDirection::writeonly) {
                responder.fail(make_error(MessageErrorType::WriteOnlyMember, "Write only member"));
                return;
            }
            if (!in && dir == robdef::MemberDirection::readonly) {
                responder.fail(make_error(MessageErrorType::ReadOnlyMember, "Read only member"));
                return;
            }
            std::shared_ptr<const PeekHandler> handler;
            std::optional<TimedValue> stored;
            {
                std::lock_guard lock(mutex_);
                handler = in ? peek_in_ : peek_out_;
                stored = in ? out_ : in_;
            }
            Result<TimedValue> v = handler ? (*handler)(session) : (stored ? Result<TimedValue>(std::move(*stored))
                                                                            : Result<TimedValue>(fail(value_not_set())));
            if (!v) {
                responder.fail(v.error());
                return;
            }
            auto reply = pack_packet(v->value, v->time, MessageEntryType::Null);  // Responder sets the reply type
            if (!reply) {
                responder.fail(reply.error());
                return;
            }
            responder.respond(std::move(*reply));
            return;
        }
        case MessageEntryType::WirePokeOutValueReq: {
            if (dir == robdef::MemberDirection::readonly) {
                responder.fail(make_error(MessageErrorType::ReadOnlyMember, "Read only member"));
                return;
            }
            auto te = detail::require_element(entry, "packettime");
            if (!te) {
                responder.fail(te.error());
                return;
            }
            auto time = unpack_timespec(**te);
            if (!time) {
                responder.fail(time.error());
                return;
            }
            auto pe = detail::require_element(entry, "packet");
            if (!pe) {
                responder.fail(pe.error());
                return;
            }
            auto v = detail::unpack_member(*info_, **pe, info_->def->type);
            if (!v) {
                responder.fail(v.error());
                return;
            }
            std::shared_ptr<const PokeHandler> poke;
            std::shared_ptr<const ValueHandler> on_value;
            {
                std::lock_guard lock(mutex_);
                poke = poke_;
                on_value = on_value_;
                if (!poke) in_ = TimedValue{*v, *time};
            }
            if (poke) {
                if (auto r = (*poke)(session, std::move(*v), *time); !r) {
                    responder.fail(r.error());
                    return;
                }
            } else if (on_value) {
                (*on_value)(nullptr, *v, *time);
            }
            responder.respond(MessageEntry{});
            return;
        }
        default: responder.fail(make_error(MessageErrorType::InvalidOperation, "Invalid Command")); return;
    }
}

void WireMember::handle_packet(const SessionRef& session, MessageEntry&& entry) {
    if (direction() == robdef::MemberDirection::readonly) return;
    std::shared_ptr<WireConnection> conn;
    std::shared_ptr<const ValueHandler> on_value;
    {
        std::lock_guard lock(mutex_);
        auto it = connections_.find(Key{session.endpoint(), entry.service_path});
        if (it == connections_.end()) return;
        conn = it->second;
        on_value = on_value_;
    }
    const auto* te = entry.find("packettime");
    const auto* pe = entry.find("packet");
    if (!te || !pe) return;
    auto time = unpack_timespec(*te);
    if (!time) return;
    auto v = detail::unpack_member(*info_, *pe, info_->def->type);
    if (!v) return;
    {
        std::lock_guard lock(conn->mutex_);
        if (conn->in_ && !(*time > conn->in_->time)) return;  // older than the last accepted: dropped
        conn->in_ = TimedValue{*v, *time};
    }
    {
        std::lock_guard lock(mutex_);
        in_ = TimedValue{*v, *time};
    }
    if (on_value) (*on_value)(conn, *v, *time);
}

}  // namespace rr::server
