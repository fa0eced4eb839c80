#include "base/message/message_reader.hpp"

#include <algorithm>
#include <string>

#include "base/message/message_decoder.hpp"

namespace rr {
namespace {

constexpr std::byte kMagic[4] = {std::byte{'R'}, std::byte{'R'}, std::byte{'A'}, std::byte{'C'}};

}  // namespace

Result<std::uint32_t> read_message_preamble(std::span<const std::byte> bytes, const Limits& limits) {
    if (bytes.size() < kMessagePreambleBytes)
        return fail(MessageErrorType::ProtocolError, "truncated: message preamble needs 8 bytes");
    if (!std::equal(std::begin(kMagic), std::end(kMagic), bytes.begin()))
        return fail(MessageErrorType::ProtocolError, "bad message magic (expected RRAC)");
    auto size = load_le<std::uint32_t>(bytes.data() + 4);
    if (size < kMinMessageSize)
        return fail(MessageErrorType::ProtocolError, "MessageSize " + std::to_string(size) + " smaller than a header");
    if (size > limits.max_message_size)
        return fail(MessageErrorType::BufferLimitViolation, "MessageSize " + std::to_string(size) +
                                                                " over limit " + std::to_string(limits.max_message_size));
    return size;
}

Result<MessageHeaderInfo> decode_message_header(std::span<const std::byte> message, const Limits& limits,
                                                const DecodeContext* context) {
    detail::MessageDecoder decoder(message, nullptr, limits, context);
    ByteReader body;
    MessageHeaderInfo info;
    if (auto ok = decoder.read_header(body, info, info.header); !ok) return ok.take_error();
    if (context && !context->keep_string_table_codes) detail::forget_string_table(info.header);
    return info;
}

Result<Message> decode_message(SharedBytes buffer, const Limits& limits, const DecodeContext* context) {
    return decode_message(std::move(buffer), limits, context, {});
}

Result<Message> decode_message(SharedBytes buffer, const Limits& limits, const DecodeContext* context,
                               std::vector<MessageEntry> storage) {
    // One named result returned on every path: the message is built in the caller's slot.
    Result<Message> out{Message{}};
    out->entries = std::move(storage);
    if (auto ok = decode_message_into(*out, buffer, limits, context); !ok) out = ok.take_error();
    return out;
}

Result<void> decode_message_into(Message& out, const SharedBytes& buffer, const Limits& limits,
                                 const DecodeContext* context) {
    detail::MessageDecoder decoder(buffer.bytes(), &buffer, limits, context);
    ByteReader body;
    MessageHeaderInfo info;
    if (auto ok = decoder.read_header(body, info, out.header); !ok) return ok;
    out.version = info.version;
    if (auto ok = decoder.read_entries(info, out.header, body, out.entries); !ok) return ok;
    if (context && !context->keep_string_table_codes) detail::forget_string_table(out.header);
    return {};
}

namespace detail {

void forget_string_table(MessageHeader& header) noexcept {
    header.string_table.clear();
    if (header.v4_flags) *header.v4_flags &= static_cast<std::uint8_t>(~message_flags::string_table);
}

Result<void> MessageDecoder::read_header(ByteReader& body, MessageHeaderInfo& info, MessageHeader& header) {
    auto size = read_message_preamble(message_, limits_);
    if (!size) return size.take_error();
    if (*size != message_.size())
        return fail(MessageErrorType::ProtocolError, "MessageSize " + std::to_string(*size) + " but " +
                                                         std::to_string(message_.size()) + " bytes given");
    ByteReader r(message_);
    (void)r.skip(kMessagePreambleBytes);
    auto version = r.read_u16();
    if (!version) return version.take_error();
    info.version = version_ = *version;
    info.message_size = *size;
    Result<void> ok;
    if (*version == 2)
        ok = read_header_v2(r, info, header);
    else if (*version == 4)
        ok = read_header_v4(r, info, header);
    else
        return fail(MessageErrorType::ProtocolError, "unknown message version " + std::to_string(*version));
    if (!ok) return ok;
    body = ByteReader(message_.subspan(info.header_size));
    return {};
}

Result<void> MessageDecoder::read_entries(const MessageHeaderInfo& info, const MessageHeader& header, ByteReader& body,
                                          std::vector<MessageEntry>& entries) {
    entries.clear();
    if (info.entry_count > limits_.max_entries)
        return error(MessageErrorType::BufferLimitViolation, body,
                     std::to_string(info.entry_count) + " entries over limit " + std::to_string(limits_.max_entries));
    const std::size_t min_entry = version_ == 2 ? 22 : 5;
    if (auto c = check_count(body, info.entry_count, min_entry, false, "entries"); !c) return c.take_error();
    if (version_ == 4 && !header.string_table.empty()) local_table_ = &header.string_table;
    if (local_table_ && local_table_->size() > kLinearLocalTable) {
        local_index_.reserve(local_table_->size());
        for (std::size_t i = 0; i < local_table_->size(); ++i) local_index_.emplace_back((*local_table_)[i].first, i);
        // CORE keeps the first definition of a duplicated code.
        std::stable_sort(local_index_.begin(), local_index_.end(),
                         [](const auto& a, const auto& b) { return a.first < b.first; });
    }
    entries.resize(info.entry_count);
    for (auto& entry : entries) {
        auto ok = version_ == 2 ? read_entry_v2(body, entry) : read_entry_v4(body, entry);
        if (!ok) return ok.take_error();
    }
    if (!body.at_end())
        return error(MessageErrorType::ProtocolError, body,
                     std::to_string(body.remaining()) + " bytes after the last entry");
    return {};
}

Result<void> MessageDecoder::read_payload(ByteReader& r, MessageElement& e, std::uint32_t data_count,
                                          std::size_t depth, bool numbered_children) {
    if (!is_wire_type(e.type))
        return error(MessageErrorType::ProtocolError, r,
                     "unknown data type " + std::to_string(static_cast<unsigned>(e.type)));
    if (e.type == DataTypes::void_t) {
        if (data_count != 0) return error(MessageErrorType::ProtocolError, r, "void element with DataCount > 0");
    } else if (!is_nested(e.type)) {
        auto bytes = r.take_array(data_count, data_type_size(e.type));
        if (!bytes) return error(MessageErrorType::ProtocolError, r, "array of " + std::to_string(data_count) +
                                                                         " items past the element end");
        e.data = view(*bytes);
    } else {
        if (data_count > 0 && depth >= limits_.max_nesting_depth)
            return error(MessageErrorType::ProtocolError, r, "elements nested deeper than the limit");
        const std::size_t min_element = version_ == 2 ? 16 : 5;
        if (auto c = check_count(r, data_count, min_element, true, "child elements"); !c) return c.take_error();
        e.elements.resize(data_count);
        for (auto& child : e.elements) {
            auto ok = version_ == 2 ? read_element_v2(r, child, depth + 1, numbered_children)
                                    : read_element_v4(r, child, depth + 1);
            if (!ok) return ok.take_error();
        }
    }
    if (!r.at_end())
        return error(MessageErrorType::ProtocolError, r,
                     "element does not end at its ElementSize (" + std::to_string(r.remaining()) + " bytes left)");
    return {};
}

Result<void> MessageDecoder::check_count(const ByteReader& r, std::uint64_t count, std::size_t min_item_bytes,
                                         bool elements, const char* what) {
    if (count > r.remaining() / min_item_bytes)
        return error(MessageErrorType::ProtocolError, r,
                     std::to_string(count) + " " + what + " cannot fit in " + std::to_string(r.remaining()) + " bytes");
    if (elements) {
        if (count > limits_.max_elements - std::min(elements_seen_, limits_.max_elements))
            return error(MessageErrorType::BufferLimitViolation, r,
                         "more than " + std::to_string(limits_.max_elements) + " elements in the message");
        elements_seen_ += count;
    }
    return {};
}

Result<ByteReader> MessageDecoder::sized_part(ByteReader& r, std::uint64_t size, std::size_t consumed,
                                              std::size_t min_size, const char* what) {
    if (size < min_size)
        return error(MessageErrorType::ProtocolError, r,
                     std::string(what) + " " + std::to_string(size) + " smaller than its fixed fields");
    if (size - consumed > r.remaining())
        return error(MessageErrorType::ProtocolError, r,
                     std::string(what) + " " + std::to_string(size) + " past the end of its parent");
    return r.sub_reader(static_cast<std::size_t>(size - consumed));
}

Unexpected MessageDecoder::error(MessageErrorType type, const ByteReader& at, std::string what) const {
    return fail(type, "message v" + std::to_string(version_) + " at offset " + std::to_string(offset_of(at)) +
                          ": " + what);
}

std::size_t MessageDecoder::offset_of(const ByteReader& r) const noexcept {
    return static_cast<std::size_t>(r.bytes().data() - message_.data()) + r.position();
}

SharedBytes MessageDecoder::view(std::span<const std::byte> bytes) const {
    if (bytes.empty() || !owner_) return {};
    return owner_->subspan(static_cast<std::size_t>(bytes.data() - owner_->data()), bytes.size());
}

}  // namespace detail
}  // namespace rr
