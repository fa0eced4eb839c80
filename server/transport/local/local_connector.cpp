#include "server/transport/local/local_connector.hpp"

#include <cerrno>
#include <cstring>

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <boost/asio/post.hpp>

#include "server/transport/local/local_entries.hpp"

namespace rr::server::local {

namespace asio = boost::asio;
using unix_socket = asio::local::stream_protocol;

namespace {

// Why one candidate entry did not give a connection.
enum class Miss { absent, permission, mismatch, bad_entry, stale, refused, busy };

struct Note {
    Miss miss;
    std::string text;
};

// Connects a non-blocking Unix socket at once (AF_UNIX connects complete or fail immediately; a full
// listen queue is EAGAIN, reported rather than waited for). Returns the fd or -errno.
int connect_now(const std::string& path) {
    sockaddr_un addr{};
    if (path.size() > kMaxSocketPath) return -ENAMETOOLONG;
    addr.sun_family = AF_UNIX;
    std::memcpy(addr.sun_path, path.data(), path.size());
    int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    if (fd < 0) return -errno;
    if (::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) == 0) return fd;
    int err = errno;
    ::close(fd);
    return -err;
}

}  // namespace

Result<unix_socket::socket> connect_local_socket(const asio::any_io_executor& executor, const ConnectionUrl& url,
                                                 const NodeDirectories& dirs, FoundNode* found) {
    auto target = local_target(url);
    if (!target) return target.take_error();
    auto me = current_user_name();
    if (!me) return me.take_error();
    const auto candidates = search_dirs(dirs, *me, *target);
    const std::string who = "local node " + target->describe();

    std::vector<Note> notes;
    auto read_entry = [&](const std::string& path) -> std::optional<InfoMap> {
        auto text = read_small_file(path, kMaxEntryFileSize);
        if (text) return parse_info(*text);
        switch (text.error().type) {
        case MessageErrorType::ResourceNotFound:
            notes.push_back({Miss::absent, path});
            break;
        case MessageErrorType::SystemResourcePermissionDenied:
            notes.push_back({Miss::permission, "permission denied reading " + path});
            break;
        default:
            notes.push_back({Miss::bad_entry, text.error().message});
        }
        return std::nullopt;
    };

    for (const auto& dir : candidates) {
        std::string info_path;
        std::optional<InfoMap> info;
        if (!target->node_id.is_any()) {
            info_path = by_nodeid_file(dir.path, target->node_id, "info");
            info = read_entry(info_path);
            if (!info) continue;
            if (!target->node_name.empty()) {
                auto name = info->find("nodename");
                if (name == info->end() || name->second != target->node_name) {
                    notes.push_back({Miss::mismatch, info_path + " is NodeID " + target->node_id.to_string() + " named \"" +
                                                         (name == info->end() ? std::string() : name->second) + "\", not \"" +
                                                         target->node_name + "\""});
                    continue;
                }
                const std::string name_path = by_nodename_file(dir.path, target->node_name, "info");
                auto by_name = read_entry(name_path);
                if (!by_name) continue;
                auto s1 = info->find("socket");
                auto s2 = by_name->find("socket");
                if (s1 == info->end() || s2 == by_name->end() || s1->second != s2->second) {
                    notes.push_back({Miss::mismatch, name_path + " and " + info_path + " name different sockets (NodeName \"" +
                                                         target->node_name + "\" belongs to another NodeID)"});
                    continue;
                }
            }
        } else {
            info_path = by_nodename_file(dir.path, target->node_name, "info");
            info = read_entry(info_path);
            if (!info) continue;
        }
        auto socket_it = info->find("socket");
        if (socket_it == info->end() || socket_it->second.empty()) {
            notes.push_back({Miss::bad_entry, info_path + " names no socket"});
            continue;
        }
        const std::string& socket_path = socket_it->second;
        int fd = connect_now(socket_path);
        if (fd >= 0) {
            unix_socket::socket sock(executor);
            boost::system::error_code ec;
            sock.assign(unix_socket(), fd, ec);
            if (ec) {
                ::close(fd);
                return fail(MessageErrorType::ConnectionError, who + ": " + ec.message());
            }
            if (found) *found = FoundNode{socket_path, info_path, *info};
            return sock;
        }
        const int err = -fd;
        if (err == ECONNREFUSED || err == ENOENT || err == ENOTSOCK) {
            auto holder = lock_holder(info_path);
            if (holder)
                notes.push_back({Miss::refused, "its entry " + info_path + " is held by process " + std::to_string(*holder) +
                                                    " but its socket " + socket_path + " refuses connections (" +
                                                    std::strerror(err) + ")"});
            else
                notes.push_back({Miss::stale, "its entry " + info_path + " names socket " + socket_path +
                                                  ", which is stale (" + std::strerror(err) +
                                                  "; no process holds the entry: the node exited without removing it)"});
        } else if (err == EACCES || err == EPERM) {
            notes.push_back({Miss::permission, "permission denied connecting to " + socket_path +
                                                   " (the node runs as another user; see docs/local-transport.md)"});
        } else if (err == EAGAIN) {
            notes.push_back({Miss::busy, "its socket " + socket_path + " is not accepting connections (listen queue full)"});
        } else {
            notes.push_back({Miss::refused, "cannot connect to " + socket_path + ": " + std::strerror(err)});
        }
    }

    // Nothing connected: every entry found and why it failed; only stale entries = not running.
    std::string reasons;
    bool only_stale = true;
    for (const auto& n : notes) {
        if (n.miss == Miss::absent) continue;
        only_stale = only_stale && n.miss == Miss::stale;
        reasons += (reasons.empty() ? "" : "; ") + n.text;
    }
    if (!reasons.empty()) return fail(MessageErrorType::ConnectionError, who + (only_stale ? " is not running: " : ": ") + reasons);
    std::string searched;
    for (const auto& d : candidates) searched += (searched.empty() ? "" : ", ") + d.path;
    std::string what = !target->node_name.empty() ? "named \"" + target->node_name + "\"" : "with NodeID " + target->node_id.to_string();
    if (!target->node_name.empty() && !target->node_id.is_any()) what += " and NodeID " + target->node_id.to_string();
    return fail(MessageErrorType::ConnectionError, "no local node " + what + " (searched " + searched + ")");
}

void LocalConnector::connect(asio::any_io_executor strand, const ConnectionUrl& url, const ConnectOptions&,
                             std::shared_ptr<ConnectionLogic> logic, ConnectHandler done) {
    // The lookup reads a few small files: done on the strand, as the TCP connect completes there.
    asio::post(strand, [strand, url, dirs = dirs_, logic = std::move(logic), done = std::move(done)]() mutable {
        auto socket = connect_local_socket(strand, url, dirs());
        if (!socket) return done(socket.take_error());
        start_client_stream(std::move(*socket), strand, std::move(logic), done);
    });
}

}  // namespace rr::server::local
