// Subscriptions of one Foxglove connection: each opens the gateway's shared upstream subscription of
// its wire or event (DeviceMirror::subscribe) or the shared pipe endpoint, and ends it on unsubscribe,
// unadvertise or close; a device that refuses or ends it gets the client a status.
#include "server/foxglove/foxglove_connection.hpp"

#include <boost/asio/post.hpp>

#include "server/gateway/mirror_service.hpp"
#include "server/gateway/session_endpoints.hpp"

namespace rr::server::foxglove {

void FoxgloveConnection::on(fg::event::Subscribed e) {
    auto server = server_.lock();
    auto member = server ? server->channel_member(e.channel_id) : nullptr;
    std::lock_guard lock(mutex_);
    if (closed_) return;
    if (!member) {
        session_.end_subscription(e.subscription_id);
        return status("subscribe refused: channel " + std::to_string(e.channel_id) + " is gone");
    }
    if (auto denied = api_->check_access(address_of(*member), gateway::auth::Operation::read)) {
        session_.end_subscription(e.subscription_id);
        return status("subscribe refused: " + member->topic + ": " + error_text(*denied));
    }
    Sub s;
    s.id = e.subscription_id;
    s.serial = ++next_serial_;
    s.member = member;
    subs_[e.subscription_id] = s;
    start_upstream(e.subscription_id, s.serial, member);
}

// Under mutex_: the upstream subscription is opened off this lock (the device's `done` may run
// inside subscribe(), and it takes the lock).
void FoxgloveConnection::start_upstream(std::uint32_t sid, std::uint64_t serial, const std::shared_ptr<const LiveMember>& member) {
    boost::asio::post(timer_.get_executor(),
                      [self = shared_from_this(), sid, serial, member] { self->open_upstream(sid, serial, member); });
}

void FoxgloveConnection::open_upstream(std::uint32_t sid, std::uint64_t serial, const std::shared_ptr<const LiveMember>& member) {
    std::weak_ptr<FoxgloveConnection> weak = weak_from_this();
    const auto& t = *member->target;
    if (member->kind == LiveKind::pipe) {
        gateway::GatewayPipeHandlers h;
        h.on_packet = [weak, sid, serial](const MessageElement& packet, std::uint32_t) {
            if (auto s = weak.lock()) s->on_pipe_packet(sid, serial, packet);
        };
        h.on_closed = [weak, sid, serial](const RRError& reason) {
            if (auto s = weak.lock()) s->upstream_closed(sid, serial, reason.message);
        };
        open_pipe(member, std::move(h),
                  [sid, serial, member](FoxgloveConnection& c, std::optional<std::uint64_t> id, const std::string& error) {
                      c.upstream_opened(sid, serial, member, id, error);
                  });
        return;
    }
    const bool is_wire = member->kind == LiveKind::wire;
    std::uint64_t upstream = t.device->subscribe(
        t.path, t.member->name, is_wire,
        [weak, sid, serial, is_wire](const SharedEntryPtr& e) {
            if (auto s = weak.lock()) is_wire ? s->on_wire(sid, serial, e) : s->on_event(sid, serial, e);
        },
        [weak, sid, serial, member](Result<void> r) {
            if (auto s = weak.lock(); s && !r) s->upstream_opened(sid, serial, member, std::nullopt, r.error().message);
        });
    bool drop = false;
    {
        std::lock_guard lock(mutex_);
        auto it = subs_.find(sid);
        if (it == subs_.end() || it->second.serial != serial || it->second.cancelled) {
            drop = true;
        } else {
            it->second.upstream = upstream;
            it->second.upstream_known = true;
            it->second.active = true;
        }
    }
    if (drop) t.device->unsubscribe(upstream);
}

void FoxgloveConnection::open_pipe(const std::shared_ptr<const LiveMember>& member, gateway::GatewayPipeHandlers handlers,
                                   std::function<void(FoxgloveConnection&, std::optional<std::uint64_t>, const std::string&)> done) {
    const auto& t = *member->target;
    std::weak_ptr<FoxgloveConnection> weak = weak_from_this();
    t.device->mirror_service()->shared_endpoints()->open_pipe(
        t.path, t.member->name, robdef::pipe_is_unreliable(*t.object, *t.member), std::move(handlers),
        [weak, member, done = std::move(done)](Result<std::uint64_t> r) {
            auto self = weak.lock();
            if (!self) {
                if (r) member->target->device->mirror_service()->shared_endpoints()->close_pipe(*r);
                return;
            }
            done(*self, r ? std::optional<std::uint64_t>(*r) : std::nullopt, r ? std::string() : r.error().message);
        });
}

void FoxgloveConnection::upstream_opened(std::uint32_t sid, std::uint64_t serial, const std::shared_ptr<const LiveMember>& member,
                     std::optional<std::uint64_t> id,
                     const std::string& error) {
    std::optional<Sub> orphan;
    {
        std::lock_guard lock(mutex_);
        auto it = subs_.find(sid);
        if (it == subs_.end() || it->second.serial != serial) {
            if (id) {  // unsubscribed (or the connection closed) while the device answered
                orphan.emplace();
                orphan->member = member;
                orphan->upstream = *id;
                orphan->upstream_known = true;
            }
        } else if (!id && !it->second.active) {
            // The device refused (a pipe's connect, or a wire's).
            const std::string topic = it->second.member->topic;
            if (it->second.upstream_known) orphan = it->second;
            subs_.erase(it);
            session_.end_subscription(sid);
            if (!closed_) status("subscription " + std::to_string(sid) + " on " + topic + " failed: " + error);
        } else if (!id) {
            const std::string topic = it->second.member->topic;
            orphan = std::move(it->second);
            subs_.erase(it);
            session_.end_subscription(sid);
            if (!closed_) status("subscription " + std::to_string(sid) + " on " + topic + " failed: " + error);
        } else {
            it->second.upstream = *id;
            it->second.upstream_known = true;
            it->second.active = true;
        }
    }
    if (orphan && orphan->upstream_known && orphan->member) end_upstream(*orphan);
}

void FoxgloveConnection::upstream_closed(std::uint32_t sid, std::uint64_t serial, const std::string& why) {
    std::lock_guard lock(mutex_);
    auto it = subs_.find(sid);
    if (it == subs_.end() || it->second.serial != serial) return;
    const std::string topic = it->second.member->topic;
    subs_.erase(it);
    session_.end_subscription(sid);
    if (!closed_) status("subscription " + std::to_string(sid) + " on " + topic + " ended by the device: " + why, fg::StatusLevel::warning);
}

void FoxgloveConnection::end_upstream(Sub& s) {
    if (!s.member) return;
    const auto& t = *s.member->target;
    if (!s.upstream_known) {
        s.cancelled = true;
        return;
    }
    if (s.member->kind == LiveKind::pipe)
        t.device->mirror_service()->shared_endpoints()->close_pipe(s.upstream);
    else
        t.device->unsubscribe(s.upstream);
}

void FoxgloveConnection::on(fg::event::Unsubscribed e) {
    std::optional<Sub> s;
    {
        std::lock_guard lock(mutex_);
        auto it = subs_.find(e.subscription_id);
        if (it == subs_.end()) return;
        s = std::move(it->second);
        subs_.erase(it);
    }
    if (s->upstream_known)
        end_upstream(*s);
    else
        s->cancelled = true;
}
}  // namespace rr::server::foxglove
