// Whatever unpack accepts from a corrupted element can be shown as JSON, and that JSON reads back to a
// value with the same JSON.
#include <catch2/catch.hpp>

#include "core/json/value_json.hpp"
#include "core/value/test_mutations.hpp"
#include "core/value/test_values.hpp"

using namespace rr;
using namespace rr::testing;
using nlohmann::json;

TEST_CASE("json: every value unpacked from a corrupted element round-trips through JSON") {
    Lcg rng(77);
    int checked = 0;
    for (const auto& f : rich_values()) {
        MessageElement original = pack_ok(f.value, f.type);
        for (int round = 0; round < 300; ++round) {
            MessageElement e = original;
            mutate(e, rng);
            for (std::string_view t : {std::string_view(f.type), std::string_view("varvalue")}) {
                auto type = type_of(t);
                auto v = unpack_value(e, type, example_lookup(), kSvc);
                if (!v) continue;
                auto j = value_to_json(*v, type, example_lookup(), kSvc);
                INFO(t << " round " << round << ": " << (j ? std::string() : j.error().message));
                REQUIRE(j);
                auto back = value_from_json(json::parse(j->dump()), type, example_lookup(), kSvc);
                INFO((back ? std::string() : back.error().message));
                REQUIRE(back);
                // Compared as JSON: string maps come back in key order, which Value equality would see.
                auto j2 = value_to_json(*back, type, example_lookup(), kSvc);
                REQUIRE(j2);
                CHECK(j2->dump() == j->dump());
                ++checked;
            }
        }
    }
    CHECK(checked > 100);
}
