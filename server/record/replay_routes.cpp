#include "server/record/replay_routes.hpp"

#include "server/gateway/auth/http_auth.hpp"
#include "server/gateway/json_rest.hpp"

namespace rr::server::record {

namespace bhttp = boost::beast::http;
using gateway::api_error;
using gateway::error_response;
using gateway::json_response;

Result<void> apply_replay_control(ReplayDevice& d, const nlohmann::json& body) {
    if (!body.is_object()) return fail(MessageErrorType::InvalidArgument, "expected an object");
    for (const auto& [k, v] : body.items())
        if (k != "position_s" && k != "speed" && k != "loop" && k != "state")
            return fail(MessageErrorType::InvalidArgument, k + ": unknown key (expected position_s, speed, loop, state)");
    if (body.contains("state")) {
        const auto& s = body["state"];
        if (s != "playing" && s != "paused") return fail(MessageErrorType::InvalidArgument, "state: expected \"playing\" or \"paused\"");
    }
    if (body.contains("position_s")) {
        if (!body["position_s"].is_number()) return fail(MessageErrorType::InvalidArgument, "position_s: expected a number");
        if (auto r = d.seek(body["position_s"].get<double>()); !r) return r;
    }
    if (body.contains("speed")) {
        if (!body["speed"].is_number()) return fail(MessageErrorType::InvalidArgument, "speed: expected a number");
        if (auto r = d.set_speed(body["speed"].get<double>()); !r) return r;
    }
    if (body.contains("loop")) {
        if (!body["loop"].is_boolean()) return fail(MessageErrorType::InvalidArgument, "loop: expected true or false");
        d.set_loop(body["loop"].get<bool>());
    }
    if (body.contains("state")) {
        if (body["state"] == "playing") d.play();
        else d.pause();
    }
    return {};
}

void install_replay_routes(http::HttpServer& http, std::shared_ptr<gateway::JsonApi> api,
                           std::vector<std::shared_ptr<ReplayDevice>> replays) {
    auto all = std::make_shared<const std::vector<std::shared_ptr<ReplayDevice>>>(std::move(replays));
    auto find = [all](std::string_view target) -> std::shared_ptr<ReplayDevice> {
        target = target.substr(0, target.find('?'));
        constexpr std::string_view prefix = "/api/replays/";
        if (target.substr(0, prefix.size()) != prefix) return nullptr;
        auto name = gateway::url_decode(target.substr(prefix.size()), false);
        if (!name) return nullptr;
        for (const auto& d : *all)
            if (d->name() == *name) return d;
        return nullptr;
    };
    http.add_route(bhttp::verb::get, "/api/replays", [api, all](const http::Request& req, http::Responder respond) {
        if (auto e = gateway::login_needed(*api, req)) return respond(error_response(req, *e));
        auto list = nlohmann::json::array();
        for (const auto& d : *all) list.push_back(replay_status_json(d->status()));
        respond(json_response(req, 200, nlohmann::json{{"replays", std::move(list)}}));
    });
    http.add_route(bhttp::verb::get, "/api/replays/", [api, find](const http::Request& req, http::Responder respond) {
        if (auto e = gateway::login_needed(*api, req)) return respond(error_response(req, *e));
        auto d = find(req.target());
        if (!d) return respond(error_response(req, api_error(404, MessageErrorType::ResourceNotFound, "no replayed device " + std::string(req.target()))));
        respond(json_response(req, 200, replay_status_json(d->status())));
    }, /*prefix=*/true);
    http.add_route(bhttp::verb::post, "/api/replays/", [api, find](const http::Request& req, http::Responder respond) {
        if (auto e = gateway::login_needed(*api, req)) return respond(error_response(req, *e));
        auto d = find(req.target());
        if (!d) return respond(error_response(req, api_error(404, MessageErrorType::ResourceNotFound, "no replayed device " + std::string(req.target()))));
        if (api->auth() && api->auth()->enabled()) {
            gateway::MemberAddress a;
            a.device = d->name();
            a.member = "*";
            auto who = gateway::auth::authenticate_request(*api->auth(), req);
            if (auto* p = std::get_if<gateway::auth::PrincipalPtr>(&who)) a.principal = *p;
            if (auto denied = api->check_access(a, gateway::auth::Operation::write)) return respond(error_response(req, *denied));
        }
        auto body = gateway::parse_request_json(req.body());
        if (!body) return respond(error_response(req, api_error(400, MessageErrorType::InvalidArgument, body.error().message)));
        if (auto r = apply_replay_control(*d, *body); !r)
            return respond(error_response(req, api_error(400, r.error().type, r.error().message)));
        respond(json_response(req, 200, replay_status_json(d->status())));
    }, /*prefix=*/true);
}

}  // namespace rr::server::record
