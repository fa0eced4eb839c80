#include "test/usb/usb_emulator.hpp"

#include <fcntl.h>  // F_SETPIPE_SZ (_GNU_SOURCE, which g++ defines)
#include <sys/stat.h>
#include <unistd.h>

#include <linux/ioctl.h>  // before usbdevice_fs.h in C++ (_IOR)
#include <linux/usbdevice_fs.h>

#include <umockdev.h>

#include <algorithm>
#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>

#include <boost/asio/strand.hpp>

#include "server/transport/transport.hpp"
#include "server/transport/usb/usb_stream.hpp"

namespace rr::test::usb {

namespace asio = boost::asio;
namespace core = rr::usb;
using server::usb::StreamCompletion;
using server::usb::UsbByteStream;
using server::usb::UsbStreamBuffers;
using server::usb::UsbStreamChannel;

std::string emulator_unavailable_reason() {
    const char* preload = std::getenv("LD_PRELOAD");
    if (!preload || std::string(preload).find("libumockdev-preload") == std::string::npos)
        return "not running under umockdev-wrapper (LD_PRELOAD has no libumockdev-preload)";
    return {};
}

namespace {

std::string hex(std::span<const std::byte> b) {
    static constexpr char d[] = "0123456789abcdef";
    std::string s;
    for (auto x : b) {
        s.push_back(d[std::to_integer<unsigned>(x) >> 4]);
        s.push_back(d[std::to_integer<unsigned>(x) & 15]);
    }
    return s;
}

void bump_max(std::atomic<std::uint64_t>& m, std::uint64_t v) {
    auto cur = m.load();
    while (v > cur && !m.compare_exchange_weak(cur, v)) {
    }
}

class DeviceCore final : public UsbStreamChannel, public EmulatedDevice, public std::enable_shared_from_this<DeviceCore> {
public:
    DeviceCore(EmulatedDeviceOptions o, core::DescriptorTable table, std::shared_ptr<server::Node> node, UMockdevTestbed* tb)
        : opt_(std::move(o)), fn_(opt_.function), table_(std::move(table)), node_(std::move(node)), tb_(tb) {
        char p[64];
        std::snprintf(p, sizeof p, "/dev/bus/usb/%03u/%03u", unsigned(opt_.bus), unsigned(opt_.address));
        devpath_ = p;
        if (opt_.sysfs_name.empty()) opt_.sysfs_name = std::to_string(opt_.bus) + "-" + std::to_string(opt_.address);
        syspath_ = "/sys/devices/pci0000:00/0000:00:14.0/usb" + std::to_string(opt_.bus) + "/" + opt_.sysfs_name;
    }
    ~DeviceCore() override {
        if (fifo_fd_ >= 0) ::close(fifo_fd_);
        if (handler_) g_object_unref(handler_);
    }

    Result<void> attach() {
        handler_ = umockdev_ioctl_base_new();
        // umockdev calls the handler on its own thread, also for an ioctl that was under way while the
        // emulator detached and dropped this device: the handler holds a weak reference, not `this`.
        g_signal_connect_data(handler_, "handle-ioctl", G_CALLBACK(&DeviceCore::on_ioctl),
                              new std::weak_ptr<DeviceCore>(weak_from_this()),
                              [](gpointer weak, GClosure*) { delete static_cast<std::weak_ptr<DeviceCore>*>(weak); },
                              GConnectFlags(0));
        if (!umockdev_testbed_attach_ioctl(tb_, devpath_.c_str(), handler_, nullptr))
            return fail(MessageErrorType::InvalidArgument, "umockdev: cannot attach an ioctl handler to " + devpath_);
        // The device node: a FIFO kept full, drained while URBs wait to be reaped (see the header).
        const std::string root = root_dir();
        const std::string node_path = root + devpath_;
        std::error_code ec;
        std::filesystem::create_directories(std::filesystem::path(node_path).parent_path(), ec);
        ::unlink(node_path.c_str());
        if (::mkfifo(node_path.c_str(), 0666) != 0 || ::chmod(node_path.c_str(), opt_.node_mode) != 0)
            return fail(MessageErrorType::IOError, "cannot make the FIFO " + node_path + ": " + std::strerror(errno));
        fifo_fd_ = ::open(node_path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
        if (fifo_fd_ < 0) return fail(MessageErrorType::IOError, "cannot open the FIFO " + node_path);
        (void)::fcntl(fifo_fd_, F_SETPIPE_SZ, 4096);  // one page: one write fills it, one read drains it
        fill_fifo();

        std::string s = "P: " + syspath_.substr(4) + "\n" +
                        "E: SUBSYSTEM=usb\nE: DEVTYPE=usb_device\nE: DRIVER=usb\n"
                        "E: BUSNUM=" + three(opt_.bus) + "\nE: DEVNUM=" + three(opt_.address) + "\nE: DEVNAME=" + devpath_ + "\n" +
                        "A: busnum=" + std::to_string(opt_.bus) + "\\n\nA: devnum=" + std::to_string(opt_.address) + "\\n\n" +
                        "A: speed=480\\n\nA: bConfigurationValue=" + std::to_string(opt_.layout.configuration_value) + "\\n\n" +
                        "A: idVendor=" + hex4(opt_.layout.vendor_id) + "\\n\nA: idProduct=" + hex4(opt_.layout.product_id) + "\\n\n" +
                        "H: descriptors=" + hex(table_.sysfs_descriptors()) + "\n";
        if (opt_.sysfs_bos && !table_.bos().empty()) s += "H: bos_descriptors=" + hex(table_.bos()) + "\n";
        GError* err = nullptr;
        if (!umockdev_testbed_add_from_string(tb_, s.c_str(), &err)) {
            std::string m = err ? err->message : "?";
            if (err) g_error_free(err);
            return fail(MessageErrorType::InvalidArgument, "umockdev: cannot add the device: " + m);
        }
        plugged_.store(true);
        return {};
    }

    void unplug() {
        {
            std::lock_guard lock(m_);
            if (gone_) return;
            gone_ = true;
            for (auto* urb : pending_in_) {
                urb->status = -ESHUTDOWN;
                urb->actual_length = 0;
                reapable_.push_back(urb);
            }
            pending_in_.clear();
            for (auto& [id, s] : streams_) s.buf.end(asio::error::eof, asio::error::broken_pipe);
            signal_ready();
        }
        plugged_.store(false);
        umockdev_testbed_uevent(tb_, syspath_.c_str(), "remove");
        umockdev_testbed_remove_device(tb_, syspath_.c_str());
    }

    void detach() { umockdev_testbed_detach_ioctl(tb_, devpath_.c_str(), nullptr); }

    // EmulatedDevice
    const EmulatorStats& stats() const override { return stats_; }
    std::vector<std::int32_t> streams() const override {
        std::lock_guard lock(m_);
        std::vector<std::int32_t> out;
        for (const auto& [id, s] : streams_)
            if (fn_.is_open(id)) out.push_back(id);
        return out;
    }
    std::uint64_t received_on(std::int32_t id) const override {
        std::lock_guard lock(m_);
        auto it = received_.find(id);
        return it == received_.end() ? 0 : it->second;
    }
    bool pause_host(std::int32_t id, bool paused) override {
        std::lock_guard lock(m_);
        if (!fn_.pause_receive(id, paused)) return false;
        pump_in();
        return true;
    }
    bool paused_by_host() const override {
        std::lock_guard lock(m_);
        return fn_.host_paused_all();
    }
    void inject_in_transfer(std::vector<std::byte> bytes) override {
        std::lock_guard lock(m_);
        injected_.push_back(std::move(bytes));
        pump_in();
    }
    void hold_in(bool hold) override {
        std::lock_guard lock(m_);
        hold_in_ = hold;
        pump_in();
    }
    std::string device_path() const override { return devpath_; }
    bool plugged() const override { return plugged_.load(); }

    // UsbStreamChannel: the node's server connections on the device's streams.
    void async_read(std::int32_t id, asio::mutable_buffer buffer, StreamCompletion done) override {
        std::lock_guard lock(m_);
        auto it = streams_.find(id);
        if (it == streams_.end()) return done(asio::error::eof, 0);
        it->second.buf.start_read(buffer, std::move(done));
        if (it->second.paused_rx && it->second.buf.queued() < opt_.rx_low_water) {
            it->second.paused_rx = false;
            (void)fn_.pause_receive(id, false);
            pump_in();
        }
    }
    void async_write(std::int32_t id, asio::const_buffer buffer, StreamCompletion done) override {
        std::lock_guard lock(m_);
        auto it = streams_.find(id);
        if (gone_ || it == streams_.end()) return done(asio::error::broken_pipe, 0);
        if (!fn_.send(id, std::span<const std::byte>(static_cast<const std::byte*>(buffer.data()), buffer.size())))
            return done(asio::error::broken_pipe, 0);
        it->second.buf.start_write(buffer.size(), std::move(done));
        pump_in();
    }
    void close_stream(std::int32_t id) override {
        std::lock_guard lock(m_);
        auto it = streams_.find(id);
        if (it == streams_.end()) return;
        fn_.drop_pending(id);
        (void)fn_.close_stream(id);  // "socket closed" to the host, unless the host closed it first
        it->second.buf.abort(asio::error::operation_aborted);
        streams_.erase(it);
        pump_in();
    }

private:
    struct Stream {
        UsbStreamBuffers buf;
        bool paused_rx = false;
    };

    static std::string three(unsigned v) {
        char b[8];
        std::snprintf(b, sizeof b, "%03u", v);
        return b;
    }
    static std::string hex4(unsigned v) {
        char b[8];
        std::snprintf(b, sizeof b, "%04x", v);
        return b;
    }
    std::string root_dir() const {
        gchar* r = umockdev_testbed_get_root_dir(tb_);
        std::string s = r;
        g_free(r);
        return s;
    }
    // The ioctl argument as the client passed it (a pointer into the client, which is this process:
    // the preload library and the handler share the address space, as libusb's own umockdev test notes).
    static void* arg_pointer(UMockdevIoctlData* arg) {
        void* p = nullptr;
        std::memcpy(&p, arg->data, std::min<std::size_t>(sizeof p, static_cast<std::size_t>(arg->data_len)));
        return p;
    }

    // FIFO readiness (under m_).
    void fill_fifo() {
        static const char zeros[4096] = {};
        while (::write(fifo_fd_, zeros, sizeof zeros) > 0) {
        }
    }
    void signal_ready() {
        if (signaled_ || reapable_.empty()) return;
        char buf[1 << 16];
        while (::read(fifo_fd_, buf, sizeof buf) > 0) {
        }
        signaled_ = true;
    }
    void unsignal() {
        if (!signaled_) return;
        fill_fifo();
        signaled_ = false;
    }

    static gboolean on_ioctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer weak) {
        auto self = static_cast<std::weak_ptr<DeviceCore>*>(weak)->lock();
        if (!self) {  // the device was dropped: answered as an unplugged device's would be
            umockdev_ioctl_client_complete(client, -1, ENODEV);
            return TRUE;
        }
        return self->ioctl(client);
    }

    gboolean ioctl(UMockdevIoctlClient* client) {
        const unsigned long request = umockdev_ioctl_client_get_request(client);
        UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
        std::vector<std::function<void()>> after;
        long res = 0;
        int err = 0;
        {
            std::lock_guard lock(m_);
            if (gone_ && request != USBDEVFS_REAPURBNDELAY && request != USBDEVFS_REAPURB && request != USBDEVFS_DISCARDURB) {
                res = -1, err = ENODEV;
            } else {
                switch (request) {
                    case USBDEVFS_GET_CAPABILITIES: {
                        const guint32 caps = USBDEVFS_CAP_BULK_CONTINUATION | USBDEVFS_CAP_NO_PACKET_SIZE_LIM |
                                             USBDEVFS_CAP_REAP_AFTER_DISCONNECT | USBDEVFS_CAP_ZERO_PACKET;
                        std::memcpy(arg_pointer(arg), &caps, sizeof caps);
                        break;
                    }
                    case USBDEVFS_CLAIMINTERFACE:
                    case USBDEVFS_RELEASEINTERFACE:
                    case USBDEVFS_DISCONNECT_CLAIM:
                    case USBDEVFS_SETINTERFACE:
                    case USBDEVFS_SETCONFIGURATION:
                    case USBDEVFS_CLEAR_HALT:
                    case USBDEVFS_RESETEP:
                    case USBDEVFS_RESET:
                        break;
                    case USBDEVFS_GETDRIVER:
                    case USBDEVFS_DISCONNECT:
                    case USBDEVFS_IOCTL:  // libusb's kernel-driver detach/attach
                        res = -1, err = ENODATA;  // no kernel driver bound
                        break;
                    case USBDEVFS_GET_SPEED:
                        res = 3;  // USB_SPEED_HIGH
                        break;
                    case USBDEVFS_CONNECTINFO: {
                        usbdevfs_connectinfo ci{};
                        ci.devnum = opt_.address;
                        ci.slow = 0;
                        std::memcpy(arg_pointer(arg), &ci, sizeof ci);
                        break;
                    }
                    case USBDEVFS_SUBMITURB:
                        submit(arg, after);
                        break;
                    case USBDEVFS_REAPURB:
                    case USBDEVFS_REAPURBNDELAY:
                        if (!reap(arg)) res = -1, err = gone_ ? ENODEV : EAGAIN;
                        break;
                    case USBDEVFS_DISCARDURB:
                        if (!discard(arg)) res = -1, err = EINVAL;
                        break;
                    default:
                        std::fprintf(stderr, "usb emulator: unhandled usbdevfs ioctl 0x%lx\n", request);
                        res = -1, err = ENOTTY;
                        break;
                }
            }
        }
        umockdev_ioctl_client_complete(client, res, err);
        for (auto& f : after) f();
        return TRUE;
    }

    // URBs are used in place (umockdev_ioctl_data_resolve would copy each one and its buffer through
    // umockdev's socket, several round trips per transfer): libusb does not touch a submitted URB until
    // it is reaped.
    void submit(UMockdevIoctlData* arg, std::vector<std::function<void()>>& after) {
        auto* urb = static_cast<usbdevfs_urb*>(arg_pointer(arg));
        std::span<std::byte> data;
        if (urb->buffer_length > 0)
            data = std::span<std::byte>(static_cast<std::byte*>(urb->buffer), static_cast<std::size_t>(urb->buffer_length));
        urb->status = 0;
        urb->actual_length = 0;
        if (urb->type == USBDEVFS_URB_TYPE_CONTROL) {
            control(urb, data, after);
        } else if (urb->type == USBDEVFS_URB_TYPE_BULK && urb->endpoint == opt_.layout.in_endpoint) {
            pending_in_.push_back(urb);
            pump_in();
            return;
        } else if (urb->type == USBDEVFS_URB_TYPE_BULK && urb->endpoint == opt_.layout.out_endpoint) {
            bulk_out(data);
            urb->actual_length = urb->buffer_length;
        } else {
            urb->status = -EPIPE;
        }
        reapable_.push_back(urb);
        signal_ready();
    }

    void control(usbdevfs_urb* urb, std::span<std::byte> data, std::vector<std::function<void()>>& after) {
        stats_.control_requests.fetch_add(1);
        auto setup = core::parse_setup_packet(data);
        if (!setup) {
            urb->status = -EPIPE;
            return;
        }
        auto stage = data.subspan(core::kSetupPacketSize);
        if (stage.size() > setup->length) stage = stage.first(setup->length);
        auto stall = [&] {
            stats_.stalls.fetch_add(1);
            urb->status = -EPIPE;
        };
        if (setup->request_type == 0x80 && setup->request == 0x06) {
            auto d = table_.get_descriptor(*setup);
            if (!d) return stall();
            const auto n = std::min(d->size(), stage.size());
            std::copy_n(d->begin(), n, stage.begin());
            urb->actual_length = static_cast<int>(n);
            return;
        }
        if (fn_.accepts(*setup) && setup->request == core::kDescriptorRequest && opt_.descriptor_set_override) {
            const auto& d = *opt_.descriptor_set_override;
            const auto n = std::min(d.size(), stage.size());
            std::copy_n(d.begin(), n, stage.begin());
            urb->actual_length = static_cast<int>(n);
            return;
        }
        if (fn_.accepts(*setup)) {
            auto o = fn_.on_control(*setup, setup->is_in() ? std::span<const std::byte>() : std::span<const std::byte>(stage),
                                    setup->is_in() ? stage : std::span<std::byte>());
            if (!o) return stall();
            urb->actual_length = static_cast<int>(setup->is_in() ? o->in_length : stage.size());
            using Effect = core::ControlOutcome::Effect;
            switch (o->effect) {
                case Effect::StreamOpened: {
                    streams_.try_emplace(o->stream_id);
                    stats_.streams_opened.fetch_add(1);
                    after.push_back([self = shared_from_this(), id = o->stream_id] {
                        server::serve_stream(*self->node_, UsbByteStream(asio::make_strand(self->node_->io_context()), self, id),
                                             server::AcceptedStream{"rr+usb:///", self->devpath_ + " stream " + std::to_string(id)});
                    });
                    break;
                }
                case Effect::StreamClosed: {
                    stats_.streams_closed_by_host.fetch_add(1);
                    auto it = streams_.find(o->stream_id);
                    if (it != streams_.end()) it->second.buf.end(asio::error::eof, asio::error::broken_pipe);
                    break;
                }
                case Effect::AllReset:
                    stats_.resets.fetch_add(1);
                    for (auto& [id, s] : streams_) s.buf.end(asio::error::eof, asio::error::broken_pipe);
                    break;
                case Effect::PausedAll:
                    stats_.pause_all.fetch_add(1);
                    break;
                case Effect::ResumedAll:
                    stats_.resume_all.fetch_add(1);
                    pump_in();
                    break;
                default:
                    break;
            }
            return;
        }
        if ((setup->request_type & 0x60) == 0 && !setup->is_in()) return;  // other standard OUT requests: accept
        stall();
    }

    void bulk_out(std::span<const std::byte> data) {
        stats_.bulk_out.fetch_add(1);
        stats_.bulk_out_bytes.fetch_add(data.size());
        bump_max(stats_.max_bulk_out_size, data.size());
        auto ev = fn_.on_bulk_out(data);
        if (!ev) {
            stats_.bulk_errors.fetch_add(1);
            return;
        }
        using Kind = core::DeviceEvent::Kind;
        auto it = streams_.find(ev->stream_id);
        switch (ev->kind) {
            case Kind::Data:
                received_[ev->stream_id] += ev->payload.size();
                if (it == streams_.end()) return;
                it->second.buf.on_data(ev->payload);
                if (!it->second.paused_rx && it->second.buf.queued() > opt_.rx_high_water) {
                    it->second.paused_rx = true;
                    (void)fn_.pause_receive(ev->stream_id, true);
                    pump_in();
                }
                return;
            case Kind::Closed:
                if (it != streams_.end()) it->second.buf.end(asio::error::eof, asio::error::broken_pipe);
                return;
            case Kind::Resumed:
                pump_in();
                return;
            default:
                return;
        }
    }

    void pump_in() {
        while (!pending_in_.empty() && !hold_in_ && !gone_) {
            usbdevfs_urb* urb = pending_in_.front();
            std::span<std::byte> out;
            if (urb->buffer_length > 0)
                out = std::span<std::byte>(static_cast<std::byte*>(urb->buffer), static_cast<std::size_t>(urb->buffer_length));
            std::size_t n = 0;
            if (!injected_.empty()) {
                auto& b = injected_.front();
                n = std::min(b.size(), out.size());
                std::copy_n(b.begin(), n, out.begin());
                injected_.pop_front();
            } else {
                auto f = fn_.fill_bulk_in(out);
                if (!f) break;
                n = f->size;
                if (f->drained) {
                    auto it = streams_.find(f->stream_id);
                    if (it != streams_.end()) it->second.buf.write_drained();
                }
            }
            urb->actual_length = static_cast<int>(n);
            urb->status = 0;
            stats_.bulk_in.fetch_add(1);
            stats_.bulk_in_bytes.fetch_add(n);
            bump_max(stats_.max_bulk_in_size, n);
            reapable_.push_back(urb);
            pending_in_.pop_front();
        }
        signal_ready();
    }

    bool reap(UMockdevIoctlData* arg) {
        if (reapable_.empty()) {
            unsignal();
            return false;
        }
        usbdevfs_urb* urb = reapable_.front();
        reapable_.pop_front();
        *static_cast<void**>(arg_pointer(arg)) = urb;
        return true;
    }

    bool discard(UMockdevIoctlData* arg) {
        auto* target = static_cast<usbdevfs_urb*>(arg_pointer(arg));
        auto it = std::find(pending_in_.begin(), pending_in_.end(), target);
        if (it == pending_in_.end()) return false;
        target->status = -ENOENT;
        target->actual_length = 0;
        reapable_.push_back(target);
        pending_in_.erase(it);
        signal_ready();
        return true;
    }

    EmulatedDeviceOptions opt_;
    mutable std::mutex m_;
    core::DeviceFunction fn_;
    core::DescriptorTable table_;
    std::shared_ptr<server::Node> node_;
    UMockdevTestbed* tb_ = nullptr;
    UMockdevIoctlBase* handler_ = nullptr;
    std::string devpath_, syspath_;
    int fifo_fd_ = -1;
    bool signaled_ = false;
    std::deque<usbdevfs_urb*> pending_in_;
    std::deque<usbdevfs_urb*> reapable_;
    std::deque<std::vector<std::byte>> injected_;
    bool hold_in_ = false;
    bool gone_ = false;
    std::atomic<bool> plugged_{false};
    std::map<std::int32_t, Stream> streams_;
    std::map<std::int32_t, std::uint64_t> received_;
    EmulatorStats stats_;
};

class Emulator final : public UsbEmulator {
public:
    Emulator() : tb_(umockdev_testbed_new()) {}
    ~Emulator() override {
        for (auto& d : devices_) d->detach();
        devices_.clear();
        g_object_unref(tb_);
    }

    Result<EmulatedDevice*> plug(EmulatedDeviceOptions options, std::shared_ptr<server::Node> node) override {
        char path[64];
        std::snprintf(path, sizeof path, "/dev/bus/usb/%03u/%03u", unsigned(options.bus), unsigned(options.address));
        for (const auto& d : devices_)
            if (d->plugged() && d->device_path() == path)
                return fail(MessageErrorType::InvalidArgument, "an emulated device is plugged at that address");
        auto table = core::DescriptorTable::build(options.layout, options.strings, options.function, options.bos_capability);
        if (!table) return table.take_error();
        auto dev = std::make_shared<DeviceCore>(std::move(options), std::move(*table), std::move(node), tb_);
        if (auto r = dev->attach(); !r) return r.take_error();
        devices_.push_back(dev);
        return static_cast<EmulatedDevice*>(dev.get());
    }

    void unplug(EmulatedDevice* device) override {
        for (auto& d : devices_)
            if (d.get() == device) d->unplug();
    }

    std::string root_dir() const override {
        gchar* r = umockdev_testbed_get_root_dir(tb_);
        std::string s = r;
        g_free(r);
        return s;
    }

private:
    UMockdevTestbed* tb_;
    std::vector<std::shared_ptr<DeviceCore>> devices_;
};

}  // namespace

Result<std::unique_ptr<UsbEmulator>> UsbEmulator::create() {
    if (auto why = emulator_unavailable_reason(); !why.empty()) return fail(MessageErrorType::NotImplementedError, why);
    return std::unique_ptr<UsbEmulator>(new Emulator());
}

}  // namespace rr::test::usb
