#include "server/record/recordings.hpp"

#include <charconv>

#include "server/gateway/auth/http_auth.hpp"
#include "server/gateway/json_rest.hpp"

namespace rr::server::record {

using gateway::ApiError;
using gateway::api_error;

Recordings::Recordings(std::shared_ptr<gateway::JsonApi> api, EventListener on_event)
    : api_(std::move(api)), on_event_(std::move(on_event)) {}

Recordings::~Recordings() { stop_all(); }

std::uint64_t Recordings::failed_start(RecordingSpec spec, const RRError& error) {
    RecordingStatus s;
    s.spec = std::move(spec);
    s.state = RecordingState::failed;
    s.error = error.message;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        s.id = next_id_++;
        entries_[s.id] = Entry{nullptr, s};
    }
    if (on_event_) on_event_(s, "failed");
    return s.id;
}

std::variant<RecordingStatus, ApiError> Recordings::start(RecordingSpec spec) {
    auto device = api_->find_device(spec.device);
    if (!device) return api_error(404, MessageErrorType::ServiceNotFound, "no device \"" + spec.device + "\"");
    std::uint64_t id;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (stopped_) return api_error(503, MessageErrorType::InvalidOperation, "the gateway is stopping");
        id = next_id_++;
    }
    std::weak_ptr<Recordings> weak = weak_from_this();
    auto on_error = [weak](const RecordingStatus& s) {
        if (auto self = weak.lock(); self && self->on_event_) self->on_event_(s, "failed");
    };
    auto r = Recording::start(id, spec, device, api_, on_error);
    if (!r) {
        const auto& e = r.error();
        if (e.type == MessageErrorType::IOError) {
            failed_start(std::move(spec), e);
            return api_error(507, e.type, e.message);
        }
        return api_error(e.type == MessageErrorType::InvalidState ? 503 : 400, e.type, e.message);
    }
    {
        std::lock_guard<std::mutex> lock(mutex_);
        entries_[id] = Entry{*r, std::nullopt};
    }
    auto s = (*r)->status();
    if (on_event_) on_event_(s, "started");
    return s;
}

void Recordings::start_when_connected(RecordingSpec spec) {
    auto device = api_->find_device(spec.device);
    if (!device) {
        failed_start(spec, make_error(MessageErrorType::ServiceNotFound, "record: no device \"" + spec.device + "\""));
        return;
    }
    auto started = std::make_shared<std::atomic<bool>>(false);
    std::weak_ptr<Recordings> weak = weak_from_this();
    auto try_start = [weak, spec, started](const gateway::DeviceStatus& st) {
        if (st.state != gateway::DeviceState::connected || started->exchange(true)) return;
        auto self = weak.lock();
        if (!self) return;
        // Off the device's strand: starting subscribes to the device and creates the first file.
        std::thread([self, spec] {
            auto r = self->start(spec);
            if (auto* e = std::get_if<ApiError>(&r); e && e->status != 507)
                self->failed_start(spec, make_error(MessageErrorType::OperationFailed, e->message));
        }).detach();
    };
    auto id = device->add_state_listener(try_start);
    {
        std::lock_guard<std::mutex> lock(mutex_);
        listeners_.emplace_back(device, id);
    }
    try_start(device->status());
}

void Recordings::stop(std::uint64_t id, std::function<void(std::optional<RecordingStatus>)> done) {
    std::shared_ptr<Recording> r;
    std::optional<RecordingStatus> failed;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        auto it = entries_.find(id);
        if (it == entries_.end()) return done(std::nullopt);
        r = it->second.recording;
        failed = it->second.failed;
    }
    if (!r) return done(failed);
    std::weak_ptr<Recordings> weak = weak_from_this();
    r->stop([weak, done = std::move(done)](const RecordingStatus& s) {
        if (auto self = weak.lock(); self && self->on_event_ && s.state == RecordingState::stopped) self->on_event_(s, "stopped");
        done(s);
    });
}

std::vector<RecordingStatus> Recordings::list() const {
    std::vector<RecordingStatus> out;
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [id, e] : entries_) out.push_back(e.recording ? e.recording->status() : *e.failed);
    return out;
}

std::optional<RecordingStatus> Recordings::get(std::uint64_t id) const {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = entries_.find(id);
    if (it == entries_.end()) return std::nullopt;
    return it->second.recording ? it->second.recording->status() : *it->second.failed;
}

void Recordings::stop_all() {
    std::vector<std::shared_ptr<Recording>> all;
    std::vector<std::pair<std::shared_ptr<gateway::DeviceMirror>, std::uint64_t>> listeners;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stopped_ = true;
        for (auto& [id, e] : entries_)
            if (e.recording) all.push_back(e.recording);
        listeners.swap(listeners_);
    }
    for (auto& [d, id] : listeners) d->remove_state_listener(id);
    for (auto& r : all) r->stop();
    for (auto& r : all) r->wait();
}

// --- routes -----------------------------------------------------------------------------------------

namespace {

namespace bhttp = boost::beast::http;

// "/api/recordings/{id}[/stop]" → id and whether it is the stop route; nullopt for anything else.
std::optional<std::pair<std::uint64_t, bool>> parse_id_path(std::string_view target) {
    target = target.substr(0, target.find('?'));
    constexpr std::string_view prefix = "/api/recordings/";
    if (target.substr(0, prefix.size()) != prefix) return std::nullopt;
    target.remove_prefix(prefix.size());
    bool stop = false;
    if (auto slash = target.find('/'); slash != std::string_view::npos) {
        if (target.substr(slash) != "/stop") return std::nullopt;
        stop = true;
        target = target.substr(0, slash);
    }
    std::uint64_t id = 0;
    auto [p, ec] = std::from_chars(target.data(), target.data() + target.size(), id);
    if (ec != std::errc() || p != target.data() + target.size() || target.empty()) return std::nullopt;
    return std::make_pair(id, stop);
}

ApiError not_found(std::string_view what) {
    return api_error(404, MessageErrorType::ResourceNotFound, "no recording " + std::string(what));
}

// With logins on, starting or stopping a device's recording writes files on the gateway's disk: it takes
// the right to write that device (docs/security.md), as replay control does; a viewer may only list.
std::optional<ApiError> write_refused(const gateway::JsonApi& api, const http::Request& req, const std::string& device) {
    if (!api.auth() || !api.auth()->enabled()) return std::nullopt;
    gateway::MemberAddress a;
    a.device = device;
    a.member = "*";
    auto who = gateway::auth::authenticate_request(*api.auth(), req);
    if (auto* p = std::get_if<gateway::auth::PrincipalPtr>(&who)) a.principal = *p;
    return api.check_access(a, gateway::auth::Operation::write);
}

}  // namespace

void install_recording_routes(http::HttpServer& http, std::shared_ptr<gateway::JsonApi> api,
                              std::shared_ptr<Recordings> recordings) {
    using gateway::error_response;
    using gateway::json_response;
    http.add_route(bhttp::verb::get, "/api/recordings", [api, recordings](const http::Request& req, http::Responder respond) {
        if (auto e = gateway::login_needed(*api, req)) return respond(error_response(req, *e));
        auto list = nlohmann::json::array();
        for (const auto& s : recordings->list()) list.push_back(status_json(s));
        respond(json_response(req, 200, nlohmann::json{{"recordings", std::move(list)}}));
    });
    http.add_route(bhttp::verb::post, "/api/recordings", [api, recordings](const http::Request& req, http::Responder respond) {
        if (auto e = gateway::login_needed(*api, req)) return respond(error_response(req, *e));
        auto body = gateway::parse_request_json(req.body());
        if (!body) return respond(error_response(req, api_error(400, MessageErrorType::InvalidArgument, body.error().message)));
        auto spec = spec_from_json(*body);
        if (!spec) return respond(error_response(req, api_error(400, spec.error().type, spec.error().message)));
        if (auto denied = write_refused(*api, req, spec->device)) return respond(error_response(req, *denied));
        auto r = recordings->start(std::move(*spec));
        if (auto* e = std::get_if<ApiError>(&r)) return respond(error_response(req, *e));
        respond(json_response(req, 201, status_json(std::get<RecordingStatus>(r))));
    });
    http.add_route(bhttp::verb::get, "/api/recordings/", [api, recordings](const http::Request& req, http::Responder respond) {
        if (auto e = gateway::login_needed(*api, req)) return respond(error_response(req, *e));
        auto id = parse_id_path(req.target());
        if (!id || id->second) return respond(error_response(req, not_found(std::string(req.target()))));
        auto s = recordings->get(id->first);
        if (!s) return respond(error_response(req, not_found(std::to_string(id->first))));
        respond(json_response(req, 200, status_json(*s)));
    }, /*prefix=*/true);
    http.add_route(bhttp::verb::post, "/api/recordings/", [api, recordings](const http::Request& req, http::Responder respond) {
        if (auto e = gateway::login_needed(*api, req)) return respond(error_response(req, *e));
        auto id = parse_id_path(req.target());
        if (!id || !id->second) return respond(error_response(req, not_found(std::string(req.target()))));
        auto current = recordings->get(id->first);
        if (!current) return respond(error_response(req, not_found(std::to_string(id->first))));
        if (auto denied = write_refused(*api, req, current->spec.device)) return respond(error_response(req, *denied));
        auto head = std::make_shared<http::Request>(req.base(), std::string());
        recordings->stop(id->first, [head, respond, n = id->first](std::optional<RecordingStatus> s) {
            if (!s) return respond(error_response(*head, not_found(std::to_string(n))));
            respond(json_response(*head, 200, status_json(*s)));
        });
    }, /*prefix=*/true);
}

}  // namespace rr::server::record
