// JS numbers, typed arrays and shapes <-> NumericArray (the numeric half of js_values.hpp): scalars as
// number / BigInt / boolean / {real, imag}, arrays as typed arrays, dims as arrays of numbers.
// Errors as js_values.hpp (DataTypeMismatch, NullValue, OutOfRange, DataTypeError).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <emscripten/val.h>

#include "base/error/rr_error.hpp"
#include "core/value/numeric_array.hpp"

namespace rr::wasm {

/// "null", "array", or typeof: for error messages.
std::string js_type(const emscripten::val& v);
/// DataTypeMismatch (or NullValue for null/undefined) naming what was expected.
Unexpected mismatch(const emscripten::val& v, std::string_view expected);
bool is_typed_array(const emscripten::val& v);
/// The numeric type of a typed array (Float64Array → double, …, Uint8Array → uint8), or nullopt.
std::optional<DataTypes> typed_array_type(const emscripten::val& v);
/// A non-null object that is not an Array.
bool is_object(const emscripten::val& v);
bool is_nullish(const emscripten::val& v);

/// A copy of the array's bytes as a typed array of its type (bool → Uint8Array, complex interleaved).
emscripten::val typed_array_copy(const NumericArray& a);
/// Item 0 as a scalar: number, BigInt (64-bit), boolean or {real, imag}.
emscripten::val numeric_scalar_to_js(const NumericArray& a);
/// A typed array; bool[] and complex arrays as Arrays of booleans / {real, imag}.
emscripten::val numeric_array_to_js(const NumericArray& a);
emscripten::val dims_to_js(const std::vector<std::uint32_t>& dims);

/// An integer JS value (number or BigInt) as int32, range-checked.
Result<std::int32_t> int32_from_js(const emscripten::val& v, std::string_view type_name);
/// One JS value as a one-item NumericArray of `type`.
Result<NumericArray> scalar_from_js(const emscripten::val& v, DataTypes type);
/// A typed array of exactly `type` (copied as bytes; complex interleaved), or any array-like item by item.
Result<NumericArray> array_from_js(const emscripten::val& v, DataTypes type);
Result<std::vector<std::uint32_t>> dims_from_js(const emscripten::val& v);

}  // namespace rr::wasm
