#include "server/service/pipe_member.hpp"

#include <charconv>
#include <limits>
#include <optional>
#include <thread>

#include "server/service/member_support.hpp"

namespace rr::server {

namespace {

/// Pipe index of a packet/ack element: ElementNumber when set, else the decimal ElementName.
std::optional<std::int32_t> element_index(const MessageElement& e) {
    if (e.number) return *e.number;
    std::int32_t v = 0;
    auto [end, ec] = std::from_chars(e.name.data(), e.name.data() + e.name.size(), v);
    if (ec != std::errc() || end != e.name.data() + e.name.size() || e.name.empty()) return std::nullopt;
    return v;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// PipeEndpoint

PipeEndpoint::PipeEndpoint(std::weak_ptr<PipeMember> member, std::shared_ptr<const detail::MemberInfo> info,
                           SessionRef session, std::string path, std::int32_t index, bool unreliable)
    : MemberConnection(std::move(session), std::move(path)), member_(std::move(member)), info_(std::move(info)),
      index_(index), unreliable_(unreliable) {}

Result<std::uint32_t> PipeEndpoint::send(const Value& packet, bool request_ack) {
    if (!open_.load()) return fail(MessageErrorType::InvalidOperation, "Pipe endpoint is closed");
    if (info_->def->direction() == robdef::MemberDirection::writeonly)
        return fail(MessageErrorType::ReadOnlyMember, "Read only pipe");
    auto member = member_.lock();
    if (!member) return fail(MessageErrorType::InvalidOperation, "Pipe endpoint is closed");
    auto packed = detail::pack_member(*info_, packet, info_->def->type, "packet");
    if (!packed) return packed.take_error();

    MessageEntry entry = detail::member_entry(MessageEntryType::PipePacket, path_, info_->def->name);
    if (unreliable_) entry.metadata = "unreliable\n";
    MessageElement pe;
    pe.name = std::to_string(index_);
    pe.type = DataTypes::dictionary_t;
    pe.elements.reserve(request_ack ? 3 : 2);
    pe.elements.push_back(make_scalar_element<std::uint32_t>("packetnumber", 0));
    pe.elements.push_back(std::move(*packed));
    if (request_ack) pe.elements.push_back(make_scalar_element<std::uint32_t>("requestack", 1));
    entry.elements.push_back(std::move(pe));

    // Numbers are assigned and packets queued in one step, so the client sees them in order and never
    // waits for a number that was refused. Queueing runs inline on the session's strand; should that
    // end the session and a close handler send on this endpoint again, fail instead of deadlocking.
    if (send_owner_.load() == std::this_thread::get_id())
        return fail(MessageErrorType::InvalidOperation, "pipe endpoint send re-entered from a handler");
    std::lock_guard lock(send_mutex_);
    send_owner_.store(std::this_thread::get_id());
    struct Release {
        std::atomic<std::thread::id>& owner;
        ~Release() { owner.store(std::thread::id()); }
    } release{send_owner_};
    const std::size_t queued = session_.queued_bytes();
    if (queued > member->max_backlog_bytes())
        return fail(MessageErrorType::BufferLimitViolation,
                    "pipe backlog full: " + std::to_string(queued) + " bytes queued for this client (limit " +
                        std::to_string(member->max_backlog_bytes()) + ")");
    const std::uint32_t number = send_number_ == UINT32_MAX ? 0 : send_number_ + 1;
    entry.elements[0].elements[0] = make_scalar_element<std::uint32_t>("packetnumber", number);
    if (auto r = session_.send(std::move(entry)); !r) return r.take_error();
    send_number_ = number;
    return number;
}

void PipeEndpoint::close() {
    if (!open_.load()) return;
    if (auto member = member_.lock()) member->close_endpoint(shared_from_this());
    open_.store(false);
}

// ---------------------------------------------------------------------------------------------
// PipeMember

PipeMember::PipeMember(std::shared_ptr<const detail::MemberInfo> info, bool unreliable)
    : info_(std::move(info)), unreliable_(unreliable) {}

const std::string& PipeMember::name() const noexcept { return info_->def->name; }

void PipeMember::on_packet(PacketHandler handler) { set_handler(on_packet_, std::move(handler)); }

void PipeMember::on_ack(AckHandler handler) { set_handler(on_ack_, std::move(handler)); }

void PipeMember::clear_handlers() { clear_handler_slots(on_packet_, on_ack_); }

std::vector<std::shared_ptr<PipeEndpoint>> PipeMember::endpoints() const { return snapshot(); }

std::size_t PipeMember::broadcast(const Value& packet) {
    std::size_t n = 0;
    for (const auto& ep : endpoints())
        if (ep->send(packet)) ++n;
    return n;
}

void PipeMember::close_endpoint(const std::shared_ptr<PipeEndpoint>& endpoint) {
    MessageEntry closed = detail::member_entry(MessageEntryType::PipeClosed, endpoint->service_path(), name());
    closed.elements.push_back(make_scalar_element<std::int32_t>("index", endpoint->index()));
    remove(Key{endpoint->session().endpoint(), endpoint->index()}, endpoint, std::move(closed));
}

void PipeMember::handle_request(const SessionRef& session, MessageEntry&& entry, Responder responder) {
    auto index = detail::require_scalar<std::int32_t>(entry, "index");
    if (!index) {
        responder.fail(index.error());
        return;
    }
    if (entry.entry_type == MessageEntryType::PipeDisconnectReq) {
        disconnect(Key{session.endpoint(), *index}, responder, make_error(MessageErrorType::InvalidArgument, "Invalid pipe"));
        return;
    }

    bool want_unreliable = false;
    if (const auto* u = entry.find("unreliable")) {
        std::int32_t flag = 0;
        want_unreliable = read_scalar(*u, flag) && flag == 1;
    }
    const bool unreliable = unreliable_ && want_unreliable;
    std::shared_ptr<PipeEndpoint> ep;
    std::shared_ptr<const ConnectHandler> on_connect;
    {
        std::lock_guard lock(mutex_);
        // CORE's rule: when this client has an endpoint at or above the requested index, the new one
        // gets one more than its highest; −1 with none gives 1. So an index in use is never refused.
        std::int32_t i = *index;
        std::optional<std::int32_t> highest;
        for (const auto& [k, e] : connections_)
            if (k.first == session.endpoint() && (!highest || k.second > *highest)) highest = k.second;
        if (highest && *highest >= i) {
            if (*highest == std::numeric_limits<std::int32_t>::max()) {
                responder.fail(make_error(MessageErrorType::InvalidArgument, "Pipe endpoint index in use"));
                return;
            }
            i = *highest + 1;
        }
        if (i == -1) i = 1;
        ep.reset(new PipeEndpoint(weak_from_this(), info_, session, entry.service_path, i, unreliable));
        connections_.emplace(Key{session.endpoint(), i}, ep);
        on_connect = on_connect_;
    }
    if (auto r = run_on_connect(on_connect, Key{session.endpoint(), ep->index()}, ep, true); !r) {
        responder.fail(r.error());
        return;
    }
    MessageEntry reply;
    reply.elements.push_back(make_scalar_element<std::int32_t>("index", ep->index()));
    if (unreliable) reply.elements.push_back(make_scalar_element<std::int32_t>("unreliable", 1));
    responder.respond(std::move(reply));
}

void PipeMember::handle_packet(const SessionRef& session, MessageEntry&& entry) {
    std::shared_ptr<const PacketHandler> on_packet;
    std::shared_ptr<const AckHandler> on_ack;
    {
        std::lock_guard lock(mutex_);
        on_packet = on_packet_;
        on_ack = on_ack_;
    }
    auto endpoint_at = [&](std::int32_t index) { return find(Key{session.endpoint(), index}); };

    if (entry.entry_type == MessageEntryType::PipePacketRet) {
        for (const auto& e : entry.elements) {
            auto index = element_index(e);
            std::uint32_t number = 0;
            if (!index || !read_scalar(e, number)) continue;
            auto ep = endpoint_at(*index);
            if (ep && on_ack) (*on_ack)(ep, number);
        }
        return;
    }

    const bool readonly = info_->def->direction() == robdef::MemberDirection::readonly;
    MessageEntry acks;
    for (const auto& e : entry.elements) {
        auto index = element_index(e);
        if (!index || e.type != DataTypes::dictionary_t) continue;
        auto ep = endpoint_at(*index);
        if (!ep) continue;
        const MessageElement* num = e.find("packetnumber");
        const MessageElement* data = e.find("packet");
        std::uint32_t number = 0;
        if (!num || !data || !read_scalar(*num, number)) continue;
        if (!readonly) {
            auto v = detail::unpack_member(*info_, *data, info_->def->type);
            if (!v) continue;  // a malformed packet is dropped (and not acknowledged), as CORE does
            if (on_packet) (*on_packet)(ep, std::move(*v));
        }
        if (e.find("requestack")) {
            MessageElement ack = make_scalar_element<std::uint32_t>("", number);
            ack.number = *index;
            acks.elements.push_back(std::move(ack));
        }
    }
    if (!acks.elements.empty()) {
        acks.entry_type = MessageEntryType::PipePacketRet;
        acks.service_path = entry.service_path;
        acks.member_name = name();
        (void)session.send(std::move(acks));
    }
}

}  // namespace rr::server
