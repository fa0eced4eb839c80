// A folder of a test's own under TMPDIR (or /tmp), made atomically (mkdtemp: parallel test runs never
// share one) and removed with everything in it when the test ends. For Catch2 tests.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <unistd.h>

#include <catch2/catch.hpp>

namespace rr::testing {

struct TempDir {
    std::filesystem::path path;
    /// `name`: the folder's name before its random suffix, e.g. "rr-recording-test".
    explicit TempDir(const std::string& name) {
        std::string tmpl = (std::filesystem::temp_directory_path() / (name + "-XXXXXX")).string();
        REQUIRE(::mkdtemp(tmpl.data()));
        path = tmpl;
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
};

}  // namespace rr::testing
