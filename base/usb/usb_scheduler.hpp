// Outbound half of an rr+usb link, shared by the host (usb_host_mux.hpp) and the device
// (usb_device_function.hpp): which RR stream's bytes go into the next bulk transfer.
//
// Each stream has at most one pending write: a view of bytes its owner keeps valid until they are
// consumed (fill() copies them into packet buffers, so a write is done once consumed – like a socket
// send buffer; the number of packet buffers in flight bounds the data queued below the stream).
// Streams are served round-robin, one sub-packet each, so a large message on one stream does not hold
// up the others. Notifications (pause/resume) go before data; a stream's "socket closed"
// notification goes after the data already pending on it.
//
// Bounded: at most `max_streams` streams and `max_notifications` queued notifications; no allocation
// after construction. Not thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "base/error/rr_error.hpp"
#include "base/usb/usb_protocol.hpp"

namespace rr::usb {

class SubpacketScheduler {
public:
    explicit SubpacketScheduler(std::size_t max_streams = 16, std::size_t max_notifications = 64);

    /// Errors: InvalidArgument (negative id, id present), OutOfSystemResource (table full).
    Result<void> add(std::int32_t id);
    /// Forgets the stream with its pending bytes and queued notifications. False when unknown.
    bool remove(std::int32_t id);
    /// Forgets every stream and notification; clears the pause-all flag.
    void clear();
    bool contains(std::int32_t id) const noexcept;
    std::size_t size() const noexcept { return entries_.size(); }
    std::size_t max_streams() const noexcept { return max_streams_; }

    /// Sets the bytes to send on `id`. Errors: InvalidArgument (unknown id or closing),
    /// InvalidOperation (a write is already pending).
    Result<void> set_pending(std::int32_t id, std::span<const std::byte> bytes);
    /// Bytes of the pending write not yet consumed (0 when none or unknown).
    std::size_t pending(std::int32_t id) const noexcept;
    /// Drops the pending write (its owner aborts it); returns the bytes dropped.
    std::size_t drop_pending(std::int32_t id) noexcept;

    /// The peer asked to pause (or resume) sending on `id`. Unknown ids are ignored.
    void set_paused(std::int32_t id, bool paused) noexcept;
    bool paused(std::int32_t id) const noexcept;
    /// Pause every stream's data (notifications still go).
    void set_all_paused(bool paused) noexcept { all_paused_ = paused; }
    bool all_paused() const noexcept { return all_paused_; }

    /// Queues a pause/resume notification for `id`. Errors: OutOfSystemResource (queue full),
    /// InvalidArgument for SocketClosed (use close_after_drain) or Null.
    Result<void> queue_notification(std::int32_t id, Notification n);
    /// Sends "socket closed" for `id` once its pending bytes are out, then forgets it. No new writes
    /// are accepted meanwhile. False when unknown.
    bool close_after_drain(std::int32_t id) noexcept;

    struct Filled {
        std::size_t size = 0;        ///< bytes of the sub-packet written into the packet buffer
        std::int32_t stream_id = 0;
        std::size_t consumed = 0;    ///< data bytes taken from the stream's pending write
        bool drained = false;        ///< the pending write is now fully consumed
        Notification notification = Notification::Null;  ///< != Null for a notification sub-packet
        bool closed = false;         ///< a "socket closed" went out; the stream is forgotten
    };
    /// Writes the next sub-packet into `packet` (its size is the endpoint's packet size, at least 10
    /// and at most kMaxPacketSize). Nothing to send (or all paused): nullopt.
    std::optional<Filled> fill(std::span<std::byte> packet);
    /// True when fill() would produce a sub-packet.
    bool has_work() const noexcept;

private:
    struct Entry {
        std::int32_t id = 0;
        std::span<const std::byte> pending;
        bool paused = false;
        bool closing = false;
    };
    struct Note {
        std::int32_t id = 0;
        Notification n = Notification::Null;
    };
    Entry* find(std::int32_t id) noexcept;
    const Entry* find(std::int32_t id) const noexcept;
    bool sendable(const Entry& e) const noexcept;

    std::size_t max_streams_;
    std::size_t max_notes_;
    std::vector<Entry> entries_;
    std::vector<Note> notes_;  // FIFO ring of capacity max_notes_
    std::size_t note_head_ = 0, note_count_ = 0;
    std::size_t cursor_ = 0;   // round-robin position in entries_
    bool all_paused_ = false;
};

}  // namespace rr::usb
