// One Foxglove WebSocket: the path and login, serverInfo, the client's messages fed to the sans-IO
// session (core/foxglove) and its events dispatched, advertise / unadvertise as devices come and go.
#include "server/foxglove/foxglove_connection.hpp"

#include <atomic>

#include "server/gateway/mirror_service.hpp"

namespace rr::server::foxglove {

namespace {


// The value of `key` in a request target's query ("" when absent); percent-escapes decoded.
std::string query_value(std::string_view target, std::string_view key) {
    auto q = target.find('?');
    if (q == std::string_view::npos) return {};
    std::string_view rest = target.substr(q + 1);
    auto hex = [](char c) -> int {
        if (c >= '0' && c <= '9') return c - '0';
        if (c >= 'a' && c <= 'f') return c - 'a' + 10;
        if (c >= 'A' && c <= 'F') return c - 'A' + 10;
        return -1;
    };
    while (!rest.empty()) {
        auto amp = rest.find('&');
        std::string_view pair = rest.substr(0, amp);
        rest = amp == std::string_view::npos ? std::string_view{} : rest.substr(amp + 1);
        auto eq = pair.find('=');
        if (eq == std::string_view::npos || pair.substr(0, eq) != key) continue;
        std::string out;
        std::string_view v = pair.substr(eq + 1);
        for (std::size_t i = 0; i < v.size(); ++i) {
            if (v[i] == '%' && i + 2 < v.size() && hex(v[i + 1]) >= 0 && hex(v[i + 2]) >= 0) {
                out.push_back(static_cast<char>(hex(v[i + 1]) * 16 + hex(v[i + 2])));
                i += 2;
            } else {
                out.push_back(v[i] == '+' ? ' ' : v[i]);
            }
        }
        return out;
    }
    return {};
}

std::string_view target_path(std::string_view target) { return target.substr(0, target.find('?')); }

}  // namespace

std::uint64_t now_ns() {
    return static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

std::uint64_t FoxgloveConnection::next_id() {
    static std::atomic<std::uint64_t> n{0};
    return n.fetch_add(1) + 1;
}

FoxgloveConnection::FoxgloveConnection(std::weak_ptr<FoxgloveServer> server, std::shared_ptr<gateway::JsonApi> api,
                                       std::shared_ptr<http::JsonSocket> socket, boost::asio::any_io_executor executor,
                                       boost::asio::strand<boost::asio::any_io_executor> convert_strand,
                                       const FoxgloveOptions& options, std::shared_ptr<FoxgloveClock> clock)
    : server_(std::move(server)),
      api_(std::move(api)),
      socket_(std::move(socket)),
      options_(options),
      session_(options.limits),
      timer_(executor),
      convert_strand_(std::move(convert_strand)),
      pipe_budget_(options.max_pipe_conversions, options.max_pipe_conversion_bytes),
      clock_(std::move(clock)) {}

void FoxgloveConnection::start() {
    auto server = server_.lock();
    if (!server) return;
    const std::string target = socket_->request_target();
    if (target_path(target) != kFoxglovePath && target_path(target) != std::string(kFoxglovePath) + "/") {
        refuse("the Foxglove WebSocket is served at path " + std::string(kFoxglovePath) + " (asked: " +
               std::string(target_path(target)) + ")");
        return;
    }
    // auth: gateway — the dashboard's session cookie, or a token in the query (browsers cannot set
    // headers on a WebSocket; Foxglove and Lichtblick keep the URL's query).
    if (const auto& a = api_->auth(); a && a->enabled()) {
        const std::string cookie = gateway::auth::cookie_value(socket_->cookie_header(), gateway::auth::kSessionCookie);
        if (!cookie.empty()) principal_ = a->session(cookie);
        if (const std::string token = query_value(target, "token"); !principal_ && !token.empty()) {
            auto who = a->login_token(token, socket_->peer(), gateway::auth::LoginChannel::websocket);
            if (!who) return refuse("login refused: " + who.error().message);
            principal_ = *who;
        }
        if (!principal_)
            return refuse("login required: open the dashboard and log in (its session cookie), or add ?token=<token> to the URL");
    }
    fg::ServerInfo info;
    info.name = "rr-gateway (Robot Raconteur)";
    info.capabilities = {fg::capability::client_publish, fg::capability::parameters, fg::capability::parameters_subscribe,
                         fg::capability::services};
    info.supported_encodings = options_.limits.encodings;
    info.session_id = server->session_id();
    info.metadata = {{"subprotocol", socket_->subprotocol()}};
    if (principal_) info.metadata["user"] = principal_->name;
    const bool sends_time = server->offers_time();
    if (sends_time) {
        info.capabilities.push_back(fg::capability::time);
        info.metadata["clock"] = clock_->device();
    }
    auto catalog = server->catalog();
    std::lock_guard lock(mutex_);
    socket_->send(fg::server_info_json(info));
    sends_time_ = sends_time;
    // The clock's time now, so that the client has one before the device's next tick.
    if (sends_time && clock_->has_time()) {
        socket_->send_binary(fg::time_frame(clock_->now_ns()));
        ++stats_.times_sent;
    }
    started_ = true;
    advertise_locked(catalog);
}

void FoxgloveConnection::time() {
    std::lock_guard lock(mutex_);
    if (!started_ || closed_ || !sends_time_) return;
    if (push_congested()) {
        ++stats_.dropped;
        return;
    }
    socket_->send_binary(fg::time_frame(clock_->now_ns()));
    ++stats_.times_sent;
}

std::uint64_t FoxgloveConnection::receive_ns() const { return sends_time_ ? clock_->now_ns() : now_ns(); }

void FoxgloveConnection::on_text(std::string text) {
    std::unique_lock lock(mutex_);
    if (!started_ || closed_) return;
    auto out = session_.feed_text(text);
    act(std::move(out), lock);
}
void FoxgloveConnection::on_binary(std::string bytes) {
    std::unique_lock lock(mutex_);
    if (!started_ || closed_) return;
    auto out = session_.feed_binary(bytes);  // events view `bytes`, which lives until act returns
    act(std::move(out), lock);
}

void FoxgloveConnection::close() {
    std::map<std::uint32_t, Sub> subs;
    std::map<std::uint32_t, PublishTarget> publishing;
    {
        std::lock_guard lock(mutex_);
        if (closed_) return;
        closed_ = true;
        subs.swap(subs_);
        publishing.swap(publish_targets_);
        timer_.cancel();
    }
    for (auto& [id, s] : subs) end_upstream(s);
    for (auto& [id, p] : publishing) end_publish(p);
    for (const auto& d : api_->devices())
        if (const auto& guard = d->motion()) guard->client_gone(motion_key_);
}

void FoxgloveConnection::advertise(const FoxgloveServer::Catalog& added) {
    std::lock_guard lock(mutex_);
    if (!started_ || closed_) return;
    advertise_locked(added);
}

void FoxgloveConnection::unadvertise(const std::vector<std::uint32_t>& channel_ids, const std::vector<std::uint32_t>& service_ids) {
    std::vector<Sub> ended;
    {
        std::lock_guard lock(mutex_);
        if (!started_ || closed_) return;
        for (const auto& u : session_.channels_unadvertised(channel_ids)) {
            if (auto it = subs_.find(u.subscription_id); it != subs_.end()) {
                ended.push_back(std::move(it->second));
                subs_.erase(it);
            }
        }
        session_.services_unadvertised(service_ids);
        if (!channel_ids.empty()) socket_->send(fg::unadvertise_json(channel_ids));
        if (!service_ids.empty()) socket_->send(fg::unadvertise_services_json(service_ids));
    }
    for (auto& s : ended) end_upstream(s);
}

void FoxgloveConnection::parameter_changed(const fg::Parameter& p) {
    std::lock_guard lock(mutex_);
    if (!started_ || closed_ || !session_.parameter_subscribed(p.name)) return;
    socket_->send(fg::parameter_values_json({p}, std::nullopt));
}

FoxgloveStats FoxgloveConnection::stats() const {
    std::lock_guard lock(mutex_);
    FoxgloveStats s = stats_;
    s.subscriptions = session_.subscription_count();
    s.client_channels = session_.client_channel_count();
    return s;
}

// A refused connection: one status naming why, then the close.
void FoxgloveConnection::refuse(const std::string& why) {
    socket_->send(fg::status_json(fg::StatusLevel::error, why));
    socket_->close();
}

void FoxgloveConnection::status(const std::string& message, fg::StatusLevel level) {
    // Under mutex_.
    ++stats_.statuses;
    socket_->send(fg::status_json(level, message));
}

void FoxgloveConnection::advertise_locked(const FoxgloveServer::Catalog& c) {
    if (!c.channels.empty()) {
        session_.channels_advertised(c.channels);
        socket_->send(fg::advertise_json(c.channels));
    }
    if (!c.services.empty()) {
        session_.services_advertised(c.services);
        socket_->send(fg::advertise_services_json(c.services));
    }
}

gateway::MemberAddress FoxgloveConnection::address_of(const LiveMember& m) const {
    gateway::MemberAddress a;
    a.device = m.target->device->config().name;
    a.object = m.object;
    a.member = m.target->member->name;
    a.principal = principal_;
    a.motion = motion_client();
    return a;
}

// The socket as a device's motion guard sees it (json_socket.cpp does the same for its sockets).
std::shared_ptr<const gateway::MotionClient> FoxgloveConnection::motion_client() const {
    auto c = std::make_shared<gateway::MotionClient>();
    c->key = motion_key_;
    c->user = principal_ ? principal_->rr_user_name() : std::string();
    const std::string peer = socket_->peer();
    c->description = "Foxglove WebSocket from " + peer.substr(0, peer.rfind(':'));
    std::weak_ptr<http::JsonSocket> weak = socket_;
    c->liveness = [weak](std::optional<std::chrono::milliseconds> timeout) {
        if (auto s = weak.lock()) s->set_liveness_probe(timeout);
    };
    return c;
}

// Acts on one fed message's output; `lock` holds mutex_ and is released before calls into devices.
void FoxgloveConnection::act(fg::Output out, std::unique_lock<std::mutex>& lock) {
    for (auto& t : out.texts) {
        ++stats_.statuses;
        socket_->send(std::move(t));
    }
    std::vector<fg::Event> events = std::move(out.events);
    lock.unlock();
    for (auto& e : events) std::visit([&](auto&& ev) { on(std::move(ev)); }, std::move(e));
}

}  // namespace rr::server::foxglove
