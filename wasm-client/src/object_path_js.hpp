// Object paths for JS: core's one parser (base/names/object_path.hpp), so the wasm client's
// subscriptions read `a.b[3].c[key]` exactly as the gateway, the service side and recording do, with
// the same error messages.
#pragma once

#include <string>

#include <emscripten/val.h>

namespace rr::wasm {

/// parse_object_path(text) (indexes as a user types them or in service-path encoding) as
/// {ok: true, value: [{name, index?}]} (`index`: the decoded text, absent without `[...]`) or
/// {ok: false, error: {name: "RobotRaconteur.InvalidArgument", message, code}} with the core's message.
emscripten::val parse_object_path_js(const std::string& text);

}  // namespace rr::wasm
