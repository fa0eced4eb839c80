// The service side of a memory member (robdef `memory T[] name` / `memory T[*] name` for numeric, pod
// and namedarray T; wire.md §6.7 "memory"): the contents are stored here and clients read and write
// blocks of it.
//
//   MemoryRead (1171)      `memorypos`, `count` (uint64; arrays of one entry per dimension for
//                          multi-dim) → 1172 with `memorypos`, `count`, `data` (the block, packed as the
//                          memory type: T[] / T[*] with dims = count). Multi-dim replies carry
//                          `memorypos` in their `count` element too: CORE does, and we match it.
//   MemoryWrite (1173)     `memorypos`, `count`, `data` → answered with EntryType 1172 (MemoryReadRet)
//                          holding `memorypos` and `count`, as CORE does (test/interop/README.md);
//                          `data` must hold at least `count` items (multi-dim: at least count per
//                          dimension; column-major).
//   MemoryGetParam (1175)  `parameter`: `Length` (uint64; 1-D), `Dimensions` (uint64[]) and `DimCount`
//                          (uint64) (multi-dim), `MaxTransferSize` (uint32, default 102400 bytes, as CORE);
//                          others → InvalidOperation "Unknown parameter".
// Errors: OutOfRange ("Index out of range") when pos + count passes the dimensions or `data` is too
// short; ReadOnlyMember for writes to `[readonly]`, WriteOnlyMember for reads of `[writeonly]`;
// MessageElementNotFound / DataTypeMismatch for missing or mistyped request elements; DataTypeError for
// `data` that does not fit the memory type.
//
// Threads: every function is thread-safe; a block read or write is atomic with respect to others.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include "server/service/service_object.hpp"

namespace rr::server {

class MemoryMember {
public:
    /// Runs after a client's write was applied: position and count per dimension.
    using WriteHandler = std::function<void(const SessionRef& session, const std::vector<std::uint64_t>& pos,
                                            const std::vector<std::uint64_t>& count)>;

    /// Replaces the contents; also sets the dimensions. Shapes by robdef type:
    ///   numeric T[]   NumericArray of T            numeric T[*]   MultiDimArray of T
    ///   pod P[]       PodArray (no dims)           pod P[*]       PodArray with dims
    ///   namedarray A[] NamedArray (no dims)        namedarray A[*] NamedArray with dims
    /// Errors: DataTypeMismatch / DataTypeError when the value does not fit.
    Result<void> set_contents(Value contents);
    /// A copy of the contents (numeric data shared copy-on-write). Null before set_contents.
    Value contents() const;
    /// Item count per dimension (1-D: one entry).
    std::vector<std::uint64_t> dimensions() const;
    void set_max_transfer_size(std::uint32_t bytes) noexcept;
    void on_write(WriteHandler handler);

    const std::string& name() const noexcept;
    bool is_multidim() const noexcept { return multidim_; }

    // --- used by ServiceObject (on the client's strand) ---
    explicit MemoryMember(std::shared_ptr<const detail::MemberInfo> info);
    void handle_request(const SessionRef& session, MessageEntry&& entry, Responder responder);
    void clear_handlers();

    struct Store;  // implementation detail (memory_member.cpp)

private:
    Result<MessageEntry> read(const MessageEntry& request);
    Result<MessageEntry> write(const SessionRef& session, const MessageEntry& request);
    Result<MessageEntry> param(const MessageEntry& request);

    const std::shared_ptr<const detail::MemberInfo> info_;
    bool multidim_ = false;
    mutable std::mutex mutex_;
    std::shared_ptr<Store> store_;
    std::uint32_t max_transfer_size_ = 102400;
    std::shared_ptr<const WriteHandler> on_write_;
};

}  // namespace rr::server
