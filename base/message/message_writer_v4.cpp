// Message format 4 writer (wire.md §2.3–§2.5; CORE Message.cpp Write4/ComputeSize4/UpdateData4).
#include <algorithm>
#include <string>

#include "base/codec/varint.hpp"
#include "base/message/message_encoder.hpp"
#include "base/message/string_table.hpp"

namespace rr::detail {
namespace {

constexpr std::uint64_t kMax32 = 0xFFFFFFFFu;

void write_xlen(ByteWriter& w, std::string_view s) {
    write_uint_x(w, static_cast<std::uint32_t>(s.size()));
    w.write_string(s);
}

std::uint8_t entry_flags_of(const MessageEntry& e) noexcept {
    std::uint8_t f = 0;
    f |= e.service_path_code ? entry_flags::service_path_code : entry_flags::service_path_str;
    f |= e.member_name_code ? entry_flags::member_name_code : entry_flags::member_name_str;
    if (e.request_id != 0) f |= entry_flags::request_id;
    if (e.error != MessageErrorType::None) f |= entry_flags::error;
    if (!e.metadata.empty()) f |= entry_flags::meta_info;
    if (!e.extended.empty()) f |= entry_flags::extended;
    return f;
}

std::uint8_t element_flags_of(const MessageElement& e) noexcept {
    std::uint8_t f = 0;
    if (e.number)
        f |= element_flags::element_number;
    else
        f |= e.name_code ? element_flags::element_name_code : element_flags::element_name_str;
    if (e.type_name_code)
        f |= element_flags::element_type_name_code;
    else if (!e.type_name.empty())
        f |= element_flags::element_type_name_str;
    if (!e.metadata.empty()) f |= element_flags::meta_info;
    if (!e.extended.empty()) f |= element_flags::extended;
    return f;
}

// Explicit header flags may omit routing, never a field that holds data.
Result<void> check_explicit_flags(const MessageHeader& h, std::size_t entry_count, std::uint8_t f) {
    const char* dropped = nullptr;
    if (!(f & message_flags::multiple_entries) && entry_count != 1)
        dropped = "MULTIPLE_ENTRIES clear but the message has != 1 entry";
    else if (!(f & message_flags::meta_info) && (!h.metadata.empty() || h.message_id || h.message_res_id))
        dropped = "META_INFO clear but MetaData/MessageID/MessageResID set";
    else if (!(f & message_flags::string_table) && !h.string_table.empty())
        dropped = "STRING_TABLE clear but the local string table is not empty";
    else if (!(f & message_flags::extended) && !h.extended.empty())
        dropped = "EXTENDED clear but Extended is not empty";
    else if (!(f & message_flags::priority) && h.priority != 0)
        dropped = "PRIORITY clear but priority set";
    if (dropped) return fail(MessageErrorType::InvalidArgument, std::string("v4_flags: ") + dropped);
    return {};
}

}  // namespace

Result<std::uint64_t> MessageEncoder::measure_name_v4(const std::string& s, const std::optional<std::uint32_t>& code) {
    if (!code) return xlen_size(s.size());
    const bool known = (*code & 1u) ? std::binary_search(local_codes_.begin(), local_codes_.end(), *code)
                                    : standard_string_for_code(*code).has_value();
    if (!known)
        return fail(MessageErrorType::InvalidArgument,
                    "string table code " + std::to_string(*code) + " for '" + s + "' is not defined");
    return std::uint64_t{uint_x_size(*code)};
}

Result<std::uint32_t> MessageEncoder::measure_v4() {
    const auto& h = m_.header;
    v4_flags_ = h.v4_flags ? *h.v4_flags : default_v4_flags(h, entry_count());
    if (h.v4_flags)
        if (auto ok = check_explicit_flags(h, entry_count(), v4_flags_); !ok) return ok.take_error();
    std::uint64_t s = 11;
    if (v4_flags_ & message_flags::routing_info)
        s += 32 + xlen_size(h.sender_node_name.size()) + xlen_size(h.receiver_node_name.size());
    if (v4_flags_ & message_flags::endpoint_info) s += uint_x_size(h.sender_endpoint) + uint_x_size(h.receiver_endpoint);
    if (v4_flags_ & message_flags::priority) s += 2;
    if (v4_flags_ & message_flags::meta_info) s += xlen_size(h.metadata.size()) + 4;
    local_codes_.clear();
    if (v4_flags_ & message_flags::string_table) {
        if (h.string_table.size() > kMax32) return fail(MessageErrorType::InvalidArgument, "string table too large");
        s += uint_x_size(static_cast<std::uint32_t>(h.string_table.size()));
        local_codes_.reserve(h.string_table.size());
        for (const auto& [code, text] : h.string_table) {
            s += uint_x_size(code) + xlen_size(text.size());
            local_codes_.push_back(code);
        }
        std::sort(local_codes_.begin(), local_codes_.end());
    }
    if (v4_flags_ & message_flags::multiple_entries) s += uint_x_size(static_cast<std::uint32_t>(entry_count()));
    if (v4_flags_ & message_flags::extended) s += xlen_size(h.extended.size());
    const std::uint64_t header = size_plus_uint_x(s);
    if (header > kMax32) return fail(MessageErrorType::InvalidArgument, "v4 header over 4 GiB");
    header_size_ = static_cast<std::uint32_t>(header);
    std::uint64_t total = header;
    for (const auto& entry : entries_) {
        auto n = measure_entry_v4(entry);
        if (!n) return n.take_error();
        total += *n;
        if (total > kMax32) return fail(MessageErrorType::InvalidArgument, "message over 4 GiB");
    }
    total += encoded_entry_.size();
    if (total > kMax32) return fail(MessageErrorType::InvalidArgument, "message over 4 GiB");
    return static_cast<std::uint32_t>(total);
}

Result<std::uint64_t> MessageEncoder::measure_entry_v4(const MessageEntry& entry) {
    const std::size_t slot = reserve_size_slot();
    if (entry.elements.size() > kMax32) return fail(MessageErrorType::InvalidArgument, "too many elements");
    std::uint64_t s = 3;  // flags + EntryType
    auto sp = measure_name_v4(entry.service_path, entry.service_path_code);
    if (!sp) return sp.take_error();
    auto mn = measure_name_v4(entry.member_name, entry.member_name_code);
    if (!mn) return mn.take_error();
    s += *sp + *mn;
    if (entry.request_id != 0) s += uint_x_size(entry.request_id);
    if (entry.error != MessageErrorType::None) s += 2;
    if (!entry.metadata.empty()) s += xlen_size(entry.metadata.size());
    if (!entry.extended.empty()) s += xlen_size(entry.extended.size());
    s += uint_x_size(static_cast<std::uint32_t>(entry.elements.size()));
    for (const auto& e : entry.elements) {
        auto n = measure_element_v4(e);
        if (!n) return n.take_error();
        s += *n;
        if (s > kMax32) return fail(MessageErrorType::InvalidArgument, "entry over 4 GiB");
    }
    const std::uint64_t size = size_plus_uint_x(s);
    if (size > kMax32) return fail(MessageErrorType::InvalidArgument, "entry over 4 GiB");
    size_slot(slot) = static_cast<std::uint32_t>(size);
    return size;
}

Result<std::uint64_t> MessageEncoder::measure_element_v4(const MessageElement& e) {
    const std::size_t slot = reserve_size_slot();
    auto payload = check_payload(e);
    if (!payload) return payload.take_error();
    count_splice(e.data);
    std::uint64_t s = 3 + *payload;  // flags + ElementType + raw data
    if (e.number) {
        s += int_x_size(*e.number);
    } else {
        auto n = measure_name_v4(e.name, e.name_code);
        if (!n) return n.take_error();
        s += *n;
    }
    if (e.type_name_code || !e.type_name.empty()) {
        auto n = measure_name_v4(e.type_name, e.type_name_code);
        if (!n) return n.take_error();
        s += *n;
    }
    if (!e.metadata.empty()) s += xlen_size(e.metadata.size());
    if (!e.extended.empty()) s += xlen_size(e.extended.size());
    s += uint_x_size(e.data_count());
    for (const auto& child : e.elements) {
        auto n = measure_element_v4(child);
        if (!n) return n.take_error();
        s += *n;
        if (s > kMax32) return fail(MessageErrorType::InvalidArgument, "element over 4 GiB");
    }
    const std::uint64_t size = size_plus_uint_x(s);
    if (size > kMax32) return fail(MessageErrorType::InvalidArgument, "element over 4 GiB");
    size_slot(slot) = static_cast<std::uint32_t>(size);
    return size;
}

void MessageEncoder::write_v4(ByteWriter& w) {
    const auto& h = m_.header;
    const std::uint8_t f = v4_flags_;
    w.write_string("RRAC");
    w.write_u32(total_);
    w.write_u16(4);
    write_uint_x(w, header_size_);
    w.write_u8(f);
    if (f & message_flags::routing_info) {
        w.write_bytes(h.sender_node_id.bytes());
        w.write_bytes(h.receiver_node_id.bytes());
        write_xlen(w, h.sender_node_name);
        write_xlen(w, h.receiver_node_name);
    }
    if (f & message_flags::endpoint_info) {
        write_uint_x(w, h.sender_endpoint);
        write_uint_x(w, h.receiver_endpoint);
    }
    if (f & message_flags::priority) w.write_u16(h.priority);
    if (f & message_flags::meta_info) {
        write_xlen(w, h.metadata);
        w.write_u16(h.message_id);
        w.write_u16(h.message_res_id);
    }
    if (f & message_flags::string_table) {
        write_uint_x(w, static_cast<std::uint32_t>(h.string_table.size()));
        for (const auto& [code, text] : h.string_table) {
            write_uint_x(w, code);
            write_xlen(w, text);
        }
    }
    if (f & message_flags::multiple_entries) write_uint_x(w, static_cast<std::uint32_t>(entry_count()));
    if (f & message_flags::extended) write_xlen(w, h.extended);
    for (const auto& entry : entries_) write_entry_v4(w, entry);
    w.write_shared(encoded_entry_);
}

void MessageEncoder::write_entry_v4(ByteWriter& w, const MessageEntry& entry) {
    const std::uint8_t f = entry_flags_of(entry);
    write_uint_x(w, next_size());
    w.write_u8(f);
    w.write_u16(static_cast<std::uint16_t>(entry.entry_type));
    if (f & entry_flags::service_path_str) write_xlen(w, entry.service_path);
    if (f & entry_flags::service_path_code) write_uint_x(w, *entry.service_path_code);
    if (f & entry_flags::member_name_str) write_xlen(w, entry.member_name);
    if (f & entry_flags::member_name_code) write_uint_x(w, *entry.member_name_code);
    if (f & entry_flags::request_id) write_uint_x(w, entry.request_id);
    if (f & entry_flags::error) w.write_u16(static_cast<std::uint16_t>(entry.error));
    if (f & entry_flags::meta_info) write_xlen(w, entry.metadata);
    if (f & entry_flags::extended) write_xlen(w, entry.extended);
    write_uint_x(w, static_cast<std::uint32_t>(entry.elements.size()));
    for (const auto& e : entry.elements) write_element_v4(w, e);
}

void MessageEncoder::write_element_v4(ByteWriter& w, const MessageElement& e) {
    const std::uint8_t f = element_flags_of(e);
    write_uint_x(w, next_size());
    w.write_u8(f);
    if (f & element_flags::element_name_str) write_xlen(w, e.name);
    if (f & element_flags::element_name_code) write_uint_x(w, *e.name_code);
    if (f & element_flags::element_number) write_int_x(w, *e.number);
    w.write_u16(static_cast<std::uint16_t>(e.type));
    if (f & element_flags::element_type_name_str) write_xlen(w, e.type_name);
    if (f & element_flags::element_type_name_code) write_uint_x(w, *e.type_name_code);
    if (f & element_flags::meta_info) write_xlen(w, e.metadata);
    if (f & element_flags::extended) write_xlen(w, e.extended);
    write_uint_x(w, e.data_count());
    if (is_nested(e.type))
        for (const auto& child : e.elements) write_element_v4(w, child);
    else
        w.write_shared(e.data);
}

}  // namespace rr::detail
