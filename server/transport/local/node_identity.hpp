// The NodeName and NodeID of a node that serves rr+local (CORE `GetUuidForNameAndLock`,
// `LocalTransportNodeLock`): a named node takes its NodeID from the NodeID cache (created with a random
// NodeID on first use, as CORE does, so the NodeID stays the same across restarts), and holds the
// name for as long as it runs, both against other processes (an fcntl lock on
// `<user run>/nodeids/<name>.pid`, the lock CORE takes) and inside this process.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "base/error/rr_error.hpp"
#include "base/names/node_id.hpp"
#include "server/transport/local/local_entries.hpp"
#include "server/transport/local/node_directories.hpp"

namespace rr::server::local {

/// Holds a NodeName (and a NodeID) for this process until destroyed. Move-only.
class InProcessClaim {
public:
    InProcessClaim() = default;
    ~InProcessClaim();
    InProcessClaim(InProcessClaim&& o) noexcept : key_(std::move(o.key_)) { o.key_.clear(); }
    InProcessClaim& operator=(InProcessClaim&& o) noexcept;
    InProcessClaim(const InProcessClaim&) = delete;
    InProcessClaim& operator=(const InProcessClaim&) = delete;

    /// Claims `key` ("name:<NodeName>" or "id:<NodeID>"); nullopt when this process already holds it.
    static std::optional<InProcessClaim> take(std::string key);
    bool held() const noexcept { return !key_.empty(); }

private:
    std::string key_;
};

/// A NodeName held by this process, and the NodeID the NodeID cache gives it.
struct NodeNameReservation {
    std::string node_name;
    NodeID node_id;
    std::string nodeid_file;  ///< the cache file the NodeID was read from (or written to)
    InProcessClaim claim;     ///< the name inside this process
    LockedFile lock;          ///< `<user run>/nodeids/<name>.pid`, holding this process's pid
};

/// Reserves `name` and reads (or creates) its NodeID, the way CORE does for StartServerAsNodeName:
///   1. the name must match `^[a-zA-Z][a-zA-Z0-9_.-]*$` (else InvalidArgument);
///   2. no other node of this process holds it (else InvalidOperation "already in use in this process");
///   3. lock `<user run>/nodeids/<name>.pid` (created, with its parents; else InvalidOperation
///      "NodeName … is already in use by process N", the official "Identifier UUID or Name already in use");
///   4. the NodeID: root reads `<user config>/nodeids/<name>` when it exists, else uses
///      `<user state>/nodeids/<name>`; other users use `<user config>/nodeids/<name>`; the file is
///      locked while read, and an empty (new) file gets a fresh random NodeID written as `{…}`, as CORE
///      writes it. A file that does not hold a NodeID is an IOError naming it (CORE: "Error in UUID name
///      store file"); a missing user config dir (no HOME) is a SystemResourceError.
/// `wanted` (a NodeID the node is configured with) is what a new, empty cache file gets instead of a
/// random one; an existing cache entry is returned as it is (the caller reports a mismatch).
Result<NodeNameReservation> reserve_node_name(const NodeDirectories& dirs, std::string_view name,
                                              const NodeID& wanted = NodeID{});

}  // namespace rr::server::local
