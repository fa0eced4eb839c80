#include "server/service/object_service.hpp"

#include <algorithm>
#include <atomic>
#include <limits>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>

#include "core/names/service_path.hpp"
#include "core/value/named_type.hpp"
#include "server/service/member_support.hpp"

namespace rr::server {

namespace {

bool valid_service_name(std::string_view name) {
    if (name.empty() || !((name[0] >= 'a' && name[0] <= 'z') || (name[0] >= 'A' && name[0] <= 'Z'))) return false;
    for (char c : name)
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_')) return false;
    return true;
}

bool is_path_char(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

RRError object_not_found(std::string_view path) {
    return make_error(MessageErrorType::ObjectNotFound, "Object not found: " + std::string(path));
}

/// Splits one path segment `name` or `name[encoded]`. Errors: ObjectNotFound.
Result<std::pair<std::string_view, std::string_view>> split_segment(std::string_view seg, bool& has_index) {
    has_index = false;
    std::size_t open = seg.find('[');
    std::string_view name = seg.substr(0, open);
    if (name.empty() || !std::all_of(name.begin(), name.end(), is_path_char)) return fail(object_not_found(seg));
    if (open == std::string_view::npos) return std::make_pair(name, std::string_view());
    if (seg.back() != ']' || seg.size() < open + 3) return fail(object_not_found(seg));
    std::string_view index = seg.substr(open + 1, seg.size() - open - 2);
    for (char c : index)
        if (!is_path_char(c) && c != '%') return fail(object_not_found(seg));
    has_index = true;
    return std::make_pair(name, index);
}

bool param_is_generator(const robdef::MemberDefinition& def) {
    return !def.parameters.empty() && def.parameters.back().container == robdef::ContainerKind::generator;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

Result<std::shared_ptr<ObjectService>> ObjectService::create(std::string name, std::shared_ptr<ServiceObject> root) {
    if (!valid_service_name(name)) return fail(MessageErrorType::InvalidArgument, "invalid service name \"" + name + "\"");
    if (!root) return fail(MessageErrorType::InvalidArgument, "no root object");
    std::shared_ptr<ObjectService> service(new ObjectService(std::move(name), std::move(root)));
    if (auto r = service->root_->bind(service, service->name_); !r) return r.take_error();
    service->objects_.emplace(service->name_, service->root_);
    service->ever_bound_.push_back(service->root_);
    return service;
}

ObjectService::ObjectService(std::string name, std::shared_ptr<ServiceObject> root)
    : name_(std::move(name)), root_(std::move(root)), types_(root_->types()), rng_(std::random_device{}()) {
    attributes_.name = "attributes";
    attributes_.type = DataTypes::dictionary_t;
}

ObjectService::~ObjectService() = default;

Result<void> ObjectService::set_attributes(MapString attributes) {
    robdef::TypeDefinition var;
    var.base = DataTypes::varvalue_t;
    MessageElement e;
    e.name = "attributes";
    e.type = DataTypes::dictionary_t;
    for (const auto& [key, value] : attributes.entries) {
        auto packed = pack_value(value, var, key, types_->set(), {});
        if (!packed) return packed.take_error();
        e.elements.push_back(std::move(*packed));
    }
    std::lock_guard lock(mutex_);
    attributes_ = std::move(e);
    return {};
}

void ObjectService::set_users(PasswordTable users) {
    std::lock_guard lock(mutex_);
    users_ = std::move(users);
}

std::vector<std::string> ObjectService::service_definitions() const {
    return types_->texts_for(root_->type().substr(0, root_->type().rfind('.')));
}

std::optional<std::string> ObjectService::service_definition(std::string_view service_type) const {
    return types_->text(service_type);
}

ObjectTypeInfo ObjectService::root_type() const { return {root_->type(), types_->implements_of(root_->type())}; }

MessageElement ObjectService::attributes() const {
    std::lock_guard lock(mutex_);
    return attributes_;
}

bool ObjectService::requires_authentication() const {
    std::lock_guard lock(mutex_);
    return !users_.empty();
}

Result<void> ObjectService::authenticate(const std::string& username, const MessageElement* credentials) {
    std::lock_guard lock(mutex_);
    if (users_.empty()) return fail(MessageErrorType::AuthenticationError, "Authentication Failed");
    return users_.check(username, credentials);
}

void ObjectService::on_session_open(const SessionRef& session) {
    std::lock_guard lock(mutex_);
    sessions_[session.endpoint()] = session;
}

void ObjectService::on_session_close(const SessionRef& session) {
    std::vector<std::shared_ptr<ServiceObject>> objects;
    std::vector<std::shared_ptr<Generator>> generators;  // destroyed outside the lock
    std::vector<ObjectLocks::MonitorEvent> monitor_events;
    std::vector<std::shared_ptr<ParkedMonitor>> parked;  // destroyed outside the lock
    {
        std::lock_guard lock(mutex_);
        sessions_.erase(session.endpoint());
        const std::string user = session.username();
        bool last_of_user = true;
        for (const auto& [e, s] : sessions_)
            if (!user.empty() && s.username() == user) last_of_user = false;
        locks_.session_closed(session.endpoint(), user, last_of_user);
        locks_.monitor_session_closed(session.endpoint(), std::chrono::steady_clock::now(), monitor_events);
        for (auto it = parked_.begin(); it != parked_.end();) {
            if (it->first.second == session.endpoint()) {
                parked.push_back(std::move(it->second));
                it = parked_.erase(it);
            } else {
                ++it;
            }
        }
        for (auto it = generators_.begin(); it != generators_.end();) {
            if (it->second.session == session.endpoint()) {
                generators.push_back(std::move(it->second.generator));
                it = generators_.erase(it);
            } else {
                ++it;
            }
        }
        for (const auto& [path, obj] : objects_)
            if (std::find(objects.begin(), objects.end(), obj) == objects.end()) objects.push_back(obj);
    }
    for (const auto& obj : objects) obj->session_closed(session);
    deliver_monitor_events(monitor_events);
}

std::vector<SessionRef> ObjectService::sessions() const {
    std::lock_guard lock(mutex_);
    std::vector<SessionRef> out;
    out.reserve(sessions_.size());
    const bool auth = !users_.empty();
    for (const auto& [e, s] : sessions_)
        if (!auth || !s.username().empty()) out.push_back(s);
    return out;
}

Result<std::shared_ptr<ServiceObject>> ObjectService::resolve(const SessionRef& session, const std::string& path) {
    {
        std::lock_guard lock(mutex_);
        if (auto it = objects_.find(path); it != objects_.end()) return it->second;
        if (shut_down_) return fail(object_not_found(path));
    }
    if (path.size() <= name_.size() || path.compare(0, name_.size(), name_) != 0 || path[name_.size()] != '.')
        return fail(object_not_found(path));
    std::shared_ptr<ServiceObject> current = root_;
    std::size_t pos = name_.size();
    while (pos < path.size()) {
        std::size_t next = path.find('.', pos + 1);
        if (next == std::string::npos) next = path.size();
        std::string prefix = path.substr(0, next);
        {
            std::lock_guard lock(mutex_);
            if (auto it = objects_.find(prefix); it != objects_.end()) {
                current = it->second;
                pos = next;
                continue;
            }
        }
        bool has_index = false;
        auto seg = split_segment(std::string_view(path).substr(pos + 1, next - pos - 1), has_index);
        if (!seg) return seg.take_error();
        std::string index;
        if (has_index) {
            auto decoded = decode_service_path_index(seg->second);
            if (!decoded) return fail(object_not_found(path));
            index = std::move(*decoded);
        }
        auto obj = current->resolve_objref(session, seg->first, index, has_index);
        if (!obj) return obj.take_error();
        std::shared_ptr<ServiceObject> resolved = std::move(*obj);
        bool inserted = false;
        {
            std::lock_guard lock(mutex_);
            auto [it, ins] = objects_.try_emplace(prefix, resolved);
            inserted = ins;
            if (!ins) resolved = it->second;  // another client resolved it meanwhile: keep one object per path
            else ever_bound_.push_back(resolved);
        }
        if (inserted) {
            if (auto r = resolved->bind(shared_from_this(), prefix); !r) {
                std::lock_guard lock(mutex_);
                objects_.erase(prefix);
                return r.take_error();
            }
        }
        current = std::move(resolved);
        pos = next;
    }
    return current;
}

void ObjectService::object_type(const SessionRef& session, const std::string& path,
                                std::function<void(Result<ObjectTypeInfo>)> done) {
    auto obj = resolve(session, path);
    if (!obj) {
        done(obj.take_error());
        return;
    }
    done(ObjectTypeInfo{(*obj)->type(), types_->implements_of((*obj)->type())});
}

Result<void> ObjectService::release_path(const std::string& path) {
    if (path == name_) return fail(MessageErrorType::InvalidArgument, "Root object cannot be released");
    std::vector<std::pair<std::string, std::shared_ptr<ServiceObject>>> released;
    std::vector<std::shared_ptr<Generator>> generators;
    std::vector<SessionRef> sessions;
    const std::string below = path + ".";
    {
        std::lock_guard lock(mutex_);
        for (auto it = objects_.begin(); it != objects_.end();) {
            if (it->first == path || it->first.starts_with(below)) {
                released.emplace_back(it->first, std::move(it->second));
                it = objects_.erase(it);
            } else {
                ++it;
            }
        }
        for (auto it = generators_.begin(); it != generators_.end();) {
            if (it->second.path == path || it->second.path.starts_with(below)) {
                generators.push_back(std::move(it->second.generator));
                it = generators_.erase(it);
            } else {
                ++it;
            }
        }
    }
    if (released.empty()) return fail(MessageErrorType::ServiceError, "Unknown service path");
    for (auto& [p, obj] : released) obj->unbind(p);
    for (const auto& s : this->sessions())
        (void)s.send(detail::member_entry(MessageEntryType::ServicePathReleasedReq, path, {}));
    return {};
}

void ObjectService::shutdown() {
    std::vector<std::shared_ptr<ServiceObject>> objects;
    std::unordered_map<std::int32_t, GeneratorEntry> generators;
    std::map<std::pair<std::string, std::uint32_t>, std::shared_ptr<ParkedMonitor>> parked;
    {
        std::lock_guard lock(mutex_);
        shut_down_ = true;
        parked.swap(parked_);
        for (auto& w : ever_bound_)
            if (auto o = w.lock()) objects.push_back(std::move(o));
        ever_bound_.clear();
        objects_.clear();
        generators.swap(generators_);
    }
    for (const auto& o : objects) o->clear_handlers();
}

Result<std::int32_t> ObjectService::add_generator(const SessionRef& session, const std::string& path,
                                                  const std::string& member, std::shared_ptr<Generator> generator) {
    std::vector<std::shared_ptr<Generator>> expired;  // destroyed outside the lock
    std::lock_guard lock(mutex_);
    const auto now = std::chrono::steady_clock::now();
    std::size_t mine = 0;
    for (auto it = generators_.begin(); it != generators_.end();) {
        if (now - it->second.last_access > kGeneratorIdleTimeout) {
            expired.push_back(std::move(it->second.generator));
            it = generators_.erase(it);
            continue;
        }
        if (it->second.session == session.endpoint()) ++mine;
        ++it;
    }
    if (mine >= kMaxGeneratorsPerSession)
        return fail(MessageErrorType::BufferLimitViolation,
                    "too many open generators for this client (" + std::to_string(mine) + ")");
    std::uniform_int_distribution<std::int32_t> dist(0, std::numeric_limits<std::int32_t>::max());
    std::int32_t index = 0;
    do index = dist(rng_);
    while (generators_.count(index));
    generators_.emplace(index, GeneratorEntry{session.endpoint(), path, member, std::move(generator), now});
    return index;
}

void ObjectService::handle_generator_next(const SessionRef& session, MessageEntry&& entry, Responder responder) {
    auto index = detail::require_scalar<std::int32_t>(entry, "index");
    if (!index) {
        responder.fail(index.error());
        return;
    }
    std::shared_ptr<Generator> generator;
    const bool ending = entry.error != MessageErrorType::None;
    {
        std::lock_guard lock(mutex_);
        auto it = generators_.find(*index);
        if (it == generators_.end() || it->second.session != session.endpoint() ||
            it->second.path != entry.service_path || it->second.member != entry.member_name) {
            responder.fail(make_error(MessageErrorType::InvalidOperation, "Invalid generator"));
            return;
        }
        generator = it->second.generator;
        it->second.last_access = std::chrono::steady_clock::now();
        if (ending) generators_.erase(it);
    }
    if (ending) {
        auto r = entry.error == MessageErrorType::StopIteration ? generator->close() : generator->abort();
        if (!r) {
            responder.fail(r.error());
            return;
        }
        MessageEntry reply;
        reply.elements.push_back(make_scalar_element<std::int32_t>("return", 0));
        responder.respond(std::move(reply));
        return;
    }
    auto obj = resolve(session, entry.service_path);
    std::shared_ptr<const detail::MemberInfo> info = obj ? (*obj)->member_info(entry.member_name) : nullptr;
    if (!info) {
        responder.fail(make_error(MessageErrorType::InvalidOperation, "Invalid generator"));
        return;
    }
    std::optional<Value> parameter;
    if (param_is_generator(*info->def)) {
        auto pe = detail::require_element(entry, "parameter");
        if (!pe) {
            responder.fail(pe.error());
            return;
        }
        auto v = detail::unpack_member(*info, **pe, without_container(info->def->parameters.back()));
        if (!v) {
            responder.fail(v.error());
            return;
        }
        parameter = std::move(*v);
    }
    struct Pending {
        Responder responder;
        std::shared_ptr<const detail::MemberInfo> info;
        std::weak_ptr<ObjectService> service;
        std::int32_t index = 0;
        std::atomic<bool> done{false};
    };
    auto pending = std::make_shared<Pending>();
    pending->responder = std::move(responder);
    pending->info = info;
    pending->service = weak_from_this();
    pending->index = *index;
    generator->async_next(std::move(parameter), [pending](Result<Value> r) {
        if (pending->done.exchange(true)) return;
        const auto& def = *pending->info->def;
        Result<MessageElement> e = r ? detail::pack_return(*pending->info, *r,
                                                           def.type.container == robdef::ContainerKind::generator
                                                               ? without_container(def.type)
                                                               : robdef::TypeDefinition{})
                                     : Result<MessageElement>(fail(r.error()));
        if (!e) {
            // Any error ends the generator (StopIteration is the normal end).
            if (auto s = pending->service.lock()) {
                std::shared_ptr<Generator> dropped;
                std::lock_guard lock(s->mutex_);
                if (auto it = s->generators_.find(pending->index); it != s->generators_.end()) {
                    dropped = std::move(it->second.generator);
                    s->generators_.erase(it);
                }
            }
            pending->responder.fail(e.error());
            return;
        }
        MessageEntry reply;
        reply.elements.push_back(std::move(*e));
        pending->responder.respond(std::move(reply));
    });
}

void ObjectService::handle_entry(const SessionRef& session, MessageEntry&& entry, Responder responder) {
    switch (entry.entry_type) {
        case MessageEntryType::ClientSessionOpReq: handle_lock_op(session, std::move(entry), std::move(responder)); return;
        case MessageEntryType::GeneratorNextReq:
            if (auto ok = check_locks(session, entry.service_path, nullptr, entry); !ok) {
                responder.fail(ok.error());
                return;
            }
            handle_generator_next(session, std::move(entry), std::move(responder));
            return;
        case MessageEntryType::PropertyGetReq:
        case MessageEntryType::PropertySetReq:
        case MessageEntryType::FunctionCallReq:
        case MessageEntryType::PipeConnectReq:
        case MessageEntryType::PipeDisconnectReq:
        case MessageEntryType::PipePacket:
        case MessageEntryType::PipePacketRet:
        case MessageEntryType::WirePacket:
        case MessageEntryType::WireConnectReq:
        case MessageEntryType::WireDisconnectReq:
        case MessageEntryType::WirePeekInValueReq:
        case MessageEntryType::WirePeekOutValueReq:
        case MessageEntryType::WirePokeOutValueReq:
        case MessageEntryType::MemoryRead:
        case MessageEntryType::MemoryWrite:
        case MessageEntryType::MemoryGetParam: break;
        default: responder.fail(make_error(MessageErrorType::ProtocolError, "Unknown request type")); return;
    }
    auto obj = resolve(session, entry.service_path);
    if (!obj) {
        responder.fail(obj.error());  // packets have an empty responder: nothing is sent
        return;
    }
    const bool packet = entry.entry_type == MessageEntryType::PipePacket || entry.entry_type == MessageEntryType::PipePacketRet ||
                        entry.entry_type == MessageEntryType::WirePacket;
    if (!packet) {
        // CORE checks locks on member requests only (ServerContext::check_lock), not on packets.
        if (auto ok = check_locks(session, entry.service_path, obj->get(), entry); !ok) {
            responder.fail(ok.error());
            return;
        }
    }
    (*obj)->handle_entry(*this, session, std::move(entry), std::move(responder));
}

// --- locks -----------------------------------------------------------------------------------

struct ObjectService::ParkedMonitor {
    Responder responder;
    std::unique_ptr<boost::asio::steady_timer> timer;
};

void ObjectService::attach(boost::asio::io_context& io) {
    std::lock_guard lock(mutex_);
    io_ = &io;
}

std::optional<ObjectLocks::Holder> ObjectService::lock_holder(const std::string& path) const {
    std::lock_guard lock(mutex_);
    return locks_.holder(path);
}

bool ObjectService::has_privilege(const std::string& username, std::string_view privilege) const {
    for (const auto& u : users_.users())
        if (u.username == username)
            return std::find(u.privileges.begin(), u.privileges.end(), privilege) != u.privileges.end();
    return false;
}

Result<void> ObjectService::check_locks(const SessionRef& session, const std::string& path, const ServiceObject* obj,
                                        const MessageEntry& entry) {
    // Members marked [nolock] pass object locks; [nolockread] lets property reads and memory reads
    // pass (CORE: generated skels' IsRequestNoLock). Monitor locks apply to every member.
    bool nolock = false;
    if (obj) {
        if (auto info = obj->member_info(entry.member_name); info && info->def) {
            for (const auto& m : info->def->modifiers) {
                if (m == "nolock") nolock = true;
                if (m == "nolockread" &&
                    (entry.entry_type == MessageEntryType::PropertyGetReq || entry.entry_type == MessageEntryType::MemoryRead ||
                     entry.entry_type == MessageEntryType::MemoryGetParam))
                    nolock = true;
            }
        }
    }
    std::vector<ObjectLocks::MonitorEvent> events;
    Result<void> r;
    const std::string username = session.username();
    {
        std::lock_guard lock(mutex_);
        r = locks_.monitor_check(path, session.endpoint(), std::chrono::steady_clock::now(), events);
        if (r && !nolock) r = locks_.check(path, username, session.endpoint());
    }
    deliver_monitor_events(events);
    return r;
}

void ObjectService::handle_lock_op(const SessionRef& session, MessageEntry&& entry, Responder responder) {
    const std::string op = entry.member_name;
    const std::string path = entry.service_path;
    const std::uint32_t endpoint = session.endpoint();
    const bool monitor = op.rfind("Monitor", 0) == 0;
    const std::string username = session.username();
    bool override_ = false;
    if (!monitor) {
        // CORE ServerContext::ClientLockOp: object locks need a user with a locking privilege.
        if (username.empty()) {
            responder.fail(make_error(MessageErrorType::PermissionDenied, "User must be authenticated to lock object"));
            return;
        }
        std::lock_guard lock(mutex_);
        override_ = has_privilege(username, "objectlockoverride");
        if (!override_ && !has_privilege(username, "objectlock")) {
            responder.fail(make_error(MessageErrorType::ObjectLockedError, "User does not have object locking privileges"));
            return;
        }
    }
    if (auto obj = resolve(session, path); !obj) {
        responder.fail(obj.error());
        return;
    }
    auto ok_reply = [&responder](const char* text) {
        MessageEntry r;
        r.elements.push_back(make_string_element("return", text));
        responder.respond(std::move(r));
    };
    std::vector<ObjectLocks::MonitorEvent> events;
    const auto now = std::chrono::steady_clock::now();
    if (op == "RequestObjectLock" || op == "RequestClientObjectLock" || op == "ReleaseObjectLock") {
        Result<void> r;
        {
            std::lock_guard lock(mutex_);
            if (op == "ReleaseObjectLock") r = locks_.release(path, username, endpoint, override_);
            else r = locks_.lock(path, username, op == "RequestClientObjectLock" ? endpoint : 0);
        }
        if (!r) responder.fail(r.error());
        else ok_reply("OK");
        return;
    }
    if (op == "MonitorEnter") {
        const MessageElement* t = entry.find("timeout");
        std::int32_t timeout = -1;
        if (!t || !read_scalar(*t, timeout)) {
            responder.fail(make_error(MessageErrorType::InvalidArgument, "MonitorEnter needs an int32 \"timeout\""));
            return;
        }
        Result<bool> r = false;
        {
            std::lock_guard lock(mutex_);
            r = locks_.monitor_enter(path, endpoint, timeout, now, events);
        }
        deliver_monitor_events(events);
        if (!r) responder.fail(r.error());
        else if (*r) ok_reply("OK");
        else {
            auto wait = std::chrono::duration_cast<std::chrono::milliseconds>(kMonitorWait);
            if (timeout >= 0 && std::chrono::milliseconds(timeout) + std::chrono::milliseconds(1) < wait)
                wait = std::chrono::milliseconds(timeout) + std::chrono::milliseconds(1);
            park_monitor(path, endpoint, std::move(responder), wait);
        }
        return;
    }
    if (op == "MonitorContinueEnter") {
        Result<bool> r = false;
        {
            std::lock_guard lock(mutex_);
            r = locks_.monitor_continue(path, endpoint, now, events);
        }
        deliver_monitor_events(events);
        if (!r) responder.fail(r.error());
        else if (*r) ok_reply("OK");
        else park_monitor(path, endpoint, std::move(responder), std::chrono::duration_cast<std::chrono::milliseconds>(kMonitorWait));
        return;
    }
    if (op == "MonitorExit") {
        Result<void> r;
        {
            std::lock_guard lock(mutex_);
            r = locks_.monitor_exit(path, endpoint, now, events);
        }
        deliver_monitor_events(events);
        if (!r) responder.fail(r.error());
        else ok_reply("OK");
        return;
    }
    // ReleaseClientObjectLock is a known command name that CORE's ClientLockOp answers this way.
    responder.fail(make_error(MessageErrorType::InvalidOperation, "Invalid command"));
}

void ObjectService::park_monitor(const std::string& path, std::uint32_t endpoint, Responder responder,
                                 std::chrono::milliseconds wait) {
    auto parked = std::make_shared<ParkedMonitor>();
    parked->responder = std::move(responder);
    std::shared_ptr<ParkedMonitor> replaced;
    bool granted_meanwhile = false;
    {
        std::lock_guard lock(mutex_);
        // Handed over between monitor_enter/continue and now (its event found nothing parked).
        granted_meanwhile = locks_.monitor_holder(path) == endpoint;
        if (io_ && !shut_down_ && !granted_meanwhile) {
            parked->timer = std::make_unique<boost::asio::steady_timer>(*io_, wait);
            replaced = std::move(parked_[{path, endpoint}]);
            parked_[{path, endpoint}] = parked;
        }
    }
    if (replaced && !replaced->responder.done()) {
        MessageEntry r;
        r.elements.push_back(make_string_element("return", "Continue"));
        replaced->responder.respond(std::move(r));
    }
    if (!parked->timer) {  // no io_context: the client asks again at once
        MessageEntry r;
        r.elements.push_back(make_string_element("return", granted_meanwhile ? "OK" : "Continue"));
        parked->responder.respond(std::move(r));
        return;
    }
    std::weak_ptr<ObjectService> weak = weak_from_this();
    std::weak_ptr<ParkedMonitor> weak_parked = parked;
    parked->timer->async_wait([weak, weak_parked, path, endpoint](const boost::system::error_code& ec) {
        if (ec) return;
        auto self = weak.lock();
        if (!self) return;
        std::vector<ObjectLocks::MonitorEvent> events;
        std::shared_ptr<ParkedMonitor> mine;
        {
            std::lock_guard lock(self->mutex_);
            self->locks_.monitor_poll(std::chrono::steady_clock::now(), events);
        }
        self->deliver_monitor_events(events);  // may answer this request "OK" or RequestTimeout
        {
            std::lock_guard lock(self->mutex_);
            auto it = self->parked_.find({path, endpoint});
            if (it != self->parked_.end() && it->second == weak_parked.lock()) {
                mine = std::move(it->second);
                self->parked_.erase(it);
            }
        }
        if (mine && !mine->responder.done()) {
            MessageEntry r;
            r.elements.push_back(make_string_element("return", "Continue"));
            mine->responder.respond(std::move(r));
        }
    });
}

void ObjectService::deliver_monitor_events(std::vector<ObjectLocks::MonitorEvent>& events) {
    for (const auto& ev : events) {
        std::shared_ptr<ParkedMonitor> p;
        {
            std::lock_guard lock(mutex_);
            auto it = parked_.find({ev.path, ev.endpoint});
            if (it == parked_.end()) continue;  // not parked: its next MonitorContinueEnter learns it
            p = std::move(it->second);
            parked_.erase(it);
        }
        if (p->timer) p->timer->cancel();
        if (p->responder.done()) continue;
        if (ev.granted) {
            MessageEntry r;
            r.elements.push_back(make_string_element("return", "OK"));
            p->responder.respond(std::move(r));
        } else {
            p->responder.fail(make_error(MessageErrorType::RequestTimeout, "Timed out waiting for the monitor lock"));
        }
    }
    events.clear();
}

}  // namespace rr::server
