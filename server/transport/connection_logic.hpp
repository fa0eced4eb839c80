// The seam between a transport (bytes on a socket) and the sans-IO protocol objects of core/.
// A transport pump calls these from its strand only; implementations are not thread-safe.
#pragma once

#include <chrono>
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "base/codec/gather_buffer.hpp"
#include "base/error/rr_error.hpp"
#include "core/session/stream_connection.hpp"

namespace rr::server {

/// The monotonic clock of the server: the only place core's MonoTime is read.
inline MonoTime mono_now() noexcept { return std::chrono::steady_clock::now(); }

class PumpHandle;

class ConnectionLogic {
public:
    virtual ~ConnectionLogic() = default;
    /// The pump that drives this logic, before any byte flows (for work posted from other threads).
    virtual void attach(std::weak_ptr<PumpHandle> pump) {}
    /// Bytes arrived. Protocol errors are handled inside (they make wants_close() true).
    virtual void on_bytes(std::span<const std::byte> bytes, MonoTime now) = 0;
    /// Where the pump may read the next bytes instead of its own buffer (the rest of a large message,
    /// read into its final buffer: StreamConnection::read_space); it then passes them to on_bytes() as
    /// usual. Empty: the pump's buffer.
    virtual std::span<std::byte> read_space() { return {}; }
    /// True when bytes are waiting to be written.
    virtual bool has_output() const = 0;
    /// Moves every pending byte into `out` (cleared first; swapping buffers keeps this copy-free), large
    /// shared payloads as splices (GatherBuffer). The pump writes `out` with one gathered write while
    /// the logic keeps queueing into its own buffer.
    virtual void take_output(GatherBuffer& out) = 0;
    virtual std::optional<MonoTime> next_deadline() const = 0;
    virtual void on_timer(MonoTime now) = 0;
    /// True once the logic is finished; the pump closes the socket after flushing pending_output().
    virtual bool wants_close() const = 0;
    /// False while the logic has too much output queued: the pump stops reading (TCP backpressure on
    /// a peer that sends requests but does not read the replies) and resumes once output drains.
    virtual bool wants_read() const { return true; }
    /// Work other threads queued for this logic is waiting (PumpHandle::wake).
    virtual void on_wake() {}
    /// The socket failed or the peer closed it; called once.
    virtual void on_transport_closed(RRError error) = 0;
    /// The pump is being destroyed without having reported the transport's end: its io_context went
    /// away first, and Asio destroyed the pending operations uncalled (a program exiting mid-connect).
    /// Drop whatever refers back to the logic's owner (completions that hold it), calling nothing:
    /// no thread runs the connection any more.
    virtual void on_abandoned() noexcept {}
};

}  // namespace rr::server
