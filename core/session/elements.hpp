// Small helpers to build and read the primitive message elements the session protocol itself uses
// (capabilities, `return`, `index`, `errorname`/`errorstring`, …). Values of user types go through
// core/value instead.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "base/message/error_entry.hpp"
#include "base/message/message.hpp"

namespace rr {

template <class T>
constexpr DataTypes data_type_of() {
    if constexpr (std::is_same_v<T, double>) return DataTypes::double_t;
    else if constexpr (std::is_same_v<T, float>) return DataTypes::single_t;
    else if constexpr (std::is_same_v<T, std::int8_t>) return DataTypes::int8_t;
    else if constexpr (std::is_same_v<T, std::uint8_t>) return DataTypes::uint8_t;
    else if constexpr (std::is_same_v<T, std::int16_t>) return DataTypes::int16_t;
    else if constexpr (std::is_same_v<T, std::uint16_t>) return DataTypes::uint16_t;
    else if constexpr (std::is_same_v<T, std::int32_t>) return DataTypes::int32_t;
    else if constexpr (std::is_same_v<T, std::uint32_t>) return DataTypes::uint32_t;
    else if constexpr (std::is_same_v<T, std::int64_t>) return DataTypes::int64_t;
    else if constexpr (std::is_same_v<T, std::uint64_t>) return DataTypes::uint64_t;
    else if constexpr (std::is_same_v<T, bool>) return DataTypes::bool_t;
    else static_assert(sizeof(T) == 0, "not an RR primitive");
}

/// Numeric array element; data little-endian (this code assumes a little-endian host, checked below).
template <class T>
MessageElement make_array_element(std::string name, std::span<const T> values) {
    static_assert(std::endian::native == std::endian::little, "big-endian hosts need byte swapping here");
    MessageElement e;
    e.name = std::move(name);
    e.type = data_type_of<T>();
    std::vector<std::byte> bytes(values.size_bytes());
    if (!bytes.empty()) std::memcpy(bytes.data(), values.data(), bytes.size());
    e.data = SharedBytes::adopt(std::move(bytes));
    return e;
}

template <class T>
MessageElement make_scalar_element(std::string name, T value) {
    return make_array_element<T>(std::move(name), std::span<const T>(&value, 1));
}

/// Items of a numeric element of type T (copied out; returns empty if the type does not match).
template <class T>
std::vector<T> read_array(const MessageElement& e) {
    if (e.type != data_type_of<T>()) return {};
    std::vector<T> out(e.data.size() / sizeof(T));
    if (!out.empty()) std::memcpy(out.data(), e.data.data(), out.size() * sizeof(T));
    return out;
}

/// Reads a scalar of type T; false when the element is not exactly one T.
template <class T>
bool read_scalar(const MessageElement& e, T& out) {
    if (e.type != data_type_of<T>() || e.data.size() != sizeof(T)) return false;
    std::memcpy(&out, e.data.data(), sizeof(T));
    return true;
}

/// The UTF-8 text of a string element (empty for other types).
inline std::string_view read_string(const MessageElement& e) {
    if (e.type != DataTypes::string_t) return {};
    return std::string_view(reinterpret_cast<const char*>(e.data.data()), e.data.size());
}

}  // namespace rr
