// v4 string tables (wire.md §2.6; CORE StringTable.cpp, StringTable_default_table.h).
//
// Replaceable strings: entry ServicePath and MemberName, element ElementName and ElementTypeName.
// Odd codes name the message-local table carried in the header (STRING_TABLE flag); even codes name
// the connection-wide table, which is the standard table below when STANDARD_TABLE was negotiated.
// The decoder resolves every code to its string and keeps the code in the model's *_code field, so a
// decoded message re-encodes with the same codes.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include "base/error/rr_error.hpp"
#include "base/message/message.hpp"

namespace rr {

/// Capability flags of page MESSAGE4_STRINGTABLE_PAGE (wire.md §2.1).
namespace string_table_capability {
inline constexpr std::uint32_t page = 0x04100000;
inline constexpr std::uint32_t enable = 0x00000001;
inline constexpr std::uint32_t message_local = 0x00000002;
inline constexpr std::uint32_t standard_table = 0x00000004;
}  // namespace string_table_capability

/// Strings CORE replaces only when at most this many bytes long.
inline constexpr std::size_t kMaxStringTableStringBytes = 128;
/// CORE's bound on the encoded message-local table (codes + XLen strings), bytes.
inline constexpr std::size_t kMaxLocalStringTableBytes = 1024;

/// The standard table: string for an even `code`, or nullopt if the code is not in it.
/// Code 0 is the empty string.
std::optional<std::string_view> standard_string_for_code(std::uint32_t code) noexcept;

/// The standard table: the first code registered for `s` (136 for "nodeid", 268 for "ServiceIndex"),
/// or nullopt.
std::optional<std::uint32_t> standard_code_for_string(std::string_view s) noexcept;

/// Which tables a sender may use (the negotiated flags of page 0x041, wire.md §2.1).
struct StringTableOptions {
    bool standard_table = true;
    bool message_local = true;
};

/// Replaces strings with codes the way CORE's sender does (StringTable::MessageReplaceStringsWithCodes),
/// for a message about to be written in format 4: per entry MemberName, then ServicePath, then each
/// element depth-first (ElementName unless it has a number, then a non-empty ElementTypeName); strings
/// over 128 bytes are left alone; a standard-table string gets its code; any other string gets a
/// message-local code 1, 3, 5, … while the local table stays within 1024 bytes. Strings stay filled
/// in; only the *_code fields, `header.string_table` and (if `header.v4_flags` is set) the STRING_TABLE
/// flag change. Does nothing if the message already has a local table. CORE stores its local table in
/// a hash map, so its table order is unspecified; ours is first-use order.
void apply_string_table(Message& message, const StringTableOptions& options);

/// Clears every *_code field and the local table (e.g. before sending on a connection without string
/// tables). Clears the STRING_TABLE flag when `header.v4_flags` is set.
void clear_string_table_codes(Message& message);

}  // namespace rr
