// Thin RAII over libusb-1.0 for the rr+usb host: a context with its own event thread (libusb's
// handle_events loop, so nothing blocks the node's io_context), hotplug registration, device
// references and handles, and asynchronous control and bulk transfers whose completions run on the
// event thread (callers post them to their strand).
//
// Rules kept here: a handle is closed only after its transfers completed (owners count them), never
// on the event thread; transfers are freed in their completion.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include <libusb.h>

#include "base/error/rr_error.hpp"
#include "base/usb/usb_protocol.hpp"

namespace rr::server::usb {

struct DeviceUnref {
    void operator()(libusb_device* d) const noexcept { libusb_unref_device(d); }
};
/// A counted reference to a libusb_device (kept while the device is known).
using DeviceRef = std::unique_ptr<libusb_device, DeviceUnref>;
inline DeviceRef ref_device(libusb_device* d) { return DeviceRef(libusb_ref_device(d)); }

struct HandleCloser {
    void operator()(libusb_device_handle* h) const noexcept { libusb_close(h); }
};
using DeviceHandle = std::unique_ptr<libusb_device_handle, HandleCloser>;

class LibusbContext {
public:
    /// libusb_init and the event thread. Errors: IOError with libusb's message.
    static Result<std::shared_ptr<LibusbContext>> create();
    ~LibusbContext();
    LibusbContext(const LibusbContext&) = delete;
    LibusbContext& operator=(const LibusbContext&) = delete;

    libusb_context* get() const noexcept { return ctx_; }
    bool has_hotplug() const noexcept;
    /// Calls `fn(arrived, device)` on the event thread for every arrival and departure (any device).
    /// Errors: NotImplementedError when libusb has no hotplug here, IOError otherwise.
    Result<void> watch_hotplug(std::function<void(bool arrived, libusb_device* device)> fn);
    /// Deregisters the hotplug callback (the event thread goes on). Idempotent.
    void stop_hotplug();
    /// Deregisters hotplug and joins the event thread; transfers must be finished first. Idempotent.
    void stop();
    bool on_event_thread() const noexcept { return std::this_thread::get_id() == thread_id_; }
    /// Contexts of this process initialised and not yet exited (the last owner may finish the exit on
    /// a thread of its own). libusb's Linux hotplug monitor is shared by all the contexts of a process
    /// and started by the first one, on the udev view of that moment: tests that change the view
    /// (umockdev testbeds) wait for 0 before they make the next context.
    static std::size_t open_contexts() noexcept;

private:
    LibusbContext() = default;
    static int LIBUSB_CALL hotplug_cb(libusb_context*, libusb_device*, libusb_hotplug_event, void*);

    libusb_context* ctx_ = nullptr;
    std::thread thread_;
    std::thread::id thread_id_;
    std::shared_ptr<std::atomic<bool>> stop_ = std::make_shared<std::atomic<bool>>(false);
    std::mutex mutex_;
    std::function<void(bool, libusb_device*)> hotplug_fn_;
    libusb_hotplug_callback_handle hotplug_handle_ = 0;
    bool hotplug_registered_ = false;
};

/// Status of a finished transfer: a libusb_transfer_status (COMPLETED = 0), or a negative libusb
/// error when the submit itself failed (e.g. LIBUSB_ERROR_NO_DEVICE).
struct TransferResult {
    int status = 0;
    std::size_t actual = 0;
    bool ok() const noexcept { return status == LIBUSB_TRANSFER_COMPLETED; }
    bool device_gone() const noexcept { return status == LIBUSB_TRANSFER_NO_DEVICE || status == LIBUSB_ERROR_NO_DEVICE; }
    std::string text() const;
};

/// Submits a control transfer; `done(result, in_data)` runs on the event thread (or at once, on the
/// calling thread, when the submit fails). `out_data` is the OUT data stage (setup.length bytes).
void submit_control(libusb_device_handle* handle, const rr::usb::SetupPacket& setup,
                    std::span<const std::byte> out_data, unsigned timeout_ms,
                    std::function<void(TransferResult, std::vector<std::byte>)> done);

/// A reusable bulk transfer with its own buffer (the link keeps a few of each direction).
class BulkTransfer {
public:
    BulkTransfer(libusb_device_handle* handle, std::uint8_t endpoint, std::size_t buffer_size);
    ~BulkTransfer();
    BulkTransfer(const BulkTransfer&) = delete;
    BulkTransfer& operator=(const BulkTransfer&) = delete;

    std::span<std::byte> buffer() noexcept { return buffer_; }
    bool in_flight() const noexcept { return in_flight_; }
    /// Submits `length` bytes (OUT) or a read of the whole buffer (IN); `done` runs on the event
    /// thread, or at once when the submit fails.
    void submit(std::size_t length, std::function<void(TransferResult)> done);
    /// Asks libusb to cancel (the completion still comes, with CANCELLED).
    void cancel() noexcept;
    std::span<const std::byte> received(std::size_t n) const noexcept { return std::span<const std::byte>(buffer_).first(n); }

private:
    static void LIBUSB_CALL completed(libusb_transfer* t);
    libusb_transfer* transfer_ = nullptr;
    std::vector<std::byte> buffer_;
    std::function<void(TransferResult)> done_;
    std::atomic<bool> in_flight_{false};
};

}  // namespace rr::server::usb
