// The rr+usb host transport (wire.md §10, docs/usb.md): finds RR USB devices with libusb, reads
// their NodeID and NodeName, and opens RR streams on them for the transport registry (URL
// `rr+usb:///?nodename=NAME&service=S` or `?nodeid=ID…`).
//
// Detection (as CORE HardwareTransport_libusb.cpp): a device is an RR device when its BOS holds the
// RR platform capability (read from sysfs `bos_descriptors` when the kernel has it, else with a
// GET_DESCRIPTOR(BOS) control request), or when its (VID, PID, interface) is on the allow-list. Either
// way the device class must be 0x00 or 0xFF and the interface's class 0xFF with a bulk IN and a bulk OUT
// endpoint. Then the RR descriptor set (vendor request 0xBA) names the NodeID and NodeName string
// descriptors, and must list protocol 0x0101.
//
// The device table follows the bus: libusb hotplug events where libusb has them (Linux), otherwise a
// rescan every `poll_interval`; connect also rescans when no device matches. Unplugging fails the
// device's streams (usb_errc::device_unplugged); a re-plugged device is found again and connects anew.
// A device the process may not open is listed with a permission error naming the udev rule
// (gateway-config/70-robotraconteur-usb.rules), not left out.
//
// Threading: the table runs on the host's strand; libusb's events on its own thread (usb_libusb.hpp).
// Public functions are thread-safe; `done` callbacks run on the host's strand (or the link's).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>

#include "base/names/connection_url.hpp"
#include "base/names/node_id.hpp"
#include "server/transport/transport.hpp"
#include "server/transport/transport_registry.hpp"
#include "server/transport/usb/usb_host_link.hpp"

namespace rr::server::usb {

/// A device admitted without the BOS capability (CORE HardwareTransport::AddUsbDevice).
struct UsbDeviceId {
    std::uint16_t vendor_id = 0;
    std::uint16_t product_id = 0;
    std::uint8_t interface_number = 0;
    friend bool operator==(const UsbDeviceId&, const UsbDeviceId&) = default;
};

struct UsbHostOptions {
    std::vector<UsbDeviceId> allowed;  ///< (VID, PID, interface) allow-list
    bool hotplug = true;               ///< use libusb hotplug when available (else poll)
    std::chrono::milliseconds poll_interval{2000};  ///< rescan period without hotplug; 0 = never
    std::string sysfs_root = "/sys";   ///< where `bus/usb/devices/*/bos_descriptors` are read
    unsigned probe_timeout_ms = 1000;  ///< per control request while reading a device's identity
    LinkOptions link;
    /// Diagnostics (why a device was skipped or failed), one line each; called on the host's strand.
    std::function<void(std::string_view)> log;
};

/// What the host knows about one RR USB device (enumerate / devices).
struct UsbDeviceInfo {
    NodeID node_id;             ///< all-zero when `error` is set
    std::string node_name;
    std::string url;            ///< rr+usb:///?nodeid=<id>&service=RobotRaconteurServiceIndex (as CORE's discovery)
    std::uint16_t vendor_id = 0, product_id = 0;
    std::uint8_t bus = 0, address = 0, interface_number = 0;
    std::string device_path;    ///< /dev/bus/usb/BBB/DDD
    bool bos_capability = false;  ///< found by its BOS capability (false: by the allow-list)
    std::optional<RRError> error; ///< why it cannot be used (permission, malformed descriptors, …)
    std::string describe() const;  ///< "USB device 1209:0001 at bus 1 address 2"
};

/// `rr+usb:///?nodeid=<id>&service=<service>` (nodeid without braces).
std::string usb_url(const NodeID& node_id, std::string_view service);
/// Checks an rr+usb URL as CORE does: NodeID and/or NodeName given, host empty or "localhost", no
/// port, path "/". Errors: InvalidArgument naming the fault.
Result<void> check_usb_url(const ConnectionUrl& url);
/// True when `info` is what `url` names (both NodeID and NodeName must match when both are given).
bool usb_url_matches(const ConnectionUrl& url, const UsbDeviceInfo& info);

struct UsbHostStats {
    std::atomic<std::uint64_t> scans{0}, probes{0}, hotplug_events{0};
};

class UsbHost : public std::enable_shared_from_this<UsbHost> {
public:
    /// Starts libusb (its event thread) and, with hotplug, the watch; the first scan runs at once.
    /// Errors: IOError when libusb cannot start.
    static Result<std::shared_ptr<UsbHost>> create(boost::asio::any_io_executor executor, UsbHostOptions options = {});
    ~UsbHost();
    UsbHost(const UsbHost&) = delete;
    UsbHost& operator=(const UsbHost&) = delete;

    /// Rescans the bus, probes new devices, and reports every RR USB device (with errors) – the
    /// function behind `rr discover` and the gateway's discovery table.
    void enumerate(std::function<void(std::vector<UsbDeviceInfo>)> done);
    /// Blocking enumerate (not from the host's strand). Errors: OperationTimeout.
    Result<std::vector<UsbDeviceInfo>> enumerate_wait(std::chrono::milliseconds timeout = std::chrono::seconds(10));
    /// The table as last scanned (no bus access).
    std::vector<UsbDeviceInfo> devices() const;
    /// Called with the new table (as devices() returns it) after a scan that changed it: a device
    /// plugged, unplugged, identified or failing (hotplug or polling). Runs on the host's strand; must
    /// not block. One listener; set it before the devices matter (the first scan starts at create()).
    void set_devices_listener(std::function<void(const std::vector<UsbDeviceInfo>&)> listener);

    /// Adds a (VID, PID, interface) to the allow-list; takes effect at the next scan.
    void allow_device(UsbDeviceId id);

    /// Opens an RR stream to the device `url` names (the rr+usb client transport's body); `done` gets
    /// the stream (executor `stream_executor`) or: InvalidArgument (bad URL), ConnectionError (no
    /// such device attached, device busy or failing), SystemResourcePermissionDenied (cannot open it).
    void open_stream(const ConnectionUrl& url, boost::asio::any_io_executor stream_executor,
                     std::function<void(Result<UsbByteStream>)> done);

    /// Fails every link (usb_errc::link_closed), stops hotplug and polling. Idempotent.
    void shutdown();

    bool uses_hotplug() const noexcept { return hotplug_active_; }
    /// True when no link is open (after shutdown(): every device handle is closed).
    bool idle() const;
    const UsbHostStats& stats() const noexcept { return stats_; }
    /// The link currently open to the device with `node_id` (tests, benchmarks), else null.
    std::shared_ptr<UsbHostLink> link_for(const NodeID& node_id) const;

private:
    struct Entry;
    struct Probe;
    explicit UsbHost(boost::asio::any_io_executor executor, UsbHostOptions options);

    // strand only
    void scan(std::function<void()> done);
    void scan_finished();
    void start_probe(const std::string& key);
    void probe_done(const std::string& key, std::uint64_t generation, std::optional<RRError> error);
    void remove_entry(std::map<std::string, Entry>::iterator it);
    void connect_to(Entry& e, boost::asio::any_io_executor stream_executor, std::function<void(Result<UsbByteStream>)> done);
    void open_matched(const ConnectionUrl& url, boost::asio::any_io_executor stream_executor,
                      std::function<void(Result<UsbByteStream>)> done, bool rescanned);
    void publish();
    void arm_poll();
    std::optional<std::vector<std::byte>> read_sysfs_bos(std::uint8_t bus, std::uint8_t address) const;

    boost::asio::strand<boost::asio::any_io_executor> strand_;
    UsbHostOptions options_;
    std::shared_ptr<LibusbContext> usb_;
    std::map<std::string, Entry> entries_;  // key "bus-address"
    std::uint64_t next_generation_ = 1;
    bool scanning_ = false;
    bool rescan_requested_ = false;
    std::size_t probes_running_ = 0;
    std::vector<std::function<void()>> scan_waiters_;
    boost::asio::steady_timer poll_timer_;
    bool hotplug_active_ = false;
    bool stopped_ = false;
    mutable std::mutex snapshot_mutex_;
    std::vector<UsbDeviceInfo> snapshot_;
    std::function<void(const std::vector<UsbDeviceInfo>&)> devices_listener_;  // guarded by snapshot_mutex_
    std::map<NodeID, std::weak_ptr<UsbHostLink>> links_by_node_;  // guarded by snapshot_mutex_
    UsbHostStats stats_;
};

/// The rr+usb Connector (server/transport/transport.hpp) over `host`. It keeps only a weak reference:
/// once `host` is gone, connects fail with ConnectionError.
std::shared_ptr<Connector> make_usb_connector(std::shared_ptr<UsbHost> host);
/// Adds that connector to `registry` as "rr+usb": a node's transports() (the gateway's devices), or
/// default_transports() for clients without a node (rr::client::Client, the rr CLI).
void register_usb_transport(TransportRegistry& registry, std::shared_ptr<UsbHost> host);

}  // namespace rr::server::usb
