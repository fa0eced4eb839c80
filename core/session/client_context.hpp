// The typed client of one RR service connection, sans-IO: ClientSession (entry level) plus the received
// service definitions, so that every member is addressed by service path + member name and every value
// is checked against (and packed/unpacked by) the robdef (robdef.md §16–§17, wire.md §3.2, §6.4–§6.7).
//
// Member kinds (wire.md §6.7): property get/set, function call, generator functions (next / close /
// abort), objrefs (plain, int32- or string-indexed, varobject), events, callbacks, pipes (connect,
// packets with numbers and acknowledgements, unreliable, closed by the service), wires (connect,
// InValue/OutValue with time stamps and lifespans, peek/poke, closed by the service), memories
// (numeric, pod and namedarray; 1-D and multi-dim; chunked by MaxTransferSize), and the monitor lock.
//
// I/O is the same as ClientSession's: bytes in with feed(), bytes out with take_output() /
// pending_output() + consume_output(), time with next_deadline() / on_timer(now). Every operation
// takes the host's monotonic `now`; wire operations that send a value also take the wall-clock time to
// stamp it with (the context reads no clock).
//
// Completions and handlers are called from feed() / on_timer() / on_transport_closed() (and, for
// failures found before sending, from the initiating call). They may start new operations on the same
// context (re-entrancy is safe), but must not call feed(), on_timer() or destroy the context.
//
// Errors: the service's errors arrive as RRError with the service's code and name (user errors keep
// their `svc.ExceptionName` with type RemoteError); local checks give MemberNotFound, ObjectNotFound,
// InvalidArgument (argument count, index kind), ReadOnlyMember / WriteOnlyMember (direction),
// DataTypeMismatch / DataTypeError / NullValue (values not matching the robdef), RequestTimeout,
// ConnectionError (connection closed), InvalidOperation (closed handle, member of the wrong kind).
//
// Not thread-safe: one owner drives it (a strand in server/, the JS event loop in wasm-client/).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/session/client_session.hpp"
#include "core/session/client_types.hpp"
#include "core/session/request_map.hpp"
#include "robdef/service_definition_set.hpp"

namespace rr {

struct ClientContextConfig {
    ClientSessionConfig session;
    /// Largest memory transfer this client makes, bytes; the smaller of this and the service's
    /// MaxTransferSize is used (wire.md §6.7; CORE default 102 400).
    std::uint32_t memory_max_transfer_size = 102400;
};

class ClientContext {
public:
    ClientContext(ClientContextConfig config, MonoTime now);
    ~ClientContext();
    ClientContext(const ClientContext&) = delete;
    ClientContext& operator=(const ClientContext&) = delete;

    // --- I/O pump (as ClientSession) ---------------------------------------------------------------
    Result<void> feed(std::span<const std::byte> bytes, MonoTime now);
    /// See StreamConnection::read_space.
    std::span<std::byte> read_space() { return session_.read_space(); }
    void on_transport_closed(RRError error);
    std::span<const std::byte> pending_output() const { return session_.pending_output(); }
    void consume_output(std::size_t n) { session_.consume_output(n); }
    void take_output(GatherBuffer& out) { session_.take_output(out); }
    void take_output(std::vector<std::byte>& out) { session_.take_output(out); }
    std::size_t pending_output_size() const noexcept { return session_.pending_output_size(); }
    std::optional<MonoTime> next_deadline() const { return session_.next_deadline(); }
    void on_timer(MonoTime now);
    bool is_connected() const noexcept { return connected_ && session_.is_connected(); }
    bool is_closed() const noexcept { return session_.is_closed(); }

    // --- connection --------------------------------------------------------------------------------
    /// Called once: with the root object when the client session is established and the service
    /// definitions are parsed, or with the error when connecting failed.
    void set_connect_handler(Completion<ObjectRef> handler) { on_connect_ = std::move(handler); }
    /// Called once when an established session ends (after every pending completion failed).
    void set_closed_handler(std::function<void(const RRError&)> handler) { on_closed_ = std::move(handler); }
    /// Called when the service releases a service path (ServicePathReleasedReq, wire.md §6.5); objects at
    /// and below it are forgotten, their pipe endpoints and wire connections closed.
    void set_path_released_handler(std::function<void(const std::string&)> handler) {
        on_path_released_ = std::move(handler);
    }
    /// DisconnectClient, then close (wire.md §6.6). Pending operations fail with ConnectionError.
    void disconnect(MonoTime now);

    const ClientSessionInfo& info() const noexcept { return session_.info(); }
    const ClientSession& session() const noexcept { return session_; }
    /// The definitions received from the service (plus any pulled later for objref types).
    const robdef::ServiceDefinitionSet& definitions() const noexcept { return defs_; }
    /// The root object (path = service name); valid once connected.
    const ObjectRef& root() const noexcept { return root_; }
    /// A known object (the root, or one returned by objref() and not released since).
    std::optional<ObjectRef> object(std::string_view path) const;
    /// True when the object at `path` is of qualified type `type` or declares to implement it.
    bool implements(std::string_view path, std::string_view type) const;
    /// The definition of `member` of the object at `path`. Errors: ObjectNotFound, MemberNotFound.
    Result<const robdef::MemberDefinition*> member_definition(std::string_view path, std::string_view member) const;
    /// The last `now` passed to any call (for handlers that start operations).
    MonoTime now() const noexcept { return now_; }

    // --- properties (1111–1114) --------------------------------------------------------------------
    void property_get(std::string_view path, std::string_view member, MonoTime now, Completion<Value> done);
    void property_set(std::string_view path, std::string_view member, Value value, MonoTime now,
                      Completion<void> done);

    // --- functions (1121/1122) ---------------------------------------------------------------------
    /// Calls a non-generator function with its parameters in order; the result is Null for void.
    void call(std::string_view path, std::string_view member, std::vector<Value> args, MonoTime now,
              Completion<Value> done);
    /// Calls a generator function (return `T{generator}` and/or last parameter `T{generator}`); `args`
    /// are the parameters before the generator parameter.
    void call_generator(std::string_view path, std::string_view member, std::vector<Value> args, MonoTime now,
                        Completion<GeneratorHandle> done);
    /// GeneratorNextReq (1123). `parameter` is required exactly when the function has a generator
    /// parameter. Result: the next value (Null for a void return); error StopIteration at the end.
    void generator_next(GeneratorHandle g, std::optional<Value> parameter, MonoTime now, Completion<Value> done);
    /// Close (request with Error StopIteration) / abort (Error AbortOperation); the handle is released.
    void generator_close(GeneratorHandle g, MonoTime now, Completion<void> done);
    void generator_abort(GeneratorHandle g, MonoTime now, Completion<void> done);

    // --- objrefs (103/104) -------------------------------------------------------------------------
    /// The object behind objref `member` (with `index` for `{int32}` / `{string}` objrefs). Known
    /// objects are answered from the cache; definitions of unknown object types are pulled first.
    void objref(std::string_view path, std::string_view member, ObjRefIndex index, MonoTime now,
                Completion<ObjectRef> done);

    // --- events (1131) -----------------------------------------------------------------------------
    /// Subscribes to event `member` of the object at `path`. Returns the subscription id.
    /// Errors: ObjectNotFound, MemberNotFound, InvalidOperation (not an event).
    Result<std::uint64_t> subscribe_event(std::string_view path, std::string_view member, EventHandler handler);
    void unsubscribe_event(std::uint64_t subscription);

    // --- callbacks (1151/1152) ---------------------------------------------------------------------
    /// Sets (or with an empty handler clears) the handler of callback `member` at `path`.
    Result<void> set_callback(std::string_view path, std::string_view member, CallbackHandler handler);
    /// As set_callback, with a handler that may answer after it returns; the CallbackCallRet is sent when
    /// it calls `reply` (nothing is sent if the connection closed meanwhile).
    Result<void> set_deferred_callback(std::string_view path, std::string_view member,
                                       DeferredCallbackHandler handler);

    // --- pipes (1141–1147) -------------------------------------------------------------------------
    /// PipeConnectReq with `index` (−1 = the service chooses).
    void pipe_connect(std::string_view path, std::string_view member, std::int32_t index, MonoTime now,
                      Completion<PipeEndpointHandle> done);
    Result<void> set_pipe_handlers(PipeEndpointHandle ep, PipeEndpointHandlers handlers);
    /// Ask the service to acknowledge every following packet (`requestack`).
    Result<void> set_pipe_request_ack(PipeEndpointHandle ep, bool request_ack);
    /// Sends a packet; returns its packet number (1, 2, … per endpoint, as CORE).
    /// Errors: ReadOnlyMember (`[readonly]` pipe), InvalidOperation (closed), value errors.
    Result<std::uint32_t> pipe_send(PipeEndpointHandle ep, const Value& packet, MonoTime now);
    /// Takes the oldest received packet; nullopt when none is queued.
    std::optional<Value> pipe_receive(PipeEndpointHandle ep);
    std::size_t pipe_available(PipeEndpointHandle ep) const;
    Result<PipeEndpointInfo> pipe_info(PipeEndpointHandle ep) const;
    /// PipeDisconnectReq (or nothing when the service already closed it); releases the handle.
    void pipe_close(PipeEndpointHandle ep, MonoTime now, Completion<void> done);

    // --- wires (1161–1167, 1181–1186) --------------------------------------------------------------
    void wire_connect(std::string_view path, std::string_view member, MonoTime now,
                      Completion<WireConnectionHandle> done);
    Result<void> set_wire_handlers(WireConnectionHandle c, WireConnectionHandlers handlers);
    /// The newest InValue. Errors: WriteOnlyMember, ValueNotSet (none yet, or older than the lifespan).
    Result<WireValue> wire_in_value(WireConnectionHandle c, MonoTime now) const;
    /// The last OutValue sent. Errors: ReadOnlyMember, ValueNotSet.
    Result<WireValue> wire_out_value(WireConnectionHandle c, MonoTime now) const;
    /// Sends a WirePacket stamped `wall_now` (made strictly increasing per connection, as CORE).
    Result<void> wire_set_out_value(WireConnectionHandle c, Value value, TimeSpec wall_now, MonoTime now);
    /// Lifespans of InValue / OutValue in ms (−1 = forever, the default).
    Result<void> set_wire_lifespans(WireConnectionHandle c, std::int32_t in_ms, std::int32_t out_ms);
    Result<WireConnectionInfo> wire_info(WireConnectionHandle c) const;
    /// WireDisconnectReq (or nothing when the service already closed it); releases the handle.
    void wire_close(WireConnectionHandle c, MonoTime now, Completion<void> done);
    void wire_peek_in_value(std::string_view path, std::string_view member, MonoTime now, Completion<WireValue> done);
    void wire_peek_out_value(std::string_view path, std::string_view member, MonoTime now, Completion<WireValue> done);
    void wire_poke_out_value(std::string_view path, std::string_view member, Value value, TimeSpec wall_now,
                             MonoTime now, Completion<void> done);

    // --- memories (1171–1176) ----------------------------------------------------------------------
    /// MemoryGetParam `Length` (array memories) / `DimCount`, `Dimensions` (multi-dim memories).
    void memory_length(std::string_view path, std::string_view member, MonoTime now, Completion<std::uint64_t> done);
    void memory_dim_count(std::string_view path, std::string_view member, MonoTime now, Completion<std::uint64_t> done);
    void memory_dimensions(std::string_view path, std::string_view member, MonoTime now,
                           Completion<std::vector<std::uint64_t>> done);
    /// Reads `count` items from `pos` of an array memory: a NumericArray, PodArray or NamedArray.
    void memory_read(std::string_view path, std::string_view member, std::uint64_t pos, std::uint64_t count,
                     MonoTime now, Completion<Value> done);
    /// Writes all items of `data` (NumericArray / PodArray / NamedArray of the memory's type) at `pos`.
    void memory_write(std::string_view path, std::string_view member, std::uint64_t pos, Value data, MonoTime now,
                      Completion<void> done);
    /// Reads the block at `pos` of shape `count` of a multi-dim memory: a MultiDimArray, or a PodArray /
    /// NamedArray with dims = `count` (column-major).
    void memory_read(std::string_view path, std::string_view member, std::vector<std::uint64_t> pos,
                     std::vector<std::uint64_t> count, MonoTime now, Completion<Value> done);
    /// Writes `data` (its dims are the block shape) at `pos` of a multi-dim memory.
    void memory_write(std::string_view path, std::string_view member, std::vector<std::uint64_t> pos, Value data,
                      MonoTime now, Completion<void> done);

    // --- session operations (1107/1108) ------------------------------------------------------------
    /// MonitorEnter (`timeout` ms; repeats MonitorContinueEnter while the service answers `Continue`).
    void monitor_enter(std::string_view path, std::int32_t timeout_ms, MonoTime now, Completion<void> done);
    void monitor_exit(std::string_view path, MonoTime now, Completion<void> done);

    // Per-kind state (client_state.hpp); public only so the per-kind sources can name it.
    struct ObjectState;
    struct GeneratorState;
    struct PipeState;
    struct WireState;
    struct MemoryCaps;
    struct MemoryOp;

private:
    using Reply = std::function<void(Result<MessageEntry>)>;

    // requests and dispatch (client_context.cpp)
    void pump_events(MonoTime now);
    void on_connected(MonoTime now);
    void on_session_closed(const RRError& error);
    void on_incoming(MessageEntry&& e, MonoTime now);
    void send_request(MessageEntry&& e, MonoTime now, Reply k);
    Result<void> send_packet(MessageEntry&& e, MonoTime now);
    Result<const ObjectState*> find_object(std::string_view path) const;
    Result<const robdef::MemberDefinition*> find_member(std::string_view path, std::string_view member,
                                                         robdef::MemberKind kind, const ObjectState** obj = nullptr) const;
    Result<MessageElement> pack(const Value& v, const robdef::TypeDefinition& t, std::string_view name,
                                std::string_view context_service) const;
    Result<Value> unpack(const MessageElement& e, const robdef::TypeDefinition& t,
                         std::string_view context_service) const;
    void resolve_object(std::string path, std::string type, std::vector<std::string> implements, MonoTime now,
                        Completion<ObjectRef> done);
    void pull_definition(std::string service, MonoTime now, Completion<void> done);
    void pull_imports(std::vector<std::string> missing, MonoTime now, Completion<void> done);
    void release_path(const std::string& path);
    void on_event(MessageEntry&& e);
    void on_callback_call(MessageEntry&& e, MonoTime now);
    void session_op(std::string_view path, std::string op, std::vector<MessageElement> elements, MonoTime now,
                    Completion<std::string> done);
    void monitor_continue(std::string path, MonoTime now, Completion<void> done);
    void fail_all_handles(const RRError& error);

    // pipes (client_pipes.cpp)
    void on_pipe_entry(MessageEntry&& e, MonoTime now);
    void close_pipe_state(std::uint64_t id, const RRError& error);
    // wires (client_wires.cpp)
    void on_wire_entry(MessageEntry&& e, MonoTime now);
    void close_wire_state(std::uint64_t id, const RRError& error);
    void wire_peek(std::string_view path, std::string_view member, MessageEntryType type, MonoTime now,
                   Completion<WireValue> done);
    // memories (client_memory.cpp)
    void memory_param(std::string_view path, std::string_view member, std::string_view param, MonoTime now,
                      Completion<MessageElement> done);
    void memory_caps(std::string_view path, std::string_view member, bool multidim, MonoTime now,
                     Completion<std::shared_ptr<const MemoryCaps>> done);
    void memory_step(std::shared_ptr<MemoryOp> op, MonoTime now);

    ClientContextConfig config_;
    ClientSession session_;
    robdef::ServiceDefinitionSet defs_;
    ObjectRef root_;
    bool connected_ = false;
    MonoTime now_;
    std::uint64_t next_id_ = 0;

    RequestMap<Reply> replies_;
    std::map<std::string, std::unique_ptr<ObjectState>, std::less<>> objects_;
    std::map<std::uint64_t, std::unique_ptr<GeneratorState>> generators_;
    std::map<std::uint64_t, std::unique_ptr<PipeState>> pipes_;
    std::map<std::uint64_t, std::unique_ptr<WireState>> wires_;
    std::map<std::string, std::shared_ptr<const MemoryCaps>, std::less<>> memory_caps_;

    struct EventSubscription {
        std::string path, member;
        std::shared_ptr<EventHandler> handler;
    };
    std::map<std::uint64_t, EventSubscription> events_;
    std::map<std::string, std::shared_ptr<DeferredCallbackHandler>, std::less<>> callbacks_;  // key: path + '\n' + member
    /// Pipe connects in flight: key path + '\n' + member → requested indexes (for early packets).
    std::map<std::string, std::vector<std::int32_t>, std::less<>> pipe_connecting_;
    /// Open pipe endpoints: key path + '\n' + member + '\n' + index → id.
    std::map<std::string, std::uint64_t, std::less<>> pipe_index_;
    /// Open wire connections: key path + '\n' + member → id.
    std::map<std::string, std::uint64_t, std::less<>> wire_index_;
    /// Wire connects in flight: key → the newest value that arrived before the WireConnectRet.
    std::map<std::string, std::shared_ptr<const WireValue>, std::less<>> wire_connecting_;

    Completion<ObjectRef> on_connect_;
    std::function<void(const RRError&)> on_closed_;
    std::function<void(const std::string&)> on_path_released_;
};

}  // namespace rr
