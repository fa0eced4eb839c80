#include "server/gateway/auth/mirror_access.hpp"

namespace rr::server::gateway::auth {

std::optional<Operation> operation_for_request(MessageEntryType type) noexcept {
    using T = MessageEntryType;
    switch (type) {
        case T::PropertyGetReq:
        case T::WireConnectReq:
        case T::WirePeekInValueReq:
        case T::WirePeekOutValueReq:
        case T::MemoryRead:
        case T::MemoryGetParam:
        case T::PipeConnectReq: return Operation::read;
        case T::PropertySetReq:
        case T::WirePacket:
        case T::WirePokeOutValueReq:
        case T::MemoryWrite:
        case T::PipePacket: return Operation::write;
        case T::FunctionCallReq:
        case T::GeneratorNextReq: return Operation::call;
        default: return std::nullopt;
    }
}

bool is_lock_operation(std::string_view op) noexcept {
    return op == "RequestObjectLock" || op == "RequestClientObjectLock" || op == "ReleaseObjectLock" ||
           op == "ReleaseClientObjectLock" || op == "MonitorEnter" || op == "MonitorContinueEnter" || op == "MonitorExit";
}

namespace {

std::string_view relative_path(std::string_view service, std::string_view path) {
    if (path.size() > service.size() + 1 && path.substr(0, service.size()) == service && path[service.size()] == '.')
        return path.substr(service.size() + 1);
    return {};
}

}  // namespace

std::string object_key_for_path(std::string_view service, std::string_view path) {
    return std::string(relative_path(service, path));
}

std::string member_key_for_path(std::string_view service, std::string_view path, std::string_view member) {
    return member_key(relative_path(service, path), member);
}

bool MirrorAccess::may(const SessionRef& session, std::string_view path, std::string_view member, Operation op) const {
    if (!active()) return true;
    auto who = auth_->principal_for_user(session.username());
    return who && who->allows(device_, member_key_for_path(device_, path, member), op);
}

std::optional<RRError> MirrorAccess::check(const SessionRef& session, const MessageEntry& entry) const {
    if (!active()) return std::nullopt;
    const bool lock = entry.entry_type == MessageEntryType::ClientSessionOpReq && is_lock_operation(entry.member_name);
    auto op = lock ? std::optional<Operation>(Operation::lock) : operation_for_request(entry.entry_type);
    if (!op) return std::nullopt;
    const std::string user = session.username();
    auto who = auth_->principal_for_user(user);
    const std::string key = lock ? object_key_for_path(device_, entry.service_path)
                                 : member_key_for_path(device_, entry.service_path, entry.member_name);
    if (who && who->allows(device_, key, *op)) return std::nullopt;
    // A pipe endpoint or wire connection is for receiving, sending, or both: either permission opens it
    // (what flows is checked packet by packet).
    const bool connect = entry.entry_type == MessageEntryType::PipeConnectReq || entry.entry_type == MessageEntryType::WireConnectReq;
    if (who && connect && who->allows(device_, key, Operation::write)) return std::nullopt;
    auth_->counters().denied.fetch_add(1);
    return make_error(MessageErrorType::PermissionDenied, (user.empty() ? std::string("anonymous") : "user " + user) +
                                                              " may not " + std::string(operation_name(*op)) + " " +
                                                              refused_target(key, *op) + " of " + device_);
}

}  // namespace rr::server::gateway::auth
