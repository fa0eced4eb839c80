// ClientContext: connection, dispatch of incoming entries, objects and objrefs, properties, functions,
// events, callbacks and session operations. Pipes, wires, generators and memories have their own files.
#include "core/session/client_context.hpp"

#include <algorithm>

#include "core/core_version.hpp"
#include "base/names/service_path.hpp"
#include "core/session/client_state.hpp"
#include "core/session/elements.hpp"
#include "core/value/named_type.hpp"
#include "core/value/pack_value.hpp"

namespace rr {

using robdef::ContainerKind;
using robdef::MemberDirection;
using robdef::MemberKind;

namespace {

struct ObjectType {
    const robdef::ServiceDefinition* service = nullptr;
    const robdef::ServiceEntryDefinition* entry = nullptr;
};

// `svc.Type` → its definition, or nulls (service unknown: service == nullptr).
ObjectType find_object_type(const robdef::ServiceDefinitionSet& defs, std::string_view qualified) {
    ObjectType t;
    auto dot = qualified.rfind('.');
    if (dot == std::string_view::npos) return t;
    t.service = defs.find_service(qualified.substr(0, dot));
    if (!t.service) return t;
    const auto* e = t.service->find_entry(qualified.substr(dot + 1));
    if (e && e->kind == robdef::EntryKind::object) t.entry = e;
    return t;
}

std::vector<std::string> read_string_list(const MessageElement* e) {
    std::vector<std::string> out;
    if (!e || e->type != DataTypes::list_t) return out;
    for (const auto& item : e->elements) out.emplace_back(read_string(item));
    return out;
}

bool path_is_under(std::string_view path, std::string_view root) {
    if (path.size() < root.size() || path.compare(0, root.size(), root) != 0) return false;
    return path.size() == root.size() || path[root.size()] == '.';
}

std::string_view kind_text(MemberKind k) { return robdef::member_kind_keyword(k); }

// `objectimplements` carries the names as written in the definition (CORE sends the parsed
// `Implements`, so a type of the same service comes unqualified): qualify them with `service`.
std::vector<std::string> qualified_implements(std::vector<std::string> names, std::string_view service) {
    for (auto& n : names)
        if (n.find('.') == std::string::npos) n = std::string(service) + "." + n;
    return names;
}

}  // namespace

ClientContext::ClientContext(ClientContextConfig config, MonoTime now)
    : config_(std::move(config)), session_(config_.session, now), now_(now) {}

ClientContext::~ClientContext() = default;

// --- pump ------------------------------------------------------------------------------------------

Result<void> ClientContext::feed(std::span<const std::byte> bytes, MonoTime now) {
    now_ = now;
    auto r = session_.feed(bytes, now);
    pump_events(now);
    return r;
}

void ClientContext::on_transport_closed(RRError error) {
    session_.on_transport_closed(std::move(error));
    pump_events(now_);
}

void ClientContext::on_timer(MonoTime now) {
    now_ = now;
    session_.on_timer(now);
    pump_events(now);
}

void ClientContext::disconnect(MonoTime now) {
    now_ = now;
    session_.disconnect(now);
    pump_events(now);
}

void ClientContext::pump_events(MonoTime now) {
    while (auto ev = session_.poll_event()) {
        if (std::holds_alternative<ClientSessionConnected>(*ev)) {
            on_connected(now);
        } else if (auto* r = std::get_if<ClientResponse>(&*ev)) {
            auto it = replies_.find(r->request_id);
            if (it == replies_.end()) continue;
            Reply k = replies_.take(it);
            k(std::move(r->entry));
        } else if (auto* in = std::get_if<ClientIncoming>(&*ev)) {
            on_incoming(std::move(in->entry), now);
        } else if (auto* c = std::get_if<ClientSessionClosed>(&*ev)) {
            on_session_closed(c->error);
        }
    }
}

void ClientContext::on_connected(MonoTime now) {
    const auto& info = session_.info();
    for (std::size_t i = 0; i < info.service_definitions.size(); ++i) {
        auto r = defs_.add_text(info.service_definitions[i], "servicedefs[" + std::to_string(i) + "]");
        if (!r) {
            auto h = std::exchange(on_connect_, nullptr);
            session_.disconnect(now);
            if (h) h(fail(MessageErrorType::ServiceDefinitionError, "received service definition does not parse: " + r.error().message));
            return;
        }
    }
    auto t = find_object_type(defs_, info.object_type);
    if (!t.entry) {
        auto h = std::exchange(on_connect_, nullptr);
        session_.disconnect(now);
        if (h) h(fail(MessageErrorType::ServiceDefinitionError, "root object type \"" + info.object_type + "\" is not in the received definitions"));
        return;
    }
    root_ = ObjectRef{config_.session.service_name, info.object_type,
                      qualified_implements(info.object_implements, t.service->name)};
    auto st = std::make_unique<ObjectState>();
    st->ref = root_;
    st->service = t.service;
    st->entry = t.entry;
    objects_[root_.path] = std::move(st);
    connected_ = true;
    if (auto h = std::exchange(on_connect_, nullptr)) h(root_);
}

void ClientContext::on_session_closed(const RRError& error) {
    // ClientSession has already failed every pending request; anything left here never got an answer.
    auto left = std::move(replies_);
    replies_.clear();
    for (auto& [id, k] : left) k(fail(MessageErrorType::ConnectionError, "connection closed: " + error.message));
    fail_all_handles(make_error(MessageErrorType::ConnectionError, "connection closed: " + error.message));
    // Nothing more can arrive: drop the handlers (they may hold references to the context's owner).
    events_.clear();
    callbacks_.clear();
    for (auto& [id, p] : pipes_) p->handlers = std::make_shared<PipeEndpointHandlers>();
    for (auto& [id, w] : wires_) w->handlers = std::make_shared<WireConnectionHandlers>();
    if (!connected_) {
        if (auto h = std::exchange(on_connect_, nullptr)) h(fail(error));
        return;
    }
    connected_ = false;
    if (auto h = std::exchange(on_closed_, nullptr)) h(error);
}

void ClientContext::fail_all_handles(const RRError& error) {
    std::vector<std::uint64_t> ids;
    for (const auto& [id, p] : pipes_)
        if (!p->closed) ids.push_back(id);
    for (auto id : ids) close_pipe_state(id, error);
    ids.clear();
    for (const auto& [id, w] : wires_)
        if (!w->closed) ids.push_back(id);
    for (auto id : ids) close_wire_state(id, error);
    generators_.clear();
    wire_connecting_.clear();
}

void ClientContext::on_incoming(MessageEntry&& e, MonoTime now) {
    switch (e.entry_type) {
        case MessageEntryType::EventReq: on_event(std::move(e)); break;
        case MessageEntryType::PipePacket:
        case MessageEntryType::PipePacketRet:
        case MessageEntryType::PipeClosed: on_pipe_entry(std::move(e), now); break;
        case MessageEntryType::WirePacket:
        case MessageEntryType::WireClosed: on_wire_entry(std::move(e), now); break;
        case MessageEntryType::CallbackCallReq: on_callback_call(std::move(e), now); break;
        case MessageEntryType::ServicePathReleasedReq: {
            std::string path = e.service_path;
            release_path(path);
            if (on_path_released_) {
                auto h = on_path_released_;  // the handler may replace itself
                h(path);
            }
            break;
        }
        default: break;  // ServiceClosed is handled by the session; anything else is ignored as CORE does
    }
}

// --- requests --------------------------------------------------------------------------------------

void ClientContext::send_request(MessageEntry&& e, MonoTime now, Reply k) {
    now_ = now;
    auto id = session_.request(std::move(e), now);
    if (!id) {
        if (session_.is_closed()) {
            k(fail(MessageErrorType::ConnectionError, "connection closed"));
        } else {
            k(id.take_error());
        }
        return;
    }
    replies_.put(*id, std::move(k));
}

Result<void> ClientContext::send_packet(MessageEntry&& e, MonoTime now) {
    now_ = now;
    if (session_.is_closed()) return fail(MessageErrorType::ConnectionError, "connection closed");
    return session_.send_packet(std::move(e), now);
}

Result<const ClientContext::ObjectState*> ClientContext::find_object(std::string_view path) const {
    if (!connected_ || session_.is_closed()) return fail(MessageErrorType::ConnectionError, "client not connected");
    auto it = objects_.find(path);
    if (it == objects_.end())
        return fail(MessageErrorType::ObjectNotFound,
                    "no object at service path \"" + std::string(path) + "\" (get it through an objref first)");
    return it->second.get();
}

Result<const robdef::MemberDefinition*> ClientContext::find_member(std::string_view path, std::string_view member,
                                                                    MemberKind kind, const ObjectState** obj) const {
    auto o = find_object(path);
    if (!o) return o.take_error();
    const auto* m = (*o)->entry->find_member(member);
    if (!m)
        return fail(MessageErrorType::MemberNotFound,
                    "object type " + (*o)->ref.type + " has no member \"" + std::string(member) + "\"");
    if (m->kind != kind)
        return fail(MessageErrorType::InvalidOperation, "member \"" + std::string(member) + "\" of " + (*o)->ref.type +
                                                            " is " + robdef::with_article(kind_text(m->kind)) + ", not " +
                                                            robdef::with_article(kind_text(kind)));
    if (obj) *obj = *o;
    return m;
}

Result<const robdef::MemberDefinition*> ClientContext::member_definition(std::string_view path,
                                                                          std::string_view member) const {
    auto o = find_object(path);
    if (!o) return o.take_error();
    const auto* m = (*o)->entry->find_member(member);
    if (!m)
        return fail(MessageErrorType::MemberNotFound,
                    "object type " + (*o)->ref.type + " has no member \"" + std::string(member) + "\"");
    return m;
}

std::optional<ObjectRef> ClientContext::object(std::string_view path) const {
    auto it = objects_.find(path);
    if (it == objects_.end()) return std::nullopt;
    return it->second->ref;
}

bool ClientContext::implements(std::string_view path, std::string_view type) const {
    auto it = objects_.find(path);
    if (it == objects_.end()) return false;
    const auto& r = it->second->ref;
    if (r.type == type) return true;
    if (std::find(r.implements.begin(), r.implements.end(), type) != r.implements.end()) return true;
    // Also what the definition says (`implements` lines, qualified against the object's service).
    for (const auto& i : it->second->entry->implements) {
        std::string q = i.find('.') == std::string::npos ? it->second->service->name + "." + i : i;
        if (q == type) return true;
    }
    return false;
}

Result<MessageElement> ClientContext::pack(const Value& v, const robdef::TypeDefinition& t, std::string_view name,
                                           std::string_view context_service) const {
    return pack_value(v, t, name, defs_, context_service, config_.session.stream.limits);
}

Result<Value> ClientContext::unpack(const MessageElement& e, const robdef::TypeDefinition& t,
                                    std::string_view context_service) const {
    return unpack_value(e, t, defs_, context_service, config_.session.stream.limits);
}

// --- properties ------------------------------------------------------------------------------------

void ClientContext::property_get(std::string_view path, std::string_view member, MonoTime now, Completion<Value> done) {
    const ObjectState* obj = nullptr;
    auto m = find_member(path, member, MemberKind::property, &obj);
    if (!m) return done(m.take_error());
    if ((*m)->direction() == MemberDirection::writeonly)
        return done(fail(MessageErrorType::WriteOnlyMember, "property \"" + std::string(member) + "\" is write-only"));
    const robdef::MemberDefinition* def = *m;
    const robdef::ServiceDefinition* svc = obj->service;
    send_request(member_entry(MessageEntryType::PropertyGetReq, path, member), now,
                 [this, def, svc, done = std::move(done)](Result<MessageEntry> r) {
                     r = reply_result(std::move(r));
                     if (!r) return done(r.take_error());
                     const auto* v = r->find("value");
                     if (!v) return done(fail(MessageErrorType::MessageElementNotFound, "PropertyGetRes without value"));
                     done(unpack(*v, def->type, svc->name));
                 });
}

void ClientContext::property_set(std::string_view path, std::string_view member, Value value, MonoTime now,
                                 Completion<void> done) {
    const ObjectState* obj = nullptr;
    auto m = find_member(path, member, MemberKind::property, &obj);
    if (!m) return done(m.take_error());
    if ((*m)->direction() == MemberDirection::readonly)
        return done(fail(MessageErrorType::ReadOnlyMember, "property \"" + std::string(member) + "\" is read-only"));
    auto el = pack(value, (*m)->type, "value", obj->service->name);
    if (!el) return done(el.take_error());
    auto e = member_entry(MessageEntryType::PropertySetReq, path, member);
    e.elements.push_back(std::move(*el));
    send_request(std::move(e), now, [done = std::move(done)](Result<MessageEntry> r) {
        r = reply_result(std::move(r));
        if (!r) return done(r.take_error());
        done({});
    });
}

// --- functions -------------------------------------------------------------------------------------

void ClientContext::call(std::string_view path, std::string_view member, std::vector<Value> args, MonoTime now,
                         Completion<Value> done) {
    const ObjectState* obj = nullptr;
    auto m = find_member(path, member, MemberKind::function, &obj);
    if (!m) return done(m.take_error());
    const robdef::MemberDefinition* def = *m;
    if (def->is_generator())
        return done(fail(MessageErrorType::InvalidOperation,
                         "function \"" + std::string(member) + "\" is a generator function: use call_generator"));
    if (args.size() != def->parameters.size())
        return done(fail(MessageErrorType::InvalidArgument, "function \"" + std::string(member) + "\" takes " +
                                                                std::to_string(def->parameters.size()) +
                                                                " arguments, got " + std::to_string(args.size())));
    const robdef::ServiceDefinition* svc = obj->service;
    auto e = member_entry(MessageEntryType::FunctionCallReq, path, member);
    for (std::size_t i = 0; i < args.size(); ++i) {
        auto el = pack(args[i], def->parameters[i], def->parameters[i].name, svc->name);
        if (!el) return done(el.take_error());
        e.elements.push_back(std::move(*el));
    }
    send_request(std::move(e), now, [this, def, svc, done = std::move(done)](Result<MessageEntry> r) {
        r = reply_result(std::move(r));
        if (!r) return done(r.take_error());
        if (def->type.is_void()) return done(Value());
        const auto* v = r->find("return");
        if (!v) return done(fail(MessageErrorType::MessageElementNotFound, "FunctionCallRes without return"));
        done(unpack(*v, def->type, svc->name));
    });
}

// --- objrefs ---------------------------------------------------------------------------------------

void ClientContext::objref(std::string_view path, std::string_view member, ObjRefIndex index, MonoTime now,
                           Completion<ObjectRef> done) {
    auto m = find_member(path, member, MemberKind::objref);
    if (!m) return done(m.take_error());
    using robdef::ObjRefIndexKind;
    const auto kind = robdef::objref_index_kind((*m)->type);
    std::string child;
    if (kind == ObjRefIndexKind::none && std::holds_alternative<std::monostate>(index)) {
        child = join_service_path(path, member);
    } else if (kind == ObjRefIndexKind::int32 && std::holds_alternative<std::int32_t>(index)) {
        child = join_service_path(path, member, std::to_string(std::get<std::int32_t>(index)));
    } else if (kind == ObjRefIndexKind::string && std::holds_alternative<std::string>(index)) {
        const auto& key = std::get<std::string>(index);
        if (key.empty()) return done(fail(MessageErrorType::InvalidArgument, "empty objref index"));
        child = join_service_path(path, member, key);
    } else {
        const char* want = kind == ObjRefIndexKind::none    ? "no index"
                           : kind == ObjRefIndexKind::int32 ? "an int32 index"
                                                            : "a string index";
        return done(fail(MessageErrorType::InvalidArgument, "objref \"" + std::string(member) + "\" takes " + want));
    }
    if (auto it = objects_.find(child); it != objects_.end()) return done(it->second->ref);

    auto e = member_entry(MessageEntryType::ObjectTypeName, child, "");
    e.elements.push_back(make_string_element("clientversion", kProtocolClientVersion));
    send_request(std::move(e), now, [this, child, done = std::move(done)](Result<MessageEntry> r) mutable {
        r = reply_result(std::move(r));
        if (!r) return done(r.take_error());
        const auto* t = r->find("objecttype");
        if (!t || t->type != DataTypes::string_t)
            return done(fail(MessageErrorType::MessageElementNotFound, "ObjectTypeNameRet without objecttype"));
        resolve_object(std::move(child), std::string(read_string(*t)), read_string_list(r->find("objectimplements")),
                       now_, std::move(done));
    });
}

void ClientContext::resolve_object(std::string path, std::string type, std::vector<std::string> implements,
                                   MonoTime now, Completion<ObjectRef> done) {
    auto t = find_object_type(defs_, type);
    if (!t.service) {
        auto dot = type.rfind('.');
        if (dot == std::string::npos || dot == 0)
            return done(fail(MessageErrorType::ServiceDefinitionError, "invalid object type \"" + type + "\""));
        std::string service = type.substr(0, dot);
        pull_definition(std::move(service), now,
                        [this, path = std::move(path), type = std::move(type), implements = std::move(implements),
                         done = std::move(done)](Result<void> r) mutable {
                            if (!r) return done(r.take_error());
                            if (!defs_.find_service(type.substr(0, type.rfind('.'))))
                                return done(fail(MessageErrorType::ServiceDefinitionError,
                                                 "service definition for \"" + type + "\" not received"));
                            resolve_object(std::move(path), std::move(type), std::move(implements), now_, std::move(done));
                        });
        return;
    }
    if (!t.entry)
        return done(fail(MessageErrorType::ServiceDefinitionError, "object type \"" + type + "\" is not defined"));
    auto st = std::make_unique<ObjectState>();
    st->ref = ObjectRef{path, std::move(type), qualified_implements(std::move(implements), t.service->name)};
    st->service = t.service;
    st->entry = t.entry;
    ObjectRef ref = st->ref;
    objects_[path] = std::move(st);
    done(std::move(ref));
}

void ClientContext::pull_definition(std::string service, MonoTime now, Completion<void> done) {
    if (defs_.find_service(service)) return done({});
    auto e = member_entry(MessageEntryType::GetServiceDesc, config_.session.service_name, "");
    e.elements.push_back(make_string_element("ServiceType", service));
    e.elements.push_back(make_string_element("clientversion", kProtocolClientVersion));
    send_request(std::move(e), now, [this, service, done = std::move(done)](Result<MessageEntry> r) mutable {
        r = reply_result(std::move(r));
        if (!r) return done(r.take_error());
        const auto* d = r->find("servicedef");
        if (!d || d->type != DataTypes::string_t)
            return done(fail(MessageErrorType::MessageElementNotFound, "GetServiceDescRet without servicedef"));
        auto added = defs_.add_text(read_string(*d), "pulled " + service);
        if (!added) return done(added.take_error());
        const auto* def = defs_.find_service(service);
        if (!def) return done(fail(MessageErrorType::ServiceDefinitionError, "pulled definition is not " + service));
        // Then every import not yet known, one after the other.
        std::vector<std::string> missing;
        for (const auto& i : def->imports)
            if (!defs_.find_service(i)) missing.push_back(i);
        pull_imports(std::move(missing), now_, std::move(done));
    });
}

void ClientContext::pull_imports(std::vector<std::string> missing, MonoTime now, Completion<void> done) {
    if (missing.empty()) return done({});
    std::string n = std::move(missing.back());
    missing.pop_back();
    pull_definition(std::move(n), now,
                    [this, missing = std::move(missing), done = std::move(done)](Result<void> r) mutable {
                        if (!r) return done(std::move(r));
                        pull_imports(std::move(missing), now_, std::move(done));
                    });
}

void ClientContext::release_path(const std::string& path) {
    for (auto it = objects_.begin(); it != objects_.end();) {
        if (path_is_under(it->first, path) && it->first != root_.path)
            it = objects_.erase(it);
        else
            ++it;
    }
    auto err = make_error(MessageErrorType::ObjectNotFound, "service path " + path + " released by the service");
    std::vector<std::uint64_t> ids;
    for (const auto& [id, p] : pipes_)
        if (!p->closed && path_is_under(p->path, path)) ids.push_back(id);
    for (auto id : ids) close_pipe_state(id, err);
    ids.clear();
    for (const auto& [id, w] : wires_)
        if (!w->closed && path_is_under(w->path, path)) ids.push_back(id);
    for (auto id : ids) close_wire_state(id, err);
    for (auto it = generators_.begin(); it != generators_.end();)
        it = path_is_under(it->second->path, path) ? generators_.erase(it) : std::next(it);
    for (auto it = memory_caps_.begin(); it != memory_caps_.end();)
        it = path_is_under(it->first.substr(0, it->first.find('\n')), path) ? memory_caps_.erase(it) : std::next(it);
    for (auto it = events_.begin(); it != events_.end();)
        it = path_is_under(it->second.path, path) ? events_.erase(it) : std::next(it);
    for (auto it = callbacks_.begin(); it != callbacks_.end();)
        it = path_is_under(it->first.substr(0, it->first.find('\n')), path) ? callbacks_.erase(it) : std::next(it);
}

// --- events ----------------------------------------------------------------------------------------

Result<std::uint64_t> ClientContext::subscribe_event(std::string_view path, std::string_view member,
                                                     EventHandler handler) {
    auto m = find_member(path, member, MemberKind::event);
    if (!m) return m.take_error();
    if (!handler) return fail(MessageErrorType::InvalidArgument, "empty event handler");
    std::uint64_t id = ++next_id_;
    events_.emplace(id, EventSubscription{std::string(path), std::string(member),
                                          std::make_shared<EventHandler>(std::move(handler))});
    return id;
}

void ClientContext::unsubscribe_event(std::uint64_t subscription) { events_.erase(subscription); }

void ClientContext::on_event(MessageEntry&& e) {
    std::vector<std::shared_ptr<EventHandler>> handlers;
    for (const auto& [id, s] : events_)
        if (s.member == e.member_name && s.path == e.service_path) handlers.push_back(s.handler);
    if (handlers.empty()) return;
    auto obj = objects_.find(e.service_path);
    if (obj == objects_.end()) return;
    const auto* m = obj->second->entry->find_member(e.member_name);
    if (!m || m->kind != MemberKind::event) return;
    std::vector<Value> args;
    args.reserve(m->parameters.size());
    for (const auto& p : m->parameters) {
        const auto* el = e.find(p.name);
        if (!el) return;  // malformed event: dropped, as CORE drops events it cannot unpack
        auto v = unpack(*el, p, obj->second->service->name);
        if (!v) return;
        args.push_back(std::move(*v));
    }
    const std::string path = e.service_path;
    for (std::size_t i = 0; i < handlers.size(); ++i) {
        if (i + 1 == handlers.size()) {
            (*handlers[i])(path, args);
        } else {
            auto copy = args;
            (*handlers[i])(path, copy);
        }
    }
}

// --- callbacks -------------------------------------------------------------------------------------

Result<void> ClientContext::set_callback(std::string_view path, std::string_view member, CallbackHandler handler) {
    if (!handler) return set_deferred_callback(path, member, nullptr);
    return set_deferred_callback(path, member,
                                 [h = std::move(handler)](std::vector<Value>& args, Completion<Value> reply) {
                                     reply(h(args));
                                 });
}

Result<void> ClientContext::set_deferred_callback(std::string_view path, std::string_view member,
                                                  DeferredCallbackHandler handler) {
    auto m = find_member(path, member, MemberKind::callback);
    if (!m) return m.take_error();
    auto key = member_key(path, member);
    if (!handler) {
        callbacks_.erase(key);
        return {};
    }
    callbacks_[key] = std::make_shared<DeferredCallbackHandler>(std::move(handler));
    return {};
}

void ClientContext::on_callback_call(MessageEntry&& e, MonoTime now) {
    MessageEntry ret = member_entry(MessageEntryType::CallbackCallRet, e.service_path, e.member_name);
    ret.request_id = e.request_id;
    auto send = [this](MessageEntry ret, Result<MessageElement> result) {
        if (result) {
            ret.elements.push_back(std::move(*result));
        } else {
            set_entry_error(ret, result.error());
        }
        (void)session_.reply(std::move(ret), now_);
    };
    std::shared_ptr<DeferredCallbackHandler> handler;
    std::vector<Value> args;
    robdef::TypeDefinition return_type;
    std::string svc;
    auto found = [&]() -> Result<void> {
        auto obj = objects_.find(e.service_path);
        if (obj == objects_.end())
            return fail(MessageErrorType::ServiceError, "no object at service path " + e.service_path);
        const auto* m = obj->second->entry->find_member(e.member_name);
        if (!m || m->kind != MemberKind::callback)
            return fail(MessageErrorType::MemberNotFound, "no callback \"" + e.member_name + "\"");
        auto h = callbacks_.find(member_key(e.service_path, e.member_name));
        if (h == callbacks_.end())
            return fail(MessageErrorType::InvalidOperation, "callback \"" + e.member_name + "\" not set");
        handler = h->second;  // the handler may clear itself
        svc = obj->second->service->name;
        return_type = m->type;  // copied: the reply may come after the definitions changed
        args.reserve(m->parameters.size());
        for (const auto& p : m->parameters) {
            const auto* el = e.find(p.name);
            if (!el) return fail(MessageErrorType::MessageElementNotFound, "callback parameter " + p.name + " missing");
            auto v = unpack(*el, p, svc);
            if (!v) return v.take_error();
            args.push_back(std::move(*v));
        }
        return {};
    }();
    if (!found) return send(std::move(ret), found.take_error());
    (*handler)(args, [this, send, ret = std::move(ret), return_type = std::move(return_type),
                      svc = std::move(svc), answered = false](Result<Value> r) mutable {
        if (std::exchange(answered, true)) return;
        if (!r) return send(std::move(ret), r.take_error());
        if (return_type.is_void()) return send(std::move(ret), make_scalar_element<std::int32_t>("return", 0));
        send(std::move(ret), pack(*r, return_type, "return", svc));
    });
}

// --- session operations ----------------------------------------------------------------------------

void ClientContext::session_op(std::string_view path, std::string op, std::vector<MessageElement> elements,
                               MonoTime now, Completion<std::string> done) {
    auto o = find_object(path);
    if (!o) return done(o.take_error());
    auto e = member_entry(MessageEntryType::ClientSessionOpReq, path, op);
    e.elements = std::move(elements);
    send_request(std::move(e), now, [done = std::move(done)](Result<MessageEntry> r) {
        r = reply_result(std::move(r));
        if (!r) return done(r.take_error());
        const auto* ret = r->find("return");
        if (!ret || ret->type != DataTypes::string_t)
            return done(fail(MessageErrorType::MessageElementNotFound, "ClientSessionOpRet without return"));
        done(std::string(read_string(*ret)));
    });
}

void ClientContext::monitor_enter(std::string_view path, std::int32_t timeout_ms, MonoTime now, Completion<void> done) {
    std::vector<MessageElement> els;
    els.push_back(make_scalar_element<std::int32_t>("timeout", timeout_ms));
    session_op(path, "MonitorEnter", std::move(els), now,
               [this, path = std::string(path), done = std::move(done)](Result<std::string> r) mutable {
                   if (!r) return done(r.take_error());
                   if (*r == "OK") return done({});
                   if (*r == "Continue") return monitor_continue(std::move(path), now_, std::move(done));
                   done(fail(MessageErrorType::ProtocolError, "MonitorEnter answered \"" + *r + "\""));
               });
}

void ClientContext::monitor_continue(std::string path, MonoTime now, Completion<void> done) {
    session_op(path, "MonitorContinueEnter", {}, now,
               [this, path, done = std::move(done)](Result<std::string> r) mutable {
                   if (!r) return done(r.take_error());
                   if (*r == "OK") return done({});
                   if (*r == "Continue") return monitor_continue(std::move(path), now_, std::move(done));
                   done(fail(MessageErrorType::ProtocolError, "MonitorContinueEnter answered \"" + *r + "\""));
               });
}

void ClientContext::monitor_exit(std::string_view path, MonoTime now, Completion<void> done) {
    session_op(path, "MonitorExit", {}, now, [done = std::move(done)](Result<std::string> r) {
        if (!r) return done(r.take_error());
        if (*r != "OK") return done(fail(MessageErrorType::ProtocolError, "MonitorExit answered \"" + *r + "\""));
        done({});
    });
}

}  // namespace rr
