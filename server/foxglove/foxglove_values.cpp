// Values to one Foxglove connection as messageData: wire values and events from the shared entries
// (one rendering for all clients), newest-wins for wires while the socket is behind, events and pipe
// packets dropped while it is congested, pipe packets and images converted on the shared strand.
#include "server/foxglove/foxglove_connection.hpp"

#include <boost/asio/post.hpp>

#include "server/gateway/json_push.hpp"

namespace rr::server::foxglove {

bool FoxgloveConnection::wire_congested() const {
    return socket_->queued() >= options_.wire_queue_threshold || socket_->queued_bytes() >= options_.wire_bytes_threshold;
}
bool FoxgloveConnection::push_congested() const {
    return socket_->queued() >= options_.push_queue_limit || socket_->queued_bytes() >= options_.push_bytes_limit;
}

// Under mutex_: one messageData frame of a wire value or event. Its payload is the value's one
// rendering, shared with every subscriber of both WebSocket front ends and the recorder and written
// without a copy, when it holds no null member; else the recorder's json message without them
// (record::json_message, which makes the same choice).
void FoxgloveConnection::send_entry(const Sub& s, const SharedEntryPtr& e) {
    const auto& t = *s.member->target;
    const bool wire = s.member->kind == LiveKind::wire;
    const std::string& body = e->rendered([&](const MessageEntry& entry) {
        return wire ? gateway::wire_push_text(*api_, entry, t) : gateway::event_push_text(*api_, entry, t);
    });
    std::string head = fg::message_data_head(s.id, receive_ns());
    if (body.find("null") == std::string::npos) {
        socket_->send_binary(std::move(head), std::shared_ptr<const std::string>(e, &body));
    } else {
        auto text = channel_message(*api_, *s.member, *e, 0);
        if (!text) return;
        socket_->send_binary(std::move(head) + *text);
    }
    ++stats_.messages_sent;
}

void FoxgloveConnection::on_wire(std::uint32_t sid, std::uint64_t serial, const SharedEntryPtr& e) {
    if (e->entry().entry_type == MessageEntryType::WireClosed) return upstream_closed(sid, serial, "wire closed");
    if (image_subscription(sid)) return convert(sid, serial, e);
    std::lock_guard lock(mutex_);
    Sub* s = live_sub(sid, serial);
    if (!s || !take_newer(*s, *e)) return;
    if (s->pending || wire_congested()) {
        if (s->pending) ++stats_.wire_coalesced;
        s->pending = e;  // newest wins
        arm_retry();
        return;
    }
    send_entry(*s, e);
}

// Under mutex_: whether a wire value is newer than the last one this subscription took. The
// wire's newest, handed to a joining subscription outside the fan-out tables' lock, can come after
// a newer value; it is dropped (counted coalesced), as the JSON subscriptions and recordings do.
bool FoxgloveConnection::take_newer(Sub& s, const gateway::SharedEntry& e) {
    if (e.arrival() <= s.newest_arrival) {
        ++stats_.wire_coalesced;
        return false;
    }
    s.newest_arrival = e.arrival();
    return true;
}

void FoxgloveConnection::on_event(std::uint32_t sid, std::uint64_t serial, const SharedEntryPtr& e) {
    std::lock_guard lock(mutex_);
    if (Sub* s = push_sub(sid, serial)) send_entry(*s, e);
}

FoxgloveConnection::Sub* FoxgloveConnection::live_sub(std::uint32_t sid, std::uint64_t serial) {
    auto it = subs_.find(sid);
    return closed_ || it == subs_.end() || it->second.serial != serial ? nullptr : &it->second;
}

FoxgloveConnection::Sub* FoxgloveConnection::push_sub(std::uint32_t sid, std::uint64_t serial) {
    Sub* s = live_sub(sid, serial);
    if (s && push_congested()) {
        ++stats_.dropped;
        return nullptr;
    }
    return s;
}

bool FoxgloveConnection::image_subscription(std::uint32_t sid) const {
    std::lock_guard lock(mutex_);
    auto it = subs_.find(sid);
    return it != subs_.end() && it->second.member->image.has_value();
}

// Under mutex_.
void FoxgloveConnection::arm_retry() {
    if (timer_armed_) return;
    timer_armed_ = true;
    timer_.expires_after(options_.wire_retry);
    std::weak_ptr<FoxgloveConnection> weak = weak_from_this();
    timer_.async_wait([weak](boost::system::error_code ec) {
        auto s = weak.lock();
        if (!s) return;
        std::lock_guard lock(s->mutex_);
        s->timer_armed_ = false;
        if (!ec && !s->closed_) s->flush_locked();
    });
}

void FoxgloveConnection::flush_locked() {
    bool waiting = false;
    for (auto& [id, s] : subs_) {
        if (!s.pending) continue;
        if (wire_congested()) {
            waiting = true;
            break;
        }
        auto e = std::move(s.pending);
        s.pending.reset();
        send_entry(s, e);
    }
    if (waiting) arm_retry();
}

// On the device's strand: a pipe packet as the recorder's pipe entry (its first element).
void FoxgloveConnection::on_pipe_packet(std::uint32_t sid, std::uint64_t serial, const MessageElement& packet) {
    MessageEntry entry;
    entry.entry_type = MessageEntryType::PipePacket;
    entry.elements.push_back(packet);
    convert(sid, serial, std::make_shared<const gateway::SharedEntry>(std::move(entry)));
}

// A pipe packet's or an image's message is made on the shared conversion strand, never on the
// device's (a camera frame is large), within this connection's budget; newer ones are dropped
// while it is full.
void FoxgloveConnection::convert(std::uint32_t sid, std::uint64_t serial, SharedEntryPtr entry) {
    std::shared_ptr<const LiveMember> member;
    {
        std::lock_guard lock(mutex_);
        Sub* s = push_sub(sid, serial);
        if (!s) return;
        member = s->member;
    }
    std::size_t bytes = 0;
    for (const auto& el : entry->entry().elements) bytes += gateway::payload_bytes(el);
    if (!pipe_budget_.try_acquire(bytes)) {
        std::lock_guard lock(mutex_);
        ++stats_.dropped;
        return;
    }
    const std::uint64_t received = receive_ns();
    boost::asio::post(convert_strand_, [self = shared_from_this(), sid, serial, entry = std::move(entry), member, bytes, received] {
        auto message = channel_message(*self->api_, *member, *entry, received);
        self->pipe_budget_.release(bytes);
        if (!message) return;  // a frame Foxglove has no form of: nothing on the image channel
        std::string frame = fg::message_data_head(sid, received) + *message;
        std::lock_guard lock(self->mutex_);
        Sub* s = self->live_sub(sid, serial);
        // An image wire's frames are ordered here, where they are sent (conversions finish in post order).
        if (!s || (member->kind == LiveKind::wire && !self->take_newer(*s, *entry))) return;
        self->socket_->send_binary(std::move(frame));
        ++self->stats_.messages_sent;
    });
}
}  // namespace rr::server::foxglove
