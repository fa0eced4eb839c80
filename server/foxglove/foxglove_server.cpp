#include "server/foxglove/foxglove_server.hpp"

#include <atomic>
#include <chrono>
#include <set>

#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>

#include "core/value/timespec.hpp"
#include "server/common/random_ids.hpp"
#include "server/gateway/auth/http_auth.hpp"
#include "server/gateway/conversion_budget.hpp"
#include "server/gateway/json_push.hpp"
#include "server/gateway/mirror_service.hpp"
#include "server/gateway/session_endpoints.hpp"
#include "server/node/node.hpp"
#include "server/service/wire_member.hpp"

namespace rr::server::foxglove {

namespace fg = rr::foxglove;
using gateway::ApiResult;
using gateway::MemberAddress;
using gateway::SharedEntryPtr;
namespace auth = gateway::auth;

namespace {

std::uint64_t now_ns() {
    return static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

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

std::string error_text(const gateway::ApiError& e) { return e.name + ": " + e.message; }

}  // namespace

// One Foxglove WebSocket. Thread-safe: the socket's strand delivers messages, device strands deliver
// values and replies; mutex_ guards the protocol state and the subscriptions.
class FoxgloveConnection : public std::enable_shared_from_this<FoxgloveConnection> {
    static std::uint64_t next_id() {
        static std::atomic<std::uint64_t> n{0};
        return n.fetch_add(1) + 1;
    }

public:
    FoxgloveConnection(std::weak_ptr<FoxgloveServer> server, std::shared_ptr<gateway::JsonApi> api,
                       std::shared_ptr<http::JsonSocket> socket, boost::asio::any_io_executor executor,
                       boost::asio::strand<boost::asio::any_io_executor> convert_strand, const FoxgloveOptions& options)
        : server_(std::move(server)),
          api_(std::move(api)),
          socket_(std::move(socket)),
          options_(options),
          session_(options.limits),
          timer_(executor),
          convert_strand_(std::move(convert_strand)),
          pipe_budget_(options.max_pipe_conversions, options.max_pipe_conversion_bytes) {}

    void start() {
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
            const std::string cookie = auth::cookie_value(socket_->cookie_header(), auth::kSessionCookie);
            if (!cookie.empty()) principal_ = a->session(cookie);
            if (const std::string token = query_value(target, "token"); !principal_ && !token.empty()) {
                auto who = a->login_token(token, socket_->peer(), auth::LoginChannel::websocket);
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
        auto catalog = server->catalog();
        std::lock_guard lock(mutex_);
        socket_->send(fg::server_info_json(info));
        started_ = true;
        advertise_locked(catalog);
    }

    void on_text(std::string text) {
        std::unique_lock lock(mutex_);
        if (!started_ || closed_) return;
        auto out = session_.feed_text(text);
        act(std::move(out), lock);
    }
    void on_binary(std::string bytes) {
        std::unique_lock lock(mutex_);
        if (!started_ || closed_) return;
        auto out = session_.feed_binary(bytes);  // events view `bytes`, which lives until act returns
        act(std::move(out), lock);
    }

    void close() {
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

    void advertise(const FoxgloveServer::Catalog& added) {
        std::lock_guard lock(mutex_);
        if (!started_ || closed_) return;
        advertise_locked(added);
    }

    void unadvertise(const std::vector<std::uint32_t>& channel_ids, const std::vector<std::uint32_t>& service_ids) {
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

    void parameter_changed(const fg::Parameter& p) {
        std::lock_guard lock(mutex_);
        if (!started_ || closed_ || !session_.parameter_subscribed(p.name)) return;
        socket_->send(fg::parameter_values_json({p}, std::nullopt));
    }

    FoxgloveStats stats() const {
        std::lock_guard lock(mutex_);
        FoxgloveStats s = stats_;
        s.subscriptions = session_.subscription_count();
        s.client_channels = session_.client_channel_count();
        return s;
    }

private:
    struct Sub {
        std::uint32_t id = 0;
        std::uint64_t serial = 0;  // this connection's count: a reused subscription id is another Sub
        std::shared_ptr<const LiveMember> member;
        std::uint64_t upstream = 0;
        bool upstream_known = false;
        bool active = false;      // the upstream subscription is open
        bool cancelled = false;   // ended before its upstream answered
        SharedEntryPtr pending;   // the newest wire value waiting while the socket is behind
    };

    struct PublishTarget {
        std::shared_ptr<const LiveMember> member;
        std::uint64_t serial = 0;
        std::uint64_t upstream = 0;  // the DeviceMirror wire subscription that keeps the wire connected
        bool upstream_known = false;
        bool ready = false;                   // that wire connection is open
        std::optional<MessageEntry> pending;  // the newest value published before it was
    };

    // A refused connection: one status naming why, then the close.
    void refuse(const std::string& why) {
        socket_->send(fg::status_json(fg::StatusLevel::error, why));
        socket_->close();
    }

    void status(const std::string& message, fg::StatusLevel level = fg::StatusLevel::error) {
        // Under mutex_.
        ++stats_.statuses;
        socket_->send(fg::status_json(level, message));
    }

    void advertise_locked(const FoxgloveServer::Catalog& c) {
        if (!c.channels.empty()) {
            session_.channels_advertised(c.channels);
            socket_->send(fg::advertise_json(c.channels));
        }
        if (!c.services.empty()) {
            session_.services_advertised(c.services);
            socket_->send(fg::advertise_services_json(c.services));
        }
    }

    MemberAddress address_of(const LiveMember& m) const {
        MemberAddress a;
        a.device = m.target->device->config().name;
        a.object = m.object;
        a.member = m.target->member->name;
        a.principal = principal_;
        a.motion = motion_client();
        return a;
    }

    // The socket as a device's motion guard sees it (json_socket.cpp does the same for its sockets).
    std::shared_ptr<const gateway::MotionClient> motion_client() const {
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
    void act(fg::Output out, std::unique_lock<std::mutex>& lock) {
        for (auto& t : out.texts) {
            ++stats_.statuses;
            socket_->send(std::move(t));
        }
        std::vector<fg::Event> events = std::move(out.events);
        lock.unlock();
        for (auto& e : events) std::visit([&](auto&& ev) { on(std::move(ev)); }, std::move(e));
    }

    // --- subscriptions ----------------------------------------------------------------------------

    void on(fg::event::Subscribed e) {
        auto server = server_.lock();
        auto member = server ? server->channel_member(e.channel_id) : nullptr;
        std::lock_guard lock(mutex_);
        if (closed_) return;
        if (!member) {
            session_.end_subscription(e.subscription_id);
            return status("subscribe refused: channel " + std::to_string(e.channel_id) + " is gone");
        }
        if (auto denied = api_->check_access(address_of(*member), auth::Operation::read)) {
            session_.end_subscription(e.subscription_id);
            return status("subscribe refused: " + member->topic + ": " + error_text(*denied));
        }
        Sub s;
        s.id = e.subscription_id;
        s.serial = ++next_serial_;
        s.member = member;
        subs_[e.subscription_id] = s;
        start_upstream(e.subscription_id, s.serial, member);
    }

    // Under mutex_: the upstream subscription is opened off this lock (the device's `done` may run
    // inside subscribe(), and it takes the lock).
    void start_upstream(std::uint32_t sid, std::uint64_t serial, const std::shared_ptr<const LiveMember>& member) {
        boost::asio::post(timer_.get_executor(),
                          [self = shared_from_this(), sid, serial, member] { self->open_upstream(sid, serial, member); });
    }

    void open_upstream(std::uint32_t sid, std::uint64_t serial, const std::shared_ptr<const LiveMember>& member) {
        std::weak_ptr<FoxgloveConnection> weak = weak_from_this();
        const auto& t = *member->target;
        if (member->kind == LiveKind::pipe) {
            gateway::GatewayPipeHandlers h;
            h.on_packet = [weak, sid, serial](const MessageElement& packet, std::uint32_t) {
                if (auto s = weak.lock()) s->on_pipe_packet(sid, serial, packet);
            };
            h.on_closed = [weak, sid, serial](const RRError& reason) {
                if (auto s = weak.lock()) s->upstream_closed(sid, serial, reason.message);
            };
            t.device->mirror_service()->shared_endpoints()->open_pipe(
                t.path, t.member->name, robdef::pipe_is_unreliable(*t.object, *t.member), std::move(h),
                [weak, sid, serial, member](Result<std::uint64_t> r) {
                    auto s = weak.lock();
                    if (!s) {
                        if (r) member->target->device->mirror_service()->shared_endpoints()->close_pipe(*r);
                        return;
                    }
                    s->upstream_opened(sid, serial, member, r ? std::optional<std::uint64_t>(*r) : std::nullopt, r ? "" : r.error().message);
                });
            return;
        }
        const bool is_wire = member->kind == LiveKind::wire;
        std::uint64_t upstream = t.device->subscribe(
            t.path, t.member->name, is_wire,
            [weak, sid, serial, is_wire](const SharedEntryPtr& e) {
                if (auto s = weak.lock()) is_wire ? s->on_wire(sid, serial, e) : s->on_event(sid, serial, e);
            },
            [weak, sid, serial, member](Result<void> r) {
                if (auto s = weak.lock(); s && !r) s->upstream_opened(sid, serial, member, std::nullopt, r.error().message);
            });
        bool drop = false;
        {
            std::lock_guard lock(mutex_);
            auto it = subs_.find(sid);
            if (it == subs_.end() || it->second.serial != serial || it->second.cancelled) {
                drop = true;
            } else {
                it->second.upstream = upstream;
                it->second.upstream_known = true;
                it->second.active = true;
            }
        }
        if (drop) t.device->unsubscribe(upstream);
    }

    void upstream_opened(std::uint32_t sid, std::uint64_t serial, const std::shared_ptr<const LiveMember>& member,
                         std::optional<std::uint64_t> id,
                         const std::string& error) {
        std::optional<Sub> orphan;
        {
            std::lock_guard lock(mutex_);
            auto it = subs_.find(sid);
            if (it == subs_.end() || it->second.serial != serial) {
                if (id) {  // unsubscribed (or the connection closed) while the device answered
                    orphan.emplace();
                    orphan->member = member;
                    orphan->upstream = *id;
                    orphan->upstream_known = true;
                }
            } else if (!id && !it->second.active) {
                // The device refused (a pipe's connect, or a wire's).
                const std::string topic = it->second.member->topic;
                if (it->second.upstream_known) orphan = it->second;
                subs_.erase(it);
                session_.end_subscription(sid);
                if (!closed_) status("subscription " + std::to_string(sid) + " on " + topic + " failed: " + error);
            } else if (!id) {
                const std::string topic = it->second.member->topic;
                orphan = std::move(it->second);
                subs_.erase(it);
                session_.end_subscription(sid);
                if (!closed_) status("subscription " + std::to_string(sid) + " on " + topic + " failed: " + error);
            } else {
                it->second.upstream = *id;
                it->second.upstream_known = true;
                it->second.active = true;
            }
        }
        if (orphan && orphan->upstream_known && orphan->member) end_upstream(*orphan);
    }

    void upstream_closed(std::uint32_t sid, std::uint64_t serial, const std::string& why) {
        std::lock_guard lock(mutex_);
        auto it = subs_.find(sid);
        if (it == subs_.end() || it->second.serial != serial) return;
        const std::string topic = it->second.member->topic;
        subs_.erase(it);
        session_.end_subscription(sid);
        if (!closed_) status("subscription " + std::to_string(sid) + " on " + topic + " ended by the device: " + why, fg::StatusLevel::warning);
    }

    void end_upstream(Sub& s) {
        if (!s.member) return;
        const auto& t = *s.member->target;
        if (!s.upstream_known) {
            s.cancelled = true;
            return;
        }
        if (s.member->kind == LiveKind::pipe)
            t.device->mirror_service()->shared_endpoints()->close_pipe(s.upstream);
        else
            t.device->unsubscribe(s.upstream);
    }

    void on(fg::event::Unsubscribed e) {
        std::optional<Sub> s;
        {
            std::lock_guard lock(mutex_);
            auto it = subs_.find(e.subscription_id);
            if (it == subs_.end()) return;
            s = std::move(it->second);
            subs_.erase(it);
        }
        if (s->upstream_known)
            end_upstream(*s);
        else
            s->cancelled = true;
    }

    // --- values -----------------------------------------------------------------------------------

    bool wire_congested() const {
        return socket_->queued() >= options_.wire_queue_threshold || socket_->queued_bytes() >= options_.wire_bytes_threshold;
    }
    bool push_congested() const {
        return socket_->queued() >= options_.push_queue_limit || socket_->queued_bytes() >= options_.push_bytes_limit;
    }

    // Under mutex_: one messageData frame of a wire value or event. Its payload is the value's one
    // rendering, shared with every subscriber of both WebSocket front ends and the recorder and written
    // without a copy, when it holds no null member; else the recorder's json message without them
    // (record::json_message, which makes the same choice).
    void send_entry(const Sub& s, const SharedEntryPtr& e) {
        const auto& t = *s.member->target;
        const bool wire = s.member->kind == LiveKind::wire;
        const std::string& body = e->rendered([&](const MessageEntry& entry) {
            return wire ? gateway::wire_push_text(*api_, entry, t) : gateway::event_push_text(*api_, entry, t);
        });
        std::string head = fg::message_data_head(s.id, now_ns());
        if (body.find("null") == std::string::npos) {
            socket_->send_binary(std::move(head), std::shared_ptr<const std::string>(e, &body));
        } else {
            auto text = channel_message(*api_, *s.member, *e, 0);
            if (!text) return;
            socket_->send_binary(std::move(head) + *text);
        }
        ++stats_.messages_sent;
    }

    void on_wire(std::uint32_t sid, std::uint64_t serial, const SharedEntryPtr& e) {
        if (e->entry().entry_type == MessageEntryType::WireClosed) return upstream_closed(sid, serial, "wire closed");
        if (image_subscription(sid)) return convert(sid, serial, e);
        std::lock_guard lock(mutex_);
        auto it = subs_.find(sid);
        if (closed_ || it == subs_.end() || it->second.serial != serial) return;
        if (it->second.pending || wire_congested()) {
            if (it->second.pending) ++stats_.wire_coalesced;
            it->second.pending = e;  // newest wins
            arm_retry();
            return;
        }
        send_entry(it->second, e);
    }

    void on_event(std::uint32_t sid, std::uint64_t serial, const SharedEntryPtr& e) {
        std::lock_guard lock(mutex_);
        auto it = subs_.find(sid);
        if (closed_ || it == subs_.end() || it->second.serial != serial) return;
        if (push_congested()) {
            ++stats_.dropped;
            return;
        }
        send_entry(it->second, e);
    }

    bool image_subscription(std::uint32_t sid) const {
        std::lock_guard lock(mutex_);
        auto it = subs_.find(sid);
        return it != subs_.end() && it->second.member->image.has_value();
    }

    // Under mutex_.
    void arm_retry() {
        if (timer_armed_) return;
        timer_armed_ = true;
        timer_.expires_after(options_.wire_retry);
        std::weak_ptr<FoxgloveConnection> weak = weak_from_this();
        timer_.async_wait([weak](boost::system::error_code ec) {
            auto s = weak.lock();
            if (!s) return;
            std::lock_guard lock(s->mutex_);
            s->timer_armed_ = false;
            if (!ec && !s->closed_) s->flush_locked();
        });
    }

    void flush_locked() {
        bool waiting = false;
        for (auto& [id, s] : subs_) {
            if (!s.pending) continue;
            if (wire_congested()) {
                waiting = true;
                break;
            }
            auto e = std::move(s.pending);
            s.pending.reset();
            send_entry(s, e);
        }
        if (waiting) arm_retry();
    }

    // On the device's strand: a pipe packet as the recorder's pipe entry (its first element).
    void on_pipe_packet(std::uint32_t sid, std::uint64_t serial, const MessageElement& packet) {
        MessageEntry entry;
        entry.entry_type = MessageEntryType::PipePacket;
        entry.elements.push_back(packet);
        convert(sid, serial, std::make_shared<const gateway::SharedEntry>(std::move(entry)));
    }

    // A pipe packet's or an image's message is made on the shared conversion strand, never on the
    // device's (a camera frame is large), within this connection's budget; newer ones are dropped
    // while it is full.
    void convert(std::uint32_t sid, std::uint64_t serial, SharedEntryPtr entry) {
        std::shared_ptr<const LiveMember> member;
        {
            std::lock_guard lock(mutex_);
            auto it = subs_.find(sid);
            if (closed_ || it == subs_.end() || it->second.serial != serial) return;
            if (push_congested()) {
                ++stats_.dropped;
                return;
            }
            member = it->second.member;
        }
        std::size_t bytes = 0;
        for (const auto& el : entry->entry().elements) bytes += gateway::payload_bytes(el);
        if (!pipe_budget_.try_acquire(bytes)) {
            std::lock_guard lock(mutex_);
            ++stats_.dropped;
            return;
        }
        const std::uint64_t received = now_ns();
        boost::asio::post(convert_strand_, [self = shared_from_this(), sid, serial, entry = std::move(entry), member, bytes, received] {
            auto message = channel_message(*self->api_, *member, *entry, received);
            self->pipe_budget_.release(bytes);
            if (!message) return;  // a frame Foxglove has no form of: nothing on the image channel
            std::string frame = fg::message_data_head(sid, received) + *message;
            std::lock_guard lock(self->mutex_);
            auto it = self->subs_.find(sid);
            if (self->closed_ || it == self->subs_.end() || it->second.serial != serial) return;
            self->socket_->send_binary(std::move(frame));
            ++self->stats_.messages_sent;
        });
    }

    // --- parameters -------------------------------------------------------------------------------

    bool begin_parameter_request() {
        std::lock_guard lock(mutex_);
        if (parameter_requests_ >= options_.max_parameter_requests) {
            status("parameter request refused: more than " + std::to_string(options_.max_parameter_requests) +
                   " getParameters / setParameters being answered on this connection");
            return false;
        }
        ++parameter_requests_;
        return true;
    }

    // Reads `members` and hands the values (in order; failures left out and named in one status) to `done`.
    void read_parameters(std::vector<std::shared_ptr<const LiveMember>> members,
                         std::function<void(std::vector<fg::Parameter>)> done) {
        struct Gather {
            std::mutex m;
            std::vector<std::optional<fg::Parameter>> values;
            std::vector<std::string> failures;
            std::size_t left = 0;
        };
        auto g = std::make_shared<Gather>();
        g->values.resize(members.size());
        g->left = members.size();
        if (members.empty()) return done({});
        auto self = shared_from_this();
        for (std::size_t i = 0; i < members.size(); ++i) {
            const std::string name = members[i]->topic;
            api_->get_property(address_of(*members[i]), [self, g, i, name, done](ApiResult r) {
                bool last = false;
                {
                    std::lock_guard lock(g->m);
                    if (r)
                        g->values[i] = fg::Parameter{name, r.value.value("value", nlohmann::json()), ""};
                    else
                        g->failures.push_back(name + ": " + error_text(*r.error));
                    last = --g->left == 0;
                }
                if (!last) return;
                std::vector<fg::Parameter> out;
                for (auto& v : g->values)
                    if (v) out.push_back(std::move(*v));
                if (!g->failures.empty()) {
                    std::string text = "parameters not read: ";
                    for (std::size_t k = 0; k < g->failures.size(); ++k) text += (k ? "; " : "") + g->failures[k];
                    std::lock_guard lock(self->mutex_);
                    if (!self->closed_) self->status(text, fg::StatusLevel::warning);
                }
                done(std::move(out));
            });
        }
    }

    // The properties `names` name ("" → all); unknown names in `unknown`.
    std::vector<std::shared_ptr<const LiveMember>> properties_named(const std::vector<std::string>& names,
                                                                    std::vector<std::string>& unknown) const {
        auto server = server_.lock();
        if (!server) return {};
        if (names.empty()) return server->properties();
        std::vector<std::shared_ptr<const LiveMember>> out;
        for (const auto& n : names) {
            if (auto m = server->member_named(n, LiveKind::property))
                out.push_back(std::move(m));
            else
                unknown.push_back(n);
        }
        return out;
    }

    void report_unknown(const std::vector<std::string>& unknown, const char* op) {
        if (unknown.empty()) return;
        std::string text = std::string(op) + ": no property named ";
        for (std::size_t i = 0; i < unknown.size(); ++i) text += (i ? ", \"" : "\"") + unknown[i] + "\"";
        std::lock_guard lock(mutex_);
        status(text, fg::StatusLevel::warning);
    }

    void on(fg::event::GetParameters e) {
        if (!begin_parameter_request()) return;
        std::vector<std::string> unknown;
        auto members = properties_named(e.names, unknown);
        report_unknown(unknown, "getParameters");
        auto self = shared_from_this();
        read_parameters(std::move(members), [self, id = e.id](std::vector<fg::Parameter> values) {
            std::lock_guard lock(self->mutex_);
            --self->parameter_requests_;
            if (!self->closed_) self->socket_->send(fg::parameter_values_json(values, id));
        });
    }

    void on(fg::event::SetParameters e) {
        if (!begin_parameter_request()) return;
        struct Gather {
            std::mutex m;
            std::vector<std::shared_ptr<const LiveMember>> set;
            std::vector<std::string> failures;
            std::size_t left = 0;
        };
        auto g = std::make_shared<Gather>();
        auto server = server_.lock();
        std::vector<std::pair<std::shared_ptr<const LiveMember>, nlohmann::json>> writes;
        for (auto& p : e.parameters) {
            auto m = server ? server->member_named(p.name, LiveKind::property) : nullptr;
            if (!m) {
                g->failures.push_back(p.name + ": no such property");
            } else if (p.type == "byte_array") {
                g->failures.push_back(p.name + ": byte_array values are not taken (send the JSON mapping's array)");
            } else if (p.value.is_null()) {
                g->failures.push_back(p.name + ": a property cannot be unset");
            } else {
                writes.emplace_back(std::move(m), std::move(p.value));
            }
        }
        g->left = writes.size();
        auto self = shared_from_this();
        auto finish = [self, g, id = e.id] {
            if (!g->failures.empty()) {
                std::string text = "setParameters: not set: ";
                for (std::size_t k = 0; k < g->failures.size(); ++k) text += (k ? "; " : "") + g->failures[k];
                std::lock_guard lock(self->mutex_);
                if (!self->closed_) self->status(text);
            }
            // The values now: the reply (with the request's id) and the update to every subscriber.
            self->read_parameters(g->set, [self, id](std::vector<fg::Parameter> values) {
                {
                    std::lock_guard lock(self->mutex_);
                    --self->parameter_requests_;
                    if (id && !self->closed_) self->socket_->send(fg::parameter_values_json(values, id));
                }
                if (auto server = self->server_.lock())
                    for (const auto& v : values) server->parameter_changed(v);
            });
        };
        if (writes.empty()) return finish();
        for (auto& [m, value] : writes) {
            std::shared_ptr<const LiveMember> member = m;
            api_->set_property(address_of(*member), value, [g, member, finish](ApiResult r) {
                bool last = false;
                {
                    std::lock_guard lock(g->m);
                    if (r)
                        g->set.push_back(member);
                    else
                        g->failures.push_back(member->topic + ": " + error_text(*r.error));
                    last = --g->left == 0;
                }
                if (last) finish();
            });
        }
    }

    void on(fg::event::ParametersSubscribed e) {
        if (!begin_parameter_request()) return;
        std::vector<std::string> unknown;
        auto members = properties_named(e.all ? std::vector<std::string>{} : e.names, unknown);
        report_unknown(unknown, "subscribeParameterUpdates");
        auto self = shared_from_this();
        read_parameters(std::move(members), [self](std::vector<fg::Parameter> values) {
            std::lock_guard lock(self->mutex_);
            --self->parameter_requests_;
            if (!self->closed_ && !values.empty()) self->socket_->send(fg::parameter_values_json(values, std::nullopt));
        });
    }

    // --- services ---------------------------------------------------------------------------------

    void on(fg::event::ServiceCall e) {
        auto server = server_.lock();
        auto member = server ? server->service_member(e.service_id) : nullptr;
        const std::uint32_t service = e.service_id, call = e.call_id;
        auto self = shared_from_this();
        auto failed = [self, service, call](const std::string& why) {
            std::lock_guard lock(self->mutex_);
            self->session_.call_finished(service, call);
            if (!self->closed_) self->socket_->send(fg::service_call_failure_json(service, call, why));
        };
        if (!member) return failed("service " + std::to_string(service) + " is gone");
        nlohmann::json args = nullptr;
        if (!e.payload.empty()) {
            args = nlohmann::json::parse(e.payload, nullptr, false);
            if (args.is_discarded() || !(args.is_object() || args.is_array() || args.is_null()))
                return failed("the request is not a JSON object of the arguments by name (or an array of them in order)");
        }
        api_->call_function(address_of(*member), args, 0, [self, service, call, failed, encoding = e.encoding](ApiResult r) {
            if (!r) return failed(error_text(*r.error));
            std::string frame = fg::service_call_response_head(service, call, encoding) + gateway::json_text(r.value);
            std::lock_guard lock(self->mutex_);
            self->session_.call_finished(service, call);
            if (!self->closed_) self->socket_->send_binary(std::move(frame));
        });
    }

    // --- client publish ---------------------------------------------------------------------------

    // A client channel on a writable wire: the gateway's wire connection to the device is opened for it
    // (DeviceMirror::subscribe, shared with every subscriber of that wire), as the JSON WebSocket's
    // set_out_value needs its subscription; values published before it is open wait (the newest).
    void on(fg::event::ClientAdvertised e) {
        auto server = server_.lock();
        auto member = server ? server->member_named(e.channel.topic, LiveKind::wire) : nullptr;
        std::uint64_t serial = 0;
        {
            std::lock_guard lock(mutex_);
            // Not a writable wire: nothing now (Lichtblick advertises ROS topics of its own, e.g.
            // /clicked_point, whether anything is published there or not); its first message gets a status.
            if (!member || !member->writable) return;
            if (auto denied = api_->check_access(address_of(*member), auth::Operation::write)) {
                status("advertise: " + e.channel.topic + ": " + error_text(*denied) + "; messages on it are refused");
                return;
            }
            PublishTarget target;
            target.member = member;
            target.serial = serial = ++next_serial_;
            publish_targets_[e.channel.id] = std::move(target);
        }
        std::weak_ptr<FoxgloveConnection> weak = weak_from_this();
        const auto& t = *member->target;
        const std::uint32_t cid = e.channel.id;
        const std::uint64_t upstream = t.device->subscribe(
            t.path, t.member->name, /*is_wire=*/true, [](const SharedEntryPtr&) {},
            [weak, cid, serial](Result<void> r) {
                if (auto s = weak.lock()) s->publish_ready(cid, serial, r ? std::string() : r.error().message);
            });
        bool drop = false;
        {
            std::lock_guard lock(mutex_);
            auto it = publish_targets_.find(cid);
            if (it == publish_targets_.end() || it->second.serial != serial) {
                drop = true;
            } else {
                it->second.upstream = upstream;
                it->second.upstream_known = true;
            }
        }
        if (drop) t.device->unsubscribe(upstream);
    }

    void publish_ready(std::uint32_t cid, std::uint64_t serial, const std::string& error) {
        std::optional<MessageEntry> pending;
        std::shared_ptr<const LiveMember> member;
        std::optional<std::uint64_t> unsubscribe;
        {
            std::lock_guard lock(mutex_);
            auto it = publish_targets_.find(cid);
            if (it == publish_targets_.end() || it->second.serial != serial) return;
            member = it->second.member;
            if (!error.empty()) {
                if (it->second.upstream_known) unsubscribe = it->second.upstream;
                status("advertise: " + member->topic + ": the device refused the wire connection: " + error);
                publish_targets_.erase(it);
            } else {
                it->second.ready = true;
                pending = std::move(it->second.pending);
                it->second.pending.reset();
            }
        }
        if (unsubscribe) member->target->device->unsubscribe(*unsubscribe);
        if (pending) send_upstream(*member, std::move(*pending));
    }

    void end_publish(PublishTarget& p) {
        if (p.upstream_known) p.member->target->device->unsubscribe(p.upstream);
    }

    void on(fg::event::ClientUnadvertised e) {
        std::optional<PublishTarget> p;
        {
            std::lock_guard lock(mutex_);
            publish_refused_.erase(e.channel.id);
            auto it = publish_targets_.find(e.channel.id);
            if (it == publish_targets_.end()) return;
            p = std::move(it->second);
            publish_targets_.erase(it);
        }
        end_publish(*p);
    }

    // The wire packet to the device over the gateway's own session (its wire connection is open).
    void send_upstream(const LiveMember& member, MessageEntry entry) {
        const auto& t = *member.target;
        auto client = t.device->upstream();
        if (!client) {
            std::lock_guard lock(mutex_);
            return status("message on \"" + member.topic + "\" refused: device \"" + t.device->config().name + "\" is not connected");
        }
        entry.service_path = t.device->mirror_service()->to_upstream(t.path);
        client->send(std::move(entry));
    }

    void on(fg::event::ClientPublish e) {
        std::shared_ptr<const LiveMember> member;
        std::string topic;
        {
            std::lock_guard lock(mutex_);
            if (!e.channel) return;
            topic = e.channel->topic;
            auto it = publish_targets_.find(e.channel->id);
            if (it == publish_targets_.end()) {
                // Once per client channel, not per message (a Publish panel sends at its rate).
                if (publish_refused_.insert(e.channel->id).second)
                    status("message on \"" + topic + "\" refused: not a writable wire of a connected device that this login may write");
                return;
            }
            member = it->second.member;
        }
        auto report = [&](const std::string& why) {
            std::lock_guard lock(mutex_);
            status("message on \"" + topic + "\" refused: " + why);
        };
        auto payload = nlohmann::json::parse(e.payload, nullptr, false);
        if (payload.is_discarded()) return report("not JSON");
        // The channel's own message shape ({"value": …}, as the wire's channel carries it) or the bare value.
        const nlohmann::json& value = payload.is_object() && payload.contains("value") ? payload["value"] : payload;
        const auto& t = *member->target;
        gateway::ApiError error;
        auto packet = api_->element_from_json(value, t.member->type, t, "packet", error, "value");
        if (!packet) return report(error_text(error));
        // A client's OutValue is the device's InValue (wire.md §6.7: WirePacket, newest wins).
        MessageEntry entry;
        entry.entry_type = MessageEntryType::WirePacket;
        entry.member_name = t.member->name;
        entry.metadata = "unreliable\n";
        entry.elements.push_back(pack_timespec(wall_clock_timespec(), "packettime"));
        entry.elements.push_back(std::move(*packet));
        entry.service_path = t.path;
        MemberAddress address = address_of(*member);
        // A command stream: refused while another client holds the motion, ended when it goes silent.
        auto motion = gateway::JsonApi::admit_motion(address, t, entry);
        if (auto* refused = std::get_if<gateway::ApiError>(&motion)) return report(error_text(*refused));
        {
            std::lock_guard lock(mutex_);
            auto it = publish_targets_.find(e.channel->id);
            if (it == publish_targets_.end()) return;
            if (!it->second.ready) {
                it->second.pending = std::move(entry);  // newest wins until the wire connection is open
                return;
            }
        }
        send_upstream(*member, std::move(entry));
    }

    std::weak_ptr<FoxgloveServer> server_;
    std::shared_ptr<gateway::JsonApi> api_;
    std::shared_ptr<http::JsonSocket> socket_;
    const FoxgloveOptions options_;
    mutable std::mutex mutex_;
    fg::Session session_;
    boost::asio::steady_timer timer_;
    bool started_ = false, closed_ = false, timer_armed_ = false;
    std::map<std::uint32_t, Sub> subs_;
    std::map<std::uint32_t, PublishTarget> publish_targets_;  // by client channel id
    std::set<std::uint32_t> publish_refused_;                 // client channels whose refusal was reported
    std::size_t parameter_requests_ = 0;
    std::uint64_t next_serial_ = 0;
    auth::PrincipalPtr principal_;
    FoxgloveStats stats_;
    const std::string motion_key_ = "foxglove:" + std::to_string(next_id());
    boost::asio::strand<boost::asio::any_io_executor> convert_strand_;
    gateway::ConversionBudget pipe_budget_;
};

// --- server ---------------------------------------------------------------------------------------

FoxgloveServer::FoxgloveServer(std::shared_ptr<gateway::JsonApi> api, boost::asio::any_io_executor executor, FoxgloveOptions options)
    : api_(std::move(api)),
      executor_(executor),
      options_(std::move(options)),
      session_id_(random_service_state_nonce()),
      convert_strand_(boost::asio::make_strand(executor)) {}

std::shared_ptr<FoxgloveServer> FoxgloveServer::create(std::shared_ptr<gateway::JsonApi> api, boost::asio::any_io_executor executor,
                                                       FoxgloveOptions options) {
    std::shared_ptr<FoxgloveServer> s(new FoxgloveServer(std::move(api), executor, std::move(options)));
    for (const auto& d : s->api_->devices()) s->watch(d);
    std::weak_ptr<FoxgloveServer> weak = s;
    s->devices_listener_ = s->api_->add_devices_listener([weak](const std::shared_ptr<gateway::DeviceMirror>& d, bool added) {
        auto self = weak.lock();
        if (!self) return;
        if (added) return self->watch(d);
        {
            std::lock_guard lock(self->mutex_);
            for (auto it = self->listeners_.begin(); it != self->listeners_.end();) {
                if (it->first == d) {
                    d->remove_state_listener(it->second);
                    it = self->listeners_.erase(it);
                } else {
                    ++it;
                }
            }
        }
        self->device_down(d->config().name);
    });
    return s;
}

FoxgloveServer::~FoxgloveServer() {
    api_->remove_devices_listener(devices_listener_);
    for (auto& [d, id] : listeners_) d->remove_state_listener(id);
    decltype(connections_) conns;
    {
        std::lock_guard lock(mutex_);
        conns.swap(connections_);
    }
    for (auto& [k, c] : conns) c->close();
}

void FoxgloveServer::watch(const std::shared_ptr<gateway::DeviceMirror>& device) {
    std::weak_ptr<FoxgloveServer> weak = weak_from_this();
    std::weak_ptr<gateway::DeviceMirror> weak_device = device;
    const auto id = device->add_state_listener([weak, weak_device](const gateway::DeviceStatus& status) {
        auto self = weak.lock();
        auto d = weak_device.lock();
        if (self && d) self->on_device_state(d, status);
    });
    {
        std::lock_guard lock(mutex_);
        listeners_.emplace_back(device, id);
    }
    on_device_state(device, device->status());
}

void FoxgloveServer::on_device_state(const std::shared_ptr<gateway::DeviceMirror>& device, const gateway::DeviceStatus& status) {
    if (status.state == gateway::DeviceState::connected)
        device_up(device);
    else
        device_down(device->config().name);
}

std::uint32_t FoxgloveServer::id_for(const std::string& key, std::map<std::string, std::uint32_t>& ids, std::uint32_t& next) {
    auto [it, added] = ids.emplace(key, next);
    if (added) ++next;
    return it->second;
}

void FoxgloveServer::device_up(const std::shared_ptr<gateway::DeviceMirror>& device) {
    const std::string name = device->config().name;
    std::vector<std::string> objects;
    if (auto it = options_.objects.find(name); it != options_.objects.end()) objects = it->second;
    auto members = device_members(*api_, device, objects);
    // An object path of the configuration that does not resolve on this device: the root alone.
    if (!members && !objects.empty() && members.error().type == MessageErrorType::InvalidArgument)
        members = device_members(*api_, device, {});
    if (!members) return;  // not usable yet (definitions); the next state change tries again
    Catalog added;
    {
        std::lock_guard lock(mutex_);
        if (devices_.count(name)) return;  // advertised already
        DeviceEntry entry;
        for (auto& m : *members) {
            auto live = std::make_shared<const LiveMember>(std::move(m));
            switch (live->kind) {
                case LiveKind::wire:
                case LiveKind::pipe:
                case LiveKind::event: {
                    fg::Channel c{0, live->topic, "json", live->schema_name, live->schema, "jsonschema"};
                    c.id = id_for(c.topic + '\n' + c.schema_name + '\n' + c.schema, channel_ids_, next_channel_);
                    channels_[c.id] = {c, live};
                    entry.channel_ids.push_back(c.id);
                    added.channels.push_back(std::move(c));
                    break;
                }
                case LiveKind::function: {
                    fg::Service s;
                    s.name = live->topic;
                    s.type = live->schema_name;
                    s.request = {"json", live->schema_name + " request", "jsonschema", live->schema};
                    s.response = {"json", live->schema_name + " response", "jsonschema", live->response_schema};
                    s.id = id_for(s.name + '\n' + s.type + '\n' + s.request.schema + '\n' + s.response.schema, service_ids_, next_service_);
                    services_[s.id] = {s, live};
                    entry.service_ids.push_back(s.id);
                    added.services.push_back(std::move(s));
                    break;
                }
                case LiveKind::property: properties_[live->topic] = live; break;
            }
        }
        devices_[name] = std::move(entry);
    }
    for (const auto& c : connections()) c->advertise(added);
}

void FoxgloveServer::device_down(const std::string& name) {
    DeviceEntry entry;
    {
        std::lock_guard lock(mutex_);
        auto it = devices_.find(name);
        if (it == devices_.end()) return;
        entry = std::move(it->second);
        devices_.erase(it);
        for (auto id : entry.channel_ids) channels_.erase(id);
        for (auto id : entry.service_ids) services_.erase(id);
        for (auto p = properties_.begin(); p != properties_.end();) {
            if (p->second->target->device->config().name == name)
                p = properties_.erase(p);
            else
                ++p;
        }
    }
    for (const auto& c : connections()) c->unadvertise(entry.channel_ids, entry.service_ids);
}

std::vector<std::shared_ptr<FoxgloveConnection>> FoxgloveServer::connections() const {
    std::vector<std::shared_ptr<FoxgloveConnection>> out;
    std::lock_guard lock(mutex_);
    for (const auto& [k, c] : connections_) out.push_back(c);
    return out;
}

FoxgloveServer::Catalog FoxgloveServer::catalog() const {
    Catalog c;
    std::lock_guard lock(mutex_);
    for (const auto& [id, ch] : channels_) c.channels.push_back(ch.first);
    for (const auto& [id, s] : services_) c.services.push_back(s.first);
    return c;
}

std::shared_ptr<const LiveMember> FoxgloveServer::channel_member(std::uint32_t id) const {
    std::lock_guard lock(mutex_);
    auto it = channels_.find(id);
    return it == channels_.end() ? nullptr : it->second.second;
}

std::shared_ptr<const LiveMember> FoxgloveServer::service_member(std::uint32_t id) const {
    std::lock_guard lock(mutex_);
    auto it = services_.find(id);
    return it == services_.end() ? nullptr : it->second.second;
}

std::shared_ptr<const LiveMember> FoxgloveServer::member_named(const std::string& topic, LiveKind kind) const {
    std::lock_guard lock(mutex_);
    if (kind == LiveKind::property) {
        auto it = properties_.find(topic);
        return it == properties_.end() ? nullptr : it->second;
    }
    for (const auto& [id, ch] : channels_)
        if (ch.second->topic == topic && ch.second->kind == kind) return ch.second;
    return nullptr;
}

std::vector<std::shared_ptr<const LiveMember>> FoxgloveServer::properties() const {
    std::vector<std::shared_ptr<const LiveMember>> out;
    std::lock_guard lock(mutex_);
    for (const auto& [name, m] : properties_) out.push_back(m);
    return out;
}

void FoxgloveServer::parameter_changed(const fg::Parameter& p) {
    for (const auto& c : connections()) c->parameter_changed(p);
}

std::vector<FoxgloveStats> FoxgloveServer::stats() const {
    std::vector<FoxgloveStats> out;
    for (const auto& c : connections()) out.push_back(c->stats());
    return out;
}

http::JsonSocketHandler FoxgloveServer::handler() {
    std::weak_ptr<FoxgloveServer> weak = weak_from_this();
    auto find = [weak](const std::shared_ptr<http::JsonSocket>& s) -> std::shared_ptr<FoxgloveConnection> {
        auto self = weak.lock();
        if (!self) return nullptr;
        std::lock_guard lock(self->mutex_);
        auto it = self->connections_.find(s.get());
        return it == self->connections_.end() ? nullptr : it->second;
    };
    http::JsonSocketHandler h;
    h.on_open = [weak](std::shared_ptr<http::JsonSocket> s) {
        auto self = weak.lock();
        if (!self) return s->close();
        auto c = std::make_shared<FoxgloveConnection>(weak, self->api_, s, self->executor_, self->convert_strand_, self->options_);
        {
            std::lock_guard lock(self->mutex_);
            self->connections_[s.get()] = c;
        }
        c->start();
    };
    h.on_message = [find](const std::shared_ptr<http::JsonSocket>& s, std::string text) {
        if (auto c = find(s)) c->on_text(std::move(text));
    };
    h.on_binary = [find](const std::shared_ptr<http::JsonSocket>& s, std::string bytes) {
        if (auto c = find(s)) c->on_binary(std::move(bytes));
    };
    h.on_close = [weak](const std::shared_ptr<http::JsonSocket>& s) {
        auto self = weak.lock();
        if (!self) return;
        std::shared_ptr<FoxgloveConnection> c;
        {
            std::lock_guard lock(self->mutex_);
            auto it = self->connections_.find(s.get());
            if (it == self->connections_.end()) return;
            c = std::move(it->second);
            self->connections_.erase(it);
        }
        c->close();
    };
    return h;
}

std::shared_ptr<FoxgloveServer> install_foxglove(http::HttpServer& http, std::shared_ptr<gateway::JsonApi> api, FoxgloveOptions options) {
    auto node = http.node();
    boost::asio::any_io_executor executor = node ? node->io_context().get_executor() : boost::asio::any_io_executor{};
    auto server = FoxgloveServer::create(std::move(api), executor, std::move(options));
    // The registered handler holds the server (as the JSON WebSocket's does).
    http::JsonSocketHandler h = server->handler();
    h.on_open = [server, open = h.on_open](std::shared_ptr<http::JsonSocket> s) { open(std::move(s)); };
    http.add_subprotocol(std::string(fg::kSubprotocolV1), h);
    http.add_subprotocol(std::string(fg::kSubprotocolSdk), h);
    return server;
}

}  // namespace rr::server::foxglove
