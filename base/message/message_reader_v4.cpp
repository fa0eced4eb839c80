// Message format 4 (wire.md §2.3–§2.6): flags select optional fields, sizes and counts are uint_x,
// strings are uint_x-prefixed ("XLen"), names may be string-table codes.
#include <algorithm>
#include <string>

#include "base/codec/varint.hpp"
#include "base/message/message_decoder.hpp"
#include "base/message/string_table.hpp"

namespace rr::detail {
namespace {

// Smallest entry / element: size, flags, uint16 type, count (one byte each for the varints).
constexpr std::size_t kMinEntryBytes = 5;
constexpr std::size_t kMinElementBytes = 5;

Result<void> read_xlen_string(ByteReader& r, std::string& out) {
    auto n = read_uint_x(r);
    if (!n) return n.take_error();
    auto s = r.read_string(*n);
    if (!s) return s.take_error();
    out.assign(*s);
    return {};
}

Result<void> read_node_id(ByteReader& r, NodeID& out) {
    auto b = r.take(16);
    if (!b) return b.take_error();
    NodeID::Bytes bytes;
    for (std::size_t i = 0; i < 16; ++i) bytes[i] = (*b)[i];
    out = NodeID(bytes);
    return {};
}

}  // namespace

Result<void> MessageDecoder::read_header_v4(ByteReader& r, MessageHeaderInfo& info, MessageHeader& h) {
    auto header_len = read_uint_x(r);
    if (!header_len) return error(MessageErrorType::ProtocolError, r, "HeaderLen: " + header_len.error().message);
    // HeaderLen counts from offset 0 and includes its own bytes; the flags byte follows it.
    if (*header_len < r.position() + 1 || *header_len > info.message_size)
        return error(MessageErrorType::ProtocolError, r,
                     "HeaderLen " + std::to_string(*header_len) + " outside the message");
    info.header_size = *header_len;
    auto hr = r.sub_reader(*header_len - r.position());
    if (!hr) return hr.take_error();
    auto flags = hr->read_u8();
    if (!flags) return flags.take_error();
    h.v4_flags = *flags;
    auto truncated = [&] { return error(MessageErrorType::ProtocolError, *hr, "header field past HeaderLen"); };

    if (*flags & message_flags::routing_info) {
        if (!read_node_id(*hr, h.sender_node_id) || !read_node_id(*hr, h.receiver_node_id) ||
            !read_xlen_string(*hr, h.sender_node_name) || !read_xlen_string(*hr, h.receiver_node_name))
            return truncated();
    } else if (context_) {
        h.sender_node_id = context_->remote_node_id;
        h.receiver_node_id = context_->local_node_id;
    }
    if (*flags & message_flags::endpoint_info) {
        auto sender = read_uint_x(*hr);
        auto receiver = read_uint_x(*hr);
        if (!sender || !receiver) return truncated();
        h.sender_endpoint = *sender;
        h.receiver_endpoint = *receiver;
    } else if (context_) {
        h.sender_endpoint = context_->remote_endpoint;
        h.receiver_endpoint = context_->local_endpoint;
    }
    if (*flags & message_flags::priority) {
        auto p = hr->read_u16();
        if (!p) return truncated();
        h.priority = *p;
    }
    if (*flags & message_flags::meta_info) {
        if (!read_xlen_string(*hr, h.metadata)) return truncated();
        auto id = hr->read_u16();
        auto res_id = hr->read_u16();
        if (!id || !res_id) return truncated();
        h.message_id = *id;
        h.message_res_id = *res_id;
    }
    if (*flags & message_flags::string_table) {
        auto count = read_uint_x(*hr);
        if (!count) return truncated();
        if (auto c = check_count(*hr, *count, 2, false, "string table entries"); !c) return c.take_error();
        h.string_table.resize(*count);
        for (auto& [code, text] : h.string_table) {
            auto c = read_uint_x(*hr);
            if (!c || !read_xlen_string(*hr, text)) return truncated();
            code = *c;
        }
    }
    info.entry_count = 1;
    if (*flags & message_flags::multiple_entries) {
        auto count = read_uint_x(*hr);
        if (!count) return truncated();
        if (*count > 0xFFFF)
            return error(MessageErrorType::ProtocolError, *hr, "EntryCount " + std::to_string(*count) + " over 65535");
        info.entry_count = *count;
    }
    if (*flags & message_flags::extended) {
        if (!read_xlen_string(*hr, h.extended)) return truncated();
    }
    if (!hr->at_end()) return error(MessageErrorType::ProtocolError, *hr, "header does not end at HeaderLen");
    return {};
}

Result<std::string_view> MessageDecoder::resolve_code(std::uint32_t code) const {
    if (code & 1u) {
        if (local_table_ && local_index_.empty()) {
            // Small table: the first definition in wire order wins, as with the index below.
            for (const auto& [c, text] : *local_table_)
                if (c == code) return std::string_view(text);
        } else {
            auto it = std::lower_bound(local_index_.begin(), local_index_.end(), code,
                                       [](const auto& e, std::uint32_t c) { return e.first < c; });
            if (it != local_index_.end() && it->first == code) return std::string_view((*local_table_)[it->second].second);
        }
        return fail(MessageErrorType::ProtocolError, "unknown local string table code " + std::to_string(code));
    }
    if (context_ && !context_->standard_string_table)
        return fail(MessageErrorType::ProtocolError, "string table code " + std::to_string(code) +
                                                         " without a negotiated standard table");
    auto s = standard_string_for_code(code);
    if (!s) return fail(MessageErrorType::ProtocolError, "unknown string table code " + std::to_string(code));
    return *s;
}

Result<void> MessageDecoder::read_entry_v4(ByteReader& r, MessageEntry& entry) {
    const std::size_t start = r.position();
    auto size = read_uint_x(r);
    if (!size) return error(MessageErrorType::ProtocolError, r, "EntrySize: " + size.error().message);
    auto er = sized_part(r, *size, r.position() - start, kMinEntryBytes, "EntrySize");
    if (!er) return er.take_error();
    auto bad = [&](const char* what) { return error(MessageErrorType::ProtocolError, *er, what); };
    auto flags = er->read_u8();
    auto type = er->read_u16();
    if (!flags || !type) return bad("entry truncated");
    entry.entry_type = static_cast<MessageEntryType>(*type);
    const std::uint8_t f = *flags;
    if ((f & entry_flags::service_path_str) && (f & entry_flags::service_path_code))
        return bad("ServicePath given both as string and as code");
    if ((f & entry_flags::member_name_str) && (f & entry_flags::member_name_code))
        return bad("MemberName given both as string and as code");

    if ((f & entry_flags::service_path_str) && !read_xlen_string(*er, entry.service_path))
        return bad("ServicePath past EntrySize");
    if (f & entry_flags::service_path_code) {
        auto code = read_uint_x(*er);
        if (!code) return bad("entry truncated");
        auto s = resolve_code(*code);
        if (!s) return error(MessageErrorType::ProtocolError, *er, s.error().message);
        entry.service_path.assign(*s);
        if (keep_codes()) entry.service_path_code = *code;
    }
    if ((f & entry_flags::member_name_str) && !read_xlen_string(*er, entry.member_name))
        return bad("MemberName past EntrySize");
    if (f & entry_flags::member_name_code) {
        auto code = read_uint_x(*er);
        if (!code) return bad("entry truncated");
        auto s = resolve_code(*code);
        if (!s) return error(MessageErrorType::ProtocolError, *er, s.error().message);
        entry.member_name.assign(*s);
        if (keep_codes()) entry.member_name_code = *code;
    }
    if (f & entry_flags::request_id) {
        auto id = read_uint_x(*er);
        if (!id) return bad("entry truncated");
        entry.request_id = *id;
    }
    if (f & entry_flags::error) {
        auto e = er->read_u16();
        if (!e) return bad("entry truncated");
        entry.error = static_cast<MessageErrorType>(*e);
    }
    if ((f & entry_flags::meta_info) && !read_xlen_string(*er, entry.metadata)) return bad("MetaData past EntrySize");
    if ((f & entry_flags::extended) && !read_xlen_string(*er, entry.extended)) return bad("Extended past EntrySize");
    auto count = read_uint_x(*er);
    if (!count) return bad("entry truncated");
    if (auto c = check_count(*er, *count, kMinElementBytes, true, "elements"); !c) return c.take_error();
    entry.elements.resize(*count);
    for (auto& e : entry.elements)
        if (auto ok = read_element_v4(*er, e, 1); !ok) return ok.take_error();
    if (!er->at_end()) return bad("entry does not end at its EntrySize");
    return {};
}

Result<void> MessageDecoder::read_element_v4(ByteReader& r, MessageElement& e, std::size_t depth) {
    const std::size_t start = r.position();
    auto size = read_uint_x(r);
    if (!size) return error(MessageErrorType::ProtocolError, r, "ElementSize: " + size.error().message);
    auto er = sized_part(r, *size, r.position() - start, kMinElementBytes, "ElementSize");
    if (!er) return er.take_error();
    auto bad = [&](const char* what) { return error(MessageErrorType::ProtocolError, *er, what); };
    auto flags = er->read_u8();
    if (!flags) return bad("element truncated");
    const std::uint8_t f = *flags;
    const bool name_str = f & element_flags::element_name_str;
    const bool name_code = f & element_flags::element_name_code;
    if (name_str && name_code) return bad("ElementName given both as string and as code");
    if ((name_str || name_code) && (f & element_flags::element_number))
        return bad("element has both a name and a number");
    if ((f & element_flags::element_type_name_str) && (f & element_flags::element_type_name_code))
        return bad("ElementTypeName given both as string and as code");

    if (name_str && !read_xlen_string(*er, e.name)) return bad("ElementName past ElementSize");
    if (name_code) {
        auto code = read_uint_x(*er);
        if (!code) return bad("element truncated");
        auto s = resolve_code(*code);
        if (!s) return error(MessageErrorType::ProtocolError, *er, s.error().message);
        e.name.assign(*s);
        if (keep_codes()) e.name_code = *code;
    }
    if (f & element_flags::element_number) {
        auto n = read_int_x(*er);
        if (!n) return bad("ElementNumber truncated or 64-bit");
        e.number = *n;
    }
    auto type = er->read_u16();
    if (!type) return bad("element truncated");
    e.type = static_cast<DataTypes>(*type);
    if ((f & element_flags::element_type_name_str) && !read_xlen_string(*er, e.type_name))
        return bad("ElementTypeName past ElementSize");
    if (f & element_flags::element_type_name_code) {
        auto code = read_uint_x(*er);
        if (!code) return bad("element truncated");
        auto s = resolve_code(*code);
        if (!s) return error(MessageErrorType::ProtocolError, *er, s.error().message);
        e.type_name.assign(*s);
        if (keep_codes()) e.type_name_code = *code;
    }
    if ((f & element_flags::meta_info) && !read_xlen_string(*er, e.metadata)) return bad("MetaData past ElementSize");
    if ((f & element_flags::extended) && !read_xlen_string(*er, e.extended)) return bad("Extended past ElementSize");
    auto count = read_uint_x(*er);
    if (!count) return bad("DataCount truncated or 64-bit");
    return read_payload(*er, e, *count, depth, false);
}

}  // namespace rr::detail
