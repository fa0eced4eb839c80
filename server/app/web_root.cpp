#include <filesystem>

#include "server/app/web_root.hpp"

namespace rr::server::app {

std::string default_web_root(const char* argv0) {
    namespace fs = std::filesystem;
    // Next to an installed binary first (share/rr-gateway/web), then the source tree it was built from.
    std::error_code ec;
    fs::path exe = fs::weakly_canonical(fs::path(argv0 ? argv0 : ""), ec);
    for (const fs::path& candidate : {exe.parent_path() / "../share/rr-gateway/web", fs::path(RR_SOURCE_DIR) / "web/dist"}) {
        if (fs::exists(candidate / "index.html", ec)) return fs::weakly_canonical(candidate, ec).string();
    }
    return {};
}

}  // namespace rr::server::app
