// Test helpers for rr+local: a temporary tree of node directories, removed afterwards.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

#include <unistd.h>

#include <catch2/catch.hpp>

#include "server/transport/local/node_directories.hpp"

namespace rr::server::local::testing {

/// A fresh directory under /tmp (mode 0755, so that a test may look at it as another user) and node
/// directories below it: system run `<tmp>/sysrun`, user run `<tmp>/run`, config `<tmp>/config`,
/// state `<tmp>/state`.
struct TempNodeDirs {
    std::string root;
    NodeDirectories dirs;

    TempNodeDirs() {
        char tmpl[] = "/tmp/rr_local_test_XXXXXX";
        char* made = ::mkdtemp(tmpl);
        REQUIRE(made);
        root = made;
        std::filesystem::permissions(root, std::filesystem::perms(0755));
        dirs.system_run_dir = root + "/sysrun";
        dirs.system_config_dir = root + "/sysconfig";
        dirs.system_state_dir = root + "/sysstate";
        dirs.system_data_dir = root + "/sysdata";
        dirs.system_cache_dir = root + "/syscache";
        dirs.user_run_dir = root + "/run";
        dirs.user_config_dir = root + "/config";
        dirs.user_state_dir = root + "/state";
        dirs.user_data_dir = root + "/data";
        dirs.user_cache_dir = root + "/cache";
    }
    ~TempNodeDirs() {
        std::error_code ec;
        // Give back any permission a test took away, then remove everything.
        for (auto it = std::filesystem::recursive_directory_iterator(root, std::filesystem::directory_options::skip_permission_denied, ec);
             !ec && it != std::filesystem::recursive_directory_iterator(); it.increment(ec))
            if (it->is_directory(ec)) std::filesystem::permissions(it->path(), std::filesystem::perms::owner_all, std::filesystem::perm_options::add, ec);
        std::filesystem::remove_all(root, ec);
    }
    TempNodeDirs(const TempNodeDirs&) = delete;
    TempNodeDirs& operator=(const TempNodeDirs&) = delete;
};

/// A NodeName unique to this process and call (tests may run side by side).
inline std::string unique_node_name(std::string_view stem) {
    static int n = 0;
    return std::string(stem) + "." + std::to_string(::getpid()) + "." + std::to_string(++n);
}

}  // namespace rr::server::local::testing
