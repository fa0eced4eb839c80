#include <catch2/catch.hpp>

#include "core/message/message_reader.hpp"
#include "core/message/message_writer.hpp"
#include "core/message/string_table.hpp"

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
