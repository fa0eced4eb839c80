// main() for Catch2 v2 test programs whose test cases may skip (test/support/skip.hpp): exits with
// 77 when at least one test case skipped and none failed, so that ctest (SKIP_RETURN_CODE 77)
// reports the test as skipped instead of passed. A test spec that matches no test case fails (exit
// status 2) instead of passing with "No tests ran": ctest splits test names at ';', and such a test
// once passed without running anything.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <atomic>
#include <cstdio>

#include "test/support/skip.hpp"

namespace rr::test {
namespace {
std::atomic<int> g_skipped{0};
}
void note_skipped() noexcept { g_skipped.fetch_add(1, std::memory_order_relaxed); }
int skipped_count() noexcept { return g_skipped.load(std::memory_order_relaxed); }
}  // namespace rr::test

int main(int argc, char* argv[]) {
    Catch::Session session;
    if (const int rc = session.applyCommandLine(argc, argv); rc != 0) return rc;
    auto& config = session.configData();
    config.warnings = static_cast<Catch::WarnAbout::What>(config.warnings | Catch::WarnAbout::NoTests);
    const int rc = session.run();
    if (rc == 0 && rr::test::skipped_count() > 0) {
        std::printf("%d test case(s) skipped (see the SKIPPED: warnings above); exit status 77\n",
                    rr::test::skipped_count());
        return 77;
    }
    return rc;
}
