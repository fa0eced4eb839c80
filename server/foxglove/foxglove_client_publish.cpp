// Client publish: a client channel on a writable wire opens the gateway's wire connection to the
// device, and each message becomes the wire's OutValue there, under the write right and the device's
// motion guard; a client channel on a pipe the client may send on opens a pipe endpoint of the
// gateway's own session, and each message becomes one pipe packet, under the write right.
#include "server/foxglove/foxglove_connection.hpp"

#include "core/value/timespec.hpp"
#include "server/gateway/mirror_service.hpp"
#include "server/gateway/session_endpoints.hpp"
#include "server/service/wire_member.hpp"

namespace rr::server::foxglove {

namespace {

// Packets a client may send on a pipe before the device accepted the endpoint; more are refused.
constexpr std::size_t kMaxPendingPipePackets = 16;

const char* kind_name(LiveKind k) { return k == LiveKind::pipe ? "pipe" : "wire"; }

}  // namespace

// A client channel on a writable wire: the gateway's wire connection to the device is opened for it
// (DeviceMirror::subscribe, shared with every subscriber of that wire), as the JSON WebSocket's
// set_out_value needs its subscription; values published before it is open wait (the newest). On a
// pipe: a pipe endpoint of the gateway's shared session is connected for this client channel alone
// (packets on it are this client's, in order); packets before it is connected wait (at most 16).
void FoxgloveConnection::on(fg::event::ClientAdvertised e) {
    auto server = server_.lock();
    auto member = server ? server->member_named(e.channel.topic, LiveKind::wire) : nullptr;
    if (!member && server) member = server->member_named(e.channel.topic, LiveKind::pipe);
    std::uint64_t serial = 0;
    {
        std::lock_guard lock(mutex_);
        // Not a writable wire or pipe: nothing now (Lichtblick advertises ROS topics of its own, e.g.
        // /clicked_point, whether anything is published there or not); its first message gets a status.
        if (!member || !member->writable) return;
        if (auto denied = api_->check_access(address_of(*member), gateway::auth::Operation::write)) {
            status("advertise: " + e.channel.topic + ": " + error_text(*denied) + "; messages on it are refused");
            return;
        }
        PublishTarget target;
        target.member = member;
        target.serial = serial = ++next_serial_;
        publish_targets_[e.channel.id] = std::move(target);
    }
    std::weak_ptr<FoxgloveConnection> weak = weak_from_this();
    const auto& t = *member->target;
    const std::uint32_t cid = e.channel.id;
    if (member->kind == LiveKind::pipe) {
        gateway::GatewayPipeHandlers h;
        h.on_packet = [](const MessageElement&, std::uint32_t) {};  // the device's packets are not this channel's
        h.on_closed = [weak, cid, serial](const RRError& reason) {
            if (auto s = weak.lock()) s->publish_closed(cid, serial, reason.message);
        };
        open_pipe(member, std::move(h),
                  [cid, serial, member](FoxgloveConnection& c, std::optional<std::uint64_t> id, const std::string& error) {
                      c.publish_opened(cid, serial, member, id, error);
                  });
        return;
    }
    const std::uint64_t upstream = t.device->subscribe(
        t.path, t.member->name, /*is_wire=*/true, [](const SharedEntryPtr&) {},
        [weak, cid, serial, member](Result<void> r) {
            if (auto s = weak.lock()) s->publish_opened(cid, serial, member, std::nullopt, r ? std::string() : r.error().message);
        });
    bool drop = false;
    {
        std::lock_guard lock(mutex_);
        auto it = publish_targets_.find(cid);
        if (it == publish_targets_.end() || it->second.serial != serial) {
            drop = true;
        } else {
            it->second.upstream = upstream;
            it->second.upstream_known = true;
        }
    }
    if (drop) t.device->unsubscribe(upstream);
}

// The wire connection (a wire: `pipe` empty, the subscription's answer) or the pipe endpoint (`pipe`:
// its id) is open, or the device refused it (`error`).
void FoxgloveConnection::publish_opened(std::uint32_t cid, std::uint64_t serial, const std::shared_ptr<const LiveMember>& member,
                                        std::optional<std::uint64_t> pipe, const std::string& error) {
    std::optional<PublishTarget> ended;
    std::optional<MessageEntry> pending;
    bool send_packets = false;
    {
        std::lock_guard lock(mutex_);
        auto it = publish_targets_.find(cid);
        if (it == publish_targets_.end() || it->second.serial != serial) {
            // Unadvertised (or the connection closed) while the device answered: its pipe endpoint ends.
            if (!pipe) return;
            ended.emplace();
            ended->member = member;
            ended->upstream = *pipe;
            ended->upstream_known = true;
        } else if (!error.empty()) {
            status("advertise: " + member->topic + ": the device refused the " + kind_name(member->kind) + " connection: " + error);
            ended = std::move(it->second);
            publish_targets_.erase(it);
        } else {
            if (pipe) {
                it->second.upstream = *pipe;
                it->second.upstream_known = true;
            }
            it->second.ready = true;
            pending = std::move(it->second.pending);
            it->second.pending.reset();
            send_packets = !it->second.pending_packets.empty() && !it->second.sending;
            if (send_packets) it->second.sending = true;
        }
    }
    if (ended) return end_publish(*ended);
    if (pending) send_upstream(*member, std::move(*pending));
    if (send_packets) send_pipe_packets(cid, serial);
}

// The device closed the pipe endpoint (or the session ended): the client channel's messages are refused
// from now on, with this one status.
void FoxgloveConnection::publish_closed(std::uint32_t cid, std::uint64_t serial, const std::string& why) {
    std::lock_guard lock(mutex_);
    auto it = publish_targets_.find(cid);
    if (it == publish_targets_.end() || it->second.serial != serial) return;
    const std::string topic = it->second.member->topic;
    publish_targets_.erase(it);
    publish_refused_.insert(cid);
    if (!closed_) status("messages on \"" + topic + "\" refused from now on: the device closed the pipe endpoint: " + why);
}

void FoxgloveConnection::end_publish(PublishTarget& p) {
    if (!p.upstream_known || !p.member) return;
    const auto& device = p.member->target->device;
    if (p.member->kind == LiveKind::pipe)
        device->mirror_service()->shared_endpoints()->close_pipe(p.upstream);
    else
        device->unsubscribe(p.upstream);
}

void FoxgloveConnection::on(fg::event::ClientUnadvertised e) {
    std::optional<PublishTarget> p;
    {
        std::lock_guard lock(mutex_);
        publish_refused_.erase(e.channel.id);
        auto it = publish_targets_.find(e.channel.id);
        if (it == publish_targets_.end()) return;
        p = std::move(it->second);
        publish_targets_.erase(it);
    }
    end_publish(*p);
}

// The wire packet to the device over the gateway's own session (its wire connection is open).
void FoxgloveConnection::send_upstream(const LiveMember& member, MessageEntry entry) {
    const auto& t = *member.target;
    auto client = t.device->upstream();
    if (!client) {
        std::lock_guard lock(mutex_);
        return status("message on \"" + member.topic + "\" refused: device \"" + t.device->config().name + "\" is not connected");
    }
    entry.service_path = t.device->mirror_service()->to_upstream(t.path);
    client->send(std::move(entry));
}

// The client channel's waiting packets on its pipe endpoint (open), in order, by the one caller that
// set `sending` (the socket's messages and the endpoint's opening run on different strands; the
// device is called without mutex_). A device that does not read gets the client a status per refused
// packet (BufferLimitViolation past 8 MiB waiting).
void FoxgloveConnection::send_pipe_packets(std::uint32_t cid, std::uint64_t serial) {
    for (;;) {
        std::shared_ptr<const LiveMember> member;
        std::uint64_t endpoint = 0;
        MessageElement packet;
        {
            std::lock_guard lock(mutex_);
            auto it = publish_targets_.find(cid);
            if (it == publish_targets_.end() || it->second.serial != serial) return;
            auto& target = it->second;
            if (target.pending_packets.empty() || !target.upstream_known) {
                target.sending = false;
                return;
            }
            member = target.member;
            endpoint = target.upstream;
            packet = std::move(target.pending_packets.front());
            target.pending_packets.pop_front();
        }
        auto sent = member->target->device->mirror_service()->shared_endpoints()->send_pipe_packet(endpoint, std::move(packet), false);
        if (!sent) {
            std::lock_guard lock(mutex_);
            status("message on \"" + member->topic + "\" refused: " + sent.error().message);
        }
    }
}

void FoxgloveConnection::on(fg::event::ClientPublish e) {
    std::shared_ptr<const LiveMember> member;
    std::string topic;
    std::uint64_t serial = 0;
    {
        std::lock_guard lock(mutex_);
        if (!e.channel) return;
        topic = e.channel->topic;
        auto it = publish_targets_.find(e.channel->id);
        if (it == publish_targets_.end()) {
            // Once per client channel, not per message (a Publish panel sends at its rate).
            if (publish_refused_.insert(e.channel->id).second)
                status("message on \"" + topic + "\" refused: not a writable wire or pipe of a connected device that this login may write");
            return;
        }
        member = it->second.member;
        serial = it->second.serial;
    }
    auto report = [&](const std::string& why) {
        std::lock_guard lock(mutex_);
        status("message on \"" + topic + "\" refused: " + why);
    };
    auto payload = nlohmann::json::parse(e.payload, nullptr, false);
    if (payload.is_discarded()) return report("not JSON");
    // The channel's own message shape ({"value": …}, as the member's channel carries it) or the bare value.
    const nlohmann::json& value = payload.is_object() && payload.contains("value") ? payload["value"] : payload;
    const auto& t = *member->target;
    gateway::ApiError error;
    auto packet = api_->element_from_json(value, t.member->type, t, "packet", error, "value");
    if (!packet) return report(error_text(error));
    if (member->kind == LiveKind::pipe) {
        {
            std::lock_guard lock(mutex_);
            auto it = publish_targets_.find(e.channel->id);
            if (it == publish_targets_.end() || it->second.serial != serial) return;
            auto& target = it->second;
            if (target.pending_packets.size() >= kMaxPendingPipePackets)
                return status("message on \"" + topic + "\" refused: " + std::to_string(kMaxPendingPipePackets) +
                              " packets wait for the device to accept the pipe endpoint");
            target.pending_packets.push_back(std::move(*packet));
            if (!target.ready || target.sending) return;  // sent when the endpoint opens / by the caller sending now
            target.sending = true;
        }
        return send_pipe_packets(e.channel->id, serial);
    }
    // A client's OutValue is the device's InValue (wire.md §6.7: WirePacket, newest wins).
    MessageEntry entry;
    entry.entry_type = MessageEntryType::WirePacket;
    entry.member_name = t.member->name;
    entry.metadata = "unreliable\n";
    entry.elements.push_back(pack_timespec(wall_clock_timespec(), "packettime"));
    entry.elements.push_back(std::move(*packet));
    entry.service_path = t.path;
    gateway::MemberAddress address = address_of(*member);
    // A command stream: refused while another client holds the motion, ended when it goes silent.
    auto motion = gateway::JsonApi::admit_motion(address, t, entry);
    if (auto* refused = std::get_if<gateway::ApiError>(&motion)) return report(error_text(*refused));
    {
        std::lock_guard lock(mutex_);
        auto it = publish_targets_.find(e.channel->id);
        if (it == publish_targets_.end()) return;
        if (!it->second.ready) {
            it->second.pending = std::move(entry);  // newest wins until the wire connection is open
            return;
        }
    }
    send_upstream(*member, std::move(entry));
}

}  // namespace rr::server::foxglove
