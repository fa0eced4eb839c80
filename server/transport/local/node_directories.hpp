// The node directories of the official Robot Raconteur library on Linux/Unix (wire.md §9; CORE
// `NodeDirectories.cpp`, GetDefaultNodeDirectories): where a node keeps its run files (local transport
// sockets and lookup entries), its configuration (the NodeID cache) and its state.
//
// The computation is pure: it takes a snapshot of the environment and the real user id, so it can be
// tested without touching the process. default_node_directories() takes the snapshot of this process.
//
// Rules (checked against the official package's RobotRaconteurNode.GetNodeDirectories() by
// test/interop/local_dirs.py, for root and for an ordinary user):
//   system dirs:  $ROBOTRACONTEUR_SYSTEM_<KIND>_DIR, else $ROBOTRACONTEUR_SYSTEM_PREFIX + default, else
//                 the default: data /usr/local/share/robotraconteur, config /etc/robotraconteur,
//                 state /var/lib/robotraconteur, cache /var/cache/robotraconteur,
//                 run /var/run/robotraconteur.
//   root (uid 0): every user dir is the system dir of the same kind, except run = <system run>/root;
//                 the ROBOTRACONTEUR_USER_* variables and XDG_* are ignored.
//   other users:  run    = $ROBOTRACONTEUR_USER_RUN_DIR, else $XDG_RUNTIME_DIR/robotraconteur, else
//                          /tmp/robotraconteur-run-<uid> (ROBOTRACONTEUR_USER_HOME plays no part);
//                 data, config, state, cache = $ROBOTRACONTEUR_USER_<KIND>_DIR, else
//                          $ROBOTRACONTEUR_USER_HOME/<rel>, else $XDG_<KIND>_HOME/RobotRaconteur, else
//                          $HOME/<rel>, with <rel> .local/share/RobotRaconteur, .config/RobotRaconteur,
//                          .local/state/RobotRaconteur, .cache/RobotRaconteur; without HOME the dir is
//                          "" (unknown). The state dir's override is ROBOTRACONTEUR_USER_CONFIG_DIR, not
//                          ..._STATE_DIR: the official code reads that variable (a quirk kept here).
//   A variable that is set but empty counts as set (its value "" is used), as getenv() sees it.
//   Paths are joined as boost::filesystem v3 does (path_join below): "/a" + "/b" = "/a/b",
//   "/a/" + "/b" = "/a//b", "" + "b" = "b"; nothing is normalised or resolved.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rr::server::local {

/// The ten directories of CORE's NodeDirectories struct. An empty string means "could not be
/// determined" (a user dir without HOME), as the official library leaves it.
struct NodeDirectories {
    std::string system_data_dir, system_config_dir, system_state_dir, system_cache_dir, system_run_dir;
    std::string user_data_dir, user_config_dir, user_state_dir, user_cache_dir, user_run_dir;

    friend bool operator==(const NodeDirectories&, const NodeDirectories&) = default;
};

/// A snapshot of environment variables (name → value; a present key with an empty value is "set").
using Environment = std::map<std::string, std::string, std::less<>>;

/// Joins two path strings the way boost::filesystem v3's operator/ does: a separator is inserted
/// only when `base` is non-empty, does not end in '/', and `rel` does not start with '/'; `rel` is
/// appended as is (an absolute `rel` does not replace `base`). An empty `rel` returns `base`.
std::string path_join(std::string_view base, std::string_view rel);

/// The node directories for `env` and real user id `uid` (0 = root). Pure.
NodeDirectories compute_node_directories(const Environment& env, std::uint32_t uid);

/// Every variable of this process's environment (reads `environ`).
Environment process_environment();

/// compute_node_directories(process_environment(), getuid()).
NodeDirectories default_node_directories();

/// The names of the variables compute_node_directories() reads (for docs and diagnostics).
const std::vector<std::string_view>& node_directory_variables();

}  // namespace rr::server::local
