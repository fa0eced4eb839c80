// Skipping a Catch2 (v2) test case so that ctest reports it as skipped, not passed.
//
// Catch2 v2 has no SKIP. A test case that cannot run (its shared test data is absent) calls
// RR_SKIP("reason"): the reason is printed as a Catch2 warning starting with `SKIPPED:`, the test
// case returns, and the test program (test/support/catch_main.cpp) exits with 77 when nothing
// failed. Test programs link rr_test_main and give their discovered tests SKIP_RETURN_CODE 77
// (catch_discover_tests(... PROPERTIES SKIP_RETURN_CODE 77)), so ctest shows "Skipped". A failure
// anywhere still fails the run (exit status 1), skipped or not.
//
// Shared test data (standard robdefs, protocol vectors, seed examples) is looked up in the
// environment variable RR_SHARED_DIR when set, else in the RR_SHARED_DIR the build was configured
// with (default ../shared next to the checkout): `RR_SHARED_DIR=/nonexistent ctest ...` shows what
// a checkout without it reports.
#pragma once

#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>

namespace rr::test {

/// Counts a skipped test case (test/support/catch_main.cpp turns a count > 0 into exit status 77).
void note_skipped() noexcept;
/// Test cases skipped so far in this process.
int skipped_count() noexcept;

/// The shared test data folder: $RR_SHARED_DIR if set and not empty, else the configured default.
inline std::filesystem::path shared_dir() {
    if (const char* env = std::getenv("RR_SHARED_DIR"); env && *env) return env;
#ifdef RR_SHARED_DIR
    return RR_SHARED_DIR;
#else
    return "../shared";
#endif
}

/// shared_dir()/<sub> when it exists, else nullopt (the caller skips with RR_SKIP).
inline std::optional<std::filesystem::path> shared_path(const std::string& sub) {
    std::filesystem::path p = shared_dir() / sub;
    std::error_code ec;
    if (!std::filesystem::exists(p, ec)) return std::nullopt;
    return p;
}

}  // namespace rr::test

/// Ends the current test case as skipped (see above). Use only where nothing of the test case has
/// run yet that could hide a result: at its start, before any assertion.
#define RR_SKIP(reason)                      \
    do {                                     \
        ::rr::test::note_skipped();          \
        WARN("SKIPPED: " << reason);         \
        return;                              \
    } while (false)
