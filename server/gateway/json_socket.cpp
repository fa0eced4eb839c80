#include "server/gateway/json_socket.hpp"

#include <atomic>

#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>

#include "core/session/elements.hpp"
#include "core/value/timespec.hpp"
#include "server/gateway/auth/http_auth.hpp"
#include "server/gateway/binary_push.hpp"
#include "server/gateway/mirror_service.hpp"
#include "server/node/node.hpp"
#include "server/service/wire_member.hpp"

namespace rr::server::gateway {

namespace {

enum class SubKind : std::uint8_t { wire, event, pipe };

std::string_view kind_name(SubKind k) {
    switch (k) {
        case SubKind::wire: return "wire";
        case SubKind::event: return "event";
        case SubKind::pipe: return "pipe";
    }
    return "?";
}

ApiError bad_request(std::string message) { return api_error(400, MessageErrorType::InvalidArgument, std::move(message)); }

}  // namespace

/// One JSON WebSocket: requests, subscriptions and their pushes (see json_socket.hpp). Thread-safe: the
/// socket's strand delivers messages, device strands deliver pushes and replies.
class JsonSocketSession : public std::enable_shared_from_this<JsonSocketSession> {
public:
    JsonSocketSession(std::shared_ptr<JsonApi> api, std::shared_ptr<http::JsonSocket> socket,
                      boost::asio::any_io_executor executor, ConvertStrand convert_strand, const JsonSocketOptions& options)
        : api_(std::move(api)),
          socket_(std::move(socket)),
          options_(options),
          timer_(executor),
          convert_strand_(std::move(convert_strand)),
          pipe_budget_(options.max_pipe_conversions, options.max_pipe_conversion_bytes) {
        // auth: gateway — the dashboard's session cookie, sent with the upgrade request, logs the socket in.
        if (const auto& a = api_->auth(); a && a->enabled()) {
            const std::string id = auth::cookie_value(socket_->cookie_header(), auth::kSessionCookie);
            if (!id.empty()) principal_ = a->session(id);
        }
    }

    void on_message(std::string text) {
        if (text.size() > options_.max_message_bytes) {
            send_reply(nullptr, ApiResult::failed(api_error(400, MessageErrorType::BufferLimitViolation,
                                                            "message of " + std::to_string(text.size()) +
                                                                " bytes is over the limit of " +
                                                                std::to_string(options_.max_message_bytes))));
            return;
        }
        auto msg = parse_request_json(text);
        if (!msg) return send_reply(nullptr, ApiResult::failed(bad_request(msg.error().message)));
        nlohmann::json id = nullptr;
        try {
            if (!msg->is_object()) return send_reply(nullptr, ApiResult::failed(bad_request("a request is a JSON object")));
            if (auto it = msg->find("id"); it != msg->end()) id = *it;
            if (!id.is_number_integer() && !id.is_string())
                return send_reply(nullptr, ApiResult::failed(bad_request("a request needs an \"id\" (integer or string)")));
            handle(id, *msg);
        } catch (const std::exception& e) {
            // A nlohmann type error would be a bug here; the socket and the gateway carry on.
            send_reply(id, ApiResult::failed(api_error(500, MessageErrorType::InternalError, e.what())));
        }
    }

    /// Ends every subscription; nothing is sent afterwards.
    void close() {
        std::map<std::uint64_t, Subscription> subs;
        std::map<std::string, DeviceLogin, std::less<>> logins;
        {
            std::lock_guard lock(mutex_);
            if (closed_) return;
            closed_ = true;
            subs.swap(subs_);
            logins.swap(device_logins_);
            timer_.cancel();
        }
        for (auto& [sid, s] : subs)
            if (s.mirror_known && !s.own) unsubscribe_upstream(s);  // those on a device_login end with its session
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
        s.push_drops = push_drops_;
        s.wire_coalesced = wire_coalesced_;
        for (const auto& [sid, sub] : subs_) s.pending_wires += sub.pending_wire ? 1 : 0;
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

    struct Subscription {
        SubKind kind = SubKind::event;
        bool may_write = true;  // auth: gateway allows `write` on the member
        bool binary = false;    // "binary": true: values with numeric arrays go as binary pushes
        std::shared_ptr<const MemberTarget> target;  // shared: every push takes it, copying no strings
        std::shared_ptr<SessionEndpoints> own;  // made on this socket's device_login session; null: the shared one
        std::uint64_t mirror_id = 0;  // DeviceMirror subscription id, internal pipe id, or `own`'s id
        bool mirror_known = false;
        bool active = false;  // subscribe answered: pushes may go
        bool failed = false;  // subscribe failed before mirror_id was known
        SharedEntryPtr pending_wire;  // newest value not yet sent
        std::uint64_t dropped = 0;  // pushes dropped since the last one sent
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

    // An asynchronous request: counted until answered.
    bool begin_request(const nlohmann::json& id) {
        {
            std::lock_guard lock(mutex_);
            if (in_flight_ < options_.max_in_flight) {
                ++in_flight_;
                return true;
            }
        }
        send_reply(id, ApiResult::failed(api_error(400, MessageErrorType::BufferLimitViolation,
                                                   "more than " + std::to_string(options_.max_in_flight) +
                                                       " requests in flight on this socket")));
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

    static std::optional<ApiError> read_address(const nlohmann::json& msg, MemberAddress& a) {
        auto d = msg.find("device");
        auto m = msg.find("member");
        if (d == msg.end() || !d->is_string() || m == msg.end() || !m->is_string())
            return bad_request("\"device\" and \"member\" (strings) are required");
        a.device = d->get<std::string>();
        a.member = m->get<std::string>();
        if (auto o = msg.find("object"); o != msg.end() && !o->is_null()) {
            if (!o->is_string()) return bad_request("\"object\" must be a string (a relative service path)");
            a.object = o->get<std::string>();
        }
        return std::nullopt;
    }

    static std::optional<ApiError> read_subscription(const nlohmann::json& msg, std::uint64_t& sid) {
        auto s = msg.find("subscription");
        if (s == msg.end() || !s->is_number_unsigned()) return bad_request("\"subscription\" (a subscription id) is required");
        sid = s->get<std::uint64_t>();
        return std::nullopt;
    }

    void handle(const nlohmann::json& id, const nlohmann::json& msg) {
        auto op_it = msg.find("op");
        if (op_it == msg.end() || !op_it->is_string())
            return send_reply(id, ApiResult::failed(bad_request("a request needs an \"op\" (string)")));
        const std::string op = op_it->get<std::string>();
        auto fail_with = [&](ApiError e) { send_reply(id, ApiResult::failed(std::move(e))); };

        // auth: gateway — logged in by the upgrade's cookie, or by a first {"op": "login"} message.
        if (const auto& a = api_->auth(); a && a->enabled()) {
            if (op == "login") return login(id, msg, *a);
            if (needs_login())
                return fail_with(api_error(401, MessageErrorType::AuthenticationError,
                                           "login required: send {\"op\": \"login\", \"username\", \"password\"} or "
                                           "{\"op\": \"login\", \"token\"} first"));
        }

        if (op == "device_login") return device_login(id, msg);
        if (op == "device_logout") return device_logout(id, msg);
        if (op == "devices") return send_reply(id, ApiResult::ok(api_->device_list()));
        if (op == "device") {
            auto d = msg.find("device");
            if (d == msg.end() || !d->is_string()) return fail_with(bad_request("\"device\" (string) is required"));
            return send_reply(id, api_->device_info(d->get<std::string>()));
        }
        if (op == "unsubscribe") {
            std::uint64_t sid = 0;
            if (auto e = read_subscription(msg, sid)) return fail_with(*e);
            return unsubscribe(id, sid);
        }
        if (op == "set_out_value" || op == "send") {
            std::uint64_t sid = 0;
            if (auto e = read_subscription(msg, sid)) return fail_with(*e);
            auto v = msg.find("value");
            if (v == msg.end()) return fail_with(bad_request("\"value\" is required"));
            if (op == "set_out_value") return set_out_value(id, sid, *v);
            bool ack = false;
            if (auto a = msg.find("requestack"); a != msg.end()) {
                if (!a->is_boolean()) return fail_with(bad_request("\"requestack\" must be true or false"));
                ack = a->get<bool>();
            }
            return send_packet(id, sid, *v, ack);
        }
        if (op != "get" && op != "set" && op != "call" && op != "peek" && op != "subscribe")
            return fail_with(bad_request("unknown op \"" + op + "\""));

        MemberAddress address;
        if (auto e = read_address(msg, address)) return fail_with(*e);
        address.principal = principal();
        address.device_session = device_session(address.device);
        nlohmann::json value, args;
        std::size_t max_items = 0;
        if (op == "set") {
            auto v = msg.find("value");
            if (v == msg.end()) return fail_with(bad_request("\"value\" is required"));
            value = *v;
        }
        if (op == "call") {
            if (auto a = msg.find("args"); a != msg.end()) args = *a;
            if (auto m = msg.find("max_items"); m != msg.end()) {
                if (!m->is_number_unsigned()) return fail_with(bad_request("\"max_items\" must be a non-negative integer"));
                max_items = m->get<std::size_t>();
            }
        }
        bool binary = false;
        if (op == "subscribe") {
            if (auto b = msg.find("binary"); b != msg.end()) {
                if (!b->is_boolean()) return fail_with(bad_request("\"binary\" must be true or false"));
                binary = b->get<bool>();
            }
        }
        if (!begin_request(id)) return;
        if (op == "get") return api_->get_property(address, replier(id));
        if (op == "set") return api_->set_property(address, value, replier(id));
        if (op == "call") return api_->call_function(address, args, max_items, replier(id));
        if (op == "peek") return api_->peek_wire(address, replier(id));
        subscribe(id, std::move(address), binary);
    }

    // --- subscriptions ----------------------------------------------------------------------------

    void subscribe(const nlohmann::json& id, MemberAddress address, bool binary) {
        // Receiving (wire values, events, pipe packets) needs `read`; sending on the subscription
        // (set_out_value, send) needs `write`, decided here once.
        if (auto denied = api_->check_access(address, auth::Operation::read)) {
            send_reply(id, ApiResult::failed(std::move(*denied)));
            return end_request();
        }
        const bool may_write = !api_->check_access(address, auth::Operation::write).has_value();
        auto self = shared_from_this();
        api_->resolve(address, [self, id, may_write, binary](Resolved r) {
            if (auto* e = std::get_if<ApiError>(&r)) {
                self->send_reply(id, ApiResult::failed(*e));
                return self->end_request();
            }
            self->start_subscription(id, std::get<MemberTarget>(std::move(r)), may_write, binary);
        });
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

    void login(const nlohmann::json& id, const nlohmann::json& msg, auth::GatewayAuth& a) {
        auto u = msg.find("username");
        auto p = msg.find("password");
        auto t = msg.find("token");
        Result<auth::PrincipalPtr> who = fail(MessageErrorType::AuthenticationError, "Invalid username or password");
        if (u != msg.end() && u->is_string() && p != msg.end() && p->is_string()) {
            who = a.login_password(u->get<std::string>(), p->get<std::string>(), socket_->peer(), auth::LoginChannel::websocket);
        } else if (t != msg.end() && t->is_string()) {
            who = a.login_token(t->get<std::string>(), socket_->peer(), auth::LoginChannel::websocket);
        } else {
            return send_reply(id, ApiResult::failed(bad_request("login takes \"username\" and \"password\", or \"token\"")));
        }
        if (!who) return send_reply(id, ApiResult::failed(auth::login_error(who.error())));
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

    // {"op": "device_login", "device", "username", "password"}: from now on this socket's get, set,
    // call and peek on the device go on a session of its own, logged in to the device as that user.
    void device_login(const nlohmann::json& id, const nlohmann::json& msg) {
        auto d = msg.find("device");
        auto u = msg.find("username");
        auto p = msg.find("password");
        if (d == msg.end() || !d->is_string() || u == msg.end() || !u->is_string() || u->get_ref<const std::string&>().empty() ||
            (p != msg.end() && !p->is_string()))
            return send_reply(id, ApiResult::failed(bad_request(
                                      "device_login takes \"device\", \"username\" (non-empty strings) and \"password\" (string)")));
        const std::string name = d->get<std::string>();
        auto device = api_->find_device(name);
        if (!device)
            return send_reply(id, ApiResult::failed(api_error(404, MessageErrorType::ServiceNotFound, "no device named \"" + name + "\"")));
        if (device->config().auth != DeviceAuth::passthrough)
            return send_reply(id, ApiResult::failed(api_error(
                                      400, MessageErrorType::InvalidOperation,
                                      "device \"" + name + "\" is auth: shared: every client uses the gateway's own login to it; "
                                      "device_login needs auth: passthrough")));
        if (!begin_request(id)) return;
        std::string username = u->get<std::string>();
        std::string password = p == msg.end() ? std::string() : p->get<std::string>();
        auto self = shared_from_this();
        std::weak_ptr<DeviceMirror> weak_device = device;
        device->open_api_session(username, std::move(password), [self, id, name, username, weak_device](Result<DeviceMirror::ApiSession> r) {
            if (!r) {
                self->send_reply(id, ApiResult::failed(device_error(r.error())));
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

    // {"op": "device_logout", "device"}: back to the gateway's shared session (the device releases this
    // socket's client locks and monitors).
    void device_logout(const nlohmann::json& id, const nlohmann::json& msg) {
        auto d = msg.find("device");
        if (d == msg.end() || !d->is_string()) return send_reply(id, ApiResult::failed(bad_request("\"device\" (string) is required")));
        std::optional<DeviceLogin> login;
        {
            std::lock_guard lock(mutex_);
            if (auto it = device_logins_.find(d->get_ref<const std::string&>()); it != device_logins_.end()) {
                login = it->second;
                device_logins_.erase(it);
            }
        }
        if (!login)
            return send_reply(id, ApiResult::failed(bad_request("this socket has no device_login for \"" + d->get<std::string>() + "\"")));
        end_device_login(*login, "device_logout ended the session it was made on");
        send_reply(id, ApiResult::ok(nlohmann::json::object()));
    }

    // Closes a device login's session; its subscriptions end, each with a "closed" push naming `why`
    // (none when the socket itself is closing: `why` empty).
    void end_device_login(const DeviceLogin& login, const std::string& why = {}) {
        std::vector<std::uint64_t> ended;
        {
            std::lock_guard lock(mutex_);
            for (auto it = subs_.begin(); it != subs_.end();) {
                if (it->second.own != login.endpoints) {
                    ++it;
                    continue;
                }
                if (it->second.active && !closed_ && !why.empty()) ended.push_back(it->first);
                it = subs_.erase(it);
            }
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

    void start_subscription(const nlohmann::json& id, MemberTarget t, bool may_write, bool binary) {
        SubKind kind;
        switch (t.member->kind) {
            case robdef::MemberKind::wire: kind = SubKind::wire; break;
            case robdef::MemberKind::event: kind = SubKind::event; break;
            case robdef::MemberKind::pipe: kind = SubKind::pipe; break;
            default:
                send_reply(id, ApiResult::failed(api_error(404, MessageErrorType::MemberNotFound,
                                                           "member \"" + t.member->name + "\" is " +
                                                               robdef::with_article(robdef::member_kind_keyword(t.member->kind)) +
                                                               "; subscribe takes a wire, an event or a pipe")));
                return end_request();
        }
        // Opening a wire connection or a pipe endpoint is a request the locks held at the gateway
        // decide; events reach every client in RR, locked or not.
        if (kind != SubKind::event) {
            if (auto locked = api_->check_locks(t, kind == SubKind::wire ? MessageEntryType::WireConnectReq
                                                                        : MessageEntryType::PipeConnectReq)) {
                send_reply(id, ApiResult::failed(std::move(*locked)));
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
            if (subs_.size() >= options_.max_subscriptions) {
                if (in_flight_) --in_flight_;
                send_reply(id, ApiResult::failed(api_error(400, MessageErrorType::BufferLimitViolation,
                                                           "more than " + std::to_string(options_.max_subscriptions) +
                                                               " subscriptions on this socket")));
                return;
            }
            sid = next_sid_++;
            Subscription s;
            s.kind = kind;
            s.may_write = may_write;
            s.binary = binary;
            s.target = std::make_shared<const MemberTarget>(t);
            s.own = own_endpoints(t.device->config().name);
            own = s.own;
            subs_.emplace(sid, std::move(s));
        }
        std::weak_ptr<JsonSocketSession> weak = weak_from_this();
        if (own) return start_own_subscription(id, sid, kind, t, own);

        if (kind == SubKind::pipe) {
            auto svc = t.device->mirror_service();
            const bool unreliable = robdef::pipe_is_unreliable(*t.object, *t.member);
            std::weak_ptr<MirrorService> weak_svc = svc;
            svc->open_internal_pipe(t.path, t.member->name, unreliable, pipe_handlers(sid),
                                    [weak, sid, id, weak_svc](Result<std::uint64_t> r) {
                                        auto close = [weak_svc](std::uint64_t pipe) {
                                            if (auto svc = weak_svc.lock()) svc->close_internal_pipe(pipe);
                                        };
                                        auto s = weak.lock();
                                        if (!s) {
                                            if (r) close(*r);
                                            return;
                                        }
                                        s->endpoint_opened(sid, id, std::move(r), close);
                                    });
            return;
        }

        const bool is_wire = kind == SubKind::wire;
        const std::uint64_t mid = t.device->subscribe(
            t.path, t.member->name, is_wire, value_handler(sid, is_wire),
            [weak, sid, id](Result<void> r) {
                if (auto s = weak.lock()) s->subscribed(sid, id, r ? std::nullopt : std::optional(device_error(r.error())));
            });
        bool drop = false;
        {
            // `subscribed` may have run already (inside subscribe), or the socket closed meanwhile.
            std::lock_guard lock(mutex_);
            auto it = subs_.find(sid);
            if (it == subs_.end()) {
                drop = true;
            } else if (it->second.failed) {
                subs_.erase(it);
                drop = true;
            } else {
                it->second.mirror_id = mid;
                it->second.mirror_known = true;
            }
        }
        if (drop) t.device->unsubscribe(mid);
    }

    void subscribed(std::uint64_t sid, const nlohmann::json& id, std::optional<ApiError> error) {
        std::optional<std::pair<MemberTarget, std::uint64_t>> unsubscribe;
        bool flush = false;
        {
            std::lock_guard lock(mutex_);
            if (in_flight_) --in_flight_;
            auto it = subs_.find(sid);
            if (it == subs_.end()) {
                if (!closed_) send_reply(id, ApiResult::failed(api_error(503, MessageErrorType::OperationAborted, "subscription ended")));
                return;
            }
            if (error) {
                if (it->second.mirror_known) {
                    unsubscribe.emplace(*it->second.target, it->second.mirror_id);
                    subs_.erase(it);
                } else {
                    it->second.failed = true;
                }
                send_reply(id, ApiResult::failed(*error));
            } else {
                // Under the lock: the reply is queued before any push of this subscription.
                send_reply(id, ApiResult::ok(nlohmann::json{{"subscription", sid}, {"kind", kind_name(it->second.kind)}}));
                it->second.active = true;
                flush = it->second.pending_wire != nullptr;
            }
        }
        if (unsubscribe) unsubscribe->first.device->unsubscribe(unsubscribe->second);
        if (flush) flush_wires();
    }

    // What a wire or event subscription's values go to (either session).
    std::function<void(const SharedEntryPtr&)> value_handler(std::uint64_t sid, bool is_wire) {
        std::weak_ptr<JsonSocketSession> weak = weak_from_this();
        return [weak, sid, is_wire](const SharedEntryPtr& e) {
            auto s = weak.lock();
            if (!s) return;
            if (is_wire)
                s->on_wire(sid, e);
            else
                s->on_event(sid, e);
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

    // A subscription on this socket's own session to a passthrough device (device_login): the
    // device's privileges and locks for that user apply to what it receives and sends.
    void start_own_subscription(const nlohmann::json& id, std::uint64_t sid, SubKind kind, const MemberTarget& t,
                                const std::shared_ptr<SessionEndpoints>& own) {
        std::weak_ptr<JsonSocketSession> weak = weak_from_this();
        std::weak_ptr<SessionEndpoints> weak_own = own;
        auto opened = [weak, sid, id, weak_own, kind](Result<std::uint64_t> r) {
            auto close = [weak_own, kind](std::uint64_t x) {
                auto o = weak_own.lock();
                if (!o) return;
                if (kind == SubKind::pipe)
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
        if (kind == SubKind::pipe) {
            own->open_pipe(t.path, t.member->name, robdef::pipe_is_unreliable(*t.object, *t.member), pipe_handlers(sid),
                           std::move(opened));
            return;
        }
        SubscriptionHandlers h;
        h.on_entry = value_handler(sid, kind == SubKind::wire);
        h.on_closed = [weak, sid](const RRError& reason) {
            if (auto s = weak.lock()) s->on_subscription_closed(sid, reason);
        };
        own->subscribe(t.path, t.member->name, kind == SubKind::wire, std::move(h), std::move(opened));
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
            auto it = subs_.find(sid);
            if (it == subs_.end()) {
                if (r) orphan = *r;  // the socket closed while connecting
                if (!closed_) send_reply(id, ApiResult::failed(api_error(503, MessageErrorType::OperationAborted, "subscription ended")));
            } else if (!r) {
                subs_.erase(it);
                send_reply(id, ApiResult::failed(device_error(r.error())));
            } else {
                it->second.mirror_id = *r;
                it->second.mirror_known = true;
                // Under the lock: the reply is queued before any push of this subscription.
                send_reply(id, ApiResult::ok(nlohmann::json{{"subscription", sid}, {"kind", kind_name(it->second.kind)}}));
                it->second.active = true;
                flush = it->second.pending_wire != nullptr;
            }
        }
        if (orphan) close(*orphan);
        if (flush) flush_wires();
    }

    void unsubscribe_upstream(const Subscription& s) {
        if (s.own) {
            if (s.kind == SubKind::pipe)
                s.own->close_pipe(s.mirror_id);
            else
                s.own->unsubscribe(s.mirror_id);
        } else if (s.kind == SubKind::pipe) {
            s.target->device->mirror_service()->close_internal_pipe(s.mirror_id);
        } else {
            s.target->device->unsubscribe(s.mirror_id);
        }
    }

    void unsubscribe(const nlohmann::json& id, std::uint64_t sid) {
        std::optional<Subscription> sub;
        {
            std::lock_guard lock(mutex_);
            auto it = subs_.find(sid);
            if (it != subs_.end() && it->second.active) {
                sub = std::move(it->second);
                subs_.erase(it);
            }
        }
        if (!sub) return send_reply(id, ApiResult::failed(bad_request("no subscription " + std::to_string(sid))));
        if (sub->mirror_known) unsubscribe_upstream(*sub);
        send_reply(id, ApiResult::ok(nlohmann::json::object()));
    }

    // Finds an active subscription of `kind` and copies its target.
    std::optional<ApiError> find_active(std::uint64_t sid, SubKind kind, MemberTarget& t, std::uint64_t& mirror_id,
                                        std::shared_ptr<SessionEndpoints>& own) {
        std::lock_guard lock(mutex_);
        auto it = subs_.find(sid);
        if (it == subs_.end() || !it->second.active) return bad_request("no subscription " + std::to_string(sid));
        if (it->second.kind != kind)
            return bad_request("subscription " + std::to_string(sid) + " is " + robdef::with_article(kind_name(it->second.kind)) +
                               " subscription, not " + robdef::with_article(kind_name(kind)));
        t = *it->second.target;
        mirror_id = it->second.mirror_id;
        own = it->second.own;
        return std::nullopt;
    }

    bool may_write(std::uint64_t sid) const {
        std::lock_guard lock(mutex_);
        auto it = subs_.find(sid);
        return it != subs_.end() && it->second.may_write;
    }

    void set_out_value(const nlohmann::json& id, std::uint64_t sid, const nlohmann::json& value) {
        MemberTarget t;
        std::uint64_t mid = 0;
        std::shared_ptr<SessionEndpoints> own;
        if (auto e = find_active(sid, SubKind::wire, t, mid, own)) return send_reply(id, ApiResult::failed(*e));
        if (!may_write(sid)) {
            if (auto a = api_->auth()) a->counters().denied.fetch_add(1);
            return send_reply(id, ApiResult::failed(api_error(403, MessageErrorType::PermissionDenied,
                                                              "this login may not write " + t.member->name)));
        }
        if (t.member->direction() == robdef::MemberDirection::readonly)
            return send_reply(id, ApiResult::failed(api_error(405, MessageErrorType::ReadOnlyMember,
                                                              "wire \"" + t.member->name + "\" is read-only")));
        ApiError error;
        auto packet = api_->element_from_json(value, t.member->type, t, "packet", error, "value");
        if (!packet) return send_reply(id, ApiResult::failed(error));
        // A client's OutValue is the device's InValue (wire.md §6.7: WirePacket, newest wins).
        MessageEntry e;
        e.entry_type = MessageEntryType::WirePacket;
        e.member_name = t.member->name;
        e.metadata = "unreliable\n";
        e.elements.push_back(pack_timespec(wall_clock_timespec(), "packettime"));
        e.elements.push_back(std::move(*packet));
        if (own) {
            e.service_path = t.path;
            auto sent = own->send_wire_packet(std::move(e));
            if (!sent) return send_reply(id, ApiResult::failed(device_error(sent.error())));
            return send_reply(id, ApiResult::ok(nlohmann::json::object()));
        }
        auto client = t.device->upstream();
        if (!client)
            return send_reply(id, ApiResult::failed(api_error(503, MessageErrorType::ConnectionError,
                                                              "device \"" + t.device->config().name + "\" is not connected")));
        e.service_path = t.device->mirror_service()->to_upstream(t.path);
        client->send(std::move(e));
        send_reply(id, ApiResult::ok(nlohmann::json::object()));
    }

    void send_packet(const nlohmann::json& id, std::uint64_t sid, const nlohmann::json& value, bool request_ack) {
        MemberTarget t;
        std::uint64_t mid = 0;
        std::shared_ptr<SessionEndpoints> own;
        if (auto e = find_active(sid, SubKind::pipe, t, mid, own)) return send_reply(id, ApiResult::failed(*e));
        if (!may_write(sid)) {
            if (auto a = api_->auth()) a->counters().denied.fetch_add(1);
            return send_reply(id, ApiResult::failed(api_error(403, MessageErrorType::PermissionDenied,
                                                              "this login may not write " + t.member->name)));
        }
        if (t.member->direction() == robdef::MemberDirection::readonly)
            return send_reply(id, ApiResult::failed(api_error(405, MessageErrorType::ReadOnlyMember,
                                                              "pipe \"" + t.member->name + "\" is read-only")));
        ApiError error;
        auto packet = api_->element_from_json(value, t.member->type, t, "packet", error, "value");
        if (!packet) return send_reply(id, ApiResult::failed(error));
        auto n = own ? own->send_pipe_packet(mid, std::move(*packet), request_ack)
                     : t.device->mirror_service()->send_internal_pipe_packet(mid, std::move(*packet), request_ack);
        if (!n) return send_reply(id, ApiResult::failed(device_error(n.error())));
        send_reply(id, ApiResult::ok(nlohmann::json{{"packetnumber", *n}}));
    }

    // --- pushes -----------------------------------------------------------------------------------

    bool push_congested() const {
        return socket_->queued() >= options_.push_queue_limit || socket_->queued_bytes() >= options_.push_bytes_limit;
    }
    bool wire_congested() const {
        return socket_->queued() >= options_.wire_queue_threshold || socket_->queued_bytes() >= options_.wire_bytes_threshold;
    }

    // Takes a push slot for subscription `sid`: false (and counted) when the client is too far behind.
    bool take_push(std::uint64_t sid, std::shared_ptr<const MemberTarget>& t, std::uint64_t& dropped, bool& binary) {
        std::lock_guard lock(mutex_);
        auto it = subs_.find(sid);
        if (it == subs_.end() || !it->second.active || closed_) return false;
        if (push_congested()) {
            ++it->second.dropped;
            ++push_drops_;
            return false;
        }
        t = it->second.target;
        dropped = std::exchange(it->second.dropped, 0);
        binary = it->second.binary;
        return true;
    }

    // A push whose body (a JSON object's text, shared by all subscribers) is `r`: a binary message
    // when it refers to arrays, else text.
    void send_push(std::uint64_t sid, std::string_view kind, std::uint64_t dropped, const SharedEntry::BinaryRendering& r) {
        if (!r.arrays)
            socket_->send(push_text(sid, kind, dropped, r.body));
        else
            socket_->send_binary(binary_push_head(push_text(sid, kind, dropped, r.body)), r.arrays);
    }

    void on_event(std::uint64_t sid, const SharedEntryPtr& e) {
        std::shared_ptr<const MemberTarget> t;
        std::uint64_t dropped = 0;
        bool binary = false;
        if (!take_push(sid, t, dropped, binary)) return;
        if (binary)
            return send_push(sid, "event", dropped, e->rendered_binary([&](const MessageEntry& entry) {
                return render_binary([&](BinaryArrays* b) { return event_body(entry, *t, b); });
            }));
        const std::string& body = e->rendered([&](const MessageEntry& entry) { return json_text(event_body(entry, *t)); });
        socket_->send(push_text(sid, "event", dropped, body));
    }

    // A push body made with numeric arrays set aside (`body(arrays)` returns the JSON object).
    template <class Body>
    static SharedEntry::BinaryRendering render_binary(Body&& body) {
        BinaryArrays arrays;
        nlohmann::json j = body(&arrays);
        if (j.contains("error") || arrays.blobs.empty())  // made before a later part failed: nothing refers to them
            return SharedEntry::BinaryRendering{json_text(j), nullptr};
        return SharedEntry::BinaryRendering{json_text(j), std::make_shared<const std::string>(binary_push_arrays(arrays.blobs))};
    }

    // {"args": {…}} or {"error": …}: the part of an event push every subscriber shares.
    nlohmann::json event_body(const MessageEntry& e, const MemberTarget& t, BinaryArrays* binary = nullptr) const {
        auto args = nlohmann::json::object();
        for (const auto& p : t.member->parameters) {
            const auto* el = e.find(p.name);
            if (!el)
                return {{"error", error_object(api_error(502, MessageErrorType::MessageElementNotFound,
                                                         "event from the device has no \"" + p.name + "\" element"))}};
            auto j = api_->element_json(*el, p, t, binary);
            if (!j) return {{"error", error_object(*j.error)}};
            args[p.name] = std::move(j.value);
        }
        return {{"args", std::move(args)}};
    }

    // {"subscription": sid, "kind": kind[, "dropped": n], …the members of `body`}; `body` is a JSON
    // object's text, rendered once per value for all subscribers.
    static std::string push_text(std::uint64_t sid, std::string_view kind, std::uint64_t dropped,
                                 const std::string& body) {
        std::string out;
        out.reserve(body.size() + 64);
        out += "{\"subscription\":";
        out += std::to_string(sid);
        out += ",\"kind\":\"";
        out += kind;
        out += '"';
        if (dropped) {
            out += ",\"dropped\":";
            out += std::to_string(dropped);
        }
        if (body.size() > 2) {
            out += ',';
            out.append(body, 1, std::string::npos);  // the members and the closing brace
        } else {
            out += '}';
        }
        return out;
    }

    // Runs on the device's strand, which must not wait for a packet's JSON (a camera frame is about
    // 1 MB of text; seconds under ASan): the device's replies to everyone arrive on it. The JSON is made
    // on the server's conversion strand; while this socket's packets waiting there fill its budget
    // (max_pipe_conversions, max_pipe_conversion_bytes), newer packets are dropped and counted.
    void on_pipe_packet(std::uint64_t sid, const MessageElement& packet) {
        std::shared_ptr<const MemberTarget> t;
        std::uint64_t dropped = 0;
        bool binary = false;
        if (!take_push(sid, t, dropped, binary)) return;
        const std::size_t bytes = payload_bytes(packet);
        if (!pipe_budget_.try_acquire(bytes)) {
            std::lock_guard lock(mutex_);
            if (auto it = subs_.find(sid); it != subs_.end()) it->second.dropped += dropped + 1;
            ++push_drops_;
            return;
        }
        boost::asio::post(convert_strand_, [self = shared_from_this(), sid, packet, t = std::move(t), dropped, bytes, binary] {
            self->convert_pipe_packet(sid, packet, *t, dropped, binary);
            self->pipe_budget_.release(bytes);
        });
    }

    // On the conversion strand (packets of one socket stay in order).
    void convert_pipe_packet(std::uint64_t sid, const MessageElement& packet, const MemberTarget& t, std::uint64_t dropped,
                             bool binary) {
        if (!push_allowed(sid)) return;
        nlohmann::json msg{{"subscription", sid}, {"kind", "pipe"}};
        BinaryArrays arrays;
        auto j = api_->element_json(packet, t.member->type, t, binary ? &arrays : nullptr);
        if (j)
            msg["value"] = std::move(j.value);
        else
            msg["error"] = error_object(*j.error);
        if (dropped) msg["dropped"] = dropped;
        auto text = json_text(msg);
        std::shared_ptr<const std::string> tail;
        if (!arrays.blobs.empty()) {
            text = binary_push_head(text);
            tail = std::make_shared<const std::string>(binary_push_arrays(arrays.blobs));
        }
        // Under the lock: never after the subscription's "closed" push or its unsubscribe reply.
        std::lock_guard lock(mutex_);
        if (!push_allowed_locked(sid)) return;
        if (!tail)
            socket_->send(std::move(text));
        else
            socket_->send_binary(std::move(text), std::move(tail));
    }

    bool push_allowed(std::uint64_t sid) const {
        std::lock_guard lock(mutex_);
        return push_allowed_locked(sid);
    }
    bool push_allowed_locked(std::uint64_t sid) const {
        auto it = subs_.find(sid);
        return !closed_ && it != subs_.end() && it->second.active;
    }

    void on_pipe_ack(std::uint64_t sid, std::uint32_t number) {
        std::lock_guard lock(mutex_);
        auto it = subs_.find(sid);
        if (it == subs_.end() || !it->second.active || closed_) return;
        send_text(nlohmann::json{{"subscription", sid}, {"kind", "pipe_ack"}, {"packetnumber", number}});
    }

    void on_subscription_closed(std::uint64_t sid, const RRError& reason) {
        std::lock_guard lock(mutex_);
        auto it = subs_.find(sid);
        if (it == subs_.end()) return;
        const bool active = it->second.active;
        subs_.erase(it);
        if (active && !closed_)
            send_text(nlohmann::json{{"subscription", sid}, {"kind", "closed"}, {"error", error_object(device_error(reason))}});
    }

    void on_wire(std::uint64_t sid, const SharedEntryPtr& e) {
        if (e->entry().entry_type == MessageEntryType::WireClosed) {
            on_subscription_closed(sid, make_error(MessageErrorType::ConnectionError, "wire closed by the device"));
            return;
        }
        {
            std::lock_guard lock(mutex_);
            auto it = subs_.find(sid);
            if (it == subs_.end()) return;
            if (it->second.pending_wire) ++wire_coalesced_;
            it->second.pending_wire = e;  // newest wins
            if (!it->second.active) return;
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
        struct Item {
            std::uint64_t sid;
            SharedEntryPtr entry;
            std::shared_ptr<const MemberTarget> target;
            bool binary;
        };
        std::vector<Item> batch;
        for (;;) {
            batch.clear();
            {
                std::lock_guard lock(mutex_);
                flush_again_ = false;
                if (closed_) {
                    flushing_ = false;
                    return;
                }
                bool waiting = false;
                for (auto& [sid, sub] : subs_) waiting |= sub.active && sub.pending_wire;
                if (!waiting) {
                    flushing_ = false;
                    return;
                }
                if (wire_congested()) {
                    arm_retry();
                    flushing_ = false;
                    return;
                }
                for (auto& [sid, sub] : subs_) {
                    if (!sub.active || !sub.pending_wire) continue;
                    batch.push_back(Item{sid, std::move(sub.pending_wire), sub.target, sub.binary});
                    sub.pending_wire = nullptr;
                }
            }
            for (auto& item : batch) {
                if (item.binary) {
                    send_push(item.sid, "wire", 0, item.entry->rendered_binary([&](const MessageEntry& e) {
                        return render_binary([&](BinaryArrays* b) { return wire_body(e, *item.target, b); });
                    }));
                    continue;
                }
                const std::string& body = item.entry->rendered(
                    [&](const MessageEntry& e) { return json_text(wire_body(e, *item.target)); });
                socket_->send(push_text(item.sid, "wire", 0, body));
            }
            std::lock_guard lock(mutex_);
            if (!flush_again_) {
                flushing_ = false;
                return;
            }
        }
    }

    // {"value": …, "time": …} or {"error": …}: the part of a wire push every subscriber shares.
    nlohmann::json wire_body(const MessageEntry& e, const MemberTarget& t, BinaryArrays* binary = nullptr) const {
        nlohmann::json msg = nlohmann::json::object();
        const auto* p = e.find("packet");
        const auto* ts = e.find("packettime");
        if (!p || !ts) {
            msg["error"] = error_object(api_error(502, MessageErrorType::MessageElementNotFound,
                                                  "WirePacket from the device without packet / packettime"));
            return msg;
        }
        auto time = unpack_timespec(*ts);
        auto j = api_->element_json(*p, t.member->type, t, binary);
        if (!time) {
            msg["error"] = error_object(ApiError{502, time.error().name, time.error().message});
        } else if (!j) {
            msg["error"] = error_object(*j.error);
        } else {
            msg["value"] = std::move(j.value);
            msg["time"] = time_json(time->seconds, time->nanoseconds);
        }
        return msg;
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
    bool timer_armed_ = false, flushing_ = false, flush_again_ = false, closed_ = false;
    std::map<std::uint64_t, Subscription> subs_;
    std::uint64_t next_sid_ = 1;
    auth::PrincipalPtr principal_;  // auth: gateway — who logged this socket in
    std::map<std::string, DeviceLogin, std::less<>> device_logins_;  // by device name
    std::size_t in_flight_ = 0;
    std::uint64_t push_drops_ = 0, wire_coalesced_ = 0;
    ConvertStrand convert_strand_;                  // shared by the server's sockets
    ConversionBudget pipe_budget_;                  // this socket's packets posted there, not yet sent
};

// --- server ---------------------------------------------------------------------------------------

JsonSocketServer::JsonSocketServer(std::shared_ptr<JsonApi> api, boost::asio::any_io_executor executor,
                                   JsonSocketOptions options)
    : api_(std::move(api)), executor_(executor), convert_strand_(boost::asio::make_strand(executor)), options_(options) {}

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
    auto session = std::make_shared<JsonSocketSession>(api_, socket, executor_, convert_strand_, options_);
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
