#include "server/app/log.hpp"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <mutex>

namespace rr::server::app {
namespace {

std::atomic<LogLevel> g_level{LogLevel::info};
std::mutex g_mutex;

const char* level_name(LogLevel l) {
    switch (l) {
        case LogLevel::trace: return "trace";
        case LogLevel::debug: return "debug";
        case LogLevel::info: return "info";
        case LogLevel::warning: return "warning";
        case LogLevel::error: return "error";
        case LogLevel::fatal: return "fatal";
        case LogLevel::disable: return "";
    }
    return "";
}

}  // namespace

LogLevel log_level_from_string(std::string_view s) noexcept {
    for (auto l : {LogLevel::trace, LogLevel::debug, LogLevel::info, LogLevel::warning, LogLevel::error, LogLevel::fatal,
                   LogLevel::disable})
        if (s == level_name(l) || (l == LogLevel::disable && s == "disable")) return l;
    return LogLevel::info;
}

void set_log_level(LogLevel level) noexcept { g_level.store(level); }

void log(LogLevel level, std::string_view message) {
    if (level < g_level.load() || g_level.load() == LogLevel::disable) return;
    auto now = std::chrono::system_clock::now();
    std::time_t t = std::chrono::system_clock::to_time_t(now);
    std::tm tm{};
    gmtime_r(&t, &tm);
    char stamp[32];
    std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%SZ", &tm);
    std::lock_guard lock(g_mutex);
    std::fprintf(stderr, "%s [%s] %.*s\n", stamp, level_name(level), static_cast<int>(message.size()), message.data());
}

}  // namespace rr::server::app
