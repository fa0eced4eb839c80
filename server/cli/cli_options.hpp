// Command line of `rr`, the command-line client (docs/cli.md): the parsed command, its options, and
// the member path syntax that reaches members of sub-objects through objrefs.
//
// Member paths: `member`, or `objref.member`, `objref[key].member`, … Each segment before the last
// names an objref of the object reached so far; `[key]` is its index (an int32 or a string, as the
// objref's `{int32}` / `{string}` type says). `--object PATH` gives the same objref segments separately
// and is prepended to the member path. Both are object paths, parsed by core's one parser
// (base/names/object_path.hpp: its syntax and error messages; a key may hold any character but `]`).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"
#include "base/names/object_path.hpp"

namespace rr::cli {

/// Exit status of `rr` (docs/cli.md §Exit status).
enum class ExitCode : int {
    ok = 0,
    rr_error = 1,         ///< the service (or the typed client) answered with an RR error
    usage_error = 2,      ///< bad command line, bad URL, JSON that does not parse
    connect_failure = 3,  ///< no client session: unreachable, ServiceNotFound, authentication, …
};

enum class CommandKind { help, info, get, set, call, watch, discover, record, replay };

/// A parsed command line.
struct CommandLine {
    CommandKind kind = CommandKind::help;
    std::string help_topic;            ///< command whose help was asked for ("" = general)
    std::string url;
    std::vector<ObjectPathSegment> objects;  ///< objref segments (from --object and the member path)
    std::optional<std::string> member;       ///< the member's name (not for info)
    std::vector<std::string> values;   ///< JSON texts: set's value, call's arguments
    double timeout_s = 15;             ///< connect and per-request timeout, seconds
    std::optional<std::uint64_t> count;  ///< watch: stop after this many values
    std::optional<double> seconds;       ///< watch: stop after this long
    std::string username, password;
    std::string token;  ///< --token: credentials {"token": …} (a gateway's bearer token or JWT)
    std::string tls_ca_file;           ///< rr+wss, rrs+tcp: PEM certificates to trust ("" = the system's)
    std::string tls_certificate_file;  ///< TLS: own certificate chain (mTLS), "" = none
    std::string tls_private_key_file;  ///< TLS: its private key
    std::string http_login;            ///< rr+ws/rr+wss: USER:PASSWORD for a reverse proxy's basic auth
    bool disable_message4 = false;
    // discover (docs/discovery.md)
    std::vector<std::string> types;       ///< --type: only services of these types (root or implemented)
    bool json = false;                    ///< --json: one JSON object per node
    std::vector<std::string> interfaces;  ///< --interface: network interfaces to use (default: all)
    // record (docs/recording.md "From the command line")
    std::optional<double> duration;        ///< --duration: stop after this many seconds (default: Ctrl-C)
    std::string directory = "recordings";  ///< --dir: where the MCAP files go
    std::vector<std::string> record_members;  ///< --members a,b: root members (default: every wire, pipe, event)
    std::string encoding;                  ///< --encoding json|robotraconteur ("" = both)
    std::string prefix;                    ///< --prefix: file name prefix ("" = the device name)
    std::string device_name;               ///< --name: the device's name in topics ("" = the URL's service)
    // replay
    std::string file;                      ///< replay: the MCAP file
    std::uint16_t port = 0;                ///< --port: rr+tcp port to serve on (0 = any free port)
    std::string address = "127.0.0.1";     ///< --address: address to listen on
    double speed = 1.0;                    ///< --speed: playback speed factor
    bool loop = false;                     ///< --loop: start again at the end
};

/// Parses argv[1..]. Errors: InvalidArgument with a message for the user (unknown command or flag,
/// missing argument, bad number).
Result<CommandLine> parse_command_line(const std::vector<std::string>& args);

/// Help text: general (topic "") or for one command. Empty for an unknown topic.
std::string help_text(std::string_view topic);

}  // namespace rr::cli
