#include "server/transport/usb/usb_host.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <iterator>
#include <set>

#include <boost/asio/dispatch.hpp>
#include <boost/asio/post.hpp>

#include "base/usb/usb_descriptors.hpp"
#include "server/transport/transport_registry.hpp"

namespace rr::server::usb {

namespace asio = boost::asio;
namespace core = rr::usb;

// --- URLs ----------------------------------------------------------------------------------------------------

std::string UsbDeviceInfo::describe() const {
    char b[80];
    std::snprintf(b, sizeof b, "USB device %04x:%04x at bus %u address %u", vendor_id, product_id, unsigned(bus), unsigned(address));
    return b;
}

std::string usb_url(const NodeID& node_id, std::string_view service) {
    return "rr+usb:///?nodeid=" + node_id.to_string() + "&service=" + std::string(service);
}

Result<void> check_usb_url(const ConnectionUrl& url) {
    if (url.scheme != "rr+usb") return fail(MessageErrorType::InvalidArgument, "not an rr+usb URL: " + url.scheme);
    if (url.node_id.is_any() && url.node_name.empty())
        return fail(MessageErrorType::InvalidArgument, "an rr+usb URL must give nodeid and/or nodename");
    if (!url.host.empty() && url.host != "localhost")
        return fail(MessageErrorType::InvalidArgument, "an rr+usb URL's host must be empty or localhost, not " + url.host);
    if (url.port != 0) return fail(MessageErrorType::InvalidArgument, "an rr+usb URL takes no port");
    if (!url.path.empty() && url.path != "/")
        return fail(MessageErrorType::InvalidArgument, "an rr+usb URL takes no path, not " + url.path);
    return {};
}

bool usb_url_matches(const ConnectionUrl& url, const UsbDeviceInfo& info) {
    if (info.error || (info.node_id.is_any() && info.node_name.empty())) return false;
    if (!url.node_id.is_any() && url.node_id != info.node_id) return false;
    if (!url.node_name.empty() && url.node_name != info.node_name) return false;
    return !(url.node_id.is_any() && url.node_name.empty());
}

// --- entries and probes ----------------------------------------------------------------------------------

struct UsbHost::Entry {
    enum class State { Probing, Ready, Failed, NotRR };
    DeviceRef device;
    std::uint64_t generation = 0;
    State state = State::NotRR;  // with generation 0: never probed yet
    UsbDeviceInfo info;
    LinkEndpoints ep;
    std::shared_ptr<UsbHostLink> link;
};

/// Reads one device's identity: an async chain of control requests on the host's strand.
struct UsbHost::Probe : std::enable_shared_from_this<UsbHost::Probe> {
    std::shared_ptr<UsbHost> host;
    std::string key;
    std::uint64_t generation = 0;
    libusb_device* device = nullptr;
    DeviceHandle handle;
    UsbDeviceInfo info;
    LinkEndpoints ep;
    bool candidate = false;       // known to be RR (BOS in sysfs or allow-list): errors are reported
    bool need_bos_read = false;   // no sysfs BOS: read it over the wire
    std::optional<std::uint8_t> allowed_interface;
    core::DescriptorSet set;
    std::uint16_t langid = core::kLangIdEnglishUs;

    void finish(std::optional<RRError> error, bool not_rr = false, std::string_view why = {}) {
        handle.reset();
        if (host->options_.log) {
            if (error) host->options_.log(error->message);
            else if (not_rr) host->options_.log(info.describe() + ": not an RR device (" + std::string(why) + ")");
            else host->options_.log(info.describe() + ": RR device " + info.node_name + " " + info.node_id.to_string());
        }
        auto h = host;
        asio::dispatch(h->strand_, [h, key = key, gen = generation, info = std::move(info), ep = ep, error = std::move(error),
                                    not_rr, candidate = candidate]() mutable {
            auto it = h->entries_.find(key);
            if (it != h->entries_.end() && it->second.generation == gen) {
                if (not_rr || (!candidate && error)) {
                    it->second.state = Entry::State::NotRR;
                } else {
                    it->second.info = std::move(info);
                    it->second.ep = ep;
                    it->second.info.error = std::move(error);
                    it->second.state = it->second.info.error ? Entry::State::Failed : Entry::State::Ready;
                }
            }
            h->probe_done(key, gen, std::nullopt);
        });
    }
    RRError error(std::string what) const {
        return make_error(MessageErrorType::ConnectionError, info.describe() + ": " + std::move(what));
    }

    // Control request; `next` runs on the host's strand.
    void request(const core::SetupPacket& setup, std::function<void(TransferResult, std::vector<std::byte>)> next) {
        auto self = shared_from_this();
        submit_control(handle.get(), setup, {}, host->options_.probe_timeout_ms,
                       [self, next = std::move(next)](TransferResult r, std::vector<std::byte> data) mutable {
                           asio::post(self->host->strand_, [next = std::move(next), r, data = std::move(data)]() mutable {
                               next(r, std::move(data));
                           });
                       });
    }

    void start(std::optional<std::vector<std::byte>> sysfs_bos) {
        libusb_device_descriptor dd{};
        if (libusb_get_device_descriptor(device, &dd) != 0) return finish(std::nullopt, true, "no device descriptor");
        info.vendor_id = dd.idVendor;
        info.product_id = dd.idProduct;
        info.bus = libusb_get_bus_number(device);
        info.address = libusb_get_device_address(device);
        char path[64];
        std::snprintf(path, sizeof path, "/dev/bus/usb/%03u/%03u", unsigned(info.bus), unsigned(info.address));
        info.device_path = path;
        if (dd.bDeviceClass != 0x00 && dd.bDeviceClass != 0xFF) return finish(std::nullopt, true, "device class");

        libusb_config_descriptor* cfg = nullptr;
        if (libusb_get_active_config_descriptor(device, &cfg) != 0 && libusb_get_config_descriptor(device, 0, &cfg) != 0)
            return finish(std::nullopt, true, "no configuration descriptor");
        std::vector<std::uint8_t> vendor_interfaces;
        for (int i = 0; i < cfg->bNumInterfaces; ++i) {
            if (cfg->interface[i].num_altsetting < 1) continue;
            const auto& alt = cfg->interface[i].altsetting[0];
            if (alt.bInterfaceClass == 0xFF) vendor_interfaces.push_back(alt.bInterfaceNumber);
            for (const auto& a : host->options_.allowed)
                if (a.vendor_id == dd.idVendor && a.product_id == dd.idProduct && a.interface_number == alt.bInterfaceNumber &&
                    !allowed_interface)
                    allowed_interface = alt.bInterfaceNumber;
        }
        const int configuration = cfg->bConfigurationValue;
        libusb_free_config_descriptor(cfg);

        if (sysfs_bos) {
            auto caps = core::find_platform_capabilities(*sysfs_bos);
            if (caps && !caps->empty()) {
                info.bos_capability = true;
                info.interface_number = (*caps)[0].interface_number;
                candidate = true;
            }
        }
        if (!candidate && allowed_interface) {
            info.interface_number = *allowed_interface;
            candidate = true;
        }
        if (!candidate) {
            // Without sysfs `bos_descriptors` (kernels before 6.3) the BOS must be read from the device:
            // only where one may exist (USB ≥ 2.01) with a vendor interface.
            if (sysfs_bos || dd.bcdUSB < 0x0201 || vendor_interfaces.empty())
                return finish(std::nullopt, true, sysfs_bos ? "no RR capability in its BOS" : "no BOS or no vendor interface");
            need_bos_read = true;
        }
        ep.configuration = configuration;

        libusb_device_handle* h = nullptr;
        const int r = libusb_open(device, &h);
        if (r == LIBUSB_ERROR_ACCESS)
            return finish(candidate ? std::optional<RRError>(permission_error(info.vendor_id, info.product_id, info.device_path))
                                    : std::nullopt,
                          !candidate);
        if (r != 0) return finish(error("cannot open: " + libusb_error_text(r)), !candidate);
        handle.reset(h);
        if (need_bos_read) return read_bos();
        endpoints();
    }

    void read_bos() {
        auto self = shared_from_this();
        request(core::SetupPacket{0x80, 0x06, 0x0F00, 0, static_cast<std::uint16_t>(core::kBosHeaderSize)},
                [self](TransferResult r, std::vector<std::byte> head) {
                    if (!r.ok() || head.size() < core::kBosHeaderSize) return self->finish(std::nullopt, true, "no BOS descriptor");
                    const auto total = static_cast<std::uint16_t>(std::to_integer<unsigned>(head[2]) |
                                                                  (std::to_integer<unsigned>(head[3]) << 8));
                    self->request(core::SetupPacket{0x80, 0x06, 0x0F00, 0, total}, [self](TransferResult r2, std::vector<std::byte> bos) {
                        if (!r2.ok()) return self->finish(std::nullopt, true, "no BOS descriptor");
                        auto caps = core::find_platform_capabilities(bos);
                        if (!caps || caps->empty()) return self->finish(std::nullopt, true, "no RR capability in its BOS");
                        self->info.bos_capability = true;
                        self->info.interface_number = (*caps)[0].interface_number;
                        self->candidate = true;
                        self->endpoints();
                    });
                });
    }

    void endpoints() {
        libusb_config_descriptor* cfg = nullptr;
        if (libusb_get_active_config_descriptor(device, &cfg) != 0 && libusb_get_config_descriptor(device, 0, &cfg) != 0)
            return finish(error("no configuration descriptor"));
        bool found = false, in = false, out = false;
        for (int i = 0; i < cfg->bNumInterfaces && !found; ++i) {
            if (cfg->interface[i].num_altsetting < 1) continue;
            const auto& alt = cfg->interface[i].altsetting[0];
            if (alt.bInterfaceNumber != info.interface_number) continue;
            found = true;
            if (alt.bInterfaceClass != 0xFF) break;
            for (int k = 0; k < alt.bNumEndpoints; ++k) {
                const auto& e = alt.endpoint[k];
                if ((e.bmAttributes & 0x03) != LIBUSB_TRANSFER_TYPE_BULK) continue;
                if ((e.bEndpointAddress & 0x80) && !in) {
                    in = true;
                    ep.in_endpoint = e.bEndpointAddress;
                    ep.in_packet_size = static_cast<std::uint16_t>(std::min<std::size_t>(e.wMaxPacketSize, core::kMaxPacketSize));
                } else if (!(e.bEndpointAddress & 0x80) && !out) {
                    out = true;
                    ep.out_endpoint = e.bEndpointAddress;
                    ep.out_packet_size = static_cast<std::uint16_t>(std::min<std::size_t>(e.wMaxPacketSize, core::kMaxPacketSize));
                }
            }
        }
        libusb_free_config_descriptor(cfg);
        if (!found) return finish(error("interface " + std::to_string(info.interface_number) + " does not exist"));
        if (!in || !out)
            return finish(error("interface " + std::to_string(info.interface_number) +
                                " is not a vendor interface with a bulk IN and a bulk OUT endpoint"));
        if (ep.in_packet_size < core::kNotificationSize || ep.out_packet_size < core::kNotificationSize)
            return finish(error("bulk endpoints of " + std::to_string(ep.in_packet_size) + "/" + std::to_string(ep.out_packet_size) +
                                " bytes are too small for sub-packets"));
        ep.interface_number = info.interface_number;
        descriptor_set();
    }

    void descriptor_set() {
        auto self = shared_from_this();
        request(core::descriptor_set_request(info.interface_number, core::kDescriptorSetHeaderSize),
                [self](TransferResult r, std::vector<std::byte> head) {
                    if (!r.ok()) return self->finish(self->error("RR descriptor set request failed: " + r.text()));
                    auto total = core::parse_descriptor_set_length(head);
                    if (!total) return self->finish(self->error(total.error().message));
                    self->request(core::descriptor_set_request(self->info.interface_number, *total),
                                  [self, total = *total](TransferResult r2, std::vector<std::byte> bytes) {
                                      if (!r2.ok()) return self->finish(self->error("RR descriptor set request failed: " + r2.text()));
                                      if (bytes.size() < total)
                                          return self->finish(self->error("RR descriptor set: " + std::to_string(bytes.size()) +
                                                                          " of " + std::to_string(total) + " bytes answered"));
                                      auto set = core::parse_descriptor_set(bytes);
                                      if (!set) return self->finish(self->error(set.error().message));
                                      if (!set->supports_stream_protocol())
                                          return self->finish(self->error("the device does not offer stream protocol 0x0101"));
                                      self->set = std::move(*set);
                                      self->strings();
                                  });
                });
    }

    void strings() {
        auto self = shared_from_this();
        request(core::SetupPacket{0x80, 0x06, 0x0300, 0, 255}, [self](TransferResult r, std::vector<std::byte> d) {
            if (!r.ok()) return self->finish(self->error("string descriptor 0: " + r.text()));
            auto lang = core::parse_language_ids(d);
            if (!lang) return self->finish(self->error(lang.error().message));
            self->langid = *lang;
            self->read_string(self->set.node_id_string, [self](Result<std::string> id) {
                if (!id) return self->finish(self->error("NodeID string: " + id.error().message));
                auto nid = NodeID::parse(*id);
                if (!nid || nid->is_any()) return self->finish(self->error("NodeID string \"" + *id + "\" is not a NodeID"));
                self->info.node_id = *nid;
                self->read_string(self->set.node_name_string, [self](Result<std::string> name) {
                    if (!name) return self->finish(self->error("NodeName string: " + name.error().message));
                    self->info.node_name = std::move(*name);
                    self->info.url = usb_url(self->info.node_id, "RobotRaconteurServiceIndex");
                    self->finish(std::nullopt);
                });
            });
        });
    }

    void read_string(std::uint8_t index, std::function<void(Result<std::string>)> next) {
        if (index == 0) return next(std::string());
        request(core::SetupPacket{0x80, 0x06, static_cast<std::uint16_t>(0x0300 | index), langid, 255},
                [next = std::move(next)](TransferResult r, std::vector<std::byte> d) {
                    if (!r.ok()) return next(fail(MessageErrorType::ConnectionError, r.text()));
                    next(core::parse_string_descriptor(d));
                });
    }
};

// --- UsbHost -----------------------------------------------------------------------------------------------

Result<std::shared_ptr<UsbHost>> UsbHost::create(asio::any_io_executor executor, UsbHostOptions options) {
    auto usb = LibusbContext::create();
    if (!usb) return usb.take_error();
    std::shared_ptr<UsbHost> host(new UsbHost(std::move(executor), std::move(options)));
    host->usb_ = *usb;
    if (host->options_.hotplug && host->usb_->has_hotplug()) {
        std::weak_ptr<UsbHost> weak = host;
        auto r = host->usb_->watch_hotplug([weak](bool, libusb_device*) {
            if (auto h = weak.lock()) {
                h->stats_.hotplug_events.fetch_add(1);
                asio::post(h->strand_, [h] { h->scan({}); });
            }
        });
        host->hotplug_active_ = r.ok();
    }
    asio::post(host->strand_, [host] {
        host->scan({});
        host->arm_poll();
    });
    return host;
}

UsbHost::UsbHost(asio::any_io_executor executor, UsbHostOptions options)
    : strand_(asio::make_strand(executor)), options_(std::move(options)), poll_timer_(strand_) {}

UsbHost::~UsbHost() {
    stopped_ = true;
    for (auto& [key, e] : entries_)
        if (e.link) e.link->fail(make_error_code(usb_errc::link_closed), "the USB host transport shut down");
    if (usb_) usb_->stop_hotplug();
}

void UsbHost::shutdown() {
    asio::dispatch(strand_, [self = shared_from_this()] {
        if (self->stopped_) return;
        self->stopped_ = true;
        self->poll_timer_.cancel();
        if (self->usb_) self->usb_->stop_hotplug();
        for (auto& [key, e] : self->entries_)
            if (e.link) e.link->fail(make_error_code(usb_errc::link_closed), "the USB host transport shut down");
        auto waiters = std::move(self->scan_waiters_);
        self->scan_waiters_.clear();
        for (auto& w : waiters) w();
    });
}

void UsbHost::arm_poll() {
    if (stopped_ || hotplug_active_ || options_.poll_interval.count() <= 0) return;
    poll_timer_.expires_after(options_.poll_interval);
    poll_timer_.async_wait([weak = weak_from_this()](boost::system::error_code ec) {
        if (ec) return;
        if (auto h = weak.lock()) {
            h->scan({});
            h->arm_poll();
        }
    });
}

void UsbHost::allow_device(UsbDeviceId id) {
    asio::dispatch(strand_, [self = shared_from_this(), id] {
        if (std::find(self->options_.allowed.begin(), self->options_.allowed.end(), id) == self->options_.allowed.end())
            self->options_.allowed.push_back(id);
        // Devices already judged not RR get another look.
        for (auto& [key, e] : self->entries_)
            if (e.state == Entry::State::NotRR) e.generation = 0;
    });
}

std::optional<std::vector<std::byte>> UsbHost::read_sysfs_bos(std::uint8_t bus, std::uint8_t address) const {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path dir = fs::path(options_.sysfs_root) / "bus/usb/devices";
    auto read_number = [](const fs::path& p) -> int {
        std::ifstream f(p);
        int v = -1;
        if (!(f >> v)) return -1;
        return v;
    };
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const auto& p = it->path();
        if (read_number(p / "busnum") != bus || read_number(p / "devnum") != address) continue;
        std::ifstream f(p / "bos_descriptors", std::ios::binary);
        if (!f) return std::nullopt;
        std::vector<char> raw{std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
        if (raw.empty()) return std::nullopt;
        std::vector<std::byte> out(raw.size());
        std::transform(raw.begin(), raw.end(), out.begin(), [](char c) { return static_cast<std::byte>(c); });
        return out;
    }
    return std::nullopt;
}

void UsbHost::scan(std::function<void()> done) {
    if (done) scan_waiters_.push_back(std::move(done));
    if (stopped_) {
        auto waiters = std::move(scan_waiters_);
        scan_waiters_.clear();
        for (auto& w : waiters) w();
        return;
    }
    if (scanning_) {
        rescan_requested_ = true;
        return;
    }
    scanning_ = true;
    stats_.scans.fetch_add(1);
    libusb_device** list = nullptr;
    const ssize_t n = libusb_get_device_list(usb_->get(), &list);
    if (options_.log) options_.log("scan: " + std::to_string(n) + " USB devices");
    std::set<std::string> present;
    std::vector<std::string> to_probe;
    for (ssize_t i = 0; i < n; ++i) {
        libusb_device* d = list[i];
        const auto key = std::to_string(libusb_get_bus_number(d)) + "-" + std::to_string(libusb_get_device_address(d));
        present.insert(key);
        auto it = entries_.find(key);
        if (it != entries_.end() && it->second.device.get() != d) {  // another device at this address
            remove_entry(it);
            it = entries_.end();
        }
        if (it == entries_.end()) {
            Entry e;
            e.device = ref_device(d);
            it = entries_.emplace(key, std::move(e)).first;
        }
        Entry& e = it->second;
        const bool reprobe = e.generation == 0 || e.state == Entry::State::Failed;
        if (reprobe && e.state != Entry::State::Probing && !(e.link && !e.link->closed())) {
            e.generation = next_generation_++;
            e.state = Entry::State::Probing;
            to_probe.push_back(key);
        }
    }
    if (list) libusb_free_device_list(list, 1);
    for (auto it = entries_.begin(); it != entries_.end();) {
        if (present.count(it->first) == 0) {
            auto next = std::next(it);
            remove_entry(it);
            it = next;
        } else {
            ++it;
        }
    }
    for (const auto& key : to_probe) start_probe(key);
    if (probes_running_ == 0) scan_finished();
}

void UsbHost::remove_entry(std::map<std::string, Entry>::iterator it) {
    if (it->second.link) it->second.link->fail(make_error_code(usb_errc::device_unplugged), "the device was unplugged");
    entries_.erase(it);
}

void UsbHost::start_probe(const std::string& key) {
    auto& e = entries_.at(key);
    ++probes_running_;
    stats_.probes.fetch_add(1);
    auto p = std::make_shared<Probe>();
    p->host = shared_from_this();
    p->key = key;
    p->generation = e.generation;
    p->device = e.device.get();
    p->start(read_sysfs_bos(libusb_get_bus_number(p->device), libusb_get_device_address(p->device)));
}

void UsbHost::probe_done(const std::string&, std::uint64_t, std::optional<RRError>) {
    --probes_running_;
    if (probes_running_ == 0 && scanning_) scan_finished();
}

void UsbHost::scan_finished() {
    scanning_ = false;
    publish();
    auto waiters = std::move(scan_waiters_);
    scan_waiters_.clear();
    for (auto& w : waiters) w();
    if (rescan_requested_) {
        rescan_requested_ = false;
        scan({});
    }
}

namespace {

bool same_device(const UsbDeviceInfo& a, const UsbDeviceInfo& b) {
    return a.node_id == b.node_id && a.node_name == b.node_name && a.url == b.url && a.bus == b.bus && a.address == b.address &&
           a.interface_number == b.interface_number && a.error.has_value() == b.error.has_value() &&
           (!a.error || a.error->message == b.error->message);
}

}  // namespace

void UsbHost::publish() {
    std::vector<UsbDeviceInfo> out;
    for (const auto& [key, e] : entries_)
        if (e.state == Entry::State::Ready || e.state == Entry::State::Failed) out.push_back(e.info);
    std::function<void(const std::vector<UsbDeviceInfo>&)> listener;
    {
        std::lock_guard lock(snapshot_mutex_);
        const bool changed = out.size() != snapshot_.size() ||
                             !std::equal(out.begin(), out.end(), snapshot_.begin(), same_device);
        snapshot_ = out;
        if (changed) listener = devices_listener_;
    }
    if (listener && !stopped_) listener(out);
}

void UsbHost::set_devices_listener(std::function<void(const std::vector<UsbDeviceInfo>&)> listener) {
    std::lock_guard lock(snapshot_mutex_);
    devices_listener_ = std::move(listener);
}

std::vector<UsbDeviceInfo> UsbHost::devices() const {
    std::lock_guard lock(snapshot_mutex_);
    return snapshot_;
}

std::shared_ptr<UsbHostLink> UsbHost::link_for(const NodeID& node_id) const {
    std::lock_guard lock(snapshot_mutex_);
    auto it = links_by_node_.find(node_id);
    if (it == links_by_node_.end()) return nullptr;
    auto l = it->second.lock();
    return l && !l->closed() ? l : nullptr;
}

bool UsbHost::idle() const {
    std::lock_guard lock(snapshot_mutex_);
    for (const auto& [id, weak] : links_by_node_)
        if (auto l = weak.lock(); l && !l->closed()) return false;
    return true;
}

void UsbHost::enumerate(std::function<void(std::vector<UsbDeviceInfo>)> done) {
    asio::post(strand_, [self = shared_from_this(), done = std::move(done)]() mutable {
        self->scan([self, done = std::move(done)] { done(self->devices()); });
    });
}

Result<std::vector<UsbDeviceInfo>> UsbHost::enumerate_wait(std::chrono::milliseconds timeout) {
    auto p = std::make_shared<std::promise<std::vector<UsbDeviceInfo>>>();
    auto f = p->get_future();
    enumerate([p](std::vector<UsbDeviceInfo> v) { p->set_value(std::move(v)); });
    if (f.wait_for(timeout) != std::future_status::ready)
        return fail(MessageErrorType::OperationTimeout, "USB enumeration did not finish in time");
    return f.get();
}

void UsbHost::open_stream(const ConnectionUrl& url, asio::any_io_executor stream_executor,
                          std::function<void(Result<UsbByteStream>)> done) {
    if (auto ok = check_usb_url(url); !ok) return done(ok.take_error());
    asio::post(strand_, [self = shared_from_this(), url, ex = std::move(stream_executor), done = std::move(done)]() mutable {
        if (self->stopped_) return done(fail(MessageErrorType::ConnectionError, "the USB host transport is shut down"));
        if (self->scanning_) {  // the first scan (or a hotplug one) is running: match against its result
            return self->scan([self, url, ex, done = std::move(done)]() mutable {
                self->open_matched(url, std::move(ex), std::move(done), true);
            });
        }
        self->open_matched(url, std::move(ex), std::move(done), false);
    });
}

void UsbHost::open_matched(const ConnectionUrl& url, asio::any_io_executor stream_executor,
                           std::function<void(Result<UsbByteStream>)> done, bool rescanned) {
    for (auto& [key, e] : entries_)
        if (e.state == Entry::State::Ready && usb_url_matches(url, e.info)) return connect_to(e, std::move(stream_executor), std::move(done));
    if (!rescanned) {
        return scan([self = shared_from_this(), url, ex = std::move(stream_executor), done = std::move(done)]() mutable {
            self->open_matched(url, std::move(ex), std::move(done), true);
        });
    }
    std::string what = "no rr+usb device with";
    if (!url.node_id.is_any()) what += " NodeID " + url.node_id.to_string();
    if (!url.node_id.is_any() && !url.node_name.empty()) what += " and";
    if (!url.node_name.empty()) what += " NodeName \"" + url.node_name + "\"";
    what += " is attached";
    auto type = MessageErrorType::ConnectionError;
    for (const auto& [key, e] : entries_) {
        if (e.state != Entry::State::Failed || !e.info.error) continue;
        what += "; " + e.info.error->message;
        if (e.info.error->type == MessageErrorType::SystemResourcePermissionDenied) type = e.info.error->type;
    }
    done(fail(type, what));
}

void UsbHost::connect_to(Entry& e, asio::any_io_executor stream_executor, std::function<void(Result<UsbByteStream>)> done) {
    if (!e.link || e.link->closed()) {
        e.link = UsbHostLink::create(strand_.get_inner_executor(), usb_, ref_device(e.device.get()), e.ep, options_.link,
                                     e.info.describe());
        std::weak_ptr<UsbHost> weak = shared_from_this();
        e.link->set_closed_handler([weak, node = e.info.node_id](auto retry) {
            auto h = weak.lock();
            if (!h) {
                for (auto& [ex, d] : retry) d(fail(MessageErrorType::ConnectionError, "the USB host transport is gone"));
                return;
            }
            if (retry.empty()) return;
            asio::post(h->strand_, [h, node, retry = std::move(retry)]() mutable {
                for (auto& [ex, d] : retry) {
                    ConnectionUrl url;
                    url.scheme = "rr+usb";
                    url.node_id = node;
                    h->open_matched(url, std::move(ex), [d = std::move(d)](Result<UsbByteStream> r) { d(std::move(r)); }, false);
                }
            });
        });
        std::lock_guard lock(snapshot_mutex_);
        links_by_node_[e.info.node_id] = e.link;
    }
    e.link->connect_stream(std::move(stream_executor), std::move(done));
}

// --- client transport --------------------------------------------------------------------------------------------

namespace {

/// rr+usb for TransportRegistry: the stream from UsbHost::open_stream, run in a StreamPump.
class UsbConnector final : public Connector {
public:
    explicit UsbConnector(std::weak_ptr<UsbHost> host) : host_(std::move(host)) {}
    void connect(asio::any_io_executor strand, const ConnectionUrl& url, const ConnectOptions&,
                 std::shared_ptr<ConnectionLogic> logic, ConnectHandler done) override {
        auto host = host_.lock();
        if (!host) return done(fail(MessageErrorType::ConnectionError, "the rr+usb transport is shut down"));
        host->open_stream(url, strand, [strand, logic = std::move(logic), done = std::move(done)](Result<UsbByteStream> s) mutable {
            asio::dispatch(strand, [strand, logic = std::move(logic), done = std::move(done), s = std::move(s)]() mutable {
                if (!s) return done(s.take_error());
                start_client_stream(std::move(*s), strand, std::move(logic), done);
            });
        });
    }

private:
    std::weak_ptr<UsbHost> host_;
};

}  // namespace

std::shared_ptr<Connector> make_usb_connector(std::shared_ptr<UsbHost> host) {
    return std::make_shared<UsbConnector>(std::move(host));
}

void register_usb_transport(TransportRegistry& registry, std::shared_ptr<UsbHost> host) {
    registry.add("rr+usb", make_usb_connector(std::move(host)));
}

}  // namespace rr::server::usb
