#include "server/gateway/upstream_subscriptions.hpp"

#include <algorithm>

namespace rr::server::gateway {
namespace {

using InternalSubs = UpstreamSubscriptions::InternalSubs;
using InternalSub = UpstreamSubscriptions::InternalSub;

bool no_subscribers(const InternalSubs& subs) { return !subs || subs->empty(); }

InternalSubs with_subscriber(const InternalSubs& subs, InternalSub sub) {
    auto next = subs ? std::make_shared<std::vector<InternalSub>>(*subs) : std::make_shared<std::vector<InternalSub>>();
    next->push_back(std::move(sub));
    return next;
}

InternalSubs without_subscriber(const InternalSubs& subs, std::uint64_t id) {
    if (!subs || std::none_of(subs->begin(), subs->end(), [&](const InternalSub& s) { return s.id == id; })) return subs;
    auto next = std::make_shared<std::vector<InternalSub>>();
    for (const auto& s : *subs)
        if (s.id != id) next->push_back(s);
    return next;
}

using SessionList = UpstreamSubscriptions::SessionList;

// The list without the sessions `drop` selects (the same list when it selects none).
template <class Drop>
SessionList without_sessions(const SessionList& list, Drop&& drop) {
    if (std::none_of(list->begin(), list->end(), drop)) return list;
    auto next = std::make_shared<std::vector<SessionRef>>();
    for (const auto& s : *list)
        if (!drop(s)) next->push_back(s);
    return next;
}

}  // namespace

const SessionList& UpstreamSubscriptions::empty_sessions() {
    static const SessionList empty = std::make_shared<const std::vector<SessionRef>>();
    return empty;
}

bool UpstreamSubscriptions::unused(const Wire& w) { return w.sessions->empty() && no_subscribers(w.internal); }

UpstreamSubscriptions::Joined UpstreamSubscriptions::join_wire(const MemberKey& key, const SessionRef& session,
                                                               Ready on_ready) {
    std::lock_guard lock(mutex_);
    Wire& w = wires_[key];
    if (std::find(w.sessions->begin(), w.sessions->end(), session) == w.sessions->end()) {
        auto next = std::make_shared<std::vector<SessionRef>>(*w.sessions);
        next->push_back(session);
        w.sessions = std::move(next);
    }
    if (w.upstream_connected) return {true, w.last};
    w.waiting.push_back(std::move(on_ready));
    return {};
}

bool UpstreamSubscriptions::leave_wire(const MemberKey& key, const SessionRef& session) {
    std::lock_guard lock(mutex_);
    auto it = wires_.find(key);
    if (it == wires_.end()) return false;
    it->second.sessions = without_sessions(it->second.sessions, [&](const SessionRef& s) { return s == session; });
    if (!unused(it->second) || !it->second.upstream_connected) return false;
    wires_.erase(it);
    return true;
}

bool UpstreamSubscriptions::has_session(const MemberKey& key, const SessionRef& session) const {
    std::lock_guard lock(mutex_);
    auto it = wires_.find(key);
    return it != wires_.end() && std::find(it->second.sessions->begin(), it->second.sessions->end(), session) !=
                                     it->second.sessions->end();
}

std::vector<UpstreamSubscriptions::MemberKey> UpstreamSubscriptions::leave_all(std::uint32_t endpoint) {
    std::vector<MemberKey> disconnect;
    std::lock_guard lock(mutex_);
    for (auto it = wires_.begin(); it != wires_.end();) {
        const SessionList before = it->second.sessions;
        it->second.sessions = without_sessions(before, [&](const SessionRef& s) { return s.endpoint() == endpoint; });
        const bool removed = it->second.sessions != before;
        if (removed && unused(it->second) && it->second.upstream_connected) {
            disconnect.push_back(it->first);
            it = wires_.erase(it);
        } else {
            ++it;
        }
    }
    return disconnect;
}

std::pair<std::uint64_t, UpstreamSubscriptions::Joined> UpstreamSubscriptions::add_internal(const MemberKey& key,
                                                                                            bool is_wire,
                                                                                            OnEntry on_entry,
                                                                                            Ready on_ready) {
    std::lock_guard lock(mutex_);
    const std::uint64_t id = next_id_++;
    if (!is_wire) {
        auto& subs = events_[key];
        subs = with_subscriber(subs, InternalSub{id, std::move(on_entry)});
        return {id, Joined{true, nullptr}};
    }
    Wire& w = wires_[key];
    w.internal = with_subscriber(w.internal, InternalSub{id, std::move(on_entry)});
    if (w.upstream_connected) return {id, Joined{true, w.last}};
    w.waiting.push_back(std::move(on_ready));
    return {id, Joined{false, w.last}};
}

std::vector<UpstreamSubscriptions::MemberKey> UpstreamSubscriptions::remove_internal(std::uint64_t id) {
    std::vector<MemberKey> disconnect;
    std::lock_guard lock(mutex_);
    for (auto it = events_.begin(); it != events_.end();) {
        it->second = without_subscriber(it->second, id);
        it = no_subscribers(it->second) ? events_.erase(it) : std::next(it);
    }
    for (auto it = wires_.begin(); it != wires_.end();) {
        Wire& w = it->second;
        w.internal = without_subscriber(w.internal, id);
        if (unused(w) && w.upstream_connected) {
            disconnect.push_back(it->first);
            it = wires_.erase(it);
        } else if (unused(w) && !w.connecting && w.waiting.empty()) {
            it = wires_.erase(it);  // never connected upstream (refused, or the device was away)
        } else {
            ++it;
        }
    }
    return disconnect;
}

bool UpstreamSubscriptions::begin_connect(const MemberKey& key) {
    std::lock_guard lock(mutex_);
    auto it = wires_.find(key);
    if (it == wires_.end() || it->second.upstream_connected || it->second.connecting) return false;
    it->second.connecting = true;
    return true;
}

std::vector<UpstreamSubscriptions::Ready> UpstreamSubscriptions::connect_done(const MemberKey& key,
                                                                              const Result<void>& outcome) {
    std::vector<Ready> waiting;
    std::lock_guard lock(mutex_);
    auto it = wires_.find(key);
    if (it == wires_.end()) return waiting;
    Wire& w = it->second;
    w.connecting = false;
    w.upstream_connected = outcome.ok();
    waiting.swap(w.waiting);
    if (!outcome.ok()) {
        w.sessions = empty_sessions();
        if (no_subscribers(w.internal)) wires_.erase(it);
    }
    return waiting;
}

std::vector<UpstreamSubscriptions::Ready> UpstreamSubscriptions::no_upstream(const MemberKey& key) {
    std::vector<Ready> waiting;
    std::lock_guard lock(mutex_);
    auto it = wires_.find(key);
    if (it != wires_.end() && !it->second.upstream_connected && !it->second.connecting) waiting.swap(it->second.waiting);
    return waiting;
}

std::vector<UpstreamSubscriptions::Ready> UpstreamSubscriptions::upstream_lost() {
    std::vector<Ready> waiting;
    std::lock_guard lock(mutex_);
    for (auto& [key, w] : wires_) {
        w.upstream_connected = false;
        w.connecting = false;
        for (auto& r : w.waiting) waiting.push_back(std::move(r));
        w.waiting.clear();
    }
    return waiting;
}

std::vector<UpstreamSubscriptions::MemberKey> UpstreamSubscriptions::upstream_back() {
    std::vector<MemberKey> reconnect;
    std::lock_guard lock(mutex_);
    for (auto& [key, w] : wires_) {
        w.upstream_connected = false;
        w.connecting = false;
        if (!unused(w)) reconnect.push_back(key);
    }
    return reconnect;
}

std::optional<UpstreamSubscriptions::Targets> UpstreamSubscriptions::wire_value(const SharedEntryPtr& value) {
    const MessageEntry& e = value->entry();
    std::lock_guard lock(mutex_);
    auto it = wires_.find(MemberKey(e.service_path, e.member_name));
    if (it == wires_.end()) return std::nullopt;
    it->second.last = value;
    return Targets{it->second.sessions, it->second.internal};
}

std::optional<UpstreamSubscriptions::Targets> UpstreamSubscriptions::wire_closed(const MemberKey& key) {
    std::lock_guard lock(mutex_);
    auto it = wires_.find(key);
    if (it == wires_.end()) return std::nullopt;
    Targets t{it->second.sessions, std::move(it->second.internal)};
    wires_.erase(it);
    return t;
}

SharedEntryPtr UpstreamSubscriptions::newest(const MemberKey& key) const {
    std::lock_guard lock(mutex_);
    auto it = wires_.find(key);
    return it == wires_.end() ? nullptr : it->second.last;
}

UpstreamSubscriptions::InternalSubs UpstreamSubscriptions::event_subscribers(const MemberKey& key) const {
    std::lock_guard lock(mutex_);
    auto it = events_.find(key);
    return it == events_.end() ? nullptr : it->second;
}

std::size_t UpstreamSubscriptions::wire_count() const {
    std::lock_guard lock(mutex_);
    return wires_.size();
}

}  // namespace rr::server::gateway
