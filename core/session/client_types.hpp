// Value types of the typed client (client_context.hpp): object references, handles of pipe endpoints,
// wire connections and generators, wire values, and the handler signatures.
//
// Handles are plain ids issued by one ClientContext; they are only meaningful to the context that
// issued them. An id is never reused within one context.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <variant>
#include <vector>

#include "base/error/rr_error.hpp"
#include "core/session/stream_connection.hpp"
#include "core/value/timespec.hpp"
#include "core/value/value.hpp"

namespace rr {

/// An object of the connected service (wire.md §6.5): its service path (`svc`, `svc.child`,
/// `svc.child_by_int[%2d1]`), the qualified object type the service reported (ObjectTypeName /
/// `objecttype`), and the types it declares to implement (`objectimplements`, which CORE sends as
/// written in the definition; qualified here with the object's service name when written unqualified).
struct ObjectRef {
    std::string path;
    std::string type;
    std::vector<std::string> implements;

    friend bool operator==(const ObjectRef&, const ObjectRef&) = default;
};

/// Index of an objref member: none (`objref T name`), an int32 key (`objref T{int32} name`) or a
/// string key (`objref T{string} name`).
using ObjRefIndex = std::variant<std::monostate, std::int32_t, std::string>;

/// A generator returned by a generator function (wire.md §6.7). 0 = none.
struct GeneratorHandle {
    std::uint64_t id = 0;
    explicit operator bool() const noexcept { return id != 0; }
    friend bool operator==(const GeneratorHandle&, const GeneratorHandle&) = default;
};

/// A connected pipe endpoint. 0 = none.
struct PipeEndpointHandle {
    std::uint64_t id = 0;
    explicit operator bool() const noexcept { return id != 0; }
    friend bool operator==(const PipeEndpointHandle&, const PipeEndpointHandle&) = default;
};

/// A connected wire connection. 0 = none.
struct WireConnectionHandle {
    std::uint64_t id = 0;
    explicit operator bool() const noexcept { return id != 0; }
    friend bool operator==(const WireConnectionHandle&, const WireConnectionHandle&) = default;
};

/// A wire value: the value, the sender's time stamp (`packettime`, wall clock, wire.md §3.2) and the
/// local monotonic time it was received, sent or answered (age = now − local_time).
struct WireValue {
    Value value;
    TimeSpec timestamp;
    MonoTime local_time{};
};

/// Facts about a connected pipe endpoint.
struct PipeEndpointInfo {
    std::string path;
    std::string member;
    std::int32_t index = 0;  ///< the index the service assigned
    bool unreliable = false;
    bool readable = true;    ///< false for a `[writeonly]` pipe
    bool writable = true;    ///< false for a `[readonly]` pipe
    bool closed = false;
};

/// Facts about a connected wire connection.
struct WireConnectionInfo {
    std::string path;
    std::string member;
    bool readable = true;    ///< InValue available (false for `[writeonly]`)
    bool writable = true;    ///< OutValue may be set (false for `[readonly]`)
    bool closed = false;
};

/// Completion of an asynchronous operation. Called exactly once: from feed()/on_timer() when the
/// answer arrives or the request times out or the connection closes, or before the initiating call
/// returns when the operation fails before anything was sent (unknown member, value not matching the
/// robdef, not connected, …).
template <class T>
using Completion = std::function<void(Result<T>)>;

/// Event handler: the object path the event came from and the event's parameters, unpacked by the
/// robdef in parameter order.
using EventHandler = std::function<void(const std::string& path, std::vector<Value>& args)>;

/// Callback handler: gets the unpacked parameters, returns the value to send back (Null for a void
/// callback) or an error, which the service receives as an error reply (user errors keep their name).
using CallbackHandler = std::function<Result<Value>(std::vector<Value>& args)>;

/// Callback handler that answers later (e.g. a JavaScript async function): gets the unpacked parameters
/// and a `reply` to call exactly once with the value or error to send back. `reply` may be called from
/// within the handler or later from the context's owner, but only while the context exists.
using DeferredCallbackHandler = std::function<void(std::vector<Value>& args, Completion<Value> reply)>;

/// Pipe endpoint handlers (any may be empty). `packets` is called after one or more packets were
/// queued on the endpoint (take them with ClientContext::pipe_receive); `ack` for every packet
/// acknowledgement (PipePacketRet, the packet number given by pipe_send); `closed` once when the service
/// closed the endpoint (PipeClosed) or the connection or service path went away.
struct PipeEndpointHandlers {
    std::function<void(PipeEndpointHandle)> packets;
    std::function<void(PipeEndpointHandle, std::uint32_t packet_number)> ack;
    std::function<void(PipeEndpointHandle, const RRError&)> closed;
};

/// Wire connection handlers (any may be empty): `value` for every newer InValue, `closed` once when the
/// service closed the connection (WireClosed) or the connection or service path went away.
struct WireConnectionHandlers {
    std::function<void(WireConnectionHandle, const WireValue&)> value;
    std::function<void(WireConnectionHandle, const RRError&)> closed;
};

}  // namespace rr
