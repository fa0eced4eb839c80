#include "server/gateway/session_endpoints.hpp"

#include <algorithm>

#include "base/message/error_entry.hpp"
#include "core/session/elements.hpp"
#include "server/gateway/pipe_entries.hpp"

namespace rr::server::gateway {
namespace {

// The device's pipe backlog bound, as for the gateway's shared session: a device that does not read
// gets no more packets.
constexpr std::size_t kMaxBacklogBytes = 8u << 20;

Result<void> reply_outcome(Result<MessageEntry>& r) {
    if (!r) return r.take_error();
    if (auto err = entry_error(*r)) return fail(*err);
    return {};
}

}  // namespace

SessionEndpoints::SessionEndpoints(Upstream upstream) : upstream_(std::move(upstream)) {}

RRError SessionEndpoints::gone() const {
    return lost_ ? *lost_ : make_error(MessageErrorType::ConnectionError, "the session to the device ended");
}

std::size_t SessionEndpoints::subscription_count() const {
    std::lock_guard lock(mutex_);
    std::size_t n = pipes_.size();
    for (const auto& [k, subs] : events_) n += subs.size();
    for (const auto& [k, w] : wires_) n += w.subscribers.size();
    return n;
}

std::size_t SessionEndpoints::open_pipe_count() const {
    std::lock_guard lock(mutex_);
    return static_cast<std::size_t>(std::count_if(pipes_.begin(), pipes_.end(), [](const auto& p) { return p.second.connected; }));
}

// --- events and wires -----------------------------------------------------------------------------

void SessionEndpoints::subscribe(std::string path, std::string member, bool is_wire, SubscriptionHandlers handlers,
                                 std::function<void(Result<std::uint64_t>)> done) {
    MemberKey key{std::move(path), std::move(member)};
    auto h = std::make_shared<const SubscriptionHandlers>(std::move(handlers));
    std::uint64_t id = 0;
    bool connect = false, ready = false;
    std::optional<RRError> refused;
    {
        std::lock_guard lock(mutex_);
        id = next_id_++;
        if (lost_) {
            refused = gone();
        } else if (!is_wire) {
            events_[key].push_back(Subscriber{id, h});
            ready = true;
        } else {
            auto [it, fresh] = wires_.try_emplace(key);
            it->second.subscribers.push_back(Subscriber{id, h});
            if (it->second.connected) {
                ready = true;
            } else {
                it->second.waiting.emplace_back(id, std::move(done));
                connect = fresh;
            }
        }
    }
    if (refused) {
        done(fail(std::move(*refused)));
        return;
    }
    if (ready) {
        done(id);
        return;
    }
    if (!connect) return;  // a connect of the same wire is in flight: its reply answers this one too
    MessageEntry e;
    e.entry_type = MessageEntryType::WireConnectReq;
    e.service_path = key.first;
    e.member_name = key.second;
    std::weak_ptr<SessionEndpoints> weak = weak_from_this();
    upstream_.request(std::move(e), [weak, key](Result<MessageEntry> r) {
        if (auto self = weak.lock()) self->wire_connected(key, std::move(r));
    });
}

void SessionEndpoints::wire_connected(const MemberKey& key, Result<MessageEntry> r) {
    const Result<void> outcome = reply_outcome(r);
    std::vector<std::pair<std::uint64_t, std::function<void(Result<std::uint64_t>)>>> waiting;
    bool orphan = false, ended = false;
    {
        std::lock_guard lock(mutex_);
        ended = lost_.has_value();
        auto it = wires_.find(key);
        if (it == wires_.end()) {
            orphan = outcome.ok();  // every subscriber left (or the session ended) while connecting
        } else {
            waiting.swap(it->second.waiting);
            if (outcome.ok()) {
                it->second.connected = true;
                orphan = it->second.subscribers.empty();
                if (orphan) wires_.erase(it);
            } else {
                wires_.erase(it);  // nobody keeps a connection that does not exist
            }
        }
    }
    if (orphan && !ended) {
        MessageEntry d;
        d.entry_type = MessageEntryType::WireDisconnectReq;
        d.service_path = key.first;
        d.member_name = key.second;
        upstream_.request(std::move(d), [](Result<MessageEntry>) {});
    }
    for (auto& [id, done] : waiting) {
        if (outcome.ok())
            done(id);
        else
            done(fail(outcome.error()));
    }
}

void SessionEndpoints::unsubscribe(std::uint64_t id) {
    std::optional<MemberKey> disconnect;
    {
        std::lock_guard lock(mutex_);
        for (auto it = events_.begin(); it != events_.end(); ++it) {
            if (std::erase_if(it->second, [&](const Subscriber& s) { return s.id == id; })) {
                if (it->second.empty()) events_.erase(it);
                return;
            }
        }
        for (auto it = wires_.begin(); it != wires_.end(); ++it) {
            auto& w = it->second;
            if (!std::erase_if(w.subscribers, [&](const Subscriber& s) { return s.id == id; })) continue;
            std::erase_if(w.waiting, [&](const auto& p) { return p.first == id; });
            if (w.subscribers.empty() && w.connected) {
                disconnect = it->first;
                wires_.erase(it);
            }
            break;  // a connect in flight with no subscriber left is disconnected by its reply
        }
    }
    if (!disconnect) return;
    MessageEntry d;
    d.entry_type = MessageEntryType::WireDisconnectReq;
    d.service_path = std::move(disconnect->first);
    d.member_name = std::move(disconnect->second);
    upstream_.request(std::move(d), [](Result<MessageEntry>) {});
}

Result<void> SessionEndpoints::send_wire_packet(MessageEntry entry) {
    {
        std::lock_guard lock(mutex_);
        if (lost_) return fail(gone());
        auto it = wires_.find(MemberKey{entry.service_path, entry.member_name});
        if (it == wires_.end() || !it->second.connected)
            return fail(MessageErrorType::InvalidOperation, "wire \"" + entry.member_name + "\" is not connected on this session");
    }
    return upstream_.send(std::move(entry));
}

// --- pipes ----------------------------------------------------------------------------------------

void SessionEndpoints::open_pipe(std::string path, std::string member, bool unreliable, GatewayPipeHandlers handlers,
                                 std::function<void(Result<std::uint64_t>)> done) {
    std::uint64_t id = 0;
    {
        std::lock_guard lock(mutex_);
        if (!lost_) {
            id = next_id_++;
            Pipe p;
            p.path = path;
            p.member = member;
            p.unreliable = unreliable;
            p.handlers = std::make_shared<const GatewayPipeHandlers>(std::move(handlers));
            pipes_.emplace(id, std::move(p));
        }
    }
    if (!id) {
        done(fail(gone()));
        return;
    }
    std::weak_ptr<SessionEndpoints> weak = weak_from_this();
    upstream_.request(pipe_connect_request(std::move(path), std::move(member), unreliable),
                      [weak, id, done = std::move(done)](Result<MessageEntry> r) {
                          auto self = weak.lock();
                          if (!self) {
                              done(fail(MessageErrorType::OperationAborted, "the session to the device ended"));
                              return;
                          }
                          Result<void> outcome = reply_outcome(r);
                          if (outcome && entry_pipe_index(*r) < 0)
                              outcome = fail(MessageErrorType::ProtocolError, "PipeConnectRet without an index");
                          if (!outcome) {
                              {
                                  std::lock_guard lock(self->mutex_);
                                  self->pipes_.erase(id);
                              }
                              done(fail(outcome.error()));
                              return;
                          }
                          if (self->pipe_connected(id, std::move(r)))
                              done(id);
                          else
                              done(fail(MessageErrorType::OperationAborted, "pipe endpoint closed while connecting"));
                      });
}

bool SessionEndpoints::pipe_connected(std::uint64_t id, Result<MessageEntry> r) {
    const std::int32_t index = entry_pipe_index(*r);
    std::int32_t flag = 0;
    const bool unreliable = r->find("unreliable") && read_scalar(*r->find("unreliable"), flag) && flag == 1;
    std::optional<MessageEntry> disconnect;
    bool kept = false;
    {
        std::lock_guard lock(mutex_);
        auto it = pipes_.find(id);
        kept = it != pipes_.end();
        if (!kept) {
            // Closed while connecting: the device still holds the endpoint.
            if (!lost_) disconnect = pipe_disconnect_request(r->service_path, r->member_name, index);
        } else {
            it->second.connected = true;
            it->second.index = index;
            it->second.unreliable = unreliable;
            pipes_by_index_[{it->second.path, it->second.member, index}] = id;
        }
    }
    if (disconnect) upstream_.request(std::move(*disconnect), [](Result<MessageEntry>) {});
    return kept;
}

Result<std::uint32_t> SessionEndpoints::send_pipe_packet(std::uint64_t id, MessageElement packet, bool request_ack) {
    if (upstream_.queued_bytes && upstream_.queued_bytes() > kMaxBacklogBytes)
        return fail(MessageErrorType::BufferLimitViolation, "device connection backlog full");
    std::lock_guard lock(mutex_);
    if (lost_) return fail(gone());
    auto it = pipes_.find(id);
    if (it == pipes_.end() || !it->second.connected) return fail(MessageErrorType::InvalidArgument, "pipe endpoint not open");
    auto& p = it->second;
    const std::uint32_t number = p.send_number == UINT32_MAX ? 0 : p.send_number + 1;
    p.send_number = number;
    // Sent under the lock: packet numbers reach the device in order.
    auto sent = upstream_.send(pipe_packet_entry(p.path, p.member, p.index, number, std::move(packet), request_ack, p.unreliable));
    if (!sent) return fail(sent.error());
    return number;
}

void SessionEndpoints::close_pipe(std::uint64_t id) {
    std::optional<Pipe> p;
    {
        std::lock_guard lock(mutex_);
        auto it = pipes_.find(id);
        if (it == pipes_.end()) return;
        p = std::move(it->second);
        pipes_.erase(it);
        if (p->connected) pipes_by_index_.erase({p->path, p->member, p->index});
        if (!p->connected || lost_) return;  // a connect in flight is disconnected by its reply
    }
    upstream_.request(pipe_disconnect_request(p->path, p->member, p->index), [](Result<MessageEntry>) {});
}

// --- from the device ------------------------------------------------------------------------------

void SessionEndpoints::deliver(MessageEntry&& entry) {
    switch (entry.entry_type) {
        case MessageEntryType::EventReq:
        case MessageEntryType::WirePacket: {
            const bool wire = entry.entry_type == MessageEntryType::WirePacket;
            std::vector<Subscriber> subs;
            {
                std::lock_guard lock(mutex_);
                MemberKey key{entry.service_path, entry.member_name};
                if (wire) {
                    auto it = wires_.find(key);
                    if (it != wires_.end()) subs = it->second.subscribers;
                } else {
                    auto it = events_.find(key);
                    if (it != events_.end()) subs = it->second;
                }
            }
            if (subs.empty()) return;
            auto shared = std::make_shared<const SharedEntry>(std::move(entry));
            for (const auto& s : subs)
                if (s.handlers->on_entry) s.handlers->on_entry(shared);
            return;
        }
        case MessageEntryType::WireClosed: {
            std::vector<Subscriber> subs;
            {
                std::lock_guard lock(mutex_);
                auto it = wires_.find(MemberKey{entry.service_path, entry.member_name});
                if (it == wires_.end()) return;
                subs = std::move(it->second.subscribers);
                wires_.erase(it);
            }
            const RRError reason = make_error(MessageErrorType::ConnectionError, "wire closed by the device");
            for (const auto& s : subs)
                if (s.handlers->on_closed) s.handlers->on_closed(reason);
            return;
        }
        case MessageEntryType::PipePacket:
        case MessageEntryType::PipePacketRet: take_pipe_elements(entry); return;  // what is left is no one's
        case MessageEntryType::PipeClosed: pipe_closed(entry.service_path, entry.member_name, entry_pipe_index(entry)); return;
        default: return;
    }
}

bool SessionEndpoints::pipe_closed(const std::string& path, const std::string& member, std::int32_t index) {
    std::shared_ptr<const GatewayPipeHandlers> h;
    {
        std::lock_guard lock(mutex_);
        auto it = pipes_by_index_.find({path, member, index});
        if (it == pipes_by_index_.end()) return false;
        h = pipes_.at(it->second).handlers;
        pipes_.erase(it->second);
        pipes_by_index_.erase(it);
    }
    if (h->on_closed) h->on_closed(make_error(MessageErrorType::ConnectionError, "pipe endpoint closed by the device"));
    return true;
}

bool SessionEndpoints::take_pipe_elements(MessageEntry& entry) {
    const bool acks = entry.entry_type == MessageEntryType::PipePacketRet;
    struct Delivery {
        std::shared_ptr<const GatewayPipeHandlers> handlers;
        MessageElement packet;
        std::uint32_t number = 0;
    };
    std::vector<Delivery> deliveries;
    MessageEntry ack_entry;
    {
        std::lock_guard lock(mutex_);
        if (pipes_by_index_.empty()) return entry.elements.empty();
        std::vector<MessageElement> rest;
        for (auto& el : entry.elements) {
            // Packets name their pipe index; acks number it (wire.md §6.7).
            std::optional<std::int32_t> index = acks ? el.number : parse_pipe_index(el.name);
            auto it = index ? pipes_by_index_.find({entry.service_path, entry.member_name, *index}) : pipes_by_index_.end();
            if (it == pipes_by_index_.end()) {
                rest.push_back(std::move(el));
                continue;
            }
            const auto& handlers = pipes_.at(it->second).handlers;
            if (acks) {
                std::uint32_t number = 0;
                if (read_scalar(el, number)) deliveries.push_back(Delivery{handlers, MessageElement{}, number});
                continue;
            }
            auto got = take_pipe_packet(el);
            if (!got) continue;
            if (got->request_ack) ack_entry.elements.push_back(pipe_ack_element(*index, got->number));
            deliveries.push_back(Delivery{handlers, std::move(got->packet), got->number});
        }
        entry.elements = std::move(rest);
    }
    if (!ack_entry.elements.empty()) {
        ack_entry.entry_type = MessageEntryType::PipePacketRet;
        ack_entry.service_path = entry.service_path;
        ack_entry.member_name = entry.member_name;
        (void)upstream_.send(std::move(ack_entry));
    }
    for (auto& d : deliveries) {
        if (acks) {
            if (d.handlers->on_ack) d.handlers->on_ack(d.number);
        } else if (d.handlers->on_packet) {
            d.handlers->on_packet(d.packet, d.number);
        }
    }
    return entry.elements.empty();
}

void SessionEndpoints::lost(const RRError& reason) {
    std::vector<std::shared_ptr<const SubscriptionHandlers>> subs;
    std::vector<std::shared_ptr<const GatewayPipeHandlers>> pipes;
    std::vector<std::function<void(Result<std::uint64_t>)>> waiting;
    {
        std::lock_guard lock(mutex_);
        if (lost_) return;
        lost_ = reason;
        for (auto& [k, list] : events_)
            for (auto& s : list) subs.push_back(s.handlers);
        for (auto& [k, w] : wires_) {
            for (auto& [id, done] : w.waiting) waiting.push_back(std::move(done));
            for (auto& s : w.subscribers)
                if (w.connected) subs.push_back(s.handlers);
        }
        for (auto& [id, p] : pipes_)
            if (p.connected) pipes.push_back(p.handlers);  // a connect in flight fails with its request
        events_.clear();
        wires_.clear();
        pipes_.clear();
        pipes_by_index_.clear();
    }
    for (auto& done : waiting) done(fail(reason));
    for (auto& h : subs)
        if (h->on_closed) h->on_closed(reason);
    for (auto& h : pipes)
        if (h->on_closed) h->on_closed(reason);
}

void SessionEndpoints::resume() {
    std::lock_guard lock(mutex_);
    lost_.reset();
}

void SessionEndpoints::forget() {
    std::lock_guard lock(mutex_);
    if (!lost_) lost_ = make_error(MessageErrorType::ConnectionError, "the session to the device was closed");
    events_.clear();
    wires_.clear();
    pipes_.clear();
    pipes_by_index_.clear();
}

}  // namespace rr::server::gateway
