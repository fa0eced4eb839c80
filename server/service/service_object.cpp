#include "server/service/service_object.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>

#include "core/value/named_type.hpp"
#include "server/service/callback_member.hpp"
#include "server/service/member_support.hpp"
#include "server/service/memory_member.hpp"
#include "server/service/object_service.hpp"
#include "server/service/pipe_member.hpp"
#include "server/service/wire_member.hpp"

namespace rr::server {

using detail::MemberInfo;
using robdef::MemberKind;

// ---------------------------------------------------------------------------------------------
// Generator defaults (generator.hpp)

Result<Value> Generator::next(std::optional<Value>) {
    return fail(MessageErrorType::StopIteration, "generator has no values");
}

void Generator::async_next(std::optional<Value> parameter, Completion done) { done(next(std::move(parameter))); }

// ---------------------------------------------------------------------------------------------

struct ServiceObject::Slot {
    std::shared_ptr<const MemberInfo> info;
    MemberKind kind = MemberKind::property;

    struct Stored {
        Value value;
        MessageElement packed;  // named "value"
    };
    std::shared_ptr<const PropertyGetter> getter;
    std::shared_ptr<const PropertySetter> setter;
    std::shared_ptr<const AsyncPropertyGetter> async_getter;
    std::shared_ptr<const AsyncPropertySetter> async_setter;
    std::shared_ptr<const Stored> stored;
    std::shared_ptr<const FunctionHandler> function;
    std::shared_ptr<const AsyncFunctionHandler> async_function;
    std::shared_ptr<const GeneratorFunctionHandler> generator;
    std::shared_ptr<const ObjRefResolver> resolver;
    std::shared_ptr<PipeMember> pipe;
    std::shared_ptr<WireMember> wire;
    std::shared_ptr<MemoryMember> memory;
    std::shared_ptr<CallbackMember> callback;
};

namespace {

// The order of the member index: by length, then by bytes. A lookup then compares lengths, which
// are integers, and calls memcmp only among names of the searched one's length.
// A function object (not a function pointer), so that std::lower_bound inlines it.
constexpr struct {
    bool operator()(std::string_view a, std::string_view b) const noexcept {
        return a.size() != b.size() ? a.size() < b.size() : a < b;
    }
} shorter_or_before;

template <class F>
std::shared_ptr<const F> share(F f) {
    if (!f) return nullptr;
    return std::make_shared<const F>(std::move(f));
}

bool param_is_generator(const robdef::MemberDefinition& def) {
    return !def.parameters.empty() && def.parameters.back().container == robdef::ContainerKind::generator;
}

/// Function parameters that travel in a FunctionCallReq (all but a trailing `{generator}` one).
std::size_t call_parameter_count(const robdef::MemberDefinition& def) {
    return def.parameters.size() - (param_is_generator(def) ? 1 : 0);
}

// A reply built in the request's element vector, once the request's elements have been read: a
// request without elements brings one kept from an earlier reply (ServiceRequest), so a reply of a
// few elements allocates nothing for them (issue 14).
MessageEntry reply_in(MessageEntry& request) {
    MessageEntry reply;
    reply.elements = std::move(request.elements);
    reply.elements.clear();
    return reply;
}

Result<std::vector<Value>> unpack_arguments(const MemberInfo& info, const MessageEntry& entry, std::size_t count) {
    std::vector<Value> args;
    args.reserve(count);
    for (std::size_t i = 0; i < count; ++i) {
        const auto& p = info.def->parameters[i];
        auto e = detail::require_element(entry, p.name);
        if (!e) return e.take_error();
        auto v = detail::unpack_member(info, **e, p);
        if (!v) return v.take_error();
        args.push_back(std::move(*v));
    }
    return args;
}

const char* kind_word(MemberKind k) {
    switch (k) {
        case MemberKind::property: return "a property";
        case MemberKind::function: return "a function";
        case MemberKind::event: return "an event";
        case MemberKind::objref: return "an objref";
        case MemberKind::pipe: return "a pipe";
        case MemberKind::callback: return "a callback";
        case MemberKind::wire: return "a wire";
        case MemberKind::memory: return "a memory";
        default: return "a member";
    }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Construction

ServiceObject::ServiceObject(std::shared_ptr<const ServiceTypes> types, const robdef::ServiceEntryDefinition* def,
                             std::string type, std::string service_name)
    : types_(std::move(types)), def_(def), type_(std::move(type)), service_name_(std::move(service_name)) {}

ServiceObject::~ServiceObject() = default;

Result<std::shared_ptr<ServiceObject>> ServiceObject::create(std::shared_ptr<const ServiceTypes> types,
                                                             std::string_view object_type) {
    if (!types) return fail(MessageErrorType::InvalidArgument, "no service types");
    const auto* def = types->find_object(object_type);
    if (!def) return fail(MessageErrorType::InvalidArgument, "unknown object type \"" + std::string(object_type) + "\"");
    std::string service_name(object_type.substr(0, object_type.rfind('.')));
    std::shared_ptr<ServiceObject> obj(new ServiceObject(types, def, std::string(object_type), service_name));
    for (const auto& m : def->members) {
        auto slot = std::make_unique<Slot>();
        auto info = std::make_shared<MemberInfo>();
        info->types = types;
        info->def = &m;
        info->service_name = service_name;
        info->owner = obj;
        slot->info = info;
        slot->kind = m.kind;
        switch (m.kind) {
            case MemberKind::pipe: slot->pipe = std::make_shared<PipeMember>(info, robdef::pipe_is_unreliable(*def, m)); break;
            case MemberKind::wire: slot->wire = std::make_shared<WireMember>(info); break;
            case MemberKind::memory: slot->memory = std::make_shared<MemoryMember>(info); break;
            case MemberKind::callback: slot->callback = std::make_shared<CallbackMember>(info); break;
            default: break;
        }
        obj->slots_.push_back(std::move(slot));
    }
    std::sort(obj->slots_.begin(), obj->slots_.end(),
              [](const auto& a, const auto& b) { return shorter_or_before(a->info->def->name, b->info->def->name); });
    obj->slot_names_.reserve(obj->slots_.size());
    for (const auto& slot : obj->slots_) obj->slot_names_.push_back(slot->info->def->name);
    return obj;
}

RRError ServiceObject::user_error(std::string_view exception, std::string message) const {
    return types_->user_error(exception, std::move(message), service_name_);
}

ServiceObject::Slot* ServiceObject::find_slot(std::string_view name) const noexcept {
    auto it = std::lower_bound(slot_names_.begin(), slot_names_.end(), name, shorter_or_before);
    if (it == slot_names_.end() || *it != name) return nullptr;
    return slots_[static_cast<std::size_t>(it - slot_names_.begin())].get();
}

Result<ServiceObject::Slot*> ServiceObject::slot_of(std::string_view name, MemberKind kind) const {
    Slot* s = find_slot(name);
    if (!s) return fail(detail::member_not_found(name));
    if (s->kind != kind)
        return fail(MessageErrorType::MemberNotFound,
                    "Member \"" + std::string(name) + "\" of " + type_ + " is not " + kind_word(kind));
    return s;
}

std::shared_ptr<const MemberInfo> ServiceObject::member_info(std::string_view name) const {
    Slot* s = find_slot(name);
    return s ? s->info : nullptr;
}

// ---------------------------------------------------------------------------------------------
// Configuration

Result<void> ServiceObject::set_property_value(std::string_view property, Value value) {
    auto s = slot_of(property, MemberKind::property);
    if (!s) return s.take_error();
    auto packed = detail::pack_member(*(*s)->info, value, (*s)->info->def->type, "value");
    if (!packed) return packed.take_error();
    auto stored = std::make_shared<const Slot::Stored>(Slot::Stored{std::move(value), std::move(*packed)});
    std::lock_guard lock(mutex_);
    (*s)->stored = std::move(stored);
    return {};
}

Result<Value> ServiceObject::property_value(std::string_view property) const {
    auto s = slot_of(property, MemberKind::property);
    if (!s) return s.take_error();
    std::shared_ptr<const Slot::Stored> stored;
    {
        std::lock_guard lock(mutex_);
        stored = (*s)->stored;
    }
    if (!stored) return fail(MessageErrorType::ValueNotSet, "property " + std::string(property) + " has no value");
    return stored->value;
}

Result<void> ServiceObject::set_property_handlers(std::string_view property, PropertyGetter get, PropertySetter set) {
    auto s = slot_of(property, MemberKind::property);
    if (!s) return s.take_error();
    auto g = share(std::move(get));
    auto st = share(std::move(set));
    std::lock_guard lock(mutex_);
    (*s)->getter = std::move(g);
    (*s)->setter = std::move(st);
    (*s)->async_getter.reset();
    (*s)->async_setter.reset();
    return {};
}

Result<void> ServiceObject::set_async_property_handlers(std::string_view property, AsyncPropertyGetter get,
                                                        AsyncPropertySetter set) {
    auto s = slot_of(property, MemberKind::property);
    if (!s) return s.take_error();
    auto g = share(std::move(get));
    auto st = share(std::move(set));
    std::lock_guard lock(mutex_);
    (*s)->async_getter = std::move(g);
    (*s)->async_setter = std::move(st);
    (*s)->getter.reset();
    (*s)->setter.reset();
    return {};
}

Result<void> ServiceObject::set_function(std::string_view function, FunctionHandler handler) {
    auto s = slot_of(function, MemberKind::function);
    if (!s) return s.take_error();
    if ((*s)->info->def->is_generator())
        return fail(MessageErrorType::MemberNotFound,
                    "function " + std::string(function) + " is a generator function: use set_generator_function");
    auto h = share(std::move(handler));
    std::lock_guard lock(mutex_);
    (*s)->function = std::move(h);
    (*s)->async_function.reset();
    return {};
}

Result<void> ServiceObject::set_async_function(std::string_view function, AsyncFunctionHandler handler) {
    auto s = slot_of(function, MemberKind::function);
    if (!s) return s.take_error();
    if ((*s)->info->def->is_generator())
        return fail(MessageErrorType::MemberNotFound,
                    "function " + std::string(function) + " is a generator function: use set_generator_function");
    auto h = share(std::move(handler));
    std::lock_guard lock(mutex_);
    (*s)->async_function = std::move(h);
    (*s)->function.reset();
    return {};
}

Result<void> ServiceObject::set_generator_function(std::string_view function, GeneratorFunctionHandler handler) {
    auto s = slot_of(function, MemberKind::function);
    if (!s) return s.take_error();
    if (!(*s)->info->def->is_generator())
        return fail(MessageErrorType::MemberNotFound, "function " + std::string(function) + " is not a generator function");
    auto h = share(std::move(handler));
    std::lock_guard lock(mutex_);
    (*s)->generator = std::move(h);
    return {};
}

Result<void> ServiceObject::set_objref(std::string_view objref, ObjRefResolver resolver) {
    auto s = slot_of(objref, MemberKind::objref);
    if (!s) return s.take_error();
    auto h = share(std::move(resolver));
    std::lock_guard lock(mutex_);
    (*s)->resolver = std::move(h);
    return {};
}

Result<std::shared_ptr<PipeMember>> ServiceObject::pipe(std::string_view name) const {
    auto s = slot_of(name, MemberKind::pipe);
    if (!s) return s.take_error();
    return (*s)->pipe;
}

Result<std::shared_ptr<CallbackMember>> ServiceObject::callback(std::string_view name) const {
    auto s = slot_of(name, MemberKind::callback);
    if (!s) return s.take_error();
    return (*s)->callback;
}

Result<std::shared_ptr<WireMember>> ServiceObject::wire(std::string_view name) const {
    auto s = slot_of(name, MemberKind::wire);
    if (!s) return s.take_error();
    return (*s)->wire;
}

Result<std::shared_ptr<MemoryMember>> ServiceObject::memory(std::string_view name) const {
    auto s = slot_of(name, MemberKind::memory);
    if (!s) return s.take_error();
    return (*s)->memory;
}

void ServiceObject::clear_handlers() {
    std::vector<std::shared_ptr<const void>> dropped;  // destroyed after the lock is released
    {
        std::lock_guard lock(mutex_);
        for (auto& s : slots_) {
            dropped.push_back(std::move(s->getter));
            dropped.push_back(std::move(s->setter));
            dropped.push_back(std::move(s->async_getter));
            dropped.push_back(std::move(s->async_setter));
            dropped.push_back(std::move(s->function));
            dropped.push_back(std::move(s->async_function));
            dropped.push_back(std::move(s->generator));
            dropped.push_back(std::move(s->resolver));
        }
    }
    for (auto& s : slots_) {
        if (s->pipe) s->pipe->clear_handlers();
        if (s->wire) s->wire->clear_handlers();
        if (s->memory) s->memory->clear_handlers();
    }
}

// ---------------------------------------------------------------------------------------------
// Binding

std::vector<std::string> ServiceObject::paths() const {
    std::lock_guard lock(mutex_);
    return paths_;
}

ServiceObject::Binding ServiceObject::binding() const {
    std::lock_guard lock(mutex_);
    return Binding{service_.lock(), paths_};
}

Result<void> ServiceObject::bind(const std::shared_ptr<ObjectService>& service, const std::string& path) {
    std::lock_guard lock(mutex_);
    auto current = service_.lock();
    if (current && current != service)
        return fail(MessageErrorType::InvalidOperation, "object is already served by service \"" + current->name() + "\"");
    service_ = service;
    if (std::find(paths_.begin(), paths_.end(), path) == paths_.end()) paths_.push_back(path);
    return {};
}

void ServiceObject::unbind(const std::string& path) {
    {
        std::lock_guard lock(mutex_);
        std::erase(paths_, path);
    }
    for (auto& s : slots_) {
        if (s->pipe) s->pipe->drop_path(path);
        if (s->wire) s->wire->drop_path(path);
    }
}

void ServiceObject::session_closed(const SessionRef& session) {
    for (auto& s : slots_) {
        if (s->pipe) s->pipe->drop_session(session);
        if (s->wire) s->wire->drop_session(session);
    }
}

// ---------------------------------------------------------------------------------------------
// Events

Result<void> ServiceObject::fire_event(std::string_view event, std::vector<Value> args) {
    auto s = slot_of(event, MemberKind::event);
    if (!s) return s.take_error();
    const MemberInfo& info = *(*s)->info;
    if (args.size() != info.def->parameters.size())
        return fail(MessageErrorType::DataTypeError, "event " + std::string(event) + " takes " +
                                                         std::to_string(info.def->parameters.size()) + " arguments, got " +
                                                         std::to_string(args.size()));
    MessageEntry entry = detail::member_entry(MessageEntryType::EventReq, {}, std::string(event));
    entry.elements.reserve(args.size());
    for (std::size_t i = 0; i < args.size(); ++i) {
        auto e = detail::pack_member(info, args[i], info.def->parameters[i], info.def->parameters[i].name);
        if (!e) return e.take_error();
        entry.elements.push_back(std::move(*e));
    }
    auto b = binding();
    if (!b.service || b.paths.empty()) return {};
    const auto sessions = b.service->sessions();
    Result<void> result;
    auto note = [&](Result<void> r) {
        if (!r && r.error().type == MessageErrorType::BufferLimitViolation && result.ok()) result = r.take_error();
    };
    for (std::size_t p = 0; p < b.paths.size(); ++p) {
        const bool last_path = p + 1 == b.paths.size();
        if (sessions.size() == 1) {
            entry.service_path = b.paths[p];
            note(sessions.front().send(last_path ? std::move(entry) : entry));  // copies share the packed data
            continue;
        }
        // Many clients: the entry is encoded once per message format for all of them.
        MessageEntry e = last_path ? std::move(entry) : entry;
        e.service_path = b.paths[p];
        const auto shared = std::make_shared<const EncodedEntry>(std::move(e));
        for (const auto& s : sessions) note(s.send(shared));
    }
    return result;
}

// ---------------------------------------------------------------------------------------------
// Objrefs

Result<std::shared_ptr<ServiceObject>> ServiceObject::resolve_objref(const SessionRef& session, std::string_view member,
                                                                     std::string_view index_text, bool has_index) {
    Slot* s = find_slot(member);
    if (!s || s->kind != MemberKind::objref) return fail(detail::member_not_found(member));
    const auto& type = s->info->def->type;
    ObjRefIndex index;
    switch (robdef::objref_index_kind(type)) {
        case robdef::ObjRefIndexKind::none:
            if (has_index) return fail(MessageErrorType::ObjectNotFound, "Object not found: objref " + std::string(member) + " takes no index");
            break;
        case robdef::ObjRefIndexKind::int32: {
            std::int32_t v = 0;
            auto [end, ec] = std::from_chars(index_text.data(), index_text.data() + index_text.size(), v);
            if (!has_index || ec != std::errc() || end != index_text.data() + index_text.size())
                return fail(MessageErrorType::ObjectNotFound, "Object not found: objref " + std::string(member) + " takes an int32 index");
            index = v;
            break;
        }
        case robdef::ObjRefIndexKind::string:
            if (!has_index) return fail(MessageErrorType::ObjectNotFound, "Object not found: objref " + std::string(member) + " takes a string index");
            index = std::string(index_text);
            break;
    }
    std::shared_ptr<const ObjRefResolver> resolver;
    {
        std::lock_guard lock(mutex_);
        resolver = s->resolver;
    }
    if (!resolver) return fail(MessageErrorType::ObjectNotFound, "Object not found: objref " + std::string(member) + " has no resolver");
    auto r = (*resolver)(session, index);
    if (!r) return r.take_error();
    if (!*r) return fail(MessageErrorType::ObjectNotFound, "Object not found: objref " + std::string(member) + " returned no object");
    if ((*r)->types() != types_)
        return fail(MessageErrorType::InternalError, "objref " + std::string(member) + " returned an object of other service types");
    if (type.base != DataTypes::varobject_t) {
        const std::string& want = type.qualified_name.empty() ? type.type_name : type.qualified_name;
        if (!types_->object_is_a((*r)->type(), want))
            return fail(MessageErrorType::InternalError,
                        "objref " + std::string(member) + " returned a " + (*r)->type() + ", expected " + want);
    }
    return std::move(*r);
}

// ---------------------------------------------------------------------------------------------
// Dispatch

void ServiceObject::handle_entry(ObjectService& service, const SessionRef& session, MessageEntry&& entry,
                                 Responder&& responder) {
    Slot* slot = find_slot(entry.member_name);
    const auto type = entry.entry_type;
    auto need = [&](MemberKind kind) {
        if (slot && slot->kind == kind) return true;
        if (!slot)
            responder.fail(detail::member_not_found(entry.member_name));
        else
            responder.fail(make_error(MessageErrorType::MemberNotFound, "Member \"" + entry.member_name + "\" of " +
                                                                            type_ + " is not " + kind_word(kind)));
        return false;
    };
    switch (type) {
        case MessageEntryType::PropertyGetReq:
            if (need(MemberKind::property)) handle_property_get(*slot, session, std::move(entry), std::move(responder));
            return;
        case MessageEntryType::PropertySetReq:
            if (need(MemberKind::property)) handle_property_set(*slot, session, std::move(entry), std::move(responder));
            return;
        case MessageEntryType::FunctionCallReq:
            if (need(MemberKind::function)) handle_function(service, *slot, session, std::move(entry), std::move(responder));
            return;
        case MessageEntryType::PipeConnectReq:
        case MessageEntryType::PipeDisconnectReq:
            if (need(MemberKind::pipe)) slot->pipe->handle_request(session, std::move(entry), std::move(responder));
            return;
        case MessageEntryType::PipePacket:
        case MessageEntryType::PipePacketRet:
            if (slot && slot->kind == MemberKind::pipe) slot->pipe->handle_packet(session, std::move(entry));
            return;
        case MessageEntryType::WirePacket:
            if (slot && slot->kind == MemberKind::wire) slot->wire->handle_packet(session, std::move(entry));
            return;
        case MessageEntryType::WireConnectReq:
        case MessageEntryType::WireDisconnectReq:
        case MessageEntryType::WirePeekInValueReq:
        case MessageEntryType::WirePeekOutValueReq:
        case MessageEntryType::WirePokeOutValueReq:
            if (need(MemberKind::wire)) slot->wire->handle_request(session, std::move(entry), std::move(responder));
            return;
        case MessageEntryType::MemoryRead:
        case MessageEntryType::MemoryWrite:
        case MessageEntryType::MemoryGetParam:
            if (need(MemberKind::memory)) slot->memory->handle_request(session, std::move(entry), std::move(responder));
            return;
        default:
            responder.fail(make_error(MessageErrorType::ProtocolError, "Unknown request type"));
            return;
    }
}

namespace {

/// An asynchronous property reply: answered once, whichever thread completes first.
struct PendingReply {
    Responder responder;
    std::shared_ptr<const MemberInfo> info;
    std::atomic<bool> done{false};
};

}  // namespace

void ServiceObject::handle_property_get(Slot& slot, const SessionRef& session, MessageEntry&& entry, Responder&& responder) {
    const MemberInfo& info = *slot.info;
    if (info.def->direction() == robdef::MemberDirection::writeonly) {
        responder.fail(make_error(MessageErrorType::WriteOnlyMember, "Write only member"));
        return;
    }
    std::shared_ptr<const PropertyGetter> getter;
    std::shared_ptr<const AsyncPropertyGetter> async_getter;
    std::shared_ptr<const Slot::Stored> stored;
    {
        std::lock_guard lock(mutex_);
        getter = slot.getter;
        async_getter = slot.async_getter;
        stored = slot.stored;
    }
    if (async_getter) {
        auto pending = std::make_shared<PendingReply>();
        pending->responder = std::move(responder);
        pending->info = slot.info;
        (*async_getter)(session, [pending](Result<Value> r) {
            if (pending->done.exchange(true)) return;
            if (!r) {
                pending->responder.fail(r.error());
                return;
            }
            auto e = detail::pack_member(*pending->info, *r, pending->info->def->type, "value");
            if (!e) {
                pending->responder.fail(e.error());
                return;
            }
            MessageEntry reply;
            reply.elements.push_back(std::move(*e));
            pending->responder.respond(std::move(reply));
        });
        return;
    }
    MessageEntry reply = reply_in(entry);
    if (getter) {
        auto v = (*getter)(session);
        if (!v) {
            responder.fail(v.error());
            return;
        }
        auto e = detail::pack_member(info, *v, info.def->type, "value");
        if (!e) {
            responder.fail(e.error());
            return;
        }
        reply.elements.push_back(std::move(*e));
    } else if (stored) {
        reply.elements.push_back(stored->packed);
    } else {
        responder.fail(make_error(MessageErrorType::ValueNotSet, "property " + info.def->name + " has no value"));
        return;
    }
    responder.respond(std::move(reply));
}

void ServiceObject::handle_property_set(Slot& slot, const SessionRef& session, MessageEntry&& entry, Responder&& responder) {
    const MemberInfo& info = *slot.info;
    if (info.def->direction() == robdef::MemberDirection::readonly) {
        responder.fail(make_error(MessageErrorType::ReadOnlyMember, "Read only member"));
        return;
    }
    auto e = detail::require_element(entry, "value");
    if (!e) {
        responder.fail(e.error());
        return;
    }
    auto v = detail::unpack_member(info, **e, info.def->type);
    if (!v) {
        responder.fail(v.error());
        return;
    }
    std::shared_ptr<const PropertySetter> setter;
    std::shared_ptr<const AsyncPropertySetter> async_setter;
    {
        std::lock_guard lock(mutex_);
        setter = slot.setter;
        async_setter = slot.async_setter;
    }
    if (async_setter) {
        auto pending = std::make_shared<PendingReply>();
        pending->responder = std::move(responder);
        (*async_setter)(session, std::move(*v), [pending](Result<void> r) {
            if (pending->done.exchange(true)) return;
            if (!r)
                pending->responder.fail(r.error());
            else
                pending->responder.respond(MessageEntry{});
        });
        return;
    }
    if (setter) {
        if (auto r = (*setter)(session, std::move(*v)); !r) {
            responder.fail(r.error());
            return;
        }
    } else {
        auto packed = detail::pack_member(info, *v, info.def->type, "value");
        if (!packed) {
            responder.fail(packed.error());
            return;
        }
        auto stored = std::make_shared<const Slot::Stored>(Slot::Stored{std::move(*v), std::move(*packed)});
        std::lock_guard lock(mutex_);
        slot.stored = std::move(stored);
    }
    responder.respond(MessageEntry{});
}

namespace {

/// Shared by an asynchronous completion: answers exactly once, whichever thread completes first.
struct PendingCall {
    Responder responder;
    std::shared_ptr<const MemberInfo> info;
    std::atomic<bool> done{false};

    void complete(Result<Value> r) {
        if (done.exchange(true)) return;
        if (!r) {
            responder.fail(r.error());
            return;
        }
        MessageEntry reply;
        if (auto e = detail::append_return(reply, *info, *r, info->def->type); !e) {
            responder.fail(e.error());
            return;
        }
        responder.respond(std::move(reply));
    }
};

}  // namespace

void ServiceObject::handle_function(ObjectService& service, Slot& slot, const SessionRef& session, MessageEntry&& entry,
                                    Responder&& responder) {
    const MemberInfo& info = *slot.info;
    const bool generator = info.def->is_generator();
    auto args = unpack_arguments(info, entry, call_parameter_count(*info.def));
    if (!args) {
        responder.fail(args.error());
        return;
    }
    std::shared_ptr<const FunctionHandler> function;
    std::shared_ptr<const AsyncFunctionHandler> async_function;
    std::shared_ptr<const GeneratorFunctionHandler> generator_function;
    {
        std::lock_guard lock(mutex_);  // only the handler this call can use is copied
        if (generator)
            generator_function = slot.generator;
        else if (slot.async_function)
            async_function = slot.async_function;
        else
            function = slot.function;
    }
    if (generator) {
        if (!generator_function) {
            responder.fail(make_error(MessageErrorType::NotImplementedError, "function " + info.def->name + " is not implemented"));
            return;
        }
        auto g = (*generator_function)(session, std::move(*args));
        if (!g) {
            responder.fail(g.error());
            return;
        }
        if (!*g) {
            responder.fail(make_error(MessageErrorType::InvalidOperation, "Generator must not be null"));
            return;
        }
        auto index = service.add_generator(session, entry.service_path, info.def->name, std::move(*g));
        if (!index) {
            responder.fail(index.error());
            return;
        }
        MessageEntry reply;
        reply.elements.push_back(make_scalar_element<std::int32_t>("index", *index));
        responder.respond(std::move(reply));
        return;
    }
    if (async_function) {
        auto pending = std::make_shared<PendingCall>();
        pending->responder = std::move(responder);
        pending->info = slot.info;
        (*async_function)(session, std::move(*args), [pending](Result<Value> r) { pending->complete(std::move(r)); });
        return;
    }
    if (!function) {
        responder.fail(make_error(MessageErrorType::NotImplementedError, "function " + info.def->name + " is not implemented"));
        return;
    }
    auto r = (*function)(session, std::move(*args));
    if (!r) {
        responder.fail(r.error());
        return;
    }
    MessageEntry reply = reply_in(entry);
    if (auto e = detail::append_return(reply, info, *r, info.def->type); !e) {
        responder.fail(e.error());
        return;
    }
    responder.respond(std::move(reply));
}

}  // namespace rr::server
