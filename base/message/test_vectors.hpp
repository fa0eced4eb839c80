// Test helper (tests only): reads the shared protocol vectors (wire.md §15) from the shared test data
// folder (test/support/skip.hpp: $RR_SHARED_DIR, else the configured RR_SHARED_DIR). Tests report
// themselves skipped (RR_SKIP) when the folder is absent; vectors are never copied into the repository.
#pragma once

#include <cstddef>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/codec/shared_bytes.hpp"
#include "test/support/skip.hpp"

namespace rr::test {

inline std::string vector_path(std::string_view name) {
    return (shared_dir() / "protocol" / "vectors" / std::string(name)).string();
}

/// Bytes of vectors/<name>, or nullopt if the file cannot be read.
inline std::optional<std::vector<std::byte>> load_vector(std::string_view name) {
    std::ifstream in(vector_path(name), std::ios::binary);
    if (!in) return std::nullopt;
    std::vector<char> chars((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::vector<std::byte> out(chars.size());
    for (std::size_t i = 0; i < chars.size(); ++i) out[i] = static_cast<std::byte>(chars[i]);
    return out;
}

/// Every vector file, in a fixed order.
inline const std::vector<std::string>& vector_names() {
    static const std::vector<std::string> names = {
        "message2.bin",
        "message4.bin",
        "vec_createconnection_req_v2.bin",
        "vec_createconnection_res_v2_only.bin",
        "vec_connectiontest_v2.bin",
        "vec_connectclientcombined_req_v2.bin",
        "vec_error_membernotfound_v2.bin",
        "vec_connectiontestret_v4_stripped.bin",
        "vec_functioncall_list_v2.bin",
        "vec_functioncall_list_v4.bin",
    };
    return names;
}

/// Bytes from hex text; spaces and newlines are ignored.
inline std::vector<std::byte> from_hex(std::string_view hex) {
    std::vector<std::byte> out;
    int hi = -1;
    for (char c : hex) {
        int v = (c >= '0' && c <= '9') ? c - '0' : (c >= 'a' && c <= 'f') ? c - 'a' + 10 : (c >= 'A' && c <= 'F') ? c - 'A' + 10 : -1;
        if (v < 0) continue;
        if (hi < 0) {
            hi = v;
        } else {
            out.push_back(static_cast<std::byte>(hi * 16 + v));
            hi = -1;
        }
    }
    return out;
}

inline SharedBytes shared(const std::vector<std::byte>& bytes) { return SharedBytes::copy_of(bytes); }

inline std::string text(const SharedBytes& b) {
    std::string s(b.size(), '\0');
    for (std::size_t i = 0; i < b.size(); ++i) s[i] = static_cast<char>(b.data()[i]);
    return s;
}

}  // namespace rr::test

/// Skips the current test case (RR_SKIP) when the shared vector is not available. Use before any
/// assertion of the test case.
#define RR_REQUIRE_VECTOR(var, name)                                                          \
    auto var##_loaded = ::rr::test::load_vector(name);                                        \
    if (!var##_loaded) RR_SKIP("shared vector " << ::rr::test::vector_path(name) << " not found"); \
    const std::vector<std::byte>& var = *var##_loaded
