// Object paths (wire.md §6.5): the path of an object below a service's root, segments `name` or
// `name[index]` joined by '.', e.g. `arms[left].tool`, `Webcams[0]`, `child_by_int[%2d1]`. In a service
// path (`svc.arms[left].tool`) every index is in RR's service-path encoding (service_path.hpp); what a
// user types (the JSON API's `object=`, a recorded member's name) may give an index as plain text
// (`child_by_name[with space]`), which is encoded. One parser and one set of error messages for both;
// walking a path through the objrefs' declared types is core/names/object_path_walk.hpp (above robdef).
//
// Errors (InvalidArgument), `P` the path as given:
//   object path "P" is empty
//   object path "P": expected a member name at offset N
//   object path "P": '[' without ']'
//   object path "P": empty index
//   object path "P": index "I" is not in service-path encoding (letters, digits, '_', %hh)   (encoded form)
//   object path "P": unexpected 'c' at offset N
//   object path "P" ends with '.'
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"

namespace rr {

/// One segment of an object path.
struct ObjectPathSegment {
    std::string name;
    bool has_index = false;
    std::string index;          ///< the index's text, decoded ("" without one)
    std::string encoded_index;  ///< the index as it stands in a service path (kept as given when it already is)
    /// `name` or `name[encoded_index]`.
    std::string text() const;
};

struct ObjectPath {
    std::vector<ObjectPathSegment> segments;
    /// The path in service-path form: the segments' text() joined by '.'.
    std::string text() const;
};

/// How indexes are given.
enum class ObjectPathIndexes {
    plain_or_encoded,  ///< an index in service-path encoding is kept, any other text is encoded (user input)
    encoded,           ///< every index is in service-path encoding (a service path from the wire)
};

/// Parses `path` (see the errors above). A `%hh` escape counts as encoded: `[%2d1]` is the index "-1".
Result<ObjectPath> parse_object_path(std::string_view path, ObjectPathIndexes indexes = ObjectPathIndexes::plain_or_encoded);

/// parse_object_path(relative).text(): `child_by_int[-1]` → `child_by_int[%2d1]`.
Result<std::string> normalize_object_path(std::string_view relative);

/// A member named with its object's path (`Webcams[0].FrameStream`), split at its last '.' outside
/// brackets: {"Webcams[0]", "FrameStream"}; `packets` → {"", "packets"}. Not checked (parse the object).
struct MemberPath {
    std::string object;  ///< the object's path ("" = the root)
    std::string member;
};
MemberPath split_member_path(std::string_view name);

}  // namespace rr
