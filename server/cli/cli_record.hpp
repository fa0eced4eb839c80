// `rr record` and `rr replay` (docs/recording.md "From the command line"): the gateway's recorder and
// replay device (server/record) without a gateway. `record` connects to the service the way the gateway
// connects to a device (a DeviceMirror on a node of its own, no listener) so that the recorder gets the
// same shared entries and writes the same files; `replay` serves a file's recorded service on an rr+tcp
// node of its own.
#pragma once

#include <atomic>
#include <ostream>

#include "server/cli/cli_options.hpp"

namespace rr::cli {

/// Records the service at cl.url (cl.record_members, or every wire, pipe and event of the root object)
/// into MCAP files in cl.directory until `stop` is set or cl.duration seconds passed; prints the final
/// recording status (record::status_json) as one JSON line on `out`, progress on `err`.
/// Exit: ok; usage_error (bad URL, a member the object lacks or that cannot be recorded);
/// connect_failure (not connected within cl.timeout_s); rr_error (unwritable directory, the recording
/// failed while running: disk full, ...).
ExitCode run_record(const CommandLine& cl, std::ostream& out, std::ostream& err, const std::atomic<bool>& stop);

/// Serves cl.file's recorded service on an rr+tcp node at cl.address:cl.port until `stop` is set;
/// prints the service's URL as the first line of `out` (flushed), the final replay status
/// (record::replay_status_json) as the last. Exit: ok; rr_error (the file cannot be read or replayed:
/// the reader's message naming the file; the port cannot be bound).
ExitCode run_replay(const CommandLine& cl, std::ostream& out, std::ostream& err, const std::atomic<bool>& stop);

}  // namespace rr::cli
