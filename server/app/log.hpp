// Leveled logging to stderr for the gateway executable: one line per message, as text or as one JSON
// object per line (gateway.log_format / --log-format; docs/deployment.md §Logs).
#pragma once

#include <chrono>
#include <string>
#include <string_view>

namespace rr::server::app {

enum class LogLevel { trace, debug, info, warning, error, fatal, disable };
enum class LogFormat { text, json };

/// What a message is about; empty fields are unknown (JSON: null; text: left out).
struct LogContext {
    std::string_view device{};   ///< gateway device name (docs/gateway-config.md devices[].name)
    std::string_view client{};   ///< remote address of the client ("ip:port")
    std::string_view request{};  ///< the client's request ("GET /api/devices", a WebSocket subprotocol…)
};

/// Parses "trace" … "disable" (as the config accepts); unknown text gives info.
LogLevel log_level_from_string(std::string_view s) noexcept;
const char* log_level_name(LogLevel level) noexcept;
/// "text" or "json"; false for anything else.
bool log_format_from_string(std::string_view s, LogFormat& out) noexcept;
void set_log_level(LogLevel level) noexcept;
void set_log_format(LogFormat format) noexcept;
/// True when a message at `level` would be written (to skip building costly messages).
bool log_enabled(LogLevel level) noexcept;
void log(LogLevel level, std::string_view message, const LogContext& context = {});

/// One log line without its newline, as log() writes it. Text:
/// `2026-11-22T05:10:40.123Z [info] message (device=…, client=…, request=…)`. JSON: an object with
/// exactly the keys time (UTC, ISO 8601 with milliseconds), level, message, device, client, request
/// (unknown ones null); invalid UTF-8 in any field is replaced by U+FFFD, so every line parses.
std::string format_log_line(LogFormat format, std::chrono::system_clock::time_point time, LogLevel level,
                            std::string_view message, const LogContext& context);

}  // namespace rr::server::app
