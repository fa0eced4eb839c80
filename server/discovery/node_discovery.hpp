// Node discovery on the network (wire.md §11; docs/discovery.md): UDP port 48653, IPv6 link-local
// multicast FF02::BA86 joined on every interface with a link-local address (the official default),
// IPv4 broadcast to 255.255.255.255 when kIpv4Broadcast is set (opt-in, as in the official flags).
//
//   listening    receives announces and requests; announces go through core's parse_packet checks into
//                core's NodeTable (expiry, caps, eviction); sends request rounds when started and on
//                send_requests_now().
//   announcing   sends our announce (NodeID, NodeName, one rr+tcp URL per listening address: IPv6
//                link-local and loopback addresses on their own interface, IPv4 ones by broadcast) every
//                55 s, within 500 ms of a request from another node or of services_changed().
//   refreshing   when a URL in the table reaches 3/4 of its expiry, a request round asks live nodes to
//                announce again (at most one round per 1/4 of the expiry): a lost announce does not
//                drop a live node, and a short expiry works with the official 55 s period. (CORE relies
//                on the periodic announces alone.)
//   services     when wanted (want_services()), interrogates each node's RobotRaconteurServiceIndex with
//                GetLocalNodeServices() (5 s timeout, at most 4 at once) and keeps the ServiceInfo2
//                records in the table.
//
// Link-local URLs are announced without a zone (as CORE does); connectable_urls() adds the interface
// the node's datagrams came from (`[fe80::1%3]`), or every local link-local interface when unknown.
//
// Other sources (rr+local node directories, USB devices: discovery_sources.hpp) add their nodes with
// add_node() and take their URLs back with remove_urls(); they share the table, the events and the
// interrogation (over rr+local and rr+usb too, interrogate_schemes).
//
// Thread-safety: every public function may be called from any thread. Listeners run on the discovery's
// strand without locks held; they must not block.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>

#include "core/discovery/discovery_timing.hpp"
#include "core/discovery/node_table.hpp"
#include "server/discovery/local_addresses.hpp"
#include "server/transport/transport_registry.hpp"

namespace rr::server::discovery {

using rr::discovery::NodeAnnouncement;
using rr::discovery::NodeEntry;
using rr::discovery::NodeTableCounters;
using rr::discovery::ServiceInfo2;

struct DiscoveryOptions {
    NodeID node_id;         ///< ours (announced; our own packets are ignored); all-zero: listen only
    std::string node_name;  ///< announced after the NodeID when not empty
    bool listen = true;
    bool announce = false;
    /// rr::discovery::DiscoveryFlags: kLinkLocal (default), kNodeLocal, kSiteLocal, kIpv4Broadcast.
    std::uint32_t flags = rr::discovery::kLinkLocal;
    std::uint16_t port = rr::discovery::kDiscoveryPort;
    std::chrono::milliseconds announce_period = rr::discovery::kDefaultAnnouncePeriod;
    rr::discovery::NodeTableLimits limits;
    /// The node's TCP listening endpoints to announce (wildcards are expanded to the local addresses).
    std::function<std::vector<boost::asio::ip::tcp::endpoint>()> listen_endpoints;
    /// URL schemes used to interrogate service indexes (a node's URLs of other schemes are not asked).
    std::vector<std::string> interrogate_schemes{"rr+tcp", "rr+local", "rr+usb"};
    /// Connectors for the interrogations (nullptr: server::default_transports()); a gateway passes its
    /// node's, which holds rr+usb when USB is on. Must outlive the discovery.
    const TransportRegistry* transports = nullptr;
    /// The node's ServiceStateNonce, announced (wire.md §11.1): the node owns one nonce that its
    /// announces and its rr+local entries both carry (Node::service_state_nonce()). Unset: the
    /// discovery keeps its own, renewed by services_changed().
    std::function<std::string()> service_state_nonce;
    std::chrono::milliseconds interrogate_timeout{5000};
    std::size_t max_parallel_interrogations = 4;
    /// Interface names to use (join, send); empty = every interface.
    std::vector<std::string> interfaces;
    /// Nodes never put in the table, whichever source reports them (as our own NodeID): a gateway's
    /// own demo node, which announces itself but is part of the gateway.
    std::vector<NodeID> ignored_nodes;
};

struct DiscoveryEvent {
    enum class Kind { node_added, node_updated, node_lost, services_updated };
    Kind kind;
    NodeEntry node;  ///< a copy of the table entry (for node_lost: the entry as it was)
};
std::string_view discovery_event_name(DiscoveryEvent::Kind k) noexcept;

class NodeDiscovery : public std::enable_shared_from_this<NodeDiscovery> {
public:
    static std::shared_ptr<NodeDiscovery> create(boost::asio::any_io_executor executor, DiscoveryOptions options);
    ~NodeDiscovery();

    /// Opens the sockets and starts the timers. Errors: IOError when no socket could be opened.
    Result<void> start();
    /// Closes the sockets and cancels everything, then waits (at most `wait`) until the interrogations
    /// in flight have ended (a connect to a silent address ends at its 5 s timeout) and their clients'
    /// connections have closed, all within `wait`: stopping the executor under a pending client
    /// connect or disconnect would leave it unfinished. Idempotent. Not on the executor's threads when
    /// `wait` > 0.
    void stop(std::chrono::milliseconds wait = std::chrono::milliseconds(0));

    /// Starts a round of 3 discovery requests (ignored when a round is running).
    void send_requests_now();
    /// Our services changed: announced within 500 ms with the new ServiceStateNonce (the provider's,
    /// or a fresh one of our own when options().service_state_nonce is unset).
    void services_changed();
    /// The current ServiceStateNonce.
    std::string service_state_nonce() const;

    /// Keeps ServiceInfo2 fresh while at least one holder exists (reference counted).
    void want_services(bool want);
    /// Interrogates every known node again now (e.g. `rr discover`).
    void refresh_services();

    /// Adds a node found by another source (rr+local directory, USB): the same table and events.
    rr::discovery::DetectResult add_node(const NodeAnnouncement& announcement);
    /// Removes a node whose source says it is gone (fires node_lost).
    void remove_node(const NodeID& id);
    /// Removes the URLs one source knew a node by (an rr+local entry gone, a USB device unplugged):
    /// node_lost when none is left, node_updated when other sources still know it.
    void remove_urls(const NodeID& id, const std::vector<std::string>& urls);

    std::vector<NodeEntry> nodes() const;
    std::optional<NodeEntry> node(const NodeID& id) const;
    NodeTableCounters counters() const;
    std::size_t size() const;
    /// Interrogations that are running.
    std::size_t interrogations() const;

    /// URLs to connect to `url` with: the zone of a link-local host added (see header comment).
    std::vector<std::string> connectable_urls(const std::string& url) const;

    /// Listeners run on the discovery's strand. One removed (remove_listener, or all by stop) is not
    /// called for events delivered after that, even ones made before; a call already running finishes.
    using Listener = std::function<void(const DiscoveryEvent&)>;
    std::uint64_t add_listener(Listener listener);
    void remove_listener(std::uint64_t id);

    const DiscoveryOptions& options() const noexcept { return options_; }
    /// The UDP port the first socket is bound to (options().port unless that was 0).
    std::uint16_t bound_port() const;

private:
    NodeDiscovery(boost::asio::any_io_executor executor, DiscoveryOptions options);
    /// Closes the sockets and the interrogations' clients at once; returns those clients (empty when
    /// already stopped).
    std::map<std::uint64_t, std::shared_ptr<void>> stop_now();
    bool ignored(const NodeID& id) const;  ///< in options_.ignored_nodes
    struct Socket;
    void open_sockets();
    std::vector<LocalAddress> addresses() const;
    void receive(const std::shared_ptr<Socket>& s);
    void on_datagram(std::string_view data, const boost::asio::ip::udp::endpoint& from);
    void arm_timer();
    void on_timer();
    void send_announces();
    void send_requests();
    void send_datagram(const boost::asio::ip::address& source, const std::string& text, bool ipv4_broadcast);
    void start_interrogations(std::vector<NodeID> due);
    void interrogate(NodeID id, std::vector<std::string> urls, std::size_t index, std::string nonce);
    void emit(std::vector<DiscoveryEvent> events);
    std::uint32_t random32();
    rr::discovery::MonoTime now() const { return std::chrono::steady_clock::now(); }

    boost::asio::any_io_executor executor_;
    boost::asio::strand<boost::asio::any_io_executor> strand_;
    DiscoveryOptions options_;
    boost::asio::steady_timer timer_;

    mutable std::mutex mutex_;
    rr::discovery::NodeTable table_;
    rr::discovery::AnnounceSchedule announce_;
    rr::discovery::RequestSchedule requests_;
    NodeID request_id_;
    std::string nonce_;
    std::map<std::string, unsigned> zones_;  // link-local host text -> interface index it was heard on
    std::vector<std::shared_ptr<Socket>> sockets_;
    std::vector<unsigned> joined_scopes_;
    rr::discovery::MonoTime next_rescan_{};
    rr::discovery::MonoTime last_refresh_{};
    std::optional<rr::discovery::MonoTime> refresh_deadline() const;  // under mutex_
    std::map<std::uint64_t, Listener> listeners_;
    std::uint64_t next_listener_ = 1;
    int want_services_ = 0;
    std::size_t running_interrogations_ = 0;
    std::vector<NodeID> waiting_interrogations_;
    // Clients of the interrogations in flight: held here (their completions hold only weak references),
    // closed and dropped by stop(), so that a call cut short by shutdown leaves no cycle behind.
    std::map<std::uint64_t, std::shared_ptr<void>> interrogation_clients_;
    std::uint64_t next_interrogation_ = 1;
    std::mt19937 rng_;
    bool started_ = false;
    bool stopped_ = false;
};

}  // namespace rr::server::discovery
