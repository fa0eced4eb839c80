#include "server/gateway/json_subscriptions.hpp"

#include <algorithm>
#include <string>
#include <utility>

#include "robdef/service_definition.hpp"
#include "server/gateway/conversion_budget.hpp"

namespace rr::server::gateway {

std::string_view kind_name(SubscriptionKind kind) {
    switch (kind) {
        case SubscriptionKind::wire: return "wire";
        case SubscriptionKind::event: return "event";
        case SubscriptionKind::pipe: return "pipe";
    }
    return "?";
}

std::variant<std::uint64_t, ApiError> JsonSubscriptions::add(JsonSubscription s) {
    if (subs_.size() >= max_)
        return api_error(400, MessageErrorType::BufferLimitViolation,
                         "more than " + std::to_string(max_) + " subscriptions on this socket");
    const std::uint64_t sid = next_id_++;
    subs_.emplace(sid, std::move(s));
    return sid;
}

JsonSubscription* JsonSubscriptions::find(std::uint64_t sid) {
    auto it = subs_.find(sid);
    return it == subs_.end() ? nullptr : &it->second;
}

std::optional<JsonSubscription> JsonSubscriptions::take_active(std::uint64_t sid) {
    auto it = subs_.find(sid);
    if (it == subs_.end() || !it->second.active) return std::nullopt;
    std::optional<JsonSubscription> s = std::move(it->second);
    subs_.erase(it);
    return s;
}

std::variant<const JsonSubscription*, ApiError> JsonSubscriptions::find_active(std::uint64_t sid,
                                                                              SubscriptionKind kind) const {
    auto it = subs_.find(sid);
    if (it == subs_.end() || !it->second.active)
        return api_error(400, MessageErrorType::InvalidArgument, "no subscription " + std::to_string(sid));
    if (it->second.kind != kind)
        return api_error(400, MessageErrorType::InvalidArgument,
                         "subscription " + std::to_string(sid) + " is " + robdef::with_article(kind_name(it->second.kind)) +
                             " subscription, not " + robdef::with_article(kind_name(kind)));
    return &it->second;
}

bool JsonSubscriptions::is_active(std::uint64_t sid) const {
    auto it = subs_.find(sid);
    return it != subs_.end() && it->second.active;
}

std::vector<std::uint64_t> JsonSubscriptions::remove_own(const std::shared_ptr<SessionEndpoints>& own) {
    std::vector<std::uint64_t> ended;
    for (auto it = subs_.begin(); it != subs_.end();) {
        if (it->second.own != own) {
            ++it;
            continue;
        }
        if (it->second.active) ended.push_back(it->first);
        it = subs_.erase(it);
    }
    return ended;
}

std::map<std::uint64_t, JsonSubscription> JsonSubscriptions::take_all() { return std::exchange(subs_, {}); }

std::optional<PushTicket> JsonSubscriptions::take_push(std::uint64_t sid, bool congested) {
    auto it = subs_.find(sid);
    if (it == subs_.end() || !it->second.active) return std::nullopt;
    if (congested) {
        ++it->second.dropped;
        ++push_drops_;
        return std::nullopt;
    }
    return PushTicket{it->second.target, std::exchange(it->second.dropped, 0), it->second.binary};
}

void JsonSubscriptions::return_push(std::uint64_t sid, std::uint64_t ticket_dropped) {
    if (auto* s = find(sid)) s->dropped += ticket_dropped + 1;
    ++push_drops_;
}

Offered JsonSubscriptions::offer_wire(std::uint64_t sid, SharedEntryPtr value, RateClock now, std::uint64_t coalesced,
                                      std::uint64_t seq) {
    auto* s = find(sid);
    if (!s) return {};
    wire_coalesced_ += coalesced;
    if (seq != 0) {
        if (seq <= s->wire_seq) {  // older than one it had: replaced unseen
            ++wire_coalesced_;
            return {};
        }
        s->wire_seq = seq;
    }
    if (s->pending_wire) ++wire_coalesced_;
    s->pending_wire = std::move(value);  // newest wins
    if (!s->active) return {};
    if (s->rate.open(now)) return {true, {}};
    return {false, s->rate.period()};
}

bool JsonSubscriptions::wires_waiting(RateClock now) const {
    for (const auto& [sid, s] : subs_)
        if (s.active && s.pending_wire && s.rate.open(now)) return true;
    return false;
}

void JsonSubscriptions::take_wires(std::vector<WireToSend>& out, RateClock now) {
    out.clear();
    for (auto& [sid, s] : subs_) {
        if (!s.active || !s.pending_wire || !s.rate.open(now)) continue;
        s.rate.sent(now);
        out.push_back(WireToSend{sid, std::exchange(s.pending_wire, nullptr), s.target, s.binary});
    }
}

void JsonSubscriptions::rate_waiting(RateClock now, std::vector<RateClock>& out) const {
    for (const auto& [sid, s] : subs_)
        if (s.active && s.pending_wire && !s.rate.open(now)) out.push_back(s.rate.period());
}

namespace {

// The oldest queued packet of `s` with its push ticket.
PipeToSend pop_packet(std::uint64_t sid, JsonSubscription& s) {
    PipeToSend p{sid, std::move(s.pipe_queue.front()), PushTicket{s.target, std::exchange(s.dropped, 0), s.binary}};
    s.pipe_queue.pop_front();
    s.queued_bytes -= std::min(s.queued_bytes, payload_bytes(p.packet));
    return p;
}

}  // namespace

Offered JsonSubscriptions::offer_pipe(std::uint64_t sid, MessageElement packet, bool congested, RateClock now,
                                      std::optional<PipeToSend>& out) {
    out.reset();
    auto* s = find(sid);
    if (!s || !s->active) return {};
    s->queued_bytes += payload_bytes(packet);
    s->pipe_queue.push_back(std::move(packet));
    // Newest kept: the oldest go while the queue is over its length or its bytes (one packet always stays).
    while (s->pipe_queue.size() > 1 && (s->pipe_queue.size() > s->queue_length || s->queued_bytes > s->queue_bytes_limit)) {
        s->queued_bytes -= std::min(s->queued_bytes, payload_bytes(s->pipe_queue.front()));
        s->pipe_queue.pop_front();
        ++s->dropped;
        ++push_drops_;
    }
    if (congested || !s->rate.open(now)) return {false, s->rate.period()};
    s->rate.sent(now);
    out = pop_packet(sid, *s);
    return {true, {}};
}

void JsonSubscriptions::take_pipe_packets(std::vector<PipeToSend>& out, bool congested, RateClock now,
                                          std::vector<RateClock>& waiting) {
    out.clear();
    for (auto& [sid, s] : subs_) {
        if (!s.active || s.pipe_queue.empty()) continue;
        if (congested || !s.rate.open(now)) {
            waiting.push_back(s.rate.period());
            continue;
        }
        s.rate.sent(now);
        out.push_back(pop_packet(sid, s));
        if (!s.pipe_queue.empty()) waiting.push_back(s.rate.period());
    }
}

std::size_t JsonSubscriptions::pending_wires() const {
    std::size_t n = 0;
    for (const auto& [sid, s] : subs_) n += (s.pending_wire || !s.pipe_queue.empty()) ? 1 : 0;
    return n;
}

}  // namespace rr::server::gateway
