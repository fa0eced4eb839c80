#include "server/discovery/discovery_sources.hpp"

#include <algorithm>

namespace rr::server::discovery {

std::shared_ptr<LocalDiscoverySource> LocalDiscoverySource::start(boost::asio::any_io_executor executor,
                                                                  std::shared_ptr<NodeDiscovery> discovery,
                                                                  LocalSourceOptions options) {
    std::shared_ptr<LocalDiscoverySource> s(new LocalDiscoverySource());
    s->discovery_ = discovery;
    s->own_id_ = discovery->options().node_id;
    const auto third = std::chrono::duration_cast<std::chrono::milliseconds>(discovery->options().limits.url_expiry / 3);
    if (third.count() > 0 && (options.watch.poll_interval.count() <= 0 || options.watch.poll_interval > third))
        options.watch.poll_interval = third;
    std::weak_ptr<LocalDiscoverySource> weak = s;
    s->watcher_ = local::LocalNodeWatcher::create(
        std::move(executor), std::move(options.dirs), options.watch,
        [weak](const std::vector<local::LocalNodeInfo>& found, const std::vector<local::LocalNodeInfo>& lost) {
            if (auto self = weak.lock()) self->on_scan(found, lost);
        });
    s->watcher_->start();
    return s;
}

LocalDiscoverySource::~LocalDiscoverySource() { stop(); }

void LocalDiscoverySource::on_scan(const std::vector<local::LocalNodeInfo>& found, const std::vector<local::LocalNodeInfo>& lost) {
    auto d = discovery_.lock();
    if (!d) return;
    std::vector<std::pair<NodeID, std::vector<std::string>>> remove;
    std::vector<NodeAnnouncement> add;
    {
        std::lock_guard lock(mutex_);
        if (stopped_) return;
        for (const auto& n : lost) {
            auto it = added_.find(n.node_id);
            if (it == added_.end()) continue;
            remove.emplace_back(n.node_id, std::move(it->second));
            added_.erase(it);
        }
        for (const auto& n : found) {
            if (n.node_id == own_id_) continue;
            auto& known = added_[n.node_id];
            std::vector<std::string> gone;
            for (const auto& u : known)
                if (std::find(n.urls.begin(), n.urls.end(), u) == n.urls.end()) gone.push_back(u);
            if (!gone.empty()) remove.emplace_back(n.node_id, std::move(gone));
            known = n.urls;
            add.push_back(NodeAnnouncement{n.node_id, n.node_name, n.urls, n.service_state_nonce, rr::discovery::NodeSource::local});
        }
    }
    for (const auto& [id, urls] : remove) d->remove_urls(id, urls);
    for (const auto& a : add) d->add_node(a);
}

void LocalDiscoverySource::stop() {
    std::map<NodeID, std::vector<std::string>> added;
    {
        std::lock_guard lock(mutex_);
        if (stopped_) return;
        stopped_ = true;
        added.swap(added_);
    }
    if (watcher_) watcher_->stop();
    if (auto d = discovery_.lock())
        for (const auto& [id, urls] : added) d->remove_urls(id, urls);
}

std::vector<local::LocalNodeInfo> LocalDiscoverySource::nodes() const { return watcher_->nodes(); }

void LocalDiscoverySource::rescan() { watcher_->rescan(); }

}  // namespace rr::server::discovery
