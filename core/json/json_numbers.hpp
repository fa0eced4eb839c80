// JSON form of RR numeric items (docs/json-mapping.md §Numbers):
//   int8 … uint32        JSON integer
//   int64, uint64        JSON integer when |v| ≤ 2^53 (exact in a JS number), else a decimal string
//   double, single       JSON number; NaN / +Inf / -Inf as "NaN" / "Infinity" / "-Infinity"
//   cdouble, csingle     {"re": <real>, "im": <imag>}
//   bool                 true / false
// Reading is more liberal where it loses nothing: integers also accept decimal strings and integral
// JSON floats up to 2^53; reals accept integers. Errors: DataTypeMismatch (wrong JSON kind),
// OutOfRange (integer outside the type, non-integral or too large float for an integer, finite value
// beyond the single range).
#pragma once

#include <nlohmann/json.hpp>

#include "base/error/rr_error.hpp"
#include "core/value/numeric_array.hpp"

namespace rr::json_numbers {

/// 2^53: the largest magnitude up to which every integer is exact in a double (and in JavaScript).
inline constexpr std::uint64_t kMaxExactInteger = 9007199254740992ull;

template <Numeric T>
nlohmann::json to_json(T v);

template <Numeric T>
Result<T> from_json(const nlohmann::json& j);

/// A JSON array of the items of `a`.
nlohmann::json array_to_json(const NumericArray& a);
/// A numeric array of `type` from a JSON array (one allocation). Errors as from_json, with the index
/// of the bad item in the message; DataTypeMismatch when `j` is not an array.
Result<NumericArray> array_from_json(const nlohmann::json& j, DataTypes type, std::size_t* bad_index = nullptr);

/// One item of `a` (index `i`) as JSON.
nlohmann::json item_to_json(const NumericArray& a, std::size_t i);

}  // namespace rr::json_numbers
