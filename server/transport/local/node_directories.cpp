#include "server/transport/local/node_directories.hpp"

#include <unistd.h>

extern char** environ;

namespace rr::server::local {

namespace {

std::optional<std::string> get(const Environment& env, std::string_view name) {
    auto it = env.find(name);
    if (it == env.end()) return std::nullopt;
    return it->second;
}

// CORE system_unix_dir: explicit variable, else prefix + default, else default.
std::string system_dir(const Environment& env, std::string_view default_dir, std::string_view var) {
    if (auto v = get(env, var)) return *v;
    if (auto prefix = get(env, "ROBOTRACONTEUR_SYSTEM_PREFIX")) return path_join(*prefix, default_dir);
    return std::string(default_dir);
}

// CORE user_unix_home_dir: explicit variable, else ROBOTRACONTEUR_USER_HOME/rel, else XDG/RobotRaconteur,
// else HOME/rel, else unknown ("").
std::string user_home_dir(const Environment& env, std::string_view rel, std::string_view xdg, std::string_view var) {
    if (auto v = get(env, var)) return *v;
    if (auto home = get(env, "ROBOTRACONTEUR_USER_HOME")) return path_join(*home, rel);
    if (auto x = get(env, xdg)) return path_join(*x, "RobotRaconteur");
    if (auto home = get(env, "HOME")) return path_join(*home, rel);
    return {};
}

// CORE user_unix_run_dir.
std::string user_run_dir(const Environment& env, std::uint32_t uid) {
    if (auto v = get(env, "ROBOTRACONTEUR_USER_RUN_DIR")) return *v;
    if (auto x = get(env, "XDG_RUNTIME_DIR")) return path_join(*x, "robotraconteur");
    return "/tmp/robotraconteur-run-" + std::to_string(uid);
}

}  // namespace

std::string path_join(std::string_view base, std::string_view rel) {
    std::string out(base);
    if (rel.empty()) return out;
    if (!out.empty() && out.back() != '/' && rel.front() != '/') out.push_back('/');
    out.append(rel);
    return out;
}

NodeDirectories compute_node_directories(const Environment& env, std::uint32_t uid) {
    NodeDirectories d;
    d.system_data_dir = system_dir(env, "/usr/local/share/robotraconteur", "ROBOTRACONTEUR_SYSTEM_DATA_DIR");
    d.system_config_dir = system_dir(env, "/etc/robotraconteur", "ROBOTRACONTEUR_SYSTEM_CONFIG_DIR");
    d.system_state_dir = system_dir(env, "/var/lib/robotraconteur", "ROBOTRACONTEUR_SYSTEM_STATE_DIR");
    d.system_cache_dir = system_dir(env, "/var/cache/robotraconteur", "ROBOTRACONTEUR_SYSTEM_CACHE_DIR");
    d.system_run_dir = system_dir(env, "/var/run/robotraconteur", "ROBOTRACONTEUR_SYSTEM_RUN_DIR");
    if (uid == 0) {
        d.user_data_dir = d.system_data_dir;
        d.user_config_dir = d.system_config_dir;
        d.user_state_dir = d.system_state_dir;
        d.user_cache_dir = d.system_cache_dir;
        d.user_run_dir = path_join(d.system_run_dir, "root");
        return d;
    }
    d.user_data_dir = user_home_dir(env, ".local/share/RobotRaconteur", "XDG_DATA_HOME", "ROBOTRACONTEUR_USER_DATA_DIR");
    d.user_config_dir = user_home_dir(env, ".config/RobotRaconteur", "XDG_CONFIG_HOME", "ROBOTRACONTEUR_USER_CONFIG_DIR");
    // The official code reads ROBOTRACONTEUR_USER_CONFIG_DIR here (NodeDirectories.cpp, user_state_dir).
    d.user_state_dir = user_home_dir(env, ".local/state/RobotRaconteur", "XDG_STATE_HOME", "ROBOTRACONTEUR_USER_CONFIG_DIR");
    d.user_cache_dir = user_home_dir(env, ".cache/RobotRaconteur", "XDG_CACHE_HOME", "ROBOTRACONTEUR_USER_CACHE_DIR");
    d.user_run_dir = user_run_dir(env, uid);
    return d;
}

Environment process_environment() {
    Environment env;
    for (char** e = environ; e && *e; ++e) {
        std::string_view kv(*e);
        auto eq = kv.find('=');
        if (eq == std::string_view::npos) continue;
        env.emplace(std::string(kv.substr(0, eq)), std::string(kv.substr(eq + 1)));
    }
    return env;
}

NodeDirectories default_node_directories() {
    return compute_node_directories(process_environment(), static_cast<std::uint32_t>(::getuid()));
}

const std::vector<std::string_view>& node_directory_variables() {
    static const std::vector<std::string_view> names{
        "ROBOTRACONTEUR_SYSTEM_PREFIX",     "ROBOTRACONTEUR_SYSTEM_DATA_DIR",  "ROBOTRACONTEUR_SYSTEM_CONFIG_DIR",
        "ROBOTRACONTEUR_SYSTEM_STATE_DIR",  "ROBOTRACONTEUR_SYSTEM_CACHE_DIR", "ROBOTRACONTEUR_SYSTEM_RUN_DIR",
        "ROBOTRACONTEUR_USER_HOME",         "ROBOTRACONTEUR_USER_DATA_DIR",    "ROBOTRACONTEUR_USER_CONFIG_DIR",
        "ROBOTRACONTEUR_USER_CACHE_DIR",    "ROBOTRACONTEUR_USER_RUN_DIR",     "XDG_RUNTIME_DIR",
        "XDG_DATA_HOME",                    "XDG_CONFIG_HOME",                 "XDG_STATE_HOME",
        "XDG_CACHE_HOME",                   "HOME"};
    return names;
}

}  // namespace rr::server::local
