#include "base/message/message_writer.hpp"

#include <algorithm>
#include <limits>
#include <string>
#include <type_traits>

#include "base/codec/varint.hpp"
#include "base/message/message_encoder.hpp"

namespace rr {

std::uint8_t default_v4_flags(const Message& message) noexcept {
    return default_v4_flags(message.header, message.entries.size());
}

std::uint8_t default_v4_flags(const MessageHeader& h, std::size_t entry_count) noexcept {
    std::uint8_t f = message_flags::routing_info | message_flags::endpoint_info;
    if (!h.metadata.empty() || h.message_id != 0 || h.message_res_id != 0) f |= message_flags::meta_info;
    if (entry_count != 1) f |= message_flags::multiple_entries;
    if (!h.string_table.empty()) f |= message_flags::string_table;
    if (!h.extended.empty()) f |= message_flags::extended;
    if (h.priority != 0) f |= message_flags::priority;
    return f;
}

Result<std::size_t> encoded_size(const Message& message) {
    detail::MessageEncoder encoder(message);
    auto size = encoder.measure();
    if (!size) return size.take_error();
    return std::size_t{*size};
}

namespace {

// Reserves for `copied` more bytes with geometric growth: `out` may be a connection's pending output
// that many messages are appended to.
void reserve_for(std::vector<std::byte>& out, std::size_t copied) {
    const std::size_t start = out.size();
    if (out.capacity() - start < copied) out.reserve(std::max<std::size_t>(start + copied, 2 * out.capacity()));
}

template <class Write>
Result<void> write_contiguous(std::vector<std::byte>& out, std::size_t size, Write&& write) {
    const std::size_t start = out.size();
    reserve_for(out, size);
    ByteWriter w(out);
    write(w);
    if (w.written() != size) {  // measure and write disagree: a bug here, never the caller's
        out.resize(start);
        return fail(MessageErrorType::InternalError, "message writer size mismatch");
    }
    return {};
}

// Measures, reserves once, writes. Into a GatherBuffer only the bytes it does not splice are reserved;
// a message with nothing to splice (every small one) takes the contiguous path.
template <class Out, class Measure, class Write>
Result<void> append_measured(Out& out, const detail::MessageEncoder& encoder, Measure&& measure, Write&& write) {
    auto size = measure();
    if (!size) return size.take_error();
    if constexpr (std::is_same_v<Out, GatherBuffer>) {
        if (encoder.spliced_bytes() == 0) return write_contiguous(out.owned(), *size, write);
        const auto mark = out.mark();
        reserve_for(out.owned(), static_cast<std::size_t>(*size - encoder.spliced_bytes()));
        ByteWriter w(out);
        write(w);
        if (w.written() != *size) {
            out.rollback(mark);
            return fail(MessageErrorType::InternalError, "message writer size mismatch");
        }
        return {};
    } else {
        return write_contiguous(out, *size, write);
    }
}

template <class Out>
Result<void> encode_message_into(const Message& message, Out& out) {
    detail::MessageEncoder encoder(message);
    return append_measured(out, encoder, [&] { return encoder.measure(); }, [&](ByteWriter& w) { encoder.write(w); });
}

template <class Out>
Result<void> encode_message_with_entry(const Message& message, SharedBytes encoded_entry, Out& out) {
    if (!message.entries.empty())
        return fail(MessageErrorType::InvalidArgument, "a message with an encoded entry has no other entries");
    detail::MessageEncoder encoder(message, std::move(encoded_entry));
    return append_measured(out, encoder, [&] { return encoder.measure(); }, [&](ByteWriter& w) { encoder.write(w); });
}

}  // namespace

Result<void> encode_message(const Message& message, std::vector<std::byte>& out) {
    return encode_message_into(message, out);
}

Result<void> encode_message(const Message& message, GatherBuffer& out) { return encode_message_into(message, out); }

Result<void> encode_entry(const MessageEntry& entry, std::uint16_t version, std::vector<std::byte>& out) {
    static const Message no_header;
    detail::MessageEncoder encoder(no_header);
    return append_measured(
        out, encoder, [&] { return encoder.measure_entry(entry, version); },
        [&](ByteWriter& w) { encoder.write_entry(w, entry, version); });
}

Result<void> encode_message(const Message& message, std::span<const std::byte> encoded_entry,
                            std::vector<std::byte>& out) {
    return encode_message_with_entry(message, SharedBytes(nullptr, encoded_entry), out);
}

Result<void> encode_message(const Message& message, const SharedBytes& encoded_entry, GatherBuffer& out) {
    return encode_message_with_entry(message, encoded_entry, out);
}

Result<void> encode_message(const Message& header, std::span<const MessageEntry> entries, GatherBuffer& out) {
    if (!header.entries.empty())
        return fail(MessageErrorType::InvalidArgument, "a message with entries given apart has no entries of its own");
    detail::MessageEncoder encoder(header, entries);
    return append_measured(out, encoder, [&] { return encoder.measure(); }, [&](ByteWriter& w) { encoder.write(w); });
}

Result<SharedBytes> encode_message(const Message& message) {
    std::vector<std::byte> out;
    if (auto ok = encode_message(message, out); !ok) return ok.take_error();
    return SharedBytes::adopt(std::move(out));
}

namespace detail {

std::uint64_t xlen_size(std::size_t n) noexcept {
    return n <= 0xFFFFFFFFu ? uint_x_size(static_cast<std::uint32_t>(n)) + std::uint64_t{n} : std::uint64_t{n} + 9;
}

Result<std::uint32_t> MessageEncoder::measure() {
    if (entries_.size() > 0xFFFF)
        return fail(MessageErrorType::InvalidArgument, std::to_string(entries_.size()) + " entries (max 65535)");
    size_count_ = 0;
    more_sizes_.clear();
    spliced_ = 0;
    count_splice(encoded_entry_);
    if (m_.version != 2 && m_.version != 4)
        return fail(MessageErrorType::InvalidArgument, "unknown message version " + std::to_string(m_.version));
    auto total = m_.version == 2 ? measure_v2() : measure_v4();
    if (!total) return total.take_error();
    total_ = *total;
    return *total;
}

Result<std::uint32_t> MessageEncoder::measure_entry(const MessageEntry& entry, std::uint16_t version) {
    size_count_ = 0;
    more_sizes_.clear();
    spliced_ = 0;
    local_codes_.clear();
    if (version != 2 && version != 4)
        return fail(MessageErrorType::InvalidArgument, "unknown message version " + std::to_string(version));
    auto size = version == 2 ? measure_entry_v2(entry) : measure_entry_v4(entry);
    if (!size) return size.take_error();
    return static_cast<std::uint32_t>(*size);
}

void MessageEncoder::write_entry(ByteWriter& w, const MessageEntry& entry, std::uint16_t version) {
    cursor_ = 0;
    if (version == 2)
        write_entry_v2(w, entry);
    else
        write_entry_v4(w, entry);
}

void MessageEncoder::write(ByteWriter& w) {
    cursor_ = 0;
    if (m_.version == 2)
        write_v2(w);
    else
        write_v4(w);
}

Result<std::uint64_t> MessageEncoder::check_payload(const MessageElement& e) const {
    if (!is_wire_type(e.type))
        return fail(MessageErrorType::InvalidArgument,
                    "element type " + std::to_string(static_cast<unsigned>(e.type)) + " cannot be sent");
    if (is_nested(e.type)) {
        if (!e.data.empty())
            return fail(MessageErrorType::InvalidArgument, "nested element '" + e.name + "' with raw data");
        if (e.elements.size() > 0xFFFFFFFFu)
            return fail(MessageErrorType::InvalidArgument, "too many child elements");
        return std::uint64_t{0};
    }
    if (!e.elements.empty())
        return fail(MessageErrorType::InvalidArgument, "element '" + e.name + "' of a raw type with children");
    if (e.type == DataTypes::void_t) {
        if (!e.data.empty()) return fail(MessageErrorType::InvalidArgument, "void element '" + e.name + "' with data");
        return std::uint64_t{0};
    }
    const std::size_t item = data_type_size(e.type);
    if (e.data.size() % item != 0)
        return fail(MessageErrorType::InvalidArgument, "element '" + e.name + "' data size " +
                                                           std::to_string(e.data.size()) + " not a multiple of " +
                                                           std::to_string(item));
    if (e.data.size() / item > 0xFFFFFFFFu)
        return fail(MessageErrorType::InvalidArgument, "element '" + e.name + "' has over 2^32 items");
    return std::uint64_t{e.data.size()};
}

std::size_t MessageEncoder::reserve_size_slot() {
    if (size_count_ < kInlineSizes)
        inline_sizes_[size_count_] = 0;
    else
        more_sizes_.push_back(0);
    return size_count_++;
}

std::uint32_t MessageEncoder::next_size() { return size_slot(cursor_++); }

}  // namespace detail
}  // namespace rr
