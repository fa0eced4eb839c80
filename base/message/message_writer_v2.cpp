// Message format 2 writer (wire.md §1.2–§1.4; CORE Message.cpp Write/ComputeSize).
#include <string>

#include "base/message/element_number.hpp"
#include "base/message/message_encoder.hpp"

namespace rr::detail {
namespace {

constexpr std::uint64_t kMax32 = 0xFFFFFFFFu;

Result<std::uint64_t> string16_size(std::string_view s, const char* what) {
    if (s.size() > 0xFFFF)
        return fail(MessageErrorType::InvalidArgument,
                    std::string(what) + " of " + std::to_string(s.size()) + " bytes (v2 max 65535)");
    return std::uint64_t{s.size()};
}

void write_string16(ByteWriter& w, std::string_view s) {
    w.write_u16(static_cast<std::uint16_t>(s.size()));
    w.write_string(s);
}

void write_node_id(ByteWriter& w, const NodeID& id) { w.write_bytes(id.bytes()); }

}  // namespace

Result<std::uint32_t> MessageEncoder::measure_v2() {
    const auto& h = m_.header;
    std::uint64_t header = 64;
    for (auto [s, what] : {std::pair<std::string_view, const char*>{h.sender_node_name, "SenderNodeName"},
                           {h.receiver_node_name, "ReceiverNodeName"},
                           {h.metadata, "header MetaData"}}) {
        auto n = string16_size(s, what);
        if (!n) return n.take_error();
        header += *n;
    }
    if (header > 0xFFFF) return fail(MessageErrorType::InvalidArgument, "v2 header over 65535 bytes");
    header_size_ = static_cast<std::uint32_t>(header);
    std::uint64_t total = header;
    for (const auto& entry : entries_) {
        auto n = measure_entry_v2(entry);
        if (!n) return n.take_error();
        total += *n;
        if (total > kMax32) return fail(MessageErrorType::InvalidArgument, "message over 4 GiB");
    }
    total += encoded_entry_.size();
    if (total > kMax32) return fail(MessageErrorType::InvalidArgument, "message over 4 GiB");
    return static_cast<std::uint32_t>(total);
}

Result<std::uint64_t> MessageEncoder::measure_entry_v2(const MessageEntry& entry) {
    const std::size_t slot = reserve_size_slot();
    if (entry.elements.size() > 0xFFFF)
        return fail(MessageErrorType::InvalidArgument, "more than 65535 elements in a v2 entry");
    std::uint64_t size = 22;
    for (auto [s, what] : {std::pair<std::string_view, const char*>{entry.service_path, "ServicePath"},
                           {entry.member_name, "MemberName"},
                           {entry.metadata, "entry MetaData"}}) {
        auto n = string16_size(s, what);
        if (!n) return n.take_error();
        size += *n;
    }
    for (const auto& e : entry.elements) {
        auto n = measure_element_v2(e);
        if (!n) return n.take_error();
        size += *n;
        if (size > kMax32) return fail(MessageErrorType::InvalidArgument, "entry over 4 GiB");
    }
    size_slot(slot) = static_cast<std::uint32_t>(size);
    return size;
}

Result<std::uint64_t> MessageEncoder::measure_element_v2(const MessageElement& e) {
    const std::size_t slot = reserve_size_slot();
    auto payload = check_payload(e);
    if (!payload) return payload.take_error();
    count_splice(e.data);
    std::uint64_t size = 16 + *payload;
    std::string_view name = e.name;
    ElementNumberText number(e.number.value_or(0));
    if (e.number) name = number.view();
    for (auto [s, what] : {std::pair<std::string_view, const char*>{name, "ElementName"},
                           {e.type_name, "ElementTypeName"},
                           {e.metadata, "element MetaData"}}) {
        auto n = string16_size(s, what);
        if (!n) return n.take_error();
        size += *n;
    }
    for (const auto& child : e.elements) {
        auto n = measure_element_v2(child);
        if (!n) return n.take_error();
        size += *n;
        if (size > kMax32) return fail(MessageErrorType::InvalidArgument, "element over 4 GiB");
    }
    if (size > kMax32) return fail(MessageErrorType::InvalidArgument, "element over 4 GiB");
    size_slot(slot) = static_cast<std::uint32_t>(size);
    return size;
}

void MessageEncoder::write_v2(ByteWriter& w) {
    const auto& h = m_.header;
    w.write_string("RRAC");
    w.write_u32(total_);
    w.write_u16(2);
    w.write_u16(static_cast<std::uint16_t>(header_size_));
    write_node_id(w, h.sender_node_id);
    write_node_id(w, h.receiver_node_id);
    w.write_u32(h.sender_endpoint);
    w.write_u32(h.receiver_endpoint);
    write_string16(w, h.sender_node_name);
    write_string16(w, h.receiver_node_name);
    write_string16(w, h.metadata);
    w.write_u16(static_cast<std::uint16_t>(entry_count()));
    w.write_u16(h.message_id);
    w.write_u16(h.message_res_id);
    for (const auto& entry : entries_) write_entry_v2(w, entry);
    w.write_shared(encoded_entry_);
}

void MessageEncoder::write_entry_v2(ByteWriter& w, const MessageEntry& entry) {
    w.write_u32(next_size());
    w.write_u16(static_cast<std::uint16_t>(entry.entry_type));
    w.write_u16(0);  // reserved
    write_string16(w, entry.service_path);
    write_string16(w, entry.member_name);
    w.write_u32(entry.request_id);
    w.write_u16(static_cast<std::uint16_t>(entry.error));
    write_string16(w, entry.metadata);
    w.write_u16(static_cast<std::uint16_t>(entry.elements.size()));
    for (const auto& e : entry.elements) write_element_v2(w, e);
}

void MessageEncoder::write_element_v2(ByteWriter& w, const MessageElement& e) {
    w.write_u32(next_size());
    if (e.number)
        write_string16(w, ElementNumberText(*e.number).view());
    else
        write_string16(w, e.name);
    w.write_u16(static_cast<std::uint16_t>(e.type));
    write_string16(w, e.type_name);
    write_string16(w, e.metadata);
    w.write_u32(e.data_count());
    if (is_nested(e.type))
        for (const auto& child : e.elements) write_element_v2(w, child);
    else
        w.write_shared(e.data);
}

}  // namespace rr::detail
