// DataTypes codes: the ElementType of a MessageElement and the base type of robdef types.
// wire.md §3.1 (CORE RobotRaconteurConstants.h enum DataTypes); element sizes wire.md §1.5.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace rr {

enum class DataTypes : std::uint16_t {
    void_t = 0,
    double_t = 1,
    single_t = 2,
    int8_t = 3,
    uint8_t = 4,
    int16_t = 5,
    uint16_t = 6,
    int32_t = 7,
    uint32_t = 8,
    int64_t = 9,
    uint64_t = 10,
    string_t = 11,
    cdouble_t = 12,
    csingle_t = 13,
    bool_t = 14,
    structure_t = 101,
    vector_t = 102,      ///< map with int32 keys, T{int32}
    dictionary_t = 103,  ///< map with string keys, T{string}
    object_t = 104,      ///< robdef only
    varvalue_t = 105,    ///< robdef only
    varobject_t = 106,   ///< robdef only
    list_t = 108,
    pod_t = 109,
    pod_array_t = 110,
    pod_multidimarray_t = 111,
    enum_t = 112,        ///< robdef only; travels as int32
    namedtype_t = 113,   ///< robdef only; unresolved named type
    namedarray_t = 114,  ///< robdef only
    namedarray_array_t = 115,
    namedarray_multidimarray_t = 116,
    multidimarray_t = 117,
};

/// Bytes per array item for numeric types and string (1), 0 for every other code (wire.md §1.5).
constexpr std::size_t data_type_size(DataTypes t) noexcept {
    switch (t) {
        case DataTypes::double_t: return 8;
        case DataTypes::single_t: return 4;
        case DataTypes::int8_t:
        case DataTypes::uint8_t: return 1;
        case DataTypes::int16_t:
        case DataTypes::uint16_t: return 2;
        case DataTypes::int32_t:
        case DataTypes::uint32_t: return 4;
        case DataTypes::int64_t:
        case DataTypes::uint64_t: return 8;
        case DataTypes::string_t: return 1;
        case DataTypes::cdouble_t: return 16;
        case DataTypes::csingle_t: return 8;
        case DataTypes::bool_t: return 1;
        default: return 0;
    }
}

/// double … uint64, cdouble, csingle, bool (not string).
constexpr bool is_numeric(DataTypes t) noexcept {
    auto c = static_cast<std::uint16_t>(t);
    return (c >= 1 && c <= 10) || (c >= 12 && c <= 14);
}

/// Element types whose payload is a list of child elements (wire.md §1.4).
constexpr bool is_nested(DataTypes t) noexcept {
    switch (t) {
        case DataTypes::structure_t:
        case DataTypes::vector_t:
        case DataTypes::dictionary_t:
        case DataTypes::list_t:
        case DataTypes::pod_t:
        case DataTypes::pod_array_t:
        case DataTypes::pod_multidimarray_t:
        case DataTypes::namedarray_array_t:
        case DataTypes::namedarray_multidimarray_t:
        case DataTypes::multidimarray_t: return true;
        default: return false;
    }
}

/// Element types that may appear on the wire: void, 1–14 and the nested types.
constexpr bool is_wire_type(DataTypes t) noexcept {
    auto c = static_cast<std::uint16_t>(t);
    return c <= 14 || is_nested(t);
}

/// robdef keyword for primitive codes ("double", "cdouble", "varvalue", …); "" otherwise.
constexpr std::string_view data_type_keyword(DataTypes t) noexcept {
    switch (t) {
        case DataTypes::void_t: return "void";
        case DataTypes::double_t: return "double";
        case DataTypes::single_t: return "single";
        case DataTypes::int8_t: return "int8";
        case DataTypes::uint8_t: return "uint8";
        case DataTypes::int16_t: return "int16";
        case DataTypes::uint16_t: return "uint16";
        case DataTypes::int32_t: return "int32";
        case DataTypes::uint32_t: return "uint32";
        case DataTypes::int64_t: return "int64";
        case DataTypes::uint64_t: return "uint64";
        case DataTypes::string_t: return "string";
        case DataTypes::cdouble_t: return "cdouble";
        case DataTypes::csingle_t: return "csingle";
        case DataTypes::bool_t: return "bool";
        case DataTypes::structure_t: return "structure";
        case DataTypes::object_t: return "object";
        case DataTypes::varvalue_t: return "varvalue";
        case DataTypes::varobject_t: return "varobject";
        default: return "";
    }
}

}  // namespace rr
