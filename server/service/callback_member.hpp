// The service side of a callback member (robdef `callback R name(params)`; wire.md §6.7 "callback"):
// the service calls a function the client provides. CallbackCallReq 1151 (service → client, RequestID
// chosen per connection by ServerConnection, parameters by name) → CallbackCallRet 1152 (`return`,
// int32 0 for void).
//
// Threads: call() may be used from any thread; `done` runs once, on the client session's strand (or at
// once on the calling thread for an argument error or a closed session).
#pragma once

#include <memory>
#include <string_view>
#include <vector>

#include "server/service/service_object.hpp"

namespace rr::server {

class CallbackMember {
public:
    /// Calls the callback on `session`'s client at the object's first service path. `args` in
    /// parameter order, checked against the robdef. `done` gets the return value (Null for void)
    /// unpacked with the return type, or an error: the client's error (its code and name, e.g. a
    /// RemoteError), RequestTimeout (ServerConnectionConfig::callback_timeout), ConnectionError,
    /// InvalidOperation (object not served), DataTypeError (wrong argument count) or a packing error.
    void call(const SessionRef& session, std::vector<Value> args, Completion done) const;

    const std::string& name() const noexcept;

    // --- used by ServiceObject ---
    explicit CallbackMember(std::shared_ptr<const detail::MemberInfo> info) : info_(std::move(info)) {}

private:
    const std::shared_ptr<const detail::MemberInfo> info_;
};

}  // namespace rr::server
