#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "core/value/numeric_array.hpp"

using namespace rr;

namespace {
SharedBytes bytes_of(std::initializer_list<int> b) {
    std::vector<std::byte> v;
    for (int x : b) v.push_back(static_cast<std::byte>(x));
    return SharedBytes::adopt(std::move(v));
}
}  // namespace

TEST_CASE("NumericArray scalars are inline and typed") {
    auto a = NumericArray::scalar<double>(1.5);
    CHECK(a.type() == DataTypes::double_t);
    CHECK(a.size() == 1);
    CHECK_FALSE(a.is_view());
    CHECK(a.at<double>(0) == 1.5);
    CHECK(a.span<double>().size() == 1);
    CHECK(a.span<double>()[0] == 1.5);
    auto b = a.to_bytes();
    REQUIRE(b.size() == 8);
    CHECK(b.data()[7] == std::byte{0x3f});  // 1.5 = 0x3FF8000000000000, little-endian
    CHECK(b.data()[6] == std::byte{0xf8});
}

TEST_CASE("NumericArray::from copies and to_bytes shares the typed buffer") {
    std::vector<std::int32_t> src{1, -2, 3};
    auto a = NumericArray::from<std::int32_t>(src);
    src[0] = 99;
    CHECK(a.at<std::int32_t>(0) == 1);
    auto b = a.to_bytes();
    CHECK(b.data() == reinterpret_cast<const std::byte*>(a.span<std::int32_t>().data()));
    CHECK(b.size() == 12);
    CHECK(b.data()[4] == std::byte{0xfe});
    CHECK(b.data()[7] == std::byte{0xff});
}

TEST_CASE("NumericArray::wrap views received bytes without copying") {
    auto bytes = bytes_of({1, 0, 2, 0, 0xff, 0xff});
    auto a = NumericArray::wrap(DataTypes::int16_t, bytes);
    REQUIRE(a);
    CHECK(a->is_view());
    CHECK(a->size() == 3);
    auto v = a->view<std::int16_t>();
    CHECK(v[0] == 1);
    CHECK(v[1] == 2);
    CHECK(v[2] == -1);
    std::vector<std::int16_t> items(v.begin(), v.end());
    CHECK(items == std::vector<std::int16_t>{1, 2, -1});
    CHECK(a->to_bytes().data() == bytes.data());  // re-packing is zero-copy too
}

TEST_CASE("NumericArray::wrap of one item copies it inline") {
    auto a = NumericArray::wrap(DataTypes::uint32_t, bytes_of({0x78, 0x56, 0x34, 0x12}));
    REQUIRE(a);
    CHECK_FALSE(a->is_view());
    CHECK(a->at<std::uint32_t>(0) == 0x12345678u);
}

TEST_CASE("NumericArray::wrap rejects non-numeric types and ragged byte counts") {
    auto r1 = NumericArray::wrap(DataTypes::string_t, bytes_of({1}));
    REQUIRE_FALSE(r1);
    CHECK(r1.error().type == MessageErrorType::DataTypeError);
    auto r2 = NumericArray::wrap(DataTypes::double_t, bytes_of({1, 2, 3}));
    REQUIRE_FALSE(r2);
    CHECK(r2.error().type == MessageErrorType::DataTypeError);
}

TEST_CASE("NumericArray copy-on-write: mutation never leaks into copies or packed bytes") {
    auto a = NumericArray::from<double>({1.0, 2.0, 3.0});
    auto packed = a.to_bytes();
    auto b = a;
    a.mutable_span<double>()[0] = 10.0;
    CHECK(a.at<double>(0) == 10.0);
    CHECK(b.at<double>(0) == 1.0);
    CHECK(detail::load_item<double>(packed.data()) == 1.0);
    // A unique owner mutates in place.
    auto* before = a.span<double>().data();
    a.mutable_span<double>()[1] = 20.0;
    CHECK(a.span<double>().data() == before);
}

TEST_CASE("NumericArray views become typed storage with make_owned or mutable_span") {
    auto a = NumericArray::wrap(DataTypes::bool_t, bytes_of({0, 1, 2})).value();
    CHECK(a.is_view());
    CHECK(a.view<bool>()[2]);  // any non-zero byte reads as true
    a.make_owned();
    CHECK_FALSE(a.is_view());
    CHECK(a.span<bool>()[2]);
    CHECK(a.to_bytes().data()[2] == std::byte{1});  // normalised
    auto c = NumericArray::wrap(DataTypes::uint8_t, bytes_of({5, 6})).value();
    c.mutable_span<std::uint8_t>()[0] = 7;
    CHECK(c.at<std::uint8_t>(0) == 7);
    CHECK_FALSE(c.is_view());
}

TEST_CASE("NumericArray complex items are real then imaginary") {
    auto a = NumericArray::from<csingle>({csingle(1.0f, -2.0f), csingle(0.5f, 4.0f)});
    auto b = a.to_bytes();
    REQUIRE(b.size() == 16);
    CHECK(detail::load_item<float>(b.data()) == 1.0f);
    CHECK(detail::load_item<float>(b.data() + 4) == -2.0f);
    auto w = NumericArray::wrap(DataTypes::csingle_t, b).value();
    CHECK(w.at<csingle>(1) == csingle(0.5f, 4.0f));
    CHECK(w == a);
}

TEST_CASE("NumericArray equality is bitwise per item") {
    double nan = std::numeric_limits<double>::quiet_NaN();
    CHECK(NumericArray::scalar(nan) == NumericArray::scalar(nan));
    CHECK_FALSE(NumericArray::scalar(0.0) == NumericArray::scalar(-0.0));
    CHECK_FALSE(NumericArray::scalar<std::int32_t>(1) == NumericArray::scalar<std::uint32_t>(1));
    CHECK(NumericArray::zeros(DataTypes::int64_t, 0) == NumericArray(DataTypes::int64_t));
    auto z = NumericArray::zeros(DataTypes::cdouble_t, 5);
    CHECK(z.size() == 5);
    CHECK(z.at<cdouble>(4) == cdouble(0, 0));
}

TEST_CASE("NumericArray::adopt takes a vector without copying") {
    std::vector<std::uint64_t> v{1, 2, std::numeric_limits<std::uint64_t>::max()};
    const auto* p = v.data();
    auto a = NumericArray::adopt(std::move(v));
    CHECK(a.span<std::uint64_t>().data() == p);
    CHECK(a.at<std::uint64_t>(2) == std::numeric_limits<std::uint64_t>::max());
}
