// The direct element → JSON text path gives exactly the text of the general path
// (unpack_value → value_to_json → nlohmann dump) for every type it renders, and declines everything
// else (the general path renders it, or words the error).
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>

#include "core/json/element_json_text.hpp"
#include "core/json/json_numbers.hpp"
#include "core/json/value_json.hpp"
#include "core/value/test_values.hpp"

using namespace rr;
using namespace rr::testing;

namespace {

// The general path's text, as the gateway renders it (json_text: compact, invalid UTF-8 replaced).
std::string general_text(const MessageElement& e, std::string_view type) {
    auto v = unpack_value(e, type_of(type), example_lookup(), kSvc);
    INFO((v ? std::string() : v.error().message));
    REQUIRE(v);
    auto j = value_to_json(*v, type_of(type), example_lookup(), kSvc);
    REQUIRE(j);
    return j->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

void check_same(const MessageElement& e, std::string_view type) {
    std::string direct = "prefix:";
    INFO(type);
    REQUIRE(element_json_text::append(direct, e, type_of(type)));
    CHECK(direct == "prefix:" + general_text(e, type));
}

template <class T>
MessageElement element_of(const std::vector<T>& items) {
    MessageElement e;
    e.name = "value";
    e.type = numeric_type_v<T>;
    std::vector<std::byte> bytes(items.size() * sizeof(T));
    for (std::size_t i = 0; i < items.size(); ++i) detail::store_item<T>(bytes.data() + i * sizeof(T), items[i]);
    e.data = SharedBytes::copy_of(bytes);
    return e;
}

template <class T>
std::vector<T> edge_values() {
    using L = std::numeric_limits<T>;
    if constexpr (std::is_same_v<T, bool>) {
        return {true, false};
    } else if constexpr (std::is_floating_point_v<T>) {
        return {T(0), -T(0), T(1), T(-1.5), T(0.1), T(1e20), T(1e-7), T(123456789.125), L::max(), L::lowest(),
                L::min(), L::denorm_min(), L::epsilon(), L::quiet_NaN(), L::infinity(), -L::infinity(), T(1e15),
                T(1e16), T(1e-5), T(3.14159265358979)};
    } else {
        std::vector<T> v{T(0), T(1), L::max(), L::min(), T(L::max() / 3)};
        if constexpr (std::is_signed_v<T>) v.push_back(T(-1));
        if constexpr (sizeof(T) == 8) {
            const auto exact = static_cast<T>(json_numbers::kMaxExactInteger);
            for (T x : {exact, T(exact - 1), T(exact + 1)}) v.push_back(x);
            if constexpr (std::is_signed_v<T>)
                for (T x : {T(-exact), T(-exact - 1), T(-exact + 1)}) v.push_back(x);
        }
        return v;
    }
}

template <class T>
std::vector<T> random_values(std::mt19937_64& rng, std::size_t n) {
    std::vector<T> out(n);
    for (std::size_t i = 0; i < n; ++i) {
        T v;
        if constexpr (std::is_same_v<T, bool>) {
            v = (rng() & 1) != 0;
        } else if constexpr (std::is_floating_point_v<T>) {
            // Any bit pattern: every exponent, NaNs and infinities included.
            using Bits = std::conditional_t<sizeof(T) == 8, std::uint64_t, std::uint32_t>;
            v = std::bit_cast<T>(static_cast<Bits>(rng()));
        } else {
            v = static_cast<T>(rng() >> (rng() % 64));
        }
        out[i] = v;
    }
    return out;
}

template <class T>
void check_type(std::string_view keyword) {
    std::mt19937_64 rng(42);
    const std::string k(keyword);
    auto edges = edge_values<T>();
    for (T v : edges) check_same(element_of<T>({v}), k);
    check_same(element_of(edges), k + "[]");
    check_same(element_of(std::vector<T>{}), k + "[]");
    check_same(element_of(random_values<T>(rng, 500)), k + "[]");
    check_same(element_of(random_values<T>(rng, 3)), k + "[3]");
    check_same(element_of(random_values<T>(rng, 2)), k + "[4-]");
    for (int i = 0; i < 200; ++i) check_same(element_of(random_values<T>(rng, 1)), k);
}

}  // namespace

TEST_CASE("element JSON text: every numeric type renders as the general path does") {
    check_type<double>("double");
    check_type<float>("single");
    check_type<std::int8_t>("int8");
    check_type<std::uint8_t>("uint8");
    check_type<std::int16_t>("int16");
    check_type<std::uint16_t>("uint16");
    check_type<std::int32_t>("int32");
    check_type<std::uint32_t>("uint32");
    check_type<std::int64_t>("int64");
    check_type<std::uint64_t>("uint64");
    check_type<bool>("bool");
}

TEST_CASE("element JSON text: complex items render as {\"re\",\"im\"} objects as the general path does") {
    std::mt19937_64 rng(7);
    auto d = random_values<double>(rng, 64);
    std::vector<cdouble> cd;
    for (std::size_t i = 0; i + 1 < d.size(); i += 2) cd.emplace_back(d[i], d[i + 1]);
    cd.emplace_back(std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::infinity());
    check_same(element_of(cd), "cdouble[]");
    check_same(element_of(std::vector<cdouble>{{1, -2}}), "cdouble");
    check_same(element_of(std::vector<csingle>{{0.1f, 2.5f}, {-0.f, 1e30f}}), "csingle[2]");
}

TEST_CASE("element JSON text: a bool byte other than 0 or 1 is true, as the general path reads it") {
    MessageElement e = element_of(std::vector<std::uint8_t>{0, 1, 2, 255});
    e.type = DataTypes::bool_t;
    check_same(e, "bool[]");
}

TEST_CASE("element JSON text: other types and elements that do not match are declined, out unchanged") {
    const std::string before = "kept";
    auto declined = [&](const MessageElement& e, std::string_view type) {
        std::string out = before;
        INFO(type);
        CHECK_FALSE(element_json_text::append(out, e, type_of(type)));
        CHECK(out == before);
    };
    auto three = element_of(std::vector<double>{1, 2, 3});
    // Types the general path renders.
    CHECK_FALSE(element_json_text::renders(type_of("string")));
    CHECK_FALSE(element_json_text::renders(type_of("double[*]")));
    CHECK_FALSE(element_json_text::renders(type_of("double{list}")));
    CHECK_FALSE(element_json_text::renders(type_of("double[]{int32}")));
    CHECK_FALSE(element_json_text::renders(type_of("varvalue")));
    CHECK_FALSE(element_json_text::renders(type_of("Vec3")));
    CHECK_FALSE(element_json_text::renders(type_of("void")));
    CHECK(element_json_text::renders(type_of("uint8[]")));
    declined(three, "double[*]");
    declined(three, "double{list}");
    declined(three, "Vec3");
    // Elements the general path refuses (it gives the error).
    declined(three, "double");                                          // 3 items for a scalar
    declined(three, "double[2]");                                       // 3 for exactly 2
    declined(three, "double[2-]");                                      // 3 for at most 2
    declined(three, "single[]");                                        // another numeric type
    declined(element_of(std::vector<double>{}), "double");              // no item for a scalar
    MessageElement ragged = three;
    ragged.data = SharedBytes::copy_of(std::vector<std::byte>(17));     // not a multiple of 8 bytes
    declined(ragged, "double[]");
    MessageElement null_element;
    declined(null_element, "double[]");
    for (auto* type : {"double", "double[2]", "double[2-]", "single[]"}) {
        auto v = unpack_value(three, type_of(type), example_lookup(), kSvc);
        CHECK_FALSE(v);
    }
    CHECK_FALSE(unpack_value(ragged, type_of("double[]"), example_lookup(), kSvc));
}
