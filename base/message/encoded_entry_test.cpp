// EncodedEntry and the writer's encoded-entry path: a message made of a header plus an entry encoded
// once must be byte-identical to the message encoded whole, in both formats and with the v4 header
// variants a session uses; errors are reported, not hidden.
#include <catch2/catch.hpp>

#include <array>
#include <bit>
#include <thread>

#include "base/codec/endian.hpp"
#include "base/message/encoded_entry.hpp"
#include "base/message/message_reader.hpp"
#include "base/message/message_writer.hpp"

using namespace rr;

namespace {

const NodeID kSender = NodeID::parse("11111111-2222-3333-4444-555555555555").value();
const NodeID kReceiver = NodeID::parse("aaaaaaaa-bbbb-cccc-dddd-eeeeeeeeeeee").value();

MessageElement doubles(std::string name, std::initializer_list<double> values) {
    MessageElement e;
    e.name = std::move(name);
    e.type = DataTypes::double_t;
    std::vector<std::byte> bytes(values.size() * 8);
    std::size_t i = 0;
    for (double v : values) store_le(bytes.data() + 8 * i++, std::bit_cast<std::uint64_t>(v));
    e.data = SharedBytes::adopt(std::move(bytes));
    return e;
}

MessageEntry wire_packet() {
    MessageEntry e;
    e.entry_type = MessageEntryType::WirePacket;
    e.service_path = "bench.sub";
    e.member_name = "Ticks";
    e.metadata = "unreliable\n";
    MessageElement time;
    time.name = "packettime";
    time.type = DataTypes::structure_t;
    time.type_name = "RobotRaconteur.TimeSpec";
    time.elements.push_back(doubles("seconds", {1.0}));
    e.elements.push_back(std::move(time));
    e.elements.push_back(doubles("value", {1.5, -2.25, 3.0}));
    return e;
}

Message header(std::uint16_t version) {
    Message m;
    m.version = version;
    m.header.sender_node_id = kSender;
    m.header.receiver_node_id = kReceiver;
    m.header.sender_endpoint = 7;
    m.header.receiver_endpoint = 9;
    m.header.message_id = 42;
    return m;
}

std::vector<std::byte> whole(Message m, const MessageEntry& entry) {
    m.entries.push_back(entry);
    std::vector<std::byte> out;
    REQUIRE(encode_message(m, out));
    return out;
}

std::vector<std::byte> with_encoded(const Message& m, const EncodedEntry& entry) {
    auto bytes = entry.bytes(m.version);
    REQUIRE(bytes);
    std::vector<std::byte> out{std::byte{0xEE}};  // appended after what is there
    REQUIRE(encode_message(m, *bytes, out));
    REQUIRE(out.front() == std::byte{0xEE});
    return {out.begin() + 1, out.end()};
}

}  // namespace

TEST_CASE("A header plus an encoded entry equals the message encoded whole", "[message][encoded_entry]") {
    const EncodedEntry entry(wire_packet());
    for (std::uint16_t version : {std::uint16_t{2}, std::uint16_t{4}}) {
        INFO("version " << version);
        Message m = header(version);
        CHECK(with_encoded(m, entry) == whole(m, entry.entry()));
        m.header.metadata = "unreliable\n";
        m.header.sender_node_name = "gw";
        CHECK(with_encoded(m, entry) == whole(m, entry.entry()));
        if (version == 4) {
            // A negotiated session omits routing and endpoints (CORE's rule for one entry ≥ 500).
            m.header.v4_flags = static_cast<std::uint8_t>(message_flags::meta_info);
            m.header.sender_node_name.clear();
            CHECK(with_encoded(m, entry) == whole(m, entry.entry()));
        }
        // And it decodes to the same entry.
        auto decoded = decode_message(SharedBytes::copy_of(with_encoded(header(version), entry)), Limits{});
        REQUIRE(decoded);
        REQUIRE(decoded->entries.size() == 1);
        CHECK(decoded->entries.front().member_name == "Ticks");
        CHECK(decoded->entries.front().elements.at(1) == entry.entry().elements.at(1));
    }
}

TEST_CASE("EncodedEntry encodes each format once and shares it across threads", "[message][encoded_entry]") {
    const EncodedEntry entry(wire_packet());
    std::array<const std::byte*, 8> seen{};
    std::vector<std::thread> threads;
    for (std::size_t i = 0; i < seen.size(); ++i)
        threads.emplace_back([&, i] {
            auto b = entry.bytes(i % 2 ? 4 : 2);
            seen[i] = b ? b->data() : nullptr;
        });
    for (auto& t : threads) t.join();
    for (std::size_t i = 0; i < seen.size(); ++i) {
        REQUIRE(seen[i] != nullptr);
        CHECK(seen[i] == seen[i % 2]);  // the same buffer every time
    }
    CHECK(seen[0] != seen[1]);
    std::vector<std::byte> direct;
    REQUIRE(encode_entry(entry.entry(), 2, direct));
    auto v2 = entry.bytes(2);
    REQUIRE(v2);
    CHECK(std::vector<std::byte>(v2->begin(), v2->end()) == direct);
}

TEST_CASE("Encoded entries report what cannot be encoded", "[message][encoded_entry]") {
    SECTION("an unknown format") {
        const EncodedEntry entry(wire_packet());
        auto b = entry.bytes(3);
        REQUIRE_FALSE(b);
        CHECK(b.error().type == MessageErrorType::InvalidArgument);
    }
    SECTION("a v2 string over 65535 bytes: v2 fails, every time; v4 works") {
        MessageEntry e = wire_packet();
        e.member_name.assign(70000, 'm');
        const EncodedEntry entry(std::move(e));
        for (int i = 0; i < 2; ++i) {
            auto b = entry.bytes(2);
            REQUIRE_FALSE(b);
            CHECK(b.error().type == MessageErrorType::InvalidArgument);
        }
        CHECK(entry.bytes(4));
    }
    SECTION("a message that has entries of its own") {
        const EncodedEntry entry(wire_packet());
        Message m = header(2);
        m.entries.push_back(entry.entry());
        std::vector<std::byte> out;
        auto ok = encode_message(m, *entry.bytes(2), out);
        REQUIRE_FALSE(ok);
        CHECK(ok.error().type == MessageErrorType::InvalidArgument);
        CHECK(out.empty());
    }
    SECTION("explicit v4 flags that would drop MULTIPLE_ENTRIES hold for the one encoded entry") {
        const EncodedEntry entry(wire_packet());
        Message m = header(4);
        m.header.v4_flags = static_cast<std::uint8_t>(message_flags::meta_info);
        std::vector<std::byte> out;
        CHECK(encode_message(m, *entry.bytes(4), out));
    }
}
