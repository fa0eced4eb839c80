#include "core/discovery/node_table.hpp"

#include <algorithm>

#include "base/names/connection_url.hpp"

namespace rr::discovery {

using std::chrono::milliseconds;

std::string_view node_source_name(NodeSource s) noexcept {
    switch (s) {
        case NodeSource::udp: return "udp";
        case NodeSource::local: return "local";
        case NodeSource::usb: return "usb";
        case NodeSource::other: return "other";
    }
    return "other";
}

std::chrono::milliseconds jitter(std::uint32_t random, unsigned lo_ms, unsigned hi_ms) noexcept {
    if (hi_ms <= lo_ms) return milliseconds(lo_ms);
    return milliseconds(lo_ms + random % (hi_ms - lo_ms + 1));
}

NodeInfo2 NodeEntry::info() const {
    NodeInfo2 n;
    n.node_id = node_id;
    n.node_name = node_name;
    for (const auto& u : urls) n.connection_urls.push_back(u.url);
    return n;
}

std::uint64_t NodeTableCounters::rejected_total() const noexcept {
    std::uint64_t t = 0;
    for (auto r : rejected) t += r;
    return t;
}

NodeTable::NodeTable(NodeTableLimits limits) : limits_(std::move(limits)) {
    if (limits_.max_nodes == 0) limits_.max_nodes = 1;
    if (limits_.max_urls_per_node == 0) limits_.max_urls_per_node = 1;
}

void NodeTable::note_rejected(Reject r) noexcept {
    auto i = static_cast<std::size_t>(r);
    if (i < std::size(counters_.rejected)) ++counters_.rejected[i];
}

bool NodeTable::url_acceptable(const std::string& url, const NodeID& id) const {
    if (url.size() > kMaxUrlLength) return false;
    auto u = parse_connection_url(url);
    return u && u->node_id == id;
}

void NodeTable::schedule_update(NodeEntry& e, MonoTime now, milliseconds delay) {
    if (!want_services_) return;
    auto due = now + delay;
    if (!e.update_due || *e.update_due > due) e.update_due = due;
}

void NodeTable::evict_oldest() {
    auto victim = nodes_.end();
    for (int pass = 0; pass < 2 && victim == nodes_.end(); ++pass) {
        for (auto it = nodes_.begin(); it != nodes_.end(); ++it) {
            if (pass == 0 && it->second.services) continue;  // first: only nodes that never answered
            if (victim == nodes_.end() || it->second.last_seen < victim->second.last_seen) victim = it;
        }
    }
    if (victim != nodes_.end()) {
        if (evicted_.size() < limits_.max_nodes) evicted_.push_back(std::move(victim->second));
        nodes_.erase(victim);
        ++counters_.evictions;
    }
}

std::vector<NodeEntry> NodeTable::take_evicted() {
    std::vector<NodeEntry> out;
    out.swap(evicted_);
    return out;
}

DetectResult NodeTable::node_detected(const NodeAnnouncement& a, MonoTime now, std::uint32_t random) {
    if (a.node_id.is_any()) return DetectResult::ignored;
    if (a.service_state_nonce.size() >= kMaxNonceLength) return DetectResult::ignored;
    const std::string name = a.node_name.size() <= kMaxNodeNameLength ? a.node_name : std::string();

    std::vector<const std::string*> good;
    for (const auto& u : a.urls) {
        if (url_acceptable(u, a.node_id) &&
            std::none_of(good.begin(), good.end(), [&](const std::string* g) { return *g == u; }))
            good.push_back(&u);
        else
            ++counters_.urls_rejected;
    }
    if (good.empty()) return DetectResult::ignored;
    if (good.size() > limits_.max_urls_per_node) {
        counters_.url_evictions += good.size() - limits_.max_urls_per_node;
        good.resize(limits_.max_urls_per_node);
    }
    ++counters_.announces;

    auto it = nodes_.find(a.node_id);
    if (it == nodes_.end()) {
        if (nodes_.size() >= limits_.max_nodes) evict_oldest();
        NodeEntry e;
        e.node_id = a.node_id;
        e.node_name = name;
        e.source = a.source;
        e.first_seen = e.last_seen = now;
        e.service_state_nonce = a.service_state_nonce;
        for (const auto* u : good) e.urls.push_back(DetectedUrl{*u, now});
        if (!a.service_state_nonce.empty()) e.recent_nonces.push_back(a.service_state_nonce);
        e.retry_window_start = now;
        schedule_update(e, now, jitter(random, 100, 600));
        nodes_.emplace(a.node_id, std::move(e));
        return DetectResult::added;
    }

    NodeEntry& e = it->second;
    bool changed = false;
    e.last_seen = std::max(e.last_seen, now);
    for (const auto* u : good) {
        auto known = std::find_if(e.urls.begin(), e.urls.end(), [&](const DetectedUrl& d) { return d.url == *u; });
        if (known != e.urls.end()) {
            known->last_announce = std::max(known->last_announce, now);
            continue;
        }
        if (e.urls.size() >= limits_.max_urls_per_node) {
            auto oldest = std::min_element(e.urls.begin(), e.urls.end(), [](const DetectedUrl& x, const DetectedUrl& y) {
                return x.last_announce < y.last_announce;
            });
            e.urls.erase(oldest);
            ++counters_.url_evictions;
        }
        e.urls.push_back(DetectedUrl{*u, now});
        changed = true;
    }
    if (!name.empty() && name != e.node_name) {
        e.node_name = name;
        changed = true;
    }
    const std::string& nonce = a.service_state_nonce;
    if (!nonce.empty() && nonce != e.service_state_nonce) {
        e.service_state_nonce = nonce;
        changed = true;
    }
    if (!nonce.empty()) {
        if (std::find(e.recent_nonces.begin(), e.recent_nonces.end(), nonce) == e.recent_nonces.end()) {
            e.recent_nonces.push_back(nonce);
            while (e.recent_nonces.size() > limits_.recent_nonces) e.recent_nonces.pop_front();
            if (nonce != e.services_nonce) schedule_update(e, now, jitter(random, 100, 600));
        }
    } else if (!e.services || now - e.services_time >= limits_.refresh_without_nonce) {
        if (!e.update_running && !e.update_due) schedule_update(e, now, jitter(random, 100, 600));
    }
    return changed ? DetectResult::updated : DetectResult::refreshed;
}

std::vector<NodeEntry> NodeTable::expire(MonoTime now) {
    std::vector<NodeEntry> lost;
    for (auto it = nodes_.begin(); it != nodes_.end();) {
        auto& urls = it->second.urls;
        urls.erase(std::remove_if(urls.begin(), urls.end(),
                                  [&](const DetectedUrl& u) { return now - u.last_announce >= limits_.url_expiry; }),
                   urls.end());
        if (urls.empty()) {
            ++counters_.expired;
            lost.push_back(std::move(it->second));
            it = nodes_.erase(it);
        } else {
            ++it;
        }
    }
    return lost;
}

std::optional<NodeEntry> NodeTable::remove(const NodeID& id) {
    auto it = nodes_.find(id);
    if (it == nodes_.end()) return std::nullopt;
    NodeEntry e = std::move(it->second);
    nodes_.erase(it);
    return e;
}

bool NodeTable::remove_urls(const NodeID& id, const std::vector<std::string>& urls, std::optional<NodeEntry>& lost) {
    lost.reset();
    auto it = nodes_.find(id);
    if (it == nodes_.end()) return false;
    auto& known = it->second.urls;
    const auto before = known.size();
    std::erase_if(known, [&](const DetectedUrl& u) { return std::find(urls.begin(), urls.end(), u.url) != urls.end(); });
    if (known.size() == before) return false;
    if (known.empty()) {
        lost = std::move(it->second);
        nodes_.erase(it);
    }
    return true;
}

void NodeTable::set_want_services(bool want, MonoTime now) {
    if (want == want_services_) return;
    want_services_ = want;
    if (!want) {
        for (auto& [id, e] : nodes_) e.update_due.reset();
        return;
    }
    std::uint32_t i = 0;
    for (auto& [id, e] : nodes_)
        if (!e.services || e.services_nonce != e.service_state_nonce || e.service_state_nonce.empty())
            schedule_update(e, now, jitter(i++ * 97u, 100, 600));
}

void NodeTable::refresh_all_services(MonoTime now, std::uint32_t random) {
    bool saved = want_services_;
    want_services_ = true;
    for (auto& [id, e] : nodes_)
        if (!e.update_running) schedule_update(e, now, jitter(random++ * 2654435761u, 100, 600));
    want_services_ = saved;
}

std::vector<NodeID> NodeTable::take_due_updates(MonoTime now) {
    std::vector<NodeID> out;
    for (auto& [id, e] : nodes_) {
        if (e.update_running || !e.update_due || *e.update_due > now) continue;
        e.update_due.reset();
        e.update_running = true;
        out.push_back(id);
    }
    return out;
}

bool NodeTable::services_updated(const NodeID& id, const std::string& nonce, std::vector<ServiceInfo2> services,
                                 MonoTime now) {
    auto it = nodes_.find(id);
    if (it == nodes_.end()) return false;
    NodeEntry& e = it->second;
    e.update_running = false;
    for (auto& s : services) {
        s.node_id = e.node_id;
        if (!e.node_name.empty()) s.node_name = e.node_name;
    }
    e.services = std::move(services);
    e.services_nonce = nonce;
    e.services_time = now;
    e.last_error.clear();
    if (e.services_nonce != e.service_state_nonce) {
        // The nonce moved while we asked: ask again (CORE does the same, with its back-off).
        services_failed(id, "", now, 0);
    } else {
        e.retry_count = 0;
    }
    return true;
}

void NodeTable::services_failed(const NodeID& id, std::string error, MonoTime now, std::uint32_t random) {
    auto it = nodes_.find(id);
    if (it == nodes_.end()) return;
    NodeEntry& e = it->second;
    e.update_running = false;
    if (!error.empty()) e.last_error = std::move(error);
    if (now - e.retry_window_start > std::chrono::seconds(60)) {
        e.retry_window_start = now;
        e.retry_count = 0;
    }
    const unsigned n = e.retry_count++;
    milliseconds backoff = jitter(random, 100, 600);
    if (n > 12)
        backoff = jitter(random, 25000, 35000);
    else if (n > 8)
        backoff = jitter(random, 9000, 11000);
    else if (n > 5)
        backoff = jitter(random, 4500, 5500);
    else if (n > 3)
        backoff = jitter(random, 2000, 2500);
    if (e.service_state_nonce.empty() && e.services) backoff += milliseconds(15000);
    bool saved = want_services_;
    want_services_ = true;  // a started interrogation finishes even if the wish went away meanwhile
    schedule_update(e, now, backoff);
    want_services_ = saved;
    if (!saved) e.update_due.reset();
}

std::optional<MonoTime> NodeTable::next_deadline() const {
    std::optional<MonoTime> t;
    auto consider = [&](MonoTime x) {
        if (!t || x < *t) t = x;
    };
    for (const auto& [id, e] : nodes_) {
        for (const auto& u : e.urls) consider(u.last_announce + limits_.url_expiry);
        if (e.update_due && !e.update_running) consider(*e.update_due);
    }
    return t;
}

std::optional<MonoTime> NodeTable::oldest_announce() const {
    std::optional<MonoTime> t;
    for (const auto& [id, e] : nodes_)
        for (const auto& u : e.urls)
            if (!t || u.last_announce < *t) t = u.last_announce;
    return t;
}

const NodeEntry* NodeTable::find(const NodeID& id) const {
    auto it = nodes_.find(id);
    return it == nodes_.end() ? nullptr : &it->second;
}

std::vector<const NodeEntry*> NodeTable::find_by_name(std::string_view name) const {
    std::vector<const NodeEntry*> out;
    for (const auto& [id, e] : nodes_)
        if (e.node_name == name) out.push_back(&e);
    return out;
}

}  // namespace rr::discovery
