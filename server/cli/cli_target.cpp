#include "server/cli/cli_target.hpp"

#include <charconv>
#include <cmath>

#include "core/json/value_json.hpp"
#include "base/names/connection_url.hpp"
#include "server/cli/cli_usb.hpp"
#include "server/transport/websocket_connector.hpp"

namespace rr::cli {

using client::Client;
using client::ObjectProxy;

Target::~Target() {
    object = {};
    if (client) (void)client->close_wait(std::chrono::milliseconds(2000));
    client.reset();
    io.reset();
}

Result<std::string> url_with_service(const std::string& url, const std::string& service) {
    auto parsed = parse_connection_url(url);
    if (!parsed) return parsed.take_error();
    if (!service.empty()) parsed->service = service;
    return parsed->to_string();
}

namespace {

// An objref segment's index (its decoded text) as the objref's declared key type asks.
Result<ObjRefIndex> objref_index(const MemberInfo& m, const ObjectPathSegment& seg) {
    using robdef::ObjRefIndexKind;
    const auto c = robdef::objref_index_kind(m.def.type);
    if (!seg.has_index) {
        if (c == ObjRefIndexKind::none) return ObjRefIndex{};
        return fail(MessageErrorType::InvalidArgument, "objref " + seg.name + " needs an index: " + seg.name + "[key]");
    }
    if (c == ObjRefIndexKind::string) return ObjRefIndex{seg.index};
    if (c == ObjRefIndexKind::int32) {
        std::int32_t k = 0;
        const auto& s = seg.index;
        auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), k);
        if (ec != std::errc() || p != s.data() + s.size())
            return fail(MessageErrorType::InvalidArgument, "objref " + seg.name + " takes an int32 index, not \"" + s + "\"");
        return ObjRefIndex{k};
    }
    return fail(MessageErrorType::InvalidArgument, "objref " + seg.name + " takes no index");
}

}  // namespace

std::string http_authorization(const CommandLine& cl) {
    const auto colon = cl.http_login.find(':');
    if (colon == std::string::npos) return {};
    return server::basic_authorization(cl.http_login.substr(0, colon), cl.http_login.substr(colon + 1));
}

std::optional<Failure> connect_target(const CommandLine& cl, const std::string& url, Target& target) {
    // A URL that does not parse is the user's typo (status 2), never a connect failure.
    if (auto parsed = parse_connection_url(url); !parsed) return Failure{ExitCode::usage_error, parsed.error()};
    client::ClientOptions options;
    const auto timeout = std::chrono::milliseconds(static_cast<std::int64_t>(std::ceil(cl.timeout_s * 1000)));
    options.connect_timeout = timeout;
    options.total_connect_timeout = timeout;  // --timeout bounds the whole connect, not each step
    options.request_timeout = timeout;
    options.username = cl.username;
    options.password = cl.password;
    options.token = cl.token;
    options.tls_ca_file = cl.tls_ca_file;
    options.tls_certificate_file = cl.tls_certificate_file;
    options.tls_private_key_file = cl.tls_private_key_file;
    options.http_authorization = http_authorization(cl);
    options.enable_message4 = !cl.disable_message4;
    target.io = command_io_threads(1);
    auto c = Client::connect(target.io->executor(), url, options);
    if (!c) return Failure{ExitCode::connect_failure, c.error()};
    target.client = *c;
    target.object = target.client->root();
    for (const auto& seg : cl.objects) {
        auto m = member_info(target.object, seg.name);
        if (!m) return Failure{ExitCode::rr_error, m.error()};
        if (m->def.kind != robdef::MemberKind::objref)
            return Failure{ExitCode::rr_error, make_error(MessageErrorType::InvalidArgument,
                                                          seg.name + " is " +
                                                              robdef::with_article(robdef::member_kind_keyword(m->def.kind)) +
                                                              ", not an objref")};
        auto index = objref_index(*m, seg);
        if (!index) return Failure{ExitCode::rr_error, index.error()};
        auto next = target.object.objref(seg.name, *index);
        if (!next) return Failure{ExitCode::rr_error, next.error()};
        target.object = *next;
    }
    return std::nullopt;
}

Result<MemberInfo> member_info(const ObjectProxy& object, const std::string& member) {
    const std::string path = object.path();
    return object.client().query<MemberInfo>([path, member](ClientContext& ctx, MonoTime) -> Result<MemberInfo> {
        auto def = ctx.member_definition(path, member);
        if (!def) return def.take_error();
        auto ref = ctx.object(path);
        std::string service;
        if (ref) service = ref->type.substr(0, ref->type.rfind('.'));
        return MemberInfo{**def, service};
    });
}

Result<nlohmann::json> to_json(Client& client, const Value& value, const robdef::TypeDefinition& type,
                               const std::string& service) {
    // Copies: the lambda may outlive this call if the strand does not answer in time.
    return client.query<nlohmann::json>([value, type, service](ClientContext& ctx, MonoTime) {
        return value_to_json(value, type, ctx.definitions(), service);
    });
}

Result<Value> from_json(Client& client, const nlohmann::json& json, const robdef::TypeDefinition& type,
                        const std::string& service) {
    return client.query<Value>([json, type, service](ClientContext& ctx, MonoTime) {
        return value_from_json(json, type, ctx.definitions(), service);
    });
}

Result<nlohmann::json> parse_json_argument(const std::string& text, const std::string& what) {
    try {
        return nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
        return fail(MessageErrorType::InvalidArgument, what + " is not valid JSON: " + e.what());
    }
}

std::string json_line(const nlohmann::json& j) {
    return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace rr::cli
