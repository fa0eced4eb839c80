#include "server/gateway/device_mirror.hpp"

#include "core/session/elements.hpp"
#include "server/gateway/device_types.hpp"
#include "server/gateway/mirror_service.hpp"
#include "server/gateway/motion_guard.hpp"
#include "server/node/node.hpp"

namespace rr::server::gateway {

std::string_view device_state_name(DeviceState s) noexcept {
    switch (s) {
        case DeviceState::connecting: return "connecting";
        case DeviceState::connected: return "connected";
        case DeviceState::failed: return "failed";
    }
    return "unknown";
}

std::string_view device_auth_name(DeviceAuth a) noexcept {
    switch (a) {
        case DeviceAuth::shared: return "shared";
        case DeviceAuth::passthrough: return "passthrough";
    }
    return "unknown";
}

void DeviceCounters::observe_latency(std::chrono::steady_clock::duration d) {
    const double s = std::chrono::duration<double>(d).count();
    std::size_t i = 0;
    while (i < std::size(kLatencyBuckets) && s > kLatencyBuckets[i]) ++i;
    latency_buckets[i].fetch_add(1);
    latency_sum_us.fetch_add(static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::microseconds>(d).count()));
}

Result<std::shared_ptr<DeviceMirror>> DeviceMirror::create(std::shared_ptr<Node> node, DeviceConfig config) {
    bool valid = !config.name.empty() && ((config.name[0] >= 'a' && config.name[0] <= 'z') ||
                                          (config.name[0] >= 'A' && config.name[0] <= 'Z'));
    for (char c : config.name)
        valid = valid && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_');
    if (!valid)
        return fail(MessageErrorType::InvalidConfiguration,
                    "device name \"" + config.name + "\" is not a valid service name (letters, digits, _; starts with a letter)");
    auto url = parse_connection_url(config.url);
    if (!url) return fail(MessageErrorType::InvalidConfiguration, "device \"" + config.name + "\": " + url.error().message);
    if (url->service.empty())
        return fail(MessageErrorType::InvalidConfiguration, "device \"" + config.name + "\": URL names no service (?service=…)");
    if (!node->transports().find(url->scheme)) {
        std::string known;
        for (const auto& s : node->transports().schemes()) known += (known.empty() ? "" : ", ") + s;
        return fail(MessageErrorType::InvalidConfiguration, "device \"" + config.name + "\": no transport for \"" +
                                                                url->scheme + "\" URLs (known: " + known + ")");
    }
    std::shared_ptr<DeviceMirror> m(new DeviceMirror(std::move(node), std::move(config), std::move(*url)));
    m->service_ = std::make_shared<MirrorService>(m, m->counters_, m->config_.name, m->url_.service);
    // The gateway's own stops and generator aborts (motion safety) go to the device like the JSON API's
    // requests: on a client's passthrough session, or on the shared one.
    {
        auto node = m->node_.lock();
        std::weak_ptr<DeviceMirror> weak = m;
        m->motion_ = std::make_shared<MotionGuard>(
            node->io_context().get_executor(), m->config_.name, m->config_.safety,
            [weak](MessageEntry e, std::uint32_t session, std::function<void(Result<MessageEntry>)> done) {
                auto self = weak.lock();
                if (!self) return done(fail(MessageErrorType::ConnectionError, "gateway device stopped"));
                self->request_stop(std::move(e), std::move(done), session);
            });
        m->service_->set_motion_guard(m->motion_);
    }
    // Lock holders are part of the device's status (JSON API pushes, the dashboard).
    m->service_->set_locks_listener([weak = std::weak_ptr<DeviceMirror>(m)] {
        if (auto self = weak.lock()) self->notify_state();
    });
    if (m->config_.auth == DeviceAuth::passthrough) {
        auto node = m->node_.lock();
        PassthroughSessions::Settings ps;
        ps.device_name = m->config_.name;
        ps.upstream_service = m->url_.service;
        ps.url = m->url_;
        ps.options = m->upstream_options(*node);
        ps.max_sessions = m->config_.max_passthrough_sessions;
        std::weak_ptr<DeviceMirror> weak = m;
        ps.on_change = [weak] {
            if (auto self = weak.lock()) self->notify_state();
        };
        m->service_->set_passthrough(
            std::make_shared<PassthroughSessions>(node->io_context().get_executor(), std::move(ps),
                                                  m->counters_));
    }
    return m;
}

DeviceMirror::DeviceMirror(std::shared_ptr<Node> node, DeviceConfig config, ConnectionUrl url)
    : node_(node), config_(std::move(config)), url_(std::move(url)), timer_(node->io_context()),
      backoff_(config_.backoff_initial) {}

DeviceMirror::~DeviceMirror() { stop(); }

void DeviceMirror::start() {
    {
        std::lock_guard lock(mutex_);
        stopped_ = false;
    }
    if (const auto& p = service_->passthrough()) p->reopen();
    connect();
}

void DeviceMirror::stop() {
    std::shared_ptr<RawClient> client;
    {
        std::lock_guard lock(mutex_);
        stopped_ = true;
        client = std::move(client_);
        ++generation_;
    }
    timer_.cancel();
    if (client) client->close();
    if (service_) service_->stop_passthrough();
    if (auto node = node_.lock(); node && registered_) node->unregister_service(config_.name);
}

void DeviceMirror::connect() {
    auto node = node_.lock();
    if (!node) return;
    std::uint64_t gen;
    {
        std::lock_guard lock(mutex_);
        if (stopped_) return;
        state_ = DeviceState::connecting;
        gen = ++generation_;
    }
    RawClientOptions options = upstream_options(*node);
    options.username = config_.username;
    options.password = config_.password;
    if (!config_.token.empty()) options.credentials = token_credentials(config_.token);
    std::weak_ptr<DeviceMirror> weak = weak_from_this();
    RawClient::connect(
        node->io_context().get_executor(), url_, options,
        [weak, gen](MessageEntry&& e) {
            if (auto self = weak.lock()) {
                std::lock_guard lock(self->mutex_);
                if (self->generation_ != gen) return;
            }
            if (auto self = weak.lock()) self->on_upstream_entry(std::move(e));
        },
        [weak, gen](const RRError& error) {
            auto self = weak.lock();
            if (!self) return;
            {
                std::lock_guard lock(self->mutex_);
                if (self->generation_ != gen) return;
            }
            self->on_disconnected(error);
        },
        [weak, gen](Result<std::shared_ptr<RawClient>> r) {
            auto self = weak.lock();
            if (!self) return;
            {
                std::lock_guard lock(self->mutex_);
                if (self->generation_ != gen || self->stopped_) {
                    if (r) (*r)->close();
                    return;
                }
            }
            if (r)
                self->on_connected(std::move(*r));
            else
                self->on_disconnected(r.error());
        });
}

RawClientOptions DeviceMirror::upstream_options(Node& node) const {
    RawClientOptions options;
    options.local_node_name = node.node_name().empty() ? std::string() : node.node_name();
    options.tls_ca_file = config_.tls_ca;
    options.tls_certificate_file = config_.tls_certificate;
    options.tls_private_key_file = config_.tls_private_key;
    options.http_authorization = config_.http_authorization;
    options.transports = &node.transports();
    return options;
}

void DeviceMirror::set_state_listener(std::function<void(const DeviceStatus&)> listener) {
    std::lock_guard lock(mutex_);
    state_listener_ = std::move(listener);
}

std::uint64_t DeviceMirror::add_state_listener(std::function<void(const DeviceStatus&)> listener) {
    std::lock_guard lock(mutex_);
    const auto id = next_listener_id_++;
    extra_listeners_.emplace(id, std::move(listener));
    return id;
}

void DeviceMirror::remove_state_listener(std::uint64_t id) {
    std::lock_guard lock(mutex_);
    extra_listeners_.erase(id);
}

void DeviceMirror::notify_state() {
    std::vector<std::function<void(const DeviceStatus&)>> listeners;
    {
        std::lock_guard lock(mutex_);
        if (state_listener_) listeners.push_back(state_listener_);
        for (const auto& [id, l] : extra_listeners_) listeners.push_back(l);
    }
    if (listeners.empty()) return;
    const auto s = status();
    for (const auto& l : listeners) l(s);
}

void DeviceMirror::on_connected(std::shared_ptr<RawClient> client) {
    bool do_register = false;
    {
        std::lock_guard lock(mutex_);
        client_ = client;
        backoff_ = config_.backoff_initial;
        definitions_ = client->info().service_definitions;
        object_type_ = client->info().object_type;
        implements_ = client->info().object_implements;
        attributes_ = client->info().attributes;
        do_register = !registered_;
        registered_ = true;
    }
    {
        // Which members move the device (its root type and definitions: motion_rules.hpp).
        auto types = DeviceTypes::parse(service_definitions());
        motion_->set_root(root_type(), types ? types->get() : nullptr);
    }
    if (do_register) {
        auto node = node_.lock();
        auto r = node ? node->register_service(service_) : Result<void>(fail(MessageErrorType::InvalidState, "gateway stopped"));
        if (!r) {
            {
                std::lock_guard lock(mutex_);
                state_ = DeviceState::failed;
                reason_ = r.error().message;
                registered_ = false;
            }
            notify_state();
            return;
        }
    }
    service_->on_upstream_connected(client);
    {
        // Connected (and so /readyz ready) only once the service is registered and upstream-ready: a
        // client that waited for readiness must find the service.
        std::lock_guard lock(mutex_);
        if (client_ != client) return;  // lost in between: on_disconnected already reported it
        state_ = DeviceState::connected;
        reason_.clear();
    }
    notify_state();
}

void DeviceMirror::on_disconnected(const RRError& error) {
    bool was_connected;
    {
        std::lock_guard lock(mutex_);
        was_connected = state_ == DeviceState::connected;
        client_.reset();
        state_ = DeviceState::failed;
        reason_ = error.message.empty() ? std::string(error.name) : error.message;
        if (was_connected) counters_->reconnects.fetch_add(1);
    }
    service_->on_upstream_lost(error);
    notify_state();
    schedule_reconnect();
}

void DeviceMirror::schedule_reconnect() {
    std::chrono::milliseconds delay;
    {
        std::lock_guard lock(mutex_);
        if (stopped_) return;
        delay = backoff_;
        backoff_ = std::min(backoff_ * 2, config_.backoff_max);
    }
    timer_.expires_after(delay);
    std::weak_ptr<DeviceMirror> weak = weak_from_this();
    timer_.async_wait([weak](boost::system::error_code ec) {
        if (ec) return;
        if (auto self = weak.lock()) self->connect();
    });
}

void DeviceMirror::on_upstream_entry(MessageEntry&& entry) { service_->on_upstream_entry(std::move(entry)); }

DeviceStatus DeviceMirror::status() const {
    DeviceStatus s;
    s.name = config_.name;
    s.url = config_.url;
    s.required = config_.required;
    s.downstream_sessions = service_->session_count();
    s.auth = config_.auth;
    s.json_api_requires_device_login = config_.json_api_requires_device_login;
    if (const auto& p = service_->passthrough()) {
        s.upstream_sessions = p->session_count();
        s.locks = p->locks();
    } else {
        s.locks = service_->gateway_locks();
    }
    std::lock_guard lock(mutex_);
    s.state = state_;
    s.reason = reason_;
    s.object_type = object_type_;
    return s;
}

std::vector<std::string> DeviceMirror::service_definitions() const {
    std::lock_guard lock(mutex_);
    return definitions_;
}

std::string DeviceMirror::object_type() const {
    std::lock_guard lock(mutex_);
    return object_type_;
}

ObjectTypeInfo DeviceMirror::root_type() const {
    std::lock_guard lock(mutex_);
    return {object_type_, implements_};
}

MessageElement DeviceMirror::attributes() const {
    std::lock_guard lock(mutex_);
    return attributes_;
}

std::shared_ptr<RawClient> DeviceMirror::upstream() const {
    std::lock_guard lock(mutex_);
    return client_;
}

void DeviceMirror::request(MessageEntry entry, std::function<void(Result<MessageEntry>)> done) {
    auto c = upstream();
    if (!c) {
        done(fail(MessageErrorType::ConnectionError, "device \"" + config_.name + "\" is not connected"));
        return;
    }
    entry.service_path = service_->to_upstream(entry.service_path);
    counters_->requests.fetch_add(1);
    auto start = std::chrono::steady_clock::now();
    auto self = shared_from_this();
    c->request(std::move(entry), [self, start, done = std::move(done)](Result<MessageEntry> r) {
        self->counters_->observe_latency(std::chrono::steady_clock::now() - start);
        if (r) r->service_path = self->service_->to_downstream(r->service_path);
        if (!r || r->error != MessageErrorType::None) self->counters_->request_errors.fetch_add(1);
        done(std::move(r));
    });
}

void DeviceMirror::request(MessageEntry entry, std::function<void(Result<MessageEntry>)> done, std::uint32_t session) {
    if (session == 0) return request(std::move(entry), std::move(done));
    const auto& p = service_->passthrough();
    if (!p) {
        done(fail(MessageErrorType::InvalidOperation, "device \"" + config_.name + "\" has no sessions of its own (auth: shared)"));
        return;
    }
    p->request(session, std::move(entry), std::move(done));
}

void DeviceMirror::request_stop(MessageEntry entry, std::function<void(Result<MessageEntry>)> done, std::uint32_t session) {
    const auto& p = service_->passthrough();
    if (!p) return request(std::move(entry), std::move(done), session);
    MessageEntry again = entry;
    std::weak_ptr<PassthroughSessions> weak = p;
    request(std::move(entry),
            [weak, session, again = std::move(again), done = std::move(done)](Result<MessageEntry> r) mutable {
                auto ps = weak.lock();
                if (!ps || !r || !PassthroughSessions::refused_by_lock(*r)) return done(std::move(r));
                ps->stop_as_lock_holder(session, std::move(again), std::move(done), std::move(r));
            },
            session);
}

void DeviceMirror::open_api_session(std::string username, std::string password, std::function<void(Result<ApiSession>)> done) {
    const auto& p = service_->passthrough();
    auto node = node_.lock();
    if (!p || !node) {
        done(fail(MessageErrorType::InvalidOperation,
                  "device \"" + config_.name +
                      "\" is auth: shared: every client uses the gateway's own login to it (device_login needs auth: passthrough)"));
        return;
    }
    // An endpoint id of the node's own numbering, so it never meets a native client's session.
    const std::uint32_t session = node->allocate_endpoint();
    MessageElement credentials;
    credentials.name = "credentials";
    credentials.type = DataTypes::dictionary_t;
    credentials.elements.push_back(make_string_element("password", password));
    std::weak_ptr<PassthroughSessions> weak_p = p;
    SessionEndpoints::Upstream upstream;
    upstream.request = [weak_p, session](MessageEntry e, std::function<void(Result<MessageEntry>)> k) {
        if (auto ps = weak_p.lock())
            ps->request(session, std::move(e), std::move(k));
        else
            k(fail(MessageErrorType::ConnectionError, "gateway device stopped"));
    };
    upstream.send = [weak_p, session](MessageEntry e) -> Result<void> {
        auto ps = weak_p.lock();
        if (!ps) return fail(MessageErrorType::ConnectionError, "gateway device stopped");
        return ps->send(session, std::move(e));
    };
    upstream.queued_bytes = [weak_p, session]() -> std::size_t {
        auto ps = weak_p.lock();
        return ps ? ps->queued_bytes(session) : 0;
    };
    auto endpoints = std::make_shared<SessionEndpoints>(std::move(upstream));
    std::weak_ptr<DeviceMirror> weak = weak_from_this();
    p->admit(session, std::move(username), std::move(credentials),
             [weak, p, session, endpoints, done = std::move(done)](Result<void> r) {
                 if (!r) {
                     if (auto self = weak.lock())
                         if (auto n = self->node_.lock()) n->release_endpoint(session);
                     done(r.take_error());
                     return;
                 }
                 std::weak_ptr<SessionEndpoints> weak_endpoints = endpoints;
                 PassthroughSessions::ApiHandlers handlers;
                 handlers.on_entry = [weak_endpoints](MessageEntry&& e) {
                     if (auto ep = weak_endpoints.lock()) ep->deliver(std::move(e));
                 };
                 handlers.on_lost = [weak_endpoints](const RRError& error) {
                     if (auto ep = weak_endpoints.lock()) ep->lost(error);
                 };
                 p->attach_api(session, std::move(handlers));
                 done(ApiSession{session, endpoints});
             });
}

void DeviceMirror::close_api_session(std::uint32_t session) {
    if (session == 0) return;
    if (const auto& p = service_->passthrough()) p->close(session);
    if (auto node = node_.lock()) node->release_endpoint(session);
}

std::uint64_t DeviceMirror::subscribe(std::string path, std::string member, bool is_wire,
                                      std::function<void(const SharedEntryPtr&)> on_entry,
                                      std::function<void(Result<void>)> done) {
    return service_->add_internal_subscriber(std::move(path), std::move(member), is_wire, std::move(on_entry),
                                             std::move(done));
}

void DeviceMirror::unsubscribe(std::uint64_t id) { service_->remove_internal_subscriber(id); }

}  // namespace rr::server::gateway
