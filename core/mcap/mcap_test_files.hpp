// Test helper (not part of rr_mcap): writes small MCAP recordings into memory and reads them back.
#pragma once

#include <catch2/catch.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "core/mcap/mcap_reader.hpp"
#include "core/mcap/mcap_writer.hpp"

namespace rr::mcap::test {

inline std::vector<std::byte> bytes_of(std::string_view s) {
    std::vector<std::byte> out(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) out[i] = static_cast<std::byte>(s[i]);
    return out;
}

/// The payload of message i on a channel: varied lengths, so chunks fill at odd places.
inline std::vector<std::byte> payload(std::uint16_t channel, std::uint32_t i) {
    return bytes_of("{\"ch\":" + std::to_string(channel) + ",\"i\":" + std::to_string(i) + ",\"pad\":\"" +
                    std::string(i % 37, 'x') + "\"}");
}

/// Writes a schema, two channels and `count` messages alternating between them (log_time 1000 + 10*i ns);
/// returns the messages written, in write order. Leaves the writer open (no close()).
inline std::vector<Message> write_sample(McapWriter& w, std::uint32_t count) {
    REQUIRE(w.open());
    auto schema = w.add_schema("experimental.sample", "jsonschema", bytes_of("{\"type\":\"object\"}"));
    REQUIRE(schema);
    auto a = w.add_channel(*schema, "dev/a", "json", {{"member", "a"}, {"device", "dev"}});
    auto b = w.add_channel(0, "dev/b", "robotraconteur", {});
    REQUIRE(a);
    REQUIRE(b);
    std::vector<Message> written;
    for (std::uint32_t i = 0; i < count; ++i) {
        Message m;
        m.channel_id = i % 2 ? *b : *a;
        m.sequence = i / 2;
        m.log_time = 1000 + 10ull * i;
        m.publish_time = m.log_time - 1;
        m.data = payload(m.channel_id, i);
        REQUIRE(w.write(MessageView{m.channel_id, m.sequence, m.log_time, m.publish_time, m.data}));
        written.push_back(std::move(m));
    }
    return written;
}

/// Every message the iterator yields; fails the test on an error.
inline std::vector<Message> drain(MessageIterator it) {
    std::vector<Message> out;
    for (;;) {
        auto m = it.next();
        INFO((m ? std::string() : m.error().message));
        REQUIRE(m);
        if (!*m) return out;
        out.push_back(std::move(**m));
    }
}

}  // namespace rr::mcap::test
