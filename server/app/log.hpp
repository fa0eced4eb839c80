// Minimal leveled logging to stderr for the gateway executable (one line per message, with time).
#pragma once

#include <string>
#include <string_view>

namespace rr::server::app {

enum class LogLevel { trace, debug, info, warning, error, fatal, disable };

/// Parses "trace" … "disable" (as the config accepts); unknown text gives info.
LogLevel log_level_from_string(std::string_view s) noexcept;
void set_log_level(LogLevel level) noexcept;
void log(LogLevel level, std::string_view message);

}  // namespace rr::server::app
