// The commands of `rr` (docs/cli.md) on top of the native typed client (server/client/client.hpp).
// Values are read and printed with the JSON mapping (docs/json-mapping.md, core/json); output goes to
// `out` (one JSON value per line for get/call/watch), errors to `err` as `rr: <ErrorName>: <message>`.
#pragma once

#include <atomic>
#include <ostream>

#include "base/error/rr_error.hpp"
#include "server/cli/cli_options.hpp"

namespace rr::cli {

/// Writes `rr: <ErrorName>: <message>` and a newline to `err` (the error name from the type when the
/// error has none).
void print_error(std::ostream& err, const RRError& e);

/// Runs a parsed command (not help). `stop` ends a watch (set from a signal handler).
/// Returns the exit status: ok, rr_error (service or typed-client error: MemberNotFound,
/// DataTypeMismatch, …), usage_error (JSON that does not parse, a URL that does not parse),
/// connect_failure (no client session).
ExitCode run_command(const CommandLine& cl, std::ostream& out, std::ostream& err, const std::atomic<bool>& stop);

}  // namespace rr::cli
