// Message format 2 (wire.md §1.2–§1.4): fixed-width fields, uint16-prefixed strings.
#include <string>

#include "base/message/element_number.hpp"
#include "base/message/message_decoder.hpp"

namespace rr::detail {
namespace {

constexpr std::size_t kHeaderFixedBytes = 64;  // header with three empty strings
constexpr std::size_t kEntryFixedBytes = 22;   // entry with empty strings and no elements
constexpr std::size_t kElementFixedBytes = 16;

// uint16 length + bytes (wire.md §1.1).
Result<void> read_string16(ByteReader& r, std::string& out) {
    auto n = r.read_u16();
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

Result<void> MessageDecoder::read_header_v2(ByteReader& r, MessageHeaderInfo& info, MessageHeader& h) {
    auto header_size = r.read_u16();
    if (!header_size) return header_size.take_error();
    if (*header_size < kHeaderFixedBytes || *header_size > info.message_size)
        return error(MessageErrorType::ProtocolError, r,
                     "HeaderSize " + std::to_string(*header_size) + " outside 64…MessageSize");
    info.header_size = *header_size;
    auto hr = r.sub_reader(*header_size - r.position());
    if (!hr) return hr.take_error();
    Result<void> ok;
    if (!(ok = read_node_id(*hr, h.sender_node_id)) || !(ok = read_node_id(*hr, h.receiver_node_id)))
        return error(MessageErrorType::ProtocolError, *hr, "header truncated");
    auto sender_ep = hr->read_u32();
    auto receiver_ep = hr->read_u32();
    if (!sender_ep || !receiver_ep) return error(MessageErrorType::ProtocolError, *hr, "header truncated");
    h.sender_endpoint = *sender_ep;
    h.receiver_endpoint = *receiver_ep;
    if (!read_string16(*hr, h.sender_node_name) || !read_string16(*hr, h.receiver_node_name) ||
        !read_string16(*hr, h.metadata))
        return error(MessageErrorType::ProtocolError, *hr, "header string past HeaderSize");
    auto entry_count = hr->read_u16();
    auto message_id = hr->read_u16();
    auto message_res_id = hr->read_u16();
    if (!entry_count || !message_id || !message_res_id)
        return error(MessageErrorType::ProtocolError, *hr, "header truncated");
    info.entry_count = *entry_count;
    h.message_id = *message_id;
    h.message_res_id = *message_res_id;
    if (!hr->at_end()) return error(MessageErrorType::ProtocolError, *hr, "header does not end at HeaderSize");
    return {};
}

Result<void> MessageDecoder::read_entry_v2(ByteReader& r, MessageEntry& entry) {
    auto size = r.read_u32();
    if (!size) return size.take_error();
    auto er = sized_part(r, *size, 4, kEntryFixedBytes, "EntrySize");
    if (!er) return er.take_error();
    auto type = er->read_u16();
    if (!type || !er->skip(2)) return error(MessageErrorType::ProtocolError, *er, "entry truncated");
    entry.entry_type = static_cast<MessageEntryType>(*type);
    if (!read_string16(*er, entry.service_path) || !read_string16(*er, entry.member_name))
        return error(MessageErrorType::ProtocolError, *er, "entry string past EntrySize");
    auto request_id = er->read_u32();
    auto err = er->read_u16();
    if (!request_id || !err) return error(MessageErrorType::ProtocolError, *er, "entry truncated");
    entry.request_id = *request_id;
    entry.error = static_cast<MessageErrorType>(*err);
    if (!read_string16(*er, entry.metadata))
        return error(MessageErrorType::ProtocolError, *er, "entry MetaData past EntrySize");
    auto count = er->read_u16();
    if (!count) return error(MessageErrorType::ProtocolError, *er, "entry truncated");
    if (auto c = check_count(*er, *count, kElementFixedBytes, true, "elements"); !c) return c.take_error();
    entry.elements.resize(*count);
    // CORE's pipe acks number their top-level elements (PipeMember.cpp).
    const bool numbered = entry.entry_type == MessageEntryType::PipePacketRet;
    for (auto& e : entry.elements)
        if (auto ok = read_element_v2(*er, e, 1, numbered); !ok) return ok.take_error();
    if (!er->at_end())
        return error(MessageErrorType::ProtocolError, *er, "entry does not end at its EntrySize");
    return {};
}

Result<void> MessageDecoder::read_element_v2(ByteReader& r, MessageElement& e, std::size_t depth, bool numbered) {
    auto size = r.read_u32();
    if (!size) return error(MessageErrorType::ProtocolError, r, "element truncated");
    auto er = sized_part(r, *size, 4, kElementFixedBytes, "ElementSize");
    if (!er) return er.take_error();
    if (!read_string16(*er, e.name)) return error(MessageErrorType::ProtocolError, *er, "ElementName past ElementSize");
    auto type = er->read_u16();
    if (!type) return error(MessageErrorType::ProtocolError, *er, "element truncated");
    e.type = static_cast<DataTypes>(*type);
    if (!read_string16(*er, e.type_name) || !read_string16(*er, e.metadata))
        return error(MessageErrorType::ProtocolError, *er, "element string past ElementSize");
    auto count = er->read_u32();
    if (!count) return error(MessageErrorType::ProtocolError, *er, "element truncated");
    if (numbered) {
        if (auto n = parse_element_number(e.name)) {
            e.number = *n;
            e.name.clear();
        }
    }
    return read_payload(*er, e, *count, depth, has_numbered_children(e.type));
}

}  // namespace rr::detail
