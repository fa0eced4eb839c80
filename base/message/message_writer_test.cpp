// Encoding: byte-identical re-encoding of every vector, v2 <-> v4 conversion, CORE's v4 flag rules,
// and the errors encode_message reports.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <span>

#include "base/codec/endian.hpp"
#include "base/message/message_reader.hpp"
#include "base/message/message_writer.hpp"
#include "base/message/test_vectors.hpp"

using namespace rr;
using rr::test::shared;

namespace {

const NodeID kClient = NodeID::parse("11111111-2222-3333-4444-555555555555").value();
const NodeID kServer = NodeID::parse("aaaaaaaa-bbbb-cccc-dddd-eeeeeeeeeeee").value();

std::vector<std::byte> encode(const Message& m) {
    std::vector<std::byte> out;
    auto ok = encode_message(m, out);
    INFO((ok ? std::string() : ok.error().message));
    REQUIRE(ok);
    auto size = encoded_size(m);
    REQUIRE(size);
    CHECK(*size == out.size());
    return out;
}

Message decode(const std::vector<std::byte>& bytes, const DecodeContext* ctx = nullptr) {
    auto m = decode_message(shared(bytes), Limits{}, ctx);
    INFO((m ? std::string() : m.error().message));
    REQUIRE(m);
    return std::move(*m);
}

Message as_version(Message m, std::uint16_t version) {
    m.version = version;
    return m;
}

MessageElement scalar_u32(std::string name, std::uint32_t v) {
    MessageElement e;
    e.name = std::move(name);
    e.type = DataTypes::uint32_t;
    std::array<std::byte, 4> b;
    store_le(b.data(), v);
    e.data = SharedBytes::copy_of(b);
    return e;
}

Message one_entry(MessageEntryType type) {
    Message m;
    m.header.sender_node_id = kClient;
    m.header.receiver_node_id = kServer;
    MessageEntry e;
    e.entry_type = type;
    m.entries.push_back(std::move(e));
    return m;
}

RRError encode_error(const Message& m) {
    std::vector<std::byte> out{std::byte{0x42}};
    auto r = encode_message(m, out);
    REQUIRE_FALSE(r);
    CHECK(out.size() == 1);  // nothing appended on error
    CHECK_FALSE(encoded_size(m));
    return r.error();
}

}  // namespace

TEST_CASE("message: every shared vector re-encodes byte-identical, whole and with its entries given apart", "[shared]") {
    for (const auto& name : rr::test::vector_names())
        if (!rr::test::load_vector(name)) RR_SKIP("shared vector " << rr::test::vector_path(name) << " not found");
    for (const auto& name : rr::test::vector_names()) {
        INFO(name);
        auto bytes = rr::test::load_vector(name);
        REQUIRE(bytes);
        Message m = decode(*bytes);
        CHECK(encode(m) == *bytes);
        // The header alone plus the entries where they are (a session's reply, ServiceSession::reply).
        Message header = m;
        header.entries.clear();
        GatherBuffer out;
        out.append(std::span<const std::byte>(std::array<std::byte, 1>{std::byte{0xEE}}));  // appended after it
        REQUIRE(encode_message(header, std::span<const MessageEntry>(m.entries), out));
        out.flatten();
        REQUIRE(out.owned().front() == std::byte{0xEE});
        CHECK(std::vector<std::byte>(out.owned().begin() + 1, out.owned().end()) == *bytes);
    }
}

TEST_CASE("message: a header with its entries given apart must not carry entries of its own") {
    Message both = one_entry(MessageEntryType::FunctionCallReq);
    GatherBuffer out;
    auto refused = encode_message(both, std::span<const MessageEntry>(both.entries), out);
    REQUIRE_FALSE(refused);
    CHECK(refused.error().type == MessageErrorType::InvalidArgument);
    CHECK(out.empty());
}

TEST_CASE("message: LITE message converts v2 -> v4 and v4 -> v2 byte-identical", "[shared]") {
    RR_REQUIRE_VECTOR(v2, "message2.bin");
    RR_REQUIRE_VECTOR(v4, "message4.bin");
    Message from2 = decode(v2);
    Message from4 = decode(v4);
    CHECK(encode(as_version(from2, 4)) == v4);  // CORE's default flags reproduce 0x53
    CHECK(encode(as_version(from4, 2)) == v2);
    // v2 -> v4 -> v2 and v4 -> v2 -> v4 through bytes.
    CHECK(encode(as_version(decode(encode(as_version(from2, 4))), 2)) == v2);
    CHECK(encode(as_version(decode(encode(as_version(from4, 2))), 4)) == v4);
    // The models agree apart from the recorded v4 flags.
    Message a = as_version(from4, 2);
    a.header.v4_flags.reset();
    CHECK(a == from2);
}

TEST_CASE("message: list parameter (wire.md 15.4g) converts between v2 and v4 without routing", "[shared]") {
    RR_REQUIRE_VECTOR(v2, "vec_functioncall_list_v2.bin");
    RR_REQUIRE_VECTOR(v4, "vec_functioncall_list_v4.bin");
    // The v4 form is what CORE sends on a negotiated connection: routing and endpoints omitted.
    Message from2 = decode(v2);
    Message stripped = as_version(from2, 4);
    stripped.header.v4_flags = std::uint8_t{0};
    CHECK(encode(stripped) == v4);
    // The receiver restores the omitted fields from its connection; then v2 is identical again.
    DecodeContext server;
    server.local_node_id = kServer;
    server.remote_node_id = kClient;
    server.local_endpoint = 0x0a0b0c0d;
    server.remote_endpoint = 0x01020304;
    Message from4 = decode(v4, &server);
    CHECK(encode(as_version(from4, 2)) == v2);
    // v4 -> v2 -> v4 keeps the recorded flags; v2 -> v4 -> v2 uses full routing on the way.
    CHECK(encode(as_version(decode(encode(as_version(from4, 2))), 2)) == v2);
    Message round = as_version(from4, 2);
    CHECK(encode(as_version(round, 4)) == v4);
    CHECK(encode(as_version(decode(encode(as_version(from2, 4))), 2)) == v2);
    // Element numbers: decimal names in v2, ELEMENT_NUMBER (flag 0x04, int_x) in v4.
    CHECK(v4[0x2f] == std::byte{0x04});
    CHECK(v4[0x30] == std::byte{0x00});
}

TEST_CASE("message: ConnectionTestRet with routing omitted (wire.md 15.4f) from a model", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "vec_connectiontestret_v4_stripped.bin");
    Message m = one_entry(MessageEntryType::ConnectionTestRet);
    m.version = 4;
    m.header.v4_flags = std::uint8_t{0};
    CHECK(encode(m) == bytes);
}

TEST_CASE("message: default v4 flags follow CORE's writer") {
    Message m = one_entry(MessageEntryType::PropertyGetReq);
    CHECK(default_v4_flags(m) == (message_flags::routing_info | message_flags::endpoint_info));
    m.header.message_id = 1;
    CHECK(default_v4_flags(m) & message_flags::meta_info);
    m.header.message_id = 0;
    m.header.metadata = "unreliable\n";
    CHECK(default_v4_flags(m) & message_flags::meta_info);
    m.header.metadata.clear();
    m.entries.push_back(MessageEntry{});
    CHECK(default_v4_flags(m) & message_flags::multiple_entries);
    m.entries.clear();
    CHECK(default_v4_flags(m) & message_flags::multiple_entries);  // 0 entries still needs the count
    m.header.extended = "x";
    m.header.priority = 3;
    m.header.string_table = {{1, "foo"}};
    auto f = default_v4_flags(m);
    CHECK(f & message_flags::extended);
    CHECK(f & message_flags::priority);
    CHECK(f & message_flags::string_table);
    CHECK_FALSE(f & message_flags::unreliable);
}

TEST_CASE("message: v4 entry and element flags follow CORE's writer") {
    Message m = one_entry(MessageEntryType::FunctionCallReq);
    m.version = 4;
    m.header.v4_flags = std::uint8_t{0};
    auto& e = m.entries[0];
    e.request_id = 300;
    e.error = MessageErrorType::StopIteration;
    e.metadata = "m";
    MessageElement el = scalar_u32("", 7);
    el.number = -129;
    e.elements.push_back(el);
    MessageElement named = scalar_u32("n", 1);
    named.metadata = "md";
    e.elements.push_back(named);
    auto bytes = encode(m);
    // header: RRAC, size, 04 00, HeaderLen 0c, flags 00; entry @12: size, flags, type
    REQUIRE(bytes.size() > 16);
    CHECK(bytes[10] == std::byte{0x0c});
    CHECK(bytes[11] == std::byte{0x00});
    const std::size_t entry = 12;
    CHECK(bytes[entry + 1] == std::byte{0x01 | 0x04 | 0x10 | 0x20 | 0x40});  // STR, STR, REQUEST_ID, ERROR, META
    Message back = decode(bytes);
    CHECK(back.entries[0].request_id == 300);
    CHECK(back.entries[0].error == MessageErrorType::StopIteration);
    CHECK(back.entries[0].metadata == "m");
    CHECK(back.entries[0].elements[0].number == -129);
    CHECK(back.entries[0].elements[1].metadata == "md");
    CHECK(back.entries == m.entries);
}

TEST_CASE("message: explicit v4 flags are honoured exactly, or refused if they would drop data") {
    Message m = one_entry(MessageEntryType::PropertyGetReq);
    m.version = 4;
    m.header.sender_endpoint = 9;
    m.header.v4_flags = message_flags::routing_info;  // endpoints omitted on purpose
    Message back = decode(encode(m));
    CHECK(back.header.sender_node_id == kClient);
    CHECK(back.header.sender_endpoint == 0);
    m.header.v4_flags = message_flags::routing_info | message_flags::meta_info | message_flags::unreliable;
    back = decode(encode(m));
    CHECK(*back.header.v4_flags == (message_flags::routing_info | message_flags::meta_info | message_flags::unreliable));

    m.header.v4_flags = std::uint8_t{0};
    m.header.message_id = 5;
    CHECK(encode_error(m).type == MessageErrorType::InvalidArgument);
    m.header.message_id = 0;
    m.entries.push_back(MessageEntry{});
    CHECK(encode_error(m).type == MessageErrorType::InvalidArgument);
    m.entries.pop_back();
    m.header.extended = "e";
    CHECK(encode_error(m).type == MessageErrorType::InvalidArgument);
    m.header.extended.clear();
    m.header.priority = 1;
    CHECK(encode_error(m).type == MessageErrorType::InvalidArgument);
    m.header.priority = 0;
    m.header.string_table = {{1, "x"}};
    CHECK(encode_error(m).type == MessageErrorType::InvalidArgument);
}

TEST_CASE("message: v4-only header fields round-trip in v4") {
    Message m = one_entry(MessageEntryType::PropertyGetReq);
    m.version = 4;
    m.header.priority = 0x1234;
    m.header.extended = std::string("\x00\x01\xff", 3);
    m.header.message_id = 65535;
    m.entries[0].extended = "ext";
    MessageElement el = scalar_u32("v", 3);
    el.extended = "el-ext";
    m.entries[0].elements.push_back(el);
    auto bytes = encode(m);
    Message back = decode(bytes);
    CHECK(*back.header.v4_flags == default_v4_flags(m));
    back.header.v4_flags.reset();
    CHECK(back == m);
    CHECK(encode(back) == bytes);
}

TEST_CASE("message: v2 writes element numbers as decimal names") {
    Message m = one_entry(MessageEntryType::PipePacketRet);
    auto& entry = m.entries[0];
    MessageElement ack = scalar_u32("", 12);
    ack.number = -1;
    entry.elements.push_back(ack);
    MessageElement map;
    map.name = "value";
    map.type = DataTypes::vector_t;
    MessageElement item = scalar_u32("ignored", 1);
    item.number = 2147483647;
    map.elements.push_back(item);
    entry.elements.push_back(map);
    auto bytes = encode(m);
    Message back = decode(bytes);
    REQUIRE(back.entries[0].elements.size() == 2);
    CHECK(back.entries[0].elements[0].number == -1);           // PipePacketRet acks are numbered
    CHECK_FALSE(back.entries[0].elements[1].number);           // "value" is a name
    CHECK(back.entries[0].elements[1].elements[0].number == 2147483647);
    CHECK(back.entries[0].elements[1].elements[0].name.empty());
    // A decimal name outside numbered containers stays a name.
    Message s = one_entry(MessageEntryType::FunctionCallReq);
    MessageElement st;
    st.name = "p";
    st.type = DataTypes::structure_t;
    st.type_name = "a.b";
    st.elements.push_back(scalar_u32("5", 5));
    s.entries[0].elements.push_back(scalar_u32("7", 7));
    s.entries[0].elements.push_back(st);
    Message sb = decode(encode(s));
    CHECK(sb.entries[0].elements[0].name == "7");
    CHECK_FALSE(sb.entries[0].elements[0].number);
    CHECK(sb.entries[0].elements[1].elements[0].name == "5");
    // Non-canonical decimal text in a list stays a name, so it re-encodes unchanged.
    Message l = one_entry(MessageEntryType::FunctionCallReq);
    MessageElement list;
    list.name = "l";
    list.type = DataTypes::list_t;
    list.elements.push_back(scalar_u32("01", 1));
    l.entries[0].elements.push_back(list);
    auto lb = encode(l);
    Message lback = decode(lb);
    CHECK(lback.entries[0].elements[0].elements[0].name == "01");
    CHECK(encode(lback) == lb);
}

TEST_CASE("message: encode appends and reports InvalidArgument for what cannot be sent") {
    Message ok = one_entry(MessageEntryType::PropertyGetReq);
    std::vector<std::byte> out{std::byte{1}, std::byte{2}};
    REQUIRE(encode_message(ok, out));
    CHECK(out[0] == std::byte{1});
    CHECK(out[2] == std::byte{'R'});
    CHECK(out.size() == 2 + 86);
    auto frame = encode_message(ok);
    REQUIRE(frame);
    CHECK(frame->size() == 86);

    auto with_element = [&](MessageElement e, std::uint16_t version = 2) {
        Message m = one_entry(MessageEntryType::PropertyGetReq);
        m.version = version;
        m.entries[0].elements.push_back(std::move(e));
        return m;
    };
    MessageElement e;
    e.type = DataTypes::double_t;
    e.data = SharedBytes::copy_of("abc", 3);  // not a multiple of 8
    CHECK(encode_error(with_element(e)).type == MessageErrorType::InvalidArgument);
    e.type = DataTypes::void_t;  // void with data
    CHECK(encode_error(with_element(e, 4)).type == MessageErrorType::InvalidArgument);
    e.type = DataTypes::structure_t;  // nested with raw data
    CHECK(encode_error(with_element(e)).type == MessageErrorType::InvalidArgument);
    e.data = {};
    e.type = DataTypes::varvalue_t;  // robdef-only type
    CHECK(encode_error(with_element(e)).type == MessageErrorType::InvalidArgument);
    e.type = DataTypes::int32_t;  // raw type with children
    e.elements.push_back(MessageElement{});
    CHECK(encode_error(with_element(e)).type == MessageErrorType::InvalidArgument);
    MessageElement coded = scalar_u32("value", 1);
    coded.name_code = 3;  // odd code without a local table
    CHECK(encode_error(with_element(coded, 4)).type == MessageErrorType::InvalidArgument);
    coded.name_code = 6;  // even code not in the standard table
    CHECK(encode_error(with_element(coded, 4)).type == MessageErrorType::InvalidArgument);
    coded.name_code = 516;  // "value": fine in v4, ignored in v2
    CHECK(encode(with_element(coded, 4)).size() < encode(with_element(coded, 2)).size());

    Message big = one_entry(MessageEntryType::PropertyGetReq);
    big.entries[0].member_name.assign(65536, 'x');
    CHECK(encode_error(big).type == MessageErrorType::InvalidArgument);
    big.version = 4;
    CHECK(encode(big).size() > 65536);
    big.version = 3;
    CHECK(encode_error(big).type == MessageErrorType::InvalidArgument);

    Message many;
    many.entries.resize(65536);
    CHECK(encode_error(many).type == MessageErrorType::InvalidArgument);
    many.version = 4;
    CHECK(encode_error(many).type == MessageErrorType::InvalidArgument);
}

TEST_CASE("message: messages appended to one buffer grow it geometrically and stay intact") {
    // A connection's pending output takes message after message while the socket is slow; growing it
    // to the exact size each time would copy all pending bytes once per message.
    Message m = one_entry(MessageEntryType::WirePacket);
    m.entries[0].elements.push_back(scalar_u32("value", 7));
    const auto one = encode(m);
    std::vector<std::byte> out;
    std::size_t reallocations = 0;
    constexpr std::size_t kMessages = 2000;
    for (std::size_t i = 0; i < kMessages; ++i) {
        const auto capacity = out.capacity();
        REQUIRE(encode_message(m, out));
        if (out.capacity() != capacity) ++reallocations;
    }
    REQUIRE(out.size() == kMessages * one.size());
    CHECK(reallocations <= 24);
    for (std::size_t i = 0; i < kMessages; i += 397)
        CHECK(std::equal(one.begin(), one.end(), out.begin() + static_cast<std::ptrdiff_t>(i * one.size())));
}
