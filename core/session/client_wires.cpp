// ClientContext: wires (wire.md §6.7; CORE WireMember.cpp).
//
// WireConnectReq/Ret (no elements; one connection per wire member and client), WirePacket
// {packettime TimeSpec, packet} with entry metadata `unreliable\n` either way, WireClosed from the
// service, WireDisconnectReq from the client, WirePeekInValueReq / WirePeekOutValueReq answered with
// {packettime, packet}, WirePokeOutValueReq {packettime, packet}. A received packet whose time stamp is
// not newer than the last accepted one is dropped; sent time stamps are made strictly increasing.
// `[readonly]` wires have no OutValue on the client, `[writeonly]` wires no InValue.
#include "core/session/client_context.hpp"
#include "core/session/client_state.hpp"
#include "core/session/elements.hpp"

namespace rr {

using robdef::MemberDirection;
using robdef::MemberKind;

namespace {

TimeSpec after(const TimeSpec& t) {
    TimeSpec n = t;
    if (++n.nanoseconds >= 1'000'000'000) {
        n.nanoseconds = 0;
        ++n.seconds;
    }
    return n;
}

bool expired(const WireValue& v, std::int32_t lifespan_ms, MonoTime now) {
    return lifespan_ms >= 0 && v.local_time + std::chrono::milliseconds(lifespan_ms) < now;
}

}  // namespace

void ClientContext::wire_connect(std::string_view path, std::string_view member, MonoTime now,
                                 Completion<WireConnectionHandle> done) {
    const ObjectState* obj = nullptr;
    auto m = find_member(path, member, MemberKind::wire, &obj);
    if (!m) return done(m.take_error());
    std::string key = member_key(path, member);
    if (wire_index_.count(key) || wire_connecting_.count(key))
        return done(fail(MessageErrorType::InvalidOperation, "wire \"" + std::string(member) + "\" already connected"));
    auto proto = std::make_shared<WireState>();
    proto->path = std::string(path);
    proto->member = std::string(member);
    proto->context_service = obj->service->name;
    proto->type = (*m)->type;
    proto->readable = (*m)->direction() != MemberDirection::writeonly;
    proto->writable = (*m)->direction() != MemberDirection::readonly;
    wire_connecting_.emplace(key, nullptr);
    send_request(member_entry(MessageEntryType::WireConnectReq, path, member), now,
                 [this, proto, key, done = std::move(done)](Result<MessageEntry> r) {
                     std::shared_ptr<const WireValue> early;
                     if (auto c = wire_connecting_.find(key); c != wire_connecting_.end()) {
                         early = std::move(c->second);
                         wire_connecting_.erase(c);
                     }
                     r = reply_result(std::move(r));
                     if (!r) return done(r.take_error());
                     std::uint64_t id = ++next_id_;
                     auto st = std::make_unique<WireState>(*proto);
                     if (st->readable) st->in = std::move(early);
                     wires_.emplace(id, std::move(st));
                     wire_index_[key] = id;
                     done(WireConnectionHandle{id});
                 });
}

Result<void> ClientContext::set_wire_handlers(WireConnectionHandle c, WireConnectionHandlers handlers) {
    auto it = wires_.find(c.id);
    if (it == wires_.end()) return fail(MessageErrorType::InvalidArgument, "unknown wire connection");
    it->second->handlers = std::make_shared<WireConnectionHandlers>(std::move(handlers));
    return {};
}

Result<WireValue> ClientContext::wire_in_value(WireConnectionHandle c, MonoTime now) const {
    auto it = wires_.find(c.id);
    if (it == wires_.end()) return fail(MessageErrorType::InvalidArgument, "unknown wire connection");
    const WireState& w = *it->second;
    if (!w.readable) return fail(MessageErrorType::WriteOnlyMember, "wire \"" + w.member + "\" is write-only");
    if (!w.in) return fail(MessageErrorType::ValueNotSet, "Value not set");
    if (expired(*w.in, w.in_lifespan_ms, now)) return fail(MessageErrorType::ValueNotSet, "Value expired");
    return *w.in;
}

Result<WireValue> ClientContext::wire_out_value(WireConnectionHandle c, MonoTime now) const {
    auto it = wires_.find(c.id);
    if (it == wires_.end()) return fail(MessageErrorType::InvalidArgument, "unknown wire connection");
    const WireState& w = *it->second;
    if (!w.writable) return fail(MessageErrorType::ReadOnlyMember, "wire \"" + w.member + "\" is read-only");
    if (!w.out) return fail(MessageErrorType::ValueNotSet, "Value not set");
    if (expired(*w.out, w.out_lifespan_ms, now)) return fail(MessageErrorType::ValueNotSet, "Value expired");
    return *w.out;
}

Result<void> ClientContext::wire_set_out_value(WireConnectionHandle c, Value value, TimeSpec wall_now, MonoTime now) {
    auto it = wires_.find(c.id);
    if (it == wires_.end()) return fail(MessageErrorType::InvalidArgument, "unknown wire connection");
    WireState& w = *it->second;
    if (w.closed) return fail(MessageErrorType::InvalidOperation, "wire connection closed");
    if (!w.writable) return fail(MessageErrorType::ReadOnlyMember, "wire \"" + w.member + "\" is read-only");
    auto el = pack(value, w.type, "packet", w.context_service);
    if (!el) return el.take_error();
    TimeSpec ts = wall_now;
    if (w.out && ts <= w.out->timestamp) ts = after(w.out->timestamp);
    auto e = member_entry(MessageEntryType::WirePacket, w.path, w.member);
    e.metadata = "unreliable\n";
    e.elements.push_back(pack_timespec(ts, "packettime"));
    e.elements.push_back(std::move(*el));
    if (auto r = send_packet(std::move(e), now); !r) return r.take_error();
    w.out = std::make_shared<const WireValue>(WireValue{std::move(value), ts, now});
    return {};
}

Result<void> ClientContext::set_wire_lifespans(WireConnectionHandle c, std::int32_t in_ms, std::int32_t out_ms) {
    auto it = wires_.find(c.id);
    if (it == wires_.end()) return fail(MessageErrorType::InvalidArgument, "unknown wire connection");
    it->second->in_lifespan_ms = in_ms < 0 ? -1 : in_ms;
    it->second->out_lifespan_ms = out_ms < 0 ? -1 : out_ms;
    return {};
}

Result<WireConnectionInfo> ClientContext::wire_info(WireConnectionHandle c) const {
    auto it = wires_.find(c.id);
    if (it == wires_.end()) return fail(MessageErrorType::InvalidArgument, "unknown wire connection");
    const WireState& w = *it->second;
    return WireConnectionInfo{w.path, w.member, w.readable, w.writable, w.closed};
}

void ClientContext::wire_close(WireConnectionHandle c, MonoTime now, Completion<void> done) {
    auto it = wires_.find(c.id);
    if (it == wires_.end()) return done(fail(MessageErrorType::InvalidArgument, "unknown wire connection"));
    std::unique_ptr<WireState> w = std::move(it->second);
    wires_.erase(it);
    if (w->closed) return done({});
    wire_index_.erase(member_key(w->path, w->member));
    send_request(member_entry(MessageEntryType::WireDisconnectReq, w->path, w->member), now,
                 [done = std::move(done)](Result<MessageEntry> r) {
                     r = reply_result(std::move(r));
                     if (!r) return done(r.take_error());
                     done({});
                 });
}

void ClientContext::close_wire_state(std::uint64_t id, const RRError& error) {
    auto it = wires_.find(id);
    if (it == wires_.end() || it->second->closed) return;
    WireState& w = *it->second;
    w.closed = true;
    wire_index_.erase(member_key(w.path, w.member));
    auto h = w.handlers;
    if (h->closed) h->closed(WireConnectionHandle{id}, error);
}

void ClientContext::on_wire_entry(MessageEntry&& e, MonoTime now) {
    auto key = member_key(e.service_path, e.member_name);
    auto idx = wire_index_.find(key);
    if (e.entry_type == MessageEntryType::WireClosed) {
        if (idx != wire_index_.end())
            close_wire_state(idx->second, make_error(MessageErrorType::ConnectionError, "wire connection closed by the service"));
        return;
    }
    WireState* w = nullptr;
    std::shared_ptr<const WireValue>* early = nullptr;
    if (idx != wire_index_.end()) {
        auto wit = wires_.find(idx->second);
        if (wit == wires_.end()) return;
        w = wit->second.get();
        if (!w->readable) return;
    } else if (auto c = wire_connecting_.find(key); c != wire_connecting_.end()) {
        early = &c->second;  // before the WireConnectRet: keep the newest
    } else {
        return;  // not connected: dropped, as CORE does
    }
    const auto* pt = e.find("packettime");
    const auto* pk = e.find("packet");
    if (!pt || !pk) return;
    auto ts = unpack_timespec(*pt);
    if (!ts) return;
    const robdef::TypeDefinition* type = nullptr;
    std::string_view ctx;
    robdef::TypeDefinition early_type;
    if (w) {
        type = &w->type;
        ctx = w->context_service;
        if (w->in && !(*ts > w->in->timestamp)) return;  // older than the last accepted value
    } else {
        auto obj = objects_.find(e.service_path);
        if (obj == objects_.end()) return;
        const auto* m = obj->second->entry->find_member(e.member_name);
        if (!m || m->kind != MemberKind::wire) return;
        type = &m->type;
        ctx = obj->second->service->name;
        if (*early && !(*ts > (*early)->timestamp)) return;
    }
    auto v = unpack(*pk, *type, ctx);
    if (!v) return;  // a value that does not match the robdef is dropped
    auto wv = std::make_shared<const WireValue>(WireValue{std::move(*v), *ts, now});
    if (!w) {
        *early = std::move(wv);
        return;
    }
    w->in = wv;
    auto h = w->handlers;
    if (h->value) h->value(WireConnectionHandle{idx->second}, *wv);
}

void ClientContext::wire_peek(std::string_view path, std::string_view member, MessageEntryType type, MonoTime now,
                              Completion<WireValue> done) {
    const ObjectState* obj = nullptr;
    auto m = find_member(path, member, MemberKind::wire, &obj);
    if (!m) return done(m.take_error());
    const auto dir = (*m)->direction();
    if (type == MessageEntryType::WirePeekInValueReq && dir == MemberDirection::writeonly)
        return done(fail(MessageErrorType::WriteOnlyMember, "wire \"" + std::string(member) + "\" is write-only"));
    if (type == MessageEntryType::WirePeekOutValueReq && dir == MemberDirection::readonly)
        return done(fail(MessageErrorType::ReadOnlyMember, "wire \"" + std::string(member) + "\" is read-only"));
    const robdef::MemberDefinition* def = *m;
    const robdef::ServiceDefinition* svc = obj->service;
    send_request(member_entry(type, path, member), now, [this, def, svc, done = std::move(done)](Result<MessageEntry> r) {
        r = reply_result(std::move(r));
        if (!r) return done(r.take_error());
        const auto* pt = r->find("packettime");
        const auto* pk = r->find("packet");
        if (!pt || !pk) return done(fail(MessageErrorType::MessageElementNotFound, "wire peek answer without packettime/packet"));
        auto ts = unpack_timespec(*pt);
        if (!ts) return done(ts.take_error());
        auto v = unpack(*pk, def->type, svc->name);
        if (!v) return done(v.take_error());
        done(WireValue{std::move(*v), *ts, now_});
    });
}

void ClientContext::wire_peek_in_value(std::string_view path, std::string_view member, MonoTime now,
                                       Completion<WireValue> done) {
    wire_peek(path, member, MessageEntryType::WirePeekInValueReq, now, std::move(done));
}

void ClientContext::wire_peek_out_value(std::string_view path, std::string_view member, MonoTime now,
                                        Completion<WireValue> done) {
    wire_peek(path, member, MessageEntryType::WirePeekOutValueReq, now, std::move(done));
}

void ClientContext::wire_poke_out_value(std::string_view path, std::string_view member, Value value, TimeSpec wall_now,
                                        MonoTime now, Completion<void> done) {
    const ObjectState* obj = nullptr;
    auto m = find_member(path, member, MemberKind::wire, &obj);
    if (!m) return done(m.take_error());
    if ((*m)->direction() == MemberDirection::readonly)
        return done(fail(MessageErrorType::ReadOnlyMember, "wire \"" + std::string(member) + "\" is read-only"));
    auto el = pack(value, (*m)->type, "packet", obj->service->name);
    if (!el) return done(el.take_error());
    auto e = member_entry(MessageEntryType::WirePokeOutValueReq, path, member);
    e.elements.push_back(pack_timespec(wall_now, "packettime"));
    e.elements.push_back(std::move(*el));
    send_request(std::move(e), now, [done = std::move(done)](Result<MessageEntry> r) {
        r = reply_result(std::move(r));
        if (!r) return done(r.take_error());
        done({});
    });
}

}  // namespace rr
