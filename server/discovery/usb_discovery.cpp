#include "server/discovery/usb_discovery.hpp"

#include <boost/asio/post.hpp>

namespace rr::server::usb {

UsbDiscoverySource::UsbDiscoverySource(boost::asio::any_io_executor executor)
    : strand_(boost::asio::make_strand(std::move(executor))), timer_(strand_) {}

std::shared_ptr<UsbDiscoverySource> UsbDiscoverySource::start(boost::asio::any_io_executor executor, std::shared_ptr<UsbHost> host,
                                                              std::shared_ptr<discovery::NodeDiscovery> discovery) {
    std::shared_ptr<UsbDiscoverySource> s(new UsbDiscoverySource(std::move(executor)));
    s->host_ = host;
    s->discovery_ = discovery;
    const auto third = std::chrono::duration_cast<std::chrono::milliseconds>(discovery->options().limits.url_expiry / 3);
    if (third.count() > 0) s->refresh_ = third;
    std::weak_ptr<UsbDiscoverySource> weak = s;
    host->set_devices_listener([weak](const std::vector<UsbDeviceInfo>& devices) {
        if (auto self = weak.lock()) self->update(devices);
    });
    s->update(host->devices());
    boost::asio::post(s->strand_, [s] { s->arm_refresh(); });
    return s;
}

UsbDiscoverySource::~UsbDiscoverySource() { stop(); }

void UsbDiscoverySource::update(const std::vector<UsbDeviceInfo>& devices) {
    auto d = discovery_.lock();
    if (!d) return;
    std::vector<std::pair<NodeID, std::string>> gone;
    std::vector<discovery::NodeAnnouncement> add;
    {
        std::lock_guard lock(mutex_);
        if (stopped_) return;
        problems_.clear();
        std::map<NodeID, std::string> now;
        for (const auto& dev : devices) {
            if (dev.error || dev.node_id.is_any() || dev.url.empty()) {
                if (dev.error) problems_.push_back(dev);
                continue;
            }
            now[dev.node_id] = dev.url;
            add.push_back(discovery::NodeAnnouncement{dev.node_id, dev.node_name, {dev.url}, {}, rr::discovery::NodeSource::usb});
        }
        for (const auto& [id, url] : added_) {
            auto it = now.find(id);
            if (it == now.end() || it->second != url) gone.emplace_back(id, url);
        }
        added_ = std::move(now);
    }
    for (const auto& [id, url] : gone) d->remove_urls(id, {url});
    for (const auto& a : add) d->add_node(a);
}

void UsbDiscoverySource::arm_refresh() {
    timer_.expires_after(refresh_);
    timer_.async_wait([weak = weak_from_this()](boost::system::error_code ec) {
        if (ec) return;
        auto self = weak.lock();
        if (!self) return;
        {
            std::lock_guard lock(self->mutex_);
            if (self->stopped_) return;
        }
        if (auto h = self->host_.lock()) self->update(h->devices());
        self->arm_refresh();
    });
}

void UsbDiscoverySource::stop() {
    std::map<NodeID, std::string> added;
    {
        std::lock_guard lock(mutex_);
        if (stopped_) return;
        stopped_ = true;
        added.swap(added_);
    }
    if (auto self = weak_from_this().lock()) boost::asio::post(strand_, [self] { self->timer_.cancel(); });
    if (auto h = host_.lock()) h->set_devices_listener({});
    if (auto d = discovery_.lock())
        for (const auto& [id, url] : added) d->remove_urls(id, {url});
}

std::vector<UsbDeviceInfo> UsbDiscoverySource::problems() const {
    std::lock_guard lock(mutex_);
    return problems_;
}

}  // namespace rr::server::usb
