// Client publish: a client channel on a writable wire opens the gateway's wire connection to the
// device, and each message becomes the wire's OutValue there, under the write right and the device's
// motion guard.
#include "server/foxglove/foxglove_connection.hpp"

#include "core/value/timespec.hpp"
#include "server/gateway/mirror_service.hpp"
#include "server/service/wire_member.hpp"

namespace rr::server::foxglove {

namespace fg = rr::foxglove;
using gateway::ApiResult;
using gateway::MemberAddress;
using gateway::SharedEntryPtr;
namespace auth = gateway::auth;


// A client channel on a writable wire: the gateway's wire connection to the device is opened for it
// (DeviceMirror::subscribe, shared with every subscriber of that wire), as the JSON WebSocket's
// set_out_value needs its subscription; values published before it is open wait (the newest).
void FoxgloveConnection::on(fg::event::ClientAdvertised e) {
    auto server = server_.lock();
    auto member = server ? server->member_named(e.channel.topic, LiveKind::wire) : nullptr;
    std::uint64_t serial = 0;
    {
        std::lock_guard lock(mutex_);
        // Not a writable wire: nothing now (Lichtblick advertises ROS topics of its own, e.g.
        // /clicked_point, whether anything is published there or not); its first message gets a status.
        if (!member || !member->writable) return;
        if (auto denied = api_->check_access(address_of(*member), auth::Operation::write)) {
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
    const std::uint64_t upstream = t.device->subscribe(
        t.path, t.member->name, /*is_wire=*/true, [](const SharedEntryPtr&) {},
        [weak, cid, serial](Result<void> r) {
            if (auto s = weak.lock()) s->publish_ready(cid, serial, r ? std::string() : r.error().message);
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

void FoxgloveConnection::publish_ready(std::uint32_t cid, std::uint64_t serial, const std::string& error) {
    std::optional<MessageEntry> pending;
    std::shared_ptr<const LiveMember> member;
    std::optional<std::uint64_t> unsubscribe;
    {
        std::lock_guard lock(mutex_);
        auto it = publish_targets_.find(cid);
        if (it == publish_targets_.end() || it->second.serial != serial) return;
        member = it->second.member;
        if (!error.empty()) {
            if (it->second.upstream_known) unsubscribe = it->second.upstream;
            status("advertise: " + member->topic + ": the device refused the wire connection: " + error);
            publish_targets_.erase(it);
        } else {
            it->second.ready = true;
            pending = std::move(it->second.pending);
            it->second.pending.reset();
        }
    }
    if (unsubscribe) member->target->device->unsubscribe(*unsubscribe);
    if (pending) send_upstream(*member, std::move(*pending));
}

void FoxgloveConnection::end_publish(PublishTarget& p) {
    if (p.upstream_known) p.member->target->device->unsubscribe(p.upstream);
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

void FoxgloveConnection::on(fg::event::ClientPublish e) {
    std::shared_ptr<const LiveMember> member;
    std::string topic;
    {
        std::lock_guard lock(mutex_);
        if (!e.channel) return;
        topic = e.channel->topic;
        auto it = publish_targets_.find(e.channel->id);
        if (it == publish_targets_.end()) {
            // Once per client channel, not per message (a Publish panel sends at its rate).
            if (publish_refused_.insert(e.channel->id).second)
                status("message on \"" + topic + "\" refused: not a writable wire of a connected device that this login may write");
            return;
        }
        member = it->second.member;
    }
    auto report = [&](const std::string& why) {
        std::lock_guard lock(mutex_);
        status("message on \"" + topic + "\" refused: " + why);
    };
    auto payload = nlohmann::json::parse(e.payload, nullptr, false);
    if (payload.is_discarded()) return report("not JSON");
    // The channel's own message shape ({"value": …}, as the wire's channel carries it) or the bare value.
    const nlohmann::json& value = payload.is_object() && payload.contains("value") ? payload["value"] : payload;
    const auto& t = *member->target;
    gateway::ApiError error;
    auto packet = api_->element_from_json(value, t.member->type, t, "packet", error, "value");
    if (!packet) return report(error_text(error));
    // A client's OutValue is the device's InValue (wire.md §6.7: WirePacket, newest wins).
    MessageEntry entry;
    entry.entry_type = MessageEntryType::WirePacket;
    entry.member_name = t.member->name;
    entry.metadata = "unreliable\n";
    entry.elements.push_back(pack_timespec(wall_clock_timespec(), "packettime"));
    entry.elements.push_back(std::move(*packet));
    entry.service_path = t.path;
    MemberAddress address = address_of(*member);
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
