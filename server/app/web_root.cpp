#include <filesystem>

#include "server/app/web_root.hpp"

namespace rr::server::app {

std::string default_web_root(const char* argv0) {
    namespace fs = std::filesystem;
    std::error_code ec;
    // The running executable: argv[0] is only a name when the binary was found on PATH.
    fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (ec) exe = fs::weakly_canonical(fs::path(argv0 ? argv0 : ""), ec);
    const fs::path share = exe.parent_path() / ".." / "share" / "rr-gateway";
    auto with_index = [&](const fs::path& dir) {
        return fs::exists(dir / "index.html", ec) ? fs::weakly_canonical(dir, ec).string() : std::string();
    };
    // Installed (cmake --install, the Debian package): only the installed files, never a source tree.
    if (fs::is_directory(share, ec)) return with_index(share / "web");
    return with_index(fs::path(RR_SOURCE_DIR) / "web" / "dist");
}

}  // namespace rr::server::app
