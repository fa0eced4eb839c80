// RR values <-> JavaScript values, typed by robdef (the package README, "Values"; it follows
// docs/json-mapping.md where JavaScript has a better native form).
//
//   numeric scalar            number; int64/uint64 BigInt; bool boolean; cdouble/csingle {real, imag}
//   numeric T[] / T[N] / T[N-] typed array (Float64Array, Int32Array, BigInt64Array, …); bool[] and
//                             complex arrays: Array of booleans / of {real, imag}
//   numeric multi-dim          {dims: number[], array: typed array (column-major)}
//   string                     string
//   struct                     plain object of its fields, or null
//   pod / namedarray           plain object of its fields; arrays: Array of objects; multi-dim
//                              {dims, array: objects[]}
//   enum                       number (a value name is accepted on input)
//   T{list}                    Array (or null);  T{string} plain object (or null);  T{int32} Map (or null)
//   varvalue                   {type: "double[]", value} (type as var_type_string), or null
// Input is lenient where nothing can be lost (a plain Array for a typed array, a number for int64 when
// it is a safe integer, a typed array for a flat namedarray array); every value is then checked again by
// pack_value against the robdef.
//
// Errors (as RRError): DataTypeMismatch (wrong JS kind), NullValue, OutOfRange (number does not fit),
// DataTypeError (shape, unknown named type), InvalidArgument (unknown enum value name).
#pragma once

#include <string>
#include <string_view>

#include <emscripten/val.h>

#include "base/error/rr_error.hpp"
#include "core/value/value.hpp"
#include "robdef/service_definition.hpp"
#include "robdef/type_lookup.hpp"

namespace rr::wasm {

/// A JS string from UTF-8 text (embind's std::string conversion decodes UTF-8).
inline emscripten::val u8(const std::string& s) { return emscripten::val(s); }

/// `value` of robdef type `type` as a JS value. Unqualified names in `type` belong to `context_service`.
Result<emscripten::val> to_js(const Value& value, const robdef::TypeDefinition& type,
                              const robdef::TypeLookup& lookup, std::string_view context_service);

/// The JS value `v` as an RR value of robdef type `type`.
Result<Value> from_js(const emscripten::val& v, const robdef::TypeDefinition& type,
                      const robdef::TypeLookup& lookup, std::string_view context_service);

}  // namespace rr::wasm
