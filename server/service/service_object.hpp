// ServiceObject: one instance of a robdef object type (`svc.Obj`), served by an ObjectService at one or
// more service paths (wire.md §6.5). Built dynamically: every member of the type has a slot, and the
// application attaches handlers by member name (checked against the robdef: a wrong name or a wrong
// member kind gives MemberNotFound) or uses the defaults:
//
//   property  stored value (set_property_value) and/or getter/setter handlers,  1111–1114
//             synchronous or asynchronous (answered later from any thread)
//   function  sync handler returning Result<Value>, or async handler + Completion 1121/1122
//   generator handler returning a Generator (generator.hpp)                     1121/1122, 1123/1124
//   event     fire_event(): packed once, sent to every client session           1131
//   objref    resolver returning the ServiceObject for an optional index        103/104, 1109
//   pipe      pipe(name) → PipeMember (pipe_member.hpp)                          1141–1147
//   callback  callback(name) → CallbackMember (callback_member.hpp)              1151/1152
//   wire      wire(name) → WireMember (wire_member.hpp)                          1161–1167, 1181–1186
//   memory    memory(name) → MemoryMember (memory_member.hpp)                    1171–1176
//
// Requests are checked against the robdef before a handler runs, with the errors the official library
// sends: a missing argument element gives MessageElementNotFound ("Element b not found."), a value
// that does not fit its type DataTypeError (wrong kind, numeric type or count, null where not allowed;
// the message names the path), a member the type does not have MemberNotFound ("Member x not found"),
// as does a request of the wrong kind (CORE's generated skeletons); setting a [readonly] property
// ReadOnlyMember, reading a [writeonly] one WriteOnlyMember; entry types no member takes ProtocolError
// "Unknown request type". Extra elements are ignored. Values returned by handlers are checked when
// packed (a packing error is sent instead of the value).
// A handler returns any RRError; user exceptions come from ServiceTypes::user_error (RemoteError 100,
// errorname `svc.ExceptionName`).
//
// Threads: handlers run on the requesting client's connection strand, possibly concurrently for
// different clients; they must not block (long work: use the async forms and complete from another
// thread). No lock of this object is held while a handler runs, so handlers may call any function of
// this object or its members. Every public function is thread-safe.
//
// Ownership: the ObjectService owns the objects it serves (root and objects resolved through objrefs,
// until their path is released). Members are owned by their object. Handlers stored in an object must
// not own that object (capture a weak_ptr or a plain pointer to longer-lived state), or the cycle keeps
// it alive; clear_handlers() breaks such cycles explicitly.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "base/message/message.hpp"
#include "core/value/value.hpp"
#include "server/service/generator.hpp"
#include "server/node/service.hpp"
#include "server/service/service_types.hpp"

namespace rr::server {

class ObjectService;
class ServiceObject;
class PipeMember;
class WireMember;
class MemoryMember;
class CallbackMember;

/// Index of an objref request: none (`objref T x`), int32 (`objref T{int32} x`) or string
/// (`objref T{string} x`), decoded from the service path segment `x[…]`.
using ObjRefIndex = std::variant<std::monostate, std::int32_t, std::string>;

using PropertyGetter = std::function<Result<Value>(const SessionRef& session)>;
using PropertySetter = std::function<Result<void>(const SessionRef& session, Value value)>;
/// Completes a property set: call once, from any thread.
using SetCompletion = std::function<void(Result<void>)>;
/// Asynchronous forms: answer later (from any thread) through `done`, e.g. after device I/O.
using AsyncPropertyGetter = std::function<void(const SessionRef& session, Completion done)>;
using AsyncPropertySetter = std::function<void(const SessionRef& session, Value value, SetCompletion done)>;
/// Arguments in robdef parameter order, each unpacked and checked against its parameter type.
using FunctionHandler = std::function<Result<Value>(const SessionRef& session, std::vector<Value> args)>;
using AsyncFunctionHandler = std::function<void(const SessionRef& session, std::vector<Value> args, Completion done)>;
/// Arguments without the `{generator}` parameter.
using GeneratorFunctionHandler =
    std::function<Result<std::shared_ptr<Generator>>(const SessionRef& session, std::vector<Value> args)>;
/// Returns the object for the index (ObjectNotFound for an unknown index). The result must be of the
/// objref's type (or implement it); any object type for `varobject`.
using ObjRefResolver =
    std::function<Result<std::shared_ptr<ServiceObject>>(const SessionRef& session, const ObjRefIndex& index)>;

namespace detail {
/// What every member of an object shares: immutable after construction.
struct MemberInfo {
    std::shared_ptr<const ServiceTypes> types;
    const robdef::MemberDefinition* def = nullptr;
    std::string service_name;  ///< the definition holding the object type (context for unqualified names)
    std::weak_ptr<ServiceObject> owner;
};
}  // namespace detail

class ServiceObject : public std::enable_shared_from_this<ServiceObject> {
public:
    /// A new object of `object_type` (qualified, e.g. "experimental.interop_test.Root").
    /// Errors: InvalidArgument when `types` has no such object type.
    static Result<std::shared_ptr<ServiceObject>> create(std::shared_ptr<const ServiceTypes> types,
                                                         std::string_view object_type);
    ~ServiceObject();
    ServiceObject(const ServiceObject&) = delete;
    ServiceObject& operator=(const ServiceObject&) = delete;

    const std::string& type() const noexcept { return type_; }
    const robdef::ServiceEntryDefinition& definition() const noexcept { return *def_; }
    const std::shared_ptr<const ServiceTypes>& types() const noexcept { return types_; }
    /// A user exception of this object's service definition (ServiceTypes::user_error).
    RRError user_error(std::string_view exception, std::string message) const;

    // --- property ---------------------------------------------------------------------------------
    /// Stores the value served by gets (when no getter is set) and replaced by sets (when no setter is
    /// set). Checked against the property type (it is packed once here; gets then send the packed form).
    /// Errors: MemberNotFound; the packing error when the value does not fit the type.
    Result<void> set_property_value(std::string_view property, Value value);
    /// The stored value. Errors: MemberNotFound; ValueNotSet when none was stored.
    Result<Value> property_value(std::string_view property) const;
    /// Handlers replace the stored value for gets / sets; an empty function removes one.
    /// A property with neither a getter nor a stored value answers gets with ValueNotSet.
    /// Replaces the property's asynchronous handlers (both).
    Result<void> set_property_handlers(std::string_view property, PropertyGetter get, PropertySetter set = {});
    /// Asynchronous handlers: the reply waits for `done` (the client's own timeout still applies);
    /// an empty function removes one. Replaces the property's synchronous handlers (both). A value
    /// given to the getter's `done` is packed with the property type (a packing error is the reply).
    Result<void> set_async_property_handlers(std::string_view property, AsyncPropertyGetter get,
                                             AsyncPropertySetter set = {});

    // --- function ---------------------------------------------------------------------------------
    /// The return value is packed with the robdef return type (void: send Null; the reply carries
    /// int32 0). A function without a handler answers NotImplementedError.
    Result<void> set_function(std::string_view function, FunctionHandler handler);
    Result<void> set_async_function(std::string_view function, AsyncFunctionHandler handler);
    /// For functions with a `{generator}` return or last parameter only (else MemberNotFound).
    Result<void> set_generator_function(std::string_view function, GeneratorFunctionHandler handler);

    // --- event ------------------------------------------------------------------------------------
    /// Sends EventReq to every client session of the service, at every path of this object. `args` in
    /// parameter order, packed once. Thread-safe; returns once queued (never blocks).
    /// Errors: MemberNotFound; DataTypeError for a wrong argument count; packing errors;
    /// BufferLimitViolation when some client's send queue was full (that client misses the event, the
    /// others get it). Not bound to a service yet: nothing is sent, no error.
    Result<void> fire_event(std::string_view event, std::vector<Value> args);

    // --- objref -----------------------------------------------------------------------------------
    Result<void> set_objref(std::string_view objref, ObjRefResolver resolver);

    // --- pipe, callback, wire, memory -------------------------------------------------------------
    /// The member object (owned by this object). Errors: MemberNotFound (no such member of that kind).
    Result<std::shared_ptr<PipeMember>> pipe(std::string_view name) const;
    Result<std::shared_ptr<CallbackMember>> callback(std::string_view name) const;
    Result<std::shared_ptr<WireMember>> wire(std::string_view name) const;
    Result<std::shared_ptr<MemoryMember>> memory(std::string_view name) const;

    /// Service paths this object is currently served at (empty until a client resolved it / after
    /// release). Release one with ObjectService::release_path.
    std::vector<std::string> paths() const;
    /// Drops every handler of this object and its members (breaks reference cycles at shutdown).
    void clear_handlers();

    // --- used by ObjectService ----------------------------------------------------------------------
    struct Binding {
        std::shared_ptr<ObjectService> service;
        std::vector<std::string> paths;
    };
    /// The service and paths this object is bound to (service null when unbound).
    Binding binding() const;
    /// Records that the object is served by `service` at `path`. Errors: InvalidOperation when it is
    /// already served by another service.
    Result<void> bind(const std::shared_ptr<ObjectService>& service, const std::string& path);
    /// Forgets `path`: pipe endpoints and wire connections opened at it are dropped (on_close handlers
    /// run); the client learns of it through ServicePathReleasedReq.
    void unbind(const std::string& path);
    /// A client session ended: its pipe endpoints and wire connections are dropped.
    void session_closed(const SessionRef& session);
    /// Resolves objref member `member` with `index` (path segment already decoded).
    /// Errors: ObjectNotFound (no such objref member, index kind mismatch, resolver refusal).
    Result<std::shared_ptr<ServiceObject>> resolve_objref(const SessionRef& session, std::string_view member,
                                                          std::string_view index_text, bool has_index);
    /// Dispatches one member request or packet (wire.md §6.7) at `path`. Runs on the session's strand.
    void handle_entry(ObjectService& service, const SessionRef& session, MessageEntry&& entry, Responder&& responder);
    /// Member info for a member name, or nullptr.
    std::shared_ptr<const detail::MemberInfo> member_info(std::string_view name) const;

private:
    struct Slot;
    ServiceObject(std::shared_ptr<const ServiceTypes> types, const robdef::ServiceEntryDefinition* def,
                  std::string type, std::string service_name);
    Slot* find_slot(std::string_view name) const noexcept;
    Result<Slot*> slot_of(std::string_view name, robdef::MemberKind kind) const;

    void handle_property_get(Slot& slot, const SessionRef& session, MessageEntry&& entry, Responder&& responder);
    void handle_property_set(Slot& slot, const SessionRef& session, MessageEntry&& entry, Responder&& responder);
    void handle_function(ObjectService& service, Slot& slot, const SessionRef& session, MessageEntry&& entry,
                         Responder&& responder);

    const std::shared_ptr<const ServiceTypes> types_;
    const robdef::ServiceEntryDefinition* const def_;
    const std::string type_;
    const std::string service_name_;
    std::vector<std::unique_ptr<Slot>> slots_;  // one per robdef member, by name length, then name
    std::vector<std::string_view> slot_names_;  // slots_[i]'s member name (the robdef's string): one flat search
    mutable std::mutex mutex_;                  // guards handlers/stored values in slots and the binding
    std::weak_ptr<ObjectService> service_;
    std::vector<std::string> paths_;
};

}  // namespace rr::server
