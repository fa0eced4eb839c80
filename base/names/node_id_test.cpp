#include <catch2/catch.hpp>

#include "base/names/node_id.hpp"

using namespace rr;

TEST_CASE("NodeID parses the text forms and prints lower case") {
    for (const char* text : {"{D835C41D-339C-47A8-84DB-F00A8FEFD2FA}", "d835c41d-339c-47a8-84db-f00a8fefd2fa",
                             "d835c41d339c47a884dbf00a8fefd2fa"}) {
        auto id = NodeID::parse(text);
        REQUIRE(id);
        CHECK(id->to_string() == "d835c41d-339c-47a8-84db-f00a8fefd2fa");
        CHECK(id->bytes()[0] == std::byte{0xd8});
        CHECK(id->bytes()[15] == std::byte{0xfa});
    }
    CHECK(NodeID().is_any());
    CHECK(NodeID().to_braced_string() == "{00000000-0000-0000-0000-000000000000}");
}

TEST_CASE("NodeID rejects malformed text") {
    for (const char* text : {"", "{}", "d835c41d-339c-47a8-84db-f00a8fefd2f", "g835c41d339c47a884dbf00a8fefd2fa",
                             "d835c41d+339c-47a8-84db-f00a8fefd2fa"}) {
        CHECK_FALSE(NodeID::parse(text));
    }
}
