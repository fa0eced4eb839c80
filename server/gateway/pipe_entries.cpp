#include "server/gateway/pipe_entries.hpp"

#include <charconv>

#include "core/session/elements.hpp"

namespace rr::server::gateway {

std::optional<std::int32_t> parse_pipe_index(std::string_view s) {
    std::int32_t v = 0;
    auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || p != s.data() + s.size()) return std::nullopt;
    return v;
}

std::int32_t entry_pipe_index(const MessageEntry& e) {
    std::int32_t idx = -1;
    if (const auto* el = e.find("index")) read_scalar(*el, idx);
    return idx;
}

MessageEntry pipe_connect_request(std::string path, std::string member, bool unreliable) {
    MessageEntry e;
    e.entry_type = MessageEntryType::PipeConnectReq;
    e.service_path = std::move(path);
    e.member_name = std::move(member);
    e.elements.push_back(make_scalar_element<std::int32_t>("index", -1));
    if (unreliable) e.elements.push_back(make_scalar_element<std::int32_t>("unreliable", 1));
    return e;
}

MessageEntry pipe_disconnect_request(std::string path, std::string member, std::int32_t index) {
    MessageEntry e;
    e.entry_type = MessageEntryType::PipeDisconnectReq;
    e.service_path = std::move(path);
    e.member_name = std::move(member);
    e.elements.push_back(make_scalar_element<std::int32_t>("index", index));
    return e;
}

MessageEntry pipe_packet_entry(std::string path, std::string member, std::int32_t index, std::uint32_t number,
                               MessageElement packet, bool request_ack, bool unreliable) {
    MessageEntry e;
    e.entry_type = MessageEntryType::PipePacket;
    e.service_path = std::move(path);
    e.member_name = std::move(member);
    if (unreliable) e.metadata = "unreliable\n";
    MessageElement d;
    d.name = std::to_string(index);  // a name, also in v4 (wire.md §6.7)
    d.type = DataTypes::dictionary_t;
    d.elements.push_back(make_scalar_element<std::uint32_t>("packetnumber", number));
    packet.name = "packet";
    packet.number.reset();
    d.elements.push_back(std::move(packet));
    if (request_ack) d.elements.push_back(make_scalar_element<std::uint32_t>("requestack", 1));
    e.elements.push_back(std::move(d));
    return e;
}

std::optional<ReceivedPipePacket> take_pipe_packet(MessageElement& el) {
    ReceivedPipePacket r;
    const MessageElement* pn = el.find("packetnumber");
    if (!pn || !read_scalar(*pn, r.number)) return std::nullopt;
    MessageElement* packet = nullptr;
    for (auto& child : el.elements)
        if (!child.number && child.name == "packet") packet = &child;
    if (!packet) return std::nullopt;
    r.packet = std::move(*packet);
    r.request_ack = el.find("requestack") != nullptr;
    return r;
}

MessageElement pipe_ack_element(std::int32_t index, std::uint32_t number) {
    MessageElement ack = make_scalar_element<std::uint32_t>("", number);
    ack.number = index;
    return ack;
}

}  // namespace rr::server::gateway
