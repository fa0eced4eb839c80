// `rr watch`: streams a wire's InValues, an event's firings or a pipe's packets as JSON lines.
#pragma once

#include <atomic>
#include <optional>
#include <ostream>

#include "server/cli/cli_target.hpp"

namespace rr::cli {

/// Streams cl.member of t.object to `out` (one JSON line per value, flushed) until `stop` is set,
/// cl.count values were printed or cl.seconds passed. Errors (rr_error): the member is not a wire,
/// event or pipe; connecting the wire / pipe failed; the connection, wire or pipe endpoint closed.
std::optional<Failure> run_watch(const CommandLine& cl, Target& t, std::ostream& out, const std::atomic<bool>& stop);

}  // namespace rr::cli
