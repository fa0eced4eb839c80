// Binary pushes (binary_push.hpp): the layout a browser relies on, the reference decoder, and messages
// that are not one.
#include <catch2/catch.hpp>

#include <cstring>

#include "core/json/value_json.hpp"
#include "core/value/numeric_array.hpp"
#include "server/gateway/binary_push.hpp"

using namespace rr;
using namespace rr::server::gateway;
using nlohmann::json;

namespace {

std::uint32_t u32_at(const std::string& m, std::size_t at) {
    std::uint32_t v = 0;
    std::memcpy(&v, m.data() + at, 4);
    return v;
}

}  // namespace

TEST_CASE("binary push: header, JSON text, and 8-aligned little-endian arrays") {
    const auto doubles = NumericArray::from<double>({1.5, -2.25});
    const auto bytes = NumericArray::from<std::uint8_t>({7, 8, 9});
    const auto words = NumericArray::from<std::int16_t>({-3});
    const std::string text =
        R"({"subscription":4,"kind":"wire","value":{"a":{"$binary":0,"type":"double","length":2,"offset":0},)"
        R"("b":{"$binary":1,"type":"uint8","length":3,"offset":16},"c":{"$binary":2,"type":"int16","length":1,"offset":24}}})";
    const std::string m = binary_push_message(text, {doubles.to_bytes(), bytes.to_bytes(), words.to_bytes()});

    CHECK(m.substr(0, 4) == "RRJB");
    REQUIRE(u32_at(m, 4) == text.size());
    CHECK(m.substr(8, text.size()) == text);
    const std::size_t base = BinaryArrays::padded(8 + text.size());
    REQUIRE(m.size() == base + 16 + 8 + 8);
    double d[2];
    std::memcpy(d, m.data() + base, 16);
    CHECK(d[0] == 1.5);
    CHECK(d[1] == -2.25);
    CHECK(static_cast<unsigned char>(m[base + 16]) == 7);
    CHECK(static_cast<unsigned char>(m[base + 18]) == 9);
    CHECK(m[base + 19] == '\0');  // padding
    std::int16_t w = 0;
    std::memcpy(&w, m.data() + base + 24, 2);
    CHECK(w == -3);

    auto parts = split_binary_push(m);
    REQUIRE(parts);
    CHECK(parts->json_text == text);
    CHECK(parts->arrays.data() == m.data() + base);
    CHECK(parts->arrays.size() == 32);

    auto decoded = decode_binary_push(m);
    INFO((decoded ? std::string() : decoded.error().message));
    REQUIRE(decoded);
    CHECK(*decoded == json::parse(R"({"subscription":4,"kind":"wire","value":{"a":[1.5,-2.25],"b":[7,8,9],"c":[-3]}})"));
}

TEST_CASE("binary push: the decoder refuses what is not a binary push") {
    const auto doubles = NumericArray::from<double>({1, 2});
    const std::string ok_text = R"({"v":{"$binary":0,"type":"double","length":2,"offset":0}})";
    const std::string ok = binary_push_message(ok_text, {doubles.to_bytes()});
    REQUIRE(decode_binary_push(ok));

    auto refused = [](const std::string& m) {
        auto r = decode_binary_push(m);
        if (r) return false;
        CHECK(r.error().type == MessageErrorType::ProtocolError);
        return true;
    };
    CHECK(refused(""));
    CHECK(refused("RRJ"));
    CHECK(refused("XXJB" + ok.substr(4)));
    CHECK(refused(ok.substr(0, ok.size() - 1)));  // the array cut short
    std::string long_json = ok;
    long_json[4] = '\xff';  // the JSON text runs past the end
    CHECK(refused(long_json));
    auto with = [&](const std::string& text, std::size_t array_bytes = 16) {
        std::string m = binary_push_message(text, {});
        m.append(array_bytes, '\0');
        return m;
    };
    CHECK(refused(with(R"({"v":{"$binary":0,"type":"double","length":3,"offset":0}})")));   // 24 bytes of 16
    CHECK(refused(with(R"({"v":{"$binary":0,"type":"double","length":1,"offset":12}})")));  // misaligned
    CHECK(refused(with(R"({"v":{"$binary":0,"type":"double","length":1,"offset":16}})")));  // past the end
    CHECK(refused(with(R"({"v":{"$binary":0,"type":"string","length":1,"offset":0}})")));
    CHECK(refused(with(R"({"v":{"$binary":0,"type":"double","length":-1,"offset":0}})")));
    CHECK(refused(with(R"({"v":{"$binary":0,"length":1,"offset":0}})")));
    CHECK(refused(with(R"({"v":{"$binary":0,"type":"double","length":18446744073709551615,"offset":0}})")));
    CHECK(refused(with("{not json")));
    // Without references it is just the JSON.
    auto plain = decode_binary_push(binary_push_message(R"({"kind":"wire","value":[]})", {}));
    REQUIRE(plain);
    CHECK(*plain == json{{"kind", "wire"}, {"value", json::array()}});
}
