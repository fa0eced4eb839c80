// Values of any robdef type drawn from the LFSR (lfsr.hpp), so that a client can compute what the test
// service sends and the service can compute what a client must send: both draw from a generator made
// of the same seed and key (test_values.hpp: the member name with `_get` or `_set`). The rules, in the
// order the numbers are drawn (test/testsvc/testsvc_values.py draws the same in Python):
//
//   numeric scalar         one next_<type>() (bool: next_bool, cdouble/csingle: real then imaginary)
//   T[]                    next_len(16) items (0…15)       T[N]  N items      T[N-]  next_len(N+1) items
//   T[*]                   next_dist(1,3) dims, each next_dist(1,4), then the items (column-major)
//   T[N,M]                 those dims, then the items
//   string                 next_string_var_len(16)
//   enum                   the value at index next_dist(0, n-1) of the n values (index 0 when n == 1)
//   struct                 each field in definition order; a struct nested 4 deep is null
//   pod, namedarray        the item count as for numeric arrays (scalar: 1), then per item each field in
//                          definition order (namedarray: every number of the item, flat, in order)
//   T{list}                next_dist(1,3) items
//   T{int32}, T{string}    next_dist(1,3) entries, each a key then its value; an int32 key is
//                          next_dist(0,999), a string key next_string(next_dist(1,8)); a key already
//                          used is drawn again
//   varvalue               kind next_dist(0,3): double[] (next_len(16) items), int32[] (the same),
//                          string (next_string_var_len(16)), double[*] (as T[*] above)
// Doubles and floats are raw register bits, so NaN, infinities and subnormals occur: compare with
// same_value(), which takes any NaN as equal to any NaN.
#pragma once

#include <string_view>

#include "core/value/value.hpp"
#include "robdef/type_lookup.hpp"
#include "test/testsvc/lfsr.hpp"

namespace rr::testsvc {

/// A value of `type` (unqualified names belong to `context_service`) drawn from `gen` by the rules
/// above. Errors: DataTypeError for types a value cannot have (objects, generators, unknown names).
Result<Value> lfsr_value(const robdef::TypeDefinition& type, Lfsr& gen, const robdef::TypeLookup& lookup,
                         std::string_view context_service);

/// `a` and `b` hold the same value: same kinds, types and shapes, numbers equal (any NaN equals any NaN,
/// 0.0 equals -0.0), struct and pod fields by name, map entries by key in any order.
bool same_value(const Value& a, const Value& b);

}  // namespace rr::testsvc
