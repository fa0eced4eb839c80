// Node directories from an environment snapshot (node_directories.hpp). The expected values are what
// the official package's RobotRaconteurNode.GetNodeDirectories() printed for the same environment on
// Linux (robotraconteur 1.2.9; test/interop/local_dirs.py re-checks a matrix of them live).
#include <catch2/catch.hpp>

#include <cstdlib>
#include <string>

#include "server/transport/local/node_directories.hpp"

using namespace rr::server::local;

TEST_CASE("local dirs: path_join follows boost::filesystem v3") {
    CHECK(path_join("/a", "b") == "/a/b");
    CHECK(path_join("/a/", "b") == "/a/b");
    CHECK(path_join("/a", "/b") == "/a/b");     // an absolute right side is appended, not substituted
    CHECK(path_join("/a/", "/b") == "/a//b");   // both separators kept
    CHECK(path_join("", "/b") == "/b");
    CHECK(path_join("", "b") == "b");
    CHECK(path_join("/a", "") == "/a");
    CHECK(path_join("rel", "x/y") == "rel/x/y");
}

TEST_CASE("local dirs: root uses the system dirs and <system run>/root") {
    Environment env{{"HOME", "/root"}, {"XDG_RUNTIME_DIR", "/run/user/0"}, {"ROBOTRACONTEUR_USER_RUN_DIR", "/ignored"},
                    {"ROBOTRACONTEUR_USER_CONFIG_DIR", "/ignored"}};
    auto d = compute_node_directories(env, 0);
    CHECK(d.system_data_dir == "/usr/local/share/robotraconteur");
    CHECK(d.system_config_dir == "/etc/robotraconteur");
    CHECK(d.system_state_dir == "/var/lib/robotraconteur");
    CHECK(d.system_cache_dir == "/var/cache/robotraconteur");
    CHECK(d.system_run_dir == "/var/run/robotraconteur");
    CHECK(d.user_data_dir == d.system_data_dir);
    CHECK(d.user_config_dir == "/etc/robotraconteur");
    CHECK(d.user_state_dir == "/var/lib/robotraconteur");
    CHECK(d.user_cache_dir == d.system_cache_dir);
    CHECK(d.user_run_dir == "/var/run/robotraconteur/root");
}

TEST_CASE("local dirs: system overrides and the prefix") {
    SECTION("prefix is prepended to every default") {
        auto d = compute_node_directories({{"ROBOTRACONTEUR_SYSTEM_PREFIX", "/opt/pre"}}, 0);
        CHECK(d.system_run_dir == "/opt/pre/var/run/robotraconteur");
        CHECK(d.system_config_dir == "/opt/pre/etc/robotraconteur");
        CHECK(d.user_run_dir == "/opt/pre/var/run/robotraconteur/root");
    }
    SECTION("a trailing slash on the prefix doubles the separator, an empty prefix is no prefix") {
        CHECK(compute_node_directories({{"ROBOTRACONTEUR_SYSTEM_PREFIX", "/opt/pre/"}}, 0).system_state_dir ==
              "/opt/pre//var/lib/robotraconteur");
        CHECK(compute_node_directories({{"ROBOTRACONTEUR_SYSTEM_PREFIX", ""}}, 0).system_state_dir == "/var/lib/robotraconteur");
        CHECK(compute_node_directories({{"ROBOTRACONTEUR_SYSTEM_PREFIX", "rel"}}, 0).system_state_dir == "rel/var/lib/robotraconteur");
    }
    SECTION("an explicit dir wins over the prefix") {
        auto d = compute_node_directories({{"ROBOTRACONTEUR_SYSTEM_PREFIX", "/p"}, {"ROBOTRACONTEUR_SYSTEM_RUN_DIR", "/x/run"},
                                           {"ROBOTRACONTEUR_SYSTEM_STATE_DIR", "/x/state"}, {"ROBOTRACONTEUR_SYSTEM_CONFIG_DIR", "/x/etc"},
                                           {"ROBOTRACONTEUR_SYSTEM_DATA_DIR", "/x/data"}, {"ROBOTRACONTEUR_SYSTEM_CACHE_DIR", "/x/cache"}},
                                          0);
        CHECK(d.system_run_dir == "/x/run");
        CHECK(d.user_run_dir == "/x/run/root");
        CHECK(d.user_state_dir == "/x/state");
        CHECK(d.user_config_dir == "/x/etc");
        CHECK(d.user_data_dir == "/x/data");
        CHECK(d.user_cache_dir == "/x/cache");
    }
}

TEST_CASE("local dirs: an ordinary user") {
    SECTION("HOME only: /tmp/robotraconteur-run-<uid> and dirs under HOME") {
        auto d = compute_node_directories({{"HOME", "/home/ann"}}, 1000);
        CHECK(d.user_run_dir == "/tmp/robotraconteur-run-1000");
        CHECK(d.user_config_dir == "/home/ann/.config/RobotRaconteur");
        CHECK(d.user_data_dir == "/home/ann/.local/share/RobotRaconteur");
        CHECK(d.user_state_dir == "/home/ann/.local/state/RobotRaconteur");
        CHECK(d.user_cache_dir == "/home/ann/.cache/RobotRaconteur");
        CHECK(d.system_run_dir == "/var/run/robotraconteur");
    }
    SECTION("XDG variables") {
        auto d = compute_node_directories({{"HOME", "/home/ann"}, {"XDG_RUNTIME_DIR", "/run/user/1000"},
                                           {"XDG_CONFIG_HOME", "/cfg/"}, {"XDG_DATA_HOME", "/data"},
                                           {"XDG_STATE_HOME", "/state"}, {"XDG_CACHE_HOME", "/cache"}},
                                          1000);
        CHECK(d.user_run_dir == "/run/user/1000/robotraconteur");
        CHECK(d.user_config_dir == "/cfg/RobotRaconteur");
        CHECK(d.user_data_dir == "/data/RobotRaconteur");
        CHECK(d.user_state_dir == "/state/RobotRaconteur");
        CHECK(d.user_cache_dir == "/cache/RobotRaconteur");
    }
    SECTION("ROBOTRACONTEUR_USER_HOME beats XDG for the home dirs but not for the run dir") {
        auto d = compute_node_directories({{"HOME", "/home/ann"}, {"ROBOTRACONTEUR_USER_HOME", "/h"},
                                           {"XDG_CONFIG_HOME", "/cfg"}, {"XDG_RUNTIME_DIR", "/run/user/1000"}},
                                          1000);
        CHECK(d.user_config_dir == "/h/.config/RobotRaconteur");
        CHECK(d.user_run_dir == "/run/user/1000/robotraconteur");
    }
    SECTION("explicit user dirs; the state dir follows ROBOTRACONTEUR_USER_CONFIG_DIR (official quirk)") {
        auto d = compute_node_directories({{"HOME", "/home/ann"}, {"ROBOTRACONTEUR_USER_RUN_DIR", "/ur"},
                                           {"ROBOTRACONTEUR_USER_CONFIG_DIR", "/uc"}, {"ROBOTRACONTEUR_USER_STATE_DIR", "/us"},
                                           {"ROBOTRACONTEUR_USER_DATA_DIR", "/ud"}, {"ROBOTRACONTEUR_USER_CACHE_DIR", "/ucc"},
                                           {"XDG_STATE_HOME", "/xs"}},
                                          1000);
        CHECK(d.user_run_dir == "/ur");
        CHECK(d.user_config_dir == "/uc");
        CHECK(d.user_state_dir == "/uc");
        CHECK(d.user_data_dir == "/ud");
        CHECK(d.user_cache_dir == "/ucc");
    }
    SECTION("set-but-empty variables count as set") {
        auto d = compute_node_directories({{"HOME", "/home/ann"}, {"XDG_RUNTIME_DIR", ""}, {"XDG_CONFIG_HOME", ""}}, 1000);
        CHECK(d.user_run_dir == "robotraconteur");
        CHECK(d.user_config_dir == "RobotRaconteur");
    }
    SECTION("no HOME: the home dirs are unknown, the run dir is not") {
        auto d = compute_node_directories({}, 65534);
        CHECK(d.user_config_dir.empty());
        CHECK(d.user_state_dir.empty());
        CHECK(d.user_run_dir == "/tmp/robotraconteur-run-65534");
    }
}

TEST_CASE("local dirs: the process snapshot matches getenv") {
    auto env = process_environment();
    REQUIRE_FALSE(node_directory_variables().empty());
    for (auto name : node_directory_variables()) {
        const char* v = std::getenv(std::string(name).c_str());
        INFO(name);
        if (v) {
            REQUIRE(env.count(name) == 1);
            CHECK(env.find(name)->second == v);
        } else {
            CHECK(env.count(name) == 0);
        }
    }
    // PATH-like values keep everything after the first '='.
    for (const auto& [k, val] : env) CHECK(std::getenv(k.c_str()) != nullptr);
}
