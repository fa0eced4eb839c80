// ClientContext: pipes (wire.md §6.7; CORE PipeMember.cpp).
//
// PipeConnectReq `index` (−1 = any) [+ `unreliable` 1] → PipeConnectRet `index`; PipePacket elements are
// named by the decimal endpoint index and hold {packetnumber uint32, packet, [requestack uint32 1]};
// packet numbers count 1, 2, … per endpoint and direction (wrapping to 0 after 2³²−1); a reliable
// endpoint delivers in packet-number order (later packets wait for earlier ones); PipePacketRet acks
// carry the index as element number and the packet number as uint32; PipeClosed `index` from the
// service; PipeDisconnectReq `index` from the client. Packets that arrive before the PipeConnectRet of
// a matching connect are kept and handed to the new endpoint (CORE "early endpoints").
#include <algorithm>

#include "core/session/client_context.hpp"
#include "core/session/client_state.hpp"
#include "core/session/elements.hpp"
#include "core/value/element_layout.hpp"

namespace rr {

using robdef::MemberDirection;
using robdef::MemberKind;

namespace {

std::string pipe_key(std::string_view path, std::string_view member, std::int32_t index) {
    std::string k = member_key(path, member);
    k.push_back('\n');
    k += std::to_string(index);
    return k;
}

std::uint32_t next_packet_number(std::uint32_t n) { return n == UINT32_MAX ? 0 : n + 1; }

}  // namespace

void ClientContext::pipe_connect(std::string_view path, std::string_view member, std::int32_t index, MonoTime now,
                                 Completion<PipeEndpointHandle> done) {
    const ObjectState* obj = nullptr;
    auto m = find_member(path, member, MemberKind::pipe, &obj);
    if (!m) return done(m.take_error());
    if (index < -1) return done(fail(MessageErrorType::InvalidArgument, "pipe index must be -1 or ≥ 0"));
    const bool unreliable = robdef::pipe_is_unreliable(*obj->entry, **m);
    auto e = member_entry(MessageEntryType::PipeConnectReq, path, member);
    e.elements.push_back(make_scalar_element<std::int32_t>("index", index));
    if (unreliable) e.elements.push_back(make_scalar_element<std::int32_t>("unreliable", 1));

    auto proto = std::make_shared<PipeState>();
    proto->path = std::string(path);
    proto->member = std::string(member);
    proto->context_service = obj->service->name;
    proto->type = (*m)->type;
    proto->readable = (*m)->direction() != MemberDirection::writeonly;
    proto->writable = (*m)->direction() != MemberDirection::readonly;
    std::string key = member_key(path, member);
    pipe_connecting_[key].push_back(index);

    send_request(std::move(e), now, [this, proto, key, index, done = std::move(done)](Result<MessageEntry> r) {
        // This connect is no longer in flight.
        auto c = pipe_connecting_.find(key);
        if (c != pipe_connecting_.end()) {
            auto pos = std::find(c->second.begin(), c->second.end(), index);
            if (pos != c->second.end()) c->second.erase(pos);
        }
        const bool last = c == pipe_connecting_.end() || c->second.empty();
        if (c != pipe_connecting_.end() && c->second.empty()) pipe_connecting_.erase(c);
        auto drop_early = [&] {
            if (!last) return;
            for (auto it = pipes_.begin(); it != pipes_.end();) {
                if (it->second->early && member_key(it->second->path, it->second->member) == key) {
                    pipe_index_.erase(pipe_key(it->second->path, it->second->member, it->second->index));
                    it = pipes_.erase(it);
                } else {
                    ++it;
                }
            }
        };

        r = reply_result(std::move(r));
        std::int32_t rindex = 0;
        if (r && (!r->find("index") || !read_scalar(*r->find("index"), rindex)))
            r = fail(MessageErrorType::MessageElementNotFound, "PipeConnectRet without index");
        if (!r) {
            drop_early();
            return done(r.take_error());
        }
        std::int32_t unrel = 0;
        const bool runreliable = r->find("unreliable") && read_scalar(*r->find("unreliable"), unrel) && unrel == 1;
        auto k = pipe_key(proto->path, proto->member, rindex);
        std::uint64_t id = 0;
        if (auto it = pipe_index_.find(k); it != pipe_index_.end()) {
            auto p = pipes_.find(it->second);
            if (p != pipes_.end() && p->second->early && !runreliable) {
                id = it->second;  // adopt the packets that came first
                p->second->early = false;
                p->second->unreliable = false;
            } else if (p != pipes_.end() && p->second->early) {
                pipes_.erase(p);
                pipe_index_.erase(it);
            } else {
                drop_early();
                return done(fail(MessageErrorType::InvalidOperation,
                                 "pipe endpoint " + std::to_string(rindex) + " is already connected"));
            }
        }
        if (id == 0) {
            id = ++next_id_;
            auto st = std::make_unique<PipeState>(*proto);
            st->index = rindex;
            st->unreliable = runreliable;
            pipes_.emplace(id, std::move(st));
            pipe_index_[k] = id;
        }
        drop_early();
        done(PipeEndpointHandle{id});
    });
}

Result<void> ClientContext::set_pipe_handlers(PipeEndpointHandle ep, PipeEndpointHandlers handlers) {
    auto it = pipes_.find(ep.id);
    if (it == pipes_.end() || it->second->early) return fail(MessageErrorType::InvalidArgument, "unknown pipe endpoint");
    it->second->handlers = std::make_shared<PipeEndpointHandlers>(std::move(handlers));
    return {};
}

Result<void> ClientContext::set_pipe_request_ack(PipeEndpointHandle ep, bool request_ack) {
    auto it = pipes_.find(ep.id);
    if (it == pipes_.end() || it->second->early) return fail(MessageErrorType::InvalidArgument, "unknown pipe endpoint");
    it->second->request_ack = request_ack;
    return {};
}

Result<std::uint32_t> ClientContext::pipe_send(PipeEndpointHandle ep, const Value& packet, MonoTime now) {
    auto it = pipes_.find(ep.id);
    if (it == pipes_.end() || it->second->early) return fail(MessageErrorType::InvalidArgument, "unknown pipe endpoint");
    PipeState& p = *it->second;
    if (p.closed) return fail(MessageErrorType::InvalidOperation, "pipe endpoint closed");
    if (!p.writable) return fail(MessageErrorType::ReadOnlyMember, "pipe \"" + p.member + "\" is read-only");
    auto el = pack(packet, p.type, "packet", p.context_service);
    if (!el) return el.take_error();
    const std::uint32_t number = next_packet_number(p.send_packet_number);
    MessageElement d;
    d.name = std::to_string(p.index);  // a name, also in v4 (wire.md §6.7)
    d.type = DataTypes::dictionary_t;
    d.elements.reserve(3);
    d.elements.push_back(make_scalar_element<std::uint32_t>("packetnumber", number));
    d.elements.push_back(std::move(*el));
    if (p.request_ack) d.elements.push_back(make_scalar_element<std::uint32_t>("requestack", 1));
    auto e = member_entry(MessageEntryType::PipePacket, p.path, p.member);
    if (p.unreliable) e.metadata = "unreliable\n";
    e.elements.push_back(std::move(d));
    if (auto r = send_packet(std::move(e), now); !r) return r.take_error();
    p.send_packet_number = number;
    return number;
}

std::optional<Value> ClientContext::pipe_receive(PipeEndpointHandle ep) {
    auto it = pipes_.find(ep.id);
    if (it == pipes_.end() || it->second->early || it->second->queue.empty()) return std::nullopt;
    Value v = std::move(it->second->queue.front());
    it->second->queue.pop_front();
    return v;
}

std::size_t ClientContext::pipe_available(PipeEndpointHandle ep) const {
    auto it = pipes_.find(ep.id);
    if (it == pipes_.end() || it->second->early) return 0;
    return it->second->queue.size();
}

Result<PipeEndpointInfo> ClientContext::pipe_info(PipeEndpointHandle ep) const {
    auto it = pipes_.find(ep.id);
    if (it == pipes_.end() || it->second->early) return fail(MessageErrorType::InvalidArgument, "unknown pipe endpoint");
    const PipeState& p = *it->second;
    return PipeEndpointInfo{p.path, p.member, p.index, p.unreliable, p.readable, p.writable, p.closed};
}

void ClientContext::pipe_close(PipeEndpointHandle ep, MonoTime now, Completion<void> done) {
    auto it = pipes_.find(ep.id);
    if (it == pipes_.end() || it->second->early)
        return done(fail(MessageErrorType::InvalidArgument, "unknown pipe endpoint"));
    std::unique_ptr<PipeState> p = std::move(it->second);
    pipes_.erase(it);
    if (p->closed) return done({});
    pipe_index_.erase(pipe_key(p->path, p->member, p->index));
    auto e = member_entry(MessageEntryType::PipeDisconnectReq, p->path, p->member);
    e.elements.push_back(make_scalar_element<std::int32_t>("index", p->index));
    send_request(std::move(e), now, [done = std::move(done)](Result<MessageEntry> r) {
        r = reply_result(std::move(r));
        if (!r) return done(r.take_error());
        done({});
    });
}

void ClientContext::close_pipe_state(std::uint64_t id, const RRError& error) {
    auto it = pipes_.find(id);
    if (it == pipes_.end() || it->second->closed) return;
    PipeState& p = *it->second;
    p.closed = true;
    pipe_index_.erase(pipe_key(p.path, p.member, p.index));
    if (p.early) {
        pipes_.erase(it);
        return;
    }
    auto h = p.handlers;  // kept alive while it runs
    if (h->closed) h->closed(PipeEndpointHandle{id}, error);
}

void ClientContext::on_pipe_entry(MessageEntry&& e, MonoTime now) {
    if (e.entry_type == MessageEntryType::PipeClosed) {
        std::int32_t index = 0;
        const auto* el = e.find("index");
        if (!el || !read_scalar(*el, index)) return;
        auto it = pipe_index_.find(pipe_key(e.service_path, e.member_name, index));
        if (it == pipe_index_.end()) return;
        close_pipe_state(it->second, make_error(MessageErrorType::ConnectionError, "pipe endpoint closed by the service"));
        return;
    }

    if (e.entry_type == MessageEntryType::PipePacketRet) {
        for (const auto& el : e.elements) {
            auto index = element_number(el);
            std::uint32_t number = 0;
            if (!index || !read_scalar(el, number)) continue;
            auto it = pipe_index_.find(pipe_key(e.service_path, e.member_name, *index));
            if (it == pipe_index_.end()) continue;
            auto p = pipes_.find(it->second);
            if (p == pipes_.end() || p->second->early) continue;
            auto h = p->second->handlers;
            if (h->ack) h->ack(PipeEndpointHandle{it->second}, number);
        }
        return;
    }

    // PipePacket: one element per packet, named by the endpoint index.
    std::vector<MessageElement> acks;
    std::vector<std::uint64_t> notify;
    const auto key = member_key(e.service_path, e.member_name);
    for (const auto& el : e.elements) {
        auto index = element_number(el);
        if (!index || el.type != DataTypes::dictionary_t) continue;
        auto k = pipe_key(e.service_path, e.member_name, *index);
        std::uint64_t id = 0;
        if (auto it = pipe_index_.find(k); it != pipe_index_.end()) {
            id = it->second;
        } else {
            // A packet before the PipeConnectRet: keep it when a connect for this index (or −1) is in flight.
            auto c = pipe_connecting_.find(key);
            if (c == pipe_connecting_.end() ||
                std::none_of(c->second.begin(), c->second.end(), [&](std::int32_t i) { return i == -1 || i == *index; }))
                continue;
            auto obj = objects_.find(e.service_path);
            if (obj == objects_.end()) continue;
            const auto* m = obj->second->entry->find_member(e.member_name);
            if (!m || m->kind != MemberKind::pipe) continue;
            auto st = std::make_unique<PipeState>();
            st->path = e.service_path;
            st->member = e.member_name;
            st->context_service = obj->second->service->name;
            st->type = m->type;
            st->index = *index;
            st->readable = m->direction() != MemberDirection::writeonly;
            st->writable = m->direction() != MemberDirection::readonly;
            st->early = true;
            id = ++next_id_;
            pipes_.emplace(id, std::move(st));
            pipe_index_[k] = id;
        }
        auto pit = pipes_.find(id);
        if (pit == pipes_.end()) continue;
        PipeState& p = *pit->second;
        std::uint32_t number = 0;
        const auto* pn = el.find("packetnumber");
        const auto* pk = el.find("packet");
        if (!pn || !pk || !read_scalar(*pn, number)) continue;
        if (el.find("requestack")) {
            MessageElement ack = make_scalar_element<std::uint32_t>("", number);
            ack.number = *index;
            acks.push_back(std::move(ack));
        }
        if (!p.readable) continue;  // a `[writeonly]` pipe drops what it receives (CORE), acks still go out
        auto v = unpack(*pk, p.type, p.context_service);
        if (!v) continue;  // a packet that does not match the robdef is dropped
        if (p.unreliable) {
            p.queue.push_back(std::move(*v));
        } else if (number == next_packet_number(p.recv_packet_number)) {
            p.queue.push_back(std::move(*v));
            p.recv_packet_number = number;
            for (auto o = p.out_of_order.find(next_packet_number(p.recv_packet_number)); o != p.out_of_order.end();
                 o = p.out_of_order.find(next_packet_number(p.recv_packet_number))) {
                p.queue.push_back(std::move(o->second));
                p.recv_packet_number = o->first;
                p.out_of_order.erase(o);
            }
        } else {
            p.out_of_order.emplace(number, std::move(*v));
            continue;
        }
        if (std::find(notify.begin(), notify.end(), id) == notify.end()) notify.push_back(id);
    }
    if (!acks.empty()) {
        auto ack = member_entry(MessageEntryType::PipePacketRet, e.service_path, e.member_name);
        ack.elements = std::move(acks);
        (void)send_packet(std::move(ack), now);
    }
    for (auto id : notify) {
        auto it = pipes_.find(id);
        if (it == pipes_.end() || it->second->early) continue;
        auto h = it->second->handlers;
        if (h->packets) h->packets(PipeEndpointHandle{id});
    }
}

}  // namespace rr
