#include "base/usb/usb_scheduler.hpp"

#include <algorithm>

namespace rr::usb {

SubpacketScheduler::SubpacketScheduler(std::size_t max_streams, std::size_t max_notifications)
    : max_streams_(max_streams), max_notes_(std::max<std::size_t>(1, max_notifications)) {
    entries_.reserve(max_streams_);
    notes_.resize(max_notes_);
}

SubpacketScheduler::Entry* SubpacketScheduler::find(std::int32_t id) noexcept {
    for (auto& e : entries_)
        if (e.id == id) return &e;
    return nullptr;
}

const SubpacketScheduler::Entry* SubpacketScheduler::find(std::int32_t id) const noexcept {
    for (const auto& e : entries_)
        if (e.id == id) return &e;
    return nullptr;
}

Result<void> SubpacketScheduler::add(std::int32_t id) {
    if (id < 0) return fail(MessageErrorType::InvalidArgument, "USB stream id " + std::to_string(id) + " is negative");
    if (find(id)) return fail(MessageErrorType::InvalidArgument, "USB stream id " + std::to_string(id) + " is in use");
    if (entries_.size() >= max_streams_)
        return fail(MessageErrorType::OutOfSystemResource,
                    "USB link has its maximum of " + std::to_string(max_streams_) + " streams open");
    entries_.push_back(Entry{id, {}, false, false});
    return {};
}

bool SubpacketScheduler::remove(std::int32_t id) {
    auto it = std::find_if(entries_.begin(), entries_.end(), [id](const Entry& e) { return e.id == id; });
    if (it == entries_.end()) return false;
    const auto index = static_cast<std::size_t>(it - entries_.begin());
    entries_.erase(it);
    if (cursor_ > index) --cursor_;
    if (cursor_ >= entries_.size()) cursor_ = 0;
    // Drop its queued notifications, keeping the others in order.
    std::size_t kept = 0;
    for (std::size_t i = 0; i < note_count_; ++i) {
        const Note n = notes_[(note_head_ + i) % max_notes_];
        if (n.id != id) notes_[(note_head_ + kept++) % max_notes_] = n;
    }
    note_count_ = kept;
    return true;
}

void SubpacketScheduler::clear() {
    entries_.clear();
    note_head_ = note_count_ = 0;
    cursor_ = 0;
    all_paused_ = false;
}

bool SubpacketScheduler::contains(std::int32_t id) const noexcept { return find(id) != nullptr; }

Result<void> SubpacketScheduler::set_pending(std::int32_t id, std::span<const std::byte> bytes) {
    auto* e = find(id);
    if (!e || e->closing)
        return fail(MessageErrorType::InvalidArgument, "USB stream " + std::to_string(id) + " is not open");
    if (!e->pending.empty())
        return fail(MessageErrorType::InvalidOperation, "USB stream " + std::to_string(id) + " already has a write pending");
    e->pending = bytes;
    return {};
}

std::size_t SubpacketScheduler::pending(std::int32_t id) const noexcept {
    const auto* e = find(id);
    return e ? e->pending.size() : 0;
}

std::size_t SubpacketScheduler::drop_pending(std::int32_t id) noexcept {
    auto* e = find(id);
    if (!e) return 0;
    const auto n = e->pending.size();
    e->pending = {};
    return n;
}

void SubpacketScheduler::set_paused(std::int32_t id, bool paused) noexcept {
    if (auto* e = find(id)) e->paused = paused;
}

bool SubpacketScheduler::paused(std::int32_t id) const noexcept {
    const auto* e = find(id);
    return e && e->paused;
}

Result<void> SubpacketScheduler::queue_notification(std::int32_t id, Notification n) {
    if (n != Notification::PauseRequest && n != Notification::ResumeRequest)
        return fail(MessageErrorType::InvalidArgument, "only pause and resume notifications are queued");
    if (note_count_ >= max_notes_)
        return fail(MessageErrorType::OutOfSystemResource, "USB notification queue is full");
    notes_[(note_head_ + note_count_) % max_notes_] = Note{id, n};
    ++note_count_;
    return {};
}

bool SubpacketScheduler::close_after_drain(std::int32_t id) noexcept {
    auto* e = find(id);
    if (!e) return false;
    e->closing = true;
    return true;
}

bool SubpacketScheduler::sendable(const Entry& e) const noexcept {
    return !e.pending.empty() && !e.paused && !all_paused_;
}

bool SubpacketScheduler::has_work() const noexcept {
    if (note_count_ > 0) return true;
    for (const auto& e : entries_)
        if ((e.closing && e.pending.empty()) || sendable(e)) return true;
    return false;
}

std::optional<SubpacketScheduler::Filled> SubpacketScheduler::fill(std::span<std::byte> packet) {
    if (packet.size() < kNotificationSize) return std::nullopt;
    if (packet.size() > kMaxPacketSize) packet = packet.first(kMaxPacketSize);
    if (note_count_ > 0) {
        const Note n = notes_[note_head_];
        note_head_ = (note_head_ + 1) % max_notes_;
        --note_count_;
        Filled f;
        f.size = write_notification(packet, n.id, n.n);
        f.stream_id = n.id;
        f.notification = n.n;
        return f;
    }
    const std::size_t count = entries_.size();
    for (std::size_t k = 0; k < count; ++k) {
        const std::size_t idx = (cursor_ + k) % count;
        Entry& e = entries_[idx];
        if (e.closing && e.pending.empty()) {
            Filled f;
            f.size = write_notification(packet, e.id, Notification::SocketClosed);
            f.stream_id = e.id;
            f.notification = Notification::SocketClosed;
            f.closed = true;
            cursor_ = idx;
            remove(e.id);
            return f;
        }
        if (!sendable(e)) continue;
        const std::size_t chunk = std::min(e.pending.size(), packet.size() - kSubpacketHeaderSize);
        Filled f;
        f.size = write_data_subpacket(packet, e.id, e.pending.first(chunk));
        f.stream_id = e.id;
        f.consumed = chunk;
        e.pending = e.pending.subspan(chunk);
        f.drained = e.pending.empty();
        cursor_ = (idx + 1) % count;
        return f;
    }
    return std::nullopt;
}

}  // namespace rr::usb
