// Internal helpers shared by the member implementations of server/service (not a public API):
// request element access with CORE's error codes, and packing/unpacking against a member's robdef.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "core/session/elements.hpp"
#include "core/value/pack_value.hpp"
#include "server/service/service_object.hpp"

namespace rr::server::detail {

/// The element `name` of `entry`. Errors: MessageElementNotFound ("Element <name> not found.", CORE's text).
inline Result<const MessageElement*> require_element(const MessageEntry& entry, std::string_view name) {
    if (const auto* e = entry.find(name)) return e;
    return fail(MessageErrorType::MessageElementNotFound, "Element " + std::string(name) + " not found.");
}

/// A numeric scalar element of type T (the first item, as CORE's RRArrayToScalar).
/// Errors: MessageElementNotFound, DataTypeMismatch ("Data type cast error"), OutOfRange (no items).
template <class T>
Result<T> require_scalar(const MessageEntry& entry, std::string_view name) {
    auto e = require_element(entry, name);
    if (!e) return e.take_error();
    if ((*e)->type != data_type_of<T>()) return fail(MessageErrorType::DataTypeMismatch, "Data type cast error");
    if ((*e)->data.size() < sizeof(T)) return fail(MessageErrorType::OutOfRange, "Index out of range");
    T v;
    std::memcpy(&v, (*e)->data.data(), sizeof(T));
    return v;
}

/// Unpacks a value a client sent. A value that does not fit the type (wrong kind or numeric type, wrong
/// count, null where not allowed, missing struct field) is DataTypeError, as the official library answers;
/// the message names the path and the expected type.
inline Result<Value> unpack_member(const MemberInfo& info, const MessageElement& e, const robdef::TypeDefinition& type) {
    auto r = unpack_value(e, type, info.types->set(), info.service_name);
    if (!r) {
        const auto t = r.error().type;
        if (t == MessageErrorType::DataTypeMismatch || t == MessageErrorType::NullValue ||
            t == MessageErrorType::MessageElementNotFound)
            return fail(MessageErrorType::DataTypeError, r.error().message);
    }
    return r;
}

inline Result<MessageElement> pack_member(const MemberInfo& info, const Value& v, const robdef::TypeDefinition& type,
                                          std::string_view name) {
    return pack_value(v, type, name, info.types->set(), info.service_name);
}

/// Appends `return` of a function/generator/callback reply to `reply`: int32 0 for void (CORE's
/// convention), else the value packed with `type`. Errors: as pack_value (`reply` is then unchanged).
inline Result<void> append_return(MessageEntry& reply, const MemberInfo& info, const Value& v,
                                  const robdef::TypeDefinition& type) {
    if (type.is_void()) {
        // CORE answers a void function with an int32 0 named "return"; its bytes are a constant, so a
        // reply allocates nothing for them, and the element is built where it stays (issue 14).
        static constexpr std::byte kZero[sizeof(std::int32_t)]{};
        MessageElement& e = reply.elements.emplace_back();
        e.name = "return";
        e.type = DataTypes::int32_t;
        e.data = SharedBytes(nullptr, kZero);  // static bytes: no owner to keep alive
        return {};
    }
    auto e = pack_member(info, v, type, "return");
    if (!e) return e.take_error();
    reply.elements.push_back(std::move(*e));
    return {};
}

/// MemberNotFound with the official library's text.
inline RRError member_not_found(std::string_view member) {
    return make_error(MessageErrorType::MemberNotFound, "Member " + std::string(member) + " not found");
}

/// An entry for the client (event, packet, callback request) of `member` at `path`.
inline MessageEntry member_entry(MessageEntryType type, std::string path, std::string member) {
    MessageEntry e;
    e.entry_type = type;
    e.service_path = std::move(path);
    e.member_name = std::move(member);
    return e;
}

}  // namespace rr::server::detail
