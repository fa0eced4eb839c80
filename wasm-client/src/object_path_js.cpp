#include "wasm-client/src/object_path_js.hpp"

#include "base/names/object_path.hpp"
#include "wasm-client/src/js_results.hpp"

namespace rr::wasm {

emscripten::val parse_object_path_js(const std::string& text) {
    auto parsed = parse_object_path(text);
    if (!parsed) return err(parsed.error());
    emscripten::val segments = emscripten::val::array();
    for (const auto& s : parsed->segments) {
        emscripten::val o = emscripten::val::object();
        o.set("name", emscripten::val(s.name));
        if (s.has_index) o.set("index", emscripten::val(s.index));
        segments.call<void>("push", o);
    }
    return ok(segments);
}

}  // namespace rr::wasm
