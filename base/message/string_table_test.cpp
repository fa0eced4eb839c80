#include <catch2/catch.hpp>

#include "base/message/message_reader.hpp"
#include "base/message/message_writer.hpp"
#include "base/message/string_table.hpp"

using namespace rr;

TEST_CASE("message: standard string table lookups (wire.md 2.6)") {
    CHECK(standard_string_for_code(0) == std::string_view(""));
    CHECK(standard_string_for_code(16) == std::string_view("capabilities"));
    CHECK(standard_string_for_code(136) == std::string_view("nodeid"));
    CHECK(standard_string_for_code(140) == std::string_view("nodeid"));
    CHECK(standard_string_for_code(308) == std::string_view("urgent"));
    CHECK(standard_string_for_code(512) == std::string_view("username"));
    CHECK(standard_string_for_code(648) == std::string_view("fiberid"));
    for (std::uint32_t missing : {1u, 2u, 6u, 312u, 508u, 652u, 0x80000000u})
        CHECK_FALSE(standard_string_for_code(missing));
    CHECK(standard_code_for_string("") == 0u);
    CHECK(standard_code_for_string("nodeid") == 136u);
    CHECK(standard_code_for_string("ServiceIndex") == 268u);
    CHECK(standard_code_for_string("RobotRaconteurServiceIndex.ServiceInfo") == 576u);
    CHECK_FALSE(standard_code_for_string("Nodeid"));
}

namespace {

Message sample() {
    Message m;
    m.version = 4;
    MessageEntry e;
    e.entry_type = MessageEntryType::StreamOp;
    e.member_name = "CreateConnection";
    MessageElement caps;
    caps.name = "capabilities";
    caps.type = DataTypes::uint32_t;
    caps.data = SharedBytes::copy_of("\x03\x00\x00\x02", 4);
    e.elements.push_back(caps);
    MessageElement s;
    s.name = "my_struct_field";
    s.type = DataTypes::structure_t;
    s.type_name = "experimental.demo.Point";
    MessageElement listed;
    listed.number = 0;
    listed.type = DataTypes::void_t;
    s.elements.push_back(listed);
    MessageElement again;
    again.name = "my_struct_field";
    again.type = DataTypes::void_t;
    s.elements.push_back(again);
    e.elements.push_back(s);
    m.entries.push_back(e);
    return m;
}

}  // namespace

TEST_CASE("message: apply_string_table replaces strings the way CORE's sender does") {
    Message m = sample();
    auto plain = encode_message(m);
    REQUIRE(plain);
    apply_string_table(m, StringTableOptions{});
    const auto& e = m.entries[0];
    CHECK(e.member_name_code == 40u);   // CreateConnection
    CHECK(e.service_path_code == 0u);   // "" is code 0 in the standard table
    CHECK(e.elements[0].name_code == 16u);
    // Local codes in first-use order: member, path, then elements depth-first.
    CHECK(e.elements[1].name_code == 1u);
    CHECK(e.elements[1].type_name_code == 3u);
    CHECK_FALSE(e.elements[1].elements[0].name_code);  // numbered: no name to replace
    CHECK(e.elements[1].elements[1].name_code == 1u);  // same string, same code
    CHECK(m.header.string_table ==
          std::vector<std::pair<std::uint32_t, std::string>>{{1, "my_struct_field"}, {3, "experimental.demo.Point"}});
    CHECK(e.member_name == "CreateConnection");  // strings stay filled in
    auto coded = encode_message(m);
    REQUIRE(coded);
    CHECK(coded->size() < plain->size());
    auto back = decode_message(*coded);
    REQUIRE(back);
    CHECK(*back->header.v4_flags & message_flags::string_table);
    back->header.v4_flags.reset();
    CHECK(*back == m);
    // v2 ignores codes: same bytes as before.
    m.version = 2;
    Message v2 = sample();
    v2.version = 2;
    CHECK(*encode_message(m) == *encode_message(v2));

    // A message that already has a local table is left alone.
    Message once = m;
    apply_string_table(once, StringTableOptions{});
    CHECK(once == m);

    clear_string_table_codes(m);
    m.version = 4;
    CHECK(m == sample());
}

TEST_CASE("message: apply_string_table honours the negotiated tables and CORE's size bounds") {
    Message standard_only = sample();
    apply_string_table(standard_only, StringTableOptions{true, false});
    CHECK(standard_only.header.string_table.empty());
    CHECK(standard_only.entries[0].elements[0].name_code == 16u);
    CHECK_FALSE(standard_only.entries[0].elements[1].name_code);

    Message local_only = sample();
    apply_string_table(local_only, StringTableOptions{false, true});
    CHECK(local_only.entries[0].member_name_code == 1u);  // not in a table we may use: local
    CHECK(local_only.entries[0].service_path_code == 3u);

    Message m;
    m.version = 4;
    m.header.v4_flags = std::uint8_t{0};
    MessageEntry e;
    e.member_name.assign(129, 'm');  // over 128 bytes: never replaced
    for (int i = 0; i < 20; ++i) {
        MessageElement el;
        el.name = std::string(100, static_cast<char>('a' + i));  // 20 × 102 bytes > 1024
        e.elements.push_back(el);
    }
    m.entries.push_back(e);
    apply_string_table(m, StringTableOptions{});
    CHECK_FALSE(m.entries[0].member_name_code);
    std::size_t table_bytes = 0;
    for (const auto& [code, s] : m.header.string_table) table_bytes += 1 + 1 + s.size();
    CHECK(table_bytes <= kMaxLocalStringTableBytes);
    CHECK(m.header.string_table.size() == 10);  // 10 × 102 = 1020 bytes
    CHECK(m.entries[0].elements[9].name_code == 19u);
    CHECK_FALSE(m.entries[0].elements[10].name_code);
    CHECK(*m.header.v4_flags == message_flags::string_table);  // explicit flags gain STRING_TABLE
    auto bytes = encode_message(m);
    REQUIRE(bytes);
    auto back = decode_message(*bytes);
    REQUIRE(back);
    CHECK(back->entries == m.entries);
}

namespace {

// `sample()` as a peer with string tables sends it: standard and message-local codes (wire.md 2.6),
// the local table bigger than the decoder's small-table bound when `long_table` is set.
SharedBytes coded_sample(bool long_table) {
    Message m = sample();
    if (long_table)
        for (int i = 0; i < 20; ++i) {
            MessageElement el;
            el.name = "field_" + std::to_string(i);
            el.type = DataTypes::void_t;
            m.entries[0].elements.push_back(el);
        }
    apply_string_table(m, StringTableOptions{});
    REQUIRE(m.header.string_table.size() == (long_table ? 22u : 2u));
    auto bytes = encode_message(m);
    REQUIRE(bytes);
    return *bytes;
}

bool has_codes(const MessageElement& e) {
    if (e.name_code || e.type_name_code) return true;
    for (const auto& c : e.elements)
        if (has_codes(c)) return true;
    return false;
}

bool has_codes(const MessageEntry& e) {
    if (e.service_path_code || e.member_name_code) return true;
    for (const auto& c : e.elements)
        if (has_codes(c)) return true;
    return false;
}

}  // namespace

TEST_CASE("message: a connection's decoder resolves string-table codes and keeps none (wire.md 2.6)") {
    for (bool long_table : {false, true}) {
        INFO("local table longer than the decoder's linear bound: " << long_table);
        const SharedBytes coded = coded_sample(long_table);
        DecodeContext connection;
        connection.keep_string_table_codes = false;
        auto m = decode_message(coded, {}, &connection);
        REQUIRE(m);
        REQUIRE(m->entries.size() == 1);
        const MessageEntry& e = m->entries[0];
        CHECK_FALSE(has_codes(e));
        CHECK(m->header.string_table.empty());
        REQUIRE(m->header.v4_flags);
        CHECK_FALSE(*m->header.v4_flags & message_flags::string_table);
        // Every name is the sender's text.
        CHECK(e.member_name == "CreateConnection");
        CHECK(e.service_path.empty());
        CHECK(e.elements[0].name == "capabilities");
        CHECK(e.elements[1].name == "my_struct_field");
        CHECK(e.elements[1].type_name == "experimental.demo.Point");
        CHECK(e.elements[1].elements[1].name == "my_struct_field");
        if (long_table) CHECK(e.elements.back().name == "field_19");
        Message plain = sample();
        CHECK(e.elements[0] == plain.entries[0].elements[0]);
        CHECK(e.elements[1] == plain.entries[0].elements[1]);

        // The entry travels in another message, alone or fanned out (encode_entry), in either format,
        // and reads back the same: with its codes kept, its local codes are defined nowhere.
        for (std::uint16_t version : {std::uint16_t{4}, std::uint16_t{2}}) {
            Message forward;
            forward.version = version;
            forward.entries.push_back(e);
            auto bytes = encode_message(forward);
            REQUIRE(bytes);
            auto back = decode_message(*bytes);
            REQUIRE(back);
            if (version == 4) {
                CHECK(back->entries == forward.entries);
            } else {  // v2 writes the struct's numbered child as a name "0": compare the names only
                CHECK(back->entries[0].member_name == "CreateConnection");
                CHECK(back->entries[0].elements[1].type_name == "experimental.demo.Point");
                CHECK(back->entries[0].elements[1].elements[1].name == "my_struct_field");
            }
            std::vector<std::byte> alone;
            CHECK(encode_entry(e, version, alone));
        }

        // Without a context (or with the default one) the codes stay, for byte-identical re-encoding.
        auto kept = decode_message(coded);
        REQUIRE(kept);
        CHECK(has_codes(kept->entries[0]));
        CHECK(*encode_message(*kept) == coded);
        Message forward_kept;
        forward_kept.version = 4;
        forward_kept.entries.push_back(kept->entries[0]);
        auto refused = encode_message(forward_kept);
        REQUIRE_FALSE(refused);
        CHECK(refused.error().message.find("is not defined") != std::string::npos);

        // The header-only decode drops the table too.
        auto header = decode_message_header(coded.bytes(), {}, &connection);
        REQUIRE(header);
        CHECK(header->header.string_table.empty());
        CHECK_FALSE(*header->header.v4_flags & message_flags::string_table);
    }
}

TEST_CASE("message: resolving codes keeps CORE's rules: first definition wins, unknown codes refused") {
    for (std::size_t extra : {std::size_t{0}, std::size_t{30}}) {
        INFO("extra table entries: " << extra);
        Message m;
        m.version = 4;
        MessageEntry e;
        e.entry_type = MessageEntryType::PropertyGetReq;
        e.member_name = "first";
        e.member_name_code = 5;
        e.service_path = "svc";
        e.service_path_code = 7;
        m.entries.push_back(e);
        for (std::size_t i = 0; i < extra; ++i) m.header.string_table.emplace_back(101 + 2 * i, "x" + std::to_string(i));
        m.header.string_table.emplace_back(5, "first");
        m.header.string_table.emplace_back(7, "svc");
        m.header.string_table.emplace_back(5, "second");  // a duplicate: CORE keeps the first
        auto bytes = encode_message(m);
        REQUIRE(bytes);
        DecodeContext connection;
        connection.keep_string_table_codes = false;
        auto back = decode_message(*bytes, {}, &connection);
        REQUIRE(back);
        CHECK(back->entries[0].member_name == "first");
        CHECK(back->entries[0].service_path == "svc");
        CHECK_FALSE(back->entries[0].member_name_code);

        // A code the message's table lacks is a protocol error (CORE: "Invalid local string table code").
        Message bad = m;
        bad.entries[0].member_name_code = 9;
        bad.header.string_table.emplace_back(9, "nine");
        auto bad_bytes = encode_message(bad);
        REQUIRE(bad_bytes);
        auto raw = bad_bytes->bytes();
        std::vector<std::byte> patched(raw.begin(), raw.end());
        // Rename code 9 in the table to 11 so the entry's 9 is undefined (the table is in the header).
        bool renamed = false;
        for (std::size_t i = 0; i + 5 < patched.size(); ++i)
            if (patched[i] == std::byte{9} && patched[i + 1] == std::byte{4} && patched[i + 2] == std::byte{'n'}) {
                patched[i] = std::byte{11};
                renamed = true;
                break;
            }
        REQUIRE(renamed);
        auto refused = decode_message(SharedBytes::copy_of(std::span<const std::byte>(patched)), {}, &connection);
        REQUIRE_FALSE(refused);
        CHECK(refused.error().type == MessageErrorType::ProtocolError);
        CHECK(refused.error().message.find("unknown local string table code 9") != std::string::npos);
    }
}
