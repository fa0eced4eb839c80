// rr+usb for the rr command-line client (docs/cli.md, docs/usb.md). The CLI's composition registers the
// rr+usb connector in server::default_transports() at start (install_usb_transport in rr_main); libusb
// itself (a UsbHost with its event thread and a first bus scan) starts only when an rr+usb URL is
// connected or `rr discover` lists USB devices. Built without libusb, nothing is registered and rr+usb
// URLs fail with "no transport for rr+usb".
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "base/error/rr_error.hpp"
#include "base/names/node_id.hpp"

namespace rr::client {
class IoThreads;
}

namespace rr::cli {

/// Keeps the CLI's USB host; destroying it shuts libusb down (keep it until the end of main).
class UsbGuard {
public:
    virtual ~UsbGuard() = default;
};

/// Registers the lazy rr+usb connector in server::default_transports(). Returns the guard (a no-op
/// one when the build has no libusb).
std::unique_ptr<UsbGuard> install_usb_transport();

/// The io threads a command runs its client (and discovery) on. With rr+usb installed these are the USB
/// host's own, kept until the guard goes: the host hands a connect's result to the client's strand
/// from its thread, so the client's io_context must outlive the host's work on it. Otherwise new ones
/// with `threads` threads.
std::shared_ptr<client::IoThreads> command_io_threads(unsigned threads);

/// An RR USB device as `rr discover` shows it.
struct CliUsbDevice {
    NodeID node_id;            ///< all-zero when `error` is set
    std::string node_name;
    std::string url;           ///< rr+usb:///?nodeid=…&service=RobotRaconteurServiceIndex
    std::string description;   ///< "USB device 1209:0001 at bus 1 address 2"
    std::optional<RRError> error;  ///< why it cannot be used (e.g. no permission: names the udev rule)
};

/// Rescans the bus with the CLI's USB host (starting it when install_usb_transport() was called and it
/// has not started yet). Errors: NotImplementedError (no libusb in this build, or no install),
/// IOError (libusb could not start, e.g. no usbfs), OperationTimeout.
Result<std::vector<CliUsbDevice>> list_usb_devices(std::chrono::milliseconds timeout);

}  // namespace rr::cli
