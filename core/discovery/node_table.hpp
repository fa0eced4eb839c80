// The table of detected nodes (official CORE Discovery.cpp NodeDetected / CleanDiscoveredNodes), fed
// with announcements and the time, sans-IO:
//
//   * every URL of a node expires 60 s after its last announcement; a node without URLs is lost;
//   * the table holds at most `max_nodes` nodes and `max_urls_per_node` URLs per node: a new node
//     beyond the cap evicts the node heard from least recently among those whose service index never
//     answered (else the least recent of all), a new URL the oldest URL. CORE instead drops newcomers
//     at 4096 nodes; evicting lets a live network recover once a flood of forged NodeIDs stops, and
//     preferring unverified nodes keeps the real ones (a forged NodeID never answers). Evictions are
//     counted and the evicted entries handed out (take_evicted) so that users treat them as lost.
//   * ServiceInfo2 (services of a node) is fetched by the caller when `want_services` is set: a node is
//     due 100–600 ms after it is first seen or announces a ServiceStateNonce not seen recently (CORE
//     keeps the last 16), and again after a failure with CORE's progressive back-off. A node announcing
//     no nonce is refreshed when its services are older than `refresh_without_nonce`.
//
// Sources other than UDP (rr+local node directories, USB devices) feed the same table through
// node_detected() with their own NodeSource.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/discovery/discovery_packet.hpp"
#include "core/discovery/service_info.hpp"

namespace rr::discovery {

using MonoTime = std::chrono::steady_clock::time_point;

enum class NodeSource : std::uint8_t { udp, local, usb, other };
std::string_view node_source_name(NodeSource s) noexcept;

/// One sighting of a node, from any source.
struct NodeAnnouncement {
    NodeID node_id;
    std::string node_name;
    std::vector<std::string> urls;  ///< each must parse and carry nodeid = node_id (others are dropped)
    std::string service_state_nonce;
    NodeSource source = NodeSource::udp;
};

struct NodeTableLimits {
    std::size_t max_nodes = 1024;
    std::size_t max_urls_per_node = 8;
    std::chrono::milliseconds url_expiry{60000};
    std::size_t recent_nonces = 16;
    std::chrono::milliseconds refresh_without_nonce{55000};
    ServiceInfoLimits services;
};

struct DetectedUrl {
    std::string url;
    MonoTime last_announce{};
};

/// A node in the table.
struct NodeEntry {
    NodeID node_id;
    std::string node_name;
    std::vector<DetectedUrl> urls;
    std::string service_state_nonce;
    NodeSource source = NodeSource::udp;
    MonoTime first_seen{}, last_seen{};
    /// Services from the last successful interrogation (nullopt: never fetched).
    std::optional<std::vector<ServiceInfo2>> services;
    std::string services_nonce;  ///< the node's nonce when the services were fetched
    MonoTime services_time{};
    std::string last_error;      ///< why the last interrogation failed ("" = none)

    NodeInfo2 info() const;

    // interrogation scheduling (internal)
    std::deque<std::string> recent_nonces;
    std::optional<MonoTime> update_due;
    bool update_running = false;
    unsigned retry_count = 0;
    MonoTime retry_window_start{};
};

struct NodeTableCounters {
    std::uint64_t announces = 0;      ///< announcements accepted
    std::uint64_t evictions = 0;      ///< nodes evicted by the cap
    std::uint64_t url_evictions = 0;  ///< URLs evicted by the per-node cap
    std::uint64_t urls_rejected = 0;  ///< URLs of an announcement that did not parse or named another node
    std::uint64_t expired = 0;        ///< nodes lost by expiry
    std::uint64_t rejected[16] = {};  ///< datagrams rejected, by Reject value (note_rejected)
    std::uint64_t rejected_total() const noexcept;
};

enum class DetectResult : std::uint8_t {
    ignored,    ///< no usable URL, all-zero NodeID
    added,      ///< a new node
    updated,    ///< a known node: new URL, name or nonce
    refreshed,  ///< a known node: only announce times moved
};

class NodeTable {
public:
    explicit NodeTable(NodeTableLimits limits = {});

    /// Feeds one sighting. `random` (any value) spreads the first interrogation over 100–600 ms.
    DetectResult node_detected(const NodeAnnouncement& a, MonoTime now, std::uint32_t random = 0);
    /// Removes URLs older than the expiry and nodes left without URLs; returns the lost nodes.
    std::vector<NodeEntry> expire(MonoTime now);
    /// Nodes evicted by the cap since the last call.
    std::vector<NodeEntry> take_evicted();
    /// Removes a node at once (its source says it is gone, e.g. an rr+local socket vanished).
    std::optional<NodeEntry> remove(const NodeID& id);
    /// Removes some URLs of a node (one source says they are gone; others may still know the node).
    /// `lost`: the node when no URL is left (then removed from the table). Returns true when a URL was
    /// removed.
    bool remove_urls(const NodeID& id, const std::vector<std::string>& urls, std::optional<NodeEntry>& lost);

    /// Whether ServiceInfo2 is wanted (some subscriber needs services): nodes become due for interrogation.
    void set_want_services(bool want, MonoTime now);
    bool want_services() const noexcept { return want_services_; }
    /// Asks for a fresh interrogation of every node (e.g. `rr discover`), due within 100–600 ms.
    void refresh_all_services(MonoTime now, std::uint32_t random = 0);
    /// Nodes due for interrogation now; each is marked running until services_updated/services_failed.
    std::vector<NodeID> take_due_updates(MonoTime now);
    /// The interrogation started when the node's nonce was `nonce` succeeded. Returns false when the
    /// node is gone. Records are re-stamped with the node's NodeID and name.
    bool services_updated(const NodeID& id, const std::string& nonce, std::vector<ServiceInfo2> services, MonoTime now);
    /// The interrogation failed: retried after CORE's back-off (100–600 ms, growing to 25–35 s).
    void services_failed(const NodeID& id, std::string error, MonoTime now, std::uint32_t random = 0);

    /// The oldest announce time of any URL in the table (the next to expire), or nullopt when empty.
    std::optional<MonoTime> oldest_announce() const;
    /// Earliest time expire() or take_due_updates() has work, or nullopt.
    std::optional<MonoTime> next_deadline() const;

    const NodeEntry* find(const NodeID& id) const;
    /// Nodes whose NodeName equals `name`.
    std::vector<const NodeEntry*> find_by_name(std::string_view name) const;
    const std::map<NodeID, NodeEntry>& nodes() const noexcept { return nodes_; }
    std::size_t size() const noexcept { return nodes_.size(); }
    const NodeTableLimits& limits() const noexcept { return limits_; }

    void note_rejected(Reject r) noexcept;
    const NodeTableCounters& counters() const noexcept { return counters_; }

private:
    bool url_acceptable(const std::string& url, const NodeID& id) const;
    void schedule_update(NodeEntry& e, MonoTime now, std::chrono::milliseconds delay);
    void evict_oldest();

    NodeTableLimits limits_;
    std::map<NodeID, NodeEntry> nodes_;
    std::vector<NodeEntry> evicted_;
    NodeTableCounters counters_;
    bool want_services_ = false;
};

/// Spreads `random` over [lo, hi] milliseconds.
std::chrono::milliseconds jitter(std::uint32_t random, unsigned lo_ms, unsigned hi_ms) noexcept;

}  // namespace rr::discovery
