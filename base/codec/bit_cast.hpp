// rr::bit_cast: std::bit_cast for standard libraries that lack it (Emscripten 3.1.6 ships libc++ 14).
// Both gcc (≥ 11) and clang provide the builtin behind std::bit_cast.
#pragma once

#include <type_traits>

namespace rr {

template <class To, class From>
constexpr To bit_cast(const From& from) noexcept {
    static_assert(sizeof(To) == sizeof(From), "bit_cast needs types of the same size");
    static_assert(std::is_trivially_copyable_v<To> && std::is_trivially_copyable_v<From>);
    return __builtin_bit_cast(To, from);
}

}  // namespace rr
