#include "server/app/log.hpp"

#include <atomic>
#include <cstdio>
#include <ctime>
#include <mutex>

#include <nlohmann/json.hpp>

namespace rr::server::app {
namespace {

std::atomic<LogLevel> g_level{LogLevel::info};
std::atomic<LogFormat> g_format{LogFormat::text};
std::mutex g_mutex;

std::string timestamp(std::chrono::system_clock::time_point time) {
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(time.time_since_epoch()).count() % 1000;
    std::time_t t = std::chrono::system_clock::to_time_t(time);
    std::tm tm{};
    gmtime_r(&t, &tm);
    char stamp[40];
    const auto n = std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%S", &tm);
    std::snprintf(stamp + n, sizeof stamp - n, ".%03dZ", static_cast<int>(ms < 0 ? ms + 1000 : ms));
    return stamp;
}

}  // namespace

const char* log_level_name(LogLevel l) noexcept {
    switch (l) {
        case LogLevel::trace: return "trace";
        case LogLevel::debug: return "debug";
        case LogLevel::info: return "info";
        case LogLevel::warning: return "warning";
        case LogLevel::error: return "error";
        case LogLevel::fatal: return "fatal";
        case LogLevel::disable: return "disable";
    }
    return "";
}

LogLevel log_level_from_string(std::string_view s) noexcept {
    for (auto l : {LogLevel::trace, LogLevel::debug, LogLevel::info, LogLevel::warning, LogLevel::error, LogLevel::fatal,
                   LogLevel::disable})
        if (s == log_level_name(l)) return l;
    return LogLevel::info;
}

bool log_format_from_string(std::string_view s, LogFormat& out) noexcept {
    if (s == "text") { out = LogFormat::text; return true; }
    if (s == "json") { out = LogFormat::json; return true; }
    return false;
}

void set_log_level(LogLevel level) noexcept { g_level.store(level); }
void set_log_format(LogFormat format) noexcept { g_format.store(format); }

bool log_enabled(LogLevel level) noexcept {
    const auto min = g_level.load();
    return min != LogLevel::disable && level != LogLevel::disable && level >= min;
}

std::string format_log_line(LogFormat format, std::chrono::system_clock::time_point time, LogLevel level,
                            std::string_view message, const LogContext& context) {
    if (format == LogFormat::json) {
        auto field = [](std::string_view v) -> nlohmann::json {
            if (v.empty()) return nullptr;
            return std::string(v);
        };
        nlohmann::ordered_json j;
        j["time"] = timestamp(time);
        j["level"] = log_level_name(level);
        j["message"] = std::string(message);
        j["device"] = field(context.device);
        j["client"] = field(context.client);
        j["request"] = field(context.request);
        // No newline can appear inside: dump() escapes control characters.
        return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    }
    std::string line = timestamp(time);
    line += " [";
    line += log_level_name(level);
    line += "] ";
    line += message;
    std::string extra;
    auto add = [&](const char* key, std::string_view v) {
        if (v.empty()) return;
        extra += extra.empty() ? " (" : ", ";
        extra += key;
        extra += '=';
        extra += v;
    };
    add("device", context.device);
    add("client", context.client);
    add("request", context.request);
    if (!extra.empty()) extra += ')';
    line += extra;
    return line;
}

void log(LogLevel level, std::string_view message, const LogContext& context) {
    if (!log_enabled(level)) return;
    auto line = format_log_line(g_format.load(), std::chrono::system_clock::now(), level, message, context);
    line += '\n';
    std::lock_guard lock(g_mutex);
    std::fwrite(line.data(), 1, line.size(), stderr);
}

}  // namespace rr::server::app
