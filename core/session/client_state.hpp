// Internal to the typed client (client_context.cpp, client_pipes.cpp, client_wires.cpp,
// client_generators.cpp, client_memory.cpp): per-kind state and small helpers. Not a public header.
#pragma once

#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "base/message/error_entry.hpp"
#include "core/session/client_context.hpp"

namespace rr {

/// An object the client knows: the root, or one resolved through an objref.
struct ClientContext::ObjectState {
    ObjectRef ref;
    const robdef::ServiceDefinition* service = nullptr;   ///< the definition holding the object type
    const robdef::ServiceEntryDefinition* entry = nullptr;  ///< the object type
};

struct ClientContext::GeneratorState {
    std::string path, member;
    std::string context_service;
    std::int32_t index = 0;             ///< the service's generator index
    robdef::TypeDefinition return_type;  ///< without `{generator}`; void for a void return
    std::optional<robdef::TypeDefinition> parameter_type;
};

struct ClientContext::PipeState {
    std::string path, member;
    std::string context_service;
    robdef::TypeDefinition type;
    std::int32_t index = 0;
    bool unreliable = false;
    bool readable = true;
    bool writable = true;
    bool closed = false;
    bool early = false;        ///< created for packets that came before the PipeConnectRet
    bool request_ack = false;
    std::uint32_t send_packet_number = 0;  ///< last sent (first sent packet is 1)
    std::uint32_t recv_packet_number = 0;  ///< last delivered in order
    std::map<std::uint32_t, Value> out_of_order;
    std::deque<Value> queue;
    std::shared_ptr<PipeEndpointHandlers> handlers = std::make_shared<PipeEndpointHandlers>();
};

struct ClientContext::WireState {
    std::string path, member;
    std::string context_service;
    robdef::TypeDefinition type;
    bool readable = true;
    bool writable = true;
    bool closed = false;
    std::shared_ptr<const WireValue> in;   ///< newest InValue (shared: handlers see it without a copy)
    std::shared_ptr<const WireValue> out;  ///< last OutValue sent
    std::int32_t in_lifespan_ms = -1;
    std::int32_t out_lifespan_ms = -1;
    std::shared_ptr<WireConnectionHandlers> handlers = std::make_shared<WireConnectionHandlers>();
};

/// What a memory member is and how big one transfer may be.
struct ClientContext::MemoryCaps {
    robdef::TypeDefinition type;    ///< the memory's type (`double[]`, `TestPod[*]`, …)
    std::string context_service;
    bool multidim = false;
    bool readable = true;
    bool writable = true;
    std::size_t item_bytes = 1;     ///< packed size of one item (for chunking)
    std::uint64_t max_items = 1;    ///< items per MemoryRead / MemoryWrite (≥ 1)
    DataTypes element_type = DataTypes::void_t;  ///< numeric / namedarray element type
    std::size_t elements_per_item = 1;           ///< namedarray: numeric elements per item
    bool pod = false;
    bool namedarray = false;
    std::string named_type;  ///< qualified pod / namedarray type
};

/// Key of a (path, member) pair in the maps of ClientContext.
inline std::string member_key(std::string_view path, std::string_view member) {
    std::string k;
    k.reserve(path.size() + member.size() + 1);
    k.append(path);
    k.push_back('\n');
    k.append(member);
    return k;
}

/// The generic entry of a member request.
inline MessageEntry member_entry(MessageEntryType type, std::string_view path, std::string_view member) {
    MessageEntry e;
    e.entry_type = type;
    e.service_path = std::string(path);
    e.member_name = std::string(member);
    return e;
}

/// A reply (or a local failure) as a Result: an entry whose Error field is set becomes its RRError.
inline Result<MessageEntry> reply_result(Result<MessageEntry> r) {
    if (!r) return r;
    if (auto err = entry_error(*r)) return fail(std::move(*err));
    return r;
}

}  // namespace rr
