// A USB device emulator for tests and benchmarks that stands behind the REAL libusb code path:
// umockdev (Debian `umockdev`, `libumockdev-dev`) fakes the sysfs/udev view libusb enumerates and
// routes the usbdevfs ioctls libusb issues on /dev/bus/usb/BBB/DDD to a handler here. The handler is
// driven by core's DeviceFunction (base/usb/usb_device_function.hpp) and DescriptorTable, exactly as
// firmware would use them, and serves an ordinary node's services (server/node) over the RR streams:
// every stream the host opens is served by the node (server::serve_stream over a UsbByteStream).
//
// ioctls answered: GET_CAPABILITIES, CLAIM/RELEASEINTERFACE, DISCONNECT_CLAIM, SETINTERFACE,
// SETCONFIGURATION, CLEAR_HALT, RESET(EP), GETDRIVER (none), GET_SPEED, CONNECTINFO, SUBMITURB
// (control: standard GET_DESCRIPTOR from the DescriptorTable, RR vendor requests to DeviceFunction;
// bulk OUT into DeviceFunction; bulk IN held until DeviceFunction has a sub-packet), REAPURB(NDELAY),
// DISCARDURB. Readiness: umockdev's device node is a plain file (always "ready", so libusb's event
// loop would spin); the emulator puts a FIFO there, keeps it full (not writable) and drains it while
// URBs are waiting to be reaped, so libusb's poll() for POLLOUT sleeps until there is work – like
// the kernel's usbfs.
//
// Unplug: in-flight URBs complete with -ESHUTDOWN, further ioctls fail with ENODEV, then a udev
// "remove" uevent (libusb's hotplug LEFT) and the sysfs entry goes; re-plug is another plug().
//
// Only in a process started by `umockdev-wrapper` (LD_PRELOAD of libumockdev-preload);
// UsbEmulator::create() says NotImplementedError elsewhere, and tests then skip (exit code 77).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "base/usb/usb_descriptor_table.hpp"
#include "base/usb/usb_device_function.hpp"
#include "server/node/node.hpp"

namespace rr::test::usb {

struct EmulatedDeviceOptions {
    rr::usb::DeviceLayout layout;
    rr::usb::DeviceStrings strings;          ///< node_id must be set (the node's NodeID, usually)
    rr::usb::DeviceFunctionConfig function;
    bool bos_capability = true;              ///< advertise the RR BOS platform capability
    bool sysfs_bos = true;                   ///< also as sysfs `bos_descriptors` (kernel ≥ 6.3); else only over the wire
    std::uint8_t bus = 1, address = 2;
    std::string sysfs_name;                  ///< default "<bus>-<address>"
    std::size_t rx_high_water = 256u << 10;  ///< device-side flow control: pause the host's stream above this
    std::size_t rx_low_water = 64u << 10;
    unsigned node_mode = 0666;               ///< mode of /dev/bus/usb/BBB/DDD (permission tests)
    /// Served for the 0xBA request instead of DeviceFunction's set (malformed-descriptor tests).
    std::optional<std::vector<std::byte>> descriptor_set_override;
};

struct EmulatorStats {
    std::atomic<std::uint64_t> control_requests{0}, bulk_out{0}, bulk_in{0}, stalls{0};
    std::atomic<std::uint64_t> bulk_out_bytes{0}, bulk_in_bytes{0};
    std::atomic<std::uint64_t> bulk_errors{0};  ///< bulk OUT transfers DeviceFunction rejected
    std::atomic<std::uint64_t> streams_opened{0}, streams_closed_by_host{0}, resets{0};
    std::atomic<std::uint64_t> pause_all{0}, resume_all{0};
    std::atomic<std::uint64_t> max_bulk_out_size{0}, max_bulk_in_size{0};
};

class EmulatedDevice {
public:
    virtual ~EmulatedDevice() = default;
    virtual const EmulatorStats& stats() const = 0;
    /// Streams the host has open now.
    virtual std::vector<std::int32_t> streams() const = 0;
    /// Bytes received from the host on `id` so far.
    virtual std::uint64_t received_on(std::int32_t id) const = 0;
    /// The device asks the host to pause (true) or resume (false) sending on `id` (a notification).
    virtual bool pause_host(std::int32_t id, bool paused) = 0;
    /// True while the host has paused every stream (PAUSE_ALL_STREAM).
    virtual bool paused_by_host() const = 0;
    /// The next bulk IN transfer carries exactly these bytes (malformed-packet tests).
    virtual void inject_in_transfer(std::vector<std::byte> bytes) = 0;
    /// Stop (or resume) answering bulk IN reads: the device's data waits (as a busy device).
    virtual void hold_in(bool hold) = 0;
    virtual std::string device_path() const = 0;
    virtual bool plugged() const = 0;
};

class UsbEmulator {
public:
    /// Errors: NotImplementedError with the reason when not running under umockdev-wrapper.
    static Result<std::unique_ptr<UsbEmulator>> create();
    virtual ~UsbEmulator() = default;
    /// Plugs in a device serving `node`'s services. Errors: InvalidArgument (descriptors, address taken).
    virtual Result<EmulatedDevice*> plug(EmulatedDeviceOptions options, std::shared_ptr<server::Node> node) = 0;
    /// Unplugs it (see the header comment); the object stays valid (plugged() false).
    virtual void unplug(EmulatedDevice* device) = 0;
    virtual std::string root_dir() const = 0;
};

/// Why the emulator cannot run here ("" when it can): checked by test mains to exit 77.
std::string emulator_unavailable_reason();

}  // namespace rr::test::usb
