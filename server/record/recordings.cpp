#include "server/record/recordings.hpp"

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <thread>

#include "server/gateway/auth/http_auth.hpp"
#include "server/gateway/json_rest.hpp"

namespace rr::server::record {

using gateway::ApiError;
using gateway::api_error;

namespace {

RecordingsSettings resolved(RecordingsSettings s) {
    if (s.root.empty()) s.root = default_recordings_root(std::getenv("STATE_DIRECTORY"));
    return s;
}

}  // namespace

Recordings::Recordings(std::shared_ptr<gateway::JsonApi> api, RecordingsSettings settings, EventListener on_event)
    : api_(std::move(api)),
      settings_(resolved(std::move(settings))),
      root_(std::make_shared<RecordingsRoot>(settings_.root, settings_.max_total_bytes)),
      on_event_(std::move(on_event)) {}

Recordings::~Recordings() { stop_all(); }

std::size_t Recordings::active_locked() const {
    std::size_t n = starting_.size();
    for (const auto& [id, e] : entries_)
        if (e.recording) ++n;
    return n;
}

std::size_t Recordings::active() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return active_locked();
}

void Recordings::keep_ended_locked(std::uint64_t id) {
    ended_order_.push_back(id);
    while (ended_order_.size() > settings_.keep_ended) {
        entries_.erase(ended_order_.front());
        ended_order_.pop_front();
    }
}

std::uint64_t Recordings::failed_start(RecordingSpec spec, const RRError& error) {
    RecordingStatus s;
    s.spec = std::move(spec);
    s.state = RecordingState::failed;
    s.error = error.message;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        s.id = next_id_++;
        entries_[s.id] = Entry{nullptr, s};
        keep_ended_locked(s.id);
    }
    if (on_event_) on_event_(s, "failed");
    return s.id;
}

void Recordings::ended(const RecordingStatus& status) {
    std::shared_ptr<Recording> gone;  // released outside the lock (the writer thread holds one more)
    {
        std::lock_guard<std::mutex> lock(mutex_);
        auto it = entries_.find(status.id);
        if (it != entries_.end()) {
            gone = std::move(it->second.recording);
            it->second.ended = status;
            keep_ended_locked(status.id);
        }
    }
    if (on_event_) on_event_(status, status.state == RecordingState::failed ? "failed" : "stopped");
}

void Recordings::start(RecordingSpec spec, StartDone done) { start_impl(std::move(spec), false, std::move(done)); }

void Recordings::start_impl(RecordingSpec spec, bool from_config, StartDone done) {
    auto refuse = [&](ApiError e) {
        if (on_event_ && (e.status == 429 || e.status == 507)) {
            RecordingStatus s;
            s.spec = spec;
            s.state = RecordingState::failed;
            s.error = e.message;
            on_event_(s, "refused");
        }
        if (from_config) failed_start(spec, make_error(MessageErrorType::OperationFailed, e.message));
        done(std::move(e));
    };
    auto device = api_->find_device(spec.device);
    if (!device) return refuse(api_error(404, MessageErrorType::ServiceNotFound, "no device \"" + spec.device + "\""));
    if (auto b = check_spec_bounds(spec, settings_); !b) return refuse(api_error(400, b.error().type, b.error().message));
    if (!spec.queue_bytes_given) spec.queue_bytes = std::min(spec.queue_bytes, settings_.max_queue_bytes);
    std::uint64_t id = 0;
    {
        std::unique_lock<std::mutex> lock(mutex_);
        if (stopped_) {
            lock.unlock();
            return refuse(api_error(503, MessageErrorType::InvalidOperation, "the gateway is stopping"));
        }
        if (const auto n = active_locked(); n >= settings_.max_active) {
            lock.unlock();
            return refuse(api_error(429, MessageErrorType::OutOfSystemResource,
                                    "record: " + std::to_string(n) + " recordings are running or starting, the gateway's limit "
                                    "(recordings.max_active); stop one first"));
        }
        id = next_id_++;
        starting_.emplace(id, nullptr);  // holds the place in max_active until the start is decided
    }
    std::weak_ptr<Recordings> weak = weak_from_this();
    RecordingListeners l;
    l.started = [weak, id, spec, from_config, done](Recording& r, const Result<void>& started) {
        auto self = weak.lock();
        if (!self) return done(api_error(503, MessageErrorType::InvalidOperation, "the gateway is stopping"));
        if (started) {
            {
                std::lock_guard<std::mutex> lock(self->mutex_);
                self->starting_.erase(id);
                self->entries_[id] = Entry{r.shared_from_this(), std::nullopt};
            }
            auto s = r.status();
            if (self->on_event_) self->on_event_(s, "started");
            return done(s);
        }
        {
            std::lock_guard<std::mutex> lock(self->mutex_);
            self->starting_.erase(id);
        }
        const auto& e = started.error();
        if (e.type == MessageErrorType::IOError || from_config) {
            // Listed with its reason (an unwritable folder says why on the dashboard).
            self->failed_start(spec, e);
        } else if (self->on_event_) {
            auto s = r.status();
            self->on_event_(s, "refused");
        }
        done(api_error(507, e.type, e.message));
    };
    l.ended = [weak](const RecordingStatus& s) {
        if (auto self = weak.lock()) self->ended(s);
    };
    auto r = Recording::create(id, spec, device, api_, root_, std::move(l));
    if (!r) {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            starting_.erase(id);
        }
        const auto& e = r.error();
        return refuse(api_error(e.type == MessageErrorType::InvalidState ? 503 : 400, e.type, e.message));
    }
    std::unique_lock<std::mutex> lock(mutex_);
    if (stopped_) {  // stop_all ran while this was being made: it ends now
        lock.unlock();
        (*r)->stop();
        (*r)->wait();
        return;
    }
    if (auto it = starting_.find(id); it != starting_.end()) it->second = *r;  // still starting: stop_all reaches it
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
        // Off the device's strand: starting reads the device's definitions and subscribes to it.
        std::thread([self, spec] { self->start_impl(spec, true, [](std::variant<RecordingStatus, ApiError>) {}); }).detach();
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
    std::optional<RecordingStatus> ended;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        auto it = entries_.find(id);
        if (it == entries_.end()) return done(std::nullopt);
        r = it->second.recording;
        ended = it->second.ended;
    }
    if (!r) return done(ended);
    r->stop([done = std::move(done)](const RecordingStatus& s) { done(s); });
}

std::vector<RecordingStatus> Recordings::list() const {
    std::vector<RecordingStatus> out;
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [id, e] : entries_) out.push_back(e.recording ? e.recording->status() : *e.ended);
    return out;
}

std::optional<RecordingStatus> Recordings::get(std::uint64_t id) const {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = entries_.find(id);
    if (it == entries_.end()) return std::nullopt;
    return it->second.recording ? it->second.recording->status() : *it->second.ended;
}

void Recordings::stop_all() {
    std::vector<std::shared_ptr<Recording>> all;
    std::vector<std::pair<std::shared_ptr<gateway::DeviceMirror>, std::uint64_t>> listeners;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stopped_ = true;
        for (auto& [id, e] : entries_)
            if (e.recording) all.push_back(e.recording);
        for (auto& [id, r] : starting_)
            if (r) all.push_back(r);
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
// the `record` right on that device (docs/security.md); others may list recordings, without their paths.
std::optional<ApiError> record_refused(const gateway::JsonApi& api, const http::Request& req, const std::string& device) {
    if (!api.auth() || !api.auth()->enabled()) return std::nullopt;
    gateway::MemberAddress a;
    a.device = device;
    a.member = "*";
    auto who = gateway::auth::authenticate_request(*api.auth(), req);
    if (auto* p = std::get_if<gateway::auth::PrincipalPtr>(&who)) a.principal = *p;
    return api.check_access(a, gateway::auth::Operation::record);
}

// The status as the caller may see it: in full with the `record` right on its device (or without
// logins), else without what names places on the gateway's disk. Not counted as a refusal.
nlohmann::json status_for(const gateway::JsonApi& api, const http::Request& req, const RecordingStatus& s) {
    if (!api.auth() || !api.auth()->enabled()) return status_json(s);
    auto who = gateway::auth::authenticate_request(*api.auth(), req);
    auto* p = std::get_if<gateway::auth::PrincipalPtr>(&who);
    if (p && *p && (*p)->allows(s.spec.device, "*", gateway::auth::Operation::record)) return status_json(s);
    return status_json_without_paths(s);
}

}  // namespace

nlohmann::json status_json_without_paths(const RecordingStatus& s) {
    auto j = status_json(s);
    j.erase("files");
    j["spec"].erase("directory");
    j["spec"].erase("prefix");
    if (j.contains("error")) j["error"] = "the recording failed (the reason is shown to users with the record right on this device)";
    return j;
}

void install_recording_routes(http::HttpServer& http, std::shared_ptr<gateway::JsonApi> api,
                              std::shared_ptr<Recordings> recordings) {
    using gateway::error_response;
    using gateway::json_response;
    http.add_route(bhttp::verb::get, "/api/recordings", [api, recordings](const http::Request& req, http::Responder respond) {
        if (auto e = gateway::login_needed(*api, req)) return respond(error_response(req, *e));
        auto list = nlohmann::json::array();
        for (const auto& s : recordings->list()) list.push_back(status_for(*api, req, s));
        respond(json_response(req, 200, nlohmann::json{{"recordings", std::move(list)}}));
    });
    http.add_route(bhttp::verb::post, "/api/recordings", [api, recordings](const http::Request& req, http::Responder respond) {
        if (auto e = gateway::login_needed(*api, req)) return respond(error_response(req, *e));
        auto body = gateway::parse_request_json(req.body());
        if (!body) return respond(error_response(req, api_error(400, MessageErrorType::InvalidArgument, body.error().message)));
        auto spec = spec_from_json(*body);
        if (!spec) return respond(error_response(req, api_error(400, spec.error().type, spec.error().message)));
        if (auto denied = record_refused(*api, req, spec->device)) return respond(error_response(req, *denied));
        // Answered once the first file is open (on the recording's writer thread): no disk work here.
        auto head = std::make_shared<http::Request>(req.base(), std::string());
        recordings->start(std::move(*spec), [head, respond](std::variant<RecordingStatus, ApiError> r) {
            if (auto* e = std::get_if<ApiError>(&r)) return respond(error_response(*head, *e));
            respond(json_response(*head, 201, status_json(std::get<RecordingStatus>(r))));
        });
    });
    http.add_route(bhttp::verb::get, "/api/recordings/", [api, recordings](const http::Request& req, http::Responder respond) {
        if (auto e = gateway::login_needed(*api, req)) return respond(error_response(req, *e));
        auto id = parse_id_path(req.target());
        if (!id || id->second) return respond(error_response(req, not_found(std::string(req.target()))));
        auto s = recordings->get(id->first);
        if (!s) return respond(error_response(req, not_found(std::to_string(id->first))));
        respond(json_response(req, 200, status_for(*api, req, *s)));
    }, /*prefix=*/true);
    http.add_route(bhttp::verb::post, "/api/recordings/", [api, recordings](const http::Request& req, http::Responder respond) {
        if (auto e = gateway::login_needed(*api, req)) return respond(error_response(req, *e));
        auto id = parse_id_path(req.target());
        if (!id || !id->second) return respond(error_response(req, not_found(std::string(req.target()))));
        auto current = recordings->get(id->first);
        if (!current) return respond(error_response(req, not_found(std::to_string(id->first))));
        if (auto denied = record_refused(*api, req, current->spec.device)) return respond(error_response(req, *denied));
        auto head = std::make_shared<http::Request>(req.base(), std::string());
        recordings->stop(id->first, [head, respond, n = id->first](std::optional<RecordingStatus> s) {
            if (!s) return respond(error_response(*head, not_found(std::to_string(n))));
            respond(json_response(*head, 200, status_json(*s)));
        });
    }, /*prefix=*/true);
}

}  // namespace rr::server::record
