// One claimed RR USB interface on the host (wire.md §10, docs/usb.md): the claim sequence, the bulk
// transfers kept in flight, core's HostMux, and the RR streams multiplexed on it, each handed out as a
// UsbByteStream.
//
// Threading: everything runs on the link's strand; libusb completions (event thread) are posted to
// it. The link lives while streams or connects use it; with the last stream closed it resets the
// device's streams, releases the interface and closes the handle (the next connect claims anew).
//
// Claim (as CORE's UsbDevice_Claim): open, claim interface, RESET_ALL_STREAM (IN 4) → zero-length bulk
// OUT → CURRENT_PROTOCOL (OUT 0x0101) → `in_transfers` bulk reads of wMaxPacketSize kept pending.
// Per stream: CONNECT_STREAM (IN 4, id ≥ 0). Local close: CLOSE_STREAM (OUT 4, id).
// Flow control: when the bytes received but not yet read pass `rx_high_water`, PAUSE_ALL_STREAM asks
// the device to hold its data; below `rx_low_water` RESUME_ALL_STREAM (a device that STALLs them –
// CORE never sends them – just is not paused). A device's pause notification for a stream stops the
// host's data on it until the resume.
// Failure (unplug, I/O error, protocol fault): every stream's pending operation fails with the
// usb_errc code, queued connects with a ConnectionError naming the cause.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/strand.hpp>

#include "base/usb/usb_host_mux.hpp"
#include "server/transport/usb/usb_error.hpp"
#include "server/transport/usb/usb_libusb.hpp"
#include "server/transport/usb/usb_stream.hpp"

namespace rr::server::usb {

/// Where the RR interface's bulk endpoints are (from the configuration descriptor).
struct LinkEndpoints {
    std::uint8_t interface_number = 0;
    std::uint8_t in_endpoint = 0x81;
    std::uint8_t out_endpoint = 0x01;
    std::uint16_t in_packet_size = 64;   ///< wMaxPacketSize of the IN endpoint: the read size
    std::uint16_t out_packet_size = 64;  ///< … of the OUT endpoint: the largest sub-packet sent
    int configuration = 1;               ///< bConfigurationValue holding the interface
};

struct LinkOptions {
    std::size_t max_streams = 16;
    unsigned control_timeout_ms = 5000;
    std::size_t in_transfers = 4;   ///< bulk reads kept pending (CORE: 4)
    std::size_t out_transfers = 4;  ///< bulk writes in flight at most (CORE: 4)
    std::size_t rx_high_water = 1u << 20;
    std::size_t rx_low_water = 256u << 10;
};

/// Counters for tests and benchmarks (read from any thread).
struct LinkStats {
    std::atomic<std::uint64_t> in_transfers{0}, out_transfers{0};
    std::atomic<std::uint64_t> dropped_unknown_stream{0};  ///< InvalidEndpoint transfers dropped
    std::atomic<std::uint64_t> pause_all_sent{0}, resume_all_sent{0};
    std::atomic<std::uint64_t> device_pause_requests{0}, device_resume_requests{0};
    std::atomic<std::uint64_t> streams_opened{0};
};

class UsbHostLink : public UsbStreamChannel, public std::enable_shared_from_this<UsbHostLink> {
public:
    using StreamDone = std::function<void(Result<UsbByteStream>)>;
    /// Connects waiting when the link finished closing: the manager retries them on a new link.
    using ClosedHandler = std::function<void(std::vector<std::pair<boost::asio::any_io_executor, StreamDone>> retry)>;

    /// `describe` names the device in errors ("USB device 1209:0001 at bus 1 address 2").
    static std::shared_ptr<UsbHostLink> create(boost::asio::any_io_executor executor, std::shared_ptr<LibusbContext> usb,
                                               DeviceRef device, LinkEndpoints endpoints, LinkOptions options,
                                               std::string describe);
    ~UsbHostLink() override;

    /// Opens an RR stream (claiming the interface first when needed). `done` runs on the link's strand;
    /// the stream's executor is `stream_executor` (the pump's strand). Errors: ConnectionError (claim
    /// or CONNECT_STREAM failed, stream refused, device gone), SystemResourcePermissionDenied.
    void connect_stream(boost::asio::any_io_executor stream_executor, StreamDone done);
    /// The device is gone or the host shuts down: fail everything with `ec` (async; idempotent).
    void fail(boost::system::error_code ec, std::string why);
    void set_closed_handler(ClosedHandler handler);

    bool closed() const noexcept { return closed_flag_.load(); }
    std::size_t stream_count() const noexcept { return stream_count_.load(); }
    const LinkStats& stats() const noexcept { return stats_; }
    libusb_device* device() const noexcept { return device_.get(); }

    // UsbStreamChannel (any thread)
    void async_read(std::int32_t id, boost::asio::mutable_buffer buffer, StreamCompletion done) override;
    void async_write(std::int32_t id, boost::asio::const_buffer buffer, StreamCompletion done) override;
    void close_stream(std::int32_t id) override;

private:
    enum class State { Idle, Claiming, Ready, Closing, Closed };
    struct Connect {
        boost::asio::any_io_executor executor;
        StreamDone done;
    };

    UsbHostLink(boost::asio::any_io_executor executor, std::shared_ptr<LibusbContext> usb, DeviceRef device,
                LinkEndpoints endpoints, LinkOptions options, std::string describe);

    // All below run on strand_.
    void claim();
    void claim_failed(RRError error);
    void after_reset(TransferResult r, std::vector<std::byte> data);
    void ready();
    void run_connects();
    void connect_one(Connect c);
    void control(const rr::usb::SetupPacket& setup, std::vector<std::byte> out_data,
                 std::function<void(TransferResult, std::vector<std::byte>)> done);
    void submit_in(std::size_t index);
    void on_in(std::size_t index, TransferResult r);
    void dispatch(std::span<const std::byte> transfer);
    void pump_out();
    void on_out(std::size_t index, TransferResult r);
    void check_rx_flow();
    void transfer_failed(const TransferResult& r, const char* what);
    void fail_now(boost::system::error_code ec, std::string why);
    void maybe_release();
    void begin_release();
    void maybe_finish();
    void finish();
    RRError link_error(std::string what) const;

    boost::asio::strand<boost::asio::any_io_executor> strand_;
    std::shared_ptr<LibusbContext> usb_;
    DeviceRef device_;
    DeviceHandle handle_;
    LinkEndpoints ep_;
    LinkOptions options_;
    std::string describe_;
    State state_ = State::Idle;
    bool claimed_ = false;
    rr::usb::HostMux mux_;
    std::vector<std::unique_ptr<BulkTransfer>> in_, out_;
    std::vector<bool> out_busy_;
    std::size_t ops_in_flight_ = 0;      // transfers submitted and not completed
    std::size_t connects_in_flight_ = 0;
    std::deque<Connect> queued_;
    std::map<std::int32_t, UsbStreamBuffers> streams_;
    bool rx_paused_ = false;
    boost::system::error_code failure_;
    std::string failure_text_;
    ClosedHandler on_closed_;
    std::atomic<bool> closed_flag_{false};
    std::atomic<std::size_t> stream_count_{0};
    LinkStats stats_;
};

}  // namespace rr::server::usb
