// The pure rules of the rr+local transport (wire.md §9; CORE `LocalTransport.cpp`,
// `NodeDirectories.cpp`): NodeName and user name syntax, the `.info` entry format, where entries,
// sockets and the NodeID cache live below the node directories, what an rr+local URL asks for, and
// which directories a client searches. No I/O: the files and sockets are handled in
// local_entries.hpp, local_listener.hpp and local_connector.hpp.
//
// Layout below the node directories (node_directories.hpp):
//   private (same user):  <user run>/transport/local/{by-nodeid,by-nodename}/  entries
//                         <user run>/socket/<16 random [A-Za-z0-9]>.sock      sockets (mode 0770)
//   public (group):       <system run>/transport/local/<user>/{by-nodeid,by-nodename,socket}/
//                         (only when an administrator created <system run>/transport/local/<user>)
//   entries:              by-nodeid/<nodeid 8-4-4-4-12>.{info,pid}, by-nodename/<NodeName>.{info,pid}
//   NodeID cache:         <user config>/nodeids/<NodeName> = "{nodeid}" (root writes
//                         <system state>/nodeids/<NodeName> unless <system config>/nodeids/<NodeName>
//                         exists), locked through <user run>/nodeids/<NodeName>.pid
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"
#include "base/names/connection_url.hpp"
#include "base/names/node_id.hpp"
#include "server/transport/local/node_directories.hpp"

namespace rr::server::local {

/// `^[a-zA-Z][a-zA-Z0-9_.-]*$` (CORE StartServerAsNodeName, GetUuidForNameAndLock).
bool is_valid_node_name(std::string_view name) noexcept;
/// `^[a-zA-Z][a-zA-Z0-9_-]*$`, the user part of `rr+local://user@localhost/` (CORE).
bool is_valid_local_username(std::string_view name) noexcept;

/// Largest `.info` / `.pid` / NodeID cache file read (bytes); larger files are refused. CORE reads
/// any size; 16 KiB is its own limit for the NodeID cache.
inline constexpr std::size_t kMaxEntryFileSize = 16 * 1024;

/// Key → value of an `.info` entry.
using InfoMap = std::map<std::string, std::string, std::less<>>;

/// Parses an `.info` file: one `key: value` per line (key of [A-Za-z0-9_+.-], blanks around key and
/// value ignored, other lines skipped). When a key repeats, the LAST value wins: CORE appends a fresh
/// block to the file of a restarted node that registers no service (it only truncates when the
/// services change), so the last block is the live one. (CORE's reader keeps the first and then
/// finds the dead socket; see docs/local-transport.md.)
InfoMap parse_info(std::string_view text);
/// `key: value\n` per entry in key order (byte order, as CORE's std::map writes them).
std::string format_info(const InfoMap& info);

/// The base of the URLs a node reports for connections that came in over rr+local (service index,
/// wire.md §11.2): the service index appends `?nodeid=<8-4-4-4-12>&service=<name>`.
inline constexpr std::string_view kLocalBaseUrl = "rr+local:///";
/// The URL CORE lists for a listening local transport: `rr+local:///?nodeid=<8-4-4-4-12>`.
std::string local_listen_url(const NodeID& id);

/// `<user run>/transport/local`: the private entry directory.
std::string private_entry_dir(const NodeDirectories& d);
/// `<user run>/socket`: where private sockets are created.
std::string private_socket_dir(const NodeDirectories& d);
/// `<system run>/transport/local`: the parent of the public per-user directories.
std::string public_search_dir(const NodeDirectories& d);
/// `<system run>/transport/local/<user>`: one user's public entry directory (its sockets are in
/// `socket/` below it).
std::string public_user_dir(const NodeDirectories& d, std::string_view user);
/// `<entry dir>/by-nodeid/<nodeid>.<ext>` (ext "info" or "pid").
std::string by_nodeid_file(std::string_view entry_dir, const NodeID& id, std::string_view ext);
/// `<entry dir>/by-nodename/<name>.<ext>`.
std::string by_nodename_file(std::string_view entry_dir, std::string_view name, std::string_view ext);
/// `<user run>/nodeids/<name>.pid`: held while a node runs under that NodeName.
std::string nodename_lock_file(const NodeDirectories& d, std::string_view name);
/// `<user config>/nodeids/<name>`: the NodeID cache read first (and, for non-root, written).
std::string nodeid_cache_file(const NodeDirectories& d, std::string_view name);
/// `<user state>/nodeids/<name>`: where root creates the NodeID when the config copy is absent.
std::string nodeid_state_file(const NodeDirectories& d, std::string_view name);

/// Longest socket path a Unix socket address holds (sun_path minus the terminating NUL).
inline constexpr std::size_t kMaxSocketPath = 107;

/// What an rr+local URL asks for.
struct LocalTarget {
    NodeID node_id;          ///< all-zero when not given
    std::string node_name;   ///< empty when not given
    std::string user;        ///< `user@localhost`; empty = the current user (and root's public nodes)
    /// `nodeid=…` when given, else the NodeName: the form used in messages.
    std::string describe() const;
};

/// Checks the URL's shape for rr+local (CORE AsyncCreateTransportConnection): scheme rr+local, no
/// port (the URL parser refuses one), host empty or `localhost`, path `/`, a valid user name when
/// `user@localhost` is given, a NodeID and/or a NodeName. Errors: InvalidArgument naming the problem.
Result<LocalTarget> local_target(const ConnectionUrl& url);

/// One directory a client searches, in order.
struct SearchDir {
    std::string path;  ///< an entry directory (holding by-nodeid/ and by-nodename/)
    bool is_public = false;
};
/// The entry directories searched for `target` by a process running as `my_user` (CORE order):
/// no user given or the user is `my_user`: the private dir, then `my_user`'s public dir; with no user
/// given also root's public dir; another user: that user's public dir only. Duplicates dropped.
/// Public dirs that do not exist are simply found empty by the caller.
std::vector<SearchDir> search_dirs(const NodeDirectories& d, std::string_view my_user, const LocalTarget& target);

}  // namespace rr::server::local
