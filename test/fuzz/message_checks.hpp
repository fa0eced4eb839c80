// Checks shared by the message codec fuzz targets (fuzz_message_reader, fuzz_message_structured):
// decode arbitrary bytes as one message and as a stream split at input-dependent offsets, and as a
// stream a host reads in place (read_space). Whatever decodes must encode again, decode to an equal
// model, and encode to the same bytes, gathered (GatherBuffer) or not; a v2 message must also survive
// conversion to v4 and back. Any violation aborts.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <span>
#include <vector>

#include "base/message/message_reader.hpp"
#include "base/message/message_stream_reader.hpp"
#include "base/message/message_writer.hpp"

namespace rr::fuzz {

inline Limits fuzz_limits() {
    Limits l;
    l.max_message_size = 1u << 20;
    l.max_elements = 1u << 16;
    return l;
}

inline Limits roomy_limits() {  // re-decoding our own output: only the structure matters
    Limits l;
    l.max_message_size = 1u << 30;
    l.max_elements = 1u << 20;
    return l;
}

inline void check(bool ok) {
    if (!ok) std::abort();
}

inline void check_round_trip(const Message& m) {
    auto bytes = encode_message(m);
    check(bytes.ok());  // everything the reader accepts is writable
    auto back = decode_message(*bytes, roomy_limits());
    check(back.ok());
    check(*back == m);
    auto again = encode_message(*back);
    check(again.ok() && *again == *bytes);
    // Gathered: the decoded payloads are views into `bytes`, spliced when large; the pieces in order
    // are the same bytes.
    GatherBuffer gathered;
    check(encode_message(*back, gathered).ok() && gathered.size() == bytes->size());
    std::vector<std::byte> joined;
    gathered.for_each_piece([&](std::span<const std::byte> p) { joined.insert(joined.end(), p.begin(), p.end()); });
    check(std::equal(joined.begin(), joined.end(), bytes->bytes().begin(), bytes->bytes().end()));
    if (m.version == 2) {  // v2 -> v4 is lossless
        Message v4 = m;
        v4.version = 4;
        auto b4 = encode_message(v4);
        check(b4.ok());
        auto d4 = decode_message(*b4, roomy_limits());
        check(d4.ok());
        d4->version = 2;
        d4->header.v4_flags.reset();
        check(*d4 == m);
    }
}

inline std::span<const std::byte> as_bytes(const std::uint8_t* data, std::size_t size) {
    return std::as_bytes(std::span<const std::uint8_t>(data, size));
}

/// All checks on one input.
inline void check_message_input(const std::uint8_t* data, std::size_t size) {
    const Limits limits = fuzz_limits();
    const auto input = as_bytes(data, size);

    // 1. The whole input as one message.
    const SharedBytes buffer = SharedBytes::copy_of(input);
    auto m = decode_message(buffer, limits);
    auto header = decode_message_header(input, limits);
    if (m) {
        check(header.ok() && header->version == m->version && header->header == m->header);
        check_round_trip(*m);
    }
    // A connection context only fills omitted fields and may forbid standard codes: never more lenient.
    DecodeContext ctx;
    ctx.local_endpoint = 7;
    ctx.remote_endpoint = 9;
    ctx.standard_string_table = false;
    if (decode_message(buffer, limits, &ctx)) check(m.ok());
    // A connection's decode resolves string-table codes and keeps none (wire.md §2.6): each entry then
    // travels alone in a message of its own, with the same strings as the decode that keeps codes.
    DecodeContext connection;
    connection.keep_string_table_codes = false;
    if (auto plain = decode_message(buffer, limits, &connection)) {
        check(m.ok() && plain->entries.size() == m->entries.size() && plain->header.string_table.empty());
        for (std::size_t i = 0; i < plain->entries.size(); ++i) {
            const MessageEntry& e = plain->entries[i];
            check(!e.service_path_code && !e.member_name_code && e.member_name == m->entries[i].member_name &&
                  e.service_path == m->entries[i].service_path);
            Message alone;
            alone.version = 4;
            alone.entries.push_back(e);
            auto bytes = encode_message(alone);
            check(bytes.ok());
            auto back = decode_message(*bytes, roomy_limits());
            check(back.ok() && back->entries.size() == 1 && back->entries[0] == e);
        }
    } else {
        check(!m.ok());
    }

    // 2. The input as a stream, fed in three parts.
    const std::size_t a = size ? (data[0] * size) / 256 : 0;
    const std::size_t b = size ? a + ((data[size - 1] * (size - a)) / 256) : 0;
    MessageStreamReader reader(limits);
    bool ok = reader.feed(input.first(a)).ok() && reader.feed(input.subspan(a, b - a)).ok() &&
              reader.feed(input.subspan(b)).ok();
    while (ok) {
        auto next = reader.take_message();
        if (!next) {
            ok = false;
            break;
        }
        if (!*next) break;
        check_round_trip(**next);
    }
    if (!ok) {  // failed readers stay failed
        check(reader.failed());
        check(!reader.feed(input.first(std::min<std::size_t>(size, 1))).ok());
        check(!reader.take_frame());
    }

    // 3. The input as a host reads it: into read_space() when offered (a large message's own buffer),
    // else in chunks through its own buffer. Same frames, same verdict as one feed of everything.
    MessageStreamReader whole(limits), in_place(limits);
    const bool whole_ok = whole.feed(input).ok();
    bool place_ok = true;
    for (std::size_t at = 0; at < size && place_ok;) {
        auto space = in_place.read_space();
        const std::size_t n = std::min(size - at, space.empty() ? std::size_t{4096} : space.size());
        if (space.empty()) {
            place_ok = in_place.feed(input.subspan(at, n)).ok();
        } else {
            check(in_place.partial_capacity() <= std::max<std::size_t>(64 * 1024, 4 * in_place.partial_bytes()));
            std::copy_n(input.begin() + static_cast<std::ptrdiff_t>(at), n, space.begin());
            place_ok = in_place.feed(space.first(n)).ok();
        }
        at += n;
    }
    check(place_ok == whole_ok);
    if (whole_ok) {
        check(in_place.partial_bytes() == whole.partial_bytes());
        while (auto f = whole.take_frame()) {
            auto g = in_place.take_frame();
            check(g.has_value() && *g == *f);
        }
        check(!in_place.take_frame());
    }
}

}  // namespace rr::fuzz
