#include "server/gateway/json_api.hpp"

#include <algorithm>
#include <atomic>

#include "core/json/json_nesting.hpp"
#include "core/json/value_json.hpp"
#include "base/message/error_entry.hpp"
#include "core/session/elements.hpp"
#include "core/value/pack_value.hpp"
#include "core/value/timespec.hpp"
#include "server/gateway/mirror_service.hpp"
#include "server/service/service_locks.hpp"

namespace rr::server::gateway {

namespace {

std::string_view kind_word(robdef::MemberKind k) { return robdef::member_kind_keyword(k); }

}  // namespace

Result<nlohmann::json> parse_request_json(std::string_view text) {
    if (rr::json_limits::nests_deeper_than(text, kMaxRequestJsonDepth))
        return fail(MessageErrorType::InvalidArgument, "JSON nested deeper than " + std::to_string(kMaxRequestJsonDepth) + " levels");
    auto j = nlohmann::json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) return fail(MessageErrorType::InvalidArgument, "the request is not valid JSON");
    return j;
}

nlohmann::json time_json(std::int64_t seconds, std::int32_t nanoseconds) {
    return nlohmann::json{{"seconds", seconds}, {"nanoseconds", nanoseconds}};
}

JsonApi::JsonApi(std::vector<std::shared_ptr<DeviceMirror>> devices, JsonApiOptions options)
    : devices_(std::move(devices)), options_(std::move(options)) {}

std::shared_ptr<DeviceMirror> JsonApi::find_device(std::string_view name) const {
    std::lock_guard lock(mutex_);
    for (const auto& d : devices_)
        if (d->config().name == name) return d;
    return nullptr;
}

std::vector<std::shared_ptr<DeviceMirror>> JsonApi::devices() const {
    std::lock_guard lock(mutex_);
    return devices_;
}

Result<void> JsonApi::add_device(std::shared_ptr<DeviceMirror> device) {
    std::vector<DevicesListener> listeners;
    {
        std::lock_guard lock(mutex_);
        for (const auto& d : devices_)
            if (d->config().name == device->config().name)
                return fail(MessageErrorType::InvalidArgument, "device name \"" + d->config().name + "\" is taken");
        devices_.push_back(device);
        for (const auto& [id, l] : devices_listeners_) listeners.push_back(l);
    }
    for (const auto& l : listeners) l(device, true);
    return {};
}

std::shared_ptr<DeviceMirror> JsonApi::remove_device(std::string_view name) {
    std::shared_ptr<DeviceMirror> removed;
    std::vector<DevicesListener> listeners;
    {
        std::lock_guard lock(mutex_);
        auto it = std::find_if(devices_.begin(), devices_.end(), [&](const auto& d) { return d->config().name == name; });
        if (it == devices_.end()) return nullptr;
        removed = *it;
        devices_.erase(it);
        types_.erase(removed.get());
        for (const auto& [id, l] : devices_listeners_) listeners.push_back(l);
    }
    for (const auto& l : listeners) l(removed, false);
    return removed;
}

std::uint64_t JsonApi::add_devices_listener(DevicesListener listener) {
    std::lock_guard lock(mutex_);
    const auto id = next_devices_listener_++;
    devices_listeners_.emplace(id, std::move(listener));
    return id;
}

void JsonApi::remove_devices_listener(std::uint64_t id) {
    std::lock_guard lock(mutex_);
    devices_listeners_.erase(id);
}

void JsonApi::set_discovery_hooks(DiscoveryHooks hooks) {
    std::lock_guard lock(mutex_);
    discovery_hooks_ = std::move(hooks);
}

JsonApi::DiscoveryHooks JsonApi::discovery_hooks() const {
    std::lock_guard lock(mutex_);
    return discovery_hooks_;
}

nlohmann::json JsonApi::status_json(const DeviceStatus& s) {
    nlohmann::json j;
    j["name"] = s.name;
    j["url"] = s.url;
    j["state"] = std::string(device_state_name(s.state));
    j["reason"] = s.reason.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.reason);
    j["object_type"] = s.object_type.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.object_type);
    j["required"] = s.required;
    j["clients"] = s.downstream_sessions;
    j["auth"] = std::string(device_auth_name(s.auth));
    if (s.auth == DeviceAuth::passthrough) {
        j["passthrough_sessions"] = s.upstream_sessions;
        j["json_api_requires_device_login"] = s.json_api_requires_device_login;
    }
    // Taken through the gateway (passthrough) or held at it (shared); docs/security.md "Who holds a lock".
    auto locks = nlohmann::json::array();
    for (const auto& l : s.locks)
        locks.push_back({{"path", l.path}, {"user", l.username.empty() ? nlohmann::json(nullptr) : nlohmann::json(l.username)},
                         {"kind", l.kind}});
    j["locks"] = std::move(locks);
    return j;
}

nlohmann::json JsonApi::device_list() const {
    auto list = nlohmann::json::array();
    for (const auto& d : devices()) list.push_back(status_json(d->status()));
    return list;
}

std::shared_ptr<const DeviceTypes> JsonApi::types_for(const DeviceMirror& device, ApiError* error) const {
    auto texts = device.service_definitions();
    if (texts.empty()) {
        if (error)
            *error = api_error(503, MessageErrorType::ConnectionError,
                               "device \"" + device.config().name + "\" has not connected yet");
        return nullptr;
    }
    {
        std::lock_guard lock(mutex_);
        auto it = types_.find(&device);
        if (it != types_.end() && it->second->texts() == texts) return it->second;
    }
    auto parsed = DeviceTypes::parse(std::move(texts));
    if (!parsed) {
        if (error)
            *error = ApiError{502, std::string(error_name(MessageErrorType::ServiceDefinitionError)),
                              "device \"" + device.config().name + "\": " + parsed.error().message};
        return nullptr;
    }
    std::lock_guard lock(mutex_);
    types_[&device] = *parsed;
    return *parsed;
}

ApiResult JsonApi::device_info(std::string_view name) const {
    auto d = find_device(name);
    if (!d) return ApiResult::failed(api_error(404, MessageErrorType::ServiceNotFound, "no device named \"" + std::string(name) + "\""));
    const auto status = d->status();
    auto j = status_json(status);
    j["definitions"] = d->service_definitions();
    j["members"] = nlohmann::json::array();
    if (auto types = types_for(*d)) {
        if (auto obj = types->find_object(d->object_type())) j["members"] = member_summary(*obj->entry);
    }
    return ApiResult::ok(std::move(j));
}

ApiResult JsonApi::definitions(std::string_view name) const {
    auto d = find_device(name);
    if (!d) return ApiResult::failed(api_error(404, MessageErrorType::ServiceNotFound, "no device named \"" + std::string(name) + "\""));
    return ApiResult::ok(nlohmann::json{{"definitions", d->service_definitions()}});
}

void JsonApi::resolve(const MemberAddress& address, std::function<void(Resolved)> done) {
    if (address.device_session != 0 || address.principal) {
        done = [session = address.device_session, user = address.principal ? address.principal->rr_user_name() : std::string(),
                inner = std::move(done)](Resolved r) {
            if (auto* t = std::get_if<MemberTarget>(&r)) {
                t->device_session = session;
                t->user = user;
            }
            inner(std::move(r));
        };
    }
    auto device = find_device(address.device);
    if (!device) {
        done(api_error(404, MessageErrorType::ServiceNotFound, "no device named \"" + address.device + "\""));
        return;
    }
    const auto status = device->status();
    if (status.state != DeviceState::connected) {
        done(api_error(503, MessageErrorType::ConnectionError,
                       "device \"" + address.device + "\" is not connected (" + std::string(device_state_name(status.state)) +
                           (status.reason.empty() ? "" : ": " + status.reason) + ")"));
        return;
    }
    ApiError error;
    auto types = types_for(*device, &error);
    if (!types) {
        done(error);
        return;
    }
    if (address.object.empty()) {
        finish_resolve(device, types, address.device, device->object_type(), address.member, done);
        return;
    }
    auto rel = normalize_object_path(address.object);
    if (!rel) {
        done(api_error(400, MessageErrorType::InvalidArgument, rel.error().message));
        return;
    }
    std::string path = address.device + "." + *rel;
    MessageEntry e;
    e.entry_type = MessageEntryType::ObjectTypeName;
    e.service_path = path;
    e.elements.push_back(make_string_element("clientversion", "1.2.8"));
    auto self = shared_from_this();
    device->request(std::move(e), [self, device, types, path, member = address.member,
                                   done = std::move(done)](Result<MessageEntry> r) {
        if (!r) {
            done(device_error(r.error()));
            return;
        }
        if (auto err = entry_error(*r)) {
            done(device_error(*err));
            return;
        }
        const auto* t = r->find("objecttype");
        if (!t || t->type != DataTypes::string_t) {
            done(api_error(502, MessageErrorType::MessageElementNotFound, "ObjectTypeName reply without objecttype"));
            return;
        }
        self->finish_resolve(device, types, path, std::string(read_string(*t)), member, done);
    });
}

void JsonApi::finish_resolve(std::shared_ptr<DeviceMirror> device, std::shared_ptr<const DeviceTypes> types,
                             std::string path, std::string object_type, std::string member,
                             const std::function<void(Resolved)>& done) const {
    auto obj = types->find_object(object_type);
    if (!obj) {
        done(api_error(502, MessageErrorType::ServiceDefinitionError,
                       "object type \"" + object_type + "\" of \"" + path + "\" is not in the device's definitions"));
        return;
    }
    const auto* m = obj->entry->find_member(member);
    if (!m) {
        done(api_error(404, MessageErrorType::MemberNotFound,
                       "object \"" + path + "\" (" + object_type + ") has no member \"" + member + "\""));
        return;
    }
    MemberTarget t;
    t.device = std::move(device);
    t.types = std::move(types);
    t.path = std::move(path);
    t.object_type = std::move(object_type);
    t.service = obj->service;
    t.object = obj->entry;
    t.member = m;
    done(std::move(t));
}

ApiResult JsonApi::element_json(const MessageElement& element, const robdef::TypeDefinition& type,
                                const MemberTarget& t, BinaryArrays* binary) const {
    if (type.is_void()) return ApiResult::ok(nullptr);
    auto v = unpack_value(element, type, t.types->set(), t.context(), options_.limits);
    if (!v) return ApiResult::failed(ApiError{502, v.error().name, "value from the device: " + v.error().message});
    auto j = value_to_json(*v, type, t.types->set(), t.context(), options_.limits, binary);
    if (!j) return ApiResult::failed(ApiError{502, j.error().name, "value from the device: " + j.error().message});
    return ApiResult::ok(std::move(*j));
}

Result<MessageElement> JsonApi::element_from_json(const nlohmann::json& json, const robdef::TypeDefinition& type,
                                                  const MemberTarget& t, std::string_view name, ApiError& error,
                                                  std::string_view where) const {
    auto v = value_from_json(json, type, t.types->set(), t.context(), options_.limits);
    if (!v) {
        error = value_error(v.error(), where);
        return v.take_error();
    }
    auto el = pack_value(*v, type, name, t.types->set(), t.context(), options_.limits);
    if (!el) {
        error = value_error(el.error(), where);
        return el.take_error();
    }
    return el;
}

namespace {

// 404 when the member is of another kind than the request needs.
std::optional<ApiError> expect_kind(const MemberTarget& t, robdef::MemberKind kind) {
    if (t.member->kind == kind) return std::nullopt;
    return api_error(404, MessageErrorType::MemberNotFound,
                     "member \"" + t.member->name + "\" of " + t.object_type + " is " +
                         robdef::with_article(kind_word(t.member->kind)) + ", not " + robdef::with_article(kind_word(kind)));
}

MessageEntry member_request(MessageEntryType type, const MemberTarget& t) {
    MessageEntry e;
    e.entry_type = type;
    e.service_path = t.path;
    e.member_name = t.member->name;
    return e;
}

// Sends `e` to the device; transport errors and error replies end in `done`, a good reply goes to `ok`.
void send_to_device(const MemberTarget& t, MessageEntry e, JsonApi::Done done,
                    std::function<ApiResult(const MessageEntry&)> ok) {
    t.device->request(std::move(e), [done = std::move(done), ok = std::move(ok)](Result<MessageEntry> r) {
        if (!r) return done(ApiResult::failed(device_error(r.error())));
        if (auto err = entry_error(*r)) return done(ApiResult::failed(device_error(*err)));
        done(ok(*r));
    }, t.device_session);
}

ApiError missing_element(std::string_view name, std::string_view reply) {
    return api_error(502, MessageErrorType::MessageElementNotFound,
                     std::string(reply) + " from the device has no \"" + std::string(name) + "\" element");
}

}  // namespace

std::optional<ApiError> JsonApi::check_access(const MemberAddress& a, auth::Operation op) const {
    if (a.device_session == 0) {
        // The device lets JSON API clients in only with a login of its own (an unknown device is left
        // to resolve(), which names it).
        if (auto d = find_device(a.device); d && d->config().json_api_requires_device_login)
            return api_error(401, MessageErrorType::AuthenticationError,
                             "device \"" + a.device +
                                 "\" takes JSON API requests only with a login of its own: send {\"op\": \"device_login\", "
                                 "\"device\", \"username\", \"password\"} on the WebSocket first (REST requests have no device session)");
    }
    if (!auth_ || !auth_->enabled()) return std::nullopt;
    if (!a.principal)
        return api_error(401, MessageErrorType::AuthenticationError, "login required");
    auto object = normalize_object_path(a.object);
    const std::string key = auth::member_key(object ? std::string_view(*object) : std::string_view(a.object), a.member);
    if (a.principal->allows(a.device, key, op)) return std::nullopt;
    auth_->counters().denied.fetch_add(1);
    return api_error(403, MessageErrorType::PermissionDenied,
                     "user " + a.principal->name + " may not " + std::string(auth::operation_name(op)) + " " + key + " of " + a.device);
}

std::variant<JsonApi::MotionAdmission, ApiError> JsonApi::admit_motion(const MemberAddress& address, const MemberTarget& t,
                                                                      MessageEntry& call) {
    MotionAdmission m;
    const auto& guard = t.device->motion();
    if (!guard || !guard->concerns(call)) return m;
    m.guard = guard;
    if (address.motion) {
        m.client = *address.motion;
    } else {
        static std::atomic<std::uint64_t> anonymous{0};
        m.client.key = "api:" + std::to_string(anonymous.fetch_add(1) + 1);
        m.client.description = "a JSON API request";
    }
    m.client.device_session = t.device_session;
    if (address.motion_waits_only && call.entry_type == MessageEntryType::FunctionCallReq) {
        const auto rules = guard->rules();
        const auto* u = rules ? rules->untimed(call.member_name) : nullptr;
        if (u && !u->wait_arg.empty() && !bool_argument(call, u->wait_arg).value_or(false))
            return api_error(409, MessageErrorType::InvalidOperation,
                             call.member_name + " with " + u->wait_arg + " false over plain HTTP would outlive the request, whose " +
                                 "connection is all the gateway can watch: call it with " + u->wait_arg +
                                 " true (the request then lasts until the motion ends, and closing its connection stops the " +
                                 "robot), or from the JSON WebSocket or an RR client (docs/security.md \"Motion safety\")");
    }
    auto ticket = guard->admit(m.client, call);
    if (!ticket)
        return api_error(ticket.error().type == MessageErrorType::InvalidArgument ? 400 : 409, ticket.error().type,
                         ticket.error().message);
    m.stop = ticket->kind == MotionGuard::Ticket::Kind::stop;
    if (ticket->kind != MotionGuard::Ticket::Kind::pass && !m.stop) m.ticket = *ticket;
    return m;
}

void JsonApi::finish_motion(const MotionAdmission& m, const Result<MessageEntry>& reply) {
    if (m.guard && m.ticket) m.guard->on_reply(m.client, *m.ticket, reply);
}

std::optional<ApiError> JsonApi::check_locks(const MemberTarget& t, MessageEntryType type) const {
    if (t.device_session != 0) return std::nullopt;
    auto ok = t.device->mirror_service()->check_api_request(t.path, t.user, passes_object_locks(t.member->modifiers, type));
    if (ok) return std::nullopt;
    return api_error(409, ok.error().type, ok.error().message);
}

void JsonApi::get_property(const MemberAddress& address, Done done) {
    if (auto denied = check_access(address, auth::Operation::read)) return done(ApiResult::failed(std::move(*denied)));
    auto self = shared_from_this();
    resolve(address, [self, done = std::move(done)](Resolved r) {
        if (auto* e = std::get_if<ApiError>(&r)) return done(ApiResult::failed(*e));
        const auto& t = std::get<MemberTarget>(r);
        if (auto e = expect_kind(t, robdef::MemberKind::property)) return done(ApiResult::failed(*e));
        if (t.member->direction() == robdef::MemberDirection::writeonly)
            return done(ApiResult::failed(api_error(405, MessageErrorType::WriteOnlyMember,
                                                    "property \"" + t.member->name + "\" is write-only")));
        if (auto locked = self->check_locks(t, MessageEntryType::PropertyGetReq)) return done(ApiResult::failed(std::move(*locked)));
        send_to_device(t, member_request(MessageEntryType::PropertyGetReq, t), done, [self, t](const MessageEntry& reply) {
            const auto* v = reply.find("value");
            if (!v) return ApiResult::failed(missing_element("value", "PropertyGetRes"));
            auto j = self->element_json(*v, t.member->type, t);
            if (!j) return j;
            return ApiResult::ok(nlohmann::json{{"value", std::move(j.value)}});
        });
    });
}

void JsonApi::set_property(const MemberAddress& address, const nlohmann::json& value, Done done) {
    if (auto denied = check_access(address, auth::Operation::write)) return done(ApiResult::failed(std::move(*denied)));
    auto self = shared_from_this();
    resolve(address, [self, address, value, done = std::move(done)](Resolved r) {
        if (auto* e = std::get_if<ApiError>(&r)) return done(ApiResult::failed(*e));
        const auto& t = std::get<MemberTarget>(r);
        if (auto e = expect_kind(t, robdef::MemberKind::property)) return done(ApiResult::failed(*e));
        if (t.member->direction() == robdef::MemberDirection::readonly)
            return done(ApiResult::failed(api_error(405, MessageErrorType::ReadOnlyMember,
                                                    "property \"" + t.member->name + "\" is read-only")));
        ApiError error;
        auto el = self->element_from_json(value, t.member->type, t, "value", error, "value");
        if (!el) return done(ApiResult::failed(error));
        auto e = member_request(MessageEntryType::PropertySetReq, t);
        e.elements.push_back(std::move(*el));
        // A stop (command_mode = halt) passes every lock (docs/security.md "Motion safety").
        auto motion = admit_motion(address, t, e);
        if (auto* refused = std::get_if<ApiError>(&motion)) return done(ApiResult::failed(std::move(*refused)));
        const bool stop = std::get<MotionAdmission>(motion).stop;
        if (!stop)
            if (auto locked = self->check_locks(t, MessageEntryType::PropertySetReq)) return done(ApiResult::failed(std::move(*locked)));
        if (stop)
            return t.device->request_stop(std::move(e), [done](Result<MessageEntry> r) {
                if (!r) return done(ApiResult::failed(device_error(r.error())));
                if (auto err = entry_error(*r)) return done(ApiResult::failed(device_error(*err)));
                done(ApiResult::ok(nlohmann::json::object()));
            }, t.device_session);
        send_to_device(t, std::move(e), done, [](const MessageEntry&) { return ApiResult::ok(nlohmann::json::object()); });
    });
}

void JsonApi::peek_wire(const MemberAddress& address, Done done) {
    if (auto denied = check_access(address, auth::Operation::read)) return done(ApiResult::failed(std::move(*denied)));
    auto self = shared_from_this();
    resolve(address, [self, done = std::move(done)](Resolved r) {
        if (auto* e = std::get_if<ApiError>(&r)) return done(ApiResult::failed(*e));
        const auto& t = std::get<MemberTarget>(r);
        if (auto e = expect_kind(t, robdef::MemberKind::wire)) return done(ApiResult::failed(*e));
        if (t.member->direction() == robdef::MemberDirection::writeonly)
            return done(ApiResult::failed(api_error(405, MessageErrorType::WriteOnlyMember,
                                                    "wire \"" + t.member->name + "\" is write-only")));
        if (auto locked = self->check_locks(t, MessageEntryType::WirePeekInValueReq)) return done(ApiResult::failed(std::move(*locked)));
        send_to_device(t, member_request(MessageEntryType::WirePeekInValueReq, t), done,
                       [self, t](const MessageEntry& reply) {
                           const auto* p = reply.find("packet");
                           const auto* ts = reply.find("packettime");
                           if (!p) return ApiResult::failed(missing_element("packet", "WirePeekInValueRet"));
                           if (!ts) return ApiResult::failed(missing_element("packettime", "WirePeekInValueRet"));
                           auto time = unpack_timespec(*ts);
                           if (!time) return ApiResult::failed(ApiError{502, time.error().name, time.error().message});
                           auto j = self->element_json(*p, t.member->type, t);
                           if (!j) return j;
                           return ApiResult::ok(nlohmann::json{{"value", std::move(j.value)},
                                                               {"time", time_json(time->seconds, time->nanoseconds)}});
                       });
    });
}

}  // namespace rr::server::gateway
