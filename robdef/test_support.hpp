// Test helpers for robdef tests: reading the shared test data (RR_SHARED_DIR) and looking for
// diagnostics. Test code only (reads files, uses exceptions).
#pragma once

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "robdef/diagnostic.hpp"
#include "test/support/skip.hpp"

namespace rr::robdef::test {

/// The shared test data folder's <sub> when it exists, else nullopt (callers RR_SKIP; see
/// test/support/skip.hpp: $RR_SHARED_DIR overrides the configured folder).
using ::rr::test::shared_path;

inline std::string read_text(const std::filesystem::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::ostringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

/// Sorted `*.robdef` files of a folder.
inline std::vector<std::filesystem::path> robdef_files(const std::filesystem::path& dir) {
    std::vector<std::filesystem::path> v;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        if (e.path().extension() == ".robdef") v.push_back(e.path());
    std::sort(v.begin(), v.end());
    return v;
}

inline std::string dump(const std::vector<Diagnostic>& ds) {
    std::string s;
    for (const auto& d : ds) s += format_diagnostic(d) + "\n";
    return s;
}

inline std::size_t count(const std::vector<Diagnostic>& ds, Severity sev) {
    return static_cast<std::size_t>(
        std::count_if(ds.begin(), ds.end(), [&](const Diagnostic& d) { return d.severity == sev; }));
}

}  // namespace rr::robdef::test
