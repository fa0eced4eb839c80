// How a synchronous C++ result reaches JS (exceptions are off): {ok: true, value} or {ok: false, error:
// {name, message, code}}, the error being the RRError the JS layer throws (errors.mjs toRRError).
#pragma once

#include <string>

#include <emscripten/val.h>

#include "base/error/rr_error.hpp"

namespace rr::wasm {

/// {name, message, code}: the RR error name (the type's name when the error has none), its message, and
/// the MessageErrorType as a number.
inline emscripten::val error_to_js(const RRError& e) {
    emscripten::val o = emscripten::val::object();
    std::string name = e.name;
    if (name.empty()) name = std::string(error_name(e.type));
    if (name.empty()) name = "RobotRaconteur.UnknownError";
    o.set("name", emscripten::val(name));
    o.set("message", emscripten::val(e.message));
    o.set("code", static_cast<int>(e.type));
    return o;
}

inline emscripten::val ok(emscripten::val v = emscripten::val::undefined()) {
    emscripten::val o = emscripten::val::object();
    o.set("ok", true);
    o.set("value", v);
    return o;
}

inline emscripten::val err(const RRError& e) {
    emscripten::val o = emscripten::val::object();
    o.set("ok", false);
    o.set("error", error_to_js(e));
    return o;
}

}  // namespace rr::wasm
