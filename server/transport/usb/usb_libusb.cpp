#include "server/transport/usb/usb_libusb.hpp"

#include <algorithm>

#include "server/transport/usb/usb_error.hpp"

namespace rr::server::usb {

// --- LibusbContext -------------------------------------------------------------------------------------

namespace {
std::atomic<std::size_t> g_open_contexts{0};  // libusb_init'ed, libusb_exit not yet returned
}

std::size_t LibusbContext::open_contexts() noexcept { return g_open_contexts.load(); }

Result<std::shared_ptr<LibusbContext>> LibusbContext::create() {
    std::shared_ptr<LibusbContext> c(new LibusbContext());
    const int r = libusb_init(&c->ctx_);
    if (r != 0) {
        c->ctx_ = nullptr;
        return fail(MessageErrorType::IOError, "libusb_init: " + libusb_error_text(r));
    }
    g_open_contexts.fetch_add(1);
    c->thread_ = std::thread([ctx = c->ctx_, stop = c->stop_] {
        while (!stop->load()) {
            timeval tv{1, 0};
            libusb_handle_events_timeout_completed(ctx, &tv, nullptr);
        }
    });
    c->thread_id_ = c->thread_.get_id();
    return c;
}

LibusbContext::~LibusbContext() {
    if (on_event_thread()) {
        // The last reference went away inside a completion: the event thread cannot join itself, so a
        // short-lived thread finishes the job.
        if (hotplug_registered_) libusb_hotplug_deregister_callback(ctx_, hotplug_handle_);
        stop_->store(true);
        std::thread([ctx = ctx_, t = std::move(thread_)]() mutable {
            libusb_interrupt_event_handler(ctx);
            t.join();
            libusb_exit(ctx);
            g_open_contexts.fetch_sub(1);
        }).detach();
        return;
    }
    stop();
    if (ctx_) {
        libusb_exit(ctx_);
        g_open_contexts.fetch_sub(1);
    }
}

bool LibusbContext::has_hotplug() const noexcept { return libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG) != 0; }

int LIBUSB_CALL LibusbContext::hotplug_cb(libusb_context*, libusb_device* device, libusb_hotplug_event event, void* user) {
    auto* self = static_cast<LibusbContext*>(user);
    std::function<void(bool, libusb_device*)> fn;
    {
        std::lock_guard lock(self->mutex_);
        fn = self->hotplug_fn_;
    }
    if (fn) fn(event == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED, device);
    return 0;  // stay registered
}

Result<void> LibusbContext::watch_hotplug(std::function<void(bool, libusb_device*)> fn) {
    if (!has_hotplug()) return fail(MessageErrorType::NotImplementedError, "libusb has no hotplug support here");
    {
        std::lock_guard lock(mutex_);
        hotplug_fn_ = std::move(fn);
        if (hotplug_registered_) return {};
    }
    const int r = libusb_hotplug_register_callback(
        ctx_, static_cast<libusb_hotplug_event>(LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED | LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT),
        static_cast<libusb_hotplug_flag>(0), LIBUSB_HOTPLUG_MATCH_ANY, LIBUSB_HOTPLUG_MATCH_ANY, LIBUSB_HOTPLUG_MATCH_ANY,
        &LibusbContext::hotplug_cb, this, &hotplug_handle_);
    if (r != LIBUSB_SUCCESS) return fail(MessageErrorType::IOError, "libusb hotplug: " + libusb_error_text(r));
    std::lock_guard lock(mutex_);
    hotplug_registered_ = true;
    return {};
}

void LibusbContext::stop_hotplug() {
    bool registered = false;
    {
        std::lock_guard lock(mutex_);
        registered = hotplug_registered_;
        hotplug_registered_ = false;
        hotplug_fn_ = nullptr;
    }
    if (registered && ctx_) libusb_hotplug_deregister_callback(ctx_, hotplug_handle_);
}

void LibusbContext::stop() {
    bool registered = false;
    {
        std::lock_guard lock(mutex_);
        registered = hotplug_registered_;
        hotplug_registered_ = false;
        hotplug_fn_ = nullptr;
    }
    if (registered && ctx_) libusb_hotplug_deregister_callback(ctx_, hotplug_handle_);
    if (thread_.joinable()) {
        stop_->store(true);
        libusb_interrupt_event_handler(ctx_);
        thread_.join();
    }
}

// --- transfers ---------------------------------------------------------------------------------------------

std::string TransferResult::text() const {
    if (status < 0) return libusb_error_text(status);
    switch (status) {
        case LIBUSB_TRANSFER_COMPLETED: return "completed";
        case LIBUSB_TRANSFER_ERROR: return "transfer error";
        case LIBUSB_TRANSFER_TIMED_OUT: return "timed out";
        case LIBUSB_TRANSFER_CANCELLED: return "cancelled";
        case LIBUSB_TRANSFER_STALL: return "stalled (the device refused the request)";
        case LIBUSB_TRANSFER_NO_DEVICE: return "device gone";
        case LIBUSB_TRANSFER_OVERFLOW: return "overflow";
    }
    return "transfer status " + std::to_string(status);
}

namespace {

struct ControlOp {
    std::vector<unsigned char> buffer;
    std::function<void(TransferResult, std::vector<std::byte>)> done;
};

void LIBUSB_CALL control_completed(libusb_transfer* t) {
    std::unique_ptr<ControlOp> op(static_cast<ControlOp*>(t->user_data));
    TransferResult r{t->status, static_cast<std::size_t>(std::max(0, t->actual_length))};
    std::vector<std::byte> data;
    if (r.ok() && (op->buffer[0] & 0x80) != 0) {
        const auto* p = reinterpret_cast<const std::byte*>(libusb_control_transfer_get_data(t));
        data.assign(p, p + r.actual);
    }
    libusb_free_transfer(t);
    op->done(r, std::move(data));
}

}  // namespace

void submit_control(libusb_device_handle* handle, const rr::usb::SetupPacket& setup,
                    std::span<const std::byte> out_data, unsigned timeout_ms,
                    std::function<void(TransferResult, std::vector<std::byte>)> done) {
    auto op = std::make_unique<ControlOp>();
    op->buffer.assign(LIBUSB_CONTROL_SETUP_SIZE + setup.length, 0);
    libusb_fill_control_setup(op->buffer.data(), setup.request_type, setup.request, setup.value, setup.index, setup.length);
    if (!setup.is_in()) {
        const auto n = std::min<std::size_t>(out_data.size(), setup.length);
        std::copy_n(reinterpret_cast<const unsigned char*>(out_data.data()), n, op->buffer.data() + LIBUSB_CONTROL_SETUP_SIZE);
    }
    op->done = std::move(done);
    libusb_transfer* t = libusb_alloc_transfer(0);
    if (!t) {
        auto d = std::move(op->done);
        return d(TransferResult{LIBUSB_ERROR_NO_MEM, 0}, {});
    }
    libusb_fill_control_transfer(t, handle, op->buffer.data(), &control_completed, op.get(), timeout_ms);
    const int r = libusb_submit_transfer(t);
    if (r != 0) {
        libusb_free_transfer(t);
        auto d = std::move(op->done);
        return d(TransferResult{r, 0}, {});
    }
    op.release();  // owned by the transfer until control_completed
}

BulkTransfer::BulkTransfer(libusb_device_handle* handle, std::uint8_t endpoint, std::size_t buffer_size)
    : transfer_(libusb_alloc_transfer(0)), buffer_(buffer_size) {
    if (transfer_)
        libusb_fill_bulk_transfer(transfer_, handle, endpoint, reinterpret_cast<unsigned char*>(buffer_.data()),
                                  static_cast<int>(buffer_.size()), &BulkTransfer::completed, this, 0);
}

BulkTransfer::~BulkTransfer() {
    if (transfer_) libusb_free_transfer(transfer_);
}

void BulkTransfer::submit(std::size_t length, std::function<void(TransferResult)> done) {
    if (!transfer_) return done(TransferResult{LIBUSB_ERROR_NO_MEM, 0});
    transfer_->length = static_cast<int>(std::min(length, buffer_.size()));
    done_ = std::move(done);
    in_flight_.store(true);
    const int r = libusb_submit_transfer(transfer_);
    if (r != 0) {
        in_flight_.store(false);
        auto d = std::move(done_);
        d(TransferResult{r, 0});
    }
}

void BulkTransfer::cancel() noexcept {
    if (transfer_ && in_flight_.load()) libusb_cancel_transfer(transfer_);
}

void LIBUSB_CALL BulkTransfer::completed(libusb_transfer* t) {
    auto* self = static_cast<BulkTransfer*>(t->user_data);
    auto d = std::move(self->done_);
    self->in_flight_.store(false);
    d(TransferResult{t->status, static_cast<std::size_t>(std::max(0, t->actual_length))});
}

}  // namespace rr::server::usb
