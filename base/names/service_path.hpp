// Service paths: `service`, `service.member`, `service.member[index]`, nested (wire.md §6.5).
// Index encoding (CORE encode_index): ASCII letters and digits are kept, every other byte becomes
// '%' + two lower-case hex digits; int32 indices are written in decimal first ("-1" -> "%2d1").
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"

namespace rr {

/// Encodes an objref index for use inside `[...]`.
std::string encode_service_path_index(std::string_view index);
std::string encode_service_path_index(std::int32_t index);

/// Reverses encode_service_path_index. Errors: InvalidArgument on a malformed `%hh` escape.
Result<std::string> decode_service_path_index(std::string_view encoded);

/// One segment of a service path: `name` or `name[encoded-index]`.
struct ServicePathSegment {
    std::string name;
    std::string index;  ///< decoded index text; empty when the segment has no index
    bool has_index = false;
};

/// Splits and validates a service path (segments match `^[A-Za-z0-9_]+(\[[A-Za-z0-9_%]+\])?$`, every
/// `%` followed by two hex digits). Errors: InvalidArgument, object_path.hpp's messages.
Result<std::vector<ServicePathSegment>> split_service_path(std::string_view path);

/// `parent.member` or `parent.member[encoded index]`.
std::string join_service_path(std::string_view parent, std::string_view member);
std::string join_service_path(std::string_view parent, std::string_view member, std::string_view index);

/// Replaces the first segment (the service name) of `path` by `new_service`: the gateway's rewrite.
/// `svc.a[1].b` with new_service "dev" gives `dev.a[1].b`.
std::string replace_service_name(std::string_view path, std::string_view new_service);

/// The first segment of a path (the service name).
std::string_view service_name_of(std::string_view path) noexcept;

}  // namespace rr
