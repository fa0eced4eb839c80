// `rr discover` and NodeName/NodeID resolution for `rr info rr+tcp:///?nodename=NAME&service=S`
// (docs/cli.md, docs/discovery.md), on server/discovery.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "base/names/connection_url.hpp"
#include "server/cli/cli_options.hpp"

namespace rr::cli {

/// Listens for announces (and sends request rounds) for cl.timeout_s seconds, asks every node found for
/// its services, and prints nodes and services (only services of cl.types, when given): a table, or one
/// JSON object per node with --json. Returns ok (also when nothing was found: a note goes to `err`).
ExitCode run_discover(const CommandLine& cl, std::ostream& out, std::ostream& err);

/// True for a URL that names a node but no host (`rr+tcp:///?nodename=N&service=S`).
bool needs_discovery(const ConnectionUrl& url);

/// Finds the node `url` names (NodeName and/or NodeID) by discovery within `timeout_s` and returns the
/// URLs to try, in order: its announced URLs of the same scheme (with the interface of link-local
/// addresses), `service=` set to `url.service` (or the service index when empty). Errors:
/// NodeNotFound naming what was looked for.
Result<std::vector<std::string>> resolve_through_discovery(const ConnectionUrl& url, double timeout_s,
                                                           const std::vector<std::string>& interfaces);

}  // namespace rr::cli
