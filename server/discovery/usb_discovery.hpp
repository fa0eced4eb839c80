// USB devices as a source of the discovery table (docs/discovery.md "Other sources", docs/usb.md): every
// RR USB device the UsbHost sees is added to a NodeDiscovery (NodeSource::usb, URL
// `rr+usb:///?nodeid=<id>&service=RobotRaconteurServiceIndex`, CORE's USB discovery form) when it is
// plugged in and identified, and its URL is taken back when it is unplugged (hotplug or polling, as
// the host follows the bus). Its services are then read over rr+usb like any node's (the discovery's
// transports must hold rr+usb: register_usb_transport). Devices the host cannot use (no permission,
// malformed descriptors) carry no identity and are not nodes; problems() lists them with the error.
#pragma once

#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>

#include "server/discovery/node_discovery.hpp"
#include "server/transport/usb/usb_host.hpp"

namespace rr::server::usb {

class UsbDiscoverySource : public std::enable_shared_from_this<UsbDiscoverySource> {
public:
    /// Takes the host's device listener (UsbHost::set_devices_listener) and adds the devices it already
    /// knows. Every third of the table's URL expiry the present devices are announced again, so that
    /// they stay while plugged in.
    static std::shared_ptr<UsbDiscoverySource> start(boost::asio::any_io_executor executor, std::shared_ptr<UsbHost> host,
                                                     std::shared_ptr<discovery::NodeDiscovery> discovery);
    ~UsbDiscoverySource();
    /// Stops and takes the URLs it added back out of the table. Idempotent.
    void stop();
    /// Devices found but unusable (UsbDeviceInfo::error set), as of the last change.
    std::vector<UsbDeviceInfo> problems() const;

private:
    explicit UsbDiscoverySource(boost::asio::any_io_executor executor);
    void update(const std::vector<UsbDeviceInfo>& devices);
    void arm_refresh();

    std::weak_ptr<UsbHost> host_;
    std::weak_ptr<discovery::NodeDiscovery> discovery_;
    boost::asio::strand<boost::asio::any_io_executor> strand_;
    boost::asio::steady_timer timer_;  // on strand_
    std::chrono::milliseconds refresh_{20000};
    mutable std::mutex mutex_;
    std::map<NodeID, std::string> added_;  ///< NodeID -> the URL added for it
    std::vector<UsbDeviceInfo> problems_;
    bool stopped_ = false;
};

}  // namespace rr::server::usb
