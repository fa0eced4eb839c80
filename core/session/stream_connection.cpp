#include "core/session/stream_connection.hpp"

#include <algorithm>
#include <string_view>

#include "base/message/message_writer.hpp"
#include "core/session/elements.hpp"

namespace rr {
namespace {

using namespace capabilities;

constexpr std::string_view kCreateConnection = "CreateConnection";

// Value StreamCheckCapability answers for a capability name (wire.md §6.2 table).
std::uint32_t stream_capability_value(std::string_view name, bool v4, bool string_table) {
    if (name == "com.robotraconteur.message.v_max") return v4 ? 4 : 2;
    if (name == "com.robotraconteur.v2" || name == "com.robotraconteur.v2.0") return 1;
    if (name == "com.robotraconteur.message.v4" || name == "com.robotraconteur.message.v4.0") return v4 ? 1 : 0;
    if (name == "com.robotraconteur.stringtable") return string_table ? 4 : 0;
    if (name == "com.robotraconteur.stringtable.v4" || name == "com.robotraconteur.stringtable.v4.0")
        return string_table ? 1 : 0;
    return 0;
}

// Entries the stream itself answers (never handed to the layer above).
bool is_stream_entry(MessageEntryType type) {
    return is_transport_internal(type) || type == MessageEntryType::ConnectionTest ||
           type == MessageEntryType::ConnectionTestRet;
}

Message single_entry_message(MessageEntry entry) {
    Message m;
    m.version = 2;
    m.entries.push_back(std::move(entry));
    return m;
}

}  // namespace

StreamConnection::StreamConnection(StreamRole role, StreamConfig config, MonoTime now)
    : role_(role), config_(std::move(config)), reader_(config_.limits), started_(now), last_send_(now),
      last_receive_(now), silent_since_(now) {
    reader_.set_max_message_size(std::min(config_.limits.max_message_size, config_.limits.max_pre_session_message_size));
    if (role_ == StreamRole::client) queue_create_connection(now);
}

void StreamConnection::queue_create_connection(MonoTime now) {
    MessageEntry e;
    e.entry_type = MessageEntryType::StreamOp;
    e.member_name = std::string(kCreateConnection);
    std::vector<std::uint32_t> caps{message2_basic_page | message2_basic_enable | message2_basic_connectcombined};
    if (config_.enable_message4) {
        caps.push_back(message4_basic_page | message4_basic_enable | message4_basic_connectcombined);
        if (config_.enable_string_table)
            caps.push_back(message4_stringtable_page | message4_stringtable_enable |
                           message4_stringtable_message_local | message4_stringtable_standard_table);
    }
    e.elements.push_back(make_array_element("capabilities", std::span<const std::uint32_t>(caps)));
    Message m = single_entry_message(std::move(e));
    m.header.sender_node_id = config_.local_node_id;
    m.header.sender_node_name = config_.local_node_name;
    m.header.receiver_node_id = config_.target_node_id;
    m.header.receiver_node_name = config_.target_node_name;
    (void)queue(m, 2, now, false);
}

Result<void> StreamConnection::feed(std::span<const std::byte> bytes, MonoTime now) {
    if (state_ == State::closed) return fail(MessageErrorType::ConnectionError, "connection closed");
    if (bytes.empty()) return {};
    last_receive_ = now;
    silent_since_ = now;
    stall_credited_ = false;
    if (auto r = reader_.feed(bytes); !r) {
        close(r.error());
        return r.take_error();
    }
    while (auto frame = reader_.take_frame()) {
        if (auto r = handle_frame(std::move(*frame), now); !r) {
            close(r.error());
            return r.take_error();
        }
        if (state_ == State::closed) break;
    }
    return {};
}

Result<void> StreamConnection::handle_frame(SharedBytes frame, MonoTime now) {
    // Decoded straight into the event it becomes for the layer above: the message is not moved again.
    // Nothing else is queued until the slot is either kept or popped.
    auto& slot = std::get<StreamMessage>(events_.emplace_back(std::in_place_type<StreamMessage>));
    Message& m = slot.message;
    m.entries = entry_vectors_.take();
    const DecodeContext ctx = decode_context();
    auto decoded = decode_message_into(m, frame, config_.limits, &ctx);
    const bool keep = decoded && !m.entries.empty() && !is_stream_entry(m.entries.front().entry_type);
    if (keep && state_ == State::connected) {
        slot.frame = std::move(frame);
        return {};
    }
    Message message = std::move(m);  // a transport entry queues events of its own: out of the slot first
    events_.pop_back();
    Result<void> handled = std::move(decoded);
    if (!handled || message.entries.empty()) {
        // a decoding error, or an empty message: legal, with nothing to do
    } else if (keep) {
        handled = fail(MessageErrorType::ProtocolError, "message received before CreateConnection completed");
    } else if (message.entries.size() != 1) {
        handled = fail(MessageErrorType::ProtocolError, "transport operation must be alone in its message");
    } else {
        handled = handle_transport_entry(message, message.entries.front(), now);
    }
    entry_vectors_.give(std::move(message.entries));
    return handled;
}

Result<void> StreamConnection::handle_transport_entry(const Message& m, const MessageEntry& e, MonoTime now) {
    switch (e.entry_type) {
        case MessageEntryType::ConnectionTest: {
            if (state_ != State::connected) return {};
            MessageEntry r;
            r.entry_type = MessageEntryType::ConnectionTestRet;
            r.service_path = e.service_path;
            r.member_name = e.member_name;
            r.request_id = e.request_id;
            Message reply = single_entry_message(std::move(r));
            reply.header.sender_node_id = config_.local_node_id;
            reply.header.sender_node_name = config_.local_node_name;
            reply.header.receiver_node_id = m.header.sender_node_id;
            reply.header.receiver_node_name = m.header.sender_node_name;
            reply.header.sender_endpoint = m.header.receiver_endpoint;
            reply.header.receiver_endpoint = m.header.sender_endpoint;
            // CORE always answers a heartbeat in v4 without routing or endpoint info (wire.md §6.3).
            if (send_version() == 4) reply.header.v4_flags = static_cast<std::uint8_t>(
                default_v4_flags(reply) & ~(message_flags::routing_info | message_flags::endpoint_info));
            return queue(reply, send_version(), now, false);
        }
        case MessageEntryType::ConnectionTestRet: return {};
        case MessageEntryType::StreamOp:
            if (e.member_name == kCreateConnection) return handle_create_connection_request(m, e, now);
            if (e.member_name == "GetRemoteNodeID") {
                MessageEntry r;
                r.entry_type = MessageEntryType::StreamOpRet;
                r.member_name = e.member_name;
                Message reply = single_entry_message(std::move(r));
                reply.header.sender_node_id = config_.local_node_id;
                reply.header.sender_node_name = config_.local_node_name;
                reply.header.receiver_node_id = m.header.sender_node_id;
                return queue(reply, 2, now, false);
            } else {
                // STARTTLS and unknown operations: TLS is not offered on this transport.
                MessageEntry r;
                r.entry_type = MessageEntryType::StreamOpRet;
                r.member_name = e.member_name;
                RRError err = e.member_name == "STARTTLS"
                                  ? make_error(MessageErrorType::ConnectionError, "Server certificate not loaded")
                                  : make_error(MessageErrorType::ProtocolError, "Invalid Stream Operation");
                set_entry_error(r, err);
                Message reply = single_entry_message(std::move(r));
                reply.header.sender_node_id = config_.local_node_id;
                reply.header.sender_node_name = config_.local_node_name;
                return queue(reply, 2, now, false);
            }
        case MessageEntryType::StreamOpRet:
            if (role_ == StreamRole::client && state_ == State::negotiating && e.member_name == kCreateConnection)
                return handle_create_connection_reply(m, e);
            return {};
        case MessageEntryType::StreamCheckCapability: {
            MessageEntry r;
            r.entry_type = MessageEntryType::StreamCheckCapabilityRet;
            r.member_name = e.member_name;
            std::uint32_t v = stream_capability_value(e.member_name, config_.enable_message4, config_.enable_string_table);
            r.elements.push_back(make_scalar_element("return", v));
            Message reply = single_entry_message(std::move(r));
            reply.header.sender_node_id = config_.local_node_id;
            reply.header.receiver_node_id = m.header.sender_node_id;
            return queue(reply, 2, now, false);
        }
        default: return {};  // other transport-internal codes carry nothing for us
    }
}

Result<void> StreamConnection::handle_create_connection_request(const Message& m, const MessageEntry& e,
                                                                 MonoTime now) {
    auto reply_with = [&](MessageEntry r) {
        Message reply = single_entry_message(std::move(r));
        reply.header.sender_node_id = config_.local_node_id;
        reply.header.sender_node_name = config_.local_node_name;
        reply.header.receiver_node_id = m.header.sender_node_id;
        reply.header.receiver_node_name = m.header.sender_node_name;
        return queue(reply, 2, now, false);
    };
    MessageEntry r;
    r.entry_type = MessageEntryType::StreamOpRet;
    r.member_name = std::string(kCreateConnection);

    if (role_ != StreamRole::server || state_ != State::negotiating) {
        set_entry_error(r, make_error(MessageErrorType::ProtocolError, "Invalid Stream Operation"));
        return reply_with(std::move(r));
    }
    const auto& h = m.header;
    const bool name_ok = h.receiver_node_name.empty() || h.receiver_node_name == config_.local_node_name;
    const bool id_ok = h.receiver_node_id.is_any() || h.receiver_node_id == config_.local_node_id;
    if (!name_ok || !id_ok) {
        set_entry_error(r, make_error(MessageErrorType::NodeNotFound, "Node not found"));
        return reply_with(std::move(r));
    }

    bool m2 = false, m2_combined = false, m4 = false, m4_combined = false, st = false;
    std::vector<std::uint32_t> reply_caps;
    const MessageElement* caps = e.find("capabilities");
    if (caps) {
        if (caps->type != DataTypes::uint32_t) {
            set_entry_error(r, make_error(MessageErrorType::ProtocolError, "Invalid Stream Operation"));
            return reply_with(std::move(r));
        }
        std::uint32_t m2_flags = 0, m4_flags = 0, st_flags = 0;
        bool asked_m4 = false, asked_st = false;
        auto words = read_array<std::uint32_t>(*caps);
        for (std::uint32_t w : words) {
            const std::uint32_t page = w & page_mask, flags = w & ~page_mask;
            if (page == message2_basic_page) {
                m2 = (flags & message2_basic_enable) != 0;
                m2_flags = flags & (message2_basic_enable | message2_basic_connectcombined);
            } else if (page == message4_basic_page) {
                asked_m4 = (flags & message4_basic_enable) != 0;
                m4_flags = flags & (message4_basic_enable | message4_basic_connectcombined);
            } else if (page == message4_stringtable_page) {
                asked_st = (flags & message4_stringtable_enable) != 0;
                st_flags = flags & (message4_stringtable_enable | message4_stringtable_message_local |
                                    message4_stringtable_standard_table);
            }
        }
        if (!m2) {
            set_entry_error(r, make_error(MessageErrorType::ProtocolError, "Invalid Stream Operation"));
            return reply_with(std::move(r));
        }
        m2_combined = (m2_flags & message2_basic_connectcombined) != 0;
        reply_caps.push_back(message2_basic_page | m2_flags);
        if (asked_m4 && config_.enable_message4) {
            m4 = true;
            m4_combined = (m4_flags & message4_basic_connectcombined) != 0;
            reply_caps.push_back(message4_basic_page | m4_flags);
            if (asked_st && config_.enable_string_table) {
                st = true;
                reply_caps.push_back(message4_stringtable_page | st_flags);
            }
        }
        r.elements.push_back(make_array_element("capabilities", std::span<const std::uint32_t>(reply_caps)));
    }
    if (auto q = reply_with(std::move(r)); !q) return q;

    negotiated_.remote_node_id = h.sender_node_id;
    negotiated_.remote_node_name = h.sender_node_name;
    negotiated_.message4 = m4;
    negotiated_.string_table = st;
    negotiated_.connect_combined = m4 ? m4_combined : m2_combined;
    state_ = State::connected;
    events_.push_back(negotiated_);
    return {};
}

Result<void> StreamConnection::handle_create_connection_reply(const Message& m, const MessageEntry& e) {
    if (e.error != MessageErrorType::None) {
        RRError err = *entry_error(e);
        return fail(std::move(err));
    }
    const auto& h = m.header;
    if (!config_.target_node_name.empty() && h.sender_node_name != config_.target_node_name)
        return fail(MessageErrorType::NodeNotFound, "connected node has NodeName \"" + h.sender_node_name +
                                                        "\", expected \"" + config_.target_node_name + "\"");
    if (!config_.target_node_id.is_any() && h.sender_node_id != config_.target_node_id)
        return fail(MessageErrorType::NodeNotFound, "connected node has NodeID " + h.sender_node_id.to_string() +
                                                        ", expected " + config_.target_node_id.to_string());
    bool m4 = false, st = false, combined = false;
    if (const MessageElement* caps = e.find("capabilities")) {
        if (caps->type != DataTypes::uint32_t)
            return fail(MessageErrorType::ProtocolError, "capabilities element is not uint32[]");
        for (std::uint32_t w : read_array<std::uint32_t>(*caps)) {
            const std::uint32_t page = w & page_mask, flags = w & ~page_mask;
            if (page == message2_basic_page) {
                if (flags & ~(message2_basic_enable | message2_basic_connectcombined))
                    return fail(MessageErrorType::ProtocolError, "unknown message2 capability flags");
                if (!m4) combined = (flags & message2_basic_connectcombined) != 0;
            } else if (page == message4_basic_page) {
                if (flags & ~(message4_basic_enable | message4_basic_connectcombined))
                    return fail(MessageErrorType::ProtocolError, "unknown message4 capability flags");
                m4 = config_.enable_message4 && (flags & message4_basic_enable) != 0;
                if (m4) combined = (flags & message4_basic_connectcombined) != 0;
            } else if (page == message4_stringtable_page) {
                if (flags & ~(message4_stringtable_enable | message4_stringtable_message_local |
                              message4_stringtable_standard_table))
                    return fail(MessageErrorType::ProtocolError, "unknown string table capability flags");
                st = (flags & message4_stringtable_enable) != 0;
            } else {
                return fail(MessageErrorType::ProtocolError, "unknown capability page in CreateConnection reply");
            }
        }
        if (st && !m4) return fail(MessageErrorType::ProtocolError, "string table offered without message4");
    }
    negotiated_.remote_node_id = h.sender_node_id;
    negotiated_.remote_node_name = h.sender_node_name;
    negotiated_.message4 = m4;
    negotiated_.string_table = st;
    negotiated_.connect_combined = combined;
    state_ = State::connected;
    events_.push_back(negotiated_);
    return {};
}

void StreamConnection::on_transport_closed(RRError error) { close(std::move(error)); }

Result<void> StreamConnection::send(const Message& message, MonoTime now) {
    if (state_ != State::connected)
        return fail(MessageErrorType::InvalidState, state_ == State::closed ? "connection closed" : "connection not ready");
    return queue(message, send_version(), now, true);
}

Result<void> StreamConnection::send_frame(std::span<const std::byte> frame, MonoTime now) {
    if (state_ != State::connected)
        return fail(MessageErrorType::InvalidState, state_ == State::closed ? "connection closed" : "connection not ready");
    if (frame.size() > send_limit())
        return fail(MessageErrorType::BufferLimitViolation, "message larger than the connection's limit");
    output_.append(frame);
    last_send_ = now;
    return {};
}

Result<void> StreamConnection::send(Message&& message, MonoTime now) {
    if (state_ != State::connected)
        return fail(MessageErrorType::InvalidState, state_ == State::closed ? "connection closed" : "connection not ready");
    auto queued = queue_owned(message, send_version(), now, true);
    if (queued) entry_vectors_.give(std::move(message.entries));
    return queued;
}

template <class Encode>
Result<void> StreamConnection::send_with_entry(Message& header, MessageEntryType entry_type, MonoTime now,
                                               Encode&& encode) {
    if (state_ != State::connected)
        return fail(MessageErrorType::InvalidState, state_ == State::closed ? "connection closed" : "connection not ready");
    if (!header.entries.empty())
        return fail(MessageErrorType::InvalidArgument, "a message with an entry given apart has no other entries");
    const std::uint16_t version = send_version();
    const bool omit = omit_routing_applies(header.header, entry_type, version, true);
    if (needs_relabel(header, version, omit)) relabel(header, 1, version, omit);
    const auto before = output_.mark();
    if (auto ok = encode(version); !ok) {
        output_.rollback(before);
        return ok;
    }
    return check_appended(before, now);
}

Result<void> StreamConnection::send(Message&& header, const EncodedEntry& entry, MonoTime now) {
    return send_with_entry(header, entry.entry().entry_type, now, [&](std::uint16_t version) -> Result<void> {
        // A large entry is spliced into the gathered write, kept alive by its owner; a small one copied.
        auto shared = entry.shared_bytes(version, GatherBuffer::kSpliceMinBytes);
        if (!shared) return shared.take_error();
        return encode_message(header, *shared, output_);
    });
}

Result<void> StreamConnection::send(Message&& header, const MessageEntry& entry, MonoTime now) {
    return send_with_entry(header, entry.entry_type, now, [&](std::uint16_t) {
        return encode_message(header, std::span<const MessageEntry>(&entry, 1), output_);
    });
}

// v4 on a negotiated connection omits ROUTING_INFO / ENDPOINT_INFO when the header names exactly this
// session's nodes and endpoints (CORE, wire.md §2.3), except for one entry below 500.
bool StreamConnection::needs_relabel(const Message& m, std::uint16_t version, bool omit) const {
    return m.version != version || (omit && !m.header.v4_flags);
}

bool StreamConnection::omit_routing_applies(const Message& m, std::uint16_t version, bool omit_routing) const {
    return m.entries.size() == 1 && omit_routing_applies(m.header, m.entries.front().entry_type, version, omit_routing);
}

bool StreamConnection::omit_routing_applies(const MessageHeader& h, MessageEntryType only_entry, std::uint16_t version,
                                            bool omit_routing) const {
    return omit_routing && version == 4 && session_established_ && static_cast<std::uint16_t>(only_entry) >= 500 &&
           h.sender_endpoint == local_endpoint_ && h.receiver_endpoint == remote_endpoint_ &&
           h.sender_node_name.empty() && h.receiver_node_name.empty() && h.sender_node_id == config_.local_node_id &&
           h.receiver_node_id == negotiated_.remote_node_id;
}

void StreamConnection::relabel(Message& m, std::uint16_t version, bool omit) const {
    relabel(m, m.entries.size(), version, omit);
}

void StreamConnection::relabel(Message& m, std::size_t entry_count, std::uint16_t version, bool omit) const {
    m.version = version;
    if (omit && !m.header.v4_flags)
        m.header.v4_flags = static_cast<std::uint8_t>(default_v4_flags(m.header, entry_count) &
                                                      ~(message_flags::routing_info | message_flags::endpoint_info));
}

Result<void> StreamConnection::queue(const Message& m, std::uint16_t version, MonoTime now, bool omit_routing) {
    const bool omit = omit_routing_applies(m, version, omit_routing);
    if (!needs_relabel(m, version, omit)) return append_encoded(m, now);
    Message copy = m;
    relabel(copy, version, omit);
    return append_encoded(copy, now);
}

Result<void> StreamConnection::queue_owned(Message& m, std::uint16_t version, MonoTime now, bool omit_routing) {
    const bool omit = omit_routing_applies(m, version, omit_routing);
    if (needs_relabel(m, version, omit)) relabel(m, version, omit);
    return append_encoded(m, now);
}

Result<void> StreamConnection::append_encoded(const Message& m, MonoTime now) {
    const auto before = output_.mark();
    Result<void> r = encode_message(m, output_);
    if (!r) {
        output_.rollback(before);
        return r;
    }
    return check_appended(before, now);
}

Result<void> StreamConnection::check_appended(const GatherBuffer::Mark& before, MonoTime now) {
    if (output_.size() - before.size() > send_limit()) [[unlikely]]
        return refuse_appended(before);
    last_send_ = now;
    return {};
}

Result<void> StreamConnection::refuse_appended(const GatherBuffer::Mark& before) {
    output_.rollback(before);
    return fail(MessageErrorType::BufferLimitViolation, "message larger than the connection's limit");
}

void StreamConnection::set_session_established(std::uint32_t local_endpoint, std::uint32_t remote_endpoint) {
    session_established_ = true;
    local_endpoint_ = local_endpoint;
    remote_endpoint_ = remote_endpoint;
    reader_.set_max_message_size(config_.limits.max_message_size);
}

std::size_t StreamConnection::send_limit() const noexcept {
    if (!session_established_) return config_.limits.max_pre_session_message_size;
    // CORE refuses to send messages within 100 bytes of the limit (wire.md §13).
    return config_.limits.max_message_size > 100 ? config_.limits.max_message_size - 100 : config_.limits.max_message_size;
}

std::size_t StreamConnection::receive_limit() const noexcept {
    return session_established_ ? config_.limits.max_message_size : config_.limits.max_pre_session_message_size;
}

std::span<const std::byte> StreamConnection::pending_output() const {
    output_.flatten();
    return std::span<const std::byte>(output_.owned()).subspan(output_offset_);
}

void StreamConnection::consume_output(std::size_t n) {
    output_.flatten();
    auto& owned = output_.owned();
    output_offset_ += std::min(n, owned.size() - output_offset_);
    if (output_offset_ == owned.size()) {
        output_.clear();
        output_offset_ = 0;
    } else if (output_offset_ > (1u << 20) && output_offset_ * 2 > owned.size()) {
        owned.erase(owned.begin(), owned.begin() + static_cast<std::ptrdiff_t>(output_offset_));
        output_offset_ = 0;
    }
}

void StreamConnection::take_output(GatherBuffer& out) {
    out.clear();
    if (output_offset_ != 0) {
        // Partly consumed through consume_output() (a host that writes contiguously): drop that part.
        output_.flatten();
        auto& owned = output_.owned();
        owned.erase(owned.begin(), owned.begin() + static_cast<std::ptrdiff_t>(output_offset_));
        output_offset_ = 0;
    }
    out.swap(output_);
}

void StreamConnection::take_output(std::vector<std::byte>& out) {
    output_.flatten();
    out.clear();
    auto& owned = output_.owned();
    if (output_offset_ == 0) {
        std::swap(out, owned);
    } else {
        out.assign(owned.begin() + static_cast<std::ptrdiff_t>(output_offset_), owned.end());
        owned.clear();
        output_offset_ = 0;
    }
}

std::optional<StreamEvent> StreamConnection::poll_event() {
    return events_.pop();
}

void StreamConnection::take_events(std::vector<StreamEvent>& batch) { events_.take_all(batch); }

std::optional<MonoTime> StreamConnection::next_deadline() const {
    switch (state_) {
        case State::closed: return std::nullopt;
        case State::negotiating: return started_ + config_.connect_timeout;
        case State::connected: {
            MonoTime next = std::min(last_send_ + config_.heartbeat_period, silent_since_ + config_.receive_timeout);
            if (probe_timeout_)
                next = std::min({next, last_probe_ + *probe_timeout_ / 5,
                                 std::max(last_receive_, probe_started_) + *probe_timeout_});
            return next;
        }
    }
    return std::nullopt;
}

void StreamConnection::on_timer(MonoTime now) {
    if (state_ == State::negotiating) {
        if (now >= started_ + config_.connect_timeout)
            close(make_error(MessageErrorType::ConnectionError, "CreateConnection timed out"));
        return;
    }
    if (state_ != State::connected) return;
    if (!stall_credited_) {
        if (auto due = next_deadline(); due && now > *due + kStallTolerance) {
            silent_since_ = std::min(now, silent_since_ + (now - *due));
            stall_credited_ = true;
        }
    }
    if (now - silent_since_ > config_.receive_timeout) {
        close(make_error(MessageErrorType::ConnectionError, "receive timeout: peer silent"));
        return;
    }
    if (probe_timeout_) {
        if (now - std::max(last_receive_, probe_started_) >= *probe_timeout_) {
            close(make_error(MessageErrorType::ConnectionError,
                             "no answer to the liveness probe within " + std::to_string(probe_timeout_->count()) + " ms"));
            return;
        }
        if (now - last_probe_ >= *probe_timeout_ / 5) {
            last_probe_ = now;
            MessageEntry e;
            e.entry_type = MessageEntryType::ConnectionTest;
            Message m = single_entry_message(std::move(e));
            m.header.sender_node_id = config_.local_node_id;
            (void)queue(m, send_version(), now, false);
            return;
        }
    }
    if (now - last_send_ >= config_.heartbeat_period) {
        MessageEntry e;
        e.entry_type = MessageEntryType::ConnectionTest;
        Message m = single_entry_message(std::move(e));
        m.header.sender_node_id = config_.local_node_id;
        (void)queue(m, send_version(), now, false);
    }
}

void StreamConnection::set_liveness_probe(std::optional<std::chrono::milliseconds> timeout, MonoTime now) {
    if (timeout && (state_ != State::connected || timeout->count() <= 0)) return;
    if (timeout && probe_timeout_) {
        probe_timeout_ = timeout;  // already probing: the new bound from the same start
        return;
    }
    probe_timeout_ = timeout;
    probe_started_ = now;
    last_probe_ = now - (timeout ? *timeout : std::chrono::milliseconds(0));  // the first probe at once
}

DecodeContext StreamConnection::decode_context() const noexcept {
    DecodeContext c;
    c.local_node_id = config_.local_node_id;
    c.remote_node_id = negotiated_.remote_node_id;
    c.local_endpoint = local_endpoint_;
    c.remote_endpoint = remote_endpoint_;
    // Codes are the sending connection's business: entries handed up hold plain strings (wire.md §2.6).
    c.keep_string_table_codes = false;
    return c;
}

void StreamConnection::close(RRError error) {
    if (state_ == State::closed) return;
    state_ = State::closed;
    events_.push_back(StreamClosed{std::move(error)});
}

}  // namespace rr
