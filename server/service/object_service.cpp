#include "server/service/object_service.hpp"

#include <algorithm>
#include <atomic>
#include <limits>

#include "base/names/object_path.hpp"
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

RRError object_not_found(std::string_view path) {
    return make_error(MessageErrorType::ObjectNotFound, "Object not found: " + std::string(path));
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
    has_users_.store(!users_.empty(), std::memory_order_release);
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

bool ObjectService::requires_authentication() const { return has_users_.load(std::memory_order_acquire); }

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
    const std::string user = session.username();
    bool last_of_user = true;
    {
        std::lock_guard lock(mutex_);
        sessions_.erase(session.endpoint());
        for (const auto& [e, s] : sessions_)
            if (!user.empty() && s.username() == user) last_of_user = false;
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
    locks_->session_closed(session.endpoint(), user, last_of_user);
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
    // The root, which most requests address, stays bound until shutdown: no lock and no map lookup.
    if (path == name_ && !shut_down_.load(std::memory_order_acquire)) return root_;
    {
        std::lock_guard lock(mutex_);
        if (auto it = objects_.find(path); it != objects_.end()) return it->second;
        if (shut_down_) return fail(object_not_found(path));
    }
    if (path.size() <= name_.size() || path.compare(0, name_.size(), name_) != 0 || path[name_.size()] != '.')
        return fail(object_not_found(path));
    // The objects below the root, segment by segment (base/names/object_path.hpp: indexes in
    // service-path encoding); each prefix is resolved once and kept.
    auto below = parse_object_path(std::string_view(path).substr(name_.size() + 1), ObjectPathIndexes::encoded);
    if (!below) return fail(object_not_found(path));
    std::shared_ptr<ServiceObject> current = root_;
    std::string prefix = name_;
    for (const auto& segment : below->segments) {
        prefix += '.';
        prefix += segment.text();  // the path's own text: indexes kept as given
        {
            std::lock_guard lock(mutex_);
            if (auto it = objects_.find(prefix); it != objects_.end()) {
                current = it->second;
                continue;
            }
        }
        auto obj = current->resolve_objref(session, segment.name, segment.index, segment.has_index);
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
    {
        std::lock_guard lock(mutex_);
        shut_down_ = true;
        for (auto& w : ever_bound_)
            if (auto o = w.lock()) objects.push_back(std::move(o));
        ever_bound_.clear();
        objects_.clear();
        generators.swap(generators_);
    }
    locks_->shutdown();
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
        if (it->second.ended != MessageErrorType::None) {
            // Closed or aborted: official clients expect StopIteration / OperationAborted from a Next
            // that follows (CORE keeps the generator, whose own next() says so); then the index goes.
            const auto ended = it->second.ended;
            if (!ending) {
                generators_.erase(it);
                responder.fail(make_error(ended, ended == MessageErrorType::StopIteration ? "Generator closed"
                                                                                        : "Generator aborted"));
                return;
            }
        } else if (ending) {
            it->second.ended = entry.error == MessageErrorType::StopIteration ? MessageErrorType::StopIteration
                                                                               : MessageErrorType::OperationAborted;
            it->second.last_access = std::chrono::steady_clock::now() - (kGeneratorIdleTimeout - kEndedGeneratorGrace);
        } else {
            it->second.last_access = std::chrono::steady_clock::now();
        }
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
        MessageEntry reply;
        Result<void> e = r ? detail::append_return(reply, *pending->info, *r,
                                                   def.type.container == robdef::ContainerKind::generator
                                                       ? without_container(def.type)
                                                       : robdef::TypeDefinition{})
                           : Result<void>(fail(r.error()));
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

void ObjectService::attach(boost::asio::io_context& io) { locks_->attach(io); }

namespace {

/// `path` is the service's root path or an object below it.
bool in_service(const std::string& service_name, const std::string& path) {
    return path == service_name ||
           (path.size() > service_name.size() && path.compare(0, service_name.size(), service_name) == 0 &&
            (path[service_name.size()] == '.' || path[service_name.size()] == '['));
}

}  // namespace

Result<void> ObjectService::request_object_lock(const std::string& path, const std::string& username) {
    if (!in_service(name_, path))
        return fail(MessageErrorType::InvalidArgument, "\"" + path + "\" is not a path of service " + name_);
    return locks_->lock_for_user(path, username);
}

Result<void> ObjectService::release_object_lock(const std::string& path) {
    if (!in_service(name_, path))
        return fail(MessageErrorType::InvalidArgument, "\"" + path + "\" is not a path of service " + name_);
    return locks_->release_user_lock(path);
}

std::optional<ObjectLocks::Holder> ObjectService::lock_holder(const std::string& path) const { return locks_->holder(path); }

bool ObjectService::has_privilege(const std::string& username, std::string_view privilege) const {
    for (const auto& u : users_.users())
        if (u.username == username)
            return std::find(u.privileges.begin(), u.privileges.end(), privilege) != u.privileges.end();
    return false;
}

Result<void> ObjectService::check_locks(const SessionRef& session, const std::string& path, const ServiceObject* obj,
                                        const MessageEntry& entry) {
    if (!locks_->any()) return {};  // the common case: nothing locked, no member lookup, no username copy
    // Members marked [nolock] / [nolockread] pass object locks; monitor locks apply to every member.
    bool nolock = false;
    if (obj)
        if (auto info = obj->member_info(entry.member_name); info && info->def)
            nolock = passes_object_locks(info->def->modifiers, entry.entry_type);
    return locks_->check(path, ServiceLocks::Requester{session.endpoint(), session.username()}, nolock);
}

void ObjectService::handle_lock_op(const SessionRef& session, MessageEntry&& entry, Responder responder) {
    const std::string username = session.username();
    ServiceLocks::Privileges privileges;
    {
        std::lock_guard lock(mutex_);
        privileges.override_ = has_privilege(username, "objectlockoverride");
        privileges.lock = has_privilege(username, "objectlock");
    }
    if (auto ok = ServiceLocks::check_privileges(entry.member_name, username, privileges); !ok) {
        responder.fail(ok.error());
        return;
    }
    if (auto obj = resolve(session, entry.service_path); !obj) {
        responder.fail(obj.error());
        return;
    }
    locks_->handle_op(ServiceLocks::Requester{session.endpoint(), username}, privileges, entry, std::move(responder));
}

}  // namespace rr::server
