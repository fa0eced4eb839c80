#include "server/gateway/json_rest.hpp"

#include "server/gateway/auth/http_auth.hpp"
#include "server/gateway/json_access.hpp"

#include <atomic>
#include <charconv>
#include <map>

namespace rr::server::gateway {

namespace bhttp = boost::beast::http;

http::Response json_response(const http::Request& req, unsigned status, const nlohmann::json& body) {
    auto r = http::make_response(req, static_cast<bhttp::status>(status), json_text(body) + "\n", "application/json");
    r.set(bhttp::field::cache_control, "no-store");
    // The HttpServer has checked the Origin against the allowlist already: allowed browsers may read.
    if (auto origin = req[bhttp::field::origin]; !origin.empty()) {
        r.set(bhttp::field::access_control_allow_origin, origin);
        r.set(bhttp::field::vary, "Origin");
    }
    return r;
}

http::Response result_response(const http::Request& req, const ApiResult& result) {
    if (result.error) return json_response(req, result.error->status, nlohmann::json{{"error", error_object(*result.error)}});
    return json_response(req, 200, result.value);
}

http::Response error_response(const http::Request& req, const ApiError& e) {
    return json_response(req, e.status, nlohmann::json{{"error", error_object(e)}});
}

// With logins on (auth: gateway), a request without a valid login gets 401 / 429.
std::optional<ApiError> login_needed(const JsonApi& api, const http::Request& req) {
    const auto& a = api.auth();
    if (!a || !a->enabled()) return std::nullopt;
    auto who = auth::authenticate_request(*a, req);
    if (auto* e = std::get_if<ApiError>(&who)) return *e;
    return std::nullopt;
}

namespace {

int hex_value(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

std::vector<std::string_view> split(std::string_view s, char sep) {
    std::vector<std::string_view> out;
    while (true) {
        auto p = s.find(sep);
        out.push_back(s.substr(0, p));
        if (p == std::string_view::npos) break;
        s.remove_prefix(p + 1);
    }
    return out;
}

struct Target {
    std::vector<std::string> segments;  // decoded path segments after /api/devices
    std::map<std::string, std::string> query;
};

std::variant<Target, ApiError> parse_target(std::string_view target) {
    const auto q = target.find('?');
    std::string_view path = target.substr(0, q);
    constexpr std::string_view prefix = "/api/devices";
    auto no_route = [&] {
        return api_error(404, MessageErrorType::ResourceNotFound,
                         "no such resource: " + std::string(path) +
                             " (the JSON API's routes are under /api/devices and /api/discovered)");
    };
    if (path.rfind(prefix, 0) != 0) return no_route();
    path.remove_prefix(prefix.size());
    if (!path.empty() && path.back() == '/') path.remove_suffix(1);
    Target t;
    if (!path.empty()) {
        if (path.front() != '/') return no_route();
        for (auto seg : split(path.substr(1), '/')) {
            auto d = url_decode(seg, false);
            if (!d) return api_error(400, MessageErrorType::InvalidArgument, d.error().message);
            t.segments.push_back(std::move(*d));
        }
    }
    if (q != std::string_view::npos) {
        for (auto pair : split(target.substr(q + 1), '&')) {
            if (pair.empty()) continue;
            const auto eq = pair.find('=');
            auto key = url_decode(pair.substr(0, eq), true);
            auto value = url_decode(eq == std::string_view::npos ? std::string_view{} : pair.substr(eq + 1), true);
            if (!key || !value)
                return api_error(400, MessageErrorType::InvalidArgument, "malformed query string");
            t.query[*key] = *value;
        }
    }
    return t;
}

std::optional<ApiError> read_max_items(const nlohmann::json& j, std::size_t& out) {
    if (j.is_number_unsigned()) {
        out = j.get<std::size_t>();
        return std::nullopt;
    }
    if (j.is_number_integer() && j.get<std::int64_t>() >= 0) {
        out = static_cast<std::size_t>(j.get<std::int64_t>());
        return std::nullopt;
    }
    return api_error(400, MessageErrorType::InvalidArgument, "max_items must be a non-negative integer");
}

// POST /api/discovered/add with logins on: a principal allowed to add devices (Principal::may_add_devices).
std::optional<ApiError> may_add_devices(const JsonApi& api, const http::Request& req) {
    const auto& a = api.auth();
    if (!a || !a->enabled()) return std::nullopt;
    auto who = auth::authenticate_request(*a, req);
    if (auto* e = std::get_if<ApiError>(&who)) return *e;
    const auto& p = std::get<auth::PrincipalPtr>(who);
    if (p && p->may_add_devices()) return std::nullopt;
    a->counters().denied.fetch_add(1);
    return api_error(403, MessageErrorType::PermissionDenied,
                     "user " + (p ? p->name : std::string("?")) +
                         " may not add devices: that takes a role allowed read, write and call on every device and member");
}

class RestRouter {
public:
    explicit RestRouter(std::shared_ptr<JsonApi> api) : api_(std::move(api)) {}
    const std::shared_ptr<JsonApi>& api() const noexcept { return api_; }

    void handle(const http::Request& req, http::Responder respond, const std::shared_ptr<http::RequestConnection>& connection = {}) {
        try {
            dispatch(req, respond, connection);
        } catch (const std::exception& e) {
            // nlohmann type errors and the like: a bug, but never a crash of the gateway.
            respond(error_response(req, api_error(500, MessageErrorType::InternalError, e.what())));
        }
    }

private:
    void dispatch(const http::Request& req, const http::Responder& respond, const std::shared_ptr<http::RequestConnection>& connection) {
        const std::string_view target(req.target().data(), req.target().size());
        const std::string_view path = target.substr(0, target.find('?'));
        // HEAD is GET without the body (the HttpServer drops it when writing).
        const auto method = req.method() == bhttp::verb::head ? bhttp::verb::get : req.method();

        auto not_allowed = [&](std::string_view allow) {
            auto r = error_response(req, api_error(405, MessageErrorType::InvalidOperation,
                                                   std::string(req.method_string()) + " is not allowed here (allowed: " +
                                                       std::string(allow) + ")"));
            r.set(bhttp::field::allow, allow);
            respond(std::move(r));
        };
        auto preflight = [&] {
            auto r = json_response(req, 204, nullptr);
            r.body().clear();
            r.set(bhttp::field::access_control_allow_methods, "GET, PUT, POST");
            r.set(bhttp::field::access_control_allow_headers, "Content-Type");
            r.set(bhttp::field::access_control_max_age, "600");
            respond(std::move(r));
        };

        // The discovery routes have their own handlers for their methods (install_json_rest); other
        // methods end up here.
        if (path == "/api/discovered" || path == "/api/discovered/add") {
            if (method == bhttp::verb::options) return preflight();
            return not_allowed(path == "/api/discovered" ? "GET" : "POST");
        }
        if (path == "/api/features" || path == "/api/whoami") {
            if (method == bhttp::verb::options) return preflight();
            return not_allowed("GET");
        }

        auto parsed = parse_target(target);
        if (auto* e = std::get_if<ApiError>(&parsed)) return respond(error_response(req, *e));
        auto& t = std::get<Target>(parsed);
        const auto& seg = t.segments;

        if (method == bhttp::verb::options) return preflight();

        // auth: gateway — every request below needs a login; members are checked by JsonApi.
        auth::PrincipalPtr principal;
        if (const auto& a = api_->auth(); a && a->enabled()) {
            auto who = auth::authenticate_request(*a, req);
            if (auto* e = std::get_if<ApiError>(&who)) {
                auto r = error_response(req, *e);
                if (e->status == 401) r.set(bhttp::field::www_authenticate, "Bearer");
                return respond(std::move(r));
            }
            principal = std::get<auth::PrincipalPtr>(std::move(who));
        }

        if (seg.empty()) {
            if (method != bhttp::verb::get) return not_allowed("GET");
            return respond(json_response(req, 200, api_->device_list()));
        }
        const std::string& device = seg[0];
        if (seg.size() == 1) {
            if (method != bhttp::verb::get) return not_allowed("GET");
            return respond(result_response(req, api_->device_info(device)));
        }
        if (seg.size() == 2 && seg[1] == "definitions") {
            if (method != bhttp::verb::get) return not_allowed("GET");
            return respond(result_response(req, api_->definitions(device)));
        }
        if (seg.size() == 2 && seg[1] == "access") {
            if (method != bhttp::verb::get) return not_allowed("GET");
            auto param = [&](const char* key) -> std::optional<std::string> {
                auto it = t.query.find(key);
                return it == t.query.end() ? std::nullopt : std::optional<std::string>(it->second);
            };
            return respond(result_response(req, member_access(*api_, device, principal, param("members"), param("device_user"))));
        }
        if (seg.size() != 3 || (seg[1] != "properties" && seg[1] != "functions" && seg[1] != "wires"))
            return respond(error_response(req, api_error(404, MessageErrorType::ResourceNotFound,
                                                         "no such resource (routes of a device: /definitions, /access, "
                                                         "/properties/NAME, /functions/NAME, /wires/NAME)")));

        MemberAddress address{device, {}, seg[2], principal};
        if (auto it = t.query.find("object"); it != t.query.end()) address.object = it->second;
        auto done = [req_head = std::make_shared<http::Request>(req.base(), std::string()),
                     respond](ApiResult r) { respond(result_response(*req_head, r)); };

        if (seg[1] == "properties") {
            if (method == bhttp::verb::get) return api_->get_property(address, done);
            if (method != bhttp::verb::put) return not_allowed("GET, PUT");
            auto body = parse_request_json(req.body());
            if (!body) return respond(error_response(req, api_error(400, MessageErrorType::InvalidArgument, body.error().message)));
            if (!body->is_object() || !body->contains("value"))
                return respond(error_response(req, api_error(400, MessageErrorType::InvalidArgument,
                                                             "the body must be an object {\"value\": …}")));
            return api_->set_property(address, (*body)["value"], done);
        }
        if (seg[1] == "wires") {
            if (method != bhttp::verb::get) return not_allowed("GET");
            return api_->peek_wire(address, done);
        }
        // functions
        if (method != bhttp::verb::post) return not_allowed("POST");
        nlohmann::json args = nullptr;
        std::size_t max_items = 0;
        if (auto it = t.query.find("max_items"); it != t.query.end()) {
            std::size_t v = 0;
            auto [p, ec] = std::from_chars(it->second.data(), it->second.data() + it->second.size(), v);
            if (ec != std::errc() || p != it->second.data() + it->second.size())
                return respond(error_response(req, api_error(400, MessageErrorType::InvalidArgument,
                                                             "max_items must be a non-negative integer")));
            max_items = v;
        }
        if (!req.body().empty()) {
            auto body = parse_request_json(req.body());
            if (!body) return respond(error_response(req, api_error(400, MessageErrorType::InvalidArgument, body.error().message)));
            if (!body->is_object())
                return respond(error_response(req, api_error(400, MessageErrorType::InvalidArgument,
                                                             "the body must be an object {\"args\": …}")));
            for (auto it = body->begin(); it != body->end(); ++it) {
                if (it.key() == "args") {
                    args = *it;
                } else if (it.key() == "max_items") {
                    if (auto e = read_max_items(*it, max_items)) return respond(error_response(req, *e));
                } else {
                    return respond(error_response(req, api_error(400, MessageErrorType::InvalidArgument,
                                                                 "unknown key \"" + it.key() + "\" in the body")));
                }
            }
        }
        // Motion safety (docs/security.md "Motion safety"): a user's requests from one address are one
        // holder; a motion without a timeout of its own must wait for its end, and ends when this
        // request's connection closes first.
        auto who = std::make_shared<MotionClient>();
        const std::string client(req[http::kClientAddressField]);
        const std::string ip = client.substr(0, client.rfind(':'));
        const std::string user = principal ? principal->rr_user_name() : std::string();
        who->key = "http:" + user + "@" + ip;
        who->owner = "http-request:" + std::to_string(next_request_.fetch_add(1) + 1);
        who->user = user;
        who->description = "HTTP requests from " + ip;
        address.motion = who;
        address.motion_waits_only = true;
        if (connection)
            connection->on_gone([api = api_, device, owner = who->owner] {
                if (auto d = api->find_device(device))
                    if (const auto& guard = d->motion()) guard->client_gone(owner);
            });
        api_->call_function(address, args, max_items, done);
    }

    std::atomic<std::uint64_t> next_request_{0};

    std::shared_ptr<JsonApi> api_;
};

}  // namespace

Result<std::string> url_decode(std::string_view text, bool plus_is_space) {
    std::string out;
    out.reserve(text.size());
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (c == '%') {
            if (i + 2 >= text.size())
                return fail(MessageErrorType::InvalidArgument, "malformed %-escape in \"" + std::string(text) + "\"");
            const int hi = hex_value(text[i + 1]), lo = hex_value(text[i + 2]);
            if (hi < 0 || lo < 0)
                return fail(MessageErrorType::InvalidArgument, "malformed %-escape in \"" + std::string(text) + "\"");
            out += static_cast<char>(hi * 16 + lo);
            i += 2;
        } else if (c == '+' && plus_is_space) {
            out += ' ';
        } else {
            out += c;
        }
    }
    return out;
}

void install_json_rest(http::HttpServer& http, std::shared_ptr<JsonApi> api) {
    auto router = std::make_shared<RestRouter>(std::move(api));
    auto handler = [router](const http::Request& req, http::Responder respond) { router->handle(req, std::move(respond)); };
    // What this gateway serves of the optional parts (docs/json-api.md "GET /api/features"), so that a
    // page asks once instead of probing routes that answer 404. Public like /api/login: it says only
    // which features are on, which the login page and the dashboard need before anyone logs in.
    http.add_route(bhttp::verb::get, "/api/features", [router](const http::Request& req, http::Responder respond) {
        const auto& api = *router->api();
        const bool logins = api.auth() && api.auth()->enabled();
        respond(json_response(req, 200, nlohmann::json{{"discovery", static_cast<bool>(api.discovery_hooks().list)}, {"auth", logins}}));
    });
    // Without logins /api/whoami still answers, as documented ({"auth": false}); with them
    // install_login_routes serves it.
    if (!router->api()->auth())
        http.add_route(bhttp::verb::get, "/api/whoami", [](const http::Request& req, http::Responder respond) {
            respond(json_response(req, 200, nlohmann::json{{"auth", false}}));
        });
    // Discovery (docs/json-api.md "Discovery"): the nodes and services found, and "add".
    auto no_discovery = [](const http::Request& req) {
        return error_response(req, api_error(404, MessageErrorType::ResourceNotFound, "discovery is not enabled"));
    };
    http.add_route(bhttp::verb::get, "/api/discovered",
                   [router, no_discovery](const http::Request& req, http::Responder respond) {
                       if (auto e = login_needed(*router->api(), req)) return respond(error_response(req, *e));
                       auto hooks = router->api()->discovery_hooks();
                       if (!hooks.list) return respond(no_discovery(req));
                       respond(json_response(req, 200, hooks.list()));
                   });
    http.add_route(bhttp::verb::post, "/api/discovered/add",
                   [router, no_discovery](const http::Request& req, http::Responder respond) {
                       if (auto e = may_add_devices(*router->api(), req)) return respond(error_response(req, *e));
                       auto hooks = router->api()->discovery_hooks();
                       if (!hooks.add) return respond(no_discovery(req));
                       auto body = parse_request_json(req.body());
                       if (!body)
                           return respond(error_response(req, api_error(400, MessageErrorType::InvalidArgument, body.error().message)));
                       auto head = std::make_shared<http::Request>(req.base(), std::string());
                       hooks.add(*body, [head, respond](ApiResult r) { respond(result_response(*head, r)); });
                   });

    // Function calls get their request's connection: a motion they start ends when it closes.
    http.add_watched_route(
        bhttp::verb::post, "/api/devices/",
        [router](const http::Request& req, http::Responder respond, const std::shared_ptr<http::RequestConnection>& connection) {
            router->handle(req, std::move(respond), connection);
        },
        /*prefix=*/true);
    // Every other method and path under /api (the HttpServer tries routes of a method first): the router
    // answers 405 (with Allow) for a method a route does not take and 404 for a path that is no route,
    // both as JSON (docs/json-api.md).
    http.add_route_any_method("/api", handler);
    http.add_route_any_method("/api/", handler, /*prefix=*/true);
}

}  // namespace rr::server::gateway
