// Corrupted element trees: unpack reports an error or a value, never crashes, and whatever it accepts
// packs again to an element that unpacks to the same value.
#include <catch2/catch.hpp>

#include "core/value/test_mutations.hpp"
#include "core/value/test_values.hpp"

using namespace rr;
using namespace rr::testing;

TEST_CASE("unpack survives corrupted elements, what it accepts packs again") {
    Lcg rng(20240611);
    int accepted = 0, rejected = 0;
    for (const auto& f : rich_values()) {
        MessageElement original = pack_ok(f.value, f.type);
        for (int round = 0; round < 400; ++round) {
            MessageElement e = original;
            int n = 1 + static_cast<int>(rng.below(3));
            for (int k = 0; k < n; ++k) mutate(e, rng);
            for (std::string_view t : {std::string_view(f.type), std::string_view("varvalue")}) {
                auto type = type_of(t);
                auto v = unpack_value(e, type, example_lookup(), kSvc);
                if (!v) {
                    ++rejected;
                    CHECK(v.error().type != MessageErrorType::None);
                    CHECK_FALSE(v.error().message.empty());
                    continue;
                }
                ++accepted;
                auto again = pack_value(*v, type, "value", example_lookup(), kSvc);
                INFO(t << " round " << round << ": " << (again ? std::string() : again.error().message));
                REQUIRE(again);
                auto back = unpack_value(*again, type, example_lookup(), kSvc);
                REQUIRE(back);
                CHECK(*back == *v);
            }
            (void)unpack_value_untyped(e);  // must not crash either
        }
    }
    CHECK(accepted > 100);
    CHECK(rejected > 1000);
}
