#include "server/cli/cli_usb.hpp"

#include <mutex>
#include <thread>

#include "server/client/client.hpp"
#include "server/transport/transport_registry.hpp"

#ifdef RR_HAVE_USB
#include "server/transport/usb/usb_host.hpp"
#endif

namespace rr::cli {

#ifdef RR_HAVE_USB

namespace {

// The host, started on first use; shut down by the guard. Its io threads also run the commands' client
// strands (command_io_threads): the host completes a connect by posting to the client's strand from its
// own thread, which is only safe while that strand's io_context lives, so the two share one that lasts
// until the guard goes.
class LazyUsb {
public:
    std::shared_ptr<client::IoThreads> io() {
        std::lock_guard lock(mutex_);
        return io_locked();
    }
    Result<std::shared_ptr<server::usb::UsbHost>> host() {
        std::lock_guard lock(mutex_);
        if (closed_) return fail(MessageErrorType::ConnectionError, "rr+usb: shut down");
        if (host_) return host_;
        if (start_error_) return fail(*start_error_);
        server::usb::UsbHostOptions o;
        auto h = server::usb::UsbHost::create(io_locked()->executor(), o);
        if (!h) {
            start_error_ = make_error(h.error().type, "rr+usb: " + h.error().message);
            return fail(*start_error_);
        }
        host_ = *h;
        return host_;
    }
    void close() {
        std::shared_ptr<server::usb::UsbHost> h;
        std::shared_ptr<client::IoThreads> io;
        {
            std::lock_guard lock(mutex_);
            closed_ = true;
            h = std::move(host_);
            io = std::move(io_);
        }
        if (h) {
            h->shutdown();
            for (int i = 0; i < 200 && !h->idle(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        h.reset();
        io.reset();  // joins the host's strand thread (unless a command still holds it)
    }

private:
    std::shared_ptr<client::IoThreads> io_locked() {
        if (!io_) io_ = std::make_shared<client::IoThreads>(2);
        return io_;
    }

    std::mutex mutex_;
    bool closed_ = false;
    std::shared_ptr<client::IoThreads> io_;
    std::shared_ptr<server::usb::UsbHost> host_;
    std::optional<RRError> start_error_;
};

std::mutex g_mutex;
std::shared_ptr<LazyUsb> g_usb;  // set by install_usb_transport, cleared by the guard

std::shared_ptr<LazyUsb> current() {
    std::lock_guard lock(g_mutex);
    return g_usb;
}

class LazyUsbConnector final : public server::Connector {
public:
    explicit LazyUsbConnector(std::weak_ptr<LazyUsb> usb) : usb_(std::move(usb)) {}
    void connect(boost::asio::any_io_executor strand, const ConnectionUrl& url, const server::ConnectOptions& options,
                 std::shared_ptr<server::ConnectionLogic> logic, server::ConnectHandler done) override {
        auto usb = usb_.lock();
        if (!usb) return done(fail(MessageErrorType::ConnectionError, "the rr+usb transport is shut down"));
        auto h = usb->host();
        if (!h) return done(h.take_error());
        server::usb::make_usb_connector(*h)->connect(std::move(strand), url, options, std::move(logic), std::move(done));
    }

private:
    std::weak_ptr<LazyUsb> usb_;
};

class RealGuard final : public UsbGuard {
public:
    explicit RealGuard(std::shared_ptr<LazyUsb> usb) : usb_(std::move(usb)) {}
    ~RealGuard() override {
        {
            std::lock_guard lock(g_mutex);
            if (g_usb == usb_) g_usb.reset();
        }
        usb_->close();
    }

private:
    std::shared_ptr<LazyUsb> usb_;
};

}  // namespace

std::unique_ptr<UsbGuard> install_usb_transport() {
    auto usb = std::make_shared<LazyUsb>();
    {
        std::lock_guard lock(g_mutex);
        g_usb = usb;
    }
    server::default_transports().add("rr+usb", std::make_shared<LazyUsbConnector>(usb));
    return std::make_unique<RealGuard>(usb);
}

std::shared_ptr<client::IoThreads> command_io_threads(unsigned threads) {
    if (auto usb = current()) return usb->io();
    return std::make_shared<client::IoThreads>(threads);
}

Result<std::vector<CliUsbDevice>> list_usb_devices(std::chrono::milliseconds timeout) {
    auto usb = current();
    if (!usb) return fail(MessageErrorType::NotImplementedError, "rr+usb is not set up in this program");
    auto h = usb->host();
    if (!h) return h.take_error();
    auto devices = (*h)->enumerate_wait(timeout);
    if (!devices) return devices.take_error();
    std::vector<CliUsbDevice> out;
    for (auto& d : *devices)
        out.push_back(CliUsbDevice{d.node_id, std::move(d.node_name), std::move(d.url), d.describe(), std::move(d.error)});
    return out;
}

#else  // no libusb in this build

namespace {
class NoGuard final : public UsbGuard {};
}  // namespace

std::unique_ptr<UsbGuard> install_usb_transport() { return std::make_unique<NoGuard>(); }

std::shared_ptr<client::IoThreads> command_io_threads(unsigned threads) { return std::make_shared<client::IoThreads>(threads); }

Result<std::vector<CliUsbDevice>> list_usb_devices(std::chrono::milliseconds) {
    return fail(MessageErrorType::NotImplementedError, "this rr was built without libusb (no rr+usb)");
}

#endif

}  // namespace rr::cli
