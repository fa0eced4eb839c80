#include "server/cli/cli_options.hpp"

#include <charconv>
#include <cmath>
#include <iterator>
#include <map>

namespace rr::cli {

namespace {

Unexpected usage(std::string message) { return fail(MessageErrorType::InvalidArgument, std::move(message)); }

const std::map<std::string, CommandKind, std::less<>> kCommands = {
    {"info", CommandKind::info}, {"get", CommandKind::get},     {"set", CommandKind::set},
    {"call", CommandKind::call}, {"watch", CommandKind::watch}, {"discover", CommandKind::discover},
    {"record", CommandKind::record}, {"replay", CommandKind::replay},
};

Result<double> parse_seconds(std::string_view flag, std::string_view text) {
    double v = 0;
    auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || p != text.data() + text.size() || !std::isfinite(v) || v <= 0)
        return usage(std::string(flag) + " needs a positive number of seconds, not \"" + std::string(text) + "\"");
    return v;
}

}  // namespace

Result<CommandLine> parse_command_line(const std::vector<std::string>& args) {
    CommandLine cl;
    std::vector<std::string> positional;
    std::optional<std::string> object_path;
    bool want_help = false;
    bool flags_done = false;
    bool timeout_given = false;
    for (std::size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        // Single-dash tokens other than -h are values (negative numbers in JSON arguments).
        if (flags_done || !(a.rfind("--", 0) == 0 || a == "-h")) {
            positional.push_back(a);
            continue;
        }
        if (a == "--") {
            flags_done = true;
            continue;
        }
        if (a == "-h" || a == "--help") {
            want_help = true;
            continue;
        }
        if (a == "--disable-message4") {
            cl.disable_message4 = true;
            continue;
        }
        if (a == "--json") {
            cl.json = true;
            continue;
        }
        if (a == "--loop") {
            cl.loop = true;
            continue;
        }
        std::string flag = a, value;
        if (auto eq = a.find('='); eq != std::string::npos) {
            flag = a.substr(0, eq);
            value = a.substr(eq + 1);
        } else {
            static const char* kWithValue[] = {"--timeout", "--username", "--password", "--token", "--object",
                                               "--count",   "--seconds",  "--tls-ca",   "--http-login",
                                               "--type",    "--interface", "--tls-cert", "--tls-key",
                                               "--duration", "--dir",      "--members", "--encoding",
                                               "--prefix",   "--name",     "--port",    "--address", "--speed"};
            bool known = false;
            for (const char* k : kWithValue) known = known || flag == k;
            if (!known) return usage("unknown option " + flag);
            if (i + 1 >= args.size()) return usage(flag + " needs a value");
            value = args[++i];
        }
        if (flag == "--timeout") {
            auto v = parse_seconds(flag, value);
            if (!v) return v.take_error();
            cl.timeout_s = *v;
            timeout_given = true;
        } else if (flag == "--type") {
            if (value.empty()) return usage("--type needs a service type");
            cl.types.push_back(value);
        } else if (flag == "--interface") {
            if (value.empty()) return usage("--interface needs an interface name");
            cl.interfaces.push_back(value);
        } else if (flag == "--seconds") {
            auto v = parse_seconds(flag, value);
            if (!v) return v.take_error();
            cl.seconds = *v;
        } else if (flag == "--count") {
            std::uint64_t n = 0;
            auto [p, ec] = std::from_chars(value.data(), value.data() + value.size(), n);
            if (ec != std::errc() || p != value.data() + value.size() || n == 0)
                return usage("--count needs a positive integer, not \"" + value + "\"");
            cl.count = n;
        } else if (flag == "--username") {
            cl.username = value;
        } else if (flag == "--password") {
            cl.password = value;
        } else if (flag == "--token") {
            cl.token = value;
        } else if (flag == "--tls-ca") {
            cl.tls_ca_file = value;
        } else if (flag == "--tls-cert") {
            cl.tls_certificate_file = value;
        } else if (flag == "--tls-key") {
            cl.tls_private_key_file = value;
        } else if (flag == "--http-login") {
            if (value.find(':') == std::string::npos) return usage("--http-login needs USER:PASSWORD");
            cl.http_login = value;
        } else if (flag == "--object") {
            object_path = value;
        } else if (flag == "--duration") {
            auto v = parse_seconds(flag, value);
            if (!v) return v.take_error();
            cl.duration = *v;
        } else if (flag == "--speed") {
            auto v = parse_seconds(flag, value);
            if (!v || *v > 1000) return usage("--speed needs a factor above 0 and at most 1000, not \"" + value + "\"");
            cl.speed = *v;
        } else if (flag == "--dir") {
            if (value.empty()) return usage("--dir needs a directory");
            cl.directory = value;
        } else if (flag == "--members") {
            std::size_t start = 0;
            while (start <= value.size()) {
                auto comma = value.find(',', start);
                if (comma == std::string::npos) comma = value.size();
                if (comma == start) return usage("--members needs names separated by commas, not \"" + value + "\"");
                cl.record_members.push_back(value.substr(start, comma - start));
                start = comma + 1;
            }
        } else if (flag == "--encoding") {
            if (value != "json" && value != "robotraconteur" && value != "both")
                return usage("--encoding is json, robotraconteur or both, not \"" + value + "\"");
            cl.encoding = value == "both" ? "" : value;
        } else if (flag == "--prefix") {
            cl.prefix = value;
        } else if (flag == "--name") {
            cl.device_name = value;
        } else if (flag == "--address") {
            cl.address = value;
        } else if (flag == "--port") {
            unsigned n = 0;
            auto [p, ec] = std::from_chars(value.data(), value.data() + value.size(), n);
            if (ec != std::errc() || p != value.data() + value.size() || n > 65535)
                return usage("--port needs a port number 0..65535, not \"" + value + "\"");
            cl.port = static_cast<std::uint16_t>(n);
        } else {
            return usage("unknown option " + flag);
        }
    }

    if (positional.empty()) {
        cl.kind = CommandKind::help;
        if (!want_help) return usage("no command given (try rr --help)");
        return cl;
    }
    auto it = kCommands.find(positional[0]);
    if (positional[0] == "help") {
        cl.kind = CommandKind::help;
        if (positional.size() > 1) cl.help_topic = positional[1];
        return cl;
    }
    if (it == kCommands.end()) return usage("unknown command \"" + positional[0] + "\" (try rr --help)");
    if (want_help) {
        cl.kind = CommandKind::help;
        cl.help_topic = positional[0];
        return cl;
    }
    cl.kind = it->second;
    const std::string& name = positional[0];
    if (cl.kind != CommandKind::discover && (!cl.types.empty() || cl.json))
        return usage("--type and --json apply to discover only");
    if (cl.kind == CommandKind::discover) {
        if (positional.size() != 1) return usage("discover takes no arguments (try rr discover --help)");
        if (!timeout_given) cl.timeout_s = 5;
        if (cl.count || cl.seconds || object_path) return usage("--count, --seconds and --object do not apply to discover");
        return cl;
    }
    const bool record_flags = cl.duration || !cl.record_members.empty() || !cl.encoding.empty() || !cl.prefix.empty() ||
                              !cl.device_name.empty() || cl.directory != "recordings";
    const bool replay_flags = cl.port != 0 || cl.address != "127.0.0.1" || cl.speed != 1.0 || cl.loop;
    if (record_flags && cl.kind != CommandKind::record)
        return usage("--duration, --dir, --members, --encoding, --prefix and --name apply to record only");
    if (replay_flags && cl.kind != CommandKind::replay)
        return usage("--port, --address, --speed and --loop apply to replay only");
    if (cl.kind == CommandKind::replay) {
        if (positional.size() != 2) return usage("replay takes one FILE (try rr replay --help)");
        if (cl.count || cl.seconds || object_path) return usage("--count, --seconds and --object do not apply to replay");
        cl.file = positional[1];
        return cl;
    }
    if (cl.kind == CommandKind::record) {
        if (positional.size() != 2) return usage("record takes one URL (try rr record --help)");
        if (cl.count || cl.seconds || object_path) return usage("--count, --seconds and --object do not apply to record");
        cl.url = positional[1];
        return cl;
    }
    auto need = [&](std::size_t min, std::size_t max) -> Result<void> {
        std::size_t n = positional.size() - 1;
        if (n < min || n > max) return usage("wrong number of arguments for \"" + name + "\" (try rr " + name + " --help)");
        return {};
    };
    Result<void> shape = {};
    switch (cl.kind) {
        case CommandKind::info: shape = need(1, 1); break;
        case CommandKind::get: shape = need(2, 2); break;
        case CommandKind::set: shape = need(3, 3); break;
        case CommandKind::call: shape = need(2, SIZE_MAX); break;
        case CommandKind::watch: shape = need(2, 2); break;
        case CommandKind::discover:
        case CommandKind::record:
        case CommandKind::replay:
        case CommandKind::help: break;
    }
    if (!shape) return shape.take_error();
    cl.url = positional[1];

    if (object_path) {
        auto parsed = parse_object_path(*object_path);
        if (!parsed) return parsed.take_error();
        cl.objects = std::move(parsed->segments);
    }
    if (cl.kind != CommandKind::info) {
        auto parsed = parse_object_path(positional[2]);
        if (!parsed) return parsed.take_error();
        auto& segments = parsed->segments;
        if (segments.back().has_index) return usage("the member itself takes no [key]: \"" + positional[2] + "\"");
        cl.member = std::move(segments.back().name);
        segments.pop_back();
        cl.objects.insert(cl.objects.end(), std::make_move_iterator(segments.begin()), std::make_move_iterator(segments.end()));
        cl.values.assign(positional.begin() + 3, positional.end());
    }
    if ((cl.count || cl.seconds) && cl.kind != CommandKind::watch)
        return usage("--count and --seconds apply to watch only");
    return cl;
}

std::string help_text(std::string_view topic) {
    static const std::string kGeneral =
        "rr: command-line client for Robot Raconteur services (docs/cli.md)\n"
        "\n"
        "usage: rr COMMAND URL [MEMBER] [JSON...] [options]\n"
        "\n"
        "commands:\n"
        "  info  URL                    service definitions and the object's members\n"
        "  get   URL MEMBER             read a property (or peek a wire's InValue)\n"
        "  set   URL MEMBER JSON        write a property (or poke a wire's OutValue)\n"
        "  call  URL FUNCTION [JSON...] call a function; a generator prints each item\n"
        "  watch URL MEMBER             stream a wire's values, an event or a pipe's packets\n"
        "  discover [--type T] [--json] nodes and services found on the network (docs/discovery.md)\n"
        "  record URL [--duration S]    record the service's wires, pipes and events to MCAP files\n"
        "  replay FILE [--port P]       serve a recording as a service on an rr+tcp node\n"
        "\n"
        "URL: rr+tcp://HOST:PORT/?service=NAME (also nodeid=, nodename=; rrs+tcp://, rr+ws://, rr+wss://;\n"
        "     rr+local:///?nodename=NAME&service=S on this computer;\n"
        "     rr+tcp:///?nodename=NAME&service=S finds the node by discovery).\n"
        "MEMBER: name, or a path through objrefs: child.leaf.x, child_by_int[7].value.\n"
        "Values are JSON as in docs/json-mapping.md; output is one JSON value per line.\n"
        "\n"
        "options:\n"
        "  --object PATH        objref path of the object (prepended to MEMBER)\n"
        "  --timeout S          connect and request timeout in seconds (default 15)\n"
        "  --count N            watch: stop after N values\n"
        "  --seconds S          watch: stop after S seconds\n"
        "  --username U --password P   credentials for services that require a login\n"
        "  --username U --token T      a gateway's bearer token or JWT instead (U: NAME@token, SUB@jwt)\n"
        "  --tls-ca FILE        rr+wss, rrs+tcp: PEM certificates to trust (default: the system's)\n"
        "  --tls-cert FILE --tls-key FILE   TLS: this client's certificate and key (mTLS)\n"
        "  --http-login U:P     rr+ws/rr+wss: login for a reverse proxy (HTTP basic auth)\n"
        "  --disable-message4   use message format v2 only\n"
        "  -h, --help           this text; rr COMMAND --help for one command\n"
        "\n"
        "exit status: 0 ok, 1 RR error (name and message on stderr), 2 usage error,\n"
        "3 connect failure\n";
    if (topic.empty()) return kGeneral;
    if (topic == "info")
        return "usage: rr info URL [--object PATH]\n"
               "Prints the service definitions the service sent, then the root object's (or the object at\n"
               "PATH's) type and members, one per line: KIND NAME TYPE [MODIFIERS].\n"
               "Without service= in the URL, lists the node's services (RobotRaconteurServiceIndex).\n";
    if (topic == "discover")
        return "usage: rr discover [--type TYPE]... [--timeout S] [--json] [--interface IF]...\n"
               "Listens for node announces (UDP 48653, IPv6 FF02::BA86) and sends discovery requests for\n"
               "S seconds (default 5), asks each node found for its services (RobotRaconteurServiceIndex),\n"
               "and prints every node with its URLs and services. --type keeps only services whose root\n"
               "object type is TYPE or implements it. --json prints one JSON object per node.\n";
    if (topic == "record")
        return "usage: rr record URL [--duration S] [--dir D] [--members A,B] [--encoding json|robotraconteur|both]\n"
               "                     [--prefix P] [--name NAME]\n"
               "Records the root object's wires, pipes and events (or the --members named, properties\n"
               "polled every second) into MCAP files in D (default ./recordings), the gateway's format\n"
               "(docs/recording.md), until SIGINT/SIGTERM or S seconds, then prints the recording's status\n"
               "as one JSON line. NAME (default: the URL's service) names the topics NAME/MEMBER.\n"
               "Credentials as for the other commands: --username/--password, --username NAME@token\n"
               "--token T (a device behind a gateway's logins), --http-login, --tls-ca/--tls-cert/--tls-key.\n";
    if (topic == "replay")
        return "usage: rr replay FILE [--port P] [--address A] [--speed S] [--loop]\n"
               "Serves the recorded service of FILE (its robotraconteur channels) on an rr+tcp node at\n"
               "A:P (default 127.0.0.1, a free port) until SIGINT/SIGTERM, playing wires, pipes and events\n"
               "with the recorded spacing divided by S; prints the service's URL as the first line.\n";
    if (topic == "get")
        return "usage: rr get URL MEMBER [--object PATH]\n"
               "Prints the value of property MEMBER as one JSON line. For a wire, prints its InValue\n"
               "(PeekInValue).\n";
    if (topic == "set")
        return "usage: rr set URL MEMBER JSON [--object PATH]\n"
               "Writes JSON (typed by the member's robdef type) to property MEMBER, or to a wire's\n"
               "OutValue (PokeOutValue). Prints nothing on success.\n";
    if (topic == "call")
        return "usage: rr call URL FUNCTION [JSON...] [--object PATH]\n"
               "Calls FUNCTION with one JSON argument per parameter. Prints the result as one JSON\n"
               "line (nothing for void). A generator function prints each item as one JSON line\n"
               "until the generator ends.\n";
    if (topic == "watch")
        return "usage: rr watch URL MEMBER [--count N] [--seconds S] [--object PATH]\n"
               "Streams JSON lines until SIGINT/SIGTERM, N values or S seconds:\n"
               "  wire   each InValue\n"
               "  event  an object of the event's parameters by name\n"
               "  pipe   each packet received on a new endpoint\n";
    return {};
}

}  // namespace rr::cli
