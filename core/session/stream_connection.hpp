// The basic stream protocol of one transport connection, sans-IO (wire.md §6; standards
// draft/basic_stream_protocol.md): CreateConnection with capability negotiation (message format v4,
// string table), node matching, heartbeats (ConnectionTest/ConnectionTestRet), the receive timeout,
// StreamCheckCapability, GetRemoteNodeID, the 512 KiB pre-session limit, and the v4 routing omission
// on a negotiated connection (wire.md §2.3).
//
// Bytes in: feed(bytes, now). Bytes out: take_output() (gathered: large payloads are not copied), or
// pending_output() / consume_output(n). Events out:
// poll_event(). Time: next_deadline() / on_timer(now). The object never reads a clock.
// Not thread-safe: one owner drives it (a strand in server/, the JS event loop in wasm-client/).
//
// Fatal errors (malformed framing, limits, receive timeout, failed negotiation) queue a Closed event
// and make is_closed() true; the host then drops the transport after flushing pending_output().
#pragma once

#include "core/session/event_queue.hpp"

#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "base/codec/gather_buffer.hpp"
#include "base/codec/limits.hpp"
#include "base/message/encoded_entry.hpp"
#include "base/message/message.hpp"
#include "base/message/message_reader.hpp"
#include "base/message/entry_vector_pool.hpp"
#include "base/message/message_stream_reader.hpp"

namespace rr {

/// Monotonic time as passed in by the host.
using MonoTime = std::chrono::steady_clock::time_point;

/// Capability words of CreateConnection (wire.md §2.1).
namespace capabilities {
inline constexpr std::uint32_t page_mask = 0xFFF00000u;
inline constexpr std::uint32_t message2_basic_page = 0x02000000u;
inline constexpr std::uint32_t message2_basic_enable = 0x1u;
inline constexpr std::uint32_t message2_basic_connectcombined = 0x2u;
inline constexpr std::uint32_t message4_basic_page = 0x04000000u;
inline constexpr std::uint32_t message4_basic_enable = 0x1u;
inline constexpr std::uint32_t message4_basic_connectcombined = 0x2u;
inline constexpr std::uint32_t message4_stringtable_page = 0x04100000u;
inline constexpr std::uint32_t message4_stringtable_enable = 0x1u;
inline constexpr std::uint32_t message4_stringtable_message_local = 0x2u;
inline constexpr std::uint32_t message4_stringtable_standard_table = 0x4u;
}  // namespace capabilities

enum class StreamRole : std::uint8_t { client, server };

struct StreamConfig {
    NodeID local_node_id;
    std::string local_node_name;
    /// Client only: the node asked for in the URL (zero / empty = any).
    NodeID target_node_id;
    std::string target_node_name;
    bool enable_message4 = true;
    /// A stock CORE server disables string tables (wire.md §2.1); clients ask for them.
    bool enable_string_table = false;
    /// Heartbeat period: send ConnectionTest when nothing was sent for this long (TCP client 10 s,
    /// server 12 s; wire.md §6.3).
    std::chrono::milliseconds heartbeat_period{10000};
    /// Close when nothing was received for this long (TCP 15 s).
    std::chrono::milliseconds receive_timeout{15000};
    /// Give up when CreateConnection is not answered (client) / not received (server) in time.
    std::chrono::milliseconds connect_timeout{10000};
    Limits limits;
};

/// Negotiation result.
struct StreamConnected {
    NodeID remote_node_id;
    std::string remote_node_name;
    bool message4 = false;
    bool string_table = false;
    bool connect_combined = false;  ///< the peer supports ConnectClientCombined
};

/// A message for the layer above (never transport-internal entries), its names resolved from string-table
/// codes. `frame` holds the exact bytes received, for zero-copy forwarding; they may hold string-table
/// codes (wire.md §2.6), which only a peer that negotiated the same tables may be sent.
struct StreamMessage {
    Message message;
    SharedBytes frame;
};

struct StreamClosed {
    RRError error;  ///< why; ConnectionError when the peer simply went away
};

using StreamEvent = std::variant<StreamConnected, StreamMessage, StreamClosed>;

class StreamConnection {
public:
    /// A client queues its CreateConnection immediately (see pending_output()).
    StreamConnection(StreamRole role, StreamConfig config, MonoTime now);

    /// Consumes all of `bytes`. A framing, decoding or protocol error is fatal: the connection closes
    /// (a Closed event is queued) and the error is returned.
    Result<void> feed(std::span<const std::byte> bytes, MonoTime now);

    /// Where the host may read the next bytes to feed() without their being copied again: the rest of
    /// a large message being received (MessageStreamReader::read_space); empty otherwise.
    std::span<std::byte> read_space() { return state_ == State::closed ? std::span<std::byte>{} : reader_.read_space(); }

    /// The host reports the transport was closed by the peer or failed.
    void on_transport_closed(RRError error);

    /// Encodes and queues `message` in the negotiated format. Errors: InvalidState before the
    /// connection is negotiated or after close; BufferLimitViolation when the encoded message is over
    /// the limit (512 KiB until set_session_established(), then max_message_size − 100 as CORE).
    Result<void> send(const Message& message, MonoTime now);
    /// The same for a message the caller gives up: its format fields are set in place (no copy of
    /// its elements when the format or routing flags differ from what it carries), and its entry
    /// vector goes back to entry_vectors() once encoded. On an error the message keeps its entries,
    /// so the caller can still answer for them (ServiceSession::reply).
    Result<void> send(Message&& message, MonoTime now);
    /// The same for a message of one entry that many messages carry unchanged: `header` (no entries)
    /// gets the entry's bytes in the negotiated format, encoded once (EncodedEntry::bytes), after its
    /// own. Errors: as send(); InvalidArgument when `header` has entries; the entry's encoding error.
    Result<void> send(Message&& header, const EncodedEntry& entry, MonoTime now);
    /// The same for a message of `header` (no entries) and `entry`, which stays the caller's: a reply
    /// is encoded where the service built it, not moved into a Message first. Errors: as send();
    /// InvalidArgument when `header` has entries.
    Result<void> send(Message&& header, const MessageEntry& entry, MonoTime now);
    /// Queues an already-encoded frame (used by forwarding when the bytes can be sent as they are).
    Result<void> send_frame(std::span<const std::byte> frame, MonoTime now);

    /// The client session on this connection exists with these endpoints: lifts the pre-session
    /// limit and enables v4 routing omission for messages matching them.
    void set_session_established(std::uint32_t local_endpoint, std::uint32_t remote_endpoint);

    /// The pending output as one contiguous range (large payloads that were spliced in are copied
    /// into it first: a host that writes gathered uses take_output(GatherBuffer&) instead).
    std::span<const std::byte> pending_output() const;
    void consume_output(std::size_t n);
    /// Moves all pending output into `out` (cleared first), large shared payloads as splices for one
    /// gathered write. Swaps buffers, so a writer can hold `out` while new messages are queued here.
    void take_output(GatherBuffer& out);
    /// The same as one contiguous buffer (splices copied in).
    void take_output(std::vector<std::byte>& out);
    std::size_t pending_output_size() const noexcept { return output_.size() - output_offset_; }

    std::optional<StreamEvent> poll_event();
    /// Every queued event at once, oldest first, into `batch` (its old events are destroyed first; see
    /// EventQueue::take_all): the host handles them in place, without moving each one out.
    void take_events(std::vector<StreamEvent>& batch);

    std::optional<MonoTime> next_deadline() const;
    /// Heartbeat, receive timeout, liveness probe. A call more than kStallTolerance after
    /// next_deadline() means this process did not run meanwhile (a stalled or starved host): that time
    /// is not the peer's silence, so once per silence (until something arrives) the receive timeout
    /// gives the peer the missed time back, and bytes already waiting in the socket are read before it
    /// can run out. The liveness probe (motion safety) gets no such credit.
    void on_timer(MonoTime now);
    static constexpr std::chrono::milliseconds kStallTolerance{1000};

    /// A short liveness probe of the peer (the gateway while a client holds a motion without a timeout
    /// of its own: docs/security.md "Motion safety"): from `now` on, a ConnectionTest is sent every
    /// `timeout` / 5 whatever else is sent (a peer answers each with ConnectionTestRet, wire.md §6.3),
    /// and the connection closes (ConnectionError "no answer to the liveness probe …") when nothing at
    /// all arrives for `timeout`, counted from `now` at the earliest. nullopt: off (the heartbeat and
    /// receive timeout of the config apply again). Ignored unless connected.
    void set_liveness_probe(std::optional<std::chrono::milliseconds> timeout, MonoTime now);

    bool is_connected() const noexcept { return state_ == State::connected; }
    bool is_closed() const noexcept { return state_ == State::closed; }
    const StreamConnected& negotiated() const noexcept { return negotiated_; }
    StreamRole role() const noexcept { return role_; }
    const StreamConfig& config() const noexcept { return config_; }
    /// DecodeContext for v4 messages without routing info; string-table codes are resolved and not
    /// kept (DecodeContext::keep_string_table_codes), so received entries can go to any connection.
    DecodeContext decode_context() const noexcept;
    std::uint16_t send_version() const noexcept { return negotiated_.message4 ? 4 : 2; }

    /// Entry vectors of this connection's messages for reuse: received messages are decoded into one
    /// taken from here; a session gives a received message's vector back once it has handled the
    /// entries, and takes one for each message it builds to send (no allocation per call).
    EntryVectorPool& entry_vectors() noexcept { return entry_vectors_; }

private:
    enum class State : std::uint8_t { negotiating, connected, closed };

    Result<void> handle_frame(SharedBytes frame, MonoTime now);
    Result<void> handle_transport_entry(const Message& m, const MessageEntry& e, MonoTime now);
    Result<void> handle_create_connection_request(const Message& m, const MessageEntry& e, MonoTime now);
    Result<void> handle_create_connection_reply(const Message& m, const MessageEntry& e);
    void queue_create_connection(MonoTime now);
    Result<void> queue(const Message& m, std::uint16_t version, MonoTime now, bool omit_routing);
    Result<void> queue_owned(Message& m, std::uint16_t version, MonoTime now, bool omit_routing);
    /// Whether the v4 routing omission applies to `m` (asked once per message; `omit` below).
    bool omit_routing_applies(const Message& m, std::uint16_t version, bool omit_routing) const;
    bool omit_routing_applies(const MessageHeader& h, MessageEntryType only_entry, std::uint16_t version,
                              bool omit_routing) const;
    /// Whether `m` must be re-labelled before encoding (format `version`, or routing omitted), and how.
    bool needs_relabel(const Message& m, std::uint16_t version, bool omit) const;
    void relabel(Message& m, std::uint16_t version, bool omit) const;
    void relabel(Message& m, std::size_t entry_count, std::uint16_t version, bool omit) const;
    Result<void> append_encoded(const Message& m, MonoTime now);
    /// The message of `header` (no entries) and one entry of `entry_type` given apart:
    /// `encode(version)` appends it to output_ once the header is labelled.
    template <class Encode>
    Result<void> send_with_entry(Message& header, MessageEntryType entry_type, MonoTime now, Encode&& encode);
    /// Undoes what was appended since `before` if the message is over the send limit.
    Result<void> check_appended(const GatherBuffer::Mark& before, MonoTime now);
    [[gnu::noinline]] Result<void> refuse_appended(const GatherBuffer::Mark& before);
    void close(RRError error);
    std::size_t send_limit() const noexcept;
    std::size_t receive_limit() const noexcept;

    StreamRole role_;
    StreamConfig config_;
    State state_ = State::negotiating;
    StreamConnected negotiated_;
    MessageStreamReader reader_;
    EntryVectorPool entry_vectors_;
    mutable GatherBuffer output_;  // mutable: pending_output() flattens it
    std::size_t output_offset_ = 0;
    EventQueue<StreamEvent> events_;
    MonoTime started_;
    MonoTime last_send_;
    MonoTime last_receive_;
    // The receive timeout counts from here: last_receive_, or later once on_timer credited a stall.
    MonoTime silent_since_;
    bool stall_credited_ = false;
    std::optional<std::chrono::milliseconds> probe_timeout_;  // set_liveness_probe
    MonoTime probe_started_{};
    MonoTime last_probe_{};
    bool session_established_ = false;
    std::uint32_t local_endpoint_ = 0;
    std::uint32_t remote_endpoint_ = 0;
};

}  // namespace rr
