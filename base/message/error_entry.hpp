// Error entries (wire.md §5.2; CORE Error.cpp): an entry whose `error` field is non-zero carries,
// instead of its normal elements, the string elements `errorname`, `errorstring` and, if non-empty,
// `errorsubname` and an optional `errorparam` (a varvalue element; core/value packs and unpacks it).
#pragma once

#include <optional>

#include "base/error/rr_error.hpp"
#include "base/message/message.hpp"

namespace rr {

/// A string (string_t) element holding a copy of `text`.
MessageElement make_string_element(std::string name, std::string_view text);

/// Turns `entry` into an error reply: sets `entry.error = error.type` and replaces its elements by
/// `errorname` (error.name, or error_name(error.type) when empty), `errorstring`, `errorsubname` if
/// non-empty and `errorparam` (a copy of error.param) if set. EntryType, ServicePath, MemberName and
/// RequestID are left as they are.
void set_entry_error(MessageEntry& entry, const RRError& error);

/// The error an entry carries, or nullopt when `entry.error` is None. The code decides the type (CORE
/// maps errors by code, wire.md §5.1); the name comes from `errorname` (falling back to
/// error_name(type) when the element is missing or not a string), the message from `errorstring`,
/// the sub-name from `errorsubname`, the parameter from `errorparam` (any element type).
std::optional<RRError> entry_error(const MessageEntry& entry);

/// The header of the reply to `request` (wire.md §4: a reply's EntryType is its request's plus one):
/// that type, the request's ServicePath, MemberName and RequestID; no elements, no error.
MessageEntry reply_to(const MessageEntry& request);

/// The reply a relay forwards: `header` (its EntryType, ServicePath, MemberName, RequestID) carrying
/// the relayed reply's error code and elements, or set_entry_error() of a request that failed.
MessageEntry relayed_reply(MessageEntry header, Result<MessageEntry> result);

}  // namespace rr
