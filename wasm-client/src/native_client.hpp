// NativeClient: one RR client session (core's ClientContext) driven by the JS event loop; exposed to JS
// by bindings.cpp. The JS layer (robotraconteur.mjs) owns the WebSocket and the timer: it passes received
// bytes to feed(), sends what take_output() returns, and calls on_timer() at next_deadline(). Times are
// milliseconds: `now` from performance.now() (monotonic), `wall_ms` from Date.now().
//
// Exceptions are off (-fno-exceptions, as core/): synchronous calls return {ok: true, value} or
// {ok: false, error: {name, message, code}}; asynchronous calls take `cb(error | null, value)`. Values are
// converted by js_values.hpp, typed by the member's robdef.
//
// Re-entrancy: JS functions handed in here (completions, handlers) are called from within feed() /
// on_timer(); the JS layer defers user code to a microtask, so it never re-enters feed().
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <emscripten/val.h>

#include "core/session/client_context.hpp"

namespace rr::wasm {

using emscripten::val;

/// A member's robdef definition and the service its unqualified type names belong to.
struct Typed {
    const robdef::MemberDefinition* member = nullptr;
    std::string ctx;
};

class NativeClient {
public:
    /// `config`: {service, targetNodeId, targetNodeName, nodeName, username, password, requestTimeoutMs,
    /// heartbeatPeriodMs?, receiveTimeoutMs? (default 10000 / 15000, wire.md §6.3),
    /// nodeId: Uint8Array(16) (random, from the host), endpoint: uint32 (random, non-zero), now}.
    explicit NativeClient(val config);

    void set_handlers(val connected, val closed, val released);

    // --- pump ---------------------------------------------------------------------------------------
    val feed(val bytes, double now);
    val take_output();
    double next_deadline() const;
    void on_timer(double now);
    void transport_closed(std::string message);
    void disconnect(double now);
    bool is_connected() const;
    bool is_closed() const;

    // --- description --------------------------------------------------------------------------------
    val info() const;

    /// {type, implements, members: [{name, kind, type, params: [{name, type}], generator, readonly, writeonly}]}
    val describe(std::string path) const;

    // --- properties ---------------------------------------------------------------------------------
    void property_get(std::string path, std::string member, double now, val cb);
    void property_set(std::string path, std::string member, val value, double now, val cb);

    // --- functions and generators -------------------------------------------------------------------
    void call(std::string path, std::string member, val args, double now, val cb);
    void call_generator(std::string path, std::string member, val args, double now, val cb);
    void generator_next(double id, val param, double now, val cb);
    void generator_close(double id, bool abort, double now, val cb);

    // --- objrefs ------------------------------------------------------------------------------------
    void objref(std::string path, std::string member, val index, double now, val cb);

    // --- events and callbacks -----------------------------------------------------------------------
    /// `handler(args: any[])` for every event. Returns {ok, value: subscription id}.
    val subscribe_event(std::string path, std::string member, val handler);
    void unsubscribe_event(double id);

    /// `handler(args: any[], replyId: number)`; the JS layer answers with callbackReply(replyId, …).
    /// A null handler clears the callback.
    val set_callback(std::string path, std::string member, val handler);
    /// Answers callback call `id` with `error` (an {name, message} object) or `value`.
    void callback_reply(double id, val error, val value);

    // --- pipes --------------------------------------------------------------------------------------
    void pipe_connect(std::string path, std::string member, int index, double now, val cb);
    /// `packets()` when packets were queued (take them with pipeReceive), `ack(n)`, `closed(error)`.
    val pipe_set_handlers(double id, val packets, val ack, val closed);
    val pipe_send(double id, val value, double now);
    /// {ok, value: packet} or {ok, value: undefined} when none is queued.
    val pipe_receive(double id);
    void pipe_close(double id, double now, val cb);

    // --- wires --------------------------------------------------------------------------------------
    void wire_connect(std::string path, std::string member, double now, val cb);
    /// `value({value, ts})` for every newer InValue; `closed(error)`.
    val wire_set_handlers(double id, val value, val closed);
    val wire_in_value(double id, double now);
    val wire_out_value(double id, double now);
    val wire_set_out_value(double id, val value, double wall_ms, double now);
    val wire_set_lifespans(double id, int in_ms, int out_ms);
    void wire_close(double id, double now, val cb);
    void wire_peek(std::string path, std::string member, bool in, double now, val cb);
    void wire_poke(std::string path, std::string member, val value, double wall_ms, double now, val cb);

    // --- memories -----------------------------------------------------------------------------------
    /// `what`: "length" (array memories), "dimcount" or "dimensions" (multi-dim memories).
    void memory_param(std::string path, std::string member, std::string what, double now, val cb);
    /// `start`/`count`: numbers (array memories) or arrays of numbers (multi-dim memories).
    void memory_read(std::string path, std::string member, val start, val count, double now, val cb);
    void memory_write(std::string path, std::string member, val start, val data, double now, val cb);

    // --- monitor lock (ClientSessionOp 1107/1108) -----------------------------------------------------
    /// MonitorEnter on the object at `path` (`timeout_ms`, −1 = wait forever) or, with `enter` false, MonitorExit.
    void monitor(std::string path, bool enter, int timeout_ms, double now, val cb);

private:
    struct GeneratorTypes {
        robdef::TypeDefinition return_type;
        std::optional<robdef::TypeDefinition> param_type;
        std::string ctx;
    };
    struct PendingReply {
        Completion<Value> reply;
        Typed typed;
    };

    static ClientContextConfig make_config(const val& c);
    val object_to_js(const ObjectRef& r) const;
    Result<Typed> typed(const std::string& path, const std::string& member) const;
    static robdef::TypeDefinition without_generator(robdef::TypeDefinition t);
    Result<std::vector<Value>> args_from_js(const Typed& t, const val& args, std::size_t n) const;
    Result<emscripten::val> values_to_js(const std::vector<Value>& values,
                                         const std::vector<robdef::TypeDefinition>& types, const std::string& ctx) const;

    /// Calls `cb(error)` or `cb(null, value as JS)`.
    void deliver(const val& cb, const Result<Value>& r, const robdef::TypeDefinition& type, const std::string& ctx);
    static Completion<void> void_completion(val cb);
    val wire_value(double id, double now, bool in);
    static std::optional<std::uint64_t> u64(const val& v);
    static std::optional<std::vector<std::uint64_t>> u64_list(const val& v);

    ClientContext ctx_;
    val on_connected_ = val::undefined();
    val on_closed_ = val::undefined();
    val on_released_ = val::undefined();
    std::vector<std::byte> in_, out_;
    std::map<std::uint64_t, GeneratorTypes> generators_;
    std::map<std::uint64_t, Typed> pipe_types_;
    std::map<std::uint64_t, Typed> wire_types_;
    std::map<std::uint64_t, PendingReply> replies_;
    std::uint64_t next_reply_ = 0;
};

}  // namespace rr::wasm
