// UTF-8 well-formedness (RFC 3629): JSON text must be valid UTF-8, RR strings on the wire are not
// checked by CORE, so strings are checked before they become JSON.
#pragma once

#include <string_view>

namespace rr {

/// True when `s` is well-formed UTF-8 (no overlong forms, no surrogates, nothing above U+10FFFF).
bool is_valid_utf8(std::string_view s) noexcept;

}  // namespace rr
