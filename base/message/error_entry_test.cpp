#include <catch2/catch.hpp>

#include "base/message/error_entry.hpp"
#include "base/message/message_reader.hpp"
#include "base/message/message_writer.hpp"
#include "base/message/test_vectors.hpp"

using namespace rr;

TEST_CASE("message: an error entry built from an RRError matches wire.md 15.4e byte for byte", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "vec_error_membernotfound_v2.bin");
    Message m;
    m.header.sender_node_id = NodeID::parse("aaaaaaaa-bbbb-cccc-dddd-eeeeeeeeeeee").value();
    m.header.receiver_node_id = NodeID::parse("11111111-2222-3333-4444-555555555555").value();
    m.header.sender_endpoint = 0x0a0b0c0d;
    m.header.receiver_endpoint = 0x01020304;
    MessageEntry e;
    e.entry_type = MessageEntryType::PropertyGetRes;
    e.service_path = "my_service";
    e.member_name = "foo";
    e.request_id = 7;
    e.elements.push_back(make_string_element("value", "replaced"));
    set_entry_error(e, make_error(MessageErrorType::MemberNotFound, "Member not found"));
    m.entries.push_back(e);
    std::vector<std::byte> out;
    REQUIRE(encode_message(m, out));
    CHECK(out == bytes);
}

TEST_CASE("message: error entries carry user error names and sub-names") {
    MessageEntry e;
    e.entry_type = MessageEntryType::FunctionCallRes;
    RRError err;
    err.type = MessageErrorType::RemoteError;
    err.name = "experimental.arm.MotorFault";
    err.message = "motor 3 over temperature";
    err.sub_name = "overtemp";
    set_entry_error(e, err);
    REQUIRE(e.elements.size() == 3);
    CHECK(e.elements[2].name == "errorsubname");
    for (std::uint16_t version : {2, 4}) {
        Message m;
        m.version = version;
        m.entries.push_back(e);
        auto bytes = encode_message(m);
        REQUIRE(bytes);
        auto back = decode_message(*bytes);
        REQUIRE(back);
        auto read = entry_error(back->entries[0]);
        REQUIRE(read);
        CHECK(*read == err);
    }
}

TEST_CASE("message: error entries carry an errorparam element and read it back") {
    MessageEntry e;
    e.entry_type = MessageEntryType::FunctionCallRes;
    RRError err = make_error(MessageErrorType::InvalidOperation, "test error");
    err.sub_name = "my_error";
    auto param = std::make_shared<MessageElement>(make_string_element("any name", "20"));
    err.param = param;
    set_entry_error(e, err);
    REQUIRE(e.elements.size() == 4);
    CHECK(e.elements[3].name == "errorparam");
    CHECK(e.elements[3].type == DataTypes::string_t);
    CHECK(param->name == "any name");  // the error's element is copied, not renamed in place
    for (std::uint16_t version : {2, 4}) {
        Message m;
        m.version = version;
        m.entries.push_back(e);
        auto bytes = encode_message(m);
        REQUIRE(bytes);
        auto back = decode_message(*bytes);
        REQUIRE(back);
        auto read = entry_error(back->entries[0]);
        REQUIRE(read);
        CHECK(read->sub_name == "my_error");
        REQUIRE(read->param);
        CHECK(read->param->name == "errorparam");
        CHECK(std::string(reinterpret_cast<const char*>(read->param->data.data()), read->param->data.size()) == "20");
    }
    MessageEntry plain;
    set_entry_error(plain, make_error(MessageErrorType::InvalidOperation, "no param"));
    CHECK(plain.elements.size() == 2);
    CHECK_FALSE(entry_error(plain)->param);
}

TEST_CASE("message: entry_error maps by code and tolerates missing elements") {
    MessageEntry ok;
    CHECK_FALSE(entry_error(ok));
    MessageEntry bare;
    bare.error = MessageErrorType::StopIteration;
    auto e = entry_error(bare);
    REQUIRE(e);
    CHECK(e->type == MessageErrorType::StopIteration);
    CHECK(e->name == "RobotRaconteur.StopIteration");
    CHECK(e->message.empty());
    // The code decides the type even when CORE sends a non-canonical name (wire.md 5.1).
    MessageEntry odd;
    set_entry_error(odd, make_error(MessageErrorType::ServiceNotFound, "no such service"));
    odd.elements[0] = make_string_element("errorname", "RobotRaconteur.ServiceNotFoundException");
    e = entry_error(odd);
    CHECK(e->type == MessageErrorType::ServiceNotFound);
    CHECK(e->name == "RobotRaconteur.ServiceNotFoundException");
    CHECK(e->message == "no such service");
    // A non-string errorname falls back to the standard name.
    odd.elements[0].type = DataTypes::int32_t;
    CHECK(entry_error(odd)->name == "RobotRaconteur.ServiceNotFound");
}
