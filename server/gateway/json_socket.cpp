#include "server/gateway/json_socket.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>

#include "core/session/elements.hpp"
#include "core/value/timespec.hpp"
#include "server/gateway/auth/http_auth.hpp"
#include "server/gateway/binary_push.hpp"
#include "server/gateway/json_access.hpp"
#include "server/gateway/json_push.hpp"
#include "server/gateway/json_socket_request.hpp"
#include "server/gateway/json_subscriptions.hpp"
#include "server/gateway/mirror_service.hpp"
#include "server/gateway/rate_ticker.hpp"
#include "server/gateway/wire_rate_groups.hpp"
#include "server/node/node.hpp"
#include "server/service/wire_member.hpp"

namespace rr::server::gateway {

/// One JSON WebSocket: its requests (json_socket_request.hpp), subscriptions (json_subscriptions.hpp)
/// and pushes (json_push.hpp) meet the socket here. Thread-safe: the socket's strand delivers
/// messages, device strands deliver pushes and replies; mutex_ guards the registry and keeps each
/// subscription's reply ahead of its pushes.
class JsonSocketSession : public std::enable_shared_from_this<JsonSocketSession> {
    static std::uint64_t next_socket_id() {
        static std::atomic<std::uint64_t> n{0};
        return n.fetch_add(1) + 1;
    }

public:
    JsonSocketSession(std::shared_ptr<JsonApi> api, std::shared_ptr<http::JsonSocket> socket,
                      boost::asio::any_io_executor executor, ConvertStrand convert_strand, const JsonSocketOptions& options,
                      std::shared_ptr<RateTicker> ticker, std::shared_ptr<WireRateGroups> groups)
        : api_(std::move(api)),
          socket_(std::move(socket)),
          options_(options),
          timer_(executor),
          ticker_(std::move(ticker)),
          groups_(std::move(groups)),
          subs_(options.max_subscriptions),
          convert_strand_(std::move(convert_strand)),
          pipe_budget_(options.max_pipe_conversions, options.max_pipe_conversion_bytes) {
        // auth: gateway — the dashboard's session cookie, sent with the upgrade request, logs the socket in.
        if (const auto& a = api_->auth(); a && a->enabled()) {
            const std::string id = auth::cookie_value(socket_->cookie_header(), auth::kSessionCookie);
            if (!id.empty()) principal_ = a->session(id);
        }
    }

    void on_message(std::string text) {
        auto parsed = parse_socket_envelope(text, options_.max_message_bytes);
        if (auto* refused = std::get_if<SocketRejection>(&parsed))
            return send_reply(refused->id, ApiResult::failed(std::move(refused->error)));
        const auto& envelope = std::get<SocketEnvelope>(parsed);
        try {
            handle(envelope);
        } catch (const std::exception& e) {
            // A nlohmann type error would be a bug here; the socket and the gateway carry on.
            send_reply(envelope.id, ApiResult::failed(api_error(500, MessageErrorType::InternalError, e.what())));
        }
    }

    /// Ends every subscription; nothing is sent afterwards.
    void close() {
        std::map<std::uint64_t, JsonSubscription> subs;
        std::map<std::string, DeviceLogin, std::less<>> logins;
        {
            std::lock_guard lock(mutex_);
            if (closed_) return;
            closed_ = true;
            subs = subs_.take_all();
            logins.swap(device_logins_);
            timer_.cancel();
        }
        for (auto& [sid, s] : subs)
            if (s.upstream_known && !s.own) unsubscribe_upstream(s);  // those on a device_login end with its session
        // What this socket started without a timeout of its own ends with it (motion safety); on a
        // device_login's session the device's stops go there first, before it closes.
        for (const auto& d : api_->devices()) {
            const auto& guard = d->motion();
            auto login = logins.find(d->config().name);
            if (!guard) continue;
            if (login == logins.end()) {
                guard->client_gone(motion_key_);
                continue;
            }
            guard->client_gone(motion_key_, [self = shared_from_this(), l = login->second] { self->end_device_login(l); });
            logins.erase(login);
        }
        for (auto& [name, l] : logins) end_device_login(l);
    }

    void push_device_state(const DeviceStatus& status) {
        if (needs_login()) return;
        push_json(nlohmann::json{{"kind", "device_state"}, {"device", JsonApi::status_json(status)}});
    }

    void push_json(const nlohmann::json& message) {
        std::lock_guard lock(mutex_);
        if (closed_) return;
        send_text(message);
    }

    JsonSocketStats stats() const {
        JsonSocketStats s;
        std::lock_guard lock(mutex_);
        s.subscriptions = subs_.size();
        s.queued = socket_->queued();
        s.queued_bytes = socket_->queued_bytes();
        s.socket_dropped = socket_->dropped();
        s.push_drops = subs_.push_drops();
        s.wire_coalesced = subs_.wire_coalesced();
        s.pending_wires = subs_.pending_wires();
        return s;
    }

private:
    /// A `device_login`: this socket's own session to a passthrough device.
    struct DeviceLogin {
        std::weak_ptr<DeviceMirror> device;
        std::uint32_t session = 0;
        std::string username;
        std::shared_ptr<SessionEndpoints> endpoints;  // the subscriptions made on that session
    };

    // --- replies ----------------------------------------------------------------------------------

    void send_text(const nlohmann::json& j) { socket_->send(json_text(j)); }

    void send_reply(const nlohmann::json& id, const ApiResult& r) {
        if (r.error) {
            socket_->send_urgent(json_text(nlohmann::json{{"id", id}, {"error", error_object(*r.error)}}));
        } else {
            socket_->send_urgent(json_text(nlohmann::json{{"id", id}, {"result", r.value}}));
        }
    }
    void fail(const nlohmann::json& id, ApiError e) { send_reply(id, ApiResult::failed(std::move(e))); }

    // An asynchronous request: counted until answered.
    bool begin_request(const nlohmann::json& id) {
        {
            std::lock_guard lock(mutex_);
            if (in_flight_ < options_.max_in_flight) {
                ++in_flight_;
                return true;
            }
        }
        fail(id, api_error(400, MessageErrorType::BufferLimitViolation,
                           "more than " + std::to_string(options_.max_in_flight) + " requests in flight on this socket"));
        return false;
    }
    void end_request() {
        std::lock_guard lock(mutex_);
        if (in_flight_) --in_flight_;
    }
    JsonApi::Done replier(const nlohmann::json& id) {
        auto self = shared_from_this();
        return [self, id](ApiResult r) {
            self->send_reply(id, r);
            self->end_request();
        };
    }

    // --- requests ---------------------------------------------------------------------------------

    void handle(const SocketEnvelope& envelope) {
        const auto& id = envelope.id;
        const auto& a = api_->auth();
        const bool logins = a && a->enabled();
        // auth: gateway — logged in by the upgrade's cookie, or by a first {"op": "login"} message.
        if (logins && envelope.op != "login" && needs_login())
            return fail(id, api_error(401, MessageErrorType::AuthenticationError,
                                      "login required: send {\"op\": \"login\", \"username\", \"password\"} or "
                                      "{\"op\": \"login\", \"token\"} first"));
        auto parsed = parse_socket_request(envelope, logins);
        if (auto* e = std::get_if<ApiError>(&parsed)) return fail(id, std::move(*e));
        std::visit([&](auto&& request) { act(id, std::move(request)); }, std::get<SocketRequest>(std::move(parsed)));
    }

    void act(const nlohmann::json& id, LoginRequest r) { login(id, r, *api_->auth()); }
    void act(const nlohmann::json& id, DeviceLoginRequest r) { device_login(id, std::move(r)); }
    void act(const nlohmann::json& id, DeviceLogoutRequest r) { device_logout(id, r); }
    void act(const nlohmann::json& id, DevicesRequest) { send_reply(id, ApiResult::ok(api_->device_list())); }
    void act(const nlohmann::json& id, DeviceRequest r) { send_reply(id, api_->device_info(r.device)); }
    void act(const nlohmann::json& id, AccessRequest r) {
        send_reply(id, member_access(*api_, r.device, principal(), r.members, r.device_user));
    }
    void act(const nlohmann::json& id, UnsubscribeRequest r) { unsubscribe(id, r.subscription); }
    void act(const nlohmann::json& id, SetOutValueRequest r) { set_out_value(id, r.subscription, r.value); }
    void act(const nlohmann::json& id, SendRequest r) { send_packet(id, r.subscription, r.value, r.request_ack); }
    void act(const nlohmann::json& id, MemberRequest r) {
        r.address.principal = principal();
        r.address.motion = motion_client(r.address.principal);
        r.address.device_session = device_session(r.address.device);
        if (!begin_request(id)) return;
        switch (r.op) {
            case MemberOp::get: return api_->get_property(r.address, replier(id));
            case MemberOp::set: return api_->set_property(r.address, r.value, replier(id));
            case MemberOp::call: return api_->call_function(r.address, r.args, r.max_items, replier(id));
            case MemberOp::peek: return api_->peek_wire(r.address, replier(id));
            case MemberOp::subscribe: {
                SubscribeChoice choice{r.binary, r.max_rate_hz, r.rate_period, r.queue_length};
                return subscribe(id, std::move(r.address), choice);
            }
        }
    }

    // --- subscriptions ----------------------------------------------------------------------------

    // What a subscribe request chose beside the member.
    struct SubscribeChoice {
        bool binary = false;
        std::optional<double> max_rate_hz;
        RateClock rate_period{0};
        std::optional<std::size_t> queue_length;
    };

    void subscribe(const nlohmann::json& id, MemberAddress address, SubscribeChoice choice) {
        // Receiving (wire values, events, pipe packets) needs `read`; sending on the subscription
        // (set_out_value, send) needs `write`, decided here once.
        if (auto denied = api_->check_access(address, auth::Operation::read)) {
            fail(id, std::move(*denied));
            return end_request();
        }
        const bool may_write = !api_->check_access(address, auth::Operation::write).has_value();
        auto self = shared_from_this();
        api_->resolve(address, [self, id, may_write, choice](Resolved r) {
            if (auto* e = std::get_if<ApiError>(&r)) {
                self->fail(id, *e);
                return self->end_request();
            }
            self->start_subscription(id, std::get<MemberTarget>(std::move(r)), may_write, choice);
        });
    }

    // The socket as a device's motion guard sees it: one holder for all its requests, probed with
    // pings while it holds a motion without a timeout of its own (docs/security.md "Motion safety").
    std::shared_ptr<const MotionClient> motion_client(const auth::PrincipalPtr& who) const {
        auto c = std::make_shared<MotionClient>();
        c->key = motion_key_;
        c->user = who ? who->rr_user_name() : std::string();
        const std::string peer = socket_->peer();
        c->description = "JSON WebSocket from " + peer.substr(0, peer.rfind(':'));
        std::weak_ptr<http::JsonSocket> weak = socket_;
        c->liveness = [weak](std::optional<std::chrono::milliseconds> timeout) {
            if (auto s = weak.lock()) s->set_liveness_probe(timeout);
        };
        return c;
    }

    bool needs_login() const {
        const auto& a = api_->auth();
        if (!a || !a->enabled()) return false;
        std::lock_guard lock(mutex_);
        return !principal_;
    }
    auth::PrincipalPtr principal() const {
        std::lock_guard lock(mutex_);
        return principal_;
    }

    void login(const nlohmann::json& id, const LoginRequest& r, auth::GatewayAuth& a) {
        auto who = r.by_token ? a.login_token(r.token, socket_->peer(), auth::LoginChannel::websocket)
                              : a.login_password(r.username, r.password, socket_->peer(), auth::LoginChannel::websocket);
        if (!who) return fail(id, auth::login_error(who.error()));
        {
            std::lock_guard lock(mutex_);
            principal_ = *who;
        }
        send_reply(id, ApiResult::ok(auth::principal_json(**who)));
    }

    // --- device logins (auth: passthrough) --------------------------------------------------------

    std::uint32_t device_session(std::string_view device) const {
        std::lock_guard lock(mutex_);
        auto it = device_logins_.find(device);
        return it == device_logins_.end() ? 0 : it->second.session;
    }

    // From now on this socket's get, set, call and peek on the device go on a session of its own,
    // logged in to the device as that user.
    void device_login(const nlohmann::json& id, DeviceLoginRequest r) {
        const std::string name = r.device;
        auto device = api_->find_device(name);
        if (!device) return fail(id, api_error(404, MessageErrorType::ServiceNotFound, "no device named \"" + name + "\""));
        if (device->config().auth != DeviceAuth::passthrough)
            return fail(id, api_error(400, MessageErrorType::InvalidOperation,
                                      "device \"" + name + "\" is auth: shared: every client uses the gateway's own login to it; "
                                      "device_login needs auth: passthrough"));
        if (!begin_request(id)) return;
        auto self = shared_from_this();
        std::weak_ptr<DeviceMirror> weak_device = device;
        const std::string username = r.username;
        device->open_api_session(std::move(r.username), std::move(r.password),
                                 [self, id, name, username, weak_device](Result<DeviceMirror::ApiSession> r) {
            if (!r) {
                self->fail(id, device_error(r.error()));
                return self->end_request();
            }
            std::optional<DeviceLogin> replaced;
            bool keep = true;
            {
                std::lock_guard lock(self->mutex_);
                if (self->closed_) {
                    keep = false;
                } else {
                    if (auto it = self->device_logins_.find(name); it != self->device_logins_.end()) replaced = it->second;
                    self->device_logins_[name] = DeviceLogin{weak_device, r->id, username, r->endpoints};
                }
            }
            if (replaced) self->end_device_login(*replaced, "a new device_login to \"" + name + "\" replaced the session it was made on");
            if (!keep) {
                self->end_device_login(DeviceLogin{weak_device, r->id, username, r->endpoints});
                return self->end_request();
            }
            self->send_reply(id, ApiResult::ok(nlohmann::json{{"device", name}, {"username", username}}));
            self->end_request();
        });
    }

    // Back to the gateway's shared session (the device releases this socket's client locks and monitors).
    void device_logout(const nlohmann::json& id, const DeviceLogoutRequest& r) {
        std::optional<DeviceLogin> login;
        {
            std::lock_guard lock(mutex_);
            if (auto it = device_logins_.find(r.device); it != device_logins_.end()) {
                login = it->second;
                device_logins_.erase(it);
            }
        }
        if (!login) return fail(id, bad_request("this socket has no device_login for \"" + r.device + "\""));
        end_device_login(*login, "device_logout ended the session it was made on");
        send_reply(id, ApiResult::ok(nlohmann::json::object()));
    }

    // Closes a device login's session; its subscriptions end, each with a "closed" push naming `why`
    // (none when the socket itself is closing: `why` empty).
    void end_device_login(const DeviceLogin& login, const std::string& why = {}) {
        {
            std::lock_guard lock(mutex_);
            const auto ended = subs_.remove_own(login.endpoints);
            if (!closed_ && !why.empty())
                for (auto sid : ended)
                    send_text(nlohmann::json{{"subscription", sid}, {"kind", "closed"},
                                             {"error", error_object(api_error(503, MessageErrorType::OperationAborted, why))}});
        }
        if (login.endpoints) login.endpoints->forget();
        if (auto device = login.device.lock()) device->close_api_session(login.session);
    }

    std::shared_ptr<SessionEndpoints> own_endpoints(std::string_view device) const {
        // Under mutex_.
        auto it = device_logins_.find(device);
        return it == device_logins_.end() ? nullptr : it->second.endpoints;
    }

    void start_subscription(const nlohmann::json& id, MemberTarget t, bool may_write, const SubscribeChoice& choice) {
        SubscriptionKind kind;
        switch (t.member->kind) {
            case robdef::MemberKind::wire: kind = SubscriptionKind::wire; break;
            case robdef::MemberKind::event: kind = SubscriptionKind::event; break;
            case robdef::MemberKind::pipe: kind = SubscriptionKind::pipe; break;
            default:
                fail(id, api_error(404, MessageErrorType::MemberNotFound,
                                   "member \"" + t.member->name + "\" is " +
                                       robdef::with_article(robdef::member_kind_keyword(t.member->kind)) +
                                       "; subscribe takes a wire, an event or a pipe"));
                return end_request();
        }
        if (choice.max_rate_hz && kind == SubscriptionKind::event) {
            fail(id, bad_request("\"max_rate_hz\" applies to wires and pipes; every event of \"" + t.member->name + "\" is delivered"));
            return end_request();
        }
        if (choice.queue_length && kind != SubscriptionKind::pipe) {
            fail(id, bad_request("\"queue_length\" applies to pipes; a wire keeps its newest value"));
            return end_request();
        }
        // Opening a wire connection or a pipe endpoint is a request the locks held at the gateway
        // decide; events reach every client in RR, locked or not.
        if (kind != SubscriptionKind::event) {
            if (auto locked = api_->check_locks(t, kind == SubscriptionKind::wire ? MessageEntryType::WireConnectReq
                                                                                 : MessageEntryType::PipeConnectReq)) {
                fail(id, std::move(*locked));
                return end_request();
            }
        }
        std::uint64_t sid = 0;
        std::shared_ptr<SessionEndpoints> own;
        {
            std::lock_guard lock(mutex_);
            if (closed_) {
                if (in_flight_) --in_flight_;
                return;
            }
            JsonSubscription s;
            s.kind = kind;
            s.may_write = may_write;
            s.binary = choice.binary;
            if (choice.max_rate_hz) {
                s.rate = RateWindow(choice.rate_period);
                s.max_rate_hz = *choice.max_rate_hz;
            }
            if (choice.queue_length) s.queue_length = *choice.queue_length;
            s.queue_bytes_limit = options_.max_pipe_conversion_bytes;
            s.target = std::make_shared<const MemberTarget>(t);
            s.own = own_endpoints(t.device->config().name);
            own = s.own;
            auto added = subs_.add(std::move(s));
            if (auto* e = std::get_if<ApiError>(&added)) {
                if (in_flight_) --in_flight_;
                return fail(id, std::move(*e));
            }
            sid = std::get<std::uint64_t>(added);
        }
        std::weak_ptr<JsonSocketSession> weak = weak_from_this();
        if (own) return start_endpoint_subscription(id, sid, kind, t, own);

        if (kind == SubscriptionKind::pipe)
            return start_endpoint_subscription(id, sid, kind, t, t.device->mirror_service()->shared_endpoints());

        const bool is_wire = kind == SubscriptionKind::wire;
        auto done = [weak, sid, id](Result<void> r) {
            if (auto s = weak.lock()) s->subscribed(sid, id, r ? std::nullopt : std::optional(device_error(r.error())));
        };
        // A rate-limited wire joins the rate group of its wire and rate (wire_rate_groups.hpp): one
        // upstream subscription and one pending value for all of them, handed out once per window.
        const bool grouped = is_wire && choice.max_rate_hz.has_value();
        const std::uint64_t upstream =
            grouped ? groups_->join(group_upstream(t), choice.rate_period, group_value_handler(sid), std::move(done))
                    : t.device->subscribe(t.path, t.member->name, is_wire, value_handler(sid, is_wire), std::move(done));
        bool drop = false;
        {
            // `subscribed` may have run already (inside subscribe), or the socket closed meanwhile.
            std::lock_guard lock(mutex_);
            auto* s = subs_.find(sid);
            if (!s) {
                drop = true;
            } else if (s->failed) {
                subs_.erase(sid);
                drop = true;
            } else {
                s->upstream_id = upstream;
                s->upstream_known = true;
                s->rate_group = grouped;
            }
        }
        if (drop) grouped ? groups_->leave(upstream) : t.device->unsubscribe(upstream);
    }

    // Where a rate group of `t`'s wire gets its values: the device's shared session.
    static WireRateGroups::Upstream group_upstream(const MemberTarget& t) {
        WireRateGroups::Upstream up;
        up.source = t.device.get();
        up.path = t.path;
        up.member = t.member->name;
        up.subscribe = [device = t.device, path = t.path, member = t.member->name](WireRateGroups::OnEntry on_entry,
                                                                                  WireRateGroups::Done done) {
            return device->subscribe(path, member, true, std::move(on_entry), std::move(done));
        };
        up.unsubscribe = [device = t.device](std::uint64_t id) { device->unsubscribe(id); };
        return up;
    }

    void subscribed(std::uint64_t sid, const nlohmann::json& id, std::optional<ApiError> error) {
        std::optional<JsonSubscription> unsubscribe;
        bool flush = false;
        {
            std::lock_guard lock(mutex_);
            if (in_flight_) --in_flight_;
            auto* s = subs_.find(sid);
            if (!s) {
                if (!closed_) fail(id, api_error(503, MessageErrorType::OperationAborted, "subscription ended"));
                return;
            }
            if (error) {
                if (s->upstream_known) {
                    unsubscribe.emplace(*s);
                    subs_.erase(sid);
                } else {
                    s->failed = true;
                }
                fail(id, std::move(*error));
            } else {
                // Under the lock: the reply is queued before any push of this subscription.
                send_reply(id, ApiResult::ok(subscribe_result(sid, *s)));
                s->active = true;
                flush = s->pending_wire != nullptr;
            }
        }
        if (unsubscribe) unsubscribe_upstream(*unsubscribe);
        if (flush) flush_wires();
    }

    // The subscribe reply: the id, the kind, and the rate and queue length it got.
    static nlohmann::json subscribe_result(std::uint64_t sid, const JsonSubscription& s) {
        nlohmann::json r{{"subscription", sid}, {"kind", kind_name(s.kind)}};
        if (s.rate.limited()) {
            // As the client wrote it: 2, not 2.0.
            const double whole = std::floor(s.max_rate_hz);
            if (whole == s.max_rate_hz) r["max_rate_hz"] = static_cast<std::int64_t>(whole);
            else r["max_rate_hz"] = s.max_rate_hz;
        }
        if (s.rate.limited() && s.kind == SubscriptionKind::pipe) r["queue_length"] = s.queue_length;
        return r;
    }

    // What a wire or event subscription's values go to (either session).
    std::function<void(const SharedEntryPtr&)> value_handler(std::uint64_t sid, bool is_wire) {
        std::weak_ptr<JsonSocketSession> weak = weak_from_this();
        return [weak, sid, is_wire](const SharedEntryPtr& e) {
            auto s = weak.lock();
            if (!s) return;
            if (is_wire)
                s->on_wire(sid, e, 0, e->arrival());  // the wire's newest, handed out on joining, may come late
            else
                s->on_event(sid, e);
        };
    }

    // A rate group's member handler (wire_rate_groups.hpp): made once per subscription.
    WireRateGroups::OnValue group_value_handler(std::uint64_t sid) {
        std::weak_ptr<JsonSocketSession> weak = weak_from_this();
        return [weak, sid](const SharedEntryPtr& e, std::uint64_t coalesced, std::uint64_t seq) {
            if (auto s = weak.lock()) s->on_wire(sid, e, coalesced, seq);
        };
    }

    GatewayPipeHandlers pipe_handlers(std::uint64_t sid) {
        std::weak_ptr<JsonSocketSession> weak = weak_from_this();
        GatewayPipeHandlers h;
        h.on_packet = [weak, sid](const MessageElement& packet, std::uint32_t) {
            if (auto s = weak.lock()) s->on_pipe_packet(sid, packet);
        };
        h.on_ack = [weak, sid](std::uint32_t number) {
            if (auto s = weak.lock()) s->on_pipe_ack(sid, number);
        };
        h.on_closed = [weak, sid](const RRError& reason) {
            if (auto s = weak.lock()) s->on_subscription_closed(sid, reason);
        };
        return h;
    }

    // A subscription through `endpoints`: this socket's own session to a passthrough device
    // (device_login: the device's privileges and locks for that user apply to what it receives and
    // sends), or the shared session's pipe endpoints (MirrorService::shared_endpoints).
    void start_endpoint_subscription(const nlohmann::json& id, std::uint64_t sid, SubscriptionKind kind,
                                     const MemberTarget& t, const std::shared_ptr<SessionEndpoints>& endpoints) {
        std::weak_ptr<JsonSocketSession> weak = weak_from_this();
        std::weak_ptr<SessionEndpoints> weak_endpoints = endpoints;
        auto opened = [weak, sid, id, weak_endpoints, kind](Result<std::uint64_t> r) {
            auto close = [weak_endpoints, kind](std::uint64_t x) {
                auto o = weak_endpoints.lock();
                if (!o) return;
                if (kind == SubscriptionKind::pipe)
                    o->close_pipe(x);
                else
                    o->unsubscribe(x);
            };
            auto s = weak.lock();
            if (!s) {
                if (r) close(*r);
                return;
            }
            s->endpoint_opened(sid, id, std::move(r), close);
        };
        if (kind == SubscriptionKind::pipe) {
            endpoints->open_pipe(t.path, t.member->name, robdef::pipe_is_unreliable(*t.object, *t.member), pipe_handlers(sid),
                           std::move(opened));
            return;
        }
        SubscriptionHandlers h;
        h.on_entry = value_handler(sid, kind == SubscriptionKind::wire);
        h.on_closed = [weak, sid](const RRError& reason) {
            if (auto s = weak.lock()) s->on_subscription_closed(sid, reason);
        };
        endpoints->subscribe(t.path, t.member->name, kind == SubscriptionKind::wire, std::move(h), std::move(opened));
    }

    // A pipe endpoint (either session) or an own-session subscription answered: `close` undoes it
    // when the subscription ended meanwhile.
    void endpoint_opened(std::uint64_t sid, const nlohmann::json& id, Result<std::uint64_t> r,
                         const std::function<void(std::uint64_t)>& close) {
        std::optional<std::uint64_t> orphan;
        bool flush = false;
        {
            std::lock_guard lock(mutex_);
            if (in_flight_) --in_flight_;
            auto* s = subs_.find(sid);
            if (!s) {
                if (r) orphan = *r;  // the socket closed while connecting
                if (!closed_) fail(id, api_error(503, MessageErrorType::OperationAborted, "subscription ended"));
            } else if (!r) {
                subs_.erase(sid);
                fail(id, device_error(r.error()));
            } else {
                s->upstream_id = *r;
                s->upstream_known = true;
                // Under the lock: the reply is queued before any push of this subscription.
                send_reply(id, ApiResult::ok(subscribe_result(sid, *s)));
                s->active = true;
                flush = s->pending_wire != nullptr;
            }
        }
        if (orphan) close(*orphan);
        if (flush) flush_wires();
    }

    // The SessionEndpoints a pipe subscription is on: the socket's device_login session, or the shared one.
    static std::shared_ptr<SessionEndpoints> pipe_endpoints(const MemberTarget& t, const std::shared_ptr<SessionEndpoints>& own) {
        return own ? own : t.device->mirror_service()->shared_endpoints();
    }

    void unsubscribe_upstream(const JsonSubscription& s) {
        if (s.rate_group)
            groups_->leave(s.upstream_id);
        else if (s.kind == SubscriptionKind::pipe)
            pipe_endpoints(*s.target, s.own)->close_pipe(s.upstream_id);
        else if (s.own)
            s.own->unsubscribe(s.upstream_id);
        else
            s.target->device->unsubscribe(s.upstream_id);
    }

    void unsubscribe(const nlohmann::json& id, std::uint64_t sid) {
        std::optional<JsonSubscription> sub;
        {
            std::lock_guard lock(mutex_);
            sub = subs_.take_active(sid);
        }
        if (!sub) return fail(id, bad_request("no subscription " + std::to_string(sid)));
        if (sub->upstream_known) unsubscribe_upstream(*sub);
        send_reply(id, ApiResult::ok(nlohmann::json::object()));
    }

    // What set_out_value and send need of an answered subscription, copied under the lock.
    struct Sending {
        MemberTarget target;
        std::uint64_t upstream_id = 0;
        std::shared_ptr<SessionEndpoints> own;
    };

    // The answered subscription `sid` of `kind` when this login may write on it; else the error.
    std::variant<Sending, ApiError> sending_on(std::uint64_t sid, SubscriptionKind kind) {
        Sending out;
        bool may_write = false;
        {
            std::lock_guard lock(mutex_);
            auto found = subs_.find_active(sid, kind);
            if (auto* e = std::get_if<ApiError>(&found)) return std::move(*e);
            const auto* s = std::get<const JsonSubscription*>(found);
            out = Sending{*s->target, s->upstream_id, s->own};
            may_write = s->may_write;
        }
        const auto& member = *out.target.member;
        if (!may_write) {
            if (auto a = api_->auth()) a->counters().denied.fetch_add(1);
            return api_error(403, MessageErrorType::PermissionDenied, "this login may not write " + member.name);
        }
        if (member.direction() == robdef::MemberDirection::readonly)
            return api_error(405, MessageErrorType::ReadOnlyMember,
                             std::string(kind_name(kind)) + " \"" + member.name + "\" is read-only");
        return out;
    }

    void set_out_value(const nlohmann::json& id, std::uint64_t sid, const nlohmann::json& value) {
        auto found = sending_on(sid, SubscriptionKind::wire);
        if (auto* e = std::get_if<ApiError>(&found)) return fail(id, std::move(*e));
        auto& [t, upstream_id, own] = std::get<Sending>(found);
        ApiError error;
        auto packet = api_->element_from_json(value, t.member->type, t, "packet", error, "value");
        if (!packet) return fail(id, error);
        // A client's OutValue is the device's InValue (wire.md §6.7: WirePacket, newest wins).
        MessageEntry e;
        e.entry_type = MessageEntryType::WirePacket;
        e.member_name = t.member->name;
        e.metadata = "unreliable\n";
        e.elements.push_back(pack_timespec(wall_clock_timespec(), "packettime"));
        e.elements.push_back(std::move(*packet));
        // A command stream (position_command, …): refused while another client holds the motion, and
        // ended by the gateway when it goes silent (motion safety).
        {
            e.service_path = t.path;
            MemberAddress address;
            address.motion = motion_client(principal());
            address.device_session = t.device_session;
            auto motion = JsonApi::admit_motion(address, t, e);
            if (auto* refused = std::get_if<ApiError>(&motion)) return fail(id, std::move(*refused));
        }
        if (own) {
            e.service_path = t.path;
            auto sent = own->send_wire_packet(std::move(e));
            if (!sent) return fail(id, device_error(sent.error()));
            return send_reply(id, ApiResult::ok(nlohmann::json::object()));
        }
        auto client = t.device->upstream();
        if (!client)
            return fail(id, api_error(503, MessageErrorType::ConnectionError,
                                      "device \"" + t.device->config().name + "\" is not connected"));
        e.service_path = t.device->mirror_service()->to_upstream(t.path);
        client->send(std::move(e));
        send_reply(id, ApiResult::ok(nlohmann::json::object()));
    }

    void send_packet(const nlohmann::json& id, std::uint64_t sid, const nlohmann::json& value, bool request_ack) {
        auto found = sending_on(sid, SubscriptionKind::pipe);
        if (auto* e = std::get_if<ApiError>(&found)) return fail(id, std::move(*e));
        auto& [t, upstream_id, own] = std::get<Sending>(found);
        ApiError error;
        auto packet = api_->element_from_json(value, t.member->type, t, "packet", error, "value");
        if (!packet) return fail(id, error);
        auto n = pipe_endpoints(t, own)->send_pipe_packet(upstream_id, std::move(*packet), request_ack);
        if (!n) return fail(id, device_error(n.error()));
        send_reply(id, ApiResult::ok(nlohmann::json{{"packetnumber", *n}}));
    }

    // --- pushes -----------------------------------------------------------------------------------

    bool push_congested() const {
        return socket_->queued() >= options_.push_queue_limit || socket_->queued_bytes() >= options_.push_bytes_limit;
    }
    bool wire_congested() const {
        return socket_->queued() >= options_.wire_queue_threshold || socket_->queued_bytes() >= options_.wire_bytes_threshold;
    }

    // A push slot for subscription `sid`: none (and counted) when the client is too far behind.
    std::optional<PushTicket> take_push(std::uint64_t sid) {
        std::lock_guard lock(mutex_);
        if (closed_) return std::nullopt;
        return subs_.take_push(sid, push_congested());
    }

    // A push whose body (a JSON object's text, shared by all subscribers) is `r`: a binary message
    // when it refers to arrays, else text.
    void send_push(std::uint64_t sid, std::string_view kind, std::uint64_t dropped, const SharedEntry::BinaryRendering& r) {
        if (!r.arrays)
            socket_->send(push_text(sid, kind, dropped, r.body));
        else
            socket_->send_binary(binary_push_head(push_text(sid, kind, dropped, r.body)), r.arrays);
    }

    // A text push whose body is `e`'s rendering `body`: only the head is made per socket; the body is
    // written from the entry's own string (kept alive by the message, not copied).
    void send_text_push(std::uint64_t sid, std::string_view kind, std::uint64_t dropped, const SharedEntryPtr& e,
                        const std::string& body) {
        const PushHead head = push_head(sid, kind, dropped, body);
        socket_->send_shared(head.text(), std::shared_ptr<const std::string>(e, &body), head.body_offset);
    }

    void on_event(std::uint64_t sid, const SharedEntryPtr& e) {
        auto ticket = take_push(sid);
        if (!ticket) return;
        const MemberTarget& t = *ticket->target;
        if (ticket->binary)
            return send_push(sid, "event", ticket->dropped, e->rendered_binary([&](const MessageEntry& entry) {
                return render_binary_body([&](BinaryArrays* b) { return event_push_body(*api_, entry, t, b); });
            }));
        const std::string& body = e->rendered([&](const MessageEntry& entry) { return event_push_text(*api_, entry, t); });
        send_text_push(sid, "event", ticket->dropped, e, body);
    }

    // Runs on the device's strand, which must not wait for a packet's JSON (a camera frame is about
    // 1 MB of text; seconds under ASan): the device's replies to everyone arrive on it. The JSON is made
    // on the server's conversion strand; while this socket's packets waiting there fill its budget
    // (max_pipe_conversions, max_pipe_conversion_bytes), newer packets are dropped and counted.
    void on_pipe_packet(std::uint64_t sid, const MessageElement& packet) {
        std::optional<PipeToSend> queued;
        {
            // A rate-limited pipe: the packet joins its queue, and the oldest goes when its window is open.
            std::lock_guard lock(mutex_);
            if (closed_) return;
            const auto* s = subs_.find(sid);
            if (!s) return;
            if (s->rate.limited()) {
                const Offered o = subs_.offer_pipe(sid, packet, push_congested(), rate_clock_now(), queued);
                if (!o.send_now && o.wait.count() > 0) wake_at_locked(o.wait);
                if (!queued) return;
            }
        }
        if (queued) return convert(queued->subscription, std::move(queued->packet), std::move(queued->ticket));
        auto ticket = take_push(sid);
        if (!ticket) return;
        convert(sid, packet, std::move(*ticket));
    }

    // Posts a pipe packet to the conversion strand, within this socket's budget (else dropped, counted).
    void convert(std::uint64_t sid, MessageElement packet, PushTicket ticket) {
        const std::size_t bytes = payload_bytes(packet);
        if (!pipe_budget_.try_acquire(bytes)) {
            std::lock_guard lock(mutex_);
            subs_.return_push(sid, ticket.dropped);
            return;
        }
        boost::asio::post(convert_strand_, [self = shared_from_this(), sid, packet = std::move(packet), ticket = std::move(ticket), bytes] {
            self->convert_pipe_packet(sid, packet, ticket);
            self->pipe_budget_.release(bytes);
        });
    }

    // --- rate-limited subscriptions (rate_window.hpp, rate_ticker.hpp) ------------------------------

    // Under mutex_: asks the server's ticker of `period` to wake this socket at its next window (once
    // per period until it has).
    void wake_at_locked(RateClock period) {
        if (closed_ || std::find(wakes_.begin(), wakes_.end(), period) != wakes_.end()) return;
        wakes_.push_back(period);
        std::weak_ptr<JsonSocketSession> weak = weak_from_this();
        ticker_->wake(period, [weak, period] {
            if (auto s = weak.lock()) s->on_rate_window(period);
        });
    }

    // A window of `period` began: the wire values and pipe packets waiting for it go (the client's
    // backpressure still applies), and the socket asks to be woken again for those still waiting.
    void on_rate_window(RateClock period) {
        {
            std::lock_guard lock(mutex_);
            wakes_.erase(std::remove(wakes_.begin(), wakes_.end(), period), wakes_.end());
            if (closed_) return;
        }
        flush_wires();
        std::vector<PipeToSend> packets;
        {
            std::lock_guard lock(mutex_);
            if (closed_) return;
            std::vector<RateClock> waiting;
            const RateClock now = rate_clock_now();
            subs_.take_pipe_packets(packets, push_congested(), now, waiting);
            subs_.rate_waiting(now, waiting);
            for (auto p : waiting) wake_at_locked(p);
        }
        for (auto& p : packets) convert(p.subscription, std::move(p.packet), std::move(p.ticket));
    }

    // On the conversion strand (packets of one socket stay in order).
    void convert_pipe_packet(std::uint64_t sid, const MessageElement& packet, const PushTicket& ticket) {
        if (!push_allowed(sid)) return;
        auto push = pipe_push(*api_, sid, packet, *ticket.target, ticket.dropped, ticket.binary);
        // Under the lock: never after the subscription's "closed" push or its unsubscribe reply.
        std::lock_guard lock(mutex_);
        if (!push_allowed_locked(sid)) return;
        if (!push.arrays)
            socket_->send(std::move(push.body));
        else
            socket_->send_binary(std::move(push.body), std::move(push.arrays));
    }

    bool push_allowed(std::uint64_t sid) const {
        std::lock_guard lock(mutex_);
        return push_allowed_locked(sid);
    }
    bool push_allowed_locked(std::uint64_t sid) const { return !closed_ && subs_.is_active(sid); }

    void on_pipe_ack(std::uint64_t sid, std::uint32_t number) {
        std::lock_guard lock(mutex_);
        if (!push_allowed_locked(sid)) return;
        send_text(nlohmann::json{{"subscription", sid}, {"kind", "pipe_ack"}, {"packetnumber", number}});
    }

    void on_subscription_closed(std::uint64_t sid, const RRError& reason) {
        std::lock_guard lock(mutex_);
        auto* s = subs_.find(sid);
        if (!s) return;
        const bool active = s->active;
        subs_.erase(sid);
        if (active && !closed_)
            send_text(nlohmann::json{{"subscription", sid}, {"kind", "closed"}, {"error", error_object(device_error(reason))}});
    }

    // `coalesced`: values its rate group replaced before this one (counted as this socket's too); `seq`:
    // the value's place in its wire's order (an older one handed out late is dropped): its rate group's
    // seq, or its arrival (shared_entry.hpp) for a subscription of its own.
    void on_wire(std::uint64_t sid, const SharedEntryPtr& e, std::uint64_t coalesced = 0, std::uint64_t seq = 0) {
        if (e->entry().entry_type == MessageEntryType::WireClosed) {
            on_subscription_closed(sid, make_error(MessageErrorType::ConnectionError, "wire closed by the device"));
            return;
        }
        {
            std::lock_guard lock(mutex_);
            const Offered o = subs_.offer_wire(sid, e, rate_clock_now(), coalesced, seq);
            if (!o.send_now) {
                if (o.wait.count() > 0) wake_at_locked(o.wait);  // waits for its window
                return;  // or not open, or waits for its subscribe reply
            }
        }
        flush_wires();
    }

    // Sends the waiting wire values unless the client is behind; then they wait (coalescing) and retry.
    // One flusher at a time, so values of one subscription are never reordered.
    void flush_wires() {
        {
            std::lock_guard lock(mutex_);
            if (flushing_) {
                flush_again_ = true;
                return;
            }
            flushing_ = true;
        }
        std::vector<WireToSend>& batch = wire_batch_;  // the flusher's alone (flushing_)
        RateClock now{0};
        for (;;) {
            {
                std::lock_guard lock(mutex_);
                flush_again_ = false;
                now = rate_clock_now();
                if (closed_ || !subs_.wires_waiting(now)) {
                    flushing_ = false;
                    return;
                }
                if (wire_congested()) {
                    arm_retry();
                    flushing_ = false;
                    return;
                }
                subs_.take_wires(batch, now);
            }
            for (const auto& w : batch) {
                const MemberTarget& t = *w.target;
                if (w.binary) {
                    send_push(w.subscription, "wire", 0, w.value->rendered_binary([&](const MessageEntry& e) {
                        return render_binary_body([&](BinaryArrays* b) { return wire_push_body(*api_, e, t, b); });
                    }));
                    continue;
                }
                const std::string& body =
                    w.value->rendered([&](const MessageEntry& e) { return wire_push_text(*api_, e, t); });
                send_text_push(w.subscription, "wire", 0, w.value, body);
            }
            batch.clear();  // the values go now, the capacity stays
            std::lock_guard lock(mutex_);
            if (!flush_again_) {
                flushing_ = false;
                return;
            }
        }
    }

    // Under mutex_.
    void arm_retry() {
        if (timer_armed_) return;
        timer_armed_ = true;
        timer_.expires_after(options_.wire_retry);
        std::weak_ptr<JsonSocketSession> weak = weak_from_this();
        timer_.async_wait([weak](boost::system::error_code ec) {
            auto s = weak.lock();
            if (!s) return;
            {
                std::lock_guard lock(s->mutex_);
                s->timer_armed_ = false;
            }
            if (!ec) s->flush_wires();
        });
    }

    std::shared_ptr<JsonApi> api_;
    std::shared_ptr<http::JsonSocket> socket_;
    JsonSocketOptions options_;
    mutable std::mutex mutex_;
    boost::asio::steady_timer timer_;
    std::shared_ptr<RateTicker> ticker_;  // the server's: wakes rate-limited subscriptions at their windows
    std::shared_ptr<WireRateGroups> groups_;  // the server's: rate-limited wires' shared values
    std::vector<RateClock> wakes_;        // periods the ticker will wake this socket at (under mutex_)
    bool timer_armed_ = false, flushing_ = false, flush_again_ = false, closed_ = false;
    std::vector<WireToSend> wire_batch_;  // flush_wires()' batch: used by the one flusher, outside mutex_
    JsonSubscriptions subs_;
    auth::PrincipalPtr principal_;  // auth: gateway — who logged this socket in
    const std::string motion_key_ = "ws:" + std::to_string(next_socket_id());  // the motion guards' holder key
    std::map<std::string, DeviceLogin, std::less<>> device_logins_;  // by device name
    std::size_t in_flight_ = 0;
    ConvertStrand convert_strand_;                  // shared by the server's sockets
    ConversionBudget pipe_budget_;                  // this socket's packets posted there, not yet sent
};

// --- server ---------------------------------------------------------------------------------------

JsonSocketServer::JsonSocketServer(std::shared_ptr<JsonApi> api, boost::asio::any_io_executor executor,
                                   JsonSocketOptions options)
    : api_(std::move(api)),
      executor_(executor),
      convert_strand_(boost::asio::make_strand(executor)),
      ticker_(std::make_shared<RateTicker>(executor)),
      groups_(WireRateGroups::create(executor)),
      options_(options) {}

std::size_t JsonSocketServer::rate_groups() const { return groups_->groups(); }

std::shared_ptr<JsonSocketServer> JsonSocketServer::create(std::shared_ptr<JsonApi> api,
                                                           boost::asio::any_io_executor executor,
                                                           JsonSocketOptions options) {
    std::shared_ptr<JsonSocketServer> s(new JsonSocketServer(std::move(api), std::move(executor), options));
    std::weak_ptr<JsonSocketServer> weak = s;
    for (const auto& d : s->api_->devices()) {
        const auto id = d->add_state_listener([weak](const DeviceStatus& status) {
            if (auto self = weak.lock()) self->on_device_state(status);
        });
        s->listeners_.emplace_back(d, id);
    }
    // Devices added and removed while running (discovery): state pushes for new ones, device_removed.
    s->devices_listener_ = s->api_->add_devices_listener([weak](const std::shared_ptr<DeviceMirror>& d, bool added) {
        if (auto self = weak.lock()) self->on_devices_changed(d, added);
    });
    return s;
}

void JsonSocketServer::on_devices_changed(const std::shared_ptr<DeviceMirror>& device, bool added) {
    std::weak_ptr<JsonSocketServer> weak = weak_from_this();
    if (added) {
        const auto id = device->add_state_listener([weak](const DeviceStatus& status) {
            if (auto self = weak.lock()) self->on_device_state(status);
        });
        {
            std::lock_guard lock(mutex_);
            listeners_.emplace_back(device, id);
        }
        on_device_state(device->status());
        return;
    }
    {
        std::lock_guard lock(mutex_);
        for (auto it = listeners_.begin(); it != listeners_.end();) {
            if (it->first == device) {
                device->remove_state_listener(it->second);
                it = listeners_.erase(it);
            } else {
                ++it;
            }
        }
    }
    push_text(nlohmann::json{{"kind", "device_removed"}, {"device", JsonApi::status_json(device->status())}});
}

void JsonSocketServer::push_text(const nlohmann::json& message) {
    std::vector<std::shared_ptr<JsonSocketSession>> sessions;
    {
        std::lock_guard lock(mutex_);
        for (const auto& [k, s] : sessions_) sessions.push_back(s);
    }
    for (const auto& s : sessions) s->push_json(message);
}

JsonSocketServer::~JsonSocketServer() {
    api_->remove_devices_listener(devices_listener_);
    for (auto& [d, id] : listeners_) d->remove_state_listener(id);
    std::map<const http::JsonSocket*, std::shared_ptr<JsonSocketSession>> sessions;
    {
        std::lock_guard lock(mutex_);
        sessions.swap(sessions_);
    }
    for (auto& [k, s] : sessions) s->close();
}

http::JsonSocketHandler JsonSocketServer::handler() {
    auto self = shared_from_this();
    return http::JsonSocketHandler{
        [self](std::shared_ptr<http::JsonSocket> s) { self->on_open(s); },
        [self](const std::shared_ptr<http::JsonSocket>& s, std::string text) { self->on_message(s, std::move(text)); },
        [self](const std::shared_ptr<http::JsonSocket>& s) { self->on_close(s); },
    };
}

void JsonSocketServer::on_open(const std::shared_ptr<http::JsonSocket>& socket) {
    auto session = std::make_shared<JsonSocketSession>(api_, socket, executor_, convert_strand_, options_, ticker_, groups_);
    std::lock_guard lock(mutex_);
    sessions_[socket.get()] = std::move(session);
}

void JsonSocketServer::on_message(const std::shared_ptr<http::JsonSocket>& socket, std::string text) {
    std::shared_ptr<JsonSocketSession> session;
    {
        std::lock_guard lock(mutex_);
        auto it = sessions_.find(socket.get());
        if (it == sessions_.end()) return;
        session = it->second;
    }
    session->on_message(std::move(text));
}

void JsonSocketServer::on_close(const std::shared_ptr<http::JsonSocket>& socket) {
    std::shared_ptr<JsonSocketSession> session;
    {
        std::lock_guard lock(mutex_);
        auto it = sessions_.find(socket.get());
        if (it == sessions_.end()) return;
        session = std::move(it->second);
        sessions_.erase(it);
    }
    session->close();
}

void JsonSocketServer::on_device_state(const DeviceStatus& status) {
    std::vector<std::shared_ptr<JsonSocketSession>> sessions;
    {
        std::lock_guard lock(mutex_);
        for (const auto& [k, s] : sessions_) sessions.push_back(s);
    }
    for (const auto& s : sessions) s->push_device_state(status);
}

std::vector<JsonSocketStats> JsonSocketServer::stats() const {
    std::vector<std::shared_ptr<JsonSocketSession>> sessions;
    {
        std::lock_guard lock(mutex_);
        for (const auto& [k, s] : sessions_) sessions.push_back(s);
    }
    std::vector<JsonSocketStats> out;
    for (const auto& s : sessions) out.push_back(s->stats());
    return out;
}

std::shared_ptr<JsonSocketServer> install_json_socket(http::HttpServer& http, std::shared_ptr<JsonApi> api,
                                                      JsonSocketOptions options) {
    auto node = http.node();
    boost::asio::any_io_executor executor = node ? node->io_context().get_executor() : boost::asio::any_io_executor{};
    auto server = JsonSocketServer::create(std::move(api), executor, options);
    http.add_subprotocol(std::string(kJsonSubprotocol), server->handler());
    return server;
}

}  // namespace rr::server::gateway
