// Sources of the discovery table besides UDP (docs/discovery.md, "Other sources"): the rr+local nodes
// of this computer (server/transport/local/local_discovery.hpp) feed NodeDiscovery::add_node() with
// NodeSource::local and their rr+local URLs, and take those URLs back (remove_urls) when the node's
// entry goes or its process ends. A node also known by UDP then keeps its other URLs. USB devices have
// their own source next to the USB transport (server/discovery/usb_discovery.hpp).
#pragma once

#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>

#include "server/discovery/node_discovery.hpp"
#include "server/transport/local/local_discovery.hpp"

namespace rr::server::discovery {

struct LocalSourceOptions {
    local::NodeDirectories dirs;  ///< usually local::default_node_directories()
    /// Passed to the watcher; its poll_interval is capped at a third of the table's URL expiry so that a
    /// running node's rr+local URL never expires between two scans.
    local::LocalWatchOptions watch;
};

/// Feeds a NodeDiscovery with the local nodes while it exists or until stop(). The discovery's own
/// NodeID is never added.
class LocalDiscoverySource : public std::enable_shared_from_this<LocalDiscoverySource> {
public:
    static std::shared_ptr<LocalDiscoverySource> start(boost::asio::any_io_executor executor,
                                                       std::shared_ptr<NodeDiscovery> discovery, LocalSourceOptions options);
    ~LocalDiscoverySource();
    /// Stops watching and takes the URLs it added back out of the table. Idempotent.
    void stop();
    /// The nodes of the last scan.
    std::vector<local::LocalNodeInfo> nodes() const;
    /// Rescans now (asynchronously).
    void rescan();

private:
    LocalDiscoverySource() = default;
    void on_scan(const std::vector<local::LocalNodeInfo>& found, const std::vector<local::LocalNodeInfo>& lost);

    std::weak_ptr<NodeDiscovery> discovery_;
    NodeID own_id_;
    std::shared_ptr<local::LocalNodeWatcher> watcher_;
    mutable std::mutex mutex_;
    std::map<NodeID, std::vector<std::string>> added_;  ///< URLs this source put in the table, per node
    bool stopped_ = false;
};

}  // namespace rr::server::discovery
