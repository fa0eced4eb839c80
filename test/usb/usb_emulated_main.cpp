// Main of the emulated rr+usb tests: exits 77 (ctest: skipped) with the reason when the process does
// not run under umockdev-wrapper; otherwise runs Catch2.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <cstdio>

#include "test/usb/usb_emulator.hpp"

int main(int argc, char** argv) {
    if (auto why = rr::test::usb::emulator_unavailable_reason(); !why.empty()) {
        std::printf("SKIP: %s\n", why.c_str());
        return 77;
    }
    return Catch::Session().run(argc, argv);
}
