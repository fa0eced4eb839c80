#include "server/app/log.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

using namespace rr::server::app;

namespace {
// 2026-11-22T05:10:40.123Z
const auto kTime = std::chrono::system_clock::time_point(std::chrono::milliseconds(1795324240123LL));
}  // namespace

TEST_CASE("log: json format is one object per line with the documented keys", "[log]") {
    auto line = format_log_line(LogFormat::json, kTime, LogLevel::warning, "device create: \"lost\"\nretrying",
                                LogContext{.device = "create", .client = "10.0.0.7:50312", .request = "GET /api/devices"});
    CHECK(line.find('\n') == std::string::npos);
    auto j = nlohmann::json::parse(line);
    REQUIRE(j.is_object());
    CHECK(j.size() == 6);
    CHECK(j["time"] == "2026-11-22T05:10:40.123Z");
    CHECK(j["level"] == "warning");
    CHECK(j["message"] == "device create: \"lost\"\nretrying");
    CHECK(j["device"] == "create");
    CHECK(j["client"] == "10.0.0.7:50312");
    CHECK(j["request"] == "GET /api/devices");
}

TEST_CASE("log: json format gives null for unknown fields and survives invalid UTF-8", "[log]") {
    auto line = format_log_line(LogFormat::json, kTime, LogLevel::info, std::string("bad \xff\xfe bytes"), {});
    auto j = nlohmann::json::parse(line);  // throws if the line were not valid JSON / UTF-8
    CHECK(j["device"].is_null());
    CHECK(j["client"].is_null());
    CHECK(j["request"].is_null());
    CHECK(j["level"] == "info");
    CHECK(j["message"].get<std::string>().find("bytes") != std::string::npos);
}

TEST_CASE("log: text format keeps the time [level] message layout, context appended", "[log]") {
    CHECK(format_log_line(LogFormat::text, kTime, LogLevel::info, "rr-gateway listening", {}) ==
          "2026-11-22T05:10:40.123Z [info] rr-gateway listening");
    CHECK(format_log_line(LogFormat::text, kTime, LogLevel::error, "HTTP 404",
                          LogContext{.client = "127.0.0.1:4000", .request = "GET /nope"}) ==
          "2026-11-22T05:10:40.123Z [error] HTTP 404 (client=127.0.0.1:4000, request=GET /nope)");
}

TEST_CASE("log: formats and levels parse", "[log]") {
    LogFormat f = LogFormat::text;
    CHECK(log_format_from_string("json", f));
    CHECK(f == LogFormat::json);
    CHECK(log_format_from_string("text", f));
    CHECK(f == LogFormat::text);
    CHECK_FALSE(log_format_from_string("xml", f));
    CHECK(log_level_from_string("debug") == LogLevel::debug);
    set_log_level(LogLevel::warning);
    CHECK_FALSE(log_enabled(LogLevel::info));
    CHECK(log_enabled(LogLevel::error));
    set_log_level(LogLevel::info);
}
