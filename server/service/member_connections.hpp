// What the pipe and wire members share (internal to server/service; pipe_member.hpp and
// wire_member.hpp give the rules of each): a member's open connections to its clients (pipe
// endpoints, wire connections), kept by a key that holds the client session's endpoint; the
// on_connect and on_close handlers; and the life of a connection:
//
//   connect     the member adds the connection, then run_on_connect() asks on_connect, before the
//               connect reply; a refusal takes a connection added by that request out again, closed
//               without on_close, and the error becomes the reply.
//   disconnect  a client's disconnect request takes the connection at its key out (no notice to the
//               client: it asked) and is answered; `missing` is the answer when there is none.
//   remove      a connection goes once: it is marked closed, the client gets the member's notice when the
//               service closed it (PipeClosed, WireClosed), and on_close runs. The end of its client
//               session (drop_session) and the release of its service path (drop_path) remove it too,
//               without a notice.
//
// Handlers are kept as shared pointers and called without mutex_ held, so a handler may call back into
// the member. mutex_ also guards the state of the member that derives from this.
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "server/node/service.hpp"

namespace rr::server::detail {

template <class Connection, class Key>
class MemberConnections;

/// The part of a pipe endpoint or wire connection its member's table needs: the client session, the
/// service path it was connected at, and whether it is still open.
class MemberConnection {
public:
    const SessionRef& session() const noexcept { return session_; }
    const std::string& service_path() const noexcept { return path_; }
    bool is_open() const noexcept { return open_.load(); }

protected:
    MemberConnection(SessionRef session, std::string path) : session_(std::move(session)), path_(std::move(path)) {}
    ~MemberConnection() = default;

    template <class Connection, class Key>
    friend class MemberConnections;

    const SessionRef session_;
    const std::string path_;
    std::atomic<bool> open_{true};
};

/// The connections of one member and their handlers. `Connection` derives from MemberConnection;
/// `Key` identifies a connection within the member (its session's endpoint first).
template <class Connection, class Key>
class MemberConnections {
public:
    /// Runs before the connect reply; an error refuses the connection (and is the reply).
    using ConnectHandler = std::function<Result<void>(const std::shared_ptr<Connection>& connection)>;
    /// Runs once per connection when it goes (see remove above).
    using CloseHandler = std::function<void(const std::shared_ptr<Connection>& connection)>;

    void on_connect(ConnectHandler handler) { set_handler(on_connect_, std::move(handler)); }
    void on_close(CloseHandler handler) { set_handler(on_close_, std::move(handler)); }

    // --- used by ServiceObject (on the client's strand) ---
    /// The client session ended: its connections go without a notice.
    void drop_session(const SessionRef& session) {
        drop_if([e = session.endpoint()](const Connection& c) { return c.session().endpoint() == e; });
    }
    /// The object at `path` was released: the connections at that path go without a notice.
    void drop_path(const std::string& path) {
        drop_if([&](const Connection& c) { return c.service_path() == path; });
    }

protected:
    MemberConnections() = default;
    ~MemberConnections() = default;

    /// Sets a handler slot of this member (empty `handler`: none).
    template <class F>
    void set_handler(std::shared_ptr<const F>& slot, F handler) {
        auto h = handler ? std::make_shared<const F>(std::move(handler)) : nullptr;
        std::lock_guard lock(mutex_);
        slot = std::move(h);
    }

    /// Drops on_connect, on_close and the member's `more` handler slots; they are destroyed after
    /// mutex_ is released (a handler's captures may call back into the member).
    template <class... F>
    void clear_handler_slots(std::shared_ptr<const F>&... more) {
        std::vector<std::shared_ptr<const void>> dropped;
        std::lock_guard lock(mutex_);
        dropped.push_back(std::move(on_connect_));
        dropped.push_back(std::move(on_close_));
        (dropped.push_back(std::move(more)), ...);
    }

    /// The open connections (a snapshot).
    std::vector<std::shared_ptr<Connection>> snapshot() const {
        std::lock_guard lock(mutex_);
        std::vector<std::shared_ptr<Connection>> out;
        out.reserve(connections_.size());
        for (const auto& [k, c] : connections_) out.push_back(c);
        return out;
    }

    /// The connection at `key`, or null.
    std::shared_ptr<Connection> find(const Key& key) const {
        std::lock_guard lock(mutex_);
        auto it = connections_.find(key);
        return it == connections_.end() ? nullptr : it->second;
    }

    /// Asks `on_connect` (on_connect_ as the member read it, with mutex_, when it put `connection` at
    /// `key`; `created`: by this request, not found there) about the connection. A refusal takes a
    /// created connection out again and closes it (no on_close runs) and is returned, for the connect
    /// reply.
    Result<void> run_on_connect(const std::shared_ptr<const ConnectHandler>& on_connect, const Key& key,
                                const std::shared_ptr<Connection>& connection, bool created) {
        if (!on_connect) return {};
        auto r = (*on_connect)(connection);
        if (!r && created) {
            {
                std::lock_guard lock(mutex_);
                auto it = connections_.find(key);
                if (it != connections_.end() && it->second == connection) connections_.erase(it);
            }
            connection->open_.store(false);
        }
        return r;
    }

    /// Takes `connection` out when it is still the one at `key` (otherwise it went already and nothing
    /// happens), marks it closed, sends `notice` to its client when given, then runs on_close.
    void remove(const Key& key, const std::shared_ptr<Connection>& connection, std::optional<MessageEntry> notice) {
        std::shared_ptr<const CloseHandler> on_close;
        {
            std::lock_guard lock(mutex_);
            auto it = connections_.find(key);
            if (it == connections_.end() || it->second != connection) return;  // already removed: on_close ran
            connections_.erase(it);
            on_close = on_close_;
        }
        connection->open_.store(false);
        if (notice) (void)connection->session().send(std::move(*notice));
        if (on_close) (*on_close)(connection);
    }

    /// A client's disconnect request for the connection at `key`: removed without a notice and answered
    /// with an empty reply, or `missing` when there is none.
    void disconnect(const Key& key, Responder& responder, RRError missing) {
        auto connection = find(key);
        if (!connection) {
            responder.fail(std::move(missing));
            return;
        }
        remove(key, connection, std::nullopt);
        responder.respond(MessageEntry{});
    }

    mutable std::mutex mutex_;  // the table, the handler slots, and the deriving member's own state
    std::map<Key, std::shared_ptr<Connection>> connections_;
    std::shared_ptr<const ConnectHandler> on_connect_;
    std::shared_ptr<const CloseHandler> on_close_;

private:
    void drop_if(const std::function<bool(const Connection&)>& pred) {
        std::vector<std::pair<Key, std::shared_ptr<Connection>>> dropped;
        {
            std::lock_guard lock(mutex_);
            for (const auto& [k, c] : connections_)
                if (pred(*c)) dropped.emplace_back(k, c);
        }
        for (const auto& [k, c] : dropped) remove(k, c, std::nullopt);
    }
};

}  // namespace rr::server::detail
