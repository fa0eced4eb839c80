// What an `rr` command works on: the client connection, the object reached through the objref path,
// and typed JSON conversion of a member's values (run on the client's strand, where the received
// definitions live).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robdef/service_definition.hpp"
#include "server/cli/cli_options.hpp"
#include "server/client/client.hpp"

namespace rr::cli {

/// A command's failure: the exit status and the RR error to print.
struct Failure {
    ExitCode code;
    RRError error;
};

/// A member definition with the service its types are relative to.
struct MemberInfo {
    robdef::MemberDefinition def;
    std::string service;  ///< service of the object type that declares the member
};

/// The connected client. Errors: connect_failure (or usage_error for a URL that does not parse).
struct Target {
    std::shared_ptr<client::IoThreads> io;  ///< command_io_threads(): shared with rr+usb when on
    std::shared_ptr<client::Client> client;
    client::ObjectProxy object;  ///< the root, or the object at the objref path

    ~Target();
};

/// `url` with `service=` replaced (when `service` is set).
Result<std::string> url_with_service(const std::string& url, const std::string& service);

/// The WebSocket handshake's Authorization header for --http-login USER:PASSWORD ("" without it);
/// used by every command that connects, `rr record` included.
std::string http_authorization(const CommandLine& cl);

/// Connects to cl.url with cl's timeout and credentials and walks cl.objects.
/// Errors: connect_failure (no session), rr_error (a segment is no objref, unknown key, …).
std::optional<Failure> connect_target(const CommandLine& cl, const std::string& url, Target& target);

/// The definition of `member` on `object`. Errors: ObjectNotFound, MemberNotFound.
Result<MemberInfo> member_info(const client::ObjectProxy& object, const std::string& member);

/// `value` as JSON for `type` (relative to `service`). Errors: those of value_to_json.
Result<nlohmann::json> to_json(client::Client& client, const Value& value, const robdef::TypeDefinition& type,
                               const std::string& service);
/// The Value of `type` that `json` denotes. Errors: those of value_from_json (DataTypeMismatch, …).
Result<Value> from_json(client::Client& client, const nlohmann::json& json, const robdef::TypeDefinition& type,
                        const std::string& service);

/// Parses a JSON command-line argument. Error: InvalidArgument with the parser's message.
Result<nlohmann::json> parse_json_argument(const std::string& text, const std::string& what);

/// One output line (no pretty printing; invalid UTF-8 replaced).
std::string json_line(const nlohmann::json& j);

}  // namespace rr::cli
