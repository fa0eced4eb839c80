// Decoding the shared protocol vectors (wire.md §15) to the documented fields. Every decode goes
// through for_each_split (the stream framer fed at every split offset).
#include <catch2/catch.hpp>

#include <bit>
#include <cstring>

#include "base/codec/endian.hpp"
#include "base/message/error_entry.hpp"
#include "base/message/for_each_split.hpp"
#include "base/message/message_reader.hpp"
#include "base/message/test_vectors.hpp"

using namespace rr;
using rr::test::for_each_split;
using rr::test::text;

namespace {

const NodeID kClient = NodeID::parse("11111111-2222-3333-4444-555555555555").value();
const NodeID kServer = NodeID::parse("aaaaaaaa-bbbb-cccc-dddd-eeeeeeeeeeee").value();

template <class T>
std::vector<T> values(const MessageElement& e) {
    std::vector<T> out;
    const std::size_t n = e.data.size() / sizeof(T);
    for (std::size_t i = 0; i < n; ++i) {
        const std::byte* p = e.data.data() + i * sizeof(T);
        if constexpr (std::is_same_v<T, double>)
            out.push_back(load_le_double(p));
        else if constexpr (std::is_same_v<T, float>)
            out.push_back(load_le_float(p));
        else
            out.push_back(load_le<T>(p));
    }
    return out;
}

/// Runs `check` on the single message decoded from `bytes` at every split offset.
template <class Check>
void check_each_split(const std::vector<std::byte>& bytes, Check check, const DecodeContext* context = nullptr) {
    for_each_split(
        bytes,
        [&](Result<std::vector<Message>> r, std::size_t at) {
            INFO("split at " << at);
            REQUIRE(r);
            REQUIRE(r->size() == 1);
            check((*r)[0]);
        },
        Limits{}, context);
}

// wire.md §15.2 / §15.3: the LITE test message (same content in both versions).
void check_lite_message(const Message& m) {
    const auto& h = m.header;
    CHECK(h.sender_node_id == NodeID::parse("d835c41d-339c-47a8-84db-f00a8fefd2fa").value());
    CHECK(h.receiver_node_id == NodeID::parse("ae78481b-c2be-4f26-9fef-74bb6e8a043f").value());
    CHECK(h.sender_endpoint == 4164376647u);
    CHECK(h.receiver_endpoint == 2805032049u);
    CHECK(h.sender_node_name == "sender_node");
    CHECK(h.receiver_node_name == "recv_node");
    CHECK(h.metadata == "extended_data\nblah blah");
    CHECK(h.message_id == 10);
    CHECK(h.message_res_id == 20);
    REQUIRE(m.entries.size() == 3);

    const auto& e1 = m.entries[0];
    CHECK(e1.entry_type == MessageEntryType::PropertyGetRes);
    CHECK(e1.service_path == "my.service.object[%28abc]");
    CHECK(e1.member_name == "my_member");
    CHECK(e1.request_id == 395728u);
    CHECK(e1.error == MessageErrorType::NullValue);
    CHECK(e1.metadata == "more\nblah\nblah");
    CHECK(e1.elements.empty());

    const auto& e2 = m.entries[1];
    CHECK(e2.entry_type == MessageEntryType::FunctionCallRes);
    CHECK(e2.service_path == "my.service.object[%12542]");
    CHECK(e2.member_name == "my_member2");
    CHECK(e2.request_id == 562846u);
    CHECK(e2.error == MessageErrorType::None);
    CHECK(e2.metadata.empty());
    REQUIRE(e2.elements.size() == 4);
    const auto& el1 = e2.elements[0];
    CHECK(el1.name == "el1");
    CHECK_FALSE(el1.number);
    CHECK(el1.type == DataTypes::double_t);
    CHECK(el1.data_count() == 5);
    CHECK(values<double>(el1) == std::vector<double>{1, 2, 3, 4, 5});
    const auto& el2 = e2.elements[1];
    CHECK(el2.type == DataTypes::string_t);
    CHECK(text(el2.data) == "some random string");
    const auto& el3 = e2.elements[2];
    CHECK(el3.name == "el3");
    CHECK(el3.type == DataTypes::structure_t);
    CHECK(el3.type_name == "some_struct_type");
    CHECK(el3.data.empty());
    REQUIRE(el3.elements.size() == 14);
    const char* names[] = {"sub_doubles", "sub_singles", "sub_int8",   "sub_uint8",   "sub_int16",
                           "sub_uint16",  "sub_int32",   "sub_uint32", "sub_int64",   "sub_uint64",
                           "sub_string",  "sub_cdouble", "sub_csingle", "sub_bool"};
    const DataTypes types[] = {DataTypes::double_t, DataTypes::single_t, DataTypes::int8_t,   DataTypes::uint8_t,
                               DataTypes::int16_t,  DataTypes::uint16_t, DataTypes::int32_t,  DataTypes::uint32_t,
                               DataTypes::int64_t,  DataTypes::uint64_t, DataTypes::string_t, DataTypes::cdouble_t,
                               DataTypes::csingle_t, DataTypes::bool_t};
    for (std::size_t i = 0; i < 14; ++i) {
        INFO("child " << i);
        CHECK(el3.elements[i].name == names[i]);
        CHECK(el3.elements[i].type == types[i]);
        CHECK(el3.elements[i].type_name.empty());
        CHECK(el3.find(names[i]) == &el3.elements[i]);
    }
    CHECK(values<float>(el3.elements[1]) == std::vector<float>{1, 2, 3, 4});
    CHECK(values<std::int8_t>(el3.elements[2]) == std::vector<std::int8_t>{1, 2, 3, 4});
    CHECK(values<std::uint16_t>(el3.elements[5]) == std::vector<std::uint16_t>{1, 2, 3, 4});
    CHECK(values<std::int64_t>(el3.elements[8]) == std::vector<std::int64_t>{1, 2, 3, 4});
    CHECK(values<std::uint64_t>(el3.elements[9]) == std::vector<std::uint64_t>{1, 2, 3, 4});
    CHECK(text(el3.elements[10].data) == "another random string");
    CHECK(el3.elements[11].data_count() == 4);
    CHECK(values<double>(el3.elements[11]) == std::vector<double>{1, 10, 2, 20, 3, 30, 4, 40});
    CHECK(values<float>(el3.elements[12]) == std::vector<float>{1, 10, 2, 20, 3, 30, 4, 40});
    CHECK(values<std::uint8_t>(el3.elements[13]) == std::vector<std::uint8_t>{1, 1, 0, 1});
    const auto& el4 = e2.elements[3];
    CHECK(el4.name == "el4_is_a_very_long_name_it_keeps_going_and_going_and_going");
    CHECK(values<double>(el4) == std::vector<double>{42.345});

    const auto& e3 = m.entries[2];
    CHECK(e3.entry_type == MessageEntryType::StreamOp);
    CHECK(e3.service_path.empty());
    CHECK(e3.member_name.empty());
    CHECK(e3.request_id == 0);
    CHECK(e3.elements.empty());
}

}  // namespace

TEST_CASE("message: LITE message v2 (wire.md 15.2) decodes to its documented fields", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "message2.bin");
    REQUIRE(bytes.size() == 1118);
    check_each_split(bytes, [](const Message& m) {
        CHECK(m.version == 2);
        CHECK_FALSE(m.header.v4_flags);
        check_lite_message(m);
    });
    auto info = decode_message_header(bytes);
    REQUIRE(info);
    CHECK(info->version == 2);
    CHECK(info->message_size == 1118);
    CHECK(info->header_size == 107);
    CHECK(info->entry_count == 3);
    CHECK(info->header.receiver_node_name == "recv_node");
}

TEST_CASE("message: LITE message v4 (wire.md 15.3) decodes to the same fields", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "message4.bin");
    REQUIRE(bytes.size() == 909);
    check_each_split(bytes, [](const Message& m) {
        CHECK(m.version == 4);
        REQUIRE(m.header.v4_flags);
        CHECK(*m.header.v4_flags == 0x53);
        CHECK(m.header.string_table.empty());
        check_lite_message(m);
    });
    auto info = decode_message_header(bytes);
    REQUIRE(info);
    CHECK(info->header_size == 105);
    CHECK(info->entry_count == 3);
}

TEST_CASE("message: decoded payloads are views into the received buffer", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "message2.bin");
    auto buffer = SharedBytes::copy_of(bytes);
    Message m = decode_message(buffer).value();
    const auto& el1 = m.entries[1].elements[0];
    CHECK(el1.data.data() >= buffer.data());
    CHECK(el1.data.data() + el1.data.size() <= buffer.data() + buffer.size());
    CHECK(el1.data.data() == buffer.data() + 177 + 57 + 19);  // entry 2 @177: fixed part 57; el1: fixed part 19
    buffer = SharedBytes();                                   // the message keeps the bytes alive
    CHECK(values<double>(el1) == std::vector<double>{1, 2, 3, 4, 5});
}

TEST_CASE("message: decode_message_into fills a message in place and reuses its entry vector", "[shared]") {
    RR_REQUIRE_VECTOR(v2, "message2.bin");
    RR_REQUIRE_VECTOR(v4, "message4.bin");
    for (const auto* bytes : {&v2, &v4}) {
        auto buffer = SharedBytes::copy_of(*bytes);
        Message m;
        m.entries.reserve(8);
        const MessageEntry* storage = m.entries.data();
        REQUIRE(decode_message_into(m, buffer, {}, nullptr));
        CHECK(m.entries.data() == storage);  // the given vector, not a new one
        CHECK(m == decode_message(buffer).value());
        check_lite_message(m);
    }
    // An error is returned as decode_message returns it; the message is left to be dropped.
    auto cut = SharedBytes::copy_of(std::span<const std::byte>(v4).first(v4.size() - 1));
    Message m;
    auto r = decode_message_into(m, cut, {}, nullptr);
    REQUIRE_FALSE(r);
    CHECK(r.error().type == decode_message(cut).error().type);
    CHECK(r.error().message == decode_message(cut).error().message);
}

TEST_CASE("message: CreateConnection request v2 (wire.md 15.4a)", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "vec_createconnection_req_v2.bin");
    check_each_split(bytes, [](const Message& m) {
        CHECK(m.version == 2);
        CHECK(m.header.sender_node_id == kClient);
        CHECK(m.header.receiver_node_id == NodeID());
        CHECK(m.header.sender_endpoint == 0);
        CHECK(m.header.sender_node_name.empty());
        REQUIRE(m.entries.size() == 1);
        const auto& e = m.entries[0];
        CHECK(e.entry_type == MessageEntryType::StreamOp);
        CHECK(e.member_name == "CreateConnection");
        REQUIRE(e.elements.size() == 1);
        CHECK(e.elements[0].name == "capabilities");
        CHECK(e.elements[0].type == DataTypes::uint32_t);
        CHECK(values<std::uint32_t>(e.elements[0]) == std::vector<std::uint32_t>{0x02000003, 0x04000003, 0x04100007});
    });
}

TEST_CASE("message: CreateConnection reply v2 (wire.md 15.4b)", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "vec_createconnection_res_v2_only.bin");
    check_each_split(bytes, [](const Message& m) {
        CHECK(m.header.sender_node_id == kServer);
        CHECK(m.header.receiver_node_id == kClient);
        CHECK(m.header.sender_node_name == "example.server");
        REQUIRE(m.entries.size() == 1);
        CHECK(m.entries[0].entry_type == MessageEntryType::StreamOpRet);
        CHECK(m.entries[0].member_name == "CreateConnection");
        REQUIRE(m.entries[0].elements.size() == 1);
        CHECK(values<std::uint32_t>(m.entries[0].elements[0]) == std::vector<std::uint32_t>{0x02000003});
    });
}

TEST_CASE("message: ConnectionTest v2 (wire.md 15.4c)", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "vec_connectiontest_v2.bin");
    check_each_split(bytes, [](const Message& m) {
        CHECK(m.header.sender_node_id == kClient);
        REQUIRE(m.entries.size() == 1);
        CHECK(m.entries[0].entry_type == MessageEntryType::ConnectionTest);
        CHECK(m.entries[0].elements.empty());
    });
}

TEST_CASE("message: ConnectClientCombined request v2 (wire.md 15.4d)", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "vec_connectclientcombined_req_v2.bin");
    check_each_split(bytes, [](const Message& m) {
        CHECK(m.header.sender_node_id == kClient);
        CHECK(m.header.receiver_node_id == kServer);
        CHECK(m.header.sender_endpoint == 0x01020304u);
        CHECK(m.header.receiver_endpoint == 0);
        CHECK(m.header.receiver_node_name == "example.server");
        REQUIRE(m.entries.size() == 1);
        const auto& e = m.entries[0];
        CHECK(e.entry_type == MessageEntryType::ConnectClientCombined);
        CHECK(e.service_path == "my_service");
        CHECK(e.request_id == 1);
        REQUIRE(e.elements.size() == 2);
        CHECK(e.find("clientversion"));
        CHECK(text(e.find("clientversion")->data) == "1.2.8");
        CHECK(text(e.find("returnservicedefs")->data) == "true");
    });
}

TEST_CASE("message: error reply v2 (wire.md 15.4e) and its RRError", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "vec_error_membernotfound_v2.bin");
    check_each_split(bytes, [](const Message& m) {
        CHECK(m.header.sender_node_id == kServer);
        CHECK(m.header.sender_endpoint == 0x0a0b0c0du);
        CHECK(m.header.receiver_endpoint == 0x01020304u);
        REQUIRE(m.entries.size() == 1);
        const auto& e = m.entries[0];
        CHECK(e.entry_type == MessageEntryType::PropertyGetRes);
        CHECK(e.service_path == "my_service");
        CHECK(e.member_name == "foo");
        CHECK(e.request_id == 7);
        CHECK(e.error == MessageErrorType::MemberNotFound);
        auto err = entry_error(e);
        REQUIRE(err);
        CHECK(err->type == MessageErrorType::MemberNotFound);
        CHECK(err->name == "RobotRaconteur.MemberNotFound");
        CHECK(err->message == "Member not found");
        CHECK(err->sub_name.empty());
    });
}

TEST_CASE("message: ConnectionTestRet v4 without routing (wire.md 15.4f) takes routing from the context", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "vec_connectiontestret_v4_stripped.bin");
    check_each_split(bytes, [](const Message& m) {
        CHECK(m.version == 4);
        CHECK(*m.header.v4_flags == 0);
        CHECK(m.header.sender_node_id == NodeID());  // no context: all zero
        REQUIRE(m.entries.size() == 1);
        CHECK(m.entries[0].entry_type == MessageEntryType::ConnectionTestRet);
    });
    DecodeContext ctx;
    ctx.local_node_id = kClient;
    ctx.remote_node_id = kServer;
    ctx.local_endpoint = 5;
    ctx.remote_endpoint = 6;
    check_each_split(
        bytes,
        [](const Message& m) {
            CHECK(m.header.sender_node_id == kServer);
            CHECK(m.header.receiver_node_id == kClient);
            CHECK(m.header.sender_endpoint == 6);
            CHECK(m.header.receiver_endpoint == 5);
            CHECK(m.header.sender_node_name.empty());
        },
        &ctx);
}

TEST_CASE("message: list parameter (wire.md 15.4g) decodes to numbered elements in v2 and v4", "[shared]") {
    RR_REQUIRE_VECTOR(v2, "vec_functioncall_list_v2.bin");
    RR_REQUIRE_VECTOR(v4, "vec_functioncall_list_v4.bin");
    auto check = [](const Message& m) {
        REQUIRE(m.entries.size() == 1);
        const auto& e = m.entries[0];
        CHECK(e.entry_type == MessageEntryType::FunctionCallReq);
        CHECK(e.service_path == "my_service.sub[1]");
        CHECK(e.member_name == "fn");
        CHECK(e.request_id == 5);
        REQUIRE(e.elements.size() == 1);
        const auto& x = e.elements[0];
        CHECK(x.name == "x");
        CHECK(x.type == DataTypes::list_t);
        REQUIRE(x.elements.size() == 2);
        CHECK(x.elements[0].number == 0);
        CHECK(x.elements[0].name.empty());
        CHECK(text(x.elements[0].data) == "a");
        CHECK(x.elements[1].number == 1);
        CHECK(text(x.elements[1].data) == "bc");
        CHECK(x.find("0") == nullptr);  // numbers never match names
    };
    check_each_split(v2, check);
    DecodeContext ctx;
    ctx.local_node_id = kServer;
    ctx.remote_node_id = kClient;
    ctx.local_endpoint = 0x0a0b0c0d;
    ctx.remote_endpoint = 0x01020304;
    check_each_split(
        v4,
        [&](const Message& m) {
            check(m);
            CHECK(m.header.sender_node_id == kClient);
            CHECK(m.header.receiver_endpoint == 0x0a0b0c0du);
        },
        &ctx);
}
