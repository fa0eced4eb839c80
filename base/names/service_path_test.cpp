#include <catch2/catch.hpp>

#include "base/names/service_path.hpp"

using namespace rr;

TEST_CASE("service path index encoding follows CORE (wire.md 15.5)") {
    CHECK(encode_service_path_index("(abc") == "%28abc");
    CHECK(encode_service_path_index("my_key") == "my%5fkey");
    CHECK(encode_service_path_index(-1) == "%2d1");
    CHECK(encode_service_path_index(12) == "12");
    CHECK(*decode_service_path_index("my%5fkey") == "my_key");
    CHECK_FALSE(decode_service_path_index("ab%2"));
    CHECK_FALSE(decode_service_path_index("ab%zz"));
}

TEST_CASE("split and rewrite service paths") {
    auto s = split_service_path("my.service.object[%28abc]");
    REQUIRE(s);
    REQUIRE(s->size() == 3);
    CHECK((*s)[2].name == "object");
    CHECK((*s)[2].index == "(abc");
    CHECK(join_service_path("svc.a", "b", "my_key") == "svc.a.b[my%5fkey]");
    CHECK(replace_service_name("svc.a[1].b", "dev") == "dev.a[1].b");
    CHECK(replace_service_name("svc", "dev") == "dev");
    CHECK(service_name_of("svc.a") == "svc");
    CHECK_FALSE(split_service_path(""));
    CHECK_FALSE(split_service_path("a..b"));
    CHECK_FALSE(split_service_path("a.b[x"));
    CHECK_FALSE(split_service_path("a.b[]"));
    CHECK_FALSE(split_service_path("a.b-c"));
}
